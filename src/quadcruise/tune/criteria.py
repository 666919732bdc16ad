"""What a tuner is asked for: the targets to reach, the requirements to meet and the metrics
to minimise, each a small frozen object checked on construction, before any flight.

- A **target** ``Target("overshoot_pct", 4, tolerance=1.5)``: the cost counts the miss in
  tolerances, squared; without a tolerance, 10 % of the value (1 in the metric's unit for a
  target of 0). A target is *met* within its tolerance. As a mapping:
  ``{"overshoot_pct": (4, 1.5), "rise_time_s": 1}`` (a value, or a pair value, tolerance).
- A **requirement** ``Requirement("overshoot_pct", "<=", 5)``, the Monte Carlo sweep's own
  (:mod:`quadcruise.montecarlo.requirements`; as a mapping ``{"overshoot_pct": ("<=", 5)}``):
  a candidate that misses it ranks behind every candidate that meets all of them.
- **minimize** ``"rmse_m"`` or a list of metrics: the metric's value, in its unit, is added to
  the cost.

The metrics are the columns of a Monte Carlo table
(:data:`quadcruise.montecarlo.schema.METRICS`), measured the same way. The text forms of the
command line (``overshoot_pct=4+-1.5``, ``overshoot_pct<=5``) are read in
:mod:`quadcruise.cli.criteria`.

Examples
--------
>>> Target("overshoot_pct", 4, 1.5)
Target(metric='overshoot_pct', value=4.0, tolerance=1.5)
>>> as_targets({"overshoot_pct": (4, 1.5), "rise_time_s": 1}, "tune()")[1].tolerance
0.1
>>> as_targets(["rise_time_s=1"], "tune()")       # doctest: +ELLIPSIS
Traceback (most recent call last):
    ...
quadcruise.errors.ArgumentTypeError: tune() argument targets[0] must be a Target, got str 'rise_time_s=1'; ...
"""

from __future__ import annotations

from collections.abc import Iterable, Mapping
from dataclasses import dataclass
from typing import Any

import numpy as np

from quadcruise import checks
from quadcruise.errors import InputError
from quadcruise.montecarlo.requirements import Requirement, as_requirements, check_metric

__all__ = ["Requirement", "Target", "as_minimize", "as_requirements", "as_targets"]


def _tolerance(where: str, name: str, value: float, tolerance: Any) -> float:
    if tolerance is None:
        return 0.1 * value if value > 0 else 1.0
    return checks.number(where, name, tolerance, "pos")


def _value(where: str, name: str, value: Any) -> float:
    return checks.number(where, name, value, "nonneg")


@dataclass(frozen=True)
class Target:
    """A value a metric should reach: the cost counts the miss in tolerances, squared.

    Parameters
    ----------
    metric : str
        A metric of :data:`~quadcruise.montecarlo.schema.METRICS`.
    value : float
        The value wanted, in the metric's unit (>= 0: every metric is).
    tolerance : float, optional
        How far from ``value`` still meets the target (> 0); None: 10 % of the value (1 for
        a value of 0), the field holding the value used after construction.

    Raises
    ------
    ArgumentTypeError
        A field of the wrong type (a value given as text).
    InputError
        An unknown metric, a negative or infinite value, a tolerance that is not positive.
    """

    metric: str
    value: float
    tolerance: float | None = None

    def __post_init__(self) -> None:
        where = "Target()"
        check_metric(where, "metric", self.metric)
        value = _value(where, "value", self.value)
        object.__setattr__(self, "value", value)
        object.__setattr__(self, "tolerance", _tolerance(where, "tolerance", value, self.tolerance))

    @property
    def text(self) -> str:
        """``METRIC=VALUE+-TOLERANCE``, as the command line writes it."""
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


_TARGETS = "Target objects or a mapping {metric: value or (value, tolerance)}"
_TARGET_HINT = "write Target('overshoot_pct', 4, 1.5) or {'overshoot_pct': (4, 1.5)}"


def as_targets(value: Any, where: str, name: str = "targets") -> tuple[Target, ...]:
    """A function's targets (a Target, several, or a mapping metric -> value or (value, tolerance)) as a
    tuple of :class:`Target`, a metric at most once."""
    if value is None:
        return ()
    if isinstance(value, Target):
        return (value,)
    if isinstance(value, str):
        checks.fail(where, name, value, _TARGETS, hint=_TARGET_HINT + "; text is read by the command line")
    if isinstance(value, Mapping):
        out = []
        for metric, given in value.items():
            item = f"{name}[{metric!r}]"
            check_metric(where, f"{name} key", metric)
            if isinstance(given, (tuple, list, np.ndarray)):
                given = checks.pair(where, item, given, "a value or a pair (value, tolerance)")
                x = _value(where, f"{item}[0]", given[0])
                tol = _tolerance(where, f"{item}[1]", x, given[1])
            else:
                x = _value(where, item, given)
                tol = None
            out.append(Target(metric, x, tol))
        return tuple(out)
    if not isinstance(value, Iterable):
        checks.fail(where, name, value, _TARGETS)
    out = list(value)
    for k, item in enumerate(out):
        if not isinstance(item, Target):
            checks.fail(where, f"{name}[{k}]", item, "a Target", hint=_TARGET_HINT)
    _once(where, name, [t.metric for t in out])
    return tuple(out)


def as_minimize(value: Any, where: str, name: str = "minimize") -> tuple[str, ...]:
    """A function's minimised metrics: one metric's name or a list of them, a metric at most once.

    Examples
    --------
    >>> as_minimize("rmse_m", "tune()"), as_minimize(["rmse_m", "effort"], "tune()")
    (('rmse_m',), ('rmse_m', 'effort'))
    """
    if value is None:
        return ()
    items = [value] if isinstance(value, str) else value
    if not isinstance(items, Iterable):
        checks.fail(where, name, value, "a metric's name or a list of them")
    out = tuple(check_metric(where, name if isinstance(value, str) else f"{name}[{k}]", m) for k, m in enumerate(items))
    _once(where, name, list(out))
    return out


def _once(where: str, name: str, metrics: list[str]) -> None:
    seen = set()
    for m in metrics:
        if m in seen:
            raise InputError(f"{where} argument {name} gives {m} twice; give each metric once")
        seen.add(m)
