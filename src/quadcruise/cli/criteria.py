"""The text forms of ``quadcruise tune``'s options, read into the library's objects: targets
``METRIC=VALUE[+-TOL]``, bounds ``NAME=LOW:HIGH``, gains and minimised metrics comma-separated,
the objective ``worst``, ``median``, ``q90`` or ``0.9``. A requirement ``METRIC<=VALUE`` is read
as a scenario's ``[montecarlo]`` table reads it
(:func:`quadcruise.montecarlo.scenario.parse_requirements`). Each bad text is one line naming it.

Examples
--------
>>> parse_targets(["overshoot_pct=4+-1.5", "rise_time_s=1"])
(Target(metric='overshoot_pct', value=4.0, tolerance=1.5), Target(metric='rise_time_s', value=1.0, tolerance=0.1))
>>> parse_bounds(["position.kp=0.5:10,position.kd=1:8"])
(Bounds(gain='position.kp', low=0.5, high=10.0), Bounds(gain='position.kd', low=1.0, high=8.0))
>>> parse_bounds(["position.kp=10:0.5"])
Traceback (most recent call last):
    ...
quadcruise.errors.InputError: bounds 'position.kp=10:0.5' are reversed or empty: LOW must be below HIGH
"""

from __future__ import annotations

import math
import re
from collections.abc import Iterable

from quadcruise.errors import InputError
from quadcruise.montecarlo.requirements import metric_hint
from quadcruise.montecarlo.scenario import parse_requirements
from quadcruise.montecarlo.schema import METRICS
from quadcruise.tune.criteria import Target
from quadcruise.tune.space import Bounds, tunable_values

__all__ = ["parse_bounds", "parse_gains", "parse_minimize", "parse_objective", "parse_requirements", "parse_targets"]

_TARGET = re.compile(r"^\s*([A-Za-z_][A-Za-z0-9_]*)\s*=\s*([^=]+?)\s*(?:(?:\+-|±|\+/-)\s*([^=]+?))?\s*$")


def _number(text: str, what: str) -> float:
    try:
        value = float(text)
    except (TypeError, ValueError):
        value = math.nan
    if not math.isfinite(value):
        raise InputError(f"{what}: {str(text).strip()!r} is not a finite number")
    return value


def _metric(name: str, what: str) -> str:
    if name not in METRICS:
        raise InputError(f"{what}: unknown metric {name!r}{metric_hint(name)}; metrics: {', '.join(METRICS)}")
    return name


def _once(names: list[str], what: str) -> None:
    for k, name in enumerate(names):
        if name in names[:k]:
            raise InputError(f"{what}: {name} is given twice")


def parse_targets(texts: Iterable[str]) -> tuple[Target, ...]:
    """Targets from ``METRIC=VALUE`` or ``METRIC=VALUE+-TOLERANCE`` texts, a metric at most once."""
    out = []
    for text in texts:
        match = _TARGET.match(str(text))
        what = f"target {str(text).strip()!r}"
        if match is None:
            raise InputError(f"{what}: expected METRIC=VALUE or METRIC=VALUE+-TOLERANCE, e.g. rise_time_s=1")
        metric = _metric(match.group(1), what)
        value = _number(match.group(2), what)
        if value < 0:
            raise InputError(f"{what}: no metric is negative; {metric} is >= 0")
        tolerance = _number(match.group(3), what) if match.group(3) else None
        if tolerance is not None and tolerance <= 0:
            raise InputError(f"{what}: the tolerance must be > 0")
        out.append(Target(metric, value, tolerance))
    _once([t.metric for t in out], "target")
    return tuple(out)


def parse_minimize(texts: Iterable[str]) -> tuple[str, ...]:
    """The metrics to minimise, from texts each holding one or several, comma-separated."""
    out = []
    for text in texts:
        found = [_metric(n.strip(), f"minimize {n.strip()!r}") for n in str(text).split(",") if n.strip()]
        if not found:
            raise InputError(f"minimize {str(text)!r}: expected a metric, e.g. rmse_m; metrics: {', '.join(METRICS)}")
        out += found
    _once(out, "minimize")
    return tuple(out)


def parse_gains(text: str | None, controller=None) -> list[str] | None:
    """The gains' names from ``--gains``, comma-separated (checked against the controller by the tune)."""
    if text is None:
        return None
    names = [n.strip() for n in text.split(",") if n.strip()]
    if not names:
        known = f"; gains of {controller.name}: {', '.join(tunable_values(controller))}" if controller else ""
        raise InputError(f"gains {text!r}: expected gain names, e.g. position.kp,position.kd{known}")
    return names


def parse_bounds(texts: Iterable[str]) -> tuple[Bounds, ...]:
    """Bounds from ``NAME=LOW:HIGH`` texts, several comma-separated in one text too."""
    out: dict[str, Bounds] = {}
    for text in texts:
        pieces = [piece for piece in str(text).split(",") if piece.strip()]
        if not pieces:
            raise InputError(f"bounds {str(text)!r}: expected NAME=LOW:HIGH, e.g. position.kp=0.5:10")
        for piece in pieces:
            name, sep, span = (part.strip() for part in piece.partition("="))
            what = f"bounds '{name}={span}'"
            if not sep or not name:
                raise InputError(f"bounds {piece.strip()!r}: expected NAME=LOW:HIGH, e.g. position.kp=0.5:10")
            low_text, sep, high_text = span.partition(":")
            if not sep:
                raise InputError(f"{what}: expected NAME=LOW:HIGH, e.g. position.kp=0.5:10")
            low, high = _number(low_text, what), _number(high_text, what)
            if not low < high:
                raise InputError(f"{what} are reversed or empty: LOW must be below HIGH")
            if name in out:
                raise InputError(f"{what}: {name} is bounded twice; give its bounds once")
            out[name] = Bounds(name, low, high)
    return tuple(out.values())


def parse_objective(text: str) -> str | float:
    """The statistic over a candidate's flights: ``worst`` (or ``max``), ``median``, or a
    quantile as ``0.9``, ``q0.9`` or ``q90``.

    Examples
    --------
    >>> parse_objective("q90"), parse_objective("median"), parse_objective("max")
    (0.9, 0.5, 'worst')
    """
    word = str(text).strip().lower()
    if word in ("worst", "max"):
        return "worst"
    if word == "median":
        return 0.5
    body = word[1:] if word.startswith("q") else word
    try:
        q = float(body)
    except ValueError:
        q = -1.0
    if word.startswith("q") and q > 1:
        q /= 100.0
    if not 0.0 < q < 1.0:
        raise InputError(f"objective {text!r}: expected worst, median or a quantile such as 0.9 (or q90)")
    return q
