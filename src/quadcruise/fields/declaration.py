"""The declaration and the validation of fields with units: :func:`unit_field` declares a
dataclass field with its unit, meaning and check; :func:`validate` checks every field of a
dataclass and stores each value in its checked form; :class:`Validated`, the base of the
package's parameter classes, runs it when an object is made.

Examples
--------
>>> from dataclasses import dataclass
>>> @dataclass(frozen=True)
... class Gust(Validated):
...     duration: float = unit_field(1.0, "s", "gust duration", "pos")
>>> Gust(duration=2).duration, Gust.units()
(2.0, {'duration': 's'})
"""

from __future__ import annotations

import dataclasses
from typing import Any, ClassVar

import numpy as np

from quadcruise.errors import InputError
from quadcruise.fields.checks import CHECKS, Check, one_of

__all__ = ["Validated", "unit_field", "units_of", "validate"]


def unit_field(
    default: Any = dataclasses.MISSING,
    unit: str = "",
    doc: str = "",
    check: str | Check = "real",
    choices: tuple = (),
    *,
    factory: Any = dataclasses.MISSING,
    batch: bool = False,
    optional: bool | None = None,
):
    """A dataclass field with its unit [SI], meaning and check.

    Parameters
    ----------
    default : Any, optional
        The default value (leave out for a required field, or give ``factory``).
    unit : str
        The SI unit, e.g. ``"m"``, ``"rad/s"`` (``"-"`` for a pure number or a word).
    doc : str
        What the field means, as an error message names it.
    check : str or Check
        A name of :data:`CHECKS`, ``"choice"`` (one of ``choices``), or a :class:`Check`.
    choices : tuple
        The allowed values of a ``choice`` field.
    factory : callable, optional
        Makes the default (for objects: gains, tables).
    batch : bool
        The field may hold one value per vehicle (a 1-D array, or arrays inside a vector).
    optional : bool, optional
        None is allowed; by default, when the default is None.

    Returns
    -------
    dataclasses.Field
        With ``metadata`` keys ``unit``, ``doc``, ``check`` (a :class:`Check`), ``batch``
        and ``optional``.

    Examples
    --------
    >>> f = unit_field(1.0, "s", "gust duration", "pos")
    >>> f.default, f.metadata["unit"], f.metadata["check"]
    (1.0, 's', <check pos: > 0>)
    """
    if not unit or not doc:
        raise TypeError("unit_field needs a unit and a doc")
    if check == "choice":
        check = one_of(*choices)
    elif isinstance(check, str):
        if check not in CHECKS:
            raise TypeError(f"unknown check {check!r}; known: choice, {', '.join(CHECKS)}")
        check = CHECKS[check]
    if optional is None:
        optional = default is None
    meta = {"unit": unit, "doc": doc, "check": check, "batch": batch, "optional": optional}
    if factory is not dataclasses.MISSING:
        return dataclasses.field(default_factory=factory, metadata=meta)
    return dataclasses.field(default=default, metadata=meta)


def owner_name(cls: type) -> str:
    """How messages name an object of ``cls``: its ``name`` attribute, else the class name."""
    name = getattr(cls, "name", "")
    return name if isinstance(name, str) and name else cls.__name__


def validate(obj: Any) -> int | None:
    """Check every field of the dataclass ``obj`` (declared with :func:`unit_field`) and store
    each value in its checked form; the one validation of every parameter class.

    Messages name the owner (``obj.name``, else its class name) and call a field a
    ``field`` (or the class's ``field_noun``: controllers say ``parameter``).

    Parameters
    ----------
    obj : dataclass instance
        A (frozen) dataclass whose fields all come from :func:`unit_field`.

    Returns
    -------
    int or None
        The batch length N if some field holds per-vehicle arrays, else None.

    Raises
    ------
    InputError
        A bad value (one line: owner, field, meaning, unit, what was wrong), or per-vehicle
        arrays of different lengths.
    TypeError
        A field not declared with :func:`unit_field` (a programming error).

    Examples
    --------
    >>> from quadcruise.missions import Circle
    >>> validate(Circle()) is None
    True
    """
    cls = type(obj)
    owner, noun = owner_name(cls), getattr(cls, "field_noun", "field")
    sizes: set[int] = set()
    for f in dataclasses.fields(obj):
        meta = f.metadata
        if not isinstance(meta.get("check"), Check):
            raise TypeError(f"{cls.__name__}.{f.name} is not declared with quadcruise.fields.unit_field")
        label = f"{owner} {noun} '{f.name}' ({meta['doc']}, {meta['unit']})"
        value = meta["check"](label, getattr(obj, f.name), batch=meta["batch"], optional=meta["optional"])
        object.__setattr__(obj, f.name, value)
        for v in value if isinstance(value, tuple) else (value,):
            if isinstance(v, np.ndarray) and meta["batch"]:
                sizes.add(v.shape[0])
    if len(sizes) > 1:
        raise InputError(f"{owner} fields have different batch lengths {sorted(sizes)}")
    return next(iter(sizes), None)


def units_of(cls: type) -> dict[str, str]:
    """Each field's unit; a field holding an object with units (gains, a disturbance part)
    lists that object's fields as ``<field>.<name>``.

    Parameters
    ----------
    cls : type
        A dataclass declared with :func:`unit_field`.

    Returns
    -------
    dict
        Field name -> unit.

    Examples
    --------
    >>> from quadcruise.control.position import NLPD
    >>> units = units_of(NLPD)
    >>> units["position.kp"], units["max_tilt"]
    ('1/s^2', 'rad')
    """
    out: dict[str, str] = {}
    for f in dataclasses.fields(cls):
        inner = getattr(f.metadata["check"], "cls", None)
        if inner is not None and hasattr(inner, "units"):
            out.update({f"{f.name}.{k}": u for k, u in inner.units().items()})
        else:
            out[f.name] = f.metadata["unit"]
    return out


class Validated:
    """Base of the package's parameter classes (frozen dataclasses of :func:`unit_field`
    fields): validates on construction (:func:`validate`) and lists units (:meth:`units`).

    A subclass names itself in messages by ``name`` (else its class name) and its fields by
    ``field_noun``; one with more to check overrides ``__post_init__`` and calls
    ``super().__post_init__()``.

    Examples
    --------
    >>> from quadcruise.model.vehicle import Vehicle
    >>> issubclass(Vehicle, Validated), Vehicle.units()["m"]
    (True, 'kg')
    """

    field_noun: ClassVar[str] = "field"

    def __post_init__(self) -> None:
        validate(self)

    @classmethod
    def units(cls) -> dict[str, str]:
        """Each field's unit: :func:`units_of`.

        Returns
        -------
        dict of str to str
            Field name -> unit (nested objects' fields as ``<field>.<name>``).
        """
        return units_of(cls)
