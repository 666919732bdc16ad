"""``fly``'s lost-track and off-track checks, computed as the flight goes, at every control
period, while the log keeps only every ``log_every``-th: the statuses and times that
:func:`~quadcruise.workflows.fly.mark_lost_track` and :func:`~quadcruise.workflows.fly.mark_off_track`
give on the full log (``log_every=1``), without that log.

What each check needs of the whole flight, and what is kept for it (per vehicle):

- lost track: the first instant the position error exceeds the tracking bound;
- off track: the first instant beyond the steady bounds after the transient, which ends
  where the error last left the 5 % band (:data:`~quadcruise.metrics.STEADY_BAND`):

  * a step, or a reference that holds still: the band is known from the first instant
    (the step's size, the initial error), so the last excursion out of it is followed as
    the flight goes, with the first instant beyond the bounds since it;
  * a moving reference: the band is measured from the error's level over the last
    quarter of the flight (:func:`~quadcruise.metrics.tracking_transient_batch`), known only
    at the end; the transient counts only if it ended in the first half, so the error and
    the beyond-the-bounds flags of the first half are kept (9 bytes per vehicle-period),
    and of the second half the largest error, the level and the first instant beyond.

docs/performance.md ("A batch that fits in memory") says why this way and what it costs.
"""

from __future__ import annotations

import numpy as np

from quadcruise.layout import REF_X, X
from quadcruise.metrics.tracking import FINAL_FRACTION, STEADY_BAND, TRANSIENT_MIN_ERROR
from quadcruise.sim.status import ExitStatus

TOLERANCE = 1e-12
"""An instant this close [s] before the end of the transient counts as after it (as in
:func:`~quadcruise.workflows.fly.off_track_since`)."""


def first_true(flags: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Each row's first True column, and whether it has one.

    Parameters
    ----------
    flags : numpy.ndarray
        (N, C) bool.

    Returns
    -------
    tuple of numpy.ndarray
        (N,) column indices (0 where none) and (N,) bool.
    """
    return flags.argmax(axis=1), flags.any(axis=1)


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
        self.t = t = np.asarray(t, dtype=float)
        self.track_bound = np.asarray(track_bound, dtype=float)
        self.bound = np.asarray(steady_bound, dtype=float)
        self.zbound = np.asarray(altitude_bound, dtype=float)
        n, length = self.track_bound.size, t.size
        self.n = n
        self.lost = np.full(n, -1, dtype=np.int64)  # first instant beyond the tracking bound
        self.first_off = np.full(n, -1, dtype=np.int64)  # first instant beyond the steady bounds
        self.finite = np.ones(n, dtype=bool)
        self.moved = np.zeros(n)  # largest move of the reference from where it started [m]
        self.off_at_end = np.zeros(n, dtype=bool)
        self.ref0 = self.pos0 = None
        self.prev_beyond = np.zeros(n, dtype=bool)  # beyond at the previous chunk's last instant
        self.prev_position = np.zeros(n)  # the step axis's position there
        # the last excursion out of the band (a step, or a still reference)
        self.kind_step = mission.get("kind") == "step"  # never a moving reference
        self.step = self.kind_step and mission.get("axis") in ("x", "y", "z")
        self.followed = True
        self.anchor0 = 0
        if self.step:
            self.axis = "xyz".index(mission["axis"])
            self.t_step = float(mission["time"])
            self.y0, self.size = float(mission[mission["axis"]]), float(mission["size"])
            self.followed = bool(t[0] <= self.t_step < t[-1])
            self.before = int(np.searchsorted(t, self.t_step, side="right")) - 1 if self.followed else 0
            self.after = self.before + 1  # the first instant after the step
            self.anchor0 = self.before if t[self.before] >= self.t_step - TOLERANCE else self.after
        self.ev_tau = np.full(n, np.nan)  # the last sample out of the band: its time, the next's,
        self.ev_tau1 = np.full(n, np.nan)  # their values, whether the next is still to come,
        self.ev_z = np.full(n, np.nan)
        self.ev_z1 = np.full(n, np.nan)
        self.ev_pending = np.zeros(n, dtype=bool)
        self.off_at_end_of_response = np.zeros(n, dtype=bool)  # out of the band at the last instant
        self.ev_anchor = np.full(n, self.anchor0, dtype=np.int64)  # the first instant at or after it
        self.since = np.full(n, -1, dtype=np.int64)  # first instant beyond at or after the anchor,
        self.since_after = np.full(n, -1, dtype=np.int64)  # and after it
        self.hold_axis = np.zeros(n, dtype=np.int64)
        self.hold_e0 = np.ones(n)
        self.hold_measured = np.zeros(n, dtype=bool)
        # a moving reference
        span = t[-1] - t[0]
        final = t >= t[-1] - FINAL_FRACTION * span
        if final.sum() < 2:
            final[-2:] = True
        self.final_from = int(np.argmax(final))
        self.held = t[-1] - 2.0 * FINAL_FRACTION * span
        margin = 1e-9 * max(1.0, abs(self.held))  # after the head, t > held + margin: too late to settle
        self.kept = 0 if self.kind_step else min(length, int(np.searchsorted(t, self.held + margin, side="right")) + 1)
        self.head_err = np.empty((n, self.kept))
        self.head_beyond = np.empty((n, self.kept), dtype=bool)
        self.level = np.full(n, -np.inf)
        self.tail_max = np.full(n, -np.inf)
        self.tail_first = np.full(n, -1, dtype=np.int64)

    def feed(self, k0: int, states: np.ndarray, references: np.ndarray) -> None:
        """Take the rows of the instants ``k0 .. k0 + C - 1``.

        Parameters
        ----------
        k0 : int
            Index of the chunk's first instant on the flight's grid.
        states, references : numpy.ndarray
            (N, C, 16) and (N, C, 11): the full log's rows (NaN after a vehicle stopped).
        """
        c = states.shape[1]
        d = [states[:, :, X + k] - references[:, :, REF_X + k] for k in range(3)]
        err = np.sqrt(d[0] * d[0] + d[1] * d[1] + d[2] * d[2])  # as fly.position_error
        with np.errstate(invalid="ignore"):
            lost = err > self.track_bound[:, None]
            beyond = (err > self.bound[:, None]) | (np.abs(d[2]) > self.zbound[:, None])
        self._first(self.lost, lost, k0)
        self._first(self.first_off, beyond, k0)
        self.finite &= np.isfinite(err).all(axis=1)
        if k0 == 0:
            self._start(states, references)
        with np.errstate(invalid="ignore"):
            for k in range(3):
                moved = np.abs(references[:, :, REF_X + k] - self.ref0[:, k, None])
                self.moved = np.fmax(self.moved, np.fmax.reduce(moved, axis=1, initial=0.0))
        if k0 + c == self.t.size:
            self.off_at_end = beyond[:, -1].copy()
        if not self.kind_step:
            self._moving(k0, err, beyond)
        if self.followed:
            self._excursions(k0, states, references, beyond)
        self.prev_beyond = beyond[:, -1].copy()
        if self.step:
            self.prev_position = states[:, -1, X + self.axis].copy()

    @staticmethod
    def _first(into: np.ndarray, flags: np.ndarray, k0: int) -> None:
        col, has = first_true(flags)
        new = has & (into < 0)
        into[new] = k0 + col[new]

    def _start(self, states: np.ndarray, references: np.ndarray) -> None:
        self.ref0 = references[:, 0, REF_X : REF_X + 3].copy()
        self.pos0 = states[:, 0, X : X + 3].copy()
        e0 = np.abs(self.ref0 - self.pos0)
        self.hold_axis = e0.argmax(axis=1)
        rows = np.arange(self.n)
        self.hold_measured = e0[rows, self.hold_axis] >= TRANSIENT_MIN_ERROR
        self.hold_e0 = (self.ref0 - self.pos0)[rows, self.hold_axis]

    def _moving(self, k0: int, err: np.ndarray, beyond: np.ndarray) -> None:
        c = err.shape[1]
        head = max(0, min(c, self.kept - k0))
        if head:
            self.head_err[:, k0 : k0 + head] = err[:, :head]
            self.head_beyond[:, k0 : k0 + head] = beyond[:, :head]
        if head < c:
            self.tail_max = np.maximum(self.tail_max, err[:, head:].max(axis=1))
            self._first(self.tail_first, beyond[:, head:], k0 + head)
        fin = max(0, self.final_from - k0)
        if fin < c:
            self.level = np.maximum(self.level, err[:, fin:].max(axis=1))

    def _excursions(self, k0: int, states: np.ndarray, references: np.ndarray, beyond: np.ndarray) -> None:
        c = states.shape[1]
        t = self.t
        # first instant beyond since each vehicle's last excursion (or the response's start), where
        # not found yet
        if beyond.any():
            for into, shift in ((self.since, 0), (self.since_after, 1)):
                rows = np.flatnonzero((into < 0) & beyond.any(axis=1))
                if rows.size:
                    cols = np.arange(c)[None, :] >= (self.ev_anchor[rows, None] + shift - k0)
                    col, has = first_true(beyond[rows] & cols)
                    into[rows[has]] = k0 + col[has]
        # the samples of the response in this chunk: values z, times, anchors on the grid
        if self.step:
            start = max(0, self.after - k0)
            if start >= c:
                return
            z = (states[:, start:, X + self.axis] - self.y0) / self.size
            taus, anchors = t[k0 + start : k0 + c], np.arange(k0 + start, k0 + c)
            if k0 <= self.after < k0 + c:  # the step's own instant, interpolated as transient_batch does
                below = states[:, start - 1, X + self.axis] if start > 0 else self.prev_position
                above = states[:, start, X + self.axis]
                window = t[self.before : self.after + 1]
                ys0 = np.array([np.interp(self.t_step, window, (b, a)) for b, a in zip(below, above, strict=True)])
                z = np.concatenate((((ys0 - self.y0) / self.size)[:, None], z), axis=1)
                taus = np.concatenate(([self.t_step], taus))
                anchors = np.concatenate(([self.anchor0], anchors))
        else:
            j = self.hold_axis[:, None, None]
            e = (
                np.take_along_axis(references[:, :, REF_X : REF_X + 3], j, axis=2)
                - np.take_along_axis(states[:, :, X : X + 3], j, axis=2)
            )[:, :, 0]
            z = 1.0 - e / self.hold_e0[:, None]
            taus, anchors = t[k0 : k0 + c], np.arange(k0, k0 + c)
        # a pending next sample: the first of this chunk
        pending = np.flatnonzero(self.ev_pending)
        if pending.size and z.shape[1]:
            self.ev_z1[pending], self.ev_tau1[pending] = z[pending, 0], taus[0]
            self.ev_pending[pending] = False
        # the last sample out of the band in this chunk: a new excursion
        with np.errstate(invalid="ignore"):
            out = np.abs(z - 1.0) > STEADY_BAND
        s = z.shape[1]
        last = s - 1 - out[:, ::-1].argmax(axis=1)
        rows = np.flatnonzero(out.any(axis=1))
        if rows.size:
            k = last[rows]
            self.ev_tau[rows], self.ev_z[rows] = taus[k], z[rows, k]
            nxt = np.minimum(k + 1, s - 1)
            self.ev_pending[rows] = k + 1 >= s
            self.ev_tau1[rows] = np.where(k + 1 < s, taus[nxt], np.nan)
            self.ev_z1[rows] = np.where(k + 1 < s, z[rows, nxt], np.nan)
            anchor = anchors[k]
            self.ev_anchor[rows] = anchor
            for into, shift in ((self.since, 0), (self.since_after, 1)):
                g = anchor + shift
                into[rows] = -1
                earlier = g < k0  # the step's instant, its anchor at the previous chunk's last instant
                into[rows[earlier & self.prev_beyond[rows]]] = k0 - 1
                cols = np.arange(c)[None, :] >= (g - k0)[:, None]
                col, has = first_true(beyond[rows] & cols)
                fill = has & (into[rows] < 0)
                into[rows[fill]] = k0 + col[fill]
        if k0 + c == t.size:
            self.off_at_end_of_response = out[:, -1].copy() if s else np.zeros(self.n, dtype=bool)

    def verdict(self, status: np.ndarray, t_stop: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """The statuses and stop times after the checks: ``lost track`` from the first instant
        beyond the tracking bound, then ``off track`` as :func:`~quadcruise.workflows.fly.mark_off_track`.

        Parameters
        ----------
        status, t_stop : numpy.ndarray
            (N,) the engine's exit codes and stop times [s].

        Returns
        -------
        tuple of numpy.ndarray
            New (N,) statuses and stop times.
        """
        t, finished = self.t, int(ExitStatus.FINISHED)
        status, t_stop = status.copy(), t_stop.copy()
        lost = (status == finished) & (self.lost >= 0)
        status[lost] = int(ExitStatus.LOST_TRACK)
        t_stop[lost] = t[self.lost[lost]]
        live = np.flatnonzero((status == finished) & (np.isfinite(self.bound) | np.isfinite(self.zbound)))
        if not live.size or t.size < 2 or not self.finite[live].all():
            return status, t_stop
        first = self._off_since(live)
        off = first >= 0
        status[live[off]] = int(ExitStatus.OFF_TRACK)
        t_stop[live[off]] = t[first[off]]
        return status, t_stop

    def _off_since(self, live: np.ndarray) -> np.ndarray:
        """(len(live),) the first instant off track of each live vehicle, -1 for none."""
        t = self.t
        moving = not self.kind_step and float(self.moved[live].max()) >= TRANSIENT_MIN_ERROR
        if moving:
            return self._moving_off(live)
        measured = self.hold_measured[live] if not self.step else np.full(live.size, self.followed)
        out = self.first_off[live].copy()  # not measured: from the first instant
        if not self.followed:
            return out
        ts0 = self.t_step if self.step else t[0]
        tau, tau1, zk, zk1 = self.ev_tau[live], self.ev_tau1[live], self.ev_z[live], self.ev_z1[live]
        edge = np.where(zk > 1.0, 1.0 + STEADY_BAND, 1.0 - STEADY_BAND)
        with np.errstate(divide="ignore", invalid="ignore"):
            settled = ts0 + (tau + (edge - zk) / (zk1 - zk) * (tau1 - tau) - ts0)
        at_end = self.off_at_end_of_response[live]
        since, since_after = self.since[live], self.since_after[live]
        event = np.isfinite(tau)
        pick = np.where(
            (since >= 0) & (t[np.maximum(since, 0)] >= settled - TOLERANCE), since, since_after
        )  # the anchor's own instant, if it is not before the end of the transient
        answer = np.where(event, pick, since)  # no excursion: from the start of the response
        answer = np.where(at_end, np.where(self.off_at_end[live], t.size - 1, -1), answer)
        return np.where(measured, answer, out)

    def _moving_off(self, live: np.ndarray) -> np.ndarray:
        t, band = self.t, STEADY_BAND
        err = self.head_err[live]
        e0, level = err[:, 0], self.level[live]
        measured = (e0 >= TRANSIENT_MIN_ERROR) & (level < e0)
        out = self.first_off[live].copy()
        kept, length = self.kept, t.size
        sel = np.flatnonzero(measured)
        if not sel.size:
            return out
        e, e0, level = err[sel], e0[sel], level[sel]
        scale = (e0 - level)[:, None]
        z = (e0[:, None] - e) / scale
        above = z < 1.0 - band
        last = kept - 1 - above[:, ::-1].argmax(axis=1)
        rows = np.arange(sel.size)
        k = np.minimum(last, length - 2)
        k = np.minimum(k, kept - 2) if kept < length else k
        zk, zk1 = z[rows, k], z[rows, k + 1]
        with np.errstate(divide="ignore", invalid="ignore"):
            settle = t[k] + (1.0 - band - zk) / (zk1 - zk) * (t[k + 1] - t[k]) - t[0]
        settle[~above[rows, last]] = 0.0
        if kept < length:
            with np.errstate(invalid="ignore"):
                tail_above = (e0 - self.tail_max[live][sel]) / (e0 - level) < 1.0 - band
            settle[tail_above | (above[rows, last] & (last >= kept - 1))] = np.nan
        settle[settle > self.held - t[0] + 1e-12] = np.nan
        settled = t[0] + settle
        after = self.head_beyond[live][sel] & (t[None, :kept] >= settled[:, None] - TOLERANCE)
        col, has = first_true(after)
        answer = np.where(has, col, self.tail_first[live][sel])
        answer = np.where(settle == 0.0, self.first_off[live][sel], answer)
        answer = np.where(np.isnan(settle), np.where(self.off_at_end[live][sel], length - 1, -1), answer)
        out[sel] = answer
        return out


__all__ = ["TrackWatch"]
