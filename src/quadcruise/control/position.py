"""The paper's position controller: the inverse-model nonlinear PD (eqs 16 and 19), with a
tilt-compensated altitude law and a yaw hold, over the decoupled attitude PID.

Per control period, with a = U1 / m:

1. PD on each axis (eq 16, with the error sign fixed to e = x_r - x; the paper prints
   x - x_r, which is positive feedback)::

       u_x = Kp (x_r - x) + Kd (x_r' - x')   [+ x_r'' if acceleration feedforward is on]

2. Altitude (not in the paper): u_z the same PD on z, and the tilt-compensated thrust
   U1 = m (g + u_z) / (cos phi cos theta), limited to [0, 4 K].
3. Pitch setpoint from eq (5) solved for theta with the current phi, psi (eq 16)::

       sin theta_d = (u_x - sin phi sin psi a) / (cos phi cos psi a)

4. Roll setpoint from eq (6) solved *exactly* for phi given theta_d and psi. The paper's
   eq (19) squares the equation and takes a square root, which loses the sign of phi;
   with A = cos psi, B = sin theta_d sin psi, eq (6) reads A sin phi - B cos phi = -u_y/a,
   i.e. sin(phi - gamma) = -u_y / (a R), R = hypot(A, B), gamma = atan2(B, A); of the two
   roots we take the one nearest level, which for cos psi > 0 is gamma - asin(u_y / (a R))
   with gamma = atan(B / A). At psi = 0 this is phi_d = -asin(u_y / a): the paper's form
   with its sign restored. sin theta_d is the asin argument of step 3 (or sin max_tilt when
   the pitch was limited), not a new sine.
5. Yaw setpoint: the mission's yaw (a hold at 0 by default).

Every asin argument outside [-1, 1] is clipped and flagged (FLAG_ASIN_CLIP), and roll and
pitch setpoints are limited to ``max_tilt`` (FLAG_TILT_LIMIT). The sequential inversion
(x first, then y) needs cos psi away from 0: it is the paper's design for a vehicle
holding yaw near zero.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np
from numba import njit

from quadcruise.control.attitude import (
    ATT_GAINS,
    ATT_I_LIMIT,
    ATT_KD,
    ATT_KI,
    ATT_KP,
    ATT_MEMORY,
    YAW_KD,
    YAW_KI,
    YAW_KP,
    decoupled_attitude,
)
from quadcruise.control.base import Controller, check_positive, write_command
from quadcruise.control.design import PDGains, PIDGains, altitude_pd_design, attitude_pid_design, position_pd_design
from quadcruise.errors import InputError
from quadcruise.layout import (
    CONTROLLER_SIG,
    FLAG_ASIN_CLIP,
    FLAG_THRUST_LIMIT,
    FLAG_TILT_LIMIT,
    P_D,
    P_G,
    P_K,
    P_M,
    PHI,
    PSI,
    REF_AX,
    REF_AY,
    REF_AZ,
    REF_PSI,
    REF_VX,
    REF_VY,
    REF_VZ,
    REF_X,
    REF_Y,
    REF_Z,
    THETA,
    VX,
    VY,
    VZ,
    X,
    Y,
    Z,
)

# gains layout after the attitude block
# (COS_MAX_TILT and SIN_MAX_TILT are cos and sin of MAX_TILT, so the step calls neither: a
# kept trick, see quadcruise.sim.fastmath)
KP_XY, KD_XY, KP_Z, KD_Z, MAX_TILT, ACCEL_FF, COS_MAX_TILT, SIN_MAX_TILT = range(ATT_GAINS, ATT_GAINS + 8)
NLPD_GAINS = ATT_GAINS + 8


@njit(cache=True, inline="always", error_model="numpy")
def clip_unit(s):
    """s clipped to [-1, 1], and whether it had to be."""
    if s > 1.0:
        return 1.0, True
    if s < -1.0:
        return -1.0, True
    return s, False


@njit(cache=True, inline="always", error_model="numpy")
def limit(value, bound):
    """value clipped to [-bound, bound], and whether it had to be."""
    if value > bound:
        return bound, True
    if value < -bound:
        return -bound, True
    return value, False


@njit(cache=True, inline="always", error_model="numpy")
def pitch_eq16(ux, sphi, cphi, spsi, cpsi, a):
    """Eq (16) from the sines and cosines of roll and yaw (see :func:`theta_from_eq5`):
    (theta, sin theta, clipped?)."""
    den = cphi * cpsi * a
    if abs(den) < 1e-9:
        return 0.0, 0.0, True
    s, clipped = clip_unit((ux - sphi * spsi * a) / den)
    return math.asin(s), s, clipped


@njit(cache=True, inline="always", error_model="numpy")
def roll_eq19(uy, stheta, spsi, cpsi, a):
    """Eq (19), sign kept, from sin(theta) and the yaw's sine and cosine (see :func:`phi_from_eq6`)."""
    A = cpsi
    B = stheta * spsi
    R = math.sqrt(A * A + B * B)         # |A|, |B| <= 1: no overflow to guard against
    if R * a < 1e-9:
        return 0.0, True
    s, clipped = clip_unit(uy / (a * R))
    r1 = math.asin(s)
    if A > 0.0:
        # |gamma| < pi/2 and |r1| <= pi/2: gamma - r1 lies in (-pi, pi) and, cos phi1 -
        # cos phi2 = 2 A sqrt(1 - s^2) / R >= 0, it is the root nearest level (a kept trick,
        # see quadcruise.sim.fastmath; plain: the general case below)
        return math.atan(B / A) - r1, clipped
    gamma = math.atan2(B, A)
    phi1 = gamma - r1
    phi2 = gamma + math.pi + r1
    phi1 -= 2.0 * math.pi * math.floor((phi1 + math.pi) / (2.0 * math.pi))
    phi2 -= 2.0 * math.pi * math.floor((phi2 + math.pi) / (2.0 * math.pi))
    return (phi1 if abs(phi1) <= abs(phi2) else phi2), clipped


@njit(cache=True, error_model="numpy")
def theta_from_eq5(ux, phi, psi, a):
    """Eq (16): the pitch that gives x'' = ux at roll phi, yaw psi and a = U1/m [m/s^2]."""
    theta, _, clipped = pitch_eq16(ux, math.sin(phi), math.cos(phi), math.sin(psi), math.cos(psi), a)
    return theta, clipped


@njit(cache=True, error_model="numpy")
def phi_from_eq6(uy, theta, psi, a):
    """Eq (19), sign-preserving: the roll that gives y'' = uy at pitch theta, yaw psi."""
    return roll_eq19(uy, math.sin(theta), math.sin(psi), math.cos(psi), a)


@njit(cache=True, inline="always", error_model="numpy")
def thrust_for_tilt(uz, cos_tilt, m, g, K, cos_max_tilt):
    """Altitude law: U1 = m (g + u_z) / (cos phi cos theta), limited to [0, 4 K] [N], and its
    flag. ``cos_tilt`` is cos phi cos theta; the compensation uses at most 1/cos(max_tilt) so
    that it cannot blow up."""
    c = max(cos_tilt, cos_max_tilt)
    U1 = m * (g + uz) / c
    if U1 < 0.0:
        return 0.0, FLAG_THRUST_LIMIT
    if U1 > 4.0 * K:
        return 4.0 * K, FLAG_THRUST_LIMIT
    return U1, 0


@njit(cache=True, inline="always", error_model="numpy")
def tilt_setpoint(angle, clipped, max_tilt, flags):
    """Limit a roll/pitch setpoint to max_tilt and add the flags that apply."""
    if clipped:
        flags |= FLAG_ASIN_CLIP
    angle, limited = limit(angle, max_tilt)
    if limited:
        flags |= FLAG_TILT_LIMIT
    return angle, flags


@njit(cache=True, inline="always", error_model="numpy")
def finish(U1, phi_d, theta_d, psi_d, flags, dt, x, vp, gains, mem, cmd):
    """Shared tail of the position controllers: the decoupled attitude PID (eqs 13-15), the
    mixer inverse to duties, and the logged command.

    Like :func:`~quadcruise.control.attitude.decoupled_attitude`, it reads before it writes
    and writes last: the scalar-only rule of :mod:`quadcruise.sim.fastmath`.
    """
    U2, U3, U4, att_flags = decoupled_attitude(x, phi_d, theta_d, psi_d, vp, gains, mem, dt)
    write_command(cmd, U1, U2, U3, U4, phi_d, theta_d, psi_d, flags | att_flags, vp[P_D], vp[P_K])


@njit(CONTROLLER_SIG, cache=True, error_model="numpy")
def nlpd(t, dt, x, ref, vp, gains, mem, cmd):
    """The paper's inverse-model nonlinear PD (eqs 16, 19) over decoupled attitude PID."""
    ff, tilt = gains[ACCEL_FF], gains[MAX_TILT]
    ux = gains[KP_XY] * (ref[REF_X] - x[X]) + gains[KD_XY] * (ref[REF_VX] - x[VX]) + ff * ref[REF_AX]
    uy = gains[KP_XY] * (ref[REF_Y] - x[Y]) + gains[KD_XY] * (ref[REF_VY] - x[VY]) + ff * ref[REF_AY]
    uz = gains[KP_Z] * (ref[REF_Z] - x[Z]) + gains[KD_Z] * (ref[REF_VZ] - x[VZ]) + ff * ref[REF_AZ]
    phi, theta, psi, psi_d = x[PHI], x[THETA], x[PSI], ref[REF_PSI]
    m, g, K = vp[P_M], vp[P_G], vp[P_K]
    sphi, cphi = math.sin(phi), math.cos(phi)           # each computed once, shared
    spsi, cpsi = math.sin(psi), math.cos(psi)
    U1, flags = thrust_for_tilt(uz, cphi * math.cos(theta), m, g, K, gains[COS_MAX_TILT])
    a = U1 / m
    # sin theta_d is eq (16)'s asin argument, not a new sine (a kept trick: quadcruise.sim.fastmath)
    pitch, stheta_d, clipped = pitch_eq16(ux, sphi, cphi, spsi, cpsi, a)      # (16)
    theta_d, flags = tilt_setpoint(pitch, clipped, tilt, flags)
    if theta_d != pitch:                  # limited: sin theta_d is no longer asin's argument
        stheta_d = math.copysign(gains[SIN_MAX_TILT], theta_d)
    phi_d, clipped = roll_eq19(uy, stheta_d, spsi, cpsi, a)                    # (19), sign kept
    phi_d, flags = tilt_setpoint(phi_d, clipped, tilt, flags)
    finish(U1, phi_d, theta_d, psi_d, flags, dt, x, vp, gains, mem, cmd)


def attitude_block(attitude: PIDGains, yaw: PIDGains, i_limit: float) -> list[float]:
    """The first ATT_GAINS entries of a controller's gains vector."""
    block = [0.0] * ATT_GAINS
    block[ATT_KP], block[ATT_KI], block[ATT_KD] = attitude.kp, attitude.ki, attitude.kd
    block[YAW_KP], block[YAW_KI], block[YAW_KD] = yaw.kp, yaw.ki, yaw.kd
    block[ATT_I_LIMIT] = i_limit
    return block


@dataclass(frozen=True)
class NLPD(Controller):
    """The paper's controller: inverse-model nonlinear PD on x, y (eqs 16, 19), PD altitude
    with tilt-compensated thrust, decoupled PID attitude (eqs 13-15) and yaw hold.

    Parameters
    ----------
    position : PDGains
        x and y loops; the paper's poles -0.7, -4.3 give Kp = 3.01 1/s^2, Kd = 5.0 1/s (eq 18).
    altitude : PDGains
        z loop (not in the paper; the same poles by default).
    attitude : PIDGains
        roll and pitch loops on the decoupled double integrator (not in the paper).
    yaw : PIDGains
        yaw loop (not in the paper; same as attitude by default).
    max_tilt : float
        roll and pitch setpoint limit [rad]; 45 degrees by default.
    i_limit : float
        anti-windup bound on the integral term Ki int(e) [rad/s^2].
    accel_feedforward : bool
        add the reference acceleration to u_x, u_y, u_z (off: the paper's eq 16 has none).

    Examples
    --------
    >>> from quadcruise.control.position import NLPD
    >>> c = NLPD()
    >>> round(c.position.kp, 2), round(c.position.kd, 2)
    (3.01, 5.0)
    >>> c.gains().shape, c.memory().shape
    ((15,), (3,))
    """

    name = "nlpd"
    memory_size = ATT_MEMORY

    position: PDGains = field(default_factory=position_pd_design)
    altitude: PDGains = field(default_factory=altitude_pd_design)
    attitude: PIDGains = field(default_factory=attitude_pid_design)
    yaw: PIDGains = field(default_factory=attitude_pid_design)
    max_tilt: float = math.radians(45.0)
    i_limit: float = 5.0
    accel_feedforward: bool = False

    def __post_init__(self) -> None:
        check_positive(self.name, max_tilt=self.max_tilt, i_limit=self.i_limit)
        if self.max_tilt >= math.pi / 2:
            raise InputError(f"{self.name} parameter 'max_tilt' must be below pi/2 rad, got {self.max_tilt!r}")

    @property
    def function(self):
        return nlpd

    def gains(self) -> np.ndarray:
        tail = [self.position.kp, self.position.kd, self.altitude.kp, self.altitude.kd,
                self.max_tilt, 1.0 if self.accel_feedforward else 0.0,
                math.cos(self.max_tilt), math.sin(self.max_tilt)]
        return np.array(attitude_block(self.attitude, self.yaw, self.i_limit) + tail)
