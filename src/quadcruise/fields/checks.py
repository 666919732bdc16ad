"""The checks of a field's value: a :class:`Check` turns a value into its stored form (a number
as a float, a per-vehicle array as a read-only float copy, a pair as a tuple) or raises one
line naming the field and what was wrong.

The checks by name (:data:`CHECKS`): ``real`` (a finite number), ``pos`` (> 0), ``nonneg``
(>= 0), ``nonzero``, ``frac`` (in [0, 1]), ``sign`` (+1 or -1), ``whole`` (a whole number >= 0),
``flag`` (true or false), ``pair`` and ``vec`` (2 or 3 numbers); made to measure:
:func:`between` (a range, open or closed at each end), :func:`one_of`, :func:`vector`
(n numbers), :func:`instance_of` (an object of a class) and :class:`Check` itself (any
predicate). How a field declares its check: :mod:`quadcruise.fields.declaration`.

Examples
--------
>>> CHECKS["pos"]("circle field 'radius' (circle radius, m)", 2)
2.0
>>> CHECKS["pos"]("circle field 'radius' (circle radius, m)", 0)
Traceback (most recent call last):
    ...
quadcruise.errors.InputError: circle field 'radius' (circle radius, m) must be > 0, got 0.0
"""

from __future__ import annotations

import math
from collections.abc import Callable
from typing import Any

import numpy as np

from quadcruise.errors import ArgumentTypeError, InputError

__all__ = [
    "CHECKS",
    "Check",
    "between",
    "check_number",
    "check_value",
    "instance_of",
    "one_of",
    "vector",
]


class Check:
    """A rule for a field's value: calling it returns the value as it is stored, or raises a
    one-line InputError ``<label> must be <want>, got <value>``.

    The base class checks a predicate; the subclasses below check numbers, vectors, choices,
    classes and flags.

    Parameters
    ----------
    name : str
        A short name (``pos``, ``range``, ...), shown by ``repr``.
    want : str
        What a good value is, as the error message says it ("a compiled function").
    test : callable, optional
        ``test(value) -> bool``, True for a good value (the value is stored as given).

    Examples
    --------
    >>> compiled = Check("compiled", "a compiled function", lambda f: hasattr(f, "py_func"))
    >>> compiled("push field 'function' (its law, -)", print)
    Traceback (most recent call last):
        ...
    quadcruise.errors.InputError: push field 'function' (its law, -) must be a compiled function, got <built-in ...
    """

    def __init__(self, name: str, want: str, test: Callable[[Any], bool] | None = None) -> None:
        self.name, self.want, self.test = name, want, test

    def __repr__(self) -> str:
        return f"<check {self.name}: {self.want}>"

    def __call__(self, label: str, value: Any, *, batch: bool = False, optional: bool = False) -> Any:
        """``value`` as stored (None passes if ``optional``); InputError naming ``label`` if it is bad."""
        if value is None and optional:
            return None
        return self.convert(_Site(label, batch, optional), value)

    def convert(self, site: _Site, value: Any) -> Any:
        """The stored form of a value that is not an allowed None (subclasses override).

        Parameters
        ----------
        site : _Site
            Where the value is (owner, field, meaning, unit), for the error message.
        value : Any
            The value given.

        Returns
        -------
        Any
            The value as stored.
        """
        if self.test is None or not self.test(value):
            site.fail(self.want, repr(value))
        return value


class _Site:
    """Where a value is checked: the field's label and what it allows; builds the message."""

    def __init__(self, label: str, batch: bool, optional: bool) -> None:
        self.label, self.batch, self.optional = label, batch, optional

    def fail(self, want: str, got: str, wrong_type: bool = False) -> None:
        """Raise the message; an ArgumentTypeError (a TypeError too) for a value of the wrong kind."""
        error = ArgumentTypeError if wrong_type else InputError
        raise error(f"{self.label} must be {want}{' or None' if self.optional else ''}, got {_short(got)}")


def _short(text: str, limit: int = 120) -> str:
    """``text`` on one line (an array's repr spans several) and at most ``limit`` characters."""
    text = " ".join(text.split())
    return text if len(text) <= limit else text[: limit - 3] + "..."


def is_number(value: Any) -> bool:
    """A real number: an int or a float of Python or numpy, not a bool."""
    return not isinstance(value, (bool, np.bool_)) and isinstance(value, (int, float, np.integer, np.floating))


class _Number(Check):
    """A finite number (or, for a batched field, a 1-D array of them) that ``refuse`` does not
    refuse (``refuse(a)`` is True where a value is bad, elementwise); stored as ``cast`` of it,
    a batch as a read-only float array."""

    def __init__(self, name: str, want: str, refuse: Callable | None = None, cast: type = float) -> None:
        super().__init__(name, want)
        self.refuse, self.cast = refuse, cast

    def convert(self, site: _Site, value: Any) -> Any:
        if isinstance(value, np.ndarray) and value.ndim == 0:
            value = value[()]
        if site.batch and isinstance(value, (list, tuple, np.ndarray)):
            return self._array(site, value)
        if not is_number(value):
            site.fail("a number or a 1-D array of numbers" if site.batch else "a number", repr(value), True)
        x = float(value)
        if not math.isfinite(x):
            site.fail("finite", repr(x))
        if self.refuse is not None and self.refuse(x):
            site.fail(self.want, repr(x))
        return self.cast(x)

    def _array(self, site: _Site, value: Any) -> np.ndarray:
        try:
            arr = np.array(value)
        except (TypeError, ValueError):
            arr = np.zeros((0, 0))
        if arr.ndim != 1 or arr.size == 0 or arr.dtype.kind not in "iuf":
            site.fail("a number or a 1-D array of numbers", repr(value), True)
        arr = arr.astype(float)
        for bad, want in (
            (~np.isfinite(arr), "finite"),
            (self.refuse(arr) if self.refuse is not None else None, self.want),
        ):
            if bad is not None and np.any(bad):
                k = int(np.argmax(bad))
                site.fail(want, f"{float(arr[k])!r} (entry {k} of {arr.size})")
        arr.flags.writeable = False
        return arr


class _Vector(Check):
    """``n`` numbers, stored as a tuple; for a batched field each may be a 1-D array, or the
    whole an (N, n) array."""

    def __init__(self, n: int, element: _Number) -> None:
        names = {2: "pair", 3: "vec"}
        super().__init__(
            names.get(n, f"vec{n}"), "a pair of numbers" if n == 2 else f"{n} numbers" + " (x, y, z)" * (n == 3)
        )
        self.n, self.element = n, element

    def convert(self, site: _Site, value: Any) -> tuple:
        n = self.n
        if site.batch and isinstance(value, np.ndarray) and value.ndim == 2 and value.shape[1] == n:
            value = tuple(value.T)
        if (
            isinstance(value, (str, bytes))
            or not hasattr(value, "__len__")
            or (isinstance(value, np.ndarray) and value.ndim != 1)
            or len(value) != n
        ):
            want = self.want + (f", each a number or a 1-D array, or an (N, {n}) array" if site.batch else "")
            site.fail(want, repr(value), True)
        return tuple(self.element.convert(site, v) for v in value)


class _OneOf(Check):
    def __init__(self, options: tuple) -> None:
        super().__init__("choice", "one of " + ", ".join(map(str, options)))
        self.options = tuple(options)

    def convert(self, site: _Site, value: Any) -> Any:
        if not isinstance(value, np.ndarray):
            for option in self.options:  # the option itself: 'x', not np.str_('x')
                if isinstance(value, type(option)) and value == option:
                    return option
        site.fail(self.want, repr(value))


class _InstanceOf(Check):
    def __init__(self, cls: type) -> None:
        super().__init__("instance", f"a {cls.__name__}")
        self.cls = cls

    def convert(self, site: _Site, value: Any) -> Any:
        if not isinstance(value, self.cls):
            site.fail(self.want, repr(value), True)
        return value


class _Flag(Check):
    def convert(self, site: _Site, value: Any) -> bool:
        if isinstance(value, (bool, np.bool_)) or (is_number(value) and value in (0, 1)):
            return bool(value)
        site.fail(self.want, repr(value), not is_number(value))


def between(low: float, high: float, closed: str = "[]", *, whole: bool = False, text: str | None = None) -> Check:
    """A number in a range: ``closed`` is "[]", "[)", "(]" or "()" (closed or open at each end).

    Parameters
    ----------
    low, high : float
        The ends of the range.
    closed : str
        Which ends belong to it.
    whole : bool
        Also a whole number (stored as a float all the same).
    text : str, optional
        How the message writes the range, e.g. "(0, pi/2)" (default from the numbers).

    Returns
    -------
    Check
        With ``bounds``: ``(low, high, closed)``.

    Examples
    --------
    >>> between(0.0, 1.0, "[)")("cascade parameter 'thrust_min' (least thrust, -)", 1.0)
    Traceback (most recent call last):
        ...
    quadcruise.errors.InputError: cascade parameter 'thrust_min' (least thrust, -) must be in [0, 1), got 1.0
    >>> between(1, 4, whole=True)("loss field 'rotor' (rotor number, -)", 3)
    3.0
    """
    if closed not in ("[]", "[)", "(]", "()"):
        raise ValueError(f"closed must be one of [], [), (], (), got {closed!r}")
    lo_in, hi_in = closed[0] == "[", closed[1] == "]"
    want = f"{'a whole number ' if whole else ''}in {text or f'{closed[0]}{low:g}, {high:g}{closed[1]}'}"

    def refuse(a):
        out = ((a < low) if lo_in else (a <= low)) | ((a > high) if hi_in else (a >= high))
        return out | (a != np.floor(a)) if whole else out

    check = _Number("range", want, refuse)
    check.bounds = (float(low), float(high), closed)  # for callers that search within the range
    return check


def one_of(*options: Any) -> Check:
    """One of ``options`` (compared by type and value), stored as given.

    Parameters
    ----------
    *options : Any
        The allowed values.

    Returns
    -------
    Check

    Examples
    --------
    >>> one_of("linear", "hold")("waypoints field 'yaw_mode' (yaw over a leg, -)", "spin")
    Traceback (most recent call last):
        ...
    quadcruise.errors.InputError: waypoints field 'yaw_mode' (yaw over a leg, -) must be one of linear, hold, got 'spin'
    """
    return _OneOf(options)


def vector(n: int, element: str = "real") -> Check:
    """``n`` numbers, each passing the named number check ``element``; stored as a tuple.

    Parameters
    ----------
    n : int
        How many.
    element : str
        The check of each (a numeric check of :data:`CHECKS`: ``real``, ``pos``, ...).

    Returns
    -------
    Check

    Examples
    --------
    >>> vector(2)("circle field 'center' (centre (x, y), m)", [1, 2])
    (1.0, 2.0)
    """
    return _Vector(n, CHECKS[element])


def instance_of(cls: type) -> Check:
    """An object of class ``cls`` (its own class validates it), stored as given. A field
    checked so, whose class has ``units()``, lists the units of its fields as ``<field>.<name>``.

    Parameters
    ----------
    cls : type
        The class.

    Returns
    -------
    Check

    Examples
    --------
    >>> instance_of(tuple)("nlpd parameter 'position' (x and y loops, -)", [3.01, 5.0])
    Traceback (most recent call last):
        ...
    quadcruise.errors.ArgumentTypeError: nlpd parameter 'position' (x and y loops, -) must be a tuple, got [3.01, 5.0]
    """
    return _InstanceOf(cls)


CHECKS: dict[str, Check] = {
    c.name: c
    for c in (
        _Number("real", "finite"),
        _Number("pos", "> 0", lambda a: a <= 0),
        _Number("nonneg", ">= 0", lambda a: a < 0),
        _Number("nonzero", "nonzero", lambda a: a == 0),
        _Number("frac", "in [0, 1]", lambda a: (a < 0) | (a > 1)),
        _Number("sign", "+1 or -1", lambda a: (a != 1) & (a != -1), cast=int),
        _Number("whole", "a whole number >= 0", lambda a: (a < 0) | (a != np.floor(a)), cast=int),
        _Flag("flag", "true or false"),
    )
}
"""The checks by name (``choice`` is made from a field's ``choices``)."""
CHECKS["pair"], CHECKS["vec"] = _Vector(2, CHECKS["real"]), _Vector(3, CHECKS["real"])


def check_value(label: str, value: Any, check: str | Check = "real", **kw: Any) -> Any:
    """One value checked as a field would be: for a function's argument.

    Parameters
    ----------
    label : str
        How the message names it, e.g. ``"rate_pid_design argument 'actuator_bandwidth'
        (rotor lag bandwidth, rad/s)"``.
    value : Any
        The value.
    check : str or Check
        A name of :data:`CHECKS` or a Check.
    **kw
        ``batch``, ``optional``: as for :func:`unit_field`.

    Returns
    -------
    Any
        The value as stored (a number as a float).

    Examples
    --------
    >>> check_value("design argument 'bandwidth' (rotor lag, rad/s)", 15, "pos")
    15.0
    """
    return (CHECKS[check] if isinstance(check, str) else check)(label, value, **kw)


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
    quadcruise.errors.ArgumentTypeError: circle field 'radius' must be a number, got '2'
    """
    return check_value(label, value, "real")
