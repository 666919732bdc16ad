"""The Python API's argument checks: one message form for every public function.

A bad argument raises one line, before any work, naming the function, the argument, what is
expected and what was given: :class:`~quadcruise.errors.ArgumentTypeError` for a value of the
wrong kind (text for a number, a bool for a number, a float for a whole number, anything but a
bool for a switch), :class:`~quadcruise.errors.InputError` for one out of range. The rule and
its reasons: docs/architecture.md, "Arguments".

Examples
--------
>>> number("fly()", "dt", 0.001, "pos", unit="s")
0.001
>>> number("fly()", "dt", "0.001", "pos", unit="s")
Traceback (most recent call last):
    ...
quadcruise.errors.ArgumentTypeError: fly() argument dt must be a positive number of seconds, got str '0.001'
>>> whole("fly()", "seed", 1.5)
Traceback (most recent call last):
    ...
quadcruise.errors.ArgumentTypeError: fly() argument seed must be a whole number >= 0, got float 1.5
"""

from __future__ import annotations

import inspect
import math
import numbers
from typing import Any

import numpy as np

from quadcruise.errors import ArgumentTypeError, InputError

__all__ = ["callback", "describe", "fail", "flag", "instance", "number", "pair", "short_number", "whole"]

_UNITS = {"s": " of seconds", "m": " of metres"}


def short_number(x: float) -> str:
    """A number as a message writes it: its repr when short, else 6 significant digits.

    Examples
    --------
    >>> short_number(0.1), short_number(10**300), short_number(2)
    ('0.1', '1e+300', '2')
    """
    if isinstance(x, (int, np.integer)) and not isinstance(x, bool) and abs(int(x)) < 10**12:
        return str(int(x))
    try:
        text = repr(float(x))
    except OverflowError:
        return f"{x:.6g}" if not isinstance(x, int) else f"{len(str(abs(x)))}-digit integer"
    return text if len(text) <= 12 else f"{float(x):.6g}"


def describe(value: Any, limit: int = 60) -> str:
    """What was given, for a message: its type and a short form of it.

    Examples
    --------
    >>> describe(3), describe("x"), describe(None), describe(1e300)
    ('int 3', "str 'x'", 'None', 'float 1e+300')
    >>> describe(np.float64("inf")), describe([np.float64(1.5), np.int64(2)])
    ('float64 inf', 'list [1.5, 2]')
    """
    if value is None:
        return "None"
    if isinstance(value, bool):
        return f"bool {value}"
    if inspect.isclass(value):
        return f"the class {value.__name__}"
    kind = type(value).__name__
    if isinstance(value, numbers.Real) and not isinstance(value, np.ndarray):
        return f"{kind} {short_number(value)}"
    if isinstance(value, np.ndarray):
        return f"{kind} of shape {value.shape}"
    text = " ".join(repr(_plain(value)).split())
    text = text if len(text) <= limit else text[: limit - 3] + "..."
    return f"{kind} {text}"


def _plain(value: Any) -> Any:
    """Numpy scalars, within lists, tuples and dicts too, as the Python values they hold: numpy
    2 writes ``np.float64(inf)`` where a message should say ``inf``."""
    if isinstance(value, np.generic):
        return value.item()
    if type(value) in (list, tuple):
        return type(value)(_plain(v) for v in value)
    if type(value) is dict:
        return {_plain(k): _plain(v) for k, v in value.items()}
    return value


def fail(where: str, name: str, value: Any, want: str, *, kind: bool = True, hint: str = "") -> None:
    """Raise the one message: ``<where> argument <name> must be <want>, got <value>``."""
    text = f"{where} argument {name} must be {want}, got {describe(value)}"
    if inspect.isclass(value) and not hint:
        hint = f"give an object, e.g. {value.__name__}()"
    if hint:
        text += f"; {hint}"
    raise (ArgumentTypeError if kind else InputError)(text)


def _is_real(value: Any) -> bool:
    return isinstance(value, (numbers.Real, np.integer, np.floating)) and not isinstance(value, (bool, np.bool_))


def number(
    where: str,
    name: str,
    value: Any,
    check: str = "real",
    *,
    unit: str = "",
    optional: bool = False,
    infinite: bool = False,
) -> float | None:
    """A finite number (an int or a float, not a bool nor a string), as a float.

    Examples
    --------
    >>> number("fly()", "duration", 0, "pos", unit="s")
    Traceback (most recent call last):
        ...
    quadcruise.errors.InputError: fly() argument duration must be a positive number of seconds, got int 0
    """
    if value is None and optional:
        return None
    of = _UNITS.get(unit, f" [{unit}]" if unit else "")
    want = {"real": f"a finite number{of}", "pos": f"a positive number{of}", "nonneg": f"a number{of} >= 0"}[check]
    want += " (inf allowed)" * infinite + " or None" * optional
    if not _is_real(value) or (isinstance(value, np.ndarray) and value.ndim):
        fail(where, name, value, want)
    x = float(value)
    if (
        math.isnan(x)
        or (math.isinf(x) and not (infinite and x > 0))
        or (check == "pos" and x <= 0)
        or (check == "nonneg" and x < 0)
    ):
        fail(where, name, value, want, kind=False)
    return x


def whole(where: str, name: str, value: Any, minimum: int = 0, *, optional: bool = False) -> int | None:
    """A whole number >= ``minimum`` (an int or a numpy integer; not a bool, not a float).

    Examples
    --------
    >>> whole("fly()", "seed", True)
    Traceback (most recent call last):
        ...
    quadcruise.errors.ArgumentTypeError: fly() argument seed must be a whole number >= 0, got bool True
    """
    if value is None and optional:
        return None
    want = f"a whole number >= {minimum}" + (" or None" if optional else "")
    if isinstance(value, (bool, np.bool_)) or not isinstance(value, (numbers.Integral, np.integer)):
        fail(where, name, value, want)
    if value < minimum:
        fail(where, name, value, want, kind=False)
    return int(value)


def flag(where: str, name: str, value: Any) -> bool:
    """``True`` or ``False`` (a numpy bool too), nothing else: a string such as ``"no"`` is
    refused, not read as true.

    Examples
    --------
    >>> flag("fly()", "full_dynamics", "no")
    Traceback (most recent call last):
        ...
    quadcruise.errors.ArgumentTypeError: fly() argument full_dynamics must be True or False, got str 'no'
    """
    if not isinstance(value, (bool, np.bool_)):
        fail(where, name, value, "True or False")
    return bool(value)


def instance(
    where: str, name: str, value: Any, cls: type | tuple, *, optional: bool = True, want: str | None = None
) -> Any:
    """An object of ``cls`` (None too if ``optional``), returned as given.

    Examples
    --------
    >>> from quadcruise.model.vehicle import Vehicle
    >>> instance("fly()", "vehicle", 3, Vehicle)
    Traceback (most recent call last):
        ...
    quadcruise.errors.ArgumentTypeError: fly() argument vehicle must be a Vehicle or None, got int 3
    """
    if value is None and optional:
        return None
    if not isinstance(value, cls):
        classes = cls if isinstance(cls, tuple) else (cls,)
        want = want or " or ".join(f"a {c.__name__}" for c in classes)
        fail(where, name, value, want + (" or None" if optional else ""))
    return value


def callback(where: str, name: str, value: Any) -> Any:
    """None or a callable (a ``progress`` function), returned as given."""
    if value is not None and not callable(value):
        fail(where, name, value, "a callable or None")
    return value


def pair(where: str, name: str, value: Any, want: str, *, hint: str = "") -> tuple:
    """Two items (a tuple, a list or a 1-D array of two), as a tuple; the caller checks their values.

    Examples
    --------
    >>> pair("tune()", "bounds['kp']", np.array([0.5, 10.0]), "a pair (low, high)")
    (0.5, 10.0)
    >>> pair("tune()", "bounds['kp']", "0.5:10", "a pair (low, high)")
    Traceback (most recent call last):
        ...
    quadcruise.errors.ArgumentTypeError: tune() argument bounds['kp'] must be a pair (low, high), got str '0.5:10'
    """
    if isinstance(value, np.ndarray) and value.shape == (2,):
        return tuple(value.tolist())
    if not isinstance(value, (tuple, list)) or len(value) != 2:
        fail(where, name, value, want, hint=hint)
    return tuple(value)
