"""``fly``'s lost-track and off-track checks, computed as the flight goes, at every control
period, while the log keeps only every ``log_every``-th: the statuses and times that
:func:`~quadcruise.workflows.fly_failures.mark_lost_track` and :func:`~quadcruise.workflows.fly_failures.mark_off_track`
give on the full log (``log_every=1``), without that log, in memory that does not grow with the
flight's length (a fixed number of figures per vehicle, :data:`~quadcruise.sim.track_figures.TRACK`,
which the engine's kernels update at every period: :mod:`quadcruise.sim.track_figures`).

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
from quadcruise.sim.track_figures import (
    TOLERANCE,
    TP_FOLLOWED,
    TP_KEPT,
    TP_ON,
    TP_STEP,
    TP_T_STEP,
    TR_AFTER_MAX,
    TR_E0,
    TR_END_ERR,
    TR_EV_TAU,
    TR_EV_TAU1,
    TR_EV_Z,
    TR_EV_Z1,
    TR_FINITE,
    TR_FIRST_OFF,
    TR_HOLD_MEASURED,
    TR_LEVEL,
    TR_LOST,
    TR_MOVED,
    TR_OFF_AT_END,
    TR_OUT_AT_END,
    TR_SINCE,
    TR_SINCE_AFTER,
    TR_TAIL_FIRST,
    TR_TAIL_MAX,
    fresh_track,
    track_plan,
)

if TYPE_CHECKING:
    from collections.abc import Callable

HEAD_BYTES = 2**26
"""Most bytes [B] of head rows (9 a vehicle-period) kept at once when the head of the vehicles
whose verdict the kept figures leave open is flown again: 64 MiB, a group of vehicles per
flight again (a 10 s flight at 1 kHz: about 1,500 vehicles a group)."""
AMBIGUOUS = -2
"""The answer of :func:`_moving_summary` for a vehicle whose head must be read again."""


class TrackWatch:
    """The track checks of N vehicles: their running figures (:attr:`rows`), which the kernel
    updates at every period (hand it :attr:`arrays`), and the verdict read from them.

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
        self.bound = np.ascontiguousarray(steady_bound, dtype=float)
        self.zbound = np.ascontiguousarray(altitude_bound, dtype=float)
        self.plan = plan = track_plan(t, mission)
        self.kind_step = mission.get("kind") == "step"  # never a moving reference
        self.step, self.followed = bool(plan[TP_STEP]), bool(plan[TP_FOLLOWED])
        self.t_step, self.kept = float(plan[TP_T_STEP]), int(plan[TP_KEPT])
        self.held = t[-1] - 2.0 * FINAL_FRACTION * (t[-1] - t[0])
        self.rows = fresh_track(self.bound.size, track_bound, self.bound, self.zbound, plan)
        if not any(np.isfinite(b).any() for b in (np.asarray(track_bound, dtype=float), self.bound, self.zbound)):
            plan[TP_ON] = 0.0  # every check turned off: the kernel passes over them

    @property
    def arrays(self) -> tuple[np.ndarray, np.ndarray]:
        """``(rows, plan)``: what the kernel updates at every period (``track`` of
        :func:`~quadcruise.sim.engine.simulate`, :func:`~quadcruise.sim.rotor_batch.fly_rotor_vehicles`
        and :class:`~quadcruise.sim.stepper.Stepper`)."""
        return self.rows, self.plan

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
            rows to ``watch`` (:meth:`HeadRecord.feed`; :func:`~quadcruise.sim.chunked.watch_again`):
            the head of a moving reference's vehicles whose verdict the kept figures leave open
            (see the module's docstring). Without it, such a vehicle is an error.

        Returns
        -------
        tuple of numpy.ndarray
            New (N,) statuses and stop times.
        """
        t, finished = self.t, int(ExitStatus.FINISHED)
        status, t_stop = status.copy(), t_stop.copy()
        first_lost = self.rows[:, TR_LOST].astype(np.int64)
        lost = (status == finished) & (first_lost >= 0)
        status[lost] = int(ExitStatus.LOST_TRACK)
        t_stop[lost] = t[first_lost[lost]]
        live = np.flatnonzero((status == finished) & (np.isfinite(self.bound) | np.isfinite(self.zbound)))
        if not live.size or t.size < 2 or not (self.rows[live, TR_FINITE] != 0.0).all():
            return status, t_stop
        first = self._off_since(live, again)
        off = first >= 0
        status[live[off]] = int(ExitStatus.OFF_TRACK)
        t_stop[live[off]] = t[first[off]]
        return status, t_stop

    def _off_since(self, live: np.ndarray, again: Callable | None) -> np.ndarray:
        """(len(live),) the first instant off track of each live vehicle, -1 for none."""
        t, rows = self.t, self.rows[live]
        moving = not self.kind_step and float(rows[:, TR_MOVED].max()) >= TRANSIENT_MIN_ERROR
        if moving:
            return self._moving_off(live, again)
        measured = rows[:, TR_HOLD_MEASURED] != 0.0 if not self.step else np.full(live.size, self.followed)
        out = rows[:, TR_FIRST_OFF].astype(np.int64)  # not measured: from the first instant
        if not self.followed:
            return out
        ts0 = self.t_step if self.step else t[0]
        tau, tau1, zk, zk1 = rows[:, TR_EV_TAU], rows[:, TR_EV_TAU1], rows[:, TR_EV_Z], rows[:, TR_EV_Z1]
        edge = np.where(zk > 1.0, 1.0 + STEADY_BAND, 1.0 - STEADY_BAND)
        with np.errstate(divide="ignore", invalid="ignore"):
            settled = ts0 + (tau + (edge - zk) / (zk1 - zk) * (tau1 - tau) - ts0)
        at_end = rows[:, TR_OUT_AT_END] != 0.0
        since, since_after = rows[:, TR_SINCE].astype(np.int64), rows[:, TR_SINCE_AFTER].astype(np.int64)
        event = np.isfinite(tau)
        pick = np.where(
            (since >= 0) & (t[np.maximum(since, 0)] >= settled - TOLERANCE), since, since_after
        )  # the anchor's own instant, if it is not before the end of the transient
        answer = np.where(event, pick, since)  # no excursion: from the start of the response
        answer = np.where(at_end, np.where(rows[:, TR_OFF_AT_END] != 0.0, t.size - 1, -1), answer)
        return np.where(measured, answer, out)

    def _moving_off(self, live: np.ndarray, again: Callable | None) -> np.ndarray:
        """:meth:`_off_since` for a moving reference (the rule of ``tracking_transient_batch``):
        from the kept figures, and for the vehicles they leave open, from their head flown again."""
        out = _moving_summary(live, self.rows, self.t, self.kept, self.held)
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
                np.arange(who.size), head.err, head.beyond, self.rows[who],
                self.t, self.kept, self.held,
            )  # fmt: skip
        return out


class HeadRecord:
    """The error and the beyond-the-bounds flag at every instant of the head (the first ``kept``
    instants) of some vehicles, fed their rows chunk by chunk (9 bytes a vehicle-period).

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
        """Take vehicles first..stop-1's rows of the instants ``k0 .. k0 + C - 1`` (chunks in time
        order; the pieces of a chunk on any thread).

        Parameters
        ----------
        k0 : int
            Index of the chunk's first instant on the flight's grid.
        first, stop : int
            The vehicles.
        states, references : numpy.ndarray
            (N, C, 16) and (N, C, 11): the full log's rows (NaN after a vehicle stopped).
        """
        _record_head(
            k0, first, stop, states, references, states.shape[1], self.kept, self.bound, self.zbound,
            self.rows, self.err, self.beyond,
        )  # fmt: skip


@njit(cache=True, nogil=True, error_model="numpy")
def _record_head(k0, first, stop, xs, refs, c, kept, bound, zbound, rows, head_err, head_beyond):
    """The head's error and flag of the vehicles with a row (``rows[i] >= 0``), by the arithmetic
    of :func:`~quadcruise.sim.track_figures.track_period` (the same numbers)."""
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
def _moving_summary(live, rows, t, kept, held):
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
        e0, level = rows[i, TR_E0], rows[i, TR_LEVEL]
        if not (e0 >= TRANSIENT_MIN_ERROR and level < e0):  # no transient measured: the whole flight
            out[r] = int(rows[i, TR_FIRST_OFF])
            continue
        scale = e0 - level
        settle = 1.0  # any finite value: settled within the head
        if kept < length and (e0 - rows[i, TR_TAIL_MAX]) / (e0 - level) < line:
            settle = np.nan  # above the line in the second half: not converged
        elif kept < 4 or kept >= length or not t[kept - 3] + 1e-9 < held:  # too short a head to read its end
            out[r] = AMBIGUOUS
            continue
        elif not (e0 - rows[i, TR_AFTER_MAX]) / scale < line:  # the last instant above is before one beyond
            out[r] = AMBIGUOUS
            continue
        else:
            z0 = (e0 - rows[i, TR_END_ERR]) / scale
            z1 = (e0 - rows[i, TR_END_ERR + 1]) / scale
            z2 = (e0 - rows[i, TR_END_ERR + 2]) / scale
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
            out[r] = length - 1 if rows[i, TR_OFF_AT_END] != 0.0 else -1
        else:  # settled after the head's last instant beyond: the second half's first
            out[r] = int(rows[i, TR_TAIL_FIRST])
    return out


@njit(cache=True, nogil=True, error_model="numpy")
def _moving_first_off(live, head_err, head_beyond, rows, t, kept, held):
    """Each live vehicle's first instant off track under a moving reference (-1: none), by
    :func:`~quadcruise.metrics.tracking_transient_batch`'s settling into STEADY_BAND and
    :func:`~quadcruise.workflows.fly_failures.off_track_since`, from the head kept and the tail's figures."""
    length, line = t.shape[0], 1.0 - STEADY_BAND
    out = np.empty(live.shape[0], dtype=np.int64)
    for r in range(live.shape[0]):
        i = live[r]
        e0, level = head_err[i, 0], rows[i, TR_LEVEL]
        if not (e0 >= TRANSIENT_MIN_ERROR and level < e0):  # no transient measured: the whole flight
            out[r] = int(rows[i, TR_FIRST_OFF])
            continue
        scale = e0 - level
        last = -1  # the last instant of the head above the line
        for g in range(kept - 1, -1, -1):
            if (e0 - head_err[i, g]) / scale < line:
                last = g
                break
        if kept < length and (e0 - rows[i, TR_TAIL_MAX]) / (e0 - level) < line:
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
            out[r] = length - 1 if rows[i, TR_OFF_AT_END] != 0.0 else -1
        elif settle == 0.0:
            out[r] = int(rows[i, TR_FIRST_OFF])
        else:
            settled = t[0] + settle
            out[r] = int(rows[i, TR_TAIL_FIRST])
            for g in range(max(0, last - 1), kept):
                if head_beyond[i, g] and t[g] >= settled - TOLERANCE:
                    out[r] = g
                    break
    return out


__all__ = ["TrackWatch"]
