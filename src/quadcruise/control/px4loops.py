"""PX4's multicopter loops (release v1.15), compiled, for one vehicle, in PX4's frames.

Written from PX4-Autopilot's source:

- :func:`rate_control`: ``src/lib/rate_control/rate_control.cpp`` as
  ``src/modules/mc_rate_control/MulticopterRateControl.cpp`` sets it up:
  ``tau = K P e + i - K D w' + FF w_sp`` with ``e = w_sp - w``, ``w'`` the (filtered) rate
  derivative, and the integral ``i += f K I e dt``, ``f = max(0, 1 - (e / 400 deg/s)^2)``,
  within ``+-MC_*R_INT_LIM``, not grown in a direction the allocator reports saturated and
  not at all while landed. ``tau`` is normalised torque (1 = the allocator's full torque).
- :func:`attitude_control`: ``src/modules/mc_att_control/AttitudeControl/AttitudeControl.cpp``:
  the tilt error first (the reduced attitude turning the body z axis onto the setpoint's),
  then ``MC_YAW_WEIGHT`` of the yaw error; rates ``P * 2 imag(q^-1 q_d)`` (the yaw gain over
  the weight), plus the yaw-rate feed-forward about the world z axis, each within
  ``MC_*RATE_MAX``.
- :func:`position_control`: ``src/modules/mc_pos_control/PositionControl/PositionControl.cpp``
  and ``ControlMath.cpp``: position P to a velocity setpoint (limited, the position term
  first), velocity PID with D on the measured acceleration to an acceleration setpoint, to a
  thrust vector (tilt within ``MPC_TILTMAX_AIR``, collective thrust scaled by the hover thrust
  and within ``[MPC_THR_MIN, MPC_THR_MAX]``, vertical first with ``MPC_THR_XY_MARG`` kept for
  the horizontal), vertical anti-windup and horizontal tracking anti-windup.

Frames are PX4's: NED world, FRD body, quaternions (w, x, y, z) body to world. Vectors are
3-tuples; the gains one float64 row, :data:`PX4_GAINS`, made from PX4's parameters by
:func:`px4_gains`. Converting quadcruise's ENU/FLU state is left to the caller
(:mod:`quadcruise.sim.px4` has the two axis swaps).
"""

from __future__ import annotations

import math
from collections.abc import Mapping

import numpy as np
from numba import njit

from quadcruise import layout as L
from quadcruise.control.px4math import (
    add_if_not_nan,
    constrain_xy,
    dcm_z,
    limit_tilt,
    qcanonical,
    qinv,
    qmul,
    quat_between,
)

__all__ = [
    "PX4_GAINS",
    "px4_gains",
    "rate_control",
    "attitude_control",
    "position_control",
    "hover_thrust_integral",
    "ONE_G",
]

ONE_G = 9.80665
"""PX4's ``CONSTANTS_ONE_G`` [m/s^2]."""
I_FACTOR_RATE = math.radians(400.0)
"""The rate error at which PX4's rate integral stops growing [rad/s]."""

PX4_GAINS = L.Row.of(
    "px4 gains",
    ("rate_p", 3),
    ("rate_i", 3),
    ("rate_d", 3),
    ("rate_ff", 3),
    ("rate_ilim", 3),
    ("att_p", 3),
    "yaw_w",
    ("rate_max", 3),
    ("pos_p", 3),
    ("vel_p", 3),
    ("vel_i", 3),
    ("vel_d", 3),
    "vmax_xy",
    "vmax_up",
    "vmax_dn",
    "tilt_max",
    "thr_hover",
    "thr_min",
    "thr_max",
    "thr_xy_marg",
    prefix="G_",
)
"""The loops' gains in SI units (rad, rad/s, m/s; torque and thrust normalised), PX4's axis
order (roll, pitch, yaw; x, y, z = north, east, down)."""
(
    G_RATE_P,
    G_RATE_I,
    G_RATE_D,
    G_RATE_FF,
    G_RATE_ILIM,
    G_ATT_P,
    G_YAW_W,
    G_RATE_MAX,
    G_POS_P,
    G_VEL_P,
    G_VEL_I,
    G_VEL_D,
    G_VMAX_XY,
    G_VMAX_UP,
    G_VMAX_DN,
    G_TILT_MAX,
    G_THR_HOVER,
    G_THR_MIN,
    G_THR_MAX,
    G_THR_XY_MARG,
) = PX4_GAINS.offsets


def px4_gains(params: Mapping[str, float]) -> np.ndarray:
    """The gain row of PX4 parameters, as PX4's modules set their controllers up.

    ``MC_*RATE_K`` multiplies P, I and D (not FF); rate and tilt limits in degrees become
    radians; the xy gains serve north and east alike.

    Parameters
    ----------
    params : Mapping of str to float
        Every parameter of :data:`quadcruise.io.px4defaults.PX4_PARAMETERS` (e.g. a
        :class:`~quadcruise.io.px4params.Px4Parameters`), PX4's units.

    Returns
    -------
    numpy.ndarray
        :data:`PX4_GAINS`'s row.

    Examples
    --------
    >>> from quadcruise.io.px4params import Px4Parameters
    >>> g = px4_gains(Px4Parameters.defaults().with_values(MC_ROLLRATE_K=2.0))
    >>> float(g[G_RATE_P]), float(g[G_RATE_I]), round(float(g[G_RATE_MAX]), 4)
    (0.3, 0.4, 3.8397)
    """
    p = params
    k = (p["MC_ROLLRATE_K"], p["MC_PITCHRATE_K"], p["MC_YAWRATE_K"])

    def axes(suffix):
        return [p[f"MC_ROLLRATE_{suffix}"], p[f"MC_PITCHRATE_{suffix}"], p[f"MC_YAWRATE_{suffix}"]]

    xy_z = lambda xy, z: [p[xy], p[xy], p[z]]  # noqa: E731
    return PX4_GAINS.pack(
        {
            "rate_p": [a * b for a, b in zip(k, axes("P"), strict=True)],
            "rate_i": [a * b for a, b in zip(k, axes("I"), strict=True)],
            "rate_d": [a * b for a, b in zip(k, axes("D"), strict=True)],
            "rate_ff": axes("FF"),
            "rate_ilim": [p["MC_RR_INT_LIM"], p["MC_PR_INT_LIM"], p["MC_YR_INT_LIM"]],
            "att_p": [p["MC_ROLL_P"], p["MC_PITCH_P"], p["MC_YAW_P"]],
            "yaw_w": p["MC_YAW_WEIGHT"],
            "rate_max": [math.radians(v) for v in axes("MAX")],
            "pos_p": xy_z("MPC_XY_P", "MPC_Z_P"),
            "vel_p": xy_z("MPC_XY_VEL_P_ACC", "MPC_Z_VEL_P_ACC"),
            "vel_i": xy_z("MPC_XY_VEL_I_ACC", "MPC_Z_VEL_I_ACC"),
            "vel_d": xy_z("MPC_XY_VEL_D_ACC", "MPC_Z_VEL_D_ACC"),
            "vmax_xy": p["MPC_XY_VEL_MAX"],
            "vmax_up": p["MPC_Z_VEL_MAX_UP"],
            "vmax_dn": p["MPC_Z_VEL_MAX_DN"],
            "tilt_max": math.radians(p["MPC_TILTMAX_AIR"]),
            "thr_hover": p["MPC_THR_HOVER"],
            "thr_min": p["MPC_THR_MIN"],
            "thr_max": p["MPC_THR_MAX"],
            "thr_xy_marg": p["MPC_THR_XY_MARG"],
        }
    )


@njit(cache=True, error_model="numpy")
def rate_control(rate, rate_sp, accel, dt, landed, g, sat_pos, sat_neg, integ):
    """One step of PX4's rate controller (``RateControl::update``).

    ``tau_i = P_i e_i + integ_i - D_i accel_i + FF_i rate_sp_i`` with ``e = rate_sp - rate``;
    then, unless ``landed``, the integral grows by ``f K I e dt``,
    ``f = max(0, 1 - (e / 400 deg/s)^2)``, with ``e`` cut to <= 0 where the allocator is
    saturated positively (``sat_pos``) and to >= 0 where negatively, within the limit.

    Parameters
    ----------
    rate, rate_sp, accel : tuple of 3 float
        Body rates (FRD) [rad/s], their setpoint [rad/s] and derivative [rad/s^2].
    dt : float
        Period [s].
    landed : bool
        PX4's ``landed`` (or ``maybe_landed``): the integral is held.
    g : numpy.ndarray
        :data:`PX4_GAINS`'s row (P, I, D already times ``MC_*RATE_K``).
    sat_pos, sat_neg : tuple of 3 bool
        The allocator's saturation per axis (``control_allocator_status.unallocated_torque``
        above or below zero).
    integ : tuple of 3 float
        The integral before the step (normalised torque).

    Returns
    -------
    torque : tuple of 3 float
        Normalised torque setpoint (``vehicle_torque_setpoint.xyz``).
    integ : tuple of 3 float
        The integral after the step (``rate_ctrl_status.*speed_integ``).
    """
    t0 = g[G_RATE_P] * (rate_sp[0] - rate[0]) + integ[0] - g[G_RATE_D] * accel[0] + g[G_RATE_FF] * rate_sp[0]
    t1 = (
        g[G_RATE_P + 1] * (rate_sp[1] - rate[1]) + integ[1] - g[G_RATE_D + 1] * accel[1] + g[G_RATE_FF + 1] * rate_sp[1]
    )
    t2 = (
        g[G_RATE_P + 2] * (rate_sp[2] - rate[2]) + integ[2] - g[G_RATE_D + 2] * accel[2] + g[G_RATE_FF + 2] * rate_sp[2]
    )
    if landed:
        return (t0, t1, t2), integ
    out0 = _integrate(integ[0], rate_sp[0] - rate[0], dt, g[G_RATE_I], g[G_RATE_ILIM], sat_pos[0], sat_neg[0])
    out1 = _integrate(integ[1], rate_sp[1] - rate[1], dt, g[G_RATE_I + 1], g[G_RATE_ILIM + 1], sat_pos[1], sat_neg[1])
    out2 = _integrate(integ[2], rate_sp[2] - rate[2], dt, g[G_RATE_I + 2], g[G_RATE_ILIM + 2], sat_pos[2], sat_neg[2])
    return (t0, t1, t2), (out0, out1, out2)


@njit(cache=True, inline="always", error_model="numpy")
def _integrate(integ, error, dt, ki, limit, sat_pos, sat_neg):
    if sat_pos:
        error = min(error, 0.0)
    if sat_neg:
        error = max(error, 0.0)
    f = error / I_FACTOR_RATE
    f = max(0.0, 1.0 - f * f)
    value = integ + f * ki * error * dt
    if math.isfinite(value):
        return min(max(value, -limit), limit)
    return integ


@njit(cache=True, error_model="numpy")
def attitude_control(q, qd, yawspeed_sp, g):
    """One step of PX4's attitude controller (``AttitudeControl::update``).

    Parameters
    ----------
    q, qd : tuple of 4 float
        The attitude and its setpoint (w, x, y, z; FRD body to NED), unit.
    yawspeed_sp : float
        Yaw-rate feed-forward about the world z axis [rad/s] (``yaw_sp_move_rate``); NaN for none.
    g : numpy.ndarray
        :data:`PX4_GAINS`'s row.

    Returns
    -------
    tuple of 3 float
        Body rate setpoint (FRD) [rad/s] (``vehicle_rates_setpoint``).
    """
    yaw_w = min(max(g[G_YAW_W], 0.0), 1.0)
    kyaw = g[G_ATT_P + 2] / yaw_w if yaw_w > 1e-4 else g[G_ATT_P + 2]
    e_z = dcm_z(q)
    e_z_d = dcm_z(qd)
    qd_red = quat_between(e_z, e_z_d)
    if abs(qd_red[1]) > 1.0 - 1e-5 or abs(qd_red[2]) > 1.0 - 1e-5:
        qd_red = qd
    else:
        qd_red = qmul(qd_red, q)
    q_mix = qcanonical(qmul(qinv(qd_red), qd))
    mix_w = min(max(q_mix[0], -1.0), 1.0)
    mix_z = min(max(q_mix[3], -1.0), 1.0)
    qd_full = qmul(qd_red, (math.cos(yaw_w * math.acos(mix_w)), 0.0, 0.0, math.sin(yaw_w * math.asin(mix_z))))
    qe = qcanonical(qmul(qinv(q), qd_full))
    r0 = 2.0 * qe[1] * g[G_ATT_P]
    r1 = 2.0 * qe[2] * g[G_ATT_P + 1]
    r2 = 2.0 * qe[3] * kyaw
    if math.isfinite(yawspeed_sp):
        zb = dcm_z(qinv(q))
        r0 += zb[0] * yawspeed_sp
        r1 += zb[1] * yawspeed_sp
        r2 += zb[2] * yawspeed_sp
    lim0, lim1, lim2 = g[G_RATE_MAX], g[G_RATE_MAX + 1], g[G_RATE_MAX + 2]
    return (min(max(r0, -lim0), lim0), min(max(r1, -lim1), lim1), min(max(r2, -lim2), lim2))


@njit(cache=True, inline="always")
def hover_thrust_integral(vel_int_z, hover_old, hover_new, acc_sp_z):
    """``PositionControl::updateHoverThrust``: the vertical velocity integral [m/s^2] moved so
    that a new hover thrust leaves the thrust output as it was: with the last acceleration
    setpoint ``a`` (NED z), the thrust ``a h / g - h`` is kept by adding
    ``(a - g) h_old / h_new + g - a`` (at ``a = 0``: ``(h_new - h_old) g / h_new``)."""
    return vel_int_z + (acc_sp_z - ONE_G) * hover_old / hover_new + ONE_G - acc_sp_z


@njit(cache=True, error_model="numpy")
def _valid_input(pos, vel, vel_dot, pos_sp, vel_sp, acc_sp):
    ok = True
    for i in range(3):
        ok = ok and (math.isfinite(pos_sp[i]) or math.isfinite(vel_sp[i]) or math.isfinite(acc_sp[i]))
    ok = ok and (math.isfinite(pos_sp[0]) == math.isfinite(pos_sp[1]))
    ok = ok and (math.isfinite(vel_sp[0]) == math.isfinite(vel_sp[1]))
    ok = ok and (math.isfinite(acc_sp[0]) == math.isfinite(acc_sp[1]))
    for i in range(3):
        if math.isfinite(pos_sp[i]):
            ok = ok and math.isfinite(pos[i])
        if math.isfinite(vel_sp[i]):
            ok = ok and math.isfinite(vel[i]) and math.isfinite(vel_dot[i])
    return ok


@njit(cache=True, error_model="numpy")
def position_control(pos, vel, vel_dot, pos_sp, vel_sp, acc_sp, dt, g, hover, tilt, vel_int):
    """One step of PX4's position controller (``PositionControl::update``), NED.

    NaN in a setpoint means "not given" (PX4's convention); each axis needs one of position,
    velocity or acceleration, and north and east come in pairs, else nothing is computed.

    Parameters
    ----------
    pos, vel, vel_dot : tuple of 3 float
        Position [m], velocity [m/s] and its derivative [m/s^2], NED.
    pos_sp, vel_sp, acc_sp : tuple of 3 float
        The trajectory setpoint (``trajectory_setpoint``), NaN where not given.
    dt : float
        Period [s].
    g : numpy.ndarray
        :data:`PX4_GAINS`'s row.
    hover : float
        Hover thrust (normalised): ``MPC_THR_HOVER`` or the hover-thrust estimate.
    tilt : float
        Tilt limit [rad] (``MPC_TILTMAX_AIR`` in the air).
    vel_int : tuple of 3 float
        Velocity integral before the step [m/s^2].

    Returns
    -------
    vel_sp, acc_sp, thr_sp : tuple of 3 float
        The velocity and acceleration setpoints used and the thrust vector (normalised, NED).
    vel_int : tuple of 3 float
        The integral after the step (unchanged when invalid).
    valid : bool
        Whether the input was complete and the output finite (PX4's return value).
    """
    nan3 = (math.nan, math.nan, math.nan)
    if not _valid_input(pos, vel, vel_dot, pos_sp, vel_sp, acc_sp):
        return nan3, nan3, nan3, vel_int, False
    thr_min = max(g[G_THR_MIN], 10e-4)
    thr_max = g[G_THR_MAX]
    # position P, the position's share first within the horizontal speed limit
    vp0 = (pos_sp[0] - pos[0]) * g[G_POS_P]
    vp1 = (pos_sp[1] - pos[1]) * g[G_POS_P + 1]
    vp2 = (pos_sp[2] - pos[2]) * g[G_POS_P + 2]
    v0 = add_if_not_nan(vel_sp[0], vp0)
    v1 = add_if_not_nan(vel_sp[1], vp1)
    v2 = add_if_not_nan(vel_sp[2], vp2)
    vp0 = vp0 if math.isfinite(vp0) else 0.0
    vp1 = vp1 if math.isfinite(vp1) else 0.0
    vp2 = vp2 if math.isfinite(vp2) else 0.0
    v0, v1 = constrain_xy((vp0, vp1), (v0 - vp0, v1 - vp1), g[G_VMAX_XY])
    lo, hi = -g[G_VMAX_UP], g[G_VMAX_DN]  # math::constrain: the lower bound wins (the takeoff ramp's lo > hi)
    v2 = lo if v2 < lo else (hi if v2 > hi else v2)
    # velocity PID, D on the measured acceleration
    iz = min(max(vel_int[2], -ONE_G), ONE_G)
    e0, e1, e2 = v0 - vel[0], v1 - vel[1], v2 - vel[2]
    a0 = add_if_not_nan(acc_sp[0], e0 * g[G_VEL_P] + vel_int[0] - vel_dot[0] * g[G_VEL_D])
    a1 = add_if_not_nan(acc_sp[1], e1 * g[G_VEL_P + 1] + vel_int[1] - vel_dot[1] * g[G_VEL_D + 1])
    a2 = add_if_not_nan(acc_sp[2], e2 * g[G_VEL_P + 2] + iz - vel_dot[2] * g[G_VEL_D + 2])
    # acceleration to thrust (tilt decoupled from the vertical acceleration, as v1.15)
    n = math.sqrt(a0 * a0 + a1 * a1 + ONE_G * ONE_G)
    bz = limit_tilt((-a0 / n, -a1 / n, ONE_G / n), (0.0, 0.0, 1.0), tilt)
    thrust_ned_z = a2 * (hover / ONE_G) - hover
    collective = min(thrust_ned_z / bz[2], -thr_min)
    t0, t1, t2 = bz[0] * collective, bz[1] * collective, bz[2] * collective
    # vertical anti-windup
    if (t2 >= -thr_min and e2 >= 0.0) or (t2 <= -thr_max and e2 <= 0.0):
        e2 = 0.0
    # vertical first, a horizontal margin kept
    txy = math.sqrt(t0 * t0 + t1 * t1)
    tmax2 = thr_max * thr_max
    allocated = min(txy, g[G_THR_XY_MARG])
    t2 = max(t2, -math.sqrt(tmax2 - allocated * allocated))
    txy_max2 = tmax2 - t2 * t2
    txy_max = math.sqrt(txy_max2) if txy_max2 > 0.0 else 0.0
    if txy > txy_max:
        t0, t1 = t0 / txy * txy_max, t1 / txy * txy_max
    # horizontal tracking anti-windup
    p0, p1 = t0 * (ONE_G / hover), t1 * (ONE_G / hover)
    if a0 * a0 + a1 * a1 > p0 * p0 + p1 * p1:
        lim0, lim1 = p0, p1
    else:
        lim0, lim1 = a0, a1
    arw = 2.0 / g[G_VEL_P]
    e0 = e0 - arw * (a0 - lim0)
    e1 = e1 - arw * (a1 - lim1)
    e0 = e0 if math.isfinite(e0) else 0.0
    e1 = e1 if math.isfinite(e1) else 0.0
    e2 = e2 if math.isfinite(e2) else 0.0
    new_int = (vel_int[0] + e0 * g[G_VEL_I] * dt, vel_int[1] + e1 * g[G_VEL_I + 1] * dt, iz + e2 * g[G_VEL_I + 2] * dt)
    acc = (a0, a1, a2)
    thr = (t0, t1, t2)
    valid = True
    for i in range(3):
        valid = valid and math.isfinite(acc[i]) and math.isfinite(thr[i])
    return (v0, v1, v2), acc, thr, new_int, valid
