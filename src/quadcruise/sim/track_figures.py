"""``fly``'s track checks inside the kernels: each vehicle's running figures, updated at every
control period from the position and the reference the kernel already has, whatever its log
keeps; :class:`~quadcruise.workflows.track_watch.TrackWatch` reads the verdict from them.

A vehicle's figures are one :data:`TRACK` row (:func:`fresh_track`), carried from one kernel
call to the next like the kernel's other carry (a flight cut into steps is bit for bit the
flight flown in one); the flight's :data:`TRACK_PLAN` (the step, the head, the last quarter)
is one row shared by the batch. In the period loop they are tuples of floats (:func:`take_track`,
:func:`track_period`, :func:`put_track`), the scalar-only rule of :mod:`quadcruise.sim.fastmath`:
no array is handed to the helper that runs every period. A plan whose ``on`` is 0 turns the
checks off (the kernel then passes over them; ``rows`` may be (N, 0)).

What the figures mean: :mod:`quadcruise.workflows.track_watch`'s docstring. Periods are grid
indices held as floats (-1: none yet), flags 0 or 1.

Examples
--------
>>> import numpy as np
>>> from quadcruise.control import NLPD
>>> from quadcruise.missions import Circle
>>> from quadcruise.model.vehicle import Vehicle
>>> from quadcruise.sim.engine import simulate
>>> from quadcruise.sim.inputs import time_grid
>>> t, v = time_grid(1.0, 1e-3), Vehicle.paper()
>>> x0 = np.zeros(16); x0[2] = 1.0; x0[12:] = v.m * v.g / 4     # hovering at 1 m, 2 m off the circle
>>> rows, plan = fresh_track(2, np.array([0.5, 9.0])), track_plan(t)
>>> r = simulate(t, x0, v.rows(2), NLPD().function, NLPD().gains(), Circle().function, Circle().params(),
...              memory=NLPD().memory(), log_every=100, track=(rows, plan))
>>> rows[:, TR_LOST].tolist()                                   # the first period beyond 0.5 m; none beyond 9 m
[0.0, -1.0]
"""

from __future__ import annotations

import math

import numpy as np
from numba import njit

from quadcruise.errors import InputError
from quadcruise.layout import Row
from quadcruise.metrics.tracking import FINAL_FRACTION, STEADY_BAND, TRANSIENT_MIN_ERROR

TRACK = Row.of(
    "track figures",
    # periods: the first beyond the tracking bound (lost), beyond the steady bounds (first_off),
    # beyond them at or after the last excursion's anchor and after it (since, since_after), beyond
    # them in the second half (tail_first); the anchor (the first period at or after the excursion's
    # sample); a still reference's axis; the last period of the head beyond them
    "lost",
    "first_off",
    "since",
    "since_after",
    "tail_first",
    "ev_anchor",
    "hold_axis",
    "last_beyond",
    # the reference's largest move; the largest error over the last quarter (level) and over the
    # second half; the last excursion's time and response, and the next sample's; a still
    # reference's initial error on its axis; the step axis's position at the previous period; the
    # error at the start (e0), its largest value in the head after last_beyond, at the head's last
    # three periods; the reference at the start
    "moved",
    "level",
    "tail_max",
    "ev_tau",
    "ev_tau1",
    "ev_z",
    "ev_z1",
    "hold_e0",
    "prev_pos",
    "e0",
    "after_max",
    ("end_err", 3),
    ("ref0", 3),
    # flags: the error finite throughout; beyond the bounds at the last period; the response out
    # of the band there; the next sample still to come; beyond at the previous period; a still
    # reference's transient measured
    "finite",
    "off_at_end",
    "out_at_end",
    "pending",
    "prev_beyond",
    "hold_measured",
    # the vehicle's bounds [m]: tracking, steady (3-D error), altitude error
    "track_bound",
    "steady_bound",
    "altitude_bound",
    prefix="TR_",
)
"""A vehicle's running figures of the track checks (one float64 row)."""
(
    TR_LOST, TR_FIRST_OFF, TR_SINCE, TR_SINCE_AFTER, TR_TAIL_FIRST, TR_EV_ANCHOR, TR_HOLD_AXIS, TR_LAST_BEYOND,
    TR_MOVED, TR_LEVEL, TR_TAIL_MAX, TR_EV_TAU, TR_EV_TAU1, TR_EV_Z, TR_EV_Z1, TR_HOLD_E0, TR_PREV_POS, TR_E0,
    TR_AFTER_MAX, TR_END_ERR, TR_REF0, TR_FINITE, TR_OFF_AT_END, TR_OUT_AT_END, TR_PENDING, TR_PREV_BEYOND,
    TR_HOLD_MEASURED, TR_TRACK_BOUND, TR_STEADY_BOUND, TR_ALTITUDE_BOUND,
) = TRACK.offsets  # fmt: skip

TRACK_PLAN = Row.of(
    "track plan",
    "on",  # 1: checks made; 0: none
    "step",  # 1: the mission is a step on one axis
    "followed",  # 1: its response is followed (the step within the grid; always, without a step)
    "axis",  # the step's axis (0, 1, 2)
    "after",  # the first period after the step's instant
    "anchor",  # the step instant's anchor: the first period at or after it
    "kept",  # periods of the head (0: a step, never a moving reference)
    "final_from",  # the first period of the last quarter
    "last",  # the grid's last period
    "t_step",  # the step's time [s] (the grid's first instant without a step)
    "y0",  # the step's start [m]
    "size",  # and size [m]
    "t_before",  # the instants [s] of periods after - 1 and after
    "t_after",
    prefix="TP_",
)
"""The flight's plan of the track checks, shared by its vehicles (one float64 row)."""
(
    TP_ON, TP_STEP, TP_FOLLOWED, TP_AXIS, TP_AFTER, TP_ANCHOR, TP_KEPT, TP_FINAL_FROM, TP_LAST, TP_T_STEP, TP_Y0,
    TP_SIZE, TP_T_BEFORE, TP_T_AFTER,
) = TRACK_PLAN.offsets  # fmt: skip

TOLERANCE = 1e-12
"""An instant this close [s] before the end of the transient counts as after it (as in
:func:`~quadcruise.workflows.fly_failures.off_track_since`)."""
TRACK_SIZE = TRACK.size
"""Entries of a :data:`TRACK` row."""
NO_FIGURES = (0.0,) * TRACK_SIZE
"""The figures a kernel carries when the checks are off."""


def track_plan(t: np.ndarray, mission: dict | None = None) -> np.ndarray:
    """The plan of the track checks of a flight over the control instants ``t``.

    Parameters
    ----------
    t : numpy.ndarray
        (L,) the flight's control instants [s].
    mission : dict, optional
        The mission's ``to_dict()`` (``{}`` or None for one mission per vehicle): a step is a step.

    Returns
    -------
    numpy.ndarray
        (:data:`TRACK_PLAN` size,) the plan, ``on`` set.

    Examples
    --------
    >>> p = track_plan(np.linspace(0.0, 2.0, 2001), {"kind": "step", "axis": "x", "time": 1.0, "x": 0.0, "size": 1.0})
    >>> int(p[TP_AFTER]), int(p[TP_ANCHOR]), int(p[TP_KEPT])     # a step: no head
    (1001, 1000, 0)
    """
    mission = mission or {}
    t = np.ascontiguousarray(t, dtype=float)
    length = t.size
    kind_step = mission.get("kind") == "step"  # never a moving reference
    step = kind_step and mission.get("axis") in ("x", "y", "z")
    followed, t_step, axis, before, after, anchor0, y0, size = True, float(t[0]), 0, 0, 0, 0, 0.0, 1.0
    if step:
        axis, t_step = "xyz".index(mission["axis"]), float(mission["time"])
        y0, size = float(mission[mission["axis"]]), float(mission["size"])
        followed = bool(t[0] <= t_step < t[-1])
        if followed:
            before = int(np.searchsorted(t, t_step, side="right")) - 1
            after = before + 1  # the first instant after the step
            anchor0 = before if t[before] >= t_step - TOLERANCE else after
    span = t[-1] - t[0]
    final = t >= t[-1] - FINAL_FRACTION * span
    if final.sum() < 2:
        final[-2:] = True
    held = t[-1] - 2.0 * FINAL_FRACTION * span
    margin = 1e-9 * max(1.0, abs(held))  # after the head, t > held + margin: too late to settle
    kept = 0 if kind_step else min(length, int(np.searchsorted(t, held + margin, side="right")) + 1)
    t_before, t_after = (float(t[before]), float(t[after])) if step and followed else (0.0, 0.0)
    return TRACK_PLAN.pack(
        dict(
            on=1, step=step, followed=followed, axis=axis, after=after, anchor=anchor0, kept=kept,
            final_from=int(np.argmax(final)), last=length - 1, t_step=t_step, y0=y0, size=size,
            t_before=t_before, t_after=t_after,
        )
    )  # fmt: skip


def no_track(n: int) -> tuple[np.ndarray, np.ndarray]:
    """The ``(rows, plan)`` of a flight of ``n`` vehicles without track checks.

    Parameters
    ----------
    n : int
        Number of vehicles.

    Returns
    -------
    tuple of numpy.ndarray
        (n, 0) rows and a plan whose ``on`` is 0.
    """
    return np.zeros((n, 0)), np.zeros(TRACK_PLAN.size)


def track_arrays(track, n: int) -> tuple[np.ndarray, np.ndarray]:
    """A flight's ``(rows, plan)`` checked (what the kernel writes must fit), or :func:`no_track`.

    Parameters
    ----------
    track : tuple of numpy.ndarray or None
        ``(rows, plan)``: (n, :data:`TRACK` size) C-ordered float64 rows, written in place, and
        a (:data:`TRACK_PLAN` size,) plan.
    n : int
        Number of vehicles.

    Returns
    -------
    tuple of numpy.ndarray

    Raises
    ------
    InputError
        Arrays of another shape, type or order.
    """
    if track is None:
        return no_track(n)
    rows, plan = track
    on = isinstance(plan, np.ndarray) and plan.shape == (TRACK_PLAN.size,) and plan.dtype == np.float64
    width = TRACK.size if on and plan[TP_ON] != 0.0 else None
    if not (
        on
        and isinstance(rows, np.ndarray)
        and rows.dtype == np.float64
        and rows.flags.c_contiguous
        and rows.ndim == 2
        and rows.shape[0] == n
        and (width is None or rows.shape[1] == width)
    ):
        raise InputError(
            f"track: (rows, plan) must be ({n}, {TRACK.size}) C-ordered float64 rows and a ({TRACK_PLAN.size},) "
            f"float64 plan, got {getattr(rows, 'shape', type(rows).__name__)} and "
            f"{getattr(plan, 'shape', type(plan).__name__)}"
        )
    return rows, np.ascontiguousarray(plan)


def fresh_track(n: int, track_bound, steady_bound=np.inf, altitude_bound=np.inf, plan=None) -> np.ndarray:
    """The rows of ``n`` vehicles about to start their flight.

    Parameters
    ----------
    n : int
        Number of vehicles.
    track_bound, steady_bound, altitude_bound : float or numpy.ndarray
        The bounds [m] (one or one per vehicle; ``inf`` turns one off).
    plan : numpy.ndarray, optional
        The flight's :func:`track_plan` (its step's anchor); none: anchor 0.

    Returns
    -------
    numpy.ndarray
        (n, :data:`TRACK` size).
    """
    rows = np.full((n, TRACK.size), np.nan)
    rows[:, TRACK.offsets[:8]] = -1.0
    rows[:, TR_EV_ANCHOR] = 0.0 if plan is None else plan[TP_ANCHOR]
    rows[:, [TR_MOVED, TR_PREV_POS]] = 0.0
    rows[:, [TR_LEVEL, TR_TAIL_MAX, TR_AFTER_MAX]] = -np.inf
    rows[:, TR_FINITE : TR_HOLD_MEASURED + 1] = 0.0
    rows[:, TR_FINITE] = 1.0
    rows[:, TR_TRACK_BOUND] = track_bound
    rows[:, TR_STEADY_BOUND] = steady_bound
    rows[:, TR_ALTITUDE_BOUND] = altitude_bound
    return rows


@njit(cache=True, inline="always")
def take_plan(plan):
    """The plan as a tuple of floats (once per kernel call)."""
    return (
        plan[0], plan[1], plan[2], plan[3], plan[4], plan[5], plan[6], plan[7], plan[8], plan[9], plan[10],
        plan[11], plan[12], plan[13],
    )  # fmt: skip


@njit(cache=True, inline="always")
def take_track(rows, i, on):
    """Vehicle i's figures as a tuple of floats (:data:`NO_FIGURES` when the checks are off)."""
    if not on:
        return NO_FIGURES
    r = rows[i]
    return (
        r[0], r[1], r[2], r[3], r[4], r[5], r[6], r[7], r[8], r[9], r[10], r[11], r[12], r[13], r[14], r[15],
        r[16], r[17], r[18], r[19], r[20], r[21], r[22], r[23], r[24], r[25], r[26], r[27], r[28], r[29],
        r[30], r[31], r[32], r[33],
    )  # fmt: skip


@njit(cache=True, inline="always")
def put_track(rows, i, on, fig):
    """Vehicle i's figures written back (nothing when the checks are off)."""
    if on:
        for j in range(TRACK_SIZE):
            rows[i, j] = fig[j]


@njit(cache=True, inline="always")
def track_period(g, tg, px, py, pz, rx, ry, rz, fig, plan):
    """The figures after period ``g`` (instant ``tg`` [s]) of a vehicle at ``(px, py, pz)`` [m],
    its reference at ``(rx, ry, rz)`` [m]: scalars and tuples of floats in and out.

    The error is ``e = |p - r|`` (as :func:`~quadcruise.workflows.fly_failures.position_error`);
    beyond the steady bounds means ``e > steady_bound or |pz - rz| > altitude_bound``; lost
    track: ``e > track_bound``. The step's response at its own instant is interpolated between
    the periods around it as ``numpy.interp`` does (``metrics.transient_batch``)."""
    (
        lost, first_off, since, since_after, tail_first, ev_anchor, hold_axis, last_beyond,
        moved, level, tail_max, ev_tau, ev_tau1, ev_z, ev_z1, hold_e0, prev_pos, e0, after_max,
        end0, end1, end2, r0x, r0y, r0z,
        finite, off_at_end, out_at_end, pending, prev_beyond, hold_measured,
        b_track, b_steady, b_alt,
    ) = fig  # fmt: skip
    _, step, followed, axis, after, anchor0, kept, final_from, last_g, t_step, y0, size, t0, t1 = plan
    dx, dy, dz = px - rx, py - ry, pz - rz
    err = math.sqrt(dx * dx + dy * dy + dz * dz)
    over = err > b_steady or abs(dz) > b_alt
    if lost < 0.0 and err > b_track:
        lost = g
    if first_off < 0.0 and over:
        first_off = g
    if not math.isfinite(err):
        finite = 0.0
    if g == 0:  # where the reference starts; a still reference's error: its largest axis
        r0x, r0y, r0z = rx, ry, rz
        ex, ey, ez = abs(rx - px), abs(ry - py), abs(rz - pz)
        hold_axis, best, hold_e0 = 0.0, ex, rx - px
        if ey > best:
            hold_axis, best, hold_e0 = 1.0, ey, ry - py
        if ez > best:
            hold_axis, best, hold_e0 = 2.0, ez, rz - pz
        hold_measured = 1.0 if best >= TRANSIENT_MIN_ERROR else 0.0
    mx, my, mz = abs(rx - r0x), abs(ry - r0y), abs(rz - r0z)
    if mx > moved:  # NaN (stopped) ignored, as numpy.fmax
        moved = mx
    if my > moved:
        moved = my
    if mz > moved:
        moved = mz
    if kept > 0.0:
        if g < kept:  # the head: what its end of the transient needs
            if g == 0:
                e0 = err
            if over:
                last_beyond, after_max = g, -np.inf
            elif err > after_max:
                after_max = err
            slot = g - (kept - 3.0)
            if slot == 0.0:
                end0 = err
            elif slot == 1.0:
                end1 = err
            elif slot == 2.0:
                end2 = err
        else:
            if err > tail_max:
                tail_max = err
            if tail_first < 0.0 and over:
                tail_first = g
        if g >= final_from and err > level:
            level = err
    pos = px if axis == 0.0 else py if axis == 1.0 else pz  # the step's axis
    if followed != 0.0:
        # the response's samples in time order: a step's own instant (interpolated, its anchor
        # the grid's instant at or after it), then the grid's; each fills a pending excursion's
        # next sample, or starts a new excursion out of the band
        for part in range(2):
            if step != 0.0:
                if part == 0 and g != after or g < after:
                    continue
                if part == 0:  # numpy.interp(t_step, (t0, t1), (prev_pos, pos))
                    if t_step == t0:
                        ys0 = prev_pos
                    else:
                        slope = (pos - prev_pos) / (t1 - t0)
                        ys0 = slope * (t_step - t0) + prev_pos
                        if math.isnan(ys0):
                            ys0 = slope * (t_step - t1) + pos
                            if math.isnan(ys0) and prev_pos == pos:
                                ys0 = prev_pos
                    z, tau, anchor, anchor_over = (ys0 - y0) / size, t_step, anchor0, prev_beyond != 0.0
                else:
                    z, tau, anchor, anchor_over = (pos - y0) / size, tg, float(g), over
            else:
                if part == 0:
                    continue
                e = (rx - px) if hold_axis == 0.0 else (ry - py) if hold_axis == 1.0 else (rz - pz)
                z, tau, anchor, anchor_over = 1.0 - e / hold_e0, tg, float(g), over
            if pending != 0.0:
                ev_z1, ev_tau1, pending = z, tau, 0.0
            out = abs(z - 1.0) > STEADY_BAND
            if out:
                ev_tau, ev_z, ev_z1, ev_tau1, pending, ev_anchor = tau, z, np.nan, np.nan, 1.0, anchor
                since = anchor if anchor < g and anchor_over else -1.0
                since_after = -1.0
            if g == last_g and part == 1:
                out_at_end = 1.0 if out else 0.0
        if over:
            if since < 0.0 and g >= ev_anchor:
                since = g
            if since_after < 0.0 and g >= ev_anchor + 1.0:
                since_after = g
    if g == last_g:
        off_at_end = 1.0 if over else 0.0
    prev_beyond = 1.0 if over else 0.0
    if step != 0.0:
        prev_pos = pos
    return (
        float(lost), float(first_off), float(since), float(since_after), float(tail_first), float(ev_anchor),
        hold_axis, float(last_beyond), moved, level, tail_max, ev_tau, ev_tau1, ev_z, ev_z1, hold_e0, prev_pos,
        e0, after_max, end0, end1, end2, r0x, r0y, r0z,
        finite, off_at_end, out_at_end, pending, prev_beyond, hold_measured,
        b_track, b_steady, b_alt,
    )  # fmt: skip


__all__ = [
    "TRACK",
    "TRACK_PLAN",
    "fresh_track",
    "no_track",
    "put_track",
    "track_arrays",
    "take_plan",
    "take_track",
    "track_period",
    "track_plan",
]
