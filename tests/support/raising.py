"""Compiled functions that raise at t >= 0.5 s, and their well-behaved twins, for the tests
that an exception in a controller, mission or disturbance reaches the caller on every path.

They live in a module (not in a test file) so that a Dask worker process can import them."""

from dataclasses import dataclass

from numba import njit

from quadcruise.control import NLPD
from quadcruise.disturbances import CustomDisturbance
from quadcruise.layout import CONTROLLER_SIG, DISTURBANCE_SIG, EXT_E1, EXT_SIZE, MISSION_SIG
from quadcruise.missions import Hover

RAISE_AT = 0.5
"""The time [s] from which the raising functions raise."""
MESSAGE = "raised on purpose at t >= 0.5 s"

_nlpd = NLPD().function
_hover = Hover().function


@njit(CONTROLLER_SIG)
def raising_law(t, dt, x, ref, vp, gains, mem, cmd):
    """nlpd until RAISE_AT, then a ValueError."""
    if t >= RAISE_AT:
        raise ValueError(MESSAGE)
    _nlpd(t, dt, x, ref, vp, gains, mem, cmd)


@njit(CONTROLLER_SIG)
def calm_law(t, dt, x, ref, vp, gains, mem, cmd):
    """nlpd, through the same kind of wrapper as :func:`raising_law` (the other direction)."""
    if t < 0.0:
        raise ValueError(MESSAGE)
    _nlpd(t, dt, x, ref, vp, gains, mem, cmd)


@njit(MISSION_SIG)
def raising_mission(t, mp, ref):
    """Hover until RAISE_AT, then a ValueError."""
    if t >= RAISE_AT:
        raise ValueError(MESSAGE)
    _hover(t, mp, ref)


@njit(DISTURBANCE_SIG)
def raising_air(t, dt, x, dp, dmem, rng, ext):
    """Still air until RAISE_AT, then a ValueError."""
    if t >= RAISE_AT:
        raise ValueError(MESSAGE)
    for j in range(EXT_SIZE):
        ext[j] = 1.0 if j >= EXT_E1 else 0.0


class Law:
    """A controller of the user's (``ControllerLike``): nlpd's gains and memory, its own function."""

    def __init__(self, raising: bool = True) -> None:
        self.name = "raising" if raising else "calm"
        self.function = raising_law if raising else calm_law

    def gains(self):
        return NLPD().gains()

    def memory(self):
        return NLPD().memory()


@dataclass(frozen=True)
class RaisingHover(Hover):
    """The hover mission whose compiled function raises from RAISE_AT on."""

    function = staticmethod(raising_mission)


def raising_environment() -> CustomDisturbance:
    """A disturbance that raises from RAISE_AT on."""
    return CustomDisturbance(raising_air, params=[0.0], memory=[0.0])


__all__ = ["Law", "RaisingHover", "raising_environment", "MESSAGE", "RAISE_AT"]
