"""Figures of logged flights, drawn with matplotlib's object-oriented API only.

No pyplot global state is touched, so the functions work headless and in threads; a
figure is shown in a notebook as is, or written with :func:`save_figure`.

Examples
--------
>>> import quadcruise as qc
>>> from quadcruise.plots import plot_flight
>>> fig = plot_flight(qc.fly("step", duration=2.0, log_every=10))
>>> len(fig.axes)
9
"""

from __future__ import annotations

import os
import warnings

import numpy as np
from matplotlib.figure import Figure
from matplotlib.ticker import MaxNLocator

from quadcruise.io.files import atomic_path
from quadcruise.plots.marks import (
    ERROR_FLOOR,
    SATURATION_STYLE,
    error_axes,
    flight_events,
    mark_events,
    position_error,
    saturation,
    shade,
)

REF_STYLE = dict(color="k", ls="--", lw=1.0, label="reference")
STOP_STYLE = dict(color="tab:red", ls=":", lw=1.5)


FLIGHT_MARGINS = dict(left=0.05, right=0.86, bottom=0.048, top=0.93, wspace=0.32, hspace=0.14)
"""The flight figure's grid in fractions of the figure, fixed rather than found by a
layout engine: constrained layout draws the whole figure once more to measure it, which
slows saving it (see docs/performance.md)."""

MAX_DRAWN = 3000
"""Figures draw at most this many instants of a flight (a 60 s flight at 1 kHz has 60,001):
more are invisible at screen resolution and only slow the drawing down."""


def drawable(result):
    """The result, decimated by the smallest step that leaves at most :data:`MAX_DRAWN` instants."""
    every = -(-len(result.t) // MAX_DRAWN)
    return result if every <= 1 else result.decimate(every)


def _has(trace: np.ndarray) -> bool:
    return bool(np.any(np.isfinite(trace)))


def _names(result, vehicle: int = 0) -> tuple[str | None, str | None]:
    """The controller's name and the mission's kind recorded in ``result.meta``."""
    meta = result.meta or {}
    mission = meta.get("mission")
    if isinstance(mission, list):
        mission = mission[min(vehicle, len(mission) - 1)] if mission else None
    ctrl = meta.get("controller")
    return (
        ctrl.get("name") if isinstance(ctrl, dict) else ctrl,
        mission.get("kind") if isinstance(mission, dict) else None,
    )


def describe(result, vehicle: int = 0) -> str:
    """What a flight was, for a title: ``"<controller> on <mission>"``, ``"open-loop replay of <file>"``,
    or what its ``meta`` records (``"flight"`` if nothing).

    Examples
    --------
    >>> from types import SimpleNamespace
    >>> describe(SimpleNamespace(meta={"controller": {"name": "nlpd"}, "mission": {"kind": "step"}}))
    'nlpd on step'
    """
    name, kind = _names(result, vehicle)
    meta = result.meta or {}
    if name and kind:
        return f"{name} on {kind}"
    if meta.get("workflow") == "replay":
        source = meta.get("source")
        return "open-loop replay" + (f" of {os.path.basename(str(source))}" if source else "")
    return name or kind or meta.get("workflow") or "flight"


def _mark_stop(ax, t_stop: float, label: bool = False) -> None:
    ax.axvline(t_stop, **STOP_STYLE, label=f"stopped, t = {t_stop:.3f} s" if label else None)


def _legend(ax, **kwargs) -> None:
    ax.legend(**{"fontsize": "small", "framealpha": 0.85, **kwargs})


def _path3d(ax, result, vehicle: int) -> None:
    pos = np.stack([result.state(n)[vehicle] for n in ("x", "y", "z")], axis=1)
    ref = np.stack([result.state(n)[vehicle] for n in ("x_ref", "y_ref", "z_ref")], axis=1)
    ax.plot(*pos.T, color="tab:blue", lw=1.5, label="actual")
    pts = [pos]
    if _has(ref):
        ax.plot(*ref.T, **REF_STYLE)
        pts.append(ref)
    live = pos[np.all(np.isfinite(pos), axis=1)]
    if live.size:
        ax.scatter(
            *live[0], facecolor="none", edgecolor="tab:green", s=90, lw=2, marker="o", label="start", depthshade=False
        )
        ax.scatter(*live[-1], color="tab:red", s=45, marker="X", label="end", depthshade=False)
    # one scale on all three axes (box aspect = spans), each span at least 3/4 of the
    # largest, so a level flight is not drawn as a flat sliver
    allp = np.concatenate(pts)
    allp = allp[np.all(np.isfinite(allp), axis=1)]
    lo, hi = (allp.min(0), allp.max(0)) if allp.size else (np.zeros(3), np.ones(3))
    half = np.maximum((hi - lo) / 2 * 1.1, 0.25)
    half = np.maximum(half, 0.75 * half.max())
    mid = (lo + hi) / 2
    for setter, m, h in zip((ax.set_xlim, ax.set_ylim, ax.set_zlim), mid, half, strict=False):
        setter(m - h, m + h)
    ax.set_box_aspect(tuple(half), zoom=0.8)
    # x ends and y starts at the front corner in the default view: prune both there
    for axis, prune in ((ax.xaxis, "upper"), (ax.yaxis, "lower"), (ax.zaxis, None)):
        axis.set_major_locator(MaxNLocator(4, prune=prune))
    ax.set(xlabel="x [m]", ylabel="y [m]", zlabel="z [m]")
    for axis in (ax.xaxis, ax.yaxis, ax.zaxis):
        axis.labelpad = 9
    _legend(ax, loc="upper center", ncols=4, title="3-D path", bbox_to_anchor=(0.5, 0.98))


def _time_panel(
    ax, t, y, ref, ylabel: str, color: str, label: str, min_span: float, ref_label: str = "reference"
) -> None:
    """A trace against time with its reference (dashed, where finite) on a y range at
    least ``min_span`` tall, so numerical noise on a held value is not blown up."""
    ax.plot(t, y, color=color, lw=1.3, label=label)
    shown = [y]
    if ref is not None and _has(ref):
        ax.plot(t, ref, **{**REF_STYLE, "label": ref_label})
        shown.append(ref)
    vals = np.concatenate(shown)
    vals = vals[np.isfinite(vals)]
    if vals.size:
        lo, hi = vals.min(), vals.max()
        pad = max(0.08 * (hi - lo), (min_span - (hi - lo)) / 2, 0.0)
        ax.set_ylim(lo - pad, hi + pad)
    ax.ticklabel_format(axis="y", useOffset=False)
    ax.set_ylabel(ylabel)
    ax.grid(True, alpha=0.3)


def plot_flight(result, vehicle: int = 0, *, title: str | None = None) -> Figure:
    """One vehicle's flight on one figure: path, position, attitude, position error and
    rotor duties.

    Parameters
    ----------
    result : SimResult
        The flight; more than :data:`MAX_DRAWN` logged instants are thinned for drawing
        (the saturation intervals are found on every logged instant).
    vehicle : int
        Which of the result's vehicles to draw.
    title : str, optional
        Figure title; by default the controller and mission from ``result.meta`` (and the
        vehicle's index when the result holds several), and the reason if the vehicle
        stopped early.

    Returns
    -------
    matplotlib.figure.Figure
        Nine axes: the 3-D path, x, y, z [m], roll, pitch, yaw [deg] against time, the
        position error ``|p - p_ref|`` [m] on a log scale (see
        :func:`~quadcruise.plots.marks.error_axes`), and the four rotor duties with their
        [0, 1] limits. References are drawn dashed where finite, attitude setpoints only
        where there is a reference (an open-loop replay has none). The events recorded in
        ``result.meta["environment"]`` (a gust, a rotor loss) are marked on every time
        panel and named in the error panel's legend; the periods in which the controller
        flagged a limit, or asked for a duty outside [0, 1] that the engine clipped, are
        shaded on the duty panel, each named in its legend only if it happened. An early
        stop is marked on every time panel, which then end shortly after it.
    """
    spans = saturation(result, vehicle)
    result = drawable(result)
    t = result.t
    fig = Figure(figsize=(16, 12))
    # row 3 and column 1 are gaps: for the time axes' labels above the error panel, and
    # between the 3-D path's labels and the position panels' own
    gs = fig.add_gridspec(
        6, 4, width_ratios=(1.3, 0.02, 1, 1), height_ratios=(1, 1, 1, 0.06, 0.9, 1.0), **FLIGHT_MARGINS
    )
    _path3d(fig.add_subplot(gs[0:3, 0], projection="3d"), result, vehicle)
    pos_axes = [fig.add_subplot(gs[0, 2])]
    pos_axes += [fig.add_subplot(gs[i, 2], sharex=pos_axes[0]) for i in (1, 2)]
    att_axes = [fig.add_subplot(gs[i, 3], sharex=pos_axes[0]) for i in range(3)]
    closed_loop = any(_has(result.state(f"{n}_ref")[vehicle]) for n in "xyz")
    for ax, name, c in zip(pos_axes, "xyz", ("tab:blue", "tab:orange", "tab:green"), strict=False):
        _time_panel(
            ax,
            t,
            result.state(name)[vehicle],
            result.state(f"{name}_ref")[vehicle],
            f"{name} [m]",
            c,
            name,
            min_span=0.02,
        )
    for ax, name, label, c in zip(
        att_axes,
        ("phi", "theta", "psi"),
        ("roll φ", "pitch θ", "yaw ψ"),
        ("tab:blue", "tab:orange", "tab:green"),
        strict=False,
    ):
        sp = np.degrees(result.state(f"{name}_d")[vehicle]) if closed_loop else None
        _time_panel(
            ax,
            t,
            np.degrees(result.state(name)[vehicle]),
            sp,
            f"{label} [deg]",
            c,
            label,
            min_span=2.0,
            ref_label="setpoint",
        )
    ax_e = fig.add_subplot(gs[4, :], sharex=pos_axes[0])
    error_axes(ax_e, [(t, position_error(result, vehicle), dict(color="k", label="|p - p_ref|"))])
    ax_u = fig.add_subplot(gs[5, :], sharex=pos_axes[0])
    stopped = int(result.status[vehicle]) != 0
    t_end = t[-1]
    if stopped:
        t_stop = float(result.t_stop[vehicle])
        step = t[1] - t[0] if t.size > 1 else 0.0
        t_end = min(t[-1], t_stop + max(0.1 * (t_stop - t[0]), 3 * step))
    t_end = t_end if t_end > t[0] else t[0] + 1.0
    _duties(ax_u, result, vehicle, spans, min_width=(t_end - t[0]) / 1500)
    time_axes = pos_axes + att_axes + [ax_e, ax_u]
    events = flight_events(result.meta, vehicle)
    for ax in time_axes:
        mark_events(ax, events, (t[0], t_end), label=ax is ax_e)
    if stopped:
        for ax in time_axes:
            _mark_stop(ax, t_stop, label=ax in (pos_axes[0], att_axes[0], ax_u))
    for ax in pos_axes + att_axes:
        _legend(ax, loc="best")
    for ax in (ax_e, ax_u):
        if ax.get_legend_handles_labels()[0]:
            _legend(ax, loc="upper left", bbox_to_anchor=(1.005, 1.0), borderaxespad=0.0)
    _room_for_legends(fig, gs, [ax.get_legend() for ax in (ax_e, ax_u) if ax.get_legend() is not None])
    for ax in (pos_axes[2], att_axes[2], ax_u):
        ax.set_xlabel("time [s]")
    for ax in pos_axes[:2] + att_axes[:2] + [ax_e]:
        ax.tick_params(labelbottom=False)
    ax_u.set_xlim(t[0], t_end)
    if title is None:
        title = describe(result, vehicle) + (f" — vehicle {vehicle}" if result.n > 1 else "")
        if stopped:
            title += f"\n{result.status_text(vehicle)}"
    fig.suptitle(title, color="tab:red" if stopped else "k")
    return fig


def _room_for_legends(fig, gs, legends) -> None:
    """Narrow the grid so that the legends right of the wide panels fit in the figure: they are
    measured (their text only, not the figure drawn), since their labels (a clipped duty, a
    gust, a rotor's loss) vary; ``FLIGHT_MARGINS["right"]`` is kept when they fit."""
    if not legends:
        return
    get = getattr(fig.canvas, "get_renderer", None)
    if get is None:
        from matplotlib.backends.backend_agg import FigureCanvasAgg

        get = FigureCanvasAgg(fig).get_renderer
    renderer = get()
    width = max(legend.get_window_extent(renderer).width for legend in legends) / fig.bbox.width
    right = min(FLIGHT_MARGINS["right"], 0.99 - width - 0.005 * (FLIGHT_MARGINS["right"] - FLIGHT_MARGINS["left"]))
    if right < FLIGHT_MARGINS["right"]:
        gs.update(right=right)
        for ax in fig.axes:  # GridSpec.update moves only the axes of pyplot's figures
            spec = ax.get_subplotspec()
            if spec is not None and spec.get_gridspec() is gs:
                ax.set_position(spec.get_position(fig))


def _duties(ax, result, vehicle: int, spans: dict, min_width: float) -> None:
    t = result.t
    duties = result.commands[vehicle, :, :4]
    for j in range(4):
        ax.plot(
            t, duties[:, j], color=("tab:blue", "tab:orange", "tab:green", "tab:purple")[j], lw=1.0, label=f"u{j + 1}"
        )
    for kind in ("flagged", "clipped"):
        shade(ax, spans[kind], min_width=min_width, **SATURATION_STYLE[kind])
    live = duties[np.isfinite(duties)]
    lo, hi = (live.min(), live.max()) if live.size else (0.0, 1.0)
    lo, hi = min(lo, 0.0), max(hi, 0.0)
    pad = 0.08 * max(hi - lo, 1e-3)
    ax.set_ylim(lo - pad, hi + pad)
    # the view fits the duties; when the upper limit is off it, the legend says so
    # rather than the duties being squashed to the bottom of a [0, 1] scale
    off = " (1 off scale)" if hi + pad < 1.0 else ""
    for limit in (0.0, 1.0):
        ax.axhline(
            limit, color="0.3", lw=1.2, ls="-.", zorder=1.5, label=f"duty limits 0, 1{off}" if limit == 0.0 else None
        )
    for a, b in ((lo - 10 * pad - 1.0, 0.0), (1.0, hi + 10 * pad + 1.0)):  # beyond the limits
        ax.axhspan(a, b, color="0.5", alpha=0.12, lw=0)
    ax.set_ylabel("rotor duty [-]")
    ax.grid(True, alpha=0.3)


def _reference_xy(results):
    for res, v in results:
        xr, yr = res.state("x_ref")[v], res.state("y_ref")[v]
        if _has(xr) and _has(yr):
            return res.t, xr, yr
    return None


def _saturation_strips(ax, spans: list[dict], min_width: float) -> list:
    """Each flight's saturation as a thin strip in its colour along the bottom of ``ax``
    (light: a limit flagged, dark: a duty clipped); legend proxies for the kinds drawn."""
    from matplotlib.patches import Patch

    drawn = set()
    for k, flight in enumerate(spans):
        y = (0.012 + 0.04 * k, 0.03)
        for kind, alpha in (("flagged", 0.35), ("clipped", 1.0)):
            if shade(ax, flight[kind], min_width=min_width, yrange=y, color=f"C{k}", alpha=alpha) is not None:
                drawn.add(kind)
    return [
        Patch(color="0.35", alpha=alpha, lw=0, label=f"{what} (strip in the flight's colour)")
        for kind, alpha, what in (("flagged", 0.35, "limit flagged"), ("clipped", 1.0, "duty clipped"))
        if kind in drawn
    ]


def plot_paths(results: dict, *, vehicle: int = 0, title: str | None = None, axes: str = "xy") -> Figure:
    """Overlay several flights: top view, position and position error against time.

    Parameters
    ----------
    results : dict of str to SimResult
        Label -> flight, e.g. ``{"NL-PD": res_a, "linear PD": res_b}``.
    vehicle : int
        Which vehicle of each result to draw.
    title : str, optional
        Figure title; by default the labels joined by " vs " and the mission's kind.
    axes : str
        The positions drawn against time, one panel each: ``"xy"`` or ``"xyz"``.

    Returns
    -------
    matplotlib.figure.Figure
        The top view (equal scale), then x [m], y [m] (and z [m]) and the position error
        ``|p - p_ref|`` [m] against time [s]; 4 or 5 axes. The error is on a log scale
        (see :func:`~quadcruise.plots.marks.error_axes`): after the transient the
        controllers' paths lie on top of each other, their errors do not. Each reference
        is taken from the first flight that has a finite one; a flight that stopped early
        ends with a red cross and its label says when. The events recorded in the flights'
        ``meta["environment"]`` are marked on the time panels; each flight's saturation
        (a limit flagged, a duty clipped) is a strip in its colour along the bottom of the
        error panel, drawn only if it happened. One legend, in the top view, names the
        flights and whatever else is drawn.

    Raises
    ------
    ValueError
        If ``results`` is empty or ``axes`` is neither ``"xy"`` nor ``"xyz"``.
    """
    if not results:
        raise ValueError("plot_paths needs at least one result")
    if axes not in ("xy", "xyz"):
        raise ValueError(f"axes must be 'xy' or 'xyz', got {axes!r}")
    spans = [saturation(r, vehicle) for r in results.values()]
    results = {label: drawable(r) for label, r in results.items()}
    fig = Figure(figsize=(13, 8.5 if axes == "xy" else 10.5), layout="constrained")
    gs = fig.add_gridspec(len(axes) + 1, 2, width_ratios=(1, 1.3))
    top = fig.add_subplot(gs[:, 0])
    first = fig.add_subplot(gs[0, 1])
    time_axes = [first] + [fig.add_subplot(gs[i, 1], sharex=first) for i in range(1, len(axes) + 1)]
    ax_e = time_axes[-1]
    ref = _reference_xy([(r, vehicle) for r in results.values()])
    if ref is not None:
        top.plot(ref[1], ref[2], **REF_STYLE)
    for ax, name in zip(time_axes, axes, strict=False):
        for res in results.values():
            if _has(res.state(f"{name}_ref")[vehicle]):
                ax.plot(res.t, res.state(f"{name}_ref")[vehicle], **REF_STYLE)
                break
    curves, events, t_lo, t_hi = [], [], np.inf, -np.inf
    for k, (label, res) in enumerate(results.items()):
        c = f"C{k}"
        x, y = res.state("x")[vehicle], res.state("y")[vehicle]
        stopped = int(res.status[vehicle]) != 0
        if stopped:
            label = f"{label} (stopped at {res.t_stop[vehicle]:.2f} s)"
        top.plot(x, y, color=c, lw=1.4, label=label)
        for ax, name in zip(time_axes, axes, strict=False):
            trace = res.state(name)[vehicle]
            ax.plot(res.t, trace, color=c, lw=1.4, label=label)
            live = np.flatnonzero(np.isfinite(trace))
            if live.size and stopped:
                ax.plot(res.t[live[-1]], trace[live[-1]], "X", color="tab:red", ms=9)
        live = np.isfinite(x) & np.isfinite(y)
        if live.any() and stopped:
            i = np.flatnonzero(live)[-1]
            top.plot(x[i], y[i], "X", color="tab:red", ms=9)
        curves.append((res.t, position_error(res, vehicle), dict(color=c, label=label)))
        events += [e for e in flight_events(res.meta, vehicle) if e not in events]
        t_lo, t_hi = min(t_lo, res.t[0]), max(t_hi, res.t[-1])
    if error_axes(ax_e, curves):
        for t, err, _ in curves:
            live = np.flatnonzero(np.isfinite(err))
            if live.size and live[-1] < err.size - 1:  # it stopped: cross its last error
                ax_e.plot(t[live[-1]], max(err[live[-1]], ERROR_FLOOR), "X", color="tab:red", ms=9)
    strips = _saturation_strips(ax_e, spans, (t_hi - t_lo) / 1500)
    for ax in time_axes:
        mark_events(ax, events, (t_lo, t_hi), label=ax is ax_e)
    top.set_aspect("equal", adjustable="datalim")
    top.set(xlabel="x [m]", ylabel="y [m]", title="top view")
    for ax, name in zip(time_axes, axes, strict=False):
        ax.set_ylabel(f"{name} [m]")
        ax.tick_params(labelbottom=False)
    ax_e.set_xlabel("time [s]")
    for ax in [top] + time_axes[:-1]:
        ax.grid(True, alpha=0.3)
    # one legend, in the top view's spare room: the flights, then what else is drawn
    handles, labels = top.get_legend_handles_labels()
    for h, lb in zip(*ax_e.get_legend_handles_labels(), strict=False):
        if lb not in labels:
            handles.append(h)
            labels.append(lb)
    _legend(top, handles=handles + strips, labels=labels + [h.get_label() for h in strips], loc="best")
    if title is None:
        kind = _names(next(iter(results.values())), vehicle)[1]
        title = " vs ".join(results) + (f" on {kind}" if kind else "")
    fig.suptitle(title)
    return fig


def _pick_paths(ok: np.ndarray, max_paths: int) -> np.ndarray:
    """Up to max_paths vehicle indices: every stopped one first (as many as fit), then
    evenly spread finished ones."""
    max_paths = max(1, max_paths)
    bad, good = np.flatnonzero(~ok)[:max_paths], np.flatnonzero(ok)
    room = min(max_paths - bad.size, good.size)
    good = good[np.unique(np.linspace(0, good.size - 1, room).round().astype(int))] if room > 0 else good[:0]
    return np.sort(np.concatenate([bad, good]))


def plot_envelope(result, *, title: str | None = None, max_paths: int = 50) -> Figure:
    """A batch of N vehicles: their paths from above and the spread of position error.

    Parameters
    ----------
    result : SimResult
        A batched flight.
    title : str, optional
        Figure title; by default what the flight was and the number of vehicles.
    max_paths : int
        At most this many paths are drawn in the top view: those of stopped vehicles
        first, then evenly picked finished ones.

    Returns
    -------
    matplotlib.figure.Figure
        Two axes: the top view (translucent paths: those of stopped vehicles thin, in red,
        underneath those of finished ones, in blue, which stay visible however many
        stopped; vehicle 0's reference dashed) and the median and 5-95 % band over
        vehicles of the position error norm ``|p - p_ref|`` [m] against time [s].
    """
    n = result.n
    fig = Figure(figsize=(13, 5.5), layout="constrained")
    top, ax_e = fig.subplots(1, 2, width_ratios=(1, 1.4))
    picks = _pick_paths(result.ok, max_paths)
    x, y = result.state("x"), result.state("y")
    # the stopped ones first, thin and translucent, underneath; the finished ones on top, as
    # opaque as their number allows, so that many stopped paths do not hide them
    good = picks[result.ok[picks]]
    alpha = float(np.clip(10.0 / max(good.size, 1), 0.35, 0.8))
    for i in picks[~result.ok[picks]]:
        top.plot(x[i], y[i], color="tab:red", lw=0.8, alpha=0.4, zorder=2.0)
        live = np.flatnonzero(np.isfinite(x[i]) & np.isfinite(y[i]))
        if live.size:
            top.plot(x[i, live[-1]], y[i, live[-1]], "x", color="tab:red", ms=6, alpha=0.7, zorder=2.1)
    for i in good:
        top.plot(x[i], y[i], color="tab:blue", lw=1.0, alpha=alpha, zorder=2.2)
    for ok, c, what in ((True, "tab:blue", "finished"), (False, "tab:red", "stopped early")):
        total = int(np.count_nonzero(result.ok == ok))
        if total:  # legend proxies: how many of each kind are drawn
            drawn = int(np.count_nonzero(result.ok[picks] == ok))
            top.plot([], [], color=c, lw=1, label=f"{what} ({drawn} drawn of {total})")
    ref = _reference_xy([(result, 0)])
    if ref is not None:
        top.plot(ref[1], ref[2], **REF_STYLE, zorder=2.5)
    top.set_aspect("equal", adjustable="datalim")
    top.set(xlabel="x [m]", ylabel="y [m]", title="top view")
    _legend(top, loc="upper center", bbox_to_anchor=(0.5, -0.12), ncols=3)
    pos = result.states[:, :, :3]
    err = np.linalg.norm(pos - result.references[:, :, :3], axis=2)
    if _has(err):
        with warnings.catch_warnings():
            warnings.simplefilter("ignore", RuntimeWarning)  # all-NaN instants after stops
            p5, p50, p95 = np.nanpercentile(err, [5, 50, 95], axis=0)
        ax_e.fill_between(result.t, p5, p95, color="tab:blue", alpha=0.25, lw=0, label="5-95 %")
        ax_e.plot(result.t, p50, color="tab:blue", lw=1.5, label="median")
        ax_e.set_ylim(bottom=0)
        _legend(ax_e, loc="best")
    else:
        ax_e.text(
            0.5,
            0.5,
            "no reference: the position error is undefined",
            ha="center",
            va="center",
            transform=ax_e.transAxes,
            color="0.4",
        )
    ax_e.set(xlabel="time [s]", ylabel="position error |p - p_ref| [m]", title=f"position error over {n} vehicles")
    ax_e.set_xlim(result.t[0], result.t[-1])
    for ax in (top, ax_e):
        ax.grid(True, alpha=0.3)
    fig.suptitle(title or f"{describe(result)} — {n} vehicles")
    return fig


def plot_reference(result, *, vehicle: int = 0, title: str | None = None) -> Figure:
    """The reference path of a flight in 3-D with the vehicle's start (the paper's Fig 4).

    Parameters
    ----------
    result : SimResult
        The flight.
    vehicle : int
        The vehicle whose reference and start are drawn.
    title : str, optional
        Axes title; none by default.

    Returns
    -------
    matplotlib.figure.Figure
        One 3-D axes, x, y, z [m]: the reference dashed, the start as a dot.
    """
    fig = Figure(figsize=(7, 6), layout="constrained")
    ax = fig.add_subplot(projection="3d")
    ref = result.references[vehicle]
    start = result.states[vehicle, 0]
    ax.plot(ref[:, 0], ref[:, 1], ref[:, 2], "k--", lw=1.5, label="reference")
    ax.scatter([start[0]], [start[1]], [start[2]], color="tab:green", label="start (hover)")
    ax.set_xlabel("x [m]")
    ax.set_ylabel("y [m]")
    ax.set_zlabel("z [m]")
    if title:
        ax.set_title(title)
    ax.legend(loc="upper left")
    return fig


def save_figure(fig: Figure, path: str | os.PathLike) -> None:
    """Write a figure as PNG (120 dpi), whole or not at all.

    The temporary file that :func:`quadcruise.io.atomic_path` hands out ends in
    ``.tmp``, so the format is given explicitly rather than taken from the suffix.

    Parameters
    ----------
    fig : matplotlib.figure.Figure
        The figure.
    path : str or os.PathLike
        The file to write (PNG whatever its suffix); its folder is created if missing.
    """
    with atomic_path(path) as tmp:
        fig.savefig(tmp, format="png", dpi=120)
