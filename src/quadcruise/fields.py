"""Fields with units: one declaration (default, unit, doc, check) and one validation for every
frozen parameter object of the package (vehicles, missions, disturbances).

A field is declared with :func:`unit_field`; :func:`check_number` turns a value into a finite
float or raises :class:`~quadcruise.errors.InputError` naming the field, its meaning and unit.
"""

from __future__ import annotations

import math
from dataclasses import field
from typing import Any

import numpy as np

from quadcruise.errors import InputError

__all__ = ["check_number", "unit_field"]


def unit_field(default: Any, unit: str, doc: str, check: str = "real", choices: tuple = ()):
    """A dataclass field with its unit [SI], meaning and check: ``real``, ``pos`` (> 0),
    ``nonneg`` (>= 0), ``sign`` (+1 or -1), ``pair``, ``choice`` (one of ``choices``), or a
    check of the owning class's own (``custom`` and the others it names).

    Parameters
    ----------
    default : Any
        The default value.
    unit : str
        The SI unit, e.g. ``"m"``, ``"rad/s"`` (``"-"`` for a pure number).
    doc : str
        What the field means, as an error message names it.
    check : str
        The check the owning class applies.
    choices : tuple
        The allowed values of a ``choice`` field.

    Returns
    -------
    dataclasses.Field
        With ``metadata`` keys ``unit``, ``doc``, ``check`` and ``choices``.
    """
    return field(default=default, metadata={"unit": unit, "doc": doc, "check": check, "choices": choices})


def check_number(label: str, value: Any) -> float:
    """``value`` as a finite float, else InputError "<label> must be a number / finite".

    Parameters
    ----------
    label : str
        How the error names the value (file, field, unit).
    value : Any
        An int or float (not a bool, not a string).

    Returns
    -------
    float

    Examples
    --------
    >>> check_number("circle field 'radius'", 2)
    2.0
    >>> check_number("circle field 'radius'", "2")
    Traceback (most recent call last):
        ...
    quadcruise.errors.InputError: circle field 'radius' must be a number, got '2'
    """
    if isinstance(value, bool) or not isinstance(value, (int, float, np.integer, np.floating)):
        raise InputError(f"{label} must be a number, got {value!r}")
    if not math.isfinite(value):
        raise InputError(f"{label} must be finite, got {float(value)!r}")
    return float(value)
