"""The result of a Monte Carlo sweep: its table of one row per flight, the kept paths,
the summary (quantiles, failure rate by reason) and the worst flights.

:data:`COLUMNS` is the table's schema, :data:`FAILURES` its failure codes and
:data:`METRICS` the metrics summarised by quantiles. The figures are drawn by
:mod:`quadcruise.plots.montecarlo` and the output folder written by
:mod:`quadcruise.montecarlo.output`.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any, ClassVar

import numpy as np

from quadcruise.errors import InputError
from quadcruise.metrics.declared import metric
from quadcruise.metrics.summary import Summary
from quadcruise.montecarlo.consistency import consistency_text, nees_consistency
from quadcruise.montecarlo.schema import COLUMNS, ESTIMATE_METRICS, FAILURES, METRICS, engine_stops
from quadcruise.montecarlo.spec import MonteCarloSpec

__all__ = ["MonteCarloResult", "Traces", "FAILURES", "COLUMNS", "METRICS"]


@dataclass
class Traces:
    """The kept paths of a sweep."""

    vehicle: np.ndarray
    t: np.ndarray
    pos: np.ndarray
    ref: np.ndarray
    sample: np.ndarray


@dataclass
class MonteCarloResult:
    """A finished sweep: one table row per flight, the kept paths, and how it ran.

    :func:`quadcruise.montecarlo.montecarlo` builds it.

    Parameters
    ----------
    spec : MonteCarloSpec
        What was flown.
    table : pandas.DataFrame
        One row per flight, sorted by vehicle index (see :data:`COLUMNS`), plus ``reason``
        (the failure as text); :meth:`metrics` is its copy (``table`` is the old name, kept).
    traces : Traces
        The kept paths.
    info : dict
        Scheduler, workers, chunk size, chunks flown and resumed, wall time [s], output
        folder.
    """

    failure_names: ClassVar[tuple] = FAILURES

    spec: MonteCarloSpec
    table: Any
    traces: Traces
    info: dict = field(default_factory=dict)

    @property
    def n(self) -> int:
        """Number of flights."""
        return len(self.table)

    def metrics(self):
        """The metrics of every flight: one row per flight (see :data:`quadcruise.montecarlo.schema.COLUMNS`).

        Returns
        -------
        pandas.DataFrame
            A copy of :attr:`table` (the old name, kept), sorted by vehicle index.
        """
        return self.table.copy()

    def to_pandas(self):
        """The flights, one row each: :meth:`metrics`.

        Returns
        -------
        pandas.DataFrame
            :meth:`metrics`.
        """
        return self.metrics()

    def plot(self, kind: str = "histograms", **kwargs):
        """A figure of the sweep: ``"histograms"`` (:meth:`plot_histograms`) or ``"envelope"``
        (:meth:`plot_envelope`).

        Parameters
        ----------
        kind : {"histograms", "envelope"}
        **kwargs
            Passed to the chosen method.

        Returns
        -------
        matplotlib.figure.Figure
        """
        if kind == "histograms":
            return self.plot_histograms(**kwargs)
        if kind == "envelope":
            return self.plot_envelope(**kwargs)
        raise InputError(f"unknown plot kind {kind!r}; choose histograms or envelope")

    def summary(self) -> Summary:
        """The headline numbers; prints as :meth:`summary_text`.

        Returns
        -------
        Summary
            See :meth:`summary_data` for the keys.
        """
        return Summary(self.summary_data(), self.summary_text())

    def summary_data(self) -> dict:
        """Failure rate by reason, the engine's stop reasons, and quantiles of each metric.

        Returns
        -------
        dict
            ``flights``, ``seed``; ``failures``: ``count``, ``rate`` and ``by_reason``
            (each flight counted once, under the first of diverged, lost track, saturated,
            failed a requirement: ``count`` and ``rate`` each); ``criteria``: the bounds
            that made those failures (``max_track_error_m`` [m], ``max_clipped_s`` [s]);
            ``requirements``: for each of the spec's requirements, ``requirement`` (its
            text), ``failed`` (flights that do not meet it, whatever else they failed; an
            undefined value does not meet it) and ``rate``; ``not_settled``: ``count`` and
            ``rate`` of flights whose transient was still outside the spec's
            ``settle_band`` at the end (a metric, not a failure); ``stopped``: the engine's
            stop reason -> count; ``metrics``: for each of :data:`METRICS`, ``count``
            (flights where it is defined, among those that kept track: a flight that diverged
            or lost track is left out, so that its numbers do not pass for a good flight's),
            ``p5``, ``p50``, ``p95``, ``max`` and ``mean`` over them, in the metric's unit
            (None when no flight defines it); ``metrics_over``: the number of flights that
            kept track.
        """
        from quadcruise.sim.status import STATUS_REASONS

        tab = self.table
        n = len(tab)
        failure = tab["failure"].to_numpy()
        counts = np.bincount(failure, minlength=len(FAILURES))
        by_reason = {
            FAILURES[c]: {"count": int(counts[c]), "rate": float(counts[c] / n)} for c in range(1, len(FAILURES))
        }
        requirements = []
        for req in self.spec.requirements:
            missed = int(np.count_nonzero(~req.met(tab[req.metric].to_numpy(dtype=float))))
            requirements.append({"requirement": req.text, "failed": missed, "rate": missed / n})
        unsettled = int(np.count_nonzero(tab["not_settled"].to_numpy()))
        stops = {
            STATUS_REASONS[c]: int(k) for c, k in zip(*np.unique(tab["status"], return_counts=True), strict=False) if c
        }
        metrics = {}
        kept = ~(tab["diverged"].to_numpy(dtype=bool) | tab["lost_track"].to_numpy(dtype=bool))
        flew_estimator = getattr(self.spec.population, "estimator", None) is not None
        for name in METRICS:
            if name in ESTIMATE_METRICS and not flew_estimator:
                continue  # a sweep on the truth: no estimate to measure
            v = tab[name].to_numpy(dtype=float)[kept]
            v = v[np.isfinite(v)]
            q = np.percentile(v, [5, 50, 95]) if v.size else [np.nan] * 3
            metrics[name] = {
                "count": int(v.size),
                "p5": _num(q[0]),
                "p50": _num(q[1]),
                "p95": _num(q[2]),
                "max": _num(v.max() if v.size else np.nan),
                "mean": _num(v.mean() if v.size else np.nan),
            }
        fails = int(np.count_nonzero(failure))
        return {
            "flights": n,
            "seed": self.spec.seed,
            "failures": {"count": fails, "rate": fails / n, "by_reason": by_reason},
            "criteria": {
                "max_track_error_m": self.spec.max_track_error_m,
                "max_altitude_error_m": self.spec.max_altitude_error_m,
                "max_clipped_s": self.spec.max_clipped_s,
            },
            "requirements": requirements,
            "not_settled": {"count": unsettled, "rate": unsettled / n, "band": self.spec.settle_band},
            "stopped": stops,
            "metrics": metrics,
            "metrics_over": int(np.count_nonzero(kept)),
            **({"consistency": nees_consistency(tab, kept)} if flew_estimator else {}),
        }

    def summary_text(self, worst: int = 0) -> str:
        """The summary as aligned text (for the terminal).

        Parameters
        ----------
        worst : int
            Also list this many worst flights (:meth:`worst_text`); none by default.

        Returns
        -------
        str
            A headline (flights, controller, mission, seed, failures), a line per failure
            reason (with its bound), a line per requirement (flights that missed it), the
            flights whose transient did not settle, a line per metric with its count,
            p5, p50, p95 and max, and the worst flights if asked for.
        """
        s = self.summary_data()
        f = s["failures"]
        lines = [
            f"{s['flights']:,} flights of {self.spec.controller.name} on {self.spec.mission.name}, "
            f"seed {s['seed']}: {f['count']:,} failed ({100 * f['rate']:.2f} %)"
        ]
        bounds = {
            "lost track": f"error after the transient > {s['criteria']['max_track_error_m']:g} m "
            f"or altitude error > {s['criteria']['max_altitude_error_m']:g} m",
            "saturated": f"duties clipped > {s['criteria']['max_clipped_s']:g} s",
            "failed a requirement": "see below" if s["requirements"] else "none given",
        }
        for reason, v in f["by_reason"].items():
            why = f"  [{bounds[reason]}]" if reason in bounds else ""
            lines.append(f"  {reason:<22} {v['count']:>8,}  ({100 * v['rate']:.2f} %){why}")
            if reason == "diverged":  # how the engine stopped them: a crash on the ground is one way
                lines += [f"    {count:>8,}  {why_stopped}" for why_stopped, count in engine_stops(s).items()]
        for r in s["requirements"]:
            lines.append(f"  requirement {r['requirement']}: missed by {r['failed']:,} ({100 * r['rate']:.2f} %)")
        ns = s["not_settled"]
        lines.append(
            f"  not settled within {100 * ns['band']:g} % (a metric, not a failure): "
            f"{ns['count']:,} ({100 * ns['rate']:.2f} %)"
        )
        left_out = s["flights"] - s["metrics_over"]
        lines.append(
            f"  metrics over the {s['metrics_over']:,} flights that kept track"
            + (f" ({left_out:,} that diverged or lost track left out)" if left_out else "")
            + ":"
        )
        width = max(22, *(len(name) + 1 for name in s["metrics"]))
        lines.append(f"  {'metric':<{width}}{'count':>8}{'p5':>11}{'p50':>11}{'p95':>11}{'max':>11}")
        for name, m in s["metrics"].items():
            lines.append(
                f"  {name:<{width}}{m['count']:>8,}"
                + "".join(f"{'-' if m[k] is None else format(m[k], '.4g'):>11}" for k in ("p5", "p50", "p95", "max"))
            )
        if "consistency" in s:
            lines.append(consistency_text(s["consistency"]))
        if worst:
            lines += [f"worst {worst} (fly one alone again with --case VEHICLE):", self.worst_text(worst)]
        return "\n".join(lines)

    def worst(self, k: int = 10, by: str = "rmse_m"):
        """The k worst flights.

        Failures come first (diverged, earliest stop first; then lost track, saturated,
        failed a requirement), then the flights by ``by``, worst first (largest first, smallest
        for a metric declared ``better="higher"``, :mod:`quadcruise.metrics.declared`).

        Parameters
        ----------
        k : int
            How many.
        by : str
            The column that ranks the flights within each outcome (a metric of
            :data:`METRICS`).

        Returns
        -------
        pandas.DataFrame
            Rows of :attr:`table` with the ``seed`` inserted after ``vehicle``:
            :func:`~quadcruise.montecarlo.replay_case` flies one again alone.

        Raises
        ------
        InputError
            If ``by`` is not a column of the table.
        """
        if by not in self.table.columns:
            raise InputError(f"unknown metric {by!r}; choose one of {', '.join(METRICS)}")
        tab = self.table
        rank = (len(FAILURES) - np.arange(len(FAILURES))) % len(FAILURES)  # 0 for ok, diverged highest
        rank = rank[tab["failure"].to_numpy()]
        value = tab[by].to_numpy(dtype=float)
        if (declared := metric(by)) is not None and declared.better == "higher":
            value = -value  # the worst of a higher-is-better metric is its smallest
        stop = np.where(tab["failure"].to_numpy() == 1, tab["stop_time_s"].to_numpy(), 0.0)
        order = np.lexsort((tab["vehicle"].to_numpy(), np.nan_to_num(-value, nan=np.inf), stop, -rank))
        out = tab.iloc[order[:k]].copy()
        out.insert(1, "seed", self.spec.seed)
        return out.reset_index(drop=True)

    def worst_text(self, k: int = 5, by: str = "rmse_m") -> str:
        """The k worst flights (:meth:`worst`) as aligned text (for the terminal).

        Parameters
        ----------
        k : int
            How many flights.
        by : str
            The metric that ranks the flights that did not fail.

        Returns
        -------
        str
            One line per flight: vehicle, seed, reason, RMSE, maximum error, RMSE and
            maximum error after the transient, 5 % settling time, stop time and mass,
            numbers to 4 significant digits.
        """
        cols = [
            "vehicle",
            "seed",
            "reason",
            "rmse_m",
            "max_error_m",
            "steady_rmse_m",
            "steady_max_error_m",
            "settling_time_5pct_s",
            "stop_time_s",
            "m",
        ]
        return self.worst(k, by)[cols].to_string(index=False, float_format=lambda v: f"{v:.4g}")

    def case(self, i: int, **kw):
        """Vehicle i flown again alone (:func:`~quadcruise.montecarlo.replay_case`).

        Parameters
        ----------
        i : int
            The vehicle's index.
        **kw
            Keywords of :func:`~quadcruise.montecarlo.montecarlo_case` (``log_every``).

        Returns
        -------
        Case
            The vehicle's index, its flight (logged at the spec's rate unless
            ``log_every`` says otherwise) and its table row.
        """
        from quadcruise.montecarlo.chunk import replay_case

        return replay_case(self, i, **kw)

    def plot_histograms(self, metrics=None):
        """Histograms of the metrics (finite values; lines at 5 %, median, 95 %) and a bar
        chart of the outcomes.

        Parameters
        ----------
        metrics : sequence of str, optional
            Columns to draw; by default
            :data:`quadcruise.plots.montecarlo.HISTOGRAM_METRICS`.

        Returns
        -------
        matplotlib.figure.Figure
            See :func:`quadcruise.plots.montecarlo.plot_histograms`.
        """
        from quadcruise.plots.montecarlo import plot_histograms

        return plot_histograms(self, metrics)

    def plot_envelope(self):
        """Top view of the kept paths and the spread of the position error.

        Returns
        -------
        matplotlib.figure.Figure
            The kept paths from above (the first vehicles and the first extra failures;
            diverged in red, other failures in orange) and the median and 5-95 % band of
            the position error [m] of the first vehicles against time [s]
            (:func:`quadcruise.plots.montecarlo.plot_envelope`).
        """
        from quadcruise.plots.montecarlo import plot_envelope

        return plot_envelope(self)

    def write(self, out: str | Path, *, fmt: str = "csv", force: bool = False) -> Path:
        """Write the sweep's folder, each file whole or not at all.

        It holds flights.csv (or .parquet), summary.json, worst.csv, histograms.png,
        envelope.png, report.md and quadcruise.json. A folder holding the chunks of this
        same sweep is completed in place.

        Parameters
        ----------
        out : str or pathlib.Path
            The folder.
        fmt : str
            Format of the flights table: ``"csv"`` or ``"parquet"``.
        force : bool
            Replace a folder that holds something else (else InputError).

        Returns
        -------
        pathlib.Path
            The folder written.
        """
        from quadcruise.montecarlo.output import write_outputs

        return write_outputs(self, out, fmt=fmt, force=force)


def _num(value) -> float | None:
    value = float(value)
    return value if math.isfinite(value) else None
