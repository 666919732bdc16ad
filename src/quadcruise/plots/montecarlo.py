"""Figures of a Monte Carlo sweep: histograms of the metrics with the outcomes, and the
envelope of the kept paths and of the position error.

Drawn with matplotlib's object-oriented API only, like :mod:`quadcruise.plots` (whose
:func:`~quadcruise.plots.plot_envelope` draws one batched flight, not a sweep).
"""

from __future__ import annotations

import math
import warnings

import numpy as np
from matplotlib.figure import Figure

__all__ = ["plot_histograms", "plot_envelope"]


HISTOGRAM_METRICS = ("rmse_m", "max_error_m", "final_error_m", "rise_time_s", "settling_time_5pct_s",
                     "overshoot_pct", "effort", "duty_clipped_s")
"""The metrics :func:`plot_histograms` draws by default."""


def plot_histograms(result, metrics=None):
    """Histograms of a sweep's metrics and a bar chart of its outcomes.

    Parameters
    ----------
    result : MonteCarloResult
        The sweep (its ``table``, ``spec``, ``n`` and ``failure_names`` are read).
    metrics : sequence of str, optional
        Columns of the table to draw; :data:`HISTOGRAM_METRICS` by default.

    Returns
    -------
    matplotlib.figure.Figure
        One panel per metric (40 bins of its finite values, in the column's unit, with
        lines at 5 %, the median and 95 %; "not measured" if none is finite), then the
        count of flights per outcome (:data:`~quadcruise.montecarlo.result.FAILURES`).
    """
    panels = list(HISTOGRAM_METRICS if metrics is None else metrics) + ["failures"]
    cols = 3
    rows = math.ceil(len(panels) / cols)
    fig = Figure(figsize=(4.3 * cols, 3.2 * rows), layout="constrained")
    axes = fig.subplots(rows, cols, squeeze=False).ravel()
    for ax, name in zip(axes, panels):
        if name == "failures":
            names = result.failure_names          # the outcome codes 0..4 of the table's 'failure' column
            counts = [int(np.count_nonzero(result.table["failure"] == c)) for c in range(len(names))]
            ax.bar(range(len(names)), counts,
                   color=["tab:green", "tab:red", "tab:orange", "tab:brown", "tab:purple"][:len(names)])
            ax.set_xticks(range(len(names)), [n.replace(" ", "\n", 1) for n in names], fontsize="small")
            for x, c in enumerate(counts):
                ax.annotate(f"{c:,}", (x, c), ha="center", va="bottom", fontsize="small")
            ax.set_title(f"outcome of {result.n:,} flights", fontsize="medium")
            ax.set_ylabel("flights")
            continue
        v = result.table[name].to_numpy(dtype=float)
        v = v[np.isfinite(v)]
        if v.size:
            ax.hist(v, bins=40, color="tab:blue", alpha=0.8)
            for q, style in zip(np.percentile(v, [5, 50, 95]), (":", "-", ":")):
                ax.axvline(q, color="k", ls=style, lw=1.0)
        else:
            ax.text(0.5, 0.5, "not measured", ha="center", va="center", transform=ax.transAxes, color="0.4")
        missing = result.n - v.size
        ax.set_title(f"{name}  (n = {v.size:,}" + (f", {missing:,} n/a)" if missing else ")"), fontsize="medium")
        ax.grid(True, alpha=0.3)
    for ax in axes[len(panels):]:
        ax.set_visible(False)
    fig.suptitle(f"{result.spec.controller.name} on {result.spec.mission.name}: {result.n:,} flights, seed "
                 f"{result.spec.seed} (lines: 5 %, median, 95 %)")
    return fig


def plot_envelope(result):
    """The kept paths of a sweep from above, and the spread of their position error.

    Parameters
    ----------
    result : MonteCarloResult
        The sweep (its ``traces``, ``table`` and ``spec`` are read).

    Returns
    -------
    matplotlib.figure.Figure
        Two axes: the top view [m] of the kept paths (the first vehicles, and the extra
        failures kept; diverged in red, other failures in orange) and the median and 5-95 %
        band of the position error norm [m] of the sampled flights against time [s].
    """
    tr = result.traces
    fig = Figure(figsize=(13, 5.5), layout="constrained")
    top, ax_e = fig.subplots(1, 2, width_ratios=(1, 1.4))
    lookup = result.table.set_index("vehicle")["failure"]
    fail = lookup.reindex(tr.vehicle).to_numpy() if len(tr.vehicle) else np.zeros(0, int)
    n_sample = int(np.count_nonzero(tr.sample))
    alpha = float(np.clip(6.0 / max(n_sample, 1), 0.08, 0.8))
    for k in range(len(tr.vehicle)):
        x, y = tr.pos[k, :, 0], tr.pos[k, :, 1]
        color = {0: "tab:blue", 1: "tab:red"}.get(int(fail[k]), "tab:orange")
        top.plot(x, y, color=color, lw=0.7 if fail[k] == 0 else 0.9, alpha=alpha if fail[k] == 0 else 0.7)
        live = np.flatnonzero(np.isfinite(x) & np.isfinite(y))
        if fail[k] == 1 and live.size:
            top.plot(x[live[-1]], y[live[-1]], "x", color="tab:red", ms=6)
    total = result.table["failure"].value_counts()
    for code, color, what in ((0, "tab:blue", "ok"), (1, "tab:red", "diverged"), (2, "tab:orange", "failed otherwise")):
        drawn = int(np.count_nonzero(fail == code)) if code < 2 else int(np.count_nonzero(fail >= 2))
        all_ = int(total.get(code, 0)) if code < 2 else int(total[total.index >= 2].sum())
        if all_:
            top.plot([], [], color=color, lw=1, label=f"{what} ({drawn:,} drawn of {all_:,})")
    ref = next((tr.ref[k] for k in range(len(tr.vehicle)) if np.all(np.isfinite(tr.ref[k, :, :2]))), None)
    if ref is not None:
        top.plot(ref[:, 0], ref[:, 1], color="k", ls="--", lw=1.0, label="reference")
    top.set_aspect("equal", adjustable="datalim")
    top.set(xlabel="x [m]", ylabel="y [m]", title="top view")
    top.legend(fontsize="small", loc="upper center", bbox_to_anchor=(0.5, -0.12), ncols=2)
    err = np.linalg.norm(tr.pos[tr.sample] - tr.ref[tr.sample], axis=2)
    if err.size and np.any(np.isfinite(err)):
        with warnings.catch_warnings():
            warnings.simplefilter("ignore", RuntimeWarning)
            p5, p50, p95 = np.nanpercentile(err, [5, 50, 95], axis=0)
        ax_e.fill_between(tr.t, p5, p95, color="tab:blue", alpha=0.25, lw=0, label="5-95 %")
        ax_e.plot(tr.t, p50, color="tab:blue", lw=1.5, label="median")
        ax_e.set_ylim(bottom=0)
        ax_e.legend(fontsize="small", loc="best")
    ax_e.set(xlabel="time [s]", ylabel="position error |p - p_ref| [m]",
             title=f"position error of the first {n_sample:,} flights")
    if tr.t.size > 1:
        ax_e.set_xlim(tr.t[0], tr.t[-1])
    for ax in (top, ax_e):
        ax.grid(True, alpha=0.3)
    fig.suptitle(f"{result.spec.controller.name} on {result.spec.mission.name}: {result.n:,} flights, seed {result.spec.seed}")
    return fig
