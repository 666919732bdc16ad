"""Figures of a Monte Carlo sweep: histograms of the metrics with the outcomes, and the
envelope of the kept paths and of the position error.

Drawn with matplotlib's object-oriented API only, like :mod:`quadcruise.plots` (whose
:func:`~quadcruise.plots.plot_envelope` draws one batched flight, not a sweep).
"""

from __future__ import annotations

import math
import textwrap
import warnings

import numpy as np
from matplotlib.figure import Figure
from matplotlib.ticker import MaxNLocator

from quadcruise.metrics.declared import METRICS as DECLARED_METRICS
from quadcruise.metrics.declared import metric_names

__all__ = ["plot_histograms", "plot_envelope", "metric_label", "degenerate", "METRIC_LABELS"]


HISTOGRAM_METRICS = metric_names(histogram=True)
"""The metrics :func:`plot_histograms` draws by default (declared ``histogram=True`` in
:mod:`quadcruise.metrics.declared`)."""

METRIC_LABELS = {
    **{m.name: m.axis_label for m in DECLARED_METRICS},
    "stop_time_s": "stop time [s]",
    "m": "mass [kg]",
    "dx0": "start offset x [m]",
    "dy0": "start offset y [m]",
    "dz0": "start offset z [m]",
    "wind_x": "wind x [m/s]",
    "wind_y": "wind y [m/s]",
    "imu_noise_factor": "IMU noise / nominal [-]",
    "gps_noise_factor": "GPS noise / nominal [-]",
}
"""Axis labels, with units, of the sweep table's columns."""


def metric_label(name: str) -> str:
    """A column of the sweep table as an axis label with its unit.

    Examples
    --------
    >>> metric_label("rmse_m"), metric_label("hover_time_s"), metric_label("K")
    ('RMSE [m]', 'hover time [s]', 'K')
    """
    if name in METRIC_LABELS:
        return METRIC_LABELS[name]
    for suffix, unit in (("_s", "s"), ("_m", "m"), ("_pct", "%"), ("_deg", "deg")):
        if name.endswith(suffix) and len(name) > len(suffix):
            return f"{name[: -len(suffix)].replace('_', ' ')} [{unit}]"
    return name.replace("_", " ")


def degenerate(values: np.ndarray, n: int) -> str | None:
    """Why a column makes no histogram, or None if it makes one.

    Examples
    --------
    >>> degenerate(np.array([0.0, 0.0, np.nan]), 3), degenerate(np.array([1.0, 2.0]), 2)
    ('0 in all 2 flights measured', None)
    """
    v = values[np.isfinite(values)]
    if not v.size:
        return "not measured"
    if v.min() == v.max():
        return f"{v[0]:.4g} in all {v.size:,} flights measured" if v.size < n else f"{v[0]:.4g} in all {n:,} flights"
    return None


def plot_histograms(result, metrics=None):
    """Histograms of a sweep's metrics over the flights that kept track (those the summary's
    quantiles are over: a flight that diverged or lost track is left out, so that its numbers
    do not pass for a good flight's), and a bar chart of every flight's outcome."""
    names = list(HISTOGRAM_METRICS if metrics is None else metrics)
    tab = result.table
    kept = ~(tab["diverged"].to_numpy(dtype=bool) | tab["lost_track"].to_numpy(dtype=bool))
    n_kept = int(np.count_nonzero(kept))
    columns = {name: tab[name].to_numpy(dtype=float)[kept] for name in names}
    skipped = {name: why for name in names if (why := degenerate(columns[name], n_kept))}
    panels = [name for name in names if name not in skipped] + ["failures"]
    cols = min(3, len(panels))
    rows = math.ceil(len(panels) / cols)
    fig = Figure(figsize=(4.3 * max(cols, 2), 3.2 * rows + (0.4 if skipped else 0.0)), layout="constrained")
    axes = fig.subplots(rows, cols, squeeze=False).ravel()
    for ax, name in zip(axes, panels, strict=False):
        if name == "failures":
            outcomes = result.failure_names  # the outcome codes 0..4 of the table's 'failure' column
            counts = [int(np.count_nonzero(result.table["failure"] == c)) for c in range(len(outcomes))]
            ax.bar(
                range(len(outcomes)),
                counts,
                color=["tab:green", "tab:red", "tab:orange", "tab:brown", "tab:purple"][: len(outcomes)],
            )
            ax.set_xticks(range(len(outcomes)), [n.replace(" ", "\n", 1) for n in outcomes], fontsize="small")
            for x, c in enumerate(counts):
                ax.annotate(f"{c:,}", (x, c), ha="center", va="bottom", fontsize="small")
            ax.set_title(f"outcome of {result.n:,} flights", fontsize="medium")
            ax.set(xlabel="outcome", ylabel="flights")
            ax.set_ylim(top=max(counts) * 1.12)
            continue
        v = columns[name]
        v = v[np.isfinite(v)]
        ax.hist(v, bins=40, color="tab:blue", alpha=0.8)
        for q, style in zip(np.percentile(v, [5, 50, 95]), (":", "-", ":"), strict=False):
            ax.axvline(q, color="k", ls=style, lw=1.0)
        missing = n_kept - v.size
        ax.set_title(f"{name}  (n = {v.size:,}" + (f", {missing:,} n/a)" if missing else ")"), fontsize="medium")
        ax.set(xlabel=metric_label(name), ylabel="flights")
        ax.yaxis.set_major_locator(MaxNLocator(integer=True))
        ax.xaxis.set_major_locator(MaxNLocator(nbins=5))  # small values (effort ~0.002 s) in powers of ten:
        ax.ticklabel_format(axis="x", style="sci", scilimits=(-2, 4), useMathText=True)  # no overlap
        ax.grid(True, alpha=0.3)
    for ax in axes[len(panels) :]:
        ax.set_visible(False)
    if skipped:
        note = "not drawn: " + ", ".join(f"{k} ({why})".replace(" ", "\u00a0") for k, why in skipped.items())
        fig.supxlabel(
            textwrap.fill(note, width=int(15 * fig.get_figwidth()), break_on_hyphens=False),
            fontsize="small",
            color="0.3",
        )
    left_out = result.n - n_kept
    fig.suptitle(
        f"{result.spec.controller.name} on {result.spec.mission.name}: {result.n:,} flights, seed "
        f"{result.spec.seed}; metrics of the {n_kept:,} that kept track"
        + (f" ({left_out:,} that diverged or lost track left out)" if left_out else "")
        + " (lines: 5 %, median, 95 %)"
    )
    return fig


def plot_envelope(result):
    """The kept paths of a sweep from above, and the spread of their position error."""
    tr = result.traces
    fig = Figure(figsize=(13, 5.5), layout="constrained")
    top, ax_e = fig.subplots(1, 2, width_ratios=(1, 1.4))
    lookup = result.table.set_index("vehicle")["failure"]
    fail = lookup.reindex(tr.vehicle).to_numpy() if len(tr.vehicle) else np.zeros(0, int)
    ok = fail == 0
    n_sample = int(np.count_nonzero(tr.sample))
    # failures first, thin and translucent, underneath; the flights that finished on top, as
    # opaque as their number allows, so that a sweep with many failures still shows them
    alpha_ok = float(np.clip(10.0 / max(int(np.count_nonzero(ok)), 1), 0.35, 0.8))
    for k in [*np.flatnonzero(~ok), *np.flatnonzero(ok)]:
        x, y = tr.pos[k, :, 0], tr.pos[k, :, 1]
        if ok[k]:
            top.plot(x, y, color="tab:blue", lw=1.0, alpha=alpha_ok, zorder=2.2)
            continue
        color = "tab:red" if fail[k] == 1 else "tab:orange"
        top.plot(x, y, color=color, lw=0.7, alpha=0.3, zorder=2.0)
        live = np.flatnonzero(np.isfinite(x) & np.isfinite(y))
        if fail[k] == 1 and live.size:
            top.plot(x[live[-1]], y[live[-1]], "x", color="tab:red", ms=6, alpha=0.6, zorder=2.1)
    total = result.table["failure"].value_counts()
    for code, color, what in ((0, "tab:blue", "ok"), (1, "tab:red", "diverged"), (2, "tab:orange", "failed otherwise")):
        drawn = int(np.count_nonzero(fail == code)) if code < 2 else int(np.count_nonzero(fail >= 2))
        all_ = int(total.get(code, 0)) if code < 2 else int(total[total.index >= 2].sum())
        if all_:
            top.plot([], [], color=color, lw=1, label=f"{what} ({drawn:,} drawn of {all_:,})")
    ref = next((tr.ref[k] for k in range(len(tr.vehicle)) if np.all(np.isfinite(tr.ref[k, :, :2]))), None)
    if ref is not None:
        top.plot(ref[:, 0], ref[:, 1], color="k", ls="--", lw=1.0, label="reference", zorder=2.5)
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
    ax_e.set(
        xlabel="time [s]",
        ylabel="position error |p - p_ref| [m]",
        title=f"position error of the first {n_sample:,} flights",
    )
    if tr.t.size > 1:
        ax_e.set_xlim(tr.t[0], tr.t[-1])
    for ax in (top, ax_e):
        ax.grid(True, alpha=0.3)
    fig.suptitle(
        f"{result.spec.controller.name} on {result.spec.mission.name}: {result.n:,} flights, seed {result.spec.seed}"
    )
    return fig
