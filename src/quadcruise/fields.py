"""Fields with units: one declaration and one validation for every parameter object of the
package (the vehicle, the missions, the disturbance parts, the controllers and their gains),
and one parser for ``KEY=VALUE`` options (:func:`parse_assignments`).

A field is declared with :func:`unit_field`: its default, its unit [SI], what it means, and a
:class:`Check`. A frozen dataclass that derives from :class:`Validated` runs :func:`validate`
when it is made: each value is checked and stored in its one form (a number as a float, a
per-vehicle array as a read-only float copy, a pair as a tuple), and a bad one raises a
one-line :class:`~quadcruise.errors.InputError` naming the owner, the field, its meaning and
unit, and what was wrong, e.g.
``circle field 'radius' (circle radius, m) must be > 0, got 0.0``.

The checks by name: ``real`` (a finite number), ``pos`` (> 0), ``nonneg`` (>= 0), ``nonzero``, ``frac``
(in [0, 1]), ``sign`` (+1 or -1), ``whole`` (a whole number >= 0), ``flag`` (true or false),
``pair`` and ``vec`` (2 or 3 numbers), ``choice`` (one of the field's ``choices``); and made
to measure: :func:`between` (a range, open or closed at each end), :func:`one_of`,
:func:`vector` (n numbers), :func:`instance_of` (an object of a class) and :class:`Check`
itself (any predicate). ``batch=True`` lets a numeric field hold one value per vehicle
(a 1-D array); ``optional=True`` (the default when the default is None) lets it be None.

Examples
--------
>>> from dataclasses import dataclass
>>> @dataclass(frozen=True)
... class Spring(Validated):
...     name = "spring"
...     stiffness: float = unit_field(100.0, "N/m", "spring rate", "pos")
...     preload: float = unit_field(0.0, "N", "force at rest", "nonneg", batch=True)
>>> Spring(preload=[1, 2]).preload
array([1., 2.])
>>> Spring.units()
{'stiffness': 'N/m', 'preload': 'N'}
>>> Spring(stiffness=-1)
Traceback (most recent call last):
    ...
quadcruise.errors.InputError: spring field 'stiffness' (spring rate, N/m) must be > 0, got -1.0
>>> parse_assignments(["radius=3", "center=1,2", "axis=x"], "--mission-param")
{'radius': 3, 'center': (1, 2), 'axis': 'x'}
"""

from __future__ import annotations

import dataclasses
import difflib
import math
import re
from collections.abc import Callable, Iterable, Mapping
from typing import Any, ClassVar

import numpy as np

from quadcruise.errors import ArgumentTypeError, InputError

__all__ = [
    "CHECKS",
    "Check",
    "Validated",
    "between",
    "check_number",
    "check_value",
    "instance_of",
    "one_of",
    "parse_assignments",
    "parse_numbers",
    "unit_field",
    "units_of",
    "validate",
    "vector",
]


# --- checks --------------------------------------------------------------------------------
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


def _is_number(value: Any) -> bool:
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
        if not _is_number(value):
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
        if isinstance(value, (bool, np.bool_)) or (_is_number(value) and value in (0, 1)):
            return bool(value)
        site.fail(self.want, repr(value), not _is_number(value))


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


# --- declaration and validation --------------------------------------------------------------
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
        check = _OneOf(tuple(choices))
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


# --- KEY=VALUE options -----------------------------------------------------------------------
_INT = re.compile(r"[+-]?\d+")


def parse_numbers(text: str, what: str, count: int | None = None) -> list[float]:
    """Comma-separated numbers, e.g. ``"2,0,0"``.

    Parameters
    ----------
    text : str
        The numbers.
    what : str
        What they are, for messages (``"AX,AY,AZ"``).
    count : int, optional
        How many there must be.

    Returns
    -------
    list of float

    Examples
    --------
    >>> parse_numbers("2, 0,0", "AX,AY,AZ", 3)
    [2.0, 0.0, 0.0]
    >>> parse_numbers("2,0", "AX,AY,AZ", 3)
    Traceback (most recent call last):
        ...
    quadcruise.errors.InputError: needs 3 values AX,AY,AZ, got '2,0'
    """
    pieces = str(text).split(",")
    if count is not None and len(pieces) != count:
        raise InputError(f"needs {count} value{'s' * (count > 1)} {what}, got {text!r}")
    try:
        return [float(p) for p in pieces]
    except ValueError:
        raise InputError(f"{what} must be numbers, got {text!r}") from None


def _value(raw: str) -> Any:
    """A number (int if written as one), true/false, or the word itself."""
    word = raw.strip()
    if _INT.fullmatch(word):
        return int(word)
    if word.lower() in ("true", "false"):
        return word.lower() == "true"
    try:
        return float(word)
    except ValueError:
        return word


def parse_assignments(
    items: str | Iterable[str], what: str, keys: Iterable[str] | Mapping[str, str] | None = None, numbers: bool = False
) -> dict[str, Any]:
    """``KEY=VALUE`` options as a dict: the one parser of the command line's options.

    Items are separated by commas, or given as several strings; a comma-separated piece
    without ``=`` continues the value before it, so ``center=1,2`` is a pair. A value is an
    int (written as one), a float, true/false, a tuple of numbers (``1,2``) or else the
    text itself. Later items win.

    Parameters
    ----------
    items : str or iterable of str
        ``"position=0.01,delay=0.002"`` or ``("radius=3", "center=1,2")``.
    what : str
        The option, for messages (``"--mission-param"``, ``"noise spec"``).
    keys : iterable of str or mapping, optional
        The allowed keys (matched ignoring case); a mapping also renames them
        (``{"position": "position_std"}``). None: any key.
    numbers : bool
        Every value must be a number or numbers.

    Returns
    -------
    dict

    Raises
    ------
    InputError
        One line naming the option and the bad item: no ``=``, no key or value, an unknown
        key, or (with ``numbers``) a value that is not a number.

    Examples
    --------
    >>> parse_assignments("position=0.01,delay=2e-3", "noise spec", keys={"position": "position_std",
    ...                   "delay": "delay"}, numbers=True)
    {'position_std': 0.01, 'delay': 0.002}
    >>> parse_assignments(["accel_feedforward=true", "max_tilt=0.5"], "-c")
    {'accel_feedforward': True, 'max_tilt': 0.5}
    >>> parse_assignments("jitter=1", "noise spec", keys=["position", "delay"])
    Traceback (most recent call last):
        ...
    quadcruise.errors.InputError: noise spec 'jitter=1': unknown key 'jitter'; keys: position, delay
    """
    texts = [items] if isinstance(items, str) else list(items)
    rename = None if keys is None else (dict(keys) if isinstance(keys, Mapping) else {k: k for k in keys})
    lower = None if rename is None else {k.lower(): v for k, v in rename.items()}
    pairs: list[list] = []  # [key, [raw pieces], item as written]
    for text in texts:
        current = None  # the pair a piece without "=" continues
        for piece in str(text).split(","):
            key, sep, raw = piece.partition("=")
            if sep:
                current = [key.strip(), [raw], piece.strip()]
                pairs.append(current)
            elif current is not None:
                current[1].append(piece)
                current[2] += "," + piece.strip()
            else:
                raise InputError(f"{what} {piece.strip()!r}: expected KEY=VALUE")
    out: dict[str, Any] = {}
    for key, raws, item in pairs:
        if not key or not all(r.strip() for r in raws):
            raise InputError(f"{what} {item!r}: expected KEY=VALUE")
        if lower is not None:
            if key.lower() not in lower:
                close = difflib.get_close_matches(key.lower(), list(lower), n=1)
                hint = f" (did you mean '{close[0]}'?)" if close else ""
                raise InputError(f"{what} {item!r}: unknown key {key!r}{hint}; keys: {', '.join(rename)}")
            key = lower[key.lower()]
        if key in out:
            raise InputError(f"{what} {item!r}: {key!r} is given twice; give each key once")
        values = [_value(r) for r in raws]
        numeric = all(_is_number(v) for v in values)
        if numbers and not numeric:
            raise InputError(f"{what} {item!r}: the value must be a number, got {','.join(r.strip() for r in raws)!r}")
        if len(values) == 1:
            out[key] = values[0]
        else:
            out[key] = tuple(values) if numeric else ",".join(r.strip() for r in raws)
    return out
