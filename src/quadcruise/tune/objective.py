"""A tuner's objective: a whole generation of candidate gains flown as one batch, each candidate
on the same M vehicles of a population (their noise and turbulence included), reduced to one
cost per candidate.

Per flight (one candidate on one vehicle), with the metrics of a Monte Carlo table
(:func:`quadcruise.montecarlo.chunk.sweep_metrics`)::

    cost = sum over targets ((metric - value) / tolerance)^2 + sum of the minimised metrics

A flight that misses a requirement costs :data:`REQUIREMENT_COST` more, plus its misses
measured in the requirements' own values (|bound|, or 1 for a bound of 0). A flight that
finished but has no value for a metric the cost needs (a transient that never settled) costs
:data:`FAILURE_COST` times (1 + its RMSE in metres), so that among such flights the search
still sees which is closer; a flight that lost track (the Monte Carlo rule: fly's status, or its error after the
transient beyond the spec's bound) costs the same; a flight the engine stopped (diverged)
costs ten times :data:`FAILURE_COST`. So every flight that meets the requirements ranks before every
one that does not, and every finished flight before every failed one.

A candidate's cost is the worst of its M flights' costs (``statistic="worst"``) or their
quantile ``q`` (``statistic=q``, 0 < q < 1): a robust tune. With one vehicle and no
population, the nominal flight alone.
"""

from __future__ import annotations

import time
from dataclasses import dataclass, field
from typing import Any

import numpy as np

from quadcruise import checks
from quadcruise.montecarlo.chunk import fly_chunk, sweep_metrics
from quadcruise.montecarlo.schema import METRICS
from quadcruise.montecarlo.spec import MonteCarloSpec
from quadcruise.tune.space import GainSpace

__all__ = ["FAILURE_COST", "REQUIREMENT_COST", "Evaluation", "Objective", "check_statistic"]

FAILURE_COST = 1e9
"""Cost of a flight that lacks a metric the cost needs, times (1 + its RMSE [m]); ten times this
for a flight that did not finish."""
REQUIREMENT_COST = 1e6
"""Added to the cost of a flight that misses a requirement."""


def check_statistic(statistic: Any, where: str = "tune()", name: str = "objective") -> str | float:
    """The statistic over a candidate's flights: ``"worst"`` or a quantile in (0, 1).

    Examples
    --------
    >>> check_statistic("worst"), check_statistic("median"), check_statistic(0.9)
    ('worst', 0.5, 0.9)
    >>> check_statistic("q90")
    Traceback (most recent call last):
        ...
    quadcruise.errors.InputError: tune() argument objective must be 'worst', 'median' or a quantile in (0, 1), got \
str 'q90'
    """
    want = "'worst', 'median' or a quantile in (0, 1)"
    if isinstance(statistic, str):
        if statistic in ("worst", "median"):
            return "worst" if statistic == "worst" else 0.5
        checks.fail(where, name, statistic, want, kind=False)
    q = checks.number(where, name, statistic)
    if not 0.0 < q < 1.0:
        checks.fail(where, name, statistic, want, kind=False)
    return q


@dataclass
class Evaluation:
    """One generation flown: each candidate's gains, cost and flights."""

    values: np.ndarray
    cost: np.ndarray
    flight_cost: np.ndarray
    metrics: dict
    wall_s: float


@dataclass
class Objective:
    """Candidate gains -> costs, one batched flight per call."""

    spec: MonteCarloSpec
    space: GainSpace
    targets: tuple = ()
    requirements: tuple = ()
    minimize: tuple = ()
    samples: int = 1
    statistic: Any = "worst"
    evaluations: list = field(default_factory=list)

    @property
    def metrics_used(self) -> list[str]:
        """The metrics the cost reads, in order of first use."""
        names = [t.metric for t in self.targets] + [r.metric for r in self.requirements] + list(self.minimize)
        return list(dict.fromkeys(names))

    def __call__(self, unit: np.ndarray) -> np.ndarray:
        """The costs of candidates given as positions in the unit cube, as scipy's
        vectorised differential evolution calls it."""
        unit = np.asarray(unit, dtype=float)
        single = unit.ndim == 1
        ev = self.evaluate(self.space.values(unit[:, None].T if single else unit.T))
        return float(ev.cost[0]) if single else ev.cost

    def evaluate(self, values: np.ndarray) -> Evaluation:
        """Fly candidates (one batch: P candidates x M vehicles) and cost them; the
        evaluation is kept in :attr:`evaluations`."""
        start = time.perf_counter()
        values = np.atleast_2d(np.asarray(values, dtype=float))
        p, m = values.shape[0], self.samples
        controllers = [c for c in self.space.controllers(values) for _ in range(m)]
        ids = np.tile(np.arange(m), p)
        res, _ = fly_chunk(self.spec, ids, p * m, controller=controllers)
        cols = sweep_metrics(res, self.spec)
        metrics = {k: np.asarray(cols[k], dtype=float).reshape(p, m) for k in METRICS}
        for key in ("status", "failure", "diverged", "lost_track"):
            metrics[key] = np.asarray(cols[key]).reshape(p, m)
        flight_cost = self.flight_cost(metrics)
        ev = Evaluation(
            values=values,
            cost=self.reduce(flight_cost),
            flight_cost=flight_cost,
            metrics=metrics,
            wall_s=time.perf_counter() - start,
        )
        self.evaluations.append(ev)
        return ev

    def flight_cost(self, metrics: dict) -> np.ndarray:
        """Each flight's cost (see the module)."""
        status = metrics["status"]
        stopped = metrics.get("diverged", status != 0)
        cost = np.zeros(status.shape)
        for t in self.targets:
            cost += t.cost(metrics[t.metric])
        for name in self.minimize:
            cost += metrics[name]
        missed = np.zeros(status.shape)
        failed = (status != 0) | stopped | metrics.get("lost_track", False)
        for r in self.requirements:
            values = metrics[r.metric]
            failed |= np.isnan(values)
            missed += np.where(r.met(values), 0.0, r.violation(values) / (abs(r.value) or 1.0))
        cost = np.where(missed > 0, cost + REQUIREMENT_COST * (1.0 + missed), cost)
        failed |= ~np.isfinite(cost)
        rmse = metrics.get("rmse_m", np.zeros(status.shape))
        fallback = np.where(~stopped & np.isfinite(rmse), FAILURE_COST * (1.0 + rmse), 10.0 * FAILURE_COST)
        return np.where(failed, fallback, cost)

    def reduce(self, flight_cost: np.ndarray) -> np.ndarray:
        """Each candidate's cost from its flights' costs: the worst or a quantile."""
        if self.statistic == "worst" or flight_cost.shape[1] == 1:
            return flight_cost.max(axis=1)
        return np.quantile(flight_cost, float(self.statistic), axis=1, method="higher")

    def statistic_of(self, values: np.ndarray) -> np.ndarray:
        """A metric's value over each candidate's flights, by the objective's statistic (worst: the largest)."""
        if self.statistic == "worst" or values.shape[1] == 1:
            return values.max(axis=1)
        return np.quantile(values, float(self.statistic), axis=1, method="higher")
