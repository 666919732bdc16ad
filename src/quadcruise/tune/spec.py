"""What a tuner is told: the gains to search and their bounds, the targets to reach, the
requirements to meet and the metrics to minimise, each parsed from text and checked before
any flight.

- A **gain** is named as ``quadcruise.fields.units()`` names it, ``position.kp`` or
  ``max_tilt``: any numeric field of the controller or of its nested gains. A PD gains field
  can also be searched by its pole pair through the design rule of
  :mod:`quadcruise.control.design` (s^2 + kd s + kp = s^2 + 2 zeta wn s + wn^2):
  ``position.wn`` [rad/s] and ``position.zeta`` [-].
- **Bounds** ``NAME=LOW:HIGH``; by default a decade either side of the controller's value, cut
  to the range the field allows (``max_tilt`` stays below pi/2; the damping ratio: [0.1, 2]). A gain whose bounds are
  positive and a decade or more apart
  is searched on a log scale.
- A **target** ``METRIC=VALUE`` or ``METRIC=VALUE+-TOLERANCE``: the cost counts the miss in
  tolerances, squared; without a tolerance, 10 % of the value (1 in the metric's unit for a
  target of 0). A target is *met* within its tolerance.
- A **requirement** ``METRIC<=VALUE`` (``<``, ``>=``, ``>``), the Monte Carlo sweep's own
  (:mod:`quadcruise.montecarlo.requirements`): a candidate that misses it ranks behind every
  candidate that meets all of them.
- **minimize** ``METRIC``: the metric's value, in its unit, is added to the cost.

The metrics are the columns of a Monte Carlo table
(:data:`quadcruise.montecarlo.schema.METRICS`), measured the same way.

Examples
--------
>>> Target.parse("overshoot_pct=4+-1.5")
Target(metric='overshoot_pct', value=4.0, tolerance=1.5)
>>> Requirement.parse("overshoot_pct <= 5").text
'overshoot_pct<=5'
>>> from quadcruise.control import NLPD
>>> space = GainSpace.build(NLPD(), ["position.kp", "position.kd"], {"position.kp": "1:10"})
>>> [(g.name, g.low, g.high, g.log) for g in space.gains]
[('position.kp', 1.0, 10.0, True), ('position.kd', 0.5, 50.0, True)]
>>> round(space.controllers([[2.0, 3.0]])[0].position.kd, 3)
3.0
"""

from __future__ import annotations

import dataclasses
import difflib
import math
import re
from collections.abc import Iterable, Mapping, Sequence
from dataclasses import dataclass
from typing import Any

import numpy as np

from quadcruise.control.design import PDGains
from quadcruise.errors import InputError
from quadcruise.montecarlo.requirements import Requirement, parse_requirements
from quadcruise.montecarlo.schema import METRICS

__all__ = [
    "Gain",
    "GainSpace",
    "Requirement",
    "Target",
    "check_metric",
    "parse_bounds",
    "parse_minimize",
    "parse_requirements",
    "parse_targets",
    "violation",
]

POLE_NAMES = ("wn", "zeta")
"""The pole-pair parameters of a PD gains field: natural frequency [rad/s], damping ratio [-]."""
DEFAULT_SPAN = 10.0
"""Default bounds: the controller's value divided and multiplied by this."""
ZETA_BOUNDS = (0.1, 2.0)
"""Default bounds of a damping ratio."""


def check_metric(name: str, what: str) -> str:
    """A metric's name, checked against the table's metrics.

    Parameters
    ----------
    name : str
        The metric, e.g. ``"rise_time_s"``.
    what : str
        Where it was given, for the message (``"target 'rise=1'"``).

    Returns
    -------
    str
        ``name``.

    Raises
    ------
    InputError
        One line naming the closest metric and the choices.

    Examples
    --------
    >>> check_metric("rise_time", "target 'rise_time=1'")          # doctest: +ELLIPSIS
    Traceback (most recent call last):
        ...
    quadcruise.errors.InputError: target 'rise_time=1': unknown metric 'rise_time' (did you mean ...
    """
    if name not in METRICS:
        close = difflib.get_close_matches(name, METRICS, n=1)
        hint = f" (did you mean '{close[0]}'?)" if close else ""
        raise InputError(f"{what}: unknown metric {name!r}{hint}; metrics: {', '.join(METRICS)}")
    return name


def _number(text: str, what: str) -> float:
    try:
        value = float(text)
    except (TypeError, ValueError):
        value = math.nan
    if not math.isfinite(value):
        raise InputError(f"{what}: {str(text).strip()!r} is not a finite number")
    return value


# --- targets, requirements, minimised metrics -------------------------------------------------
_TARGET = re.compile(r"^\s*([A-Za-z_][A-Za-z0-9_]*)\s*=\s*([^=]+?)\s*(?:(?:\+-|±|\+/-)\s*([^=]+?))?\s*$")


@dataclass(frozen=True)
class Target:
    """A value a metric should reach: the cost counts the miss in tolerances, squared.

    Parameters
    ----------
    metric : str
        A metric of :data:`~quadcruise.montecarlo.schema.METRICS`.
    value : float
        The value wanted, in the metric's unit (>= 0: every metric is).
    tolerance : float
        How far from ``value`` still meets the target (> 0).
    """

    metric: str
    value: float
    tolerance: float

    @classmethod
    def parse(cls, text: str) -> Target:
        """A target from ``METRIC=VALUE`` or ``METRIC=VALUE+-TOLERANCE``.

        Parameters
        ----------
        text : str
            E.g. ``"rise_time_s=1"``, ``"overshoot_pct=4+-1.5"``.

        Returns
        -------
        Target
            The tolerance 10 % of the value if not given (1 for a value of 0).

        Raises
        ------
        InputError
            Not of that form, an unknown metric, a value no metric has (negative), a
            tolerance that is not positive.
        """
        if isinstance(text, Target):
            return text
        match = _TARGET.match(str(text))
        what = f"target {str(text).strip()!r}"
        if match is None:
            raise InputError(f"{what}: expected METRIC=VALUE or METRIC=VALUE+-TOLERANCE, e.g. rise_time_s=1")
        metric = check_metric(match.group(1), what)
        value = _number(match.group(2), what)
        if value < 0:
            raise InputError(f"{what}: no metric is negative; {metric} is >= 0")
        tol = _number(match.group(3), what) if match.group(3) else (0.1 * value if value > 0 else 1.0)
        if tol <= 0:
            raise InputError(f"{what}: the tolerance must be > 0")
        return cls(metric, value, tol)

    @property
    def text(self) -> str:
        """``METRIC=VALUE+-TOLERANCE``."""
        return f"{self.metric}={self.value:g}+-{self.tolerance:g}"

    def cost(self, values: np.ndarray) -> np.ndarray:
        """The miss in tolerances, squared.

        Parameters
        ----------
        values : ndarray
            Values of the metric.

        Returns
        -------
        ndarray
            ((values - value) / tolerance)^2, NaN where a value is NaN.
        """
        return ((np.asarray(values, dtype=float) - self.value) / self.tolerance) ** 2

    def met(self, values) -> np.ndarray:
        """Which values are within the tolerance.

        Parameters
        ----------
        values : array_like
            Values of the metric.

        Returns
        -------
        ndarray of bool
            False where a value is NaN.
        """
        v = np.asarray(values, dtype=float)
        with np.errstate(invalid="ignore"):
            return np.abs(v - self.value) <= self.tolerance * (1 + 1e-12)


def violation(requirement: Requirement, values) -> np.ndarray:
    """How far each value is on the wrong side of a requirement's bound, in the metric's unit.

    Parameters
    ----------
    requirement : Requirement
        A Monte Carlo requirement (:class:`quadcruise.montecarlo.requirements.Requirement`).
    values : array_like
        Values of its metric.

    Returns
    -------
    ndarray
        0 where the value is on the right side (and at the bound of a strict comparison).

    Examples
    --------
    >>> violation(Requirement.parse("overshoot_pct<=5"), [3.0, 7.5]).tolist()
    [0.0, 2.5]
    """
    v = np.asarray(values, dtype=float)
    gap = v - requirement.value if requirement.op in ("<=", "<") else requirement.value - v
    return np.maximum(gap, 0.0)


def parse_targets(texts: str | Iterable | None) -> tuple[Target, ...]:
    """Targets from their texts (see :meth:`Target.parse`); a metric at most once.

    Parameters
    ----------
    texts : str, Target, or an iterable of them, or None

    Returns
    -------
    tuple of Target

    Raises
    ------
    InputError
        A bad target, or two targets on one metric.
    """
    out = tuple(Target.parse(t) for t in _items(texts))
    _once([t.metric for t in out], "target")
    return out


def parse_minimize(names: str | Iterable[str] | None) -> tuple[str, ...]:
    """The metrics to minimise, each checked; a metric at most once.

    Parameters
    ----------
    names : str or iterable of str or None
        Metric names (a string may hold several, comma-separated).

    Returns
    -------
    tuple of str
    """
    out = []
    for item in _items(names):
        found = [check_metric(n.strip(), f"minimize {n.strip()!r}") for n in str(item).split(",") if n.strip()]
        if not found:
            raise InputError(f"minimize {str(item)!r}: expected a metric, e.g. rmse_m; metrics: {', '.join(METRICS)}")
        out += found
    _once(out, "minimize")
    return tuple(out)


def _items(texts) -> list:
    if texts is None:
        return []
    if isinstance(texts, (str, Target)):
        return [texts]
    return list(texts)


def _once(metrics: list[str], what: str) -> None:
    seen = set()
    for m in metrics:
        if m in seen:
            raise InputError(f"{what}: {m} is given twice")
        seen.add(m)


# --- gains ---------------------------------------------------------------------------------
@dataclass(frozen=True)
class Gain:
    """One searched gain and its bounds.

    Parameters
    ----------
    name : str
        ``position.kp``, ``max_tilt``, ``position.wn``, ...
    low, high : float
        Its bounds (low < high).
    log : bool
        Searched on a log scale (bounds positive and a decade or more apart).
    unit : str
        Its unit.
    """

    name: str
    low: float
    high: float
    log: bool
    unit: str

    def from_unit(self, u: np.ndarray) -> np.ndarray:
        """Values from positions in [0, 1] between the bounds (geometric on a log scale).

        Parameters
        ----------
        u : ndarray
            Positions in [0, 1].

        Returns
        -------
        ndarray
            The gain's values.
        """
        u = np.asarray(u, dtype=float)
        if self.log:
            return np.exp(np.log(self.low) + u * (np.log(self.high) - np.log(self.low)))
        return self.low + u * (self.high - self.low)

    def to_unit(self, value: float) -> float:
        """The position in [0, 1] of a value between the bounds (:meth:`from_unit` inverted).

        Parameters
        ----------
        value : float
            The gain's value.

        Returns
        -------
        float
        """
        if self.log:
            return (math.log(value) - math.log(self.low)) / (math.log(self.high) - math.log(self.low))
        return (value - self.low) / (self.high - self.low)


def _pole_pair(gains: PDGains) -> dict[str, float]:
    """wn and zeta of a PD pair: s^2 + kd s + kp = s^2 + 2 zeta wn s + wn^2."""
    wn = math.sqrt(gains.kp)
    return {"wn": wn, "zeta": gains.kd / (2.0 * wn)}


def tunable_values(controller: Any) -> dict[str, tuple[float, str]]:
    """Every numeric gain of a controller by name, with its value and unit.

    Parameters
    ----------
    controller : Controller
        A frozen dataclass with ``units()`` (:class:`quadcruise.fields.Validated`).

    Returns
    -------
    dict of str to (float, str)
        ``position.kp`` -> (3.01, '1/s^2'), ...; also ``<field>.wn`` and ``<field>.zeta`` of
        every PD gains field. Flags and choices are left out.

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
        if dataclasses.is_dataclass(value):
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
    if not dataclasses.is_dataclass(obj):
        return low, high
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


def parse_bounds(items: str | Iterable[str] | Mapping | None) -> dict[str, tuple[float, float]]:
    """Bounds from ``NAME=LOW:HIGH`` texts (or a mapping of name to a pair or such a text).

    Parameters
    ----------
    items : str, iterable of str, mapping, or None
        ``"position.kp=0.5:10"``; several comma-separated or as a list.

    Returns
    -------
    dict of str to (float, float)

    Raises
    ------
    InputError
        Not of that form, not numbers, or bounds reversed or empty (LOW >= HIGH).

    Examples
    --------
    >>> parse_bounds("position.kp=0.5:10,position.kd=1:8")
    {'position.kp': (0.5, 10.0), 'position.kd': (1.0, 8.0)}
    >>> parse_bounds("position.kp=10:0.5")
    Traceback (most recent call last):
        ...
    quadcruise.errors.InputError: bounds 'position.kp=10:0.5' are reversed or empty: LOW must be below HIGH
    """
    if items is None:
        return {}
    if isinstance(items, Mapping):
        pairs = [(str(k), v) for k, v in items.items()]
    else:
        pairs = []
        for text in [items] if isinstance(items, str) else list(items):
            pieces = [piece for piece in str(text).split(",") if piece.strip()]
            if not pieces:
                raise InputError(f"bounds {str(text)!r}: expected NAME=LOW:HIGH, e.g. position.kp=0.5:10")
            for piece in pieces:
                name, sep, span = piece.partition("=")
                if not sep or not name.strip():
                    raise InputError(f"bounds {piece.strip()!r}: expected NAME=LOW:HIGH, e.g. position.kp=0.5:10")
                pairs.append((name.strip(), span.strip()))
    out: dict[str, tuple[float, float]] = {}
    for name, span in pairs:
        what = f"bounds '{name}={span}'" if isinstance(span, str) else f"bounds of {name}"
        if isinstance(span, str):
            low_text, sep, high_text = span.partition(":")
            if not sep:
                raise InputError(f"{what}: expected NAME=LOW:HIGH, e.g. position.kp=0.5:10")
            low, high = _number(low_text, what), _number(high_text, what)
        else:
            try:
                low, high = (float(v) for v in span)
            except (TypeError, ValueError):
                raise InputError(f"{what}: expected a pair (low, high)") from None
            _number(low, what), _number(high, what)
        if not low < high:
            raise InputError(f"{what} are reversed or empty: LOW must be below HIGH")
        if name.strip() in out:
            raise InputError(f"{what}: {name.strip()} is bounded twice; give its bounds once")
        out[name.strip()] = (low, high)
    return out


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
        cls, base: Any, names: Sequence[str] | str | None = None, bounds: Mapping | str | Iterable[str] | None = None
    ) -> GainSpace:
        """The space of ``names`` around ``base``, each within its bounds.

        Parameters
        ----------
        base : Controller
            A built-in controller (a frozen dataclass of validated fields).
        names : sequence of str or str, optional
            The gains (comma-separated in a string); ``position.kp, position.kd`` by default
            where the controller has them.
        bounds : mapping or str or iterable of str, optional
            :func:`parse_bounds` input; by default a decade either side of each value, cut to
            the range its field allows (``max_tilt``: below pi/2).

        Returns
        -------
        GainSpace

        Raises
        ------
        InputError
            An unknown gain (the message lists the tunable ones), a gain given twice, a gain
            both by its value and by its pole pair, bounds of a gain not searched, bounds
            reversed or empty, a value of 0 without bounds, or bounds the controller refuses
            (a candidate at each corner is built and validated).
        """
        if not dataclasses.is_dataclass(base) or not hasattr(type(base), "units"):
            raise InputError(f"a tuner needs a built-in controller (a dataclass of gains), got {type(base).__name__}")
        values = tunable_values(base)
        if isinstance(names, str):
            text, names = names, [n.strip() for n in names.split(",") if n.strip()]
            if not names:
                raise InputError(
                    f"gains {text!r}: expected gain names, e.g. position.kp,position.kd; "
                    f"gains of {base.name}: {', '.join(values)}"
                )
        if not names:
            if "position.kp" not in values:
                raise InputError(f"name the gains of {base.name} to tune (gains: {', '.join(values)})")
            names = ["position.kp", "position.kd"]
        names = list(names)
        for name in names:
            if name not in values:
                close = difflib.get_close_matches(name, list(values), n=1)
                hint = f" (did you mean '{close[0]}'?)" if close else ""
                raise InputError(f"unknown gain {name!r} of {base.name}{hint}; gains: {', '.join(values)}")
        _once(names, "gains")
        for name in names:
            owner, _, leaf = name.rpartition(".")
            if owner and leaf in POLE_NAMES and {f"{owner}.kp", f"{owner}.kd"} & set(names):
                raise InputError(f"gains: {owner} is searched both by its gains and by its poles ({name}); choose one")
        given = parse_bounds(bounds)
        for name in given:
            if name not in names:
                raise InputError(f"bounds of {name!r}, which is not searched (gains: {', '.join(names)})")
        gains = []
        for name in names:
            value, unit = values[name]
            if name in given:
                low, high = given[name]
            elif name.endswith(".zeta"):
                low, high = ZETA_BOUNDS
            elif value > 0:
                low, high = _within_range(base, name, value / DEFAULT_SPAN, value * DEFAULT_SPAN)
            else:
                raise InputError(f"{name} is {value:g}: give its bounds (NAME=LOW:HIGH)")
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
                top[owner] = dataclasses.replace(inner, **changes)
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
