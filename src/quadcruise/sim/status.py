"""How a flight ended: each vehicle's exit status, its code and its reason in one place.

The compiled engine writes the integer codes; everything that reads them (results, Monte
Carlo tables, the command line's exit code) names them through :class:`ExitStatus`.

Examples
--------
>>> ExitStatus(2).reason
'diverged: position left the bound'
>>> ExitStatus.FINISHED.ok, ExitStatus.NONFINITE.ok, ExitStatus.LOST_TRACK.ok
(True, False, False)
>>> ExitStatus.LOST_TRACK.stopped, ExitStatus.OFF_TRACK.stopped, ExitStatus.TILT_BOUND.stopped
(False, False, True)
"""

from __future__ import annotations

from enum import IntEnum

__all__ = ["ExitStatus", "STATUS_REASONS"]


class ExitStatus(IntEnum):
    """A vehicle's exit status: the engine's integer code with its reason.

    ``FINISHED`` flew the whole mission. ``LOST_TRACK`` flew it too, but its position error
    left the tracking bound at the time recorded in :attr:`quadcruise.SimResult.t_stop` (see
    :func:`quadcruise.fly`'s ``max_track_error``: a runaway). ``OFF_TRACK`` flew it too, but
    its position error after the transient exceeded the steady bound, first at ``t_stop``
    (``max_steady_error``: a vehicle that never got onto its path, or left it). Every other
    status is the engine's: it stopped the vehicle at ``t_stop``, and its later log rows are NaN.
    """

    FINISHED = 0
    NONFINITE = 1
    POSITION_BOUND = 2
    SPEED_BOUND = 3
    RATE_BOUND = 4
    TILT_BOUND = 5
    BAD_COMMAND = 6
    LOST_TRACK = 7
    PITCH_SINGULAR = 8
    OFF_TRACK = 9
    CRASHED = 10

    @property
    def reason(self) -> str:
        """One line saying what happened."""
        return _REASONS[self]

    @property
    def ok(self) -> bool:
        """True for a vehicle that flew its whole mission."""
        return self is ExitStatus.FINISHED

    @property
    def stopped(self) -> bool:
        """True for a vehicle the engine stopped before the end (diverged or a bad command)."""
        return self not in (ExitStatus.FINISHED, ExitStatus.LOST_TRACK, ExitStatus.OFF_TRACK)


_REASONS = {
    ExitStatus.FINISHED: "finished",
    ExitStatus.NONFINITE: "diverged: the state became non-finite (NaN or inf)",
    ExitStatus.POSITION_BOUND: "diverged: position left the bound",
    ExitStatus.SPEED_BOUND: "diverged: speed left the bound",
    ExitStatus.RATE_BOUND: "diverged: body rate left the bound",
    ExitStatus.TILT_BOUND: "diverged: tilt left the bound",
    ExitStatus.BAD_COMMAND: "stopped: the controller returned a non-finite command",
    ExitStatus.LOST_TRACK: "lost track: the position error left the tracking bound",
    ExitStatus.PITCH_SINGULAR: "stopped: pitch beyond 85 degrees, near the full plant's Euler-angle singularity",
    ExitStatus.OFF_TRACK: "off track: the position or altitude error after the transient (at the end, if it never "
    "settled) exceeded the steady bound",
    ExitStatus.CRASHED: "crashed: hit the ground faster than the vehicle's touchdown speed, or upside down",
}

STATUS_REASONS = tuple(status.reason for status in ExitStatus)
"""The reasons by integer code (index = :class:`ExitStatus` value)."""
