"""A user's own pass criteria for a Monte Carlo sweep (and a tune): ``Requirement("rmse_m", "<=", 0.5)``.

A requirement names one metric of the sweep's table (:data:`~quadcruise.montecarlo.schema.METRICS`),
a comparison (``<=``, ``<``, ``>=``, ``>``) and a number in the metric's unit. A flight meets
it if its value satisfies the comparison; an undefined value (NaN: a flight that stopped
early, a transient that never settled) does not meet it. A flight that misses any
requirement (and no earlier failure reason) fails as "failed a requirement".

The library takes the objects, or a mapping ``{metric: (op, value)}``
(:func:`as_requirements`); the text form ``"rmse_m<=0.5"`` of the command line and of a
scenario's ``[montecarlo]`` table is read by
:func:`quadcruise.montecarlo.scenario.parse_requirement`.

Examples
--------
>>> req = Requirement("steady_max_error_m", "<=", 0.2)
>>> req.text, req.met(np.array([0.1, 0.3, np.nan])).tolist()
('steady_max_error_m<=0.2', [True, False, False])
>>> as_requirements({"overshoot_pct": ("<=", 5)}, "montecarlo()")
(Requirement(metric='overshoot_pct', op='<=', value=5.0),)
>>> Requirement("steady_max_error", "<=", 0.2)      # doctest: +ELLIPSIS
Traceback (most recent call last):
    ...
quadcruise.errors.InputError: Requirement() argument metric must be a metric of the flights table, got str \
'steady_max_error'; did you mean 'steady_max_error_m'? metrics: rmse_m, ...
"""

from __future__ import annotations

import difflib
import operator
from collections.abc import Iterable, Mapping
from dataclasses import dataclass
from typing import Any

import numpy as np

from quadcruise import checks
from quadcruise.montecarlo.schema import ESTIMATE_METRICS, METRICS

__all__ = ["OPERATORS", "Requirement", "as_requirements", "check_metric", "metric_hint"]

_OPERATORS = {"<=": operator.le, "<": operator.lt, ">=": operator.ge, ">": operator.gt}
OPERATORS = tuple(_OPERATORS)
"""The comparisons a requirement may make."""


def metric_hint(name: str) -> str:
    """The closest metric's name, for a message: ``" (did you mean 'rmse_m'?)"`` or ``""``."""
    close = _closest(name)
    return f" (did you mean '{close}'?)" if close else ""


_UNITS = ("_m", "_s", "_pct")


def _base(metric: str) -> str:
    """A metric's name without its unit: ``rise_time_s`` -> ``rise_time``."""
    return next((metric[: -len(u)] for u in _UNITS if metric.endswith(u)), metric)


def _closest(name: str) -> str | None:
    """The metric a mistyped or shortened name most likely means: the one whose name (less its unit)
    it begins, the shortest of them (``rise`` -> ``rise_time_s``, ``settling`` -> ``settling_time_s``,
    ``overshoot`` -> ``overshoot_pct``), else the closest spelling (``rmse`` -> ``rmse_m``).

    Examples
    --------
    >>> [_closest(n) for n in ("rise", "settling", "Overshoot", "peak-time", "rmse", "steady_max_eror", "zzz")]
    ['rise_time_s', 'settling_time_s', 'overshoot_pct', 'peak_time_s', 'rmse_m', 'steady_max_error_m', None]
    """
    word = str(name).strip().lower().replace("-", "_").replace(" ", "_")
    if word in METRICS:
        return word
    bases = {_base(m): m for m in METRICS}
    if word and (begun := [b for b in bases if b == _base(word) or b.startswith(word)]):
        return bases[min(begun, key=len)]
    close = difflib.get_close_matches(_base(word), list(bases), n=1) or difflib.get_close_matches(word, METRICS, n=1)
    return bases.get(close[0], close[0]) if close else None


def check_metric(where: str, name: str, value: Any) -> str:
    """A metric's name, checked against the table's metrics, in the API's message form.

    Examples
    --------
    >>> check_metric("tune()", "minimize", "rmse")          # doctest: +ELLIPSIS
    Traceback (most recent call last):
        ...
    quadcruise.errors.InputError: tune() argument minimize must be a metric of the flights table, got str 'rmse'; did \
you mean 'rmse_m'? metrics: rmse_m, ...
    """
    estimate = [m for m in METRICS if m in ESTIMATE_METRICS]  # named by their stems: the line stays short
    metrics = f"metrics: {', '.join(m for m in METRICS if m not in estimate)}, on an estimator estimate_*, nees_*"
    if not isinstance(value, str):
        checks.fail(where, name, value, "a metric's name (str)", hint=metrics)
    if value not in METRICS:
        close = _closest(value)
        hint = f"did you mean '{close}'? {metrics}" if close else metrics
        checks.fail(where, name, value, "a metric of the flights table", kind=False, hint=hint)
    return value


@dataclass(frozen=True)
class Requirement:
    """One pass criterion: ``metric op value``, checked on construction.

    Parameters
    ----------
    metric : str
        A column of :data:`~quadcruise.montecarlo.schema.METRICS`.
    op : {"<=", "<", ">=", ">"}
        The comparison.
    value : float
        The bound, in the metric's unit (a finite number).

    Raises
    ------
    ArgumentTypeError
        A field of the wrong type (a metric that is not a string, a bound given as text).
    InputError
        An unknown metric, comparison or a bound that is not finite.
    """

    metric: str
    op: str
    value: float

    def __post_init__(self) -> None:
        where = "Requirement()"
        check_metric(where, "metric", self.metric)
        if not isinstance(self.op, str):
            checks.fail(where, "op", self.op, "one of '<=', '<', '>=', '>'")
        if self.op not in _OPERATORS:
            checks.fail(where, "op", self.op, "one of '<=', '<', '>=', '>'", kind=False)
        object.__setattr__(self, "value", checks.number(where, "value", self.value))

    @property
    def text(self) -> str:
        """The requirement as text, without spaces: ``"steady_max_error_m<=0.2"`` (the value
        written so that it reads back to the same float)."""
        number = repr(self.value)
        return f"{self.metric}{self.op}{number[:-2] if number.endswith('.0') else number}"

    def met(self, values) -> np.ndarray:
        """Which values meet the requirement.

        Parameters
        ----------
        values : array_like
            Values of :attr:`metric`, one per flight.

        Returns
        -------
        ndarray of bool
            True where the value satisfies the comparison; False where it does not or is NaN.
        """
        v = np.asarray(values, dtype=float)
        with np.errstate(invalid="ignore"):
            return np.asarray(_OPERATORS[self.op](v, self.value), dtype=bool) & np.isfinite(v)

    def violation(self, values) -> np.ndarray:
        """How far each value is on the wrong side of the bound, in the metric's unit.

        Parameters
        ----------
        values : array_like
            Values of :attr:`metric`.

        Returns
        -------
        ndarray
            0 where the value is on the right side (and at the bound of a strict comparison).

        Examples
        --------
        >>> Requirement("overshoot_pct", "<=", 5).violation([3.0, 7.5]).tolist()
        [0.0, 2.5]
        """
        v = np.asarray(values, dtype=float)
        gap = v - self.value if self.op in ("<=", "<") else self.value - v
        return np.maximum(gap, 0.0)


_WANT = "Requirement objects or a mapping {metric: (op, value)}"


def as_requirements(value: Any, where: str, name: str = "requirements") -> tuple[Requirement, ...]:
    """A function's requirements argument as a tuple of :class:`Requirement`."""
    if value is None:
        return ()
    if isinstance(value, Requirement):
        return (value,)
    hint = "write Requirement('rmse_m', '<=', 0.5) or {'rmse_m': ('<=', 0.5)}"
    if isinstance(value, str):
        checks.fail(where, name, value, _WANT, hint=hint + "; text is read by the command line and scenario files")
    if isinstance(value, Mapping):
        out = []
        for metric, pair in value.items():
            item = f"{name}[{metric!r}]"
            check_metric(where, f"{name} key", metric)
            pair = checks.pair(where, item, pair, "a pair (op, value), e.g. ('<=', 0.5)")
            if not isinstance(pair[0], str) or pair[0] not in _OPERATORS:
                checks.fail(
                    where, f"{item}[0]", pair[0], "one of '<=', '<', '>=', '>'", kind=not isinstance(pair[0], str)
                )
            out.append(Requirement(metric, pair[0], checks.number(where, f"{item}[1]", pair[1])))
        return tuple(out)
    if not isinstance(value, Iterable):
        checks.fail(where, name, value, _WANT)
    out = list(value)
    for k, item in enumerate(out):
        if not isinstance(item, Requirement):
            checks.fail(where, f"{name}[{k}]", item, "a Requirement", hint=hint)
    return tuple(out)
