"""What a tuner searches: the gains, by name, and their bounds, and how a row of values
becomes a controller.

- A **gain** is named as ``quadcruise.fields.units()`` names it, ``position.kp`` or
  ``max_tilt``: any numeric field of the controller or of its nested gains. A PD gains field
  can also be searched by its pole pair through the design rule of
  :mod:`quadcruise.control.design` (s^2 + kd s + kp = s^2 + 2 zeta wn s + wn^2):
  ``position.wn`` [rad/s] and ``position.zeta`` [-]. Several gains are a list of names.
- **Bounds** ``Bounds("position.kp", 0.5, 10)``, or a mapping ``{"position.kp": (0.5, 10)}``;
  by default a decade either side of the controller's value, cut to the range the field
  allows (``max_tilt`` stays below pi/2; the damping ratio: [0.1, 2]). A gain whose bounds are
  positive and a decade or more apart is searched on a log scale.

The text forms of the command line (``--gains position.kp,position.kd``, ``--bounds
position.kp=0.5:10``) are read in :mod:`quadcruise.cli.criteria`.

Examples
--------
>>> from quadcruise.control import NLPD
>>> space = GainSpace.build(NLPD(), ["position.kp", "position.kd"], {"position.kp": (1, 10)})
>>> [(g.name, g.low, g.high, g.log) for g in space.gains]
[('position.kp', 1.0, 10.0, True), ('position.kd', 0.5, 50.0, True)]
>>> round(space.controllers([[2.0, 3.0]])[0].position.kd, 3)
3.0
"""

from __future__ import annotations

import dataclasses
import difflib
import math
from collections.abc import Iterable, Mapping, Sequence
from dataclasses import dataclass
from typing import Any

import numpy as np

from quadcruise import checks
from quadcruise.control.design import PDGains
from quadcruise.errors import InputError

__all__ = ["Bounds", "Gain", "GainSpace", "as_bounds", "as_gain_names", "tunable_values"]

POLE_NAMES = ("wn", "zeta")
"""The pole-pair parameters of a PD gains field: natural frequency [rad/s], damping ratio [-]."""
DEFAULT_SPAN = 10.0
"""Default bounds: the controller's value divided and multiplied by this."""
ZETA_BOUNDS = (0.1, 2.0)
"""Default bounds of a damping ratio."""


# --- gains ---------------------------------------------------------------------------------
@dataclass(frozen=True)
class Gain:
    """One searched gain and its bounds."""

    name: str
    low: float
    high: float
    log: bool
    unit: str

    def from_unit(self, u: np.ndarray) -> np.ndarray:
        """Values from positions in [0, 1] between the bounds (geometric on a log scale)."""
        u = np.asarray(u, dtype=float)
        if self.log:
            return np.exp(np.log(self.low) + u * (np.log(self.high) - np.log(self.low)))
        return self.low + u * (self.high - self.low)

    def to_unit(self, value: float) -> float:
        """The position in [0, 1] of a value between the bounds (:meth:`from_unit` inverted)."""
        if self.log:
            return (math.log(value) - math.log(self.low)) / (math.log(self.high) - math.log(self.low))
        return (value - self.low) / (self.high - self.low)


def _pole_pair(gains: PDGains) -> dict[str, float]:
    """wn and zeta of a PD pair: s^2 + kd s + kp = s^2 + 2 zeta wn s + wn^2."""
    wn = math.sqrt(gains.kp)
    return {"wn": wn, "zeta": gains.kd / (2.0 * wn)}


def tunable_values(controller: Any) -> dict[str, tuple[float, str]]:
    """Every numeric gain of a controller by name, with its value and unit.

    Examples
    --------
    >>> from quadcruise.control import NLPD
    >>> v = tunable_values(NLPD())
    >>> v["position.kd"], round(v["position.wn"][0], 3), "inversion" in v
    ((5.0, '1/s'), 1.735, False)
    """
    units = type(controller).units()
    out: dict[str, tuple[float, str]] = {}
    for f in dataclasses.fields(controller):
        value = getattr(controller, f.name)
        if isinstance(value, Mapping) and hasattr(value, "with_values"):  # px4's parameters, by PX4's names
            for key, inner in value.items():
                if _is_number(inner):
                    out[f"{f.name}.{key}"] = (float(inner), value.unit_of(key))
        elif dataclasses.is_dataclass(value):
            for g in dataclasses.fields(value):
                inner = getattr(value, g.name)
                if _is_number(inner):
                    out[f"{f.name}.{g.name}"] = (float(inner), units.get(f"{f.name}.{g.name}", "-"))
            if isinstance(value, PDGains):
                pair = _pole_pair(value)
                out[f"{f.name}.wn"] = (pair["wn"], "rad/s")
                out[f"{f.name}.zeta"] = (pair["zeta"], "-")
        elif _is_number(value):
            out[f.name] = (float(value), units.get(f.name, "-"))
    return out


def _is_number(value: Any) -> bool:
    return isinstance(value, (int, float, np.integer, np.floating)) and not isinstance(value, (bool, np.bool_))


def _within_range(base: Any, name: str, low: float, high: float) -> tuple[float, float]:
    """Default bounds cut to the range the gain's field allows (``fields.between``): a decade
    above ``max_tilt`` = 0.785 rad would be 7.85 rad, beyond its (0, pi/2). An open end is
    approached to a relative 1e-9, a closed one reached."""
    owner, _, leaf = name.rpartition(".")
    obj = getattr(base, owner) if owner else base
    if hasattr(obj, "bounds_of"):  # px4's parameters: PX4's range
        limits = obj.bounds_of(leaf)
    elif not dataclasses.is_dataclass(obj):
        return low, high
    else:
        check = next((f.metadata.get("check") for f in dataclasses.fields(obj) if f.name == leaf), None)
        limits = getattr(check, "bounds", None)
    if limits is None:
        return low, high
    lo, hi, closed = limits
    if low <= lo:
        low = lo if closed[0] == "[" else lo + 1e-9 * max(abs(lo), hi - lo)
    if high >= hi:
        high = hi if closed[1] == "]" else hi - 1e-9 * max(abs(hi), hi - lo)
    return low, high


@dataclass(frozen=True)
class Bounds:
    """The bounds of one searched gain, checked on construction.

    Parameters
    ----------
    gain : str
        The gain's name, ``position.kp``, ``max_tilt``, ``position.wn``, ...
    low, high : float
        Finite, low < high. Whether the controller accepts them is checked when the
        search is built (:meth:`GainSpace.build` builds a candidate at each corner).

    Raises
    ------
    ArgumentTypeError
        A field of the wrong type (a bound given as text).
    InputError
        A bound that is not finite, or bounds reversed or empty (low >= high).

    Examples
    --------
    >>> Bounds("position.kp", 10, 0.5)
    Traceback (most recent call last):
        ...
    quadcruise.errors.InputError: Bounds() argument high must be above low = 10, got float 0.5; bounds reversed or empty
    """

    gain: str
    low: float
    high: float

    def __post_init__(self) -> None:
        where = "Bounds()"
        if not isinstance(self.gain, str) or not self.gain:
            checks.fail(where, "gain", self.gain, "a gain's name, e.g. 'position.kp'")
        low = checks.number(where, "low", self.low)
        high = checks.number(where, "high", self.high)
        if not low < high:
            checks.fail(
                where, "high", self.high, f"above low = {self.low}", kind=False, hint="bounds reversed or empty"
            )
        object.__setattr__(self, "low", low)
        object.__setattr__(self, "high", high)


_BOUNDS = "Bounds objects or a mapping {gain: (low, high)}"


def as_bounds(value: Any, where: str, name: str = "bounds") -> dict[str, Bounds]:
    """A function's bounds argument as :class:`Bounds` by gain, a gain at most once.

    Examples
    --------
    >>> as_bounds({"position.kp": (0.5, 10)}, "tune()")
    {'position.kp': Bounds(gain='position.kp', low=0.5, high=10.0)}
    >>> as_bounds({"position.kp": (10, 0.5)}, "tune()")
    Traceback (most recent call last):
        ...
    quadcruise.errors.InputError: tune() argument bounds['position.kp'] must be a pair (low, high) with low < high, \
got tuple (10, 0.5); bounds reversed or empty
    """
    if value is None:
        return {}
    if isinstance(value, Bounds):
        return {value.gain: value}
    hint = "write {'position.kp': (0.5, 10)} or [Bounds('position.kp', 0.5, 10)]"
    if isinstance(value, str):
        checks.fail(where, name, value, _BOUNDS, hint=hint + "; text is read by the command line")
    if isinstance(value, Mapping):
        out = {}
        for gain, pair in value.items():
            item = f"{name}[{gain!r}]"
            if not isinstance(gain, str) or not gain:
                checks.fail(where, f"{name} key", gain, "a gain's name, e.g. 'position.kp'")
            pair = checks.pair(where, item, pair, "a pair (low, high)", hint=hint)
            low, high = checks.number(where, f"{item}[0]", pair[0]), checks.number(where, f"{item}[1]", pair[1])
            if not low < high:
                checks.fail(
                    where,
                    item,
                    tuple(pair),
                    "a pair (low, high) with low < high",
                    kind=False,
                    hint="bounds reversed or empty",
                )
            out[gain] = Bounds(gain, low, high)
        return out
    if not isinstance(value, Iterable):
        checks.fail(where, name, value, _BOUNDS)
    out = {}
    for k, item in enumerate(value):
        if not isinstance(item, Bounds):
            checks.fail(where, f"{name}[{k}]", item, "a Bounds", hint=hint)
        if item.gain in out:
            raise InputError(f"{where} argument {name} bounds {item.gain} twice; give its bounds once")
        out[item.gain] = item
    return out


def as_gain_names(value: Any, where: str, name: str = "gains") -> list[str]:
    """A function's gains argument as a list of names (not yet checked against a controller)."""
    if value is None:
        return []
    items = [value] if isinstance(value, str) else value
    if not isinstance(items, Iterable):
        checks.fail(where, name, value, "a gain's name or a list of them, e.g. ['position.kp', 'position.kd']")
    items = list(items)
    for k, item in enumerate(items):
        if not isinstance(item, str):
            checks.fail(where, f"{name}[{k}]", item, "a gain's name (str)")
    return items


@dataclass(frozen=True)
class GainSpace:
    """The searched gains of one controller: names, bounds, and how a row of values becomes
    a controller (``dataclasses.replace`` on the nested fields, validated as any controller).

    Parameters
    ----------
    base : Controller
        The controller whose other gains stay as they are.
    gains : tuple of Gain
        The searched gains, in order.
    derived : tuple of str
        Fields of ``base`` left at None (their default follows other fields, e.g. the
        baseline's saturation levels a_p = k_p x 1 m): a candidate derives them again.
    """

    base: Any
    gains: tuple
    derived: tuple = ()

    @classmethod
    def build(
        cls,
        base: Any,
        names: Sequence[str] | str | None = None,
        bounds: Mapping | Bounds | Iterable[Bounds] | None = None,
        *,
        where: str = "GainSpace.build()",
    ) -> GainSpace:
        """The space of ``names`` around ``base``, each within its bounds.

        Parameters
        ----------
        base : Controller
            A built-in controller (a frozen dataclass of validated fields).
        names : sequence of str or str, optional
            The gains (one name, or a list); ``position.kp, position.kd`` by default where the
            controller has them.
        bounds : mapping, Bounds or iterable of Bounds, optional
            :func:`as_bounds` input, ``{"position.kp": (0.5, 10)}``; by default a decade either
            side of each value, cut to the range its field allows (``max_tilt``: below pi/2).
        where : str
            The function the arguments were given to, for the messages.

        Returns
        -------
        GainSpace

        Raises
        ------
        ArgumentTypeError
            Names or bounds of the wrong type (text bounds, ``"position.kp=0.5:10"``, included).
        InputError
            An unknown gain (the message lists the tunable ones), a gain given twice, a gain
            both by its value and by its pole pair, bounds of a gain not searched, bounds
            reversed or empty, a value of 0 without bounds, or bounds the controller refuses
            (a candidate at each corner is built and validated).
        """
        if not dataclasses.is_dataclass(base) or not hasattr(type(base), "units"):
            raise InputError(f"a tuner needs a built-in controller (a dataclass of gains), got {type(base).__name__}")
        values = tunable_values(base)
        names = as_gain_names(names, where)
        given = as_bounds(bounds, where)
        if not names:
            if "position.kp" not in values:
                raise InputError(f"name the gains of {base.name} to tune (gains: {', '.join(values)})")
            names = ["position.kp", "position.kd"]
        for name in names:
            if name not in values:
                close = difflib.get_close_matches(name, list(values), n=1)
                hint = f" (did you mean '{close[0]}'?)" if close else ""
                if "," in name:
                    hint += f"; several gains are a list, e.g. {[n.strip() for n in name.split(',')]}"
                raise InputError(f"unknown gain {name!r} of {base.name}{hint}; gains: {', '.join(values)}")
        for k, name in enumerate(names):
            if name in names[:k]:
                raise InputError(f"gains: {name} is given twice")
        for name in names:
            owner, _, leaf = name.rpartition(".")
            if owner and leaf in POLE_NAMES and {f"{owner}.kp", f"{owner}.kd"} & set(names):
                raise InputError(f"gains: {owner} is searched both by its gains and by its poles ({name}); choose one")
        for name in given:
            if name not in names:
                raise InputError(f"bounds of {name!r}, which is not searched (gains: {', '.join(names)})")
        gains = []
        for name in names:
            value, unit = values[name]
            if name in given:
                low, high = given[name].low, given[name].high
            elif name.endswith(".zeta"):
                low, high = ZETA_BOUNDS
            elif value > 0:
                low, high = _within_range(base, name, value / DEFAULT_SPAN, value * DEFAULT_SPAN)
            else:
                raise InputError(f"{name} is {value:g}: give its bounds")
            gains.append(Gain(name, low, high, bool(low > 0 and high / low >= 10.0), unit))
        derived = tuple(
            f.name
            for f in dataclasses.fields(base)
            if f.default is None
            and getattr(dataclasses.replace(base, **{f.name: None}), f.name) == getattr(base, f.name)
        )
        space = cls(base, tuple(gains), derived)
        corners = np.array([[g.low for g in gains], [g.high for g in gains]])
        space.controllers(corners)  # the controller validates its gains: bad bounds fail here
        return space

    @property
    def names(self) -> list[str]:
        """The searched gains' names, in order."""
        return [g.name for g in self.gains]

    def start(self) -> np.ndarray | None:
        """The base controller's values, as positions in [0, 1], if they lie within the bounds.

        Returns
        -------
        ndarray or None
        """
        values = tunable_values(self.base)
        u = np.array([g.to_unit(values[g.name][0]) for g in self.gains])
        return u if np.all((u >= 0) & (u <= 1)) else None

    def values(self, unit: np.ndarray) -> np.ndarray:
        """Gains from positions in the unit cube.

        Parameters
        ----------
        unit : ndarray, shape (P, G)
            Positions in [0, 1].

        Returns
        -------
        ndarray, shape (P, G)
        """
        unit = np.atleast_2d(np.asarray(unit, dtype=float))
        return np.column_stack([g.from_unit(unit[:, k]) for k, g in enumerate(self.gains)])

    def controllers(self, values: np.ndarray) -> list:
        """One controller per row of gain values.

        Parameters
        ----------
        values : array_like, shape (P, G)
            The gains, in the order of :attr:`names`.

        Returns
        -------
        list of Controller
            ``base`` with those gains (``dataclasses.replace``, so each is validated).
        """
        out = []
        for row in np.atleast_2d(np.asarray(values, dtype=float)):
            top: dict[str, Any] = {f: None for f in self.derived}
            nested: dict[str, dict[str, float]] = {}
            for g, v in zip(self.gains, row, strict=False):
                owner, _, leaf = g.name.rpartition(".")
                if owner:
                    nested.setdefault(owner, {})[leaf] = float(v)
                else:
                    top[g.name] = float(v)
            for owner, changes in nested.items():
                inner = getattr(self.base, owner)
                if set(changes) & set(POLE_NAMES):
                    pair = {**_pole_pair(inner), **changes}
                    changes = {"kp": pair["wn"] ** 2, "kd": 2.0 * pair["zeta"] * pair["wn"]}
                top[owner] = (
                    inner.with_values(**changes)
                    if hasattr(inner, "with_values")
                    else dataclasses.replace(inner, **changes)
                )
            out.append(dataclasses.replace(self.base, **top))
        return out

    def describe(self, controller: Any) -> dict[str, float]:
        """The searched gains of a controller, by name.

        Parameters
        ----------
        controller : Controller
            Of the base's kind.

        Returns
        -------
        dict of str to float
        """
        values = tunable_values(controller)
        return {name: values[name][0] for name in self.names}
