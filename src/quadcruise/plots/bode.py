"""Bode plots of a loop linearised about hover: the closed loops and, beside them, the loop
transfers with their margins marked (python-control's ``bode_plot`` draws the curves)."""

from __future__ import annotations

import math
from collections.abc import Callable

import numpy as np

from quadcruise.metrics.margins import MIN_GAIN_MARGIN_DB, MIN_PHASE_MARGIN_DEG, db

__all__ = ["margin_label", "plot_bode"]


def margin_label(m: dict) -> str:
    """One loop's margins as its legend reads them."""
    parts = []
    if math.isfinite(m["phase_margin"]) and math.isfinite(m["gain_crossover"]):
        short = f" (< {MIN_PHASE_MARGIN_DEG:g}°)" if m["phase_margin"] < MIN_PHASE_MARGIN_DEG else ""
        parts.append(f"PM {m['phase_margin']:.3g}° @ {m['gain_crossover']:.3g} rad/s{short}")
    gms = []
    if math.isfinite(m["gain_decrease_db"]):
        short = f" (> {-MIN_GAIN_MARGIN_DB:+g} dB)" if m["gain_decrease_db"] > -MIN_GAIN_MARGIN_DB else ""
        gms.append(f"down {m['gain_decrease_db']:+.3g} dB @ {m['gain_decrease_frequency']:.3g} rad/s{short}")
    if math.isfinite(m["gain_increase_db"]):
        short = f" (< {MIN_GAIN_MARGIN_DB:+g} dB)" if m["gain_increase_db"] < MIN_GAIN_MARGIN_DB else ""
        gms.append(f"up {m['gain_increase_db']:+.3g} dB @ {m['gain_increase_frequency']:.3g} rad/s{short}")
    if gms:
        parts.append("GM " + ", ".join(gms))
    return ", ".join(parts) or "no crossover"


def _nearest_minus_180(phase: float) -> float:
    """The line -180 + 360 k [deg] nearest ``phase``: where a margin is read on an unwrapped phase."""
    return -180.0 + 360.0 * round((phase + 180.0) / 360.0)


def _draw(axes, system, w, start, label, style):
    """One response drawn by ``control.bode_plot`` on a (magnitude, phase) column; its phase line."""
    import control

    r = control.frequency_response(system, w).complex.ravel()
    # handed over as data (no dt): for a discrete system bode_plot adds a line at the Nyquist
    # frequency, beyond the 0.9 pi / dt drawn, and stretches the axis to it
    plot = control.bode_plot(
        control.frd(r, w),
        ax=axes,
        dB=True,
        deg=True,
        wrap_phase=False,
        initial_phase=start,
        label=label,
        legend_loc=False,
        **style,
    )
    return plot.lines[1, 0][0]


def plot_bode(
    lin, *, loops: bool = False, omega=None, at: str = "input", progress: Callable[[int, int], None] | None = None
):
    """Bode plots of the closed loop and, optionally, of the loop transfers with their margins."""
    from matplotlib.figure import Figure
    from matplotlib.ticker import MultipleLocator, NullLocator

    w = np.logspace(-2, math.log10(0.9 * math.pi / lin.dt), 800) if omega is None else np.asarray(omega, float)
    fig = Figure(figsize=(12 if loops else 7, 6.5), layout="constrained")
    axes = fig.subplots(2, 2 if loops else 1, sharex="col", squeeze=False)
    marked = []
    names = list(lin.loops)
    if progress is not None:
        progress(0, len(names))
    for k, (loop, color) in enumerate(zip(names, ("C0", "C1", "C2", "C3"), strict=False)):
        style = {"color": color, "linestyle": "--" if loop == "y" else "-"}
        closed = lin.closed_loop(loop)
        state = closed.output_labels[0]
        _draw(axes[:, [0]], closed, w, 0.0, f"{state}_r -> {state}", style)
        if loops:
            m = lin.margins(loop, at)
            phase_line = _draw(
                axes[:, [1]], lin.loop_transfer(loop, at), w, -180.0, f"L {loop}: {margin_label(m)}", style
            )
            key = {q: round(m[q], 9) for q in ("phase_margin", "gain_crossover", "gain_increase", "gain_decrease")}
            if key not in marked:  # y's margins are x's: marked once
                marked.append(key)
                _mark_margins(axes[:, 1], m, phase_line, loop, color)
        if progress is not None:
            progress(k + 1, len(names))
    axes[0, 0].set_ylim(bottom=max(axes[0, 0].get_ylim()[0], -150.0))
    for col, title in enumerate([f"closed loop (discrete, dt = {lin.dt:g} s)", "loop transfers"][: axes.shape[1]]):
        axes[0, col].set(ylabel="magnitude [dB]", title=title)
        axes[1, col].set(ylabel="phase [deg]", xlabel="frequency [rad/s]")
        low, high = axes[1, col].get_ylim()
        axes[1, col].yaxis.set_major_locator(MultipleLocator(90.0 if high - low <= 720.0 else 180.0))
        axes[1, col].yaxis.set_minor_locator(NullLocator())
        axes[0, col].axhline(0.0, color="0.6", lw=0.6)
        for k in range(math.ceil((low + 180.0) / 360.0), math.floor((high + 180.0) / 360.0) + 1):
            axes[1, col].axhline(-180.0 + 360.0 * k, color="0.6", lw=0.6)
        axes[1, col].set_ylim(low, high)
        handles, labels = axes[0, col].get_legend_handles_labels()
        keep = [(h, lb) for h, lb in zip(handles, labels, strict=False) if not lb.startswith(("PM ", "GM "))]
        # under the figure, below the axes and their labels: inside the axes, the margins' long
        # labels covered the magnitude axis and its curves; constrained layout makes room for it
        fig.legend(
            *zip(*keep, strict=False),
            fontsize=7 if col else 8,
            loc="outside lower " + ("center" if axes.shape[1] == 1 else "right" if col else "left"),
            ncols=1 if col or axes.shape[1] == 1 else 2,
        )
        for ax in axes[:, col]:
            ax.grid(True, which="both", alpha=0.3)
    fig.suptitle(f"{getattr(lin.controller, 'name', 'controller')}: linearised about hover")
    return fig


def _mark_margins(axes, m, phase_line, loop, color):
    """The margins' segments and marks on a (magnitude, phase) column; bode_plot's own
    ``display_margins`` draws one gain margin in black, not both ways per loop in its colour."""
    w, phase = np.asarray(phase_line.get_xdata(), float), np.asarray(phase_line.get_ydata(), float)
    wgc = m["gain_crossover"]
    if math.isfinite(m["phase_margin"]) and math.isfinite(wgc):
        p = float(np.interp(np.log(wgc), np.log(w), phase))  # the phase at the crossover
        base = _nearest_minus_180(p - m["phase_margin"])
        axes[1].plot(
            [wgc, wgc], [base, base + m["phase_margin"]], color=color, lw=2.5, solid_capstyle="butt", label=f"PM {loop}"
        )
        axes[1].plot([wgc], [base + m["phase_margin"]], "o", color=color, ms=5)
        axes[0].plot([wgc], [0.0], "o", color=color, ms=5)
    for way in ("down", "up"):
        factor = m["gain_decrease" if way == "down" else "gain_increase"]
        wpc = m["gain_decrease_frequency" if way == "down" else "gain_increase_frequency"]
        if not (0.0 < factor < math.inf and math.isfinite(wpc)):
            continue
        g = -db(factor)  # the magnitude at the phase crossover
        axes[0].plot([wpc, wpc], [0.0, g], color=color, lw=2.5, solid_capstyle="butt", label=f"GM {way} {loop}")
        axes[0].plot([wpc], [g], "s", color=color, ms=5)
        axes[1].plot(
            [wpc], [_nearest_minus_180(float(np.interp(np.log(wpc), np.log(w), phase)))], "s", color=color, ms=5
        )
