"""What happened during a flight, for marking figures: the disturbance events recorded in
its meta (a gust, a rotor loss), the intervals in which it saturated, and its position
error on a log scale.

Results are read duck-typed: ``t``, ``states``, ``references``, ``commands`` and ``meta``.

Examples
--------
>>> intervals(np.arange(6.0), np.array([0, 1, 1, 0, 0, 1], bool)).tolist()
[[1.0, 3.0], [5.0, 6.0]]
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
from matplotlib.ticker import FuncFormatter, NullFormatter

from quadcruise.layout import CMD_FLAGS, CMD_U1

__all__ = [
    "Event",
    "flight_events",
    "intervals",
    "saturation",
    "position_error",
    "mark_events",
    "shade",
    "error_axes",
    "ERROR_FLOOR",
    "EVENT_COLORS",
    "SATURATION_STYLE",
]

ERROR_FLOOR = 1e-4
"""The smallest position error [m] the error panels show (0.1 mm): an error below it, an
exact zero included, is drawn at it, as a log scale has no zero."""

EVENT_COLORS = {"gust": "tab:cyan", "rotor_loss": "tab:brown"}
"""The colour of each kind of event."""

SATURATION_STYLE = {
    "flagged": dict(color="tab:red", alpha=0.15, label="controller limit flagged"),
    "clipped": dict(color="tab:purple", alpha=0.25, hatch="////", label="duty clipped (asked outside [0, 1])"),
}
"""How the intervals of :func:`saturation` are shaded, and their legend entries."""


@dataclass(frozen=True)
class Event:
    """Something that happened to a vehicle during its flight."""

    kind: str
    start: float
    end: float
    label: str


def _pick(value, vehicle: int):
    """One vehicle's number from a scalar or a per-vehicle list; None if not a number."""
    if isinstance(value, list | tuple | np.ndarray):
        if len(value) == 0:
            return None
        value = value[min(vehicle, len(value) - 1)]
    try:
        value = float(value)
    except (TypeError, ValueError):
        return None
    return value if math.isfinite(value) else None


def flight_events(meta, vehicle: int = 0) -> list[Event]:
    """The events of ``meta["environment"]`` (as ``Environment.to_dict()`` writes it); none from a malformed one.

    Examples
    --------
    >>> env = {"gust": {"amplitude": [3.0, 4.0, 0.0], "start": 2.0, "duration": 1.5},
    ...        "rotor_loss": {"rotor": [1, 2], "fraction": 0.3, "time": 8.0}, "wind": None}
    >>> [e.label for e in flight_events({"environment": env}, vehicle=1)]
    ['gust 5 m/s, 2-3.5 s', 'rotor 2 loses 30 % at 8 s']
    """
    env = meta.get("environment") if isinstance(meta, dict) else None
    if not isinstance(env, dict):
        return []
    out = []
    gust = env.get("gust")
    if isinstance(gust, dict):
        start, duration = _pick(gust.get("start"), vehicle), _pick(gust.get("duration"), vehicle)
        if start is not None and duration is not None and duration > 0:
            amplitude = gust.get("amplitude")
            parts = [_pick(a, vehicle) for a in amplitude] if isinstance(amplitude, list | tuple) else []
            peak = f" {math.hypot(*parts):.3g} m/s" if parts and None not in parts else ""
            out.append(Event("gust", start, start + duration, f"gust{peak}, {start:g}-{start + duration:g} s"))
    loss = env.get("rotor_loss")
    if isinstance(loss, dict):
        time = _pick(loss.get("time"), vehicle)
        if time is not None:
            rotor, fraction = _pick(loss.get("rotor"), vehicle), _pick(loss.get("fraction"), vehicle)
            who = f"rotor {rotor:.0f}" if rotor is not None else "a rotor"
            what = f"loses {100 * fraction:.0f} %" if fraction is not None else "loses thrust"
            out.append(Event("rotor_loss", time, time, f"{who} {what} at {time:g} s"))
    return out


def intervals(t: np.ndarray, mask: np.ndarray) -> np.ndarray:
    """The time intervals over which ``mask`` holds, each sample holding until the next."""
    t, mask = np.asarray(t, float), np.asarray(mask, bool)
    if not mask.any():
        return np.zeros((0, 2))
    edges = np.diff(np.r_[0, mask.astype(np.int8), 0])
    first, stop = np.flatnonzero(edges == 1), np.flatnonzero(edges == -1)
    step = t[-1] - t[-2] if t.size > 1 else 0.0
    ends = np.r_[t, t[-1] + step][stop]
    return np.column_stack([t[first], ends])


def saturation(result, vehicle: int = 0) -> dict[str, np.ndarray]:
    """When a vehicle's controller flagged a limit, and when a duty it asked for was clipped."""
    cmd = result.commands[vehicle]
    flags = cmd[:, CMD_FLAGS]
    duties = cmd[:, CMD_U1 : CMD_U1 + 4]
    with np.errstate(invalid="ignore"):
        clipped = np.any((duties < 0.0) | (duties > 1.0), axis=1)  # NaN after a stop: False
    return {"flagged": intervals(result.t, np.isfinite(flags) & (flags != 0)), "clipped": intervals(result.t, clipped)}


def position_error(result, vehicle: int = 0) -> np.ndarray:
    """The norm of the 3-D position error ``|p - p_ref|`` [m] at each logged instant."""
    d = result.states[vehicle, :, :3] - result.references[vehicle, :, :3]
    return np.sqrt(np.sum(d * d, axis=1))


def mark_events(ax, events, t_range, *, label: bool = True) -> list[Event]:
    """Draw events on a time axes: a gust as a band, a rotor loss as a vertical line."""
    lo, hi = t_range
    drawn = []
    for e in events:
        if e.end < lo or e.start > hi:
            continue
        color = EVENT_COLORS.get(e.kind, "0.4")
        text = e.label if label else None
        if e.end > e.start:
            ax.axvspan(e.start, e.end, color=color, alpha=0.18, lw=0, zorder=0.5, label=text)
        else:
            ax.axvline(e.start, color=color, lw=1.6, ls=(0, (6, 2, 1, 2)), zorder=1.8, label=text)
        drawn.append(e)
    return drawn


def shade(ax, spans: np.ndarray, *, min_width: float = 0.0, yrange=(0.0, 1.0), **style):
    """Shade time intervals over the height of an axes, as one collection; intervals closer than
    ``min_width`` [s] merge, each drawn at least that wide."""
    spans = np.asarray(spans, float).reshape(-1, 2)
    if not spans.size:
        return None
    merged = [list(spans[0])]
    for a, b in spans[1:]:
        if a - merged[-1][1] <= min_width:
            merged[-1][1] = max(merged[-1][1], b)
        else:
            merged.append([a, b])
    bars = [(a, max(b - a, min_width)) for a, b in merged]
    return ax.broken_barh(bars, yrange, transform=ax.get_xaxis_transform(), lw=0, zorder=0.6, **style)


def _tick(value: float, _pos=None) -> str:
    """A log axis tick as a plain number, or as 1e-4 below a millimetre (narrower)."""
    return f"{value:g}" if value >= 1e-3 else f"{value:.0e}".replace("e-0", "e-")


def error_axes(ax, curves) -> bool:
    """Draw position errors against time on a log scale, values below :data:`ERROR_FLOOR` at it;
    False if none is finite."""
    # A log scale shows the error through its whole range: metres in a transient and millimetres
    # while tracking, which a linear axis scaled to the transient flattens onto zero. The y range
    # runs from the decade below the least error shown to just above the largest, at least two
    # decades labelled as plain numbers.
    finite = [e[np.isfinite(e)] for _, e, _ in curves]
    values = np.concatenate(finite) if finite else np.zeros(0)
    ax.set_ylabel("position error [m]")
    if not values.size:
        ax.text(
            0.5,
            0.5,
            "no reference: the position error is undefined",
            ha="center",
            va="center",
            transform=ax.transAxes,
            color="0.4",
        )
        ax.set_yticks([])
        return False
    for t, e, style in curves:
        ax.plot(t, np.maximum(e, ERROR_FLOOR), **{"lw": 1.3, **style})
    ax.set_yscale("log")
    top = max(float(values.max()), 10 * ERROR_FLOOR)
    low = max(float(values.min()), ERROR_FLOOR)
    ax.set_ylim(10.0 ** math.floor(math.log10(min(low, top / 10) / 1.5)), top * 1.6)  # two decades at least
    if values.min() < ERROR_FLOOR:
        ax.axhline(
            ERROR_FLOOR, color="0.55", lw=0.8, ls=":", zorder=1.2, label=f"≤ {ERROR_FLOOR * 1e3:g} mm (drawn here)"
        )
    ax.yaxis.set_major_formatter(FuncFormatter(_tick))
    ax.yaxis.set_minor_formatter(NullFormatter())
    ax.grid(True, which="major", alpha=0.3)
    ax.grid(True, which="minor", alpha=0.1)
    return True
