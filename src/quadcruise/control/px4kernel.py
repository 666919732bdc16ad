"""The compiled part of :class:`quadcruise.control.px4.Px4`: its gains and memory rows and
:func:`px4_controller`, one control period of PX4 v1.15's loops, allocation and thrust model
(the steps are in :mod:`quadcruise.control.px4`'s docstring)."""

from __future__ import annotations

import math

from numba import njit

from quadcruise import layout as L
from quadcruise.control.base import write_command
from quadcruise.control.px4allocation import allocate_into
from quadcruise.control.px4filters import alpha_of, lpf2p_apply, lpf2p_coefficients, lpf2p_reset
from quadcruise.control.px4hover import HTE_HOVER, HTE_RATIO, HTE_STATE, HTE_VAR, hte_fuse, hte_noise_scale, hte_predict
from quadcruise.control.px4hover import hte_reset_into as _hte_reset
from quadcruise.control.px4loops import (
    G_RATE_D,
    G_RATE_I,
    G_RATE_P,
    G_THR_HOVER,
    G_THR_MIN,
    G_TILT_MAX,
    G_VEL_P,
    G_VMAX_UP,
    ONE_G,
    PX4_GAINS,
    attitude_control,
    hover_thrust_integral,
    position_control,
    rate_control,
)
from quadcruise.control.px4math import body_z_to_attitude, dcm_from_quat, euler_from_dcm, quat_enu_flu_to_ned_frd

__all__ = ["px4_controller", "resolve_gains", "PX4C_GAINS", "PX4C_MEMORY", "MAX_ROTORS", "YAW_DESIGN_SHARE"]

MAX_ROTORS = 12
"""The most rotors PX4's ``CA_ROTOR*`` parameters describe."""
PX4C_GAINS = L.Row.of(
    "px4 controller gains",
    "n_rotors",
    ("mix", 6 * MAX_ROTORS),
    ("alloc", 4 * MAX_ROTORS),
    ("geom", 3 * MAX_ROTORS),
    ("lo", MAX_ROTORS),
    ("hi", MAX_ROTORS),
    "airmode",
    "thr_mdl_fac",
    "thrust_curve",
    "gyro_cutoff",
    "dgyro_cutoff",
    "veld_lp",
    "pos_period",
    "att_period",
    "hover_auto",
    "designed",
    ("design", 9),
    "hte",
    "takeoff",
    "tko_ramp_t",
    "tko_speed_up",
    "tilt_lnd",
    "hte_noise",
    "hte_gate",
    "hte_err_init",
    "hte_vxy",
    "hte_vz",
    "hte_range",
    parent=PX4_GAINS,
    prefix="X_",
)
"""The gains row of :func:`px4_controller`: :data:`~quadcruise.control.px4loops.PX4_GAINS`, then
the rotor count, PX4's normalised mix (n x 6: roll, pitch, yaw, thrust x, y, z), the
allocated-control rows (n x 4: the effectiveness times PX4's scale, roll, pitch, yaw, thrust z),
the vehicle's layout (n x 3: y / l, -x / l, direction, FLU), each rotor's range, ``MC_AIRMODE``,
``THR_MDL_FAC``, the vehicle's thrust curve, the gyro and D-term cutoffs [Hz], ``MPC_VELD_LP``
[Hz], the position and attitude loops' periods [s], the two vehicle flags and the designed rate P, I, D per
unit inertia (roll, pitch, yaw); then the hover-thrust estimator's and the takeoff's flags, ``MPC_TKO_RAMP_T``
[s], the ramp's target climb rate [m/s], ``MPC_TILTMAX_LND`` [rad], ``HTE_HT_NOISE``, ``HTE_ACC_GATE``,
``HTE_HT_ERR_INIT``, ``HTE_VXY_THR``, ``HTE_VZ_THR`` [m/s] and ``HTE_THR_RANGE``."""
(
    X_N_ROTORS,
    X_MIX,
    X_ALLOC,
    X_GEOM,
    X_LO,
    X_HI,
    X_AIRMODE,
    X_THR_MDL_FAC,
    X_THRUST_CURVE,
    X_GYRO_CUTOFF,
    X_DGYRO_CUTOFF,
    X_VELD_LP,
    X_POS_PERIOD,
    X_ATT_PERIOD,
    X_HOVER_AUTO,
    X_DESIGNED,
    X_DESIGN,
    X_HTE,
    X_TAKEOFF,
    X_TKO_RAMP_T,
    X_TKO_SPEED_UP,
    X_TILT_LND,
    X_HTE_NOISE,
    X_HTE_GATE,
    X_HTE_ERR_INIT,
    X_HTE_VXY,
    X_HTE_VZ,
    X_HTE_RANGE,
) = PX4C_GAINS.offsets
PX4C_MEMORY = L.Row.of(
    "px4 controller memory",
    "init",
    ("integ", 3),
    ("lpf", 6),
    ("coef", 5),
    "alpha_d",
    "last_dt",
    ("raw_last", 3),
    ("accel", 3),
    ("vel_int", 3),
    ("veld", 3),
    ("vel_last", 3),
    "next_pos",
    "last_pos",
    ("qd", 4),
    "thrust",
    "yawspeed",
    ("sat", 6),
    ("euler", 3),
    "next_att",
    ("rate_sp", 3),
    ("g", PX4_GAINS.size),
    ("sp", MAX_ROTORS),
    ("control", 6),
    ("hte", HTE_STATE.size),
    "hte_valid",
    "hte_since",
    "in_air",
    "landed",
    "tko_state",
    "tko_progress",
    "tilt",
    "thr_z",
    "hover_param",
    "thr_min_param",
    "vmax_up_param",
    "acc_sp_z",
    prefix="Y_",
)
"""The memory of :func:`px4_controller`: a flag set after period one, the rate integral, the
gyro filter's delays and coefficients, the D-term alpha and the period they are for, the last
raw rate and the filtered derivative, the velocity integral, derivative and last velocity, the
next position-loop time and the last, the held attitude setpoint, thrust and yaw feed-forward,
the allocator's saturation (positive, negative), the setpoint's angles (logged), the next
attitude-loop time and its held rate setpoint, the loops' gains for this vehicle, scratch; then the
hover-thrust estimator's state (:data:`~quadcruise.control.px4hover.HTE_STATE`), whether it is
valid and since when its test passes, the land detector's in-air and landed flags, the takeoff
state (4 ramp-up, 5 flight, PX4's numbers) and the ramp's progress, the tilt limit [rad], the last
thrust setpoint's z (NED), the hover thrust, minimum thrust and climb limit as resolved, and the
last acceleration setpoint's z (NED, for ``updateHoverThrust``)."""
(
    Y_INIT,
    Y_INTEG,
    Y_LPF,
    Y_COEF,
    Y_ALPHA_D,
    Y_LAST_DT,
    Y_RAW_LAST,
    Y_ACCEL,
    Y_VEL_INT,
    Y_VELD,
    Y_VEL_LAST,
    Y_NEXT_POS,
    Y_LAST_POS,
    Y_QD,
    Y_THRUST,
    Y_YAWSPEED,
    Y_SAT,
    Y_EULER,
    Y_NEXT_ATT,
    Y_RATE_SP,
    Y_G,
    Y_SP,
    Y_CONTROL,
    Y_HTE,
    Y_HTE_VALID,
    Y_HTE_SINCE,
    Y_IN_AIR,
    Y_LANDED,
    Y_TKO_STATE,
    Y_TKO_PROGRESS,
    Y_TILT,
    Y_THR_Z,
    Y_HOVER_PARAM,
    Y_THR_MIN_PARAM,
    Y_VMAX_UP_PARAM,
    Y_ACC_SP_Z,
) = PX4C_MEMORY.offsets
_EPS = 1.1920929e-07
YAW_DESIGN_SHARE = 0.5
"""The designed yaw rate P and I are this share of :func:`~quadcruise.control.cascade.rate_pid_design`'s:
a rotor's inertia (the Iris's ``J_rotor``) makes yaw torque through its acceleration, a fast path
that the 40 Hz gyro filter's lag turns into a 47 Hz yaw oscillation at the full design (and not at half)."""
_NG = PX4_GAINS.size
_NH = HTE_STATE.size


@njit(cache=True, inline="always")
def _command(t, fac):
    """PX4's thrust model inverted: the command whose thrust ``(1 - fac) u + fac u^2`` is ``t``."""
    if fac <= 0.0:
        return t
    b = 1.0 - fac
    return (-b + math.sqrt(b * b + 4.0 * fac * t)) / (2.0 * fac)


@njit(cache=True, inline="always")
def _quat_zyx(phi, theta, psi):
    """``qz(psi) qy(theta) qx(phi)``, w first."""
    cf, sf = math.cos(0.5 * phi), math.sin(0.5 * phi)
    ct, st = math.cos(0.5 * theta), math.sin(0.5 * theta)
    cp, sp = math.cos(0.5 * psi), math.sin(0.5 * psi)
    return (
        cf * ct * cp + sf * st * sp,
        sf * ct * cp - cf * st * sp,
        cf * st * cp + sf * ct * sp,
        cf * ct * sp - sf * st * cp,
    )


@njit(cache=True, inline="always")
def _gyro_axis(mem, a, coef, raw, alpha_d, dt, first):
    """One axis of the gyro: the rate through the 2-pole low-pass, the differenced raw rate through
    the D-term alpha filter (0 in the first period); the filters' state kept in ``mem``."""
    if first:
        d0, d1 = lpf2p_reset(coef, raw)
        acc = 0.0
    else:
        d0, d1 = mem[Y_LPF + 2 * a], mem[Y_LPF + 2 * a + 1]
        acc = mem[Y_ACCEL + a] + alpha_d * ((raw - mem[Y_RAW_LAST + a]) / dt - mem[Y_ACCEL + a])
    out, delay = lpf2p_apply(coef, (d0, d1), raw)
    mem[Y_LPF + 2 * a], mem[Y_LPF + 2 * a + 1] = delay[0], delay[1]
    mem[Y_RAW_LAST + a] = raw
    mem[Y_ACCEL + a] = acc
    return out, acc


@njit(cache=True, inline="always")
def _vel_axis(mem, a, v, alpha, dtp, first):
    """``BlockDerivative``: the velocity differenced at the position loop's period, low-passed (0 at first)."""
    d = 0.0 if first else mem[Y_VELD + a] + alpha * ((v - mem[Y_VEL_LAST + a]) / dtp - mem[Y_VELD + a])
    mem[Y_VELD + a] = d
    mem[Y_VEL_LAST + a] = v
    return d


@njit(cache=True, inline="always")
def _log_setpoint(mem, qd, psi_ref):
    """The attitude setpoint as the paper's ZYX angles (FLU to ENU), its yaw beside the reference's."""
    r = euler_from_dcm(dcm_from_quat(quat_enu_flu_to_ned_frd(qd)))
    mem[Y_EULER], mem[Y_EULER + 1] = r[0], r[1]
    mem[Y_EULER + 2] = psi_ref + math.atan2(math.sin(r[2] - psi_ref), math.cos(r[2] - psi_ref))


@njit(cache=True, inline="always")
def _saturation(mem, a, miss):
    """PX4's saturation flags of one axis from the torque the allocator could not give."""
    mem[Y_SAT + a] = 1.0 if miss > _EPS else 0.0
    mem[Y_SAT + 3 + a] = 1.0 if miss < -_EPS else 0.0
    return miss > _EPS or miss < -_EPS


TAKEOFF_RAMPUP = 4
"""``takeoff_status.takeoff_state`` while the takeoff ramp runs (PX4's ``TakeoffState::rampup``)."""
TAKEOFF_FLIGHT = 5
"""... and once flying (``TakeoffState::flight``)."""
TILT_SLEW = 0.2
"""The tilt limit's slew rate [rad/s] (``MulticopterPositionControl``'s ``_tilt_limit_slew_rate``)."""
HTE_VALID_TIME = 2.0
"""How long [s] the estimate's test must pass before PX4 calls it valid (``_valid_hysteresis``)."""


@njit(cache=True, inline="always")
def _ground_start(mem, gains, g):
    """First period: the values the takeoff and the estimator change, as resolved, and their states
    (on the ground in the ramp's first step with ``takeoff``, else flying)."""
    mem[Y_HOVER_PARAM], mem[Y_THR_MIN_PARAM], mem[Y_VMAX_UP_PARAM] = g[G_THR_HOVER], g[G_THR_MIN], g[G_VMAX_UP]
    takeoff = gains[X_TAKEOFF] != 0.0
    mem[Y_LANDED] = 1.0 if takeoff else 0.0
    mem[Y_IN_AIR] = 0.0 if takeoff else 1.0
    mem[Y_TKO_STATE] = TAKEOFF_RAMPUP if takeoff else TAKEOFF_FLIGHT
    mem[Y_TKO_PROGRESS] = 0.0
    mem[Y_TILT] = gains[X_TILT_LND] if takeoff else g[G_TILT_MAX]
    _hte_reset(mem[Y_HTE : Y_HTE + _NH], g[G_THR_HOVER], gains[X_HTE_ERR_INIT])
    mem[Y_HTE_VALID] = 0.0
    mem[Y_HTE_SINCE] = -1.0


@njit(cache=True, inline="always")
def _takeoff_step(mem, gains, g, dtp, altitude):
    """One position-loop step of the land detector and the takeoff (before the position loop).

    Land detector (``MulticopterLandDetector::_get_maybe_landed_state``): landed until the thrust
    setpoint exceeds ``MPC_THR_MIN + 0.1 (hover - MPC_THR_MIN)``; in the air (the estimator's
    ``_in_air``) once not landed and over 1 m above the ground. Takeoff (``TakeoffHandling``):
    ramp-up becomes flight once the ramp's progress reaches 1, the progress grows by
    ``dt / MPC_TKO_RAMP_T``, the climb limit goes from ``-g / MPC_Z_VEL_P_ACC`` (no thrust) to
    the target (the flight task's climb rate, at most ``MPC_Z_VEL_MAX_UP``); until flight the
    minimum thrust is 0 and the hover thrust the parameter; the tilt limit slews at 0.2 rad/s
    between ``MPC_TILTMAX_LND`` and ``MPC_TILTMAX_AIR``. Returns whether flying."""
    if mem[Y_LANDED] != 0.0:
        low = mem[Y_THR_MIN_PARAM] + (g[G_THR_HOVER] - mem[Y_THR_MIN_PARAM]) * 0.1
        if mem[Y_THRUST] > low:
            mem[Y_LANDED] = 0.0
    if mem[Y_LANDED] == 0.0 and altitude > 1.0:
        mem[Y_IN_AIR] = 1.0
    if gains[X_TAKEOFF] == 0.0:
        return True
    if mem[Y_TKO_STATE] == TAKEOFF_RAMPUP and mem[Y_TKO_PROGRESS] >= 1.0:
        mem[Y_TKO_STATE] = TAKEOFF_FLIGHT
    target = min(gains[X_TKO_SPEED_UP], mem[Y_VMAX_UP_PARAM])  # PX4: a flight task's faster climb is capped
    limit = target
    if mem[Y_TKO_STATE] == TAKEOFF_RAMPUP:
        ramp = gains[X_TKO_RAMP_T]
        mem[Y_TKO_PROGRESS] = mem[Y_TKO_PROGRESS] + dtp / ramp if ramp > dtp else 1.0
        if mem[Y_TKO_PROGRESS] < 1.0:
            start = -ONE_G / max(g[G_VEL_P + 2], 0.01)
            limit = start + mem[Y_TKO_PROGRESS] * (target - start)
    flying = mem[Y_TKO_STATE] >= TAKEOFF_FLIGHT
    g[G_VMAX_UP] = min(limit, mem[Y_VMAX_UP_PARAM])
    g[G_THR_MIN] = mem[Y_THR_MIN_PARAM] if flying else 0.0
    if not flying:
        g[G_THR_HOVER] = mem[Y_HOVER_PARAM]
    goal = g[G_TILT_MAX] if flying else gains[X_TILT_LND]
    step = TILT_SLEW * dtp
    mem[Y_TILT] = min(max(goal, mem[Y_TILT] - step), mem[Y_TILT] + step)
    return flying


@njit(cache=True, inline="always")
def _hover_estimate(mem, gains, t, dtp, vel, acc_up, thrust_up):
    """One step of PX4's hover-thrust estimator module on a local position (after the position
    loop): predict and fuse while in the air, valid after its test passed for 2 s."""
    s = mem[Y_HTE : Y_HTE + _NH]
    if mem[Y_IN_AIR] == 0.0 or not (0.001 < dtp < 1.0) or not math.isfinite(acc_up):
        mem[Y_HTE_VALID], mem[Y_HTE_SINCE] = 0.0, -1.0
        return
    q = gains[X_HTE_NOISE] * gains[X_HTE_NOISE]
    hte_predict(s, dtp, q)
    scale = hte_noise_scale(vel[2], math.sqrt(vel[0] * vel[0] + vel[1] * vel[1]), gains[X_HTE_VZ], gains[X_HTE_VXY])
    hover, span = mem[Y_HOVER_PARAM], gains[X_HTE_RANGE]  # MPC_THR_HOVER -+ HTE_THR_RANGE
    lo, hi = min(max(hover - span, 0.0), 0.8), min(max(hover + span, 0.2), 0.9)
    hte_fuse(s, acc_up, thrust_up, gains[X_HTE_GATE], scale, lo, hi, q)
    ok = s[HTE_VAR] < 0.001
    if mem[Y_HTE_VALID] == 0.0:
        ok = ok and s[HTE_RATIO] < 1.0
    if not ok:
        mem[Y_HTE_VALID], mem[Y_HTE_SINCE] = 0.0, -1.0
        return
    if mem[Y_HTE_SINCE] < 0.0:
        mem[Y_HTE_SINCE] = t
    if t - mem[Y_HTE_SINCE] >= HTE_VALID_TIME - 1e-9:
        mem[Y_HTE_VALID] = 1.0


@njit(cache=True)
def resolve_gains(gains, vp, g):
    """The loops' gains for one vehicle (what :func:`px4_controller` computes in its first period).

    PX4's (the head of ``gains``), with, where the flags ask: the rate P, I, D designed per unit
    inertia times ``J / tau``, tau the vehicle's torque per unit of normalised torque (FRD); the
    hover thrust ``(1 - f) u + f u^2`` (f = ``THR_MDL_FAC``) of the command u at which each rotor
    carries its share of ``m g``, and ``MPC_THR_MIN`` at most half of it.

    Parameters
    ----------
    gains : numpy.ndarray
        :data:`PX4C_GAINS`'s row.
    vp : numpy.ndarray
        The vehicle parameter row (``layout.PARAMS``).
    g : numpy.ndarray
        Output: :data:`~quadcruise.control.px4loops.PX4_GAINS`'s row.
    """
    n = int(gains[X_N_ROTORS])
    for i in range(_NG):
        g[i] = gains[i]
    full = 4.0 * vp[L.P_K] / n  # a rotor's full thrust [N]
    curve, fac = gains[X_THRUST_CURVE], gains[X_THR_MDL_FAC]
    if gains[X_HOVER_AUTO] != 0.0:
        f = vp[L.P_M] * vp[L.P_G] / (n * full)  # each rotor's share of the weight, over its full thrust
        u = f if curve <= 0.0 else (-(1.0 - curve) + math.sqrt((1.0 - curve) ** 2 + 4.0 * curve * f)) / (2.0 * curve)
        g[G_THR_HOVER] = (1.0 - fac) * u + fac * u * u
        g[G_THR_MIN] = min(g[G_THR_MIN], 0.5 * g[G_THR_HOVER])  # room to descend
    if gains[X_DESIGNED] != 0.0:
        inertia = (vp[L.P_JXX], vp[L.P_JYY], vp[L.P_JZZ])
        arms = (vp[L.P_L], vp[L.P_L], vp[L.P_D])
        signs = (1.0, -1.0, -1.0)  # FRD axes from the FLU layout
        for a in range(3):
            torque = 0.0  # [N m] per unit of normalised torque
            for i in range(n):
                torque += gains[X_GEOM + 3 * i + a] * gains[X_MIX + 6 * i + a] * full
            torque *= arms[a] * signs[a]
            c = inertia[a] / torque
            g[G_RATE_P + a] = gains[X_DESIGN + 3 * a] * c
            g[G_RATE_I + a] = gains[X_DESIGN + 3 * a + 1] * c
            g[G_RATE_D + a] = gains[X_DESIGN + 3 * a + 2] * c


@njit(L.CONTROLLER_SIG, cache=True, error_model="numpy")
def px4_controller(t, dt, x, ref, vp, gains, mem, cmd):
    """One period of :class:`Px4`: gyro filters, position (decimated), attitude and rate loops,
    allocation, thrust model. Arguments: ``CONTROLLER_SIG``; the steps are in the module docstring.

    Examples
    --------
    >>> import numpy as np
    >>> import quadcruise as qc
    >>> from quadcruise.layout import CMD_THRUST, P_G, P_M
    >>> from quadcruise.control.px4 import Px4
    >>> c, vp = Px4(), qc.Vehicle.paper().rows()[0]
    >>> mem, cmd = c.memory(), np.zeros(12)
    >>> px4_controller(0.0, 0.001, np.zeros(16), np.zeros(11), vp, c.gains(), mem, cmd)   # hover
    >>> bool(np.isclose(cmd[CMD_THRUST], vp[P_M] * vp[P_G]))
    True
    """
    first = mem[Y_INIT] == 0.0
    g = mem[Y_G : Y_G + _NG]
    if first:
        resolve_gains(gains, vp, g)
        _ground_start(mem, gains, g)
    n = int(gains[X_N_ROTORS])
    # the state in PX4's frames
    pos = (x[L.Y], x[L.X], -x[L.Z])
    vel = (x[L.VY], x[L.VX], -x[L.VZ])
    raw = (x[L.P], -x[L.Q], -x[L.R])
    # 1. the gyro filters (coefficients kept while the period stays)
    if dt != mem[Y_LAST_DT]:
        c = lpf2p_coefficients(1.0 / dt, gains[X_GYRO_CUTOFF])
        for k in range(5):
            mem[Y_COEF + k] = c[k]
        mem[Y_ALPHA_D] = alpha_of(1.0 / dt, gains[X_DGYRO_CUTOFF])
        mem[Y_LAST_DT] = dt
    coef = (mem[Y_COEF], mem[Y_COEF + 1], mem[Y_COEF + 2], mem[Y_COEF + 3], mem[Y_COEF + 4])
    alpha_d = mem[Y_ALPHA_D]
    r0, a0 = _gyro_axis(mem, 0, coef, raw[0], alpha_d, dt, first)
    r1, a1 = _gyro_axis(mem, 1, coef, raw[1], alpha_d, dt, first)
    r2, a2 = _gyro_axis(mem, 2, coef, raw[2], alpha_d, dt, first)
    # 2. the position loop, at its own rate
    period = gains[X_POS_PERIOD]
    psi_ref = ref[L.REF_PSI] if math.isfinite(ref[L.REF_PSI]) else x[L.PSI]  # NaN: hold the current yaw (PX4)
    yaw_sp = 0.5 * math.pi - psi_ref
    yaw_sp = math.atan2(math.sin(yaw_sp), math.cos(yaw_sp))
    if first or t >= mem[Y_NEXT_POS] - 0.25 * dt:
        dtp = max(period, dt) if first else t - mem[Y_LAST_POS]
        acc_up = math.nan if first else -(vel[2] - mem[Y_VEL_LAST + 2]) / dtp  # measured, up positive
        flying = _takeoff_step(mem, gains, g, dtp, x[L.Z])
        if flying and gains[X_HTE] != 0.0 and mem[Y_HTE_VALID] != 0.0:  # updateHoverThrust
            new = mem[Y_HTE + HTE_HOVER]
            if new != g[G_THR_HOVER]:
                mem[Y_VEL_INT + 2] = hover_thrust_integral(mem[Y_VEL_INT + 2], g[G_THR_HOVER], new, mem[Y_ACC_SP_Z])
                g[G_THR_HOVER] = new
        b = 2.0 * math.pi * gains[X_VELD_LP] * dtp
        alpha_v = b / (1.0 + b)
        vd0 = _vel_axis(mem, 0, vel[0], alpha_v, dtp, first)
        vd1 = _vel_axis(mem, 1, vel[1], alpha_v, dtp, first)
        vd2 = _vel_axis(mem, 2, vel[2], alpha_v, dtp, first)
        pos_sp = (ref[L.REF_Y], ref[L.REF_X], -ref[L.REF_Z])
        vel_sp = (ref[L.REF_VY], ref[L.REF_VX], -ref[L.REF_VZ])
        acc_sp = (ref[L.REF_AY], ref[L.REF_AX], -ref[L.REF_AZ])
        if mem[Y_TKO_STATE] == TAKEOFF_RAMPUP and math.isfinite(vel_sp[2]):  # no feed-forward in the ramp
            acc_sp = (acc_sp[0], acc_sp[1], math.nan)
        vel_int = (mem[Y_VEL_INT], mem[Y_VEL_INT + 1], mem[Y_VEL_INT + 2])
        tilt = g[G_TILT_MAX] if gains[X_TAKEOFF] == 0.0 else mem[Y_TILT]
        _, acc_out, thr, vel_int, valid = position_control(
            pos, vel, (vd0, vd1, vd2), pos_sp, vel_sp, acc_sp, dtp, g, g[G_THR_HOVER], tilt, vel_int
        )
        if gains[X_HTE] != 0.0:  # on the thrust that made the acceleration just measured
            _hover_estimate(mem, gains, t, dtp, vel, acc_up, -mem[Y_THR_Z])
        if valid:
            qd_new = body_z_to_attitude((-thr[0], -thr[1], -thr[2]), yaw_sp)
            for k in range(4):
                mem[Y_QD + k] = qd_new[k]
            mem[Y_THRUST] = math.sqrt(thr[0] * thr[0] + thr[1] * thr[1] + thr[2] * thr[2])
            mem[Y_THR_Z] = thr[2]
            mem[Y_ACC_SP_Z] = acc_out[2]
            _log_setpoint(mem, qd_new, psi_ref)
            for a in range(3):
                mem[Y_VEL_INT + a] = vel_int[a]
        elif first:  # level at the heading, hover thrust
            qd_new = body_z_to_attitude((0.0, 0.0, 1.0), yaw_sp)
            for k in range(4):
                mem[Y_QD + k] = qd_new[k]
            mem[Y_THRUST] = g[G_THR_HOVER]
            mem[Y_THR_Z] = -g[G_THR_HOVER]
            _log_setpoint(mem, qd_new, psi_ref)
        mem[Y_YAWSPEED] = -ref[L.REF_PSI_DOT] if math.isfinite(ref[L.REF_PSI_DOT]) else 0.0
        nxt = mem[Y_NEXT_POS] + period
        mem[Y_NEXT_POS] = nxt if (not first and nxt > t) else t + period
        mem[Y_LAST_POS] = t
    qd = (mem[Y_QD], mem[Y_QD + 1], mem[Y_QD + 2], mem[Y_QD + 3])
    collective = mem[Y_THRUST]
    # 3. attitude, 4. rate
    if first or t >= mem[Y_NEXT_ATT] - 0.25 * dt:
        q = quat_enu_flu_to_ned_frd(_quat_zyx(x[L.PHI], x[L.THETA], x[L.PSI]))
        rsp = attitude_control(q, qd, mem[Y_YAWSPEED], g)
        mem[Y_RATE_SP], mem[Y_RATE_SP + 1], mem[Y_RATE_SP + 2] = rsp[0], rsp[1], rsp[2]
        nxt = mem[Y_NEXT_ATT] + gains[X_ATT_PERIOD]
        mem[Y_NEXT_ATT] = nxt if (not first and nxt > t) else t + gains[X_ATT_PERIOD]
    rate_sp = (mem[Y_RATE_SP], mem[Y_RATE_SP + 1], mem[Y_RATE_SP + 2])
    sat_pos = (mem[Y_SAT] != 0.0, mem[Y_SAT + 1] != 0.0, mem[Y_SAT + 2] != 0.0)
    sat_neg = (mem[Y_SAT + 3] != 0.0, mem[Y_SAT + 4] != 0.0, mem[Y_SAT + 5] != 0.0)
    integ = (mem[Y_INTEG], mem[Y_INTEG + 1], mem[Y_INTEG + 2])
    landed = mem[Y_LANDED] != 0.0
    torque, integ = rate_control((r0, r1, r2), rate_sp, (a0, a1, a2), dt, landed, g, sat_pos, sat_neg, integ)
    for a in range(3):
        mem[Y_INTEG + a] = integ[a]
    # 5. allocation
    control = mem[Y_CONTROL : Y_CONTROL + 6]
    control[0], control[1], control[2] = torque[0], torque[1], torque[2]
    control[3], control[4], control[5] = 0.0, 0.0, -collective
    sp = mem[Y_SP : Y_SP + n]
    mix = gains[X_MIX : X_MIX + 6 * n].reshape((n, 6))
    lo, hi = gains[X_LO : X_LO + n], gains[X_HI : X_HI + n]
    allocate_into(sp, mix, control, int(gains[X_AIRMODE]), lo, hi)
    # 6. the vehicle: thrust model, rotor thrusts, wrench; the allocator's saturation
    full = 4.0 * vp[L.P_K] / n
    fac, curve = gains[X_THR_MDL_FAC], gains[X_THRUST_CURVE]
    T = mx = my = mz = 0.0
    got0 = got1 = got2 = got3 = 0.0
    for i in range(n):
        s = min(max(sp[i], lo[i]), hi[i])
        got0 += gains[X_ALLOC + 4 * i] * s
        got1 += gains[X_ALLOC + 4 * i + 1] * s
        got2 += gains[X_ALLOC + 4 * i + 2] * s
        got3 += gains[X_ALLOC + 4 * i + 3] * s
        u = _command(s, fac)
        f = full * ((1.0 - curve) * u + curve * u * u)
        T += f
        mx += gains[X_GEOM + 3 * i] * f
        my += gains[X_GEOM + 3 * i + 1] * f
        mz += gains[X_GEOM + 3 * i + 2] * f
    flags = 0
    if (
        _saturation(mem, 0, control[0] - got0)
        | _saturation(mem, 1, control[1] - got1)
        | _saturation(mem, 2, control[2] - got2)
    ):
        flags |= L.FLAG_INTEGRATOR_HOLD
    if abs(control[5] - got3) > _EPS:
        flags |= L.FLAG_THRUST_LIMIT
    mem[Y_INIT] = 1.0
    write_command(
        cmd, T, mx, my, vp[L.P_D] * mz, mem[Y_EULER], mem[Y_EULER + 1], mem[Y_EULER + 2], flags, vp[L.P_D], vp[L.P_K]
    )
