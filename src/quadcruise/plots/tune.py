"""The figure of a tune: how the search converged, and the tuned response against the targets.

Duck-typed: it reads a result's ``history`` (a table with ``generation`` and ``cost``),
``response`` and ``start_response`` (flights, as :class:`quadcruise.SimResult`) and
``targets`` (objects with ``metric``, ``value`` and ``tolerance``); it imports no result class.
"""

from __future__ import annotations

import numpy as np
from matplotlib.figure import Figure

from quadcruise.plots.flight import REF_STYLE, drawable

__all__ = ["plot_tune", "transient_axis"]


def transient_axis(result) -> tuple[int, float, float]:
    """The axis a flight's transient is measured on, its start value and its step time."""
    mission = result.meta.get("mission") if isinstance(result.meta.get("mission"), dict) else {}
    if mission.get("kind") == "step" and mission.get("axis") in ("x", "y", "z"):
        return "xyz".index(mission["axis"]), float(mission[mission["axis"]]), float(mission["time"])
    e0 = np.abs(result.references[0, 0, :3] - result.states[0, 0, :3])
    j = int(np.argmax(e0))
    return j, float(result.states[0, 0, j]), float(result.t[0])


def plot_tune(result, *, title: str | None = None) -> Figure:
    """Two panels: the best cost after each generation, and the response of the tuned gains
    (and of the starting ones) with the targets marked."""
    fig = Figure(figsize=(11.0, 4.2))
    ax_cost, ax_resp = fig.subplots(1, 2, gridspec_kw={"width_ratios": [1.0, 1.6]})
    hist = result.history
    best = hist.groupby("generation")["cost"].min().cummin()
    ax_cost.semilogy(best.index, np.maximum(best.to_numpy(), 1e-12), "o-", ms=3, color="tab:blue")
    ax_cost.set_xlabel("generation")
    ax_cost.set_ylabel("best cost so far")
    ax_cost.grid(True, which="both", alpha=0.3)
    ax_cost.set_title("convergence", fontsize=10)

    tuned, start = drawable(result.response), drawable(result.start_response)
    j, y0, t_step = transient_axis(tuned)
    name = "xyz"[j]
    ax_resp.plot(start.t, start.states[0, :, j], color="0.6", lw=1.2, label="start gains")
    ax_resp.plot(tuned.t, tuned.states[0, :, j], color="tab:blue", lw=1.6, label="tuned gains")
    ax_resp.plot(tuned.t, tuned.references[0, :, j], **REF_STYLE)
    final = float(tuned.references[0, -1, j])
    size = final - y0
    for target in result.targets:
        if target.metric == "overshoot_pct":
            level = final + size * target.value / 100.0
            ax_resp.axhline(level, color="tab:red", ls=":", lw=1.0, label=f"overshoot target {target.value:g} %")
        elif target.metric == "rise_time_s":
            ax_resp.axvline(
                t_step + target.value, color="tab:green", ls=":", lw=1.0, label=f"rise target {target.value:g} s"
            )
        elif target.metric in ("settling_time_s", "settling_time_5pct_s"):
            band = 0.02 if target.metric == "settling_time_s" else 0.05
            t_set = t_step + target.value
            ax_resp.axvline(t_set, color="tab:purple", ls=":", lw=1.0, label=f"settling target {target.value:g} s")
            ax_resp.fill_between(
                [t_set, tuned.t[-1]],
                final - band * abs(size),
                final + band * abs(size),
                color="tab:purple",
                alpha=0.12,
                lw=0,
            )
    ax_resp.set_xlabel("t [s]")
    ax_resp.set_ylabel(f"{name} [m]")
    ax_resp.grid(True, alpha=0.3)
    ax_resp.legend(fontsize=8, loc="lower right")
    ax_resp.set_title("response", fontsize=10)
    fig.suptitle(title or "tune", fontsize=11)
    fig.subplots_adjust(left=0.07, right=0.98, bottom=0.13, top=0.86, wspace=0.25)
    return fig
