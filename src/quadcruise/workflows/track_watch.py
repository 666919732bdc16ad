"""``fly``'s lost-track and off-track checks, computed as the flight goes, at every control
period, while the log keeps only every ``log_every``-th: the statuses and times that
:func:`~quadcruise.workflows.fly_failures.mark_lost_track` and :func:`~quadcruise.workflows.fly_failures.mark_off_track`
give on the full log (``log_every=1``), without that log, in memory that does not grow with the
flight's length (a fixed number of figures per vehicle).

What each check needs of the whole flight, and what is kept for it (per vehicle):

- lost track: the first instant the position error exceeds the tracking bound;
- off track: the first instant beyond the steady bounds after the transient, which ends
  where the error last left the 5 % band (:data:`~quadcruise.metrics.STEADY_BAND`):

  * a step, or a reference that holds still: the band is known from the first instant
    (the step's size, the initial error), so the last excursion out of it is followed as the
    flight goes, with the first instant beyond the bounds since it;
  * a moving reference: the band is measured from the error's level ``E`` over the last quarter
    of the flight (:func:`~quadcruise.metrics.tracking_transient_batch`), known only at the
    end; the transient counts only if it ended in the first half (the head). Kept: the
    initial error, the last instant of the head beyond the bounds and the largest error
    after it, the head's last three errors, and of the second half the largest error, the
    level and the first instant beyond. If the error after the head's last instant beyond
    the bounds rose above the band (the usual case: the entry from a start away from the
    path), the transient ended after that instant, and the answer is the first instant
    beyond in the second half (or none, or the end if it never settled), found from these
    figures alone. Otherwise (a vehicle whose error sits near the bound, found only at the
    end) the head of those vehicles alone is flown again (``again``, the same flight bit
    for bit), in groups of at most :data:`HEAD_BYTES`, and read with ``E`` known.

docs/performance.md ("A batch that fits in memory") says why this way and what it costs.
"""

from __future__ import annotations

import math
from typing import TYPE_CHECKING

import numpy as np
from numba import njit

from quadcruise.layout import REF_X, X
from quadcruise.metrics.tracking import FINAL_FRACTION, STEADY_BAND, TRANSIENT_MIN_ERROR
from quadcruise.sim.status import ExitStatus

if TYPE_CHECKING:
    from collections.abc import Callable

TOLERANCE = 1e-12
"""An instant this close [s] before the end of the transient counts as after it (as in
:func:`~quadcruise.workflows.fly_failures.off_track_since`)."""
HEAD_BYTES = 2**26
"""Most bytes [B] of head rows (9 a vehicle-period) kept at once when the head of the vehicles
whose verdict the kept figures leave open is flown again: 64 MiB, a group of vehicles per
flight again (a 10 s flight at 1 kHz: about 1,500 vehicles a group)."""
AMBIGUOUS = -2
"""The answer of :func:`_moving_summary` for a vehicle whose head must be read again."""


# columns of the per-vehicle rows the compiled pass keeps (periods as grid indices, -1: none yet).
# ints: the first period beyond the tracking bound (LOST), beyond the steady bounds (FIRST_OFF), beyond
# them at or after the last excursion's anchor and after it (SINCE, SINCE_AFTER), beyond them in the
# second half (TAIL_FIRST); the anchor (EV_ANCHOR: the first period at or after the excursion's
# sample); a still reference's axis (HOLD_AXIS); the last period of the head beyond them (LAST_BEYOND).
# floats: the reference's largest move (MOVED); the largest error over the last quarter (LEVEL) and
# over the second half (TAIL_MAX); the last excursion's time and response, and the next sample's
# (EV_TAU, EV_Z, EV_TAU1, EV_Z1); a still reference's initial error on its axis (HOLD_E0); the step
# axis's position at the previous period (PREV_POS); the error at the start (E0), its largest value in
# the head after LAST_BEYOND (AFTER_MAX), at the head's last three periods (END_ERR, 3 columns); the
# reference at the start (REF0, 3 columns).
# flags: the error finite throughout (FINITE); beyond the bounds at the last period (OFF_AT_END); the
# response out of the band there (OUT_AT_END); the next sample still to come (PENDING); beyond at
# the previous period (PREV_BEYOND); a still reference's transient measured (HOLD_MEASURED).
LOST, FIRST_OFF, SINCE, SINCE_AFTER, TAIL_FIRST, EV_ANCHOR, HOLD_AXIS, LAST_BEYOND = range(8)
MOVED, LEVEL, TAIL_MAX, EV_TAU, EV_TAU1, EV_Z, EV_Z1, HOLD_E0, PREV_POS, E0, AFTER_MAX = range(11)
END_ERR, REF0 = 11, 14  # 3 columns each
INT_WIDTH, FLOAT_WIDTH, FLAG_WIDTH = 8, REF0 + 3, 6
FINITE, OFF_AT_END, OUT_AT_END, PENDING, PREV_BEYOND, HOLD_MEASURED = range(6)


@njit(cache=True, nogil=True, error_model="numpy")
def _watch_chunk(
    k0, first, stop, xs, refs, c, t, track_bound, bound, zbound,
    ints, floats, flags, plan, step_plan, virtual,
):  # fmt: skip
    """The instants k0 .. k0 + c - 1 of vehicles first..stop-1, in time order (:meth:`TrackWatch.feed`).

    ``plan``: step (1 or 0), followed (1 or 0), the step's axis, the first instant after the
    step, the anchor of the step's instant, kept, final_from; ``step_plan``: the step's time
    [s], start and size [m]; ``virtual``: the response at the step's instant where this chunk
    holds the instant after it. A vehicle's rows are read into scalars and written back at
    its end (the scalar-only rule of :mod:`quadcruise.sim.fastmath`)."""
    step, followed, axis, after, anchor0 = plan[0], plan[1], plan[2], plan[3], plan[4]
    kept, final_from = plan[5], plan[6]
    t_step, y0, size = step_plan[0], step_plan[1], step_plan[2]
    last_g = t.shape[0] - 1
    for i in range(first, stop):
        lost, first_off, since, since_after = ints[i, LOST], ints[i, FIRST_OFF], ints[i, SINCE], ints[i, SINCE_AFTER]
        tail_first, ev_anchor, hold_axis = ints[i, TAIL_FIRST], ints[i, EV_ANCHOR], ints[i, HOLD_AXIS]
        last_beyond = ints[i, LAST_BEYOND]
        moved, level, tail_max = floats[i, MOVED], floats[i, LEVEL], floats[i, TAIL_MAX]
        e0, after_max = floats[i, E0], floats[i, AFTER_MAX]
        end0, end1, end2 = floats[i, END_ERR], floats[i, END_ERR + 1], floats[i, END_ERR + 2]
        ev_tau, ev_tau1, ev_z, ev_z1 = floats[i, EV_TAU], floats[i, EV_TAU1], floats[i, EV_Z], floats[i, EV_Z1]
        hold_e0, prev_pos = floats[i, HOLD_E0], floats[i, PREV_POS]
        r0x, r0y, r0z = floats[i, REF0], floats[i, REF0 + 1], floats[i, REF0 + 2]
        finite, off_at_end, out_at_end = flags[i, FINITE], flags[i, OFF_AT_END], flags[i, OUT_AT_END]
        pending, prev_beyond, hold_measured = flags[i, PENDING], flags[i, PREV_BEYOND], flags[i, HOLD_MEASURED]
        b_track, b_steady, b_alt = track_bound[i], bound[i], zbound[i]
        for col in range(c):
            g = k0 + col
            px, py, pz = xs[i, col, X], xs[i, col, X + 1], xs[i, col, X + 2]
            rx, ry, rz = refs[i, col, REF_X], refs[i, col, REF_X + 1], refs[i, col, REF_X + 2]
            dx, dy, dz = px - rx, py - ry, pz - rz
            err = math.sqrt(dx * dx + dy * dy + dz * dz)  # as fly.position_error
            over = err > b_steady or abs(dz) > b_alt
            if lost < 0 and err > b_track:
                lost = g
            if first_off < 0 and over:
                first_off = g
            if not math.isfinite(err):
                finite = False
            if g == 0:  # where the reference starts; a still reference's error: its largest axis
                r0x, r0y, r0z = rx, ry, rz
                ex, ey, ez = abs(rx - px), abs(ry - py), abs(rz - pz)
                hold_axis, best, hold_e0 = 0, ex, rx - px
                if ey > best:
                    hold_axis, best, hold_e0 = 1, ey, ry - py
                if ez > best:
                    hold_axis, best, hold_e0 = 2, ez, rz - pz
                hold_measured = best >= TRANSIENT_MIN_ERROR
            for moved_k in (abs(rx - r0x), abs(ry - r0y), abs(rz - r0z)):
                if moved_k > moved:  # NaN (stopped) ignored, as numpy.fmax
                    moved = moved_k
            if kept > 0:
                if g < kept:  # the head: what its end of the transient needs (_moving_summary)
                    if g == 0:
                        e0 = err
                    if over:
                        last_beyond, after_max = g, -np.inf
                    elif err > after_max:
                        after_max = err
                    slot = g - (kept - 3)
                    if slot == 0:
                        end0 = err
                    elif slot == 1:
                        end1 = err
                    elif slot == 2:
                        end2 = err
                else:
                    if err > tail_max:
                        tail_max = err
                    if tail_first < 0 and over:
                        tail_first = g
                if g >= final_from and err > level:
                    level = err
            if followed:
                # the response's samples in time order: a step's own instant (interpolated, its
                # anchor the grid's instant at or after it), then the grid's; each fills a pending
                # excursion's next sample, or starts a new excursion out of the band
                for part in range(2):
                    if step:
                        if part == 0 and g != after or g < after:
                            continue
                        z = virtual[i] if part == 0 else (xs[i, col, X + axis] - y0) / size
                        tau, anchor, anchor_over = (t_step, anchor0, prev_beyond) if part == 0 else (t[g], g, over)
                    else:
                        if part == 0:
                            continue
                        e = (rx - px) if hold_axis == 0 else (ry - py) if hold_axis == 1 else (rz - pz)
                        z, tau, anchor, anchor_over = 1.0 - e / hold_e0, t[g], g, over
                    if pending:
                        ev_z1, ev_tau1, pending = z, tau, False
                    out = abs(z - 1.0) > STEADY_BAND
                    if out:
                        ev_tau, ev_z, ev_z1, ev_tau1, pending, ev_anchor = tau, z, np.nan, np.nan, True, anchor
                        since = anchor if anchor < g and anchor_over else -1
                        since_after = -1
                    if g == last_g and part == 1:
                        out_at_end = out
                if over:
                    if since < 0 and g >= ev_anchor:
                        since = g
                    if since_after < 0 and g >= ev_anchor + 1:
                        since_after = g
            if g == last_g:
                off_at_end = over
            prev_beyond = over
            if step:
                prev_pos = xs[i, col, X + axis]
        ints[i, LOST], ints[i, FIRST_OFF], ints[i, SINCE], ints[i, SINCE_AFTER] = lost, first_off, since, since_after
        ints[i, TAIL_FIRST], ints[i, EV_ANCHOR], ints[i, HOLD_AXIS] = tail_first, ev_anchor, hold_axis
        ints[i, LAST_BEYOND] = last_beyond
        floats[i, MOVED], floats[i, LEVEL], floats[i, TAIL_MAX] = moved, level, tail_max
        floats[i, E0], floats[i, AFTER_MAX] = e0, after_max
        floats[i, END_ERR], floats[i, END_ERR + 1], floats[i, END_ERR + 2] = end0, end1, end2
        floats[i, EV_TAU], floats[i, EV_TAU1], floats[i, EV_Z], floats[i, EV_Z1] = ev_tau, ev_tau1, ev_z, ev_z1
        floats[i, HOLD_E0], floats[i, PREV_POS] = hold_e0, prev_pos
        floats[i, REF0], floats[i, REF0 + 1], floats[i, REF0 + 2] = r0x, r0y, r0z
        flags[i, FINITE], flags[i, OFF_AT_END], flags[i, OUT_AT_END] = finite, off_at_end, out_at_end
        flags[i, PENDING], flags[i, PREV_BEYOND], flags[i, HOLD_MEASURED] = pending, prev_beyond, hold_measured


class TrackWatch:
    """The track checks of N vehicles, fed their states and references chunk by chunk.

    Parameters
    ----------
    t : numpy.ndarray
        (L,) the flight's control instants [s].
    mission : dict
        The mission's ``to_dict()`` (``{}`` for one mission per vehicle): a step is a step.
    track_bound, steady_bound, altitude_bound : numpy.ndarray
        (N,) the bounds [m] of ``fly`` (``inf`` turns one off).
    """

    def __init__(self, t, mission: dict, track_bound, steady_bound, altitude_bound) -> None:
        self.t = t = np.ascontiguousarray(t, dtype=float)
        self.track_bound = np.ascontiguousarray(track_bound, dtype=float)
        self.bound = np.ascontiguousarray(steady_bound, dtype=float)
        self.zbound = np.ascontiguousarray(altitude_bound, dtype=float)
        n, length = self.track_bound.size, t.size
        self.kind_step = mission.get("kind") == "step"  # never a moving reference
        self.step = self.kind_step and mission.get("axis") in ("x", "y", "z")
        self.followed, self.t_step, axis, before, after, anchor0, y0, size = True, float(t[0]), 0, 0, 0, 0, 0.0, 1.0
        if self.step:
            axis, self.t_step = "xyz".index(mission["axis"]), float(mission["time"])
            y0, size = float(mission[mission["axis"]]), float(mission["size"])
            self.followed = bool(t[0] <= self.t_step < t[-1])
            if self.followed:
                before = int(np.searchsorted(t, self.t_step, side="right")) - 1
                after = before + 1  # the first instant after the step
                anchor0 = before if t[before] >= self.t_step - TOLERANCE else after
        self.before, self.after, self.axis = before, after, axis
        span = t[-1] - t[0]
        final = t >= t[-1] - FINAL_FRACTION * span
        if final.sum() < 2:
            final[-2:] = True
        self.held = t[-1] - 2.0 * FINAL_FRACTION * span
        margin = 1e-9 * max(1.0, abs(self.held))  # after the head, t > held + margin: too late to settle
        self.kept = 0 if self.kind_step else min(length, int(np.searchsorted(t, self.held + margin, side="right")) + 1)
        self.plan = np.array(
            [self.step, self.followed, axis, after, anchor0, self.kept, int(np.argmax(final))], dtype=np.int64
        )
        self.step_plan = np.array([self.t_step, y0, size])
        self.ints = np.full((n, INT_WIDTH), -1, dtype=np.int64)
        self.ints[:, EV_ANCHOR] = anchor0
        self.floats = np.full((n, FLOAT_WIDTH), np.nan)
        self.floats[:, [MOVED, PREV_POS]] = 0.0
        self.floats[:, [LEVEL, TAIL_MAX, AFTER_MAX]] = -np.inf
        self.flags = np.zeros((n, FLAG_WIDTH), dtype=bool)
        self.flags[:, FINITE] = True
        self.virtual = np.zeros(n)  # the step's response at its own instant

    def feed(self, k0: int, first: int, stop: int, states: np.ndarray, references: np.ndarray) -> None:
        """Take vehicles first..stop-1's rows of the instants ``k0 .. k0 + C - 1`` (chunks in
        time order; the pieces of a chunk on any thread).

        Parameters
        ----------
        k0 : int
            Index of the chunk's first instant on the flight's grid.
        first, stop : int
            The vehicles.
        states, references : numpy.ndarray
            (N, C, 16) and (N, C, 11): the full log's rows (NaN after a vehicle stopped).
        """
        c = states.shape[1]
        virtual = self.virtual
        if self.step and self.followed and k0 <= self.after < k0 + c:  # interpolated as transient_batch does
            col = self.after - k0
            below = states[first:stop, col - 1, X + self.axis] if col > 0 else self.floats[first:stop, PREV_POS]
            above = states[first:stop, col, X + self.axis]
            window = self.t[self.before : self.after + 1]
            ys0 = np.array([np.interp(self.t_step, window, (b, a)) for b, a in zip(below, above, strict=True)])
            virtual[first:stop] = (ys0 - self.step_plan[1]) / self.step_plan[2]
        _watch_chunk(
            k0, first, stop, states, references, c, self.t, self.track_bound, self.bound, self.zbound,
            self.ints, self.floats, self.flags, self.plan, self.step_plan, virtual,
        )  # fmt: skip

    def verdict(
        self, status: np.ndarray, t_stop: np.ndarray, again: Callable | None = None
    ) -> tuple[np.ndarray, np.ndarray]:
        """The statuses and stop times after the checks: ``lost track`` from the first instant
        beyond the tracking bound, then ``off track`` as :func:`~quadcruise.workflows.fly_failures.mark_off_track`.

        Parameters
        ----------
        status, t_stop : numpy.ndarray
            (N,) the engine's exit codes and stop times [s].
        again : callable, optional
            ``again(vehicles, periods, watch)`` flies the (N,) bool mask ``vehicles`` of the same
            flight again, bit for bit, for at least its first ``periods`` instants, handing their
            rows to ``watch`` as the first flight did (:func:`~quadcruise.sim.chunked.watch_again`):
            the head of a moving reference's vehicles whose verdict the kept figures leave open
            (see the module's docstring). Without it, such a vehicle is an error.

        Returns
        -------
        tuple of numpy.ndarray
            New (N,) statuses and stop times.
        """
        t, finished = self.t, int(ExitStatus.FINISHED)
        status, t_stop = status.copy(), t_stop.copy()
        lost = (status == finished) & (self.ints[:, LOST] >= 0)
        status[lost] = int(ExitStatus.LOST_TRACK)
        t_stop[lost] = t[self.ints[lost, LOST]]
        live = np.flatnonzero((status == finished) & (np.isfinite(self.bound) | np.isfinite(self.zbound)))
        if not live.size or t.size < 2 or not self.flags[live, FINITE].all():
            return status, t_stop
        first = self._off_since(live, again)
        off = first >= 0
        status[live[off]] = int(ExitStatus.OFF_TRACK)
        t_stop[live[off]] = t[first[off]]
        return status, t_stop

    def _off_since(self, live: np.ndarray, again: Callable | None) -> np.ndarray:
        """(len(live),) the first instant off track of each live vehicle, -1 for none."""
        t, ints, floats, flags = self.t, self.ints[live], self.floats[live], self.flags[live]
        moving = not self.kind_step and float(floats[:, MOVED].max()) >= TRANSIENT_MIN_ERROR
        if moving:
            return self._moving_off(live, again)
        measured = flags[:, HOLD_MEASURED] if not self.step else np.full(live.size, self.followed)
        out = ints[:, FIRST_OFF].copy()  # not measured: from the first instant
        if not self.followed:
            return out
        ts0 = self.t_step if self.step else t[0]
        tau, tau1, zk, zk1 = floats[:, EV_TAU], floats[:, EV_TAU1], floats[:, EV_Z], floats[:, EV_Z1]
        edge = np.where(zk > 1.0, 1.0 + STEADY_BAND, 1.0 - STEADY_BAND)
        with np.errstate(divide="ignore", invalid="ignore"):
            settled = ts0 + (tau + (edge - zk) / (zk1 - zk) * (tau1 - tau) - ts0)
        at_end = flags[:, OUT_AT_END]
        since, since_after = ints[:, SINCE], ints[:, SINCE_AFTER]
        event = np.isfinite(tau)
        pick = np.where(
            (since >= 0) & (t[np.maximum(since, 0)] >= settled - TOLERANCE), since, since_after
        )  # the anchor's own instant, if it is not before the end of the transient
        answer = np.where(event, pick, since)  # no excursion: from the start of the response
        answer = np.where(at_end, np.where(flags[:, OFF_AT_END], t.size - 1, -1), answer)
        return np.where(measured, answer, out)

    def _moving_off(self, live: np.ndarray, again: Callable | None) -> np.ndarray:
        """:meth:`_off_since` for a moving reference (the rule of ``tracking_transient_batch``):
        from the kept figures, and for the vehicles they leave open, from their head flown again."""
        out = _moving_summary(live, self.ints, self.floats, self.flags, self.t, self.kept, self.held)
        open_ = np.flatnonzero(out == AMBIGUOUS)
        if not open_.size:
            return out
        if again is None:
            raise RuntimeError("TrackWatch.verdict: a vehicle's head must be flown again, and no `again` was given")
        group = max(1, HEAD_BYTES // (9 * max(self.kept, 1)))
        for start in range(0, open_.size, group):
            rows = open_[start : start + group]
            who = live[rows]
            head = HeadRecord(who, self.kept, self.bound, self.zbound)
            again(head.mask, self.kept, head.feed)
            out[rows] = _moving_first_off(
                np.arange(who.size), head.err, head.beyond, self.ints[who], self.floats[who], self.flags[who],
                self.t, self.kept, self.held,
            )  # fmt: skip
        return out


class HeadRecord:
    """The error and the beyond-the-bounds flag at every instant of the head (the first ``kept``
    instants) of some vehicles, fed as :meth:`TrackWatch.feed` is (9 bytes a vehicle-period).

    Parameters
    ----------
    who : numpy.ndarray
        (M,) the vehicles' indices in the batch.
    kept : int
        Instants of the head.
    bound, zbound : numpy.ndarray
        (N,) the steady bounds [m] on the 3-D error and on the altitude error.
    """

    def __init__(self, who: np.ndarray, kept: int, bound: np.ndarray, zbound: np.ndarray) -> None:
        self.kept, self.bound, self.zbound = int(kept), bound, zbound
        self.mask = np.zeros(bound.size, dtype=bool)
        self.mask[who] = True
        self.rows = np.full(bound.size, -1, dtype=np.int64)
        self.rows[who] = np.arange(who.size)
        self.err = np.full((who.size, self.kept), np.nan)
        self.beyond = np.zeros((who.size, self.kept), dtype=bool)

    def feed(self, k0: int, first: int, stop: int, states: np.ndarray, references: np.ndarray) -> None:
        """Take vehicles first..stop-1's rows of the instants ``k0 .. k0 + C - 1`` (as :meth:`TrackWatch.feed`)."""
        _record_head(
            k0, first, stop, states, references, states.shape[1], self.kept, self.bound, self.zbound,
            self.rows, self.err, self.beyond,
        )  # fmt: skip


@njit(cache=True, nogil=True, error_model="numpy")
def _record_head(k0, first, stop, xs, refs, c, kept, bound, zbound, rows, head_err, head_beyond):
    """The head's error and flag of the vehicles with a row (``rows[i] >= 0``), by the arithmetic
    of :func:`_watch_chunk` (the same numbers)."""
    for i in range(first, stop):
        r = rows[i]
        if r < 0:
            continue
        b_steady, b_alt = bound[i], zbound[i]
        for col in range(c):
            g = k0 + col
            if g >= kept:
                break
            px, py, pz = xs[i, col, X], xs[i, col, X + 1], xs[i, col, X + 2]
            rx, ry, rz = refs[i, col, REF_X], refs[i, col, REF_X + 1], refs[i, col, REF_X + 2]
            dx, dy, dz = px - rx, py - ry, pz - rz
            err = math.sqrt(dx * dx + dy * dy + dz * dz)
            head_err[r, g], head_beyond[r, g] = err, err > b_steady or abs(dz) > b_alt


@njit(cache=True, nogil=True, error_model="numpy")
def _moving_summary(live, ints, floats, flags, t, kept, held):
    """:func:`_moving_first_off` from the kept figures alone, or :data:`AMBIGUOUS` where they do
    not decide it.

    With ``z(e) = (e0 - e) / (e0 - E)`` and ``last`` the head's last instant with ``z < 1 - band``
    (``z`` falls as ``e`` grows, so one comparison of the largest error after the head's last
    instant beyond the bounds says whether ``last`` is after it): if it is, no instant beyond
    lies between ``last`` and the head's end, so the answer is the second half's first (or the
    end's rule when the transient did not settle, which the head's last three errors decide);
    if it is not, the answer depends on where ``last`` lies before that instant: open."""
    length, line = t.shape[0], 1.0 - STEADY_BAND
    out = np.empty(live.shape[0], dtype=np.int64)
    for r in range(live.shape[0]):
        i = live[r]
        e0, level = floats[i, E0], floats[i, LEVEL]
        if not (e0 >= TRANSIENT_MIN_ERROR and level < e0):  # no transient measured: the whole flight
            out[r] = ints[i, FIRST_OFF]
            continue
        scale = e0 - level
        settle = 1.0  # any finite value: settled within the head
        if kept < length and (e0 - floats[i, TAIL_MAX]) / (e0 - level) < line:
            settle = np.nan  # above the line in the second half: not converged
        elif kept < 4 or kept >= length or not t[kept - 3] + 1e-9 < held:  # too short a head to read its end
            out[r] = AMBIGUOUS
            continue
        elif not (e0 - floats[i, AFTER_MAX]) / scale < line:  # the last instant above is before one beyond
            out[r] = AMBIGUOUS
            continue
        else:
            z0 = (e0 - floats[i, END_ERR]) / scale
            z1 = (e0 - floats[i, END_ERR + 1]) / scale
            z2 = (e0 - floats[i, END_ERR + 2]) / scale
            if z2 < line:  # above at the head's last instant: not settled in time
                settle = np.nan
            elif z1 < line or z0 < line:  # last = kept - 2 or kept - 3: where it crossed
                k = kept - 2 if z1 < line else kept - 3
                zk, zk1 = (z1, z2) if z1 < line else (z0, z1)
                settle = t[k] + (line - zk) / (zk1 - zk) * (t[k + 1] - t[k]) - t[0]
                if settle > held - t[0] + 1e-12:
                    settle = np.nan
            # else last < kept - 3: settled by t[kept - 3], before the head's end (held)
        if np.isnan(settle):  # from the last instant
            out[r] = length - 1 if flags[i, OFF_AT_END] else -1
        else:  # settled after the head's last instant beyond: the second half's first
            out[r] = ints[i, TAIL_FIRST]
    return out


@njit(cache=True, nogil=True, error_model="numpy")
def _moving_first_off(live, head_err, head_beyond, ints, floats, flags, t, kept, held):
    """Each live vehicle's first instant off track under a moving reference (-1: none), by
    :func:`~quadcruise.metrics.tracking_transient_batch`'s settling into STEADY_BAND and
    :func:`~quadcruise.workflows.fly_failures.off_track_since`, from the head kept and the tail's figures."""
    length, line = t.shape[0], 1.0 - STEADY_BAND
    out = np.empty(live.shape[0], dtype=np.int64)
    for r in range(live.shape[0]):
        i = live[r]
        e0, level = head_err[i, 0], floats[i, LEVEL]
        if not (e0 >= TRANSIENT_MIN_ERROR and level < e0):  # no transient measured: the whole flight
            out[r] = ints[i, FIRST_OFF]
            continue
        scale = e0 - level
        last = -1  # the last instant of the head above the line
        for g in range(kept - 1, -1, -1):
            if (e0 - head_err[i, g]) / scale < line:
                last = g
                break
        if kept < length and (e0 - floats[i, TAIL_MAX]) / (e0 - level) < line:
            settle = np.nan  # above it in the second half: not converged
        elif last < 0:
            settle = 0.0
        elif kept < length and last >= kept - 1:
            settle = np.nan
        else:
            k = min(last, length - 2)
            zk, zk1 = (e0 - head_err[i, k]) / scale, (e0 - head_err[i, k + 1]) / scale
            settle = t[k] + (line - zk) / (zk1 - zk) * (t[k + 1] - t[k]) - t[0]
        if settle > held - t[0] + 1e-12:
            settle = np.nan
        if np.isnan(settle):  # from the last instant
            out[r] = length - 1 if flags[i, OFF_AT_END] else -1
        elif settle == 0.0:
            out[r] = ints[i, FIRST_OFF]
        else:
            settled = t[0] + settle
            out[r] = ints[i, TAIL_FIRST]
            for g in range(max(0, last - 1), kept):
                if head_beyond[i, g] and t[g] >= settled - TOLERANCE:
                    out[r] = g
                    break
    return out


__all__ = ["TrackWatch"]
