"""The ``sysid`` mission: hover with 1-2-1 doublets of the acceleration reference on roll, pitch,
thrust and yaw, then roll and pitch doublets while spinning, flown closed loop for a log worth
identifying. What each doublet excites and why its defaults: docs/missions.md and
docs/identify.md.

Examples
--------
>>> m = Sysid()
>>> round(m.duration, 6)
58.0
>>> ref = m.reference([0.0, 2.25, 4.5, 5.0])   # hover; inside the roll doublet; after it; pitch's start
>>> ref[:, 1].round(4) + 0.0                     # y: the doublet's position comes back to 0
array([0.    , 0.0469, 0.    , 0.    ])
>>> ref[:, 7].round(3) + 0.0                     # ay: +A for a pulse
array([0. , 1.5, 0. , 0. ])
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import ClassVar

from numba import njit

from quadcruise import layout as L
from quadcruise.fields import unit_field as _f
from quadcruise.missions.base import Mission

__all__ = ["Sysid", "sysid_ref"]

AXES_ORDER = ("roll", "pitch", "thrust", "yaw")
"""The doublets of each repeat before the spin, in order (then roll, pitch, roll, pitch spinning)."""


@njit(cache=True, error_model="numpy")
def _doublet(w, pulse, amp):
    """Position, velocity and acceleration of a 1-2-1 acceleration doublet, ``w`` after its start."""
    if w < 0.0 or w >= 4.0 * pulse:
        return 0.0, 0.0, 0.0
    if w < pulse:
        return 0.5 * amp * w * w, amp * w, amp
    if w < 3.0 * pulse:
        v = w - pulse
        return amp * (0.5 * pulse * pulse + pulse * v - 0.5 * v * v), amp * (pulse - v), -amp
    v = w - 3.0 * pulse
    return amp * (0.5 * pulse * pulse - pulse * v + 0.5 * v * v), amp * (v - pulse), amp


@njit(cache=True, error_model="numpy")
def sysid_ref(t, mp, ref):
    """The sysid reference: hover at (x, y, z, yaw) with the doublets of :class:`Sysid`.

    Parameters
    ----------
    t : float
        Time [s].
    mp : numpy.ndarray
        The mission's parameter vector (float64, 1-D): (x [m], y [m], z [m], yaw [rad],
        accel [m/s^2], climb [m/s^2], yaw_accel [rad/s^2], spin [rad/s], pulse [s], rest [s],
        settle [s], repeats [-]).
    ref : numpy.ndarray
        Output, REF_SIZE float64 entries: position [m], velocity [m/s], acceleration
        [m/s^2], yaw [rad] and yaw rate [rad/s] at ``t`` (overwritten).
    """
    for i in range(L.REF_SIZE):
        ref[i] = 0.0
    ref[L.REF_X], ref[L.REF_Y], ref[L.REF_Z], ref[L.REF_PSI] = mp[0], mp[1], mp[2], mp[3]
    accel, climb, yaw_accel, spin, pulse, rest, settle = mp[4], mp[5], mp[6], mp[7], mp[8], mp[9], mp[10]
    repeats = int(mp[11])
    slot = 4.0 * pulse + rest  # one doublet and the hover after it
    ramp = 2.0 * pulse  # spin-up and spin-down time
    hold = rest + 4.0 * slot  # spinning: a rest, then four doublets
    turn = spin * (ramp + hold)  # the yaw one spin adds
    period = 4.0 * slot + 2.0 * ramp + hold + rest  # 4 doublets, spin up, hold, spin down, rest
    tau = t - settle
    if tau < 0.0 or repeats <= 0:
        return
    k = int(math.floor(tau / period))
    if k >= repeats:
        if repeats % 2 == 1:
            ref[L.REF_PSI] += turn
        return
    sign = 1.0 if k % 2 == 0 else -1.0
    if k % 2 == 1:
        ref[L.REF_PSI] += turn  # an odd repeat starts where the even one before it left the yaw
    u = tau - k * period
    if u < 4.0 * slot:  # roll, pitch, thrust, yaw
        j = int(u / slot)
        w = u - j * slot
        if j == 0:
            ref[L.REF_Y] += _doublet(w, pulse, accel)[0]
            ref[L.REF_VY], ref[L.REF_AY] = _doublet(w, pulse, accel)[1], _doublet(w, pulse, accel)[2]
        elif j == 1:
            ref[L.REF_X] += _doublet(w, pulse, accel)[0]
            ref[L.REF_VX], ref[L.REF_AX] = _doublet(w, pulse, accel)[1], _doublet(w, pulse, accel)[2]
        elif j == 2:
            ref[L.REF_Z] += _doublet(w, pulse, climb)[0]
            ref[L.REF_VZ], ref[L.REF_AZ] = _doublet(w, pulse, climb)[1], _doublet(w, pulse, climb)[2]
        else:
            angle, rate, _ = _doublet(w, pulse, yaw_accel)
            ref[L.REF_PSI] += angle
            ref[L.REF_PSI_DOT] = rate
        return
    u -= 4.0 * slot
    rate_step = spin / ramp
    if u < ramp:  # spin up
        ref[L.REF_PSI] += sign * 0.5 * rate_step * u * u
        ref[L.REF_PSI_DOT] = sign * rate_step * u
        return
    u -= ramp
    if u < hold:  # spinning: rest, then roll, pitch, roll, pitch
        ref[L.REF_PSI] += sign * spin * (0.5 * ramp + u)
        ref[L.REF_PSI_DOT] = sign * spin
        w = u - rest
        if w >= 0.0:
            j = int(w / slot)
            w -= j * slot
            pos, vel, acc = _doublet(w, pulse, accel)
            if j % 2 == 0:
                ref[L.REF_Y] += pos
                ref[L.REF_VY], ref[L.REF_AY] = vel, acc
            else:
                ref[L.REF_X] += pos
                ref[L.REF_VX], ref[L.REF_AX] = vel, acc
        return
    u -= hold
    if u < ramp:  # spin down
        ref[L.REF_PSI] += sign * (spin * (0.5 * ramp + hold + u) - 0.5 * rate_step * u * u)
        ref[L.REF_PSI_DOT] = sign * (spin - rate_step * u)
        return
    ref[L.REF_PSI] += sign * turn  # the rest after the spin


@dataclass(frozen=True)
class Sysid(Mission):
    """Hover with 1-2-1 doublets on roll, pitch, thrust and yaw, and roll and pitch doublets
    while spinning: a closed-loop excitation for identification (see the module).

    mp = (x, y, z, yaw, accel, climb, yaw_accel, spin, pulse, rest, settle, repeats).

    Parameters
    ----------
    x, y : float
        Hover position [m].
    z : float
        Hover altitude [m].
    yaw : float
        Yaw at the start [rad].
    accel : float
        Horizontal acceleration of the roll and pitch doublets [m/s^2], > 0 (tilt steps of
        about arctan(accel / g)).
    climb : float
        Vertical acceleration of the thrust doublet [m/s^2], > 0.
    yaw_accel : float
        Yaw acceleration of the yaw doublet [rad/s^2], > 0.
    spin : float
        Yaw rate held while the roll and pitch doublets are flown again [rad/s], > 0.
    pulse : float
        A doublet's unit step [s], > 0 (a doublet lasts 4 of them).
    rest : float
        Hover after each doublet [s], >= 0.
    settle : float
        Hover before the first doublet [s], >= 0.
    repeats : int
        How many times the pattern is flown (each spinning the other way), >= 1.

    Examples
    --------
    >>> Sysid(repeats=1).duration
    30.0
    >>> Sysid(pulse=0.0)
    Traceback (most recent call last):
        ...
    quadcruise.errors.InputError: sysid field 'pulse' (a doublet's unit step, s) must be > 0, got 0.0
    """

    x: float = _f(0.0, "m", "hover x")
    y: float = _f(0.0, "m", "hover y")
    z: float = _f(2.0, "m", "hover altitude")
    yaw: float = _f(0.0, "rad", "yaw at the start")
    accel: float = _f(1.5, "m/s^2", "horizontal acceleration of the roll and pitch doublets", "pos")
    climb: float = _f(1.0, "m/s^2", "vertical acceleration of the thrust doublet", "pos")
    yaw_accel: float = _f(2.0, "rad/s^2", "yaw acceleration of the yaw doublet", "pos")
    spin: float = _f(1.0, "rad/s", "yaw rate while spinning", "pos")
    pulse: float = _f(0.5, "s", "a doublet's unit step", "pos")
    rest: float = _f(1.0, "s", "hover after each doublet", "nonneg")
    settle: float = _f(2.0, "s", "hover before the first doublet", "nonneg")
    repeats: int = _f(2, "-", "times the pattern is flown", "whole")

    name: ClassVar[str] = "sysid"
    columns: ClassVar[tuple] = (
        "x",
        "y",
        "z",
        "yaw",
        "accel",
        "climb",
        "yaw_accel",
        "spin",
        "pulse",
        "rest",
        "settle",
        "repeats",
    )
    function = staticmethod(sysid_ref)

    def __post_init__(self) -> None:
        super().__post_init__()
        if self.repeats < 1:
            from quadcruise.errors import InputError

            raise InputError(f"sysid field 'repeats' (times the pattern is flown, -) must be >= 1, got {self.repeats}")

    @property
    def period(self) -> float:
        """One repeat of the pattern [s]: 8 doublets, the spin up and down, two rests."""
        slot = 4.0 * self.pulse + self.rest
        return 8.0 * slot + 4.0 * self.pulse + 2.0 * self.rest

    @property
    def duration(self) -> float:
        """The settling hover and every repeat [s]."""
        return self.settle + self.repeats * self.period

    def _row(self) -> tuple:
        return (
            self.x,
            self.y,
            self.z,
            self.yaw,
            self.accel,
            self.climb,
            self.yaw_accel,
            self.spin,
            self.pulse,
            self.rest,
            self.settle,
            float(self.repeats),
        )
