"""The PX4 multicopter cascade on the paper's plant: the compiled law of
:class:`Cascade` and its building blocks.

PX4's ``PositionControl``, ``AttitudeControl`` and ``RateControl``, in SI units with z up
(PX4 works in NED; every sign below is re-derived for z up and eqs 5-7):

1. Position P: v_sp = K_pos (p_ref - p) + v_ref. The horizontal part is limited to
   ``max_speed_xy`` with the position term taking priority over the feedforward (PX4's
   ``ControlMath::constrainXY``), the vertical part to [-max_speed_down, max_speed_up].
2. Velocity PID: a_sp = K_p e_v + int(K_i e_v) - K_d v' + a_ref, v' the measured velocity
   differenced and low-passed at MPC_VELD_LP. Thrust direction b3_d = (a_x, a_y, g) / |.|
   (PX4's decoupled horizontal and vertical acceleration, MPC_ACC_DECOUPLE), turned towards
   the vertical to at most ``max_tilt`` (FLAG_TILT_LIMIT); U1 = m (g + a_z) / b3_d,z within
   [thrust_min m g, thrust_max 4 K] (FLAG_THRUST_LIMIT). Anti-windup as PX4: the vertical
   integral stops while the thrust limit acts against its error (FLAG_INTEGRATOR_HOLD) and
   stays within +/- g; the horizontal error is corrected by 2 / K_p times the acceleration
   the limited thrust cannot give (tracking anti-windup, Rundqwist 1990).
3. Attitude P: R_d from b3_d and the yaw reference as PX4's ``bodyzToAttitude`` (its ZYX yaw
   is the reference), the error 2 sign(w) (x, y, z) of the quaternion of R^T R_d (body
   frame), rate setpoint (K_roll e1, K_pitch e2, K_yaw e3) plus the yaw rate reference
   expressed in the body frame, each limited to its maximum rate.
4. Rate PID per unit inertia: alpha = K_p e_w + int(i_f K_i e_w) - K_d w' with the derivative
   on the measured rate (differenced, low-passed at IMU_DGYRO_CUTOFF), PX4's
   i_f = max(0, 1 - (e_w / 400 deg/s)^2), the integral within ``rate_i_limit`` times the
   axis' full torque (l K for roll and pitch, 2 d K for yaw) over its inertia
   (FLAG_INTEGRATOR_HOLD). Torques J alpha: U2 = Jxx alpha_x / l, U3 = Jyy alpha_y / l,
   U4 = Jzz alpha_z. No gyroscopic compensation (PX4 has none).

The derivatives are zero in the first period (no previous sample). Not modelled: PX4's yaw
weight (MC_YAW_WEIGHT; the full attitude error is used), its hover-thrust estimator (the
vehicle row's m g is used), the xy thrust margin, and flags for the speed and rate limits
(the command layout has no bit for them). The yaw rate reference is fed forward (step 3), as
PX4 does; its yaw acceleration is not (PX4 has none), so a turning heading still lags by what
the yaw rate PI leaves: 1.1 deg on a minimum-snap square whose heading turns at up to 0.83
rad/s, against the 17 deg a P attitude loop without the feedforward would lag
(``tests/integration/test_se3_cascade.py``).

Rate gains. PX4's are in normalized torque (1 = the full torque) per rad/s. Converted with
this vehicle's full roll torque l K / Jxx = 800 rad/s^2, MC_ROLLRATE_P = 0.15 would be
120 1/s: a rate-loop crossover eight times above the 15 rad/s rotor lag, which is unstable.
So they are designed for the lag instead (:func:`rate_pid_design`).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
from numba import njit

from quadcruise import layout as L
from quadcruise.control.base import TILT, Controller
from quadcruise.control.design import python_control
from quadcruise.control.so3 import attitude_px4, command_from_rotation, error_quaternion, limit_tilt, rotation_zyx
from quadcruise.fields import Validated, between, check_value, instance_of
from quadcruise.fields import unit_field as _f
from quadcruise.numeric import clamp

CASCADE_GAINS = L.Row.of(
    "cascade gains",
    "pos_xy",
    "pos_z",
    "vel_p_xy",
    "vel_i_xy",
    "vel_d_xy",
    "vel_p_z",
    "vel_i_z",
    "vel_d_z",
    "vmax_xy",
    "vmax_up",
    "vmax_down",
    "max_tilt",
    "thr_min",
    "thr_max",
    "att_rp",
    "att_yaw",
    "rmax_rp",
    "rmax_yaw",
    "rate_p",
    "rate_i",
    "rate_d",
    "yrate_p",
    "yrate_i",
    "yrate_d",
    "rate_i_lim",
    "vel_d_lp",
    "rate_d_lp",
    prefix="C_",
)
"""The gains of :func:`cascade`, in :class:`Cascade`'s order and units."""
(
    C_POS_XY,
    C_POS_Z,
    C_VEL_P_XY,
    C_VEL_I_XY,
    C_VEL_D_XY,
    C_VEL_P_Z,
    C_VEL_I_Z,
    C_VEL_D_Z,
    C_VMAX_XY,
    C_VMAX_UP,
    C_VMAX_DOWN,
    C_MAX_TILT,
    C_THR_MIN,
    C_THR_MAX,
    C_ATT_RP,
    C_ATT_YAW,
    C_RMAX_RP,
    C_RMAX_YAW,
    C_RATE_P,
    C_RATE_I,
    C_RATE_D,
    C_YRATE_P,
    C_YRATE_I,
    C_YRATE_D,
    C_RATE_I_LIM,
    C_VEL_D_LP,
    C_RATE_D_LP,
) = CASCADE_GAINS.offsets
CASCADE_MEMORY = L.Row.of(
    "cascade memory", ("vi", 3), ("ri", 3), ("v", 3), ("w", 3), ("vd", 3), ("wd", 3), "init", prefix="M_"
)
"""The memory of :func:`cascade`: velocity integral [m/s^2], rate integral [rad/s^2], last
velocity and rate, their low-passed derivatives, and a flag set after period one."""
M_VI, M_RI, M_V, M_W, M_VD, M_WD, M_INIT = CASCADE_MEMORY.offsets
I_FACTOR_RATE = math.radians(400.0)
"""PX4's rate error at which the rate integral stops growing [rad/s]."""


@njit(cache=True, inline="always", error_model="numpy")
def _derivative(value, last, state, dt, alpha, first):
    """Low-passed backward difference of ``value`` (its last sample ``last``, the filter's
    state ``state``): the new state, which is the output. Zero in the first period."""
    if first:
        return state
    return state + alpha * ((value - last) / dt - state)


@njit(cache=True, error_model="numpy")
def constrain_xy(v0x, v0y, v1x, v1y, vmax):
    """PX4 ``ControlMath::constrainXY``: v0 + v1 limited to norm vmax, v0 taking priority (then as much
    of v1, along v1, as fits).

    Examples
    --------
    >>> constrain_xy(3.0, 0.0, 0.0, 5.0, 5.0)         # v0 kept, v1 scaled to fit
    (3.0, 4.0)
    >>> constrain_xy(1.0, 0.0, 1.0, 0.0, 5.0)         # within vmax: the plain sum
    (2.0, 0.0)
    """
    sx, sy = v0x + v1x, v0y + v1y
    if math.hypot(sx, sy) <= vmax:
        return sx, sy
    n0 = math.hypot(v0x, v0y)
    if n0 >= vmax:
        return v0x / n0 * vmax, v0y / n0 * vmax
    n1 = math.hypot(v1x, v1y)
    if n0 < 1e-3:
        return v1x / n1 * vmax, v1y / n1 * vmax
    ux, uy = v1x / n1, v1y / n1
    mm = ux * v0x + uy * v0y
    s = -mm + math.sqrt(mm * mm - (n0 * n0 - vmax * vmax))
    return v0x + ux * s, v0y + uy * s


@njit(cache=True, inline="always", error_model="numpy")
def _rate_axis(setpoint, rate, integral, last, state, dt, alpha, first, kp, ki, kd, i_limit):
    """PX4 rate PID on one axis, per unit inertia [rad/s^2]; the integral updates after use.
    Returns (output, new integral, new derivative state, integrator held?)."""
    e = setpoint - rate
    d = _derivative(rate, last, state, dt, alpha, first)
    out = kp * e + integral - kd * d
    i_factor = max(0.0, 1.0 - (e / I_FACTOR_RATE) ** 2)
    integral, held = clamp(integral + i_factor * ki * e * dt, -i_limit, i_limit)
    return out, integral, d, held


@njit(L.CONTROLLER_SIG, cache=True, error_model="numpy")
def cascade(t, dt, x, ref, vp, G, mem, cmd):
    """One period of :class:`Cascade`: P position, PID velocity, P attitude, PID body rate.
    Arguments: ``CONTROLLER_SIG`` (:mod:`quadcruise.layout`); the law is in the module docstring.

    Examples
    --------
    >>> import numpy as np
    >>> import quadcruise as qc
    >>> from quadcruise.layout import CMD_THRUST, P_G, P_M
    >>> c, vp = Cascade(), qc.Vehicle.paper().rows()[0]
    >>> mem, cmd = c.memory(), np.zeros(12)
    >>> cascade(0.0, 0.001, np.zeros(16), np.zeros(11), vp, c.gains(), mem, cmd)   # hover, on the reference
    >>> bool(np.isclose(cmd[CMD_THRUST], vp[P_M] * vp[P_G])), float(mem[M_INIT])
    (True, 1.0)
    """
    # every array entry read first, mem and cmd written last (fastmath's scalar-only rule)
    m, g, K, l, d = vp[L.P_M], vp[L.P_G], vp[L.P_K], vp[L.P_L], vp[L.P_D]
    jx, jy, jz = vp[L.P_JXX], vp[L.P_JYY], vp[L.P_JZZ]
    vx, vy, vz, p, q, r = x[L.VX], x[L.VY], x[L.VZ], x[L.P], x[L.Q], x[L.R]
    phi, theta, psi = x[L.PHI], x[L.THETA], x[L.PSI]
    vi_x, vi_y, vi_z = mem[M_VI], mem[M_VI + 1], mem[M_VI + 2]
    ri_1, ri_2, ri_3 = mem[M_RI], mem[M_RI + 1], mem[M_RI + 2]
    lv_x, lv_y, lv_z = mem[M_V], mem[M_V + 1], mem[M_V + 2]
    lw_1, lw_2, lw_3 = mem[M_W], mem[M_W + 1], mem[M_W + 2]
    dv_x, dv_y, dv_z = mem[M_VD], mem[M_VD + 1], mem[M_VD + 2]
    dw_1, dw_2, dw_3 = mem[M_WD], mem[M_WD + 1], mem[M_WD + 2]
    first = mem[M_INIT] == 0.0
    k_pos_xy, k_pos_z = G[C_POS_XY], G[C_POS_Z]
    kv_p_xy, kv_i_xy, kv_d_xy, kv_p_z, kv_i_z, kv_d_z = (
        G[C_VEL_P_XY],
        G[C_VEL_I_XY],
        G[C_VEL_D_XY],
        G[C_VEL_P_Z],
        G[C_VEL_I_Z],
        G[C_VEL_D_Z],
    )
    vmax_xy, vmax_up, vmax_down = G[C_VMAX_XY], G[C_VMAX_UP], G[C_VMAX_DOWN]
    max_tilt, thr_min, thr_max = G[C_MAX_TILT], G[C_THR_MIN], G[C_THR_MAX]
    k_att_rp, k_att_yaw, rmax_rp, rmax_yaw = G[C_ATT_RP], G[C_ATT_YAW], G[C_RMAX_RP], G[C_RMAX_YAW]
    kr_p, kr_i, kr_d, ky_p, ky_i, ky_d, rate_i_lim = (
        G[C_RATE_P],
        G[C_RATE_I],
        G[C_RATE_D],
        G[C_YRATE_P],
        G[C_YRATE_I],
        G[C_YRATE_D],
        G[C_RATE_I_LIM],
    )
    vel_d_lp, rate_d_lp = G[C_VEL_D_LP], G[C_RATE_D_LP]
    psi_d, yr = ref[L.REF_PSI], ref[L.REF_PSI_DOT]
    av = dt / (dt + 1.0 / (2.0 * math.pi * vel_d_lp))
    aw = dt / (dt + 1.0 / (2.0 * math.pi * rate_d_lp))
    flags = 0
    # 1. position P -> velocity setpoint
    vsx, vsy = constrain_xy(
        k_pos_xy * (ref[L.REF_X] - x[L.X]), k_pos_xy * (ref[L.REF_Y] - x[L.Y]), ref[L.REF_VX], ref[L.REF_VY], vmax_xy
    )
    vsz, _ = clamp(k_pos_z * (ref[L.REF_Z] - x[L.Z]) + ref[L.REF_VZ], -vmax_down, vmax_up)
    # 2. velocity PID -> acceleration -> thrust vector
    ex, ey, ez = vsx - vx, vsy - vy, vsz - vz
    dv_x = _derivative(vx, lv_x, dv_x, dt, av, first)
    dv_y = _derivative(vy, lv_y, dv_y, dt, av, first)
    dv_z = _derivative(vz, lv_z, dv_z, dt, av, first)
    ax = kv_p_xy * ex + vi_x - kv_d_xy * dv_x + ref[L.REF_AX]
    ay = kv_p_xy * ey + vi_y - kv_d_xy * dv_y + ref[L.REF_AY]
    az = kv_p_z * ez + vi_z - kv_d_z * dv_z + ref[L.REF_AZ]
    hx, hy, tilted = limit_tilt(ax, ay, g, max_tilt)
    if tilted:
        flags |= L.FLAG_TILT_LIMIT
    n = math.sqrt(hx * hx + hy * hy + g * g)
    b3x, b3y, b3z = hx / n, hy / n, g / n
    u_min, u_max = thr_min * m * g, thr_max * 4.0 * K
    U1, limited = clamp(m * (g + az) / b3z, u_min, u_max)
    if limited:
        flags |= L.FLAG_THRUST_LIMIT
        if (U1 == u_min and ez <= 0.0) or (U1 == u_max and ez >= 0.0):
            ez = 0.0  # vertical anti-windup
            flags |= L.FLAG_INTEGRATOR_HOLD
    px, py = U1 * b3x / m, U1 * b3y / m  # horizontal acceleration produced
    if ax * ax + ay * ay > px * px + py * py:  # tracking anti-windup
        ex -= 2.0 / kv_p_xy * (ax - px)
        ey -= 2.0 / kv_p_xy * (ay - py)
    vi_x += kv_i_xy * ex * dt
    vi_y += kv_i_xy * ey * dt
    vi_z, _ = clamp(vi_z + kv_i_z * ez * dt, -g, g)
    # 3. attitude P -> body-rate setpoints (+ the yaw rate reference in the body frame)
    Rm = rotation_zyx(phi, theta, psi)
    Rd = attitude_px4(b3x, b3y, b3z, psi_d)
    e1, e2, e3 = error_quaternion(Rm, Rd)
    sp1, _ = clamp(k_att_rp * e1 + Rm[2][0] * yr, -rmax_rp, rmax_rp)
    sp2, _ = clamp(k_att_rp * e2 + Rm[2][1] * yr, -rmax_rp, rmax_rp)
    sp3, _ = clamp(k_att_yaw * e3 + Rm[2][2] * yr, -rmax_yaw, rmax_yaw)
    # 4. rate PID -> torques
    full = l * K  # full roll/pitch torque [N m]
    a1, ri_1, dw_1, h1 = _rate_axis(sp1, p, ri_1, lw_1, dw_1, dt, aw, first, kr_p, kr_i, kr_d, rate_i_lim * full / jx)
    a2, ri_2, dw_2, h2 = _rate_axis(sp2, q, ri_2, lw_2, dw_2, dt, aw, first, kr_p, kr_i, kr_d, rate_i_lim * full / jy)
    a3, ri_3, dw_3, h3 = _rate_axis(
        sp3, r, ri_3, lw_3, dw_3, dt, aw, first, ky_p, ky_i, ky_d, rate_i_lim * 2.0 * d * K / jz
    )
    if h1 or h2 or h3:
        flags |= L.FLAG_INTEGRATOR_HOLD
    mem[M_VI], mem[M_VI + 1], mem[M_VI + 2] = vi_x, vi_y, vi_z
    mem[M_RI], mem[M_RI + 1], mem[M_RI + 2] = ri_1, ri_2, ri_3
    mem[M_V], mem[M_V + 1], mem[M_V + 2] = vx, vy, vz
    mem[M_W], mem[M_W + 1], mem[M_W + 2] = p, q, r
    mem[M_VD], mem[M_VD + 1], mem[M_VD + 2] = dv_x, dv_y, dv_z
    mem[M_WD], mem[M_WD + 1], mem[M_WD + 2] = dw_1, dw_2, dw_3
    mem[M_INIT] = 1.0
    command_from_rotation(U1, jx * a1 / l, jy * a2 / l, jz * a3, Rd, flags, d, K, cmd)


@dataclass(frozen=True)
class RateGains(Validated):
    """Body-rate PID per unit inertia: alpha = kp e + ki int(e) - kd w' [rad/s^2], torque J alpha;
    kp [1/s], ki [1/s^2], kd [-] on the measured rate.

    Examples
    --------
    >>> RateGains(kp=15.0, ki=20.0, kd=0.6).kd
    0.6
    >>> RateGains(kp=1.0, ki=0.0, kd=-1.0)
    Traceback (most recent call last):
        ...
    quadcruise.errors.InputError: rate gain 'kd' (derivative gain, on the measured rate, -) must be >= 0, got -1.0
    """

    kp: float = _f(unit="1/s", doc="proportional gain", check="pos")
    ki: float = _f(unit="1/s^2", doc="integral gain", check="nonneg")
    kd: float = _f(unit="-", doc="derivative gain, on the measured rate", check="nonneg")
    name = "rate"
    field_noun = "gain"


RATE_ZETA = 0.8
"""Damping of the rate loop over the rotor lag (the attitude design's zeta)."""
PX4_RATE_I_RATIO = 0.2 / 0.15
"""MC_ROLLRATE_I / MC_ROLLRATE_P [1/s], PX4 defaults (the same for pitch)."""
PX4_YAW_RATE_I_RATIO = 0.1 / 0.2
"""MC_YAWRATE_I / MC_YAWRATE_P [1/s], PX4 defaults (MC_YAWRATE_D = 0)."""


def rate_pid_design(actuator_bandwidth: float = 15.0, yaw: bool = False) -> RateGains:
    """Rate gains for a rotor lag of bandwidth w: w' = alpha, alpha' = w (alpha_c - alpha); pair at wn = w, zeta 0.8.
    Why, and the margins they give: docs/paper.md, "The PX4-style cascade's rate gains".

    Examples
    --------
    >>> g = rate_pid_design()
    >>> round(g.kp, 6), round(g.ki, 6), round(g.kd, 6)
    (15.0, 20.0, 0.6)
    >>> g = rate_pid_design(yaw=True)
    >>> round(g.kp, 3), round(g.ki, 3), g.kd
    (5.859, 2.93, 0.0)
    """
    w = check_value(
        "rate_pid_design argument 'actuator_bandwidth' (rotor lag bandwidth, rad/s)", actuator_bandwidth, "pos"
    )
    if yaw:
        kp = w / (4.0 * RATE_ZETA**2)
        return RateGains(kp=kp, ki=PX4_YAW_RATE_I_RATIO * kp, kd=0.0)
    return RateGains(kp=w, ki=PX4_RATE_I_RATIO * w, kd=2.0 * RATE_ZETA - 1.0)


def rate_loops(controller, actuator_bandwidth: float = 15.0, axis: str = "roll") -> dict:
    """Linearised single-axis loops of a Cascade at hover (python-control): ``rate`` and ``attitude`` open
    loops, ``closed`` angle over setpoint; ``axis`` 'roll' (= 'pitch') or 'yaw'.

    Examples
    --------
    >>> from quadcruise.control.cascade import Cascade
    >>> import control
    >>> loops = rate_loops(Cascade())
    >>> [round(float(v), 1) for v in control.stability_margins(loops["rate"])[1::3]]
    [70.9, 12.7]
    >>> [round(float(v), 1) for v in control.stability_margins(loops["attitude"])[1::3]]
    [45.1, 6.9]
    """
    ct = python_control()
    s = ct.tf("s")
    g, k_att = (controller.yaw_rate, controller.yaw_p) if axis == "yaw" else (controller.rate, controller.roll_p)
    fc = 2.0 * math.pi * controller.rate_d_cutoff
    plant = actuator_bandwidth / (s + actuator_bandwidth) / s
    pi_part = g.kp + g.ki / s
    rate = plant * (pi_part + g.kd * s * fc / (s + fc))
    t_rate = ct.minreal(plant * pi_part / (1 + rate), verbose=False)
    attitude = k_att * t_rate / s
    return {"rate": rate, "attitude": attitude, "closed": ct.feedback(attitude, 1)}


@dataclass(frozen=True)
class Cascade(Controller):
    """PX4-style multicopter cascade (the law is in the module docstring and :func:`cascade`).

    Defaults are PX4's parameters (names in brackets), in SI units.

    Parameters
    ----------
    xy_p, z_p : float
        position P [1/s] (MPC_XY_P = 0.95, MPC_Z_P = 1).
    xy_vel_p, xy_vel_i, xy_vel_d : float
        horizontal velocity PID: [1/s], [1/s^2], [-] (MPC_XY_VEL_P/I/D_ACC = 1.8, 0.4, 0.2).
    z_vel_p, z_vel_i, z_vel_d : float
        vertical velocity PID (MPC_Z_VEL_P/I/D_ACC = 4, 2, 0).
    max_speed_xy, max_speed_up, max_speed_down : float
        velocity setpoint limits [m/s] (MPC_XY_VEL_MAX = 12, MPC_Z_VEL_MAX_UP = 3,
        MPC_Z_VEL_MAX_DN = 1.5; 1 in older PX4 releases).
    max_tilt : float
        thrust tilt limit [rad] (MPC_TILTMAX_AIR = 45 deg).
    thrust_min : float
        least thrust as a fraction of the weight m g [-]: PX4's MPC_THR_MIN = 0.12 of full
        thrust at its default hover thrust MPC_THR_HOVER = 0.5 is 0.24 of the weight (this
        vehicle hovers at 7 % of its full thrust, so 0.12 of full would not let it descend).
    thrust_max : float
        most thrust as a fraction of the full thrust 4 K [-] (MPC_THR_MAX = 1).
    roll_p, yaw_p : float
        attitude P [1/s], roll and pitch, yaw (MC_ROLL_P = MC_PITCH_P = 6.5, MC_YAW_P = 2.8).
    max_rate_rp, max_rate_yaw : float
        rate setpoint limits [rad/s] (MC_ROLLRATE_MAX = 220 deg/s, MC_YAWRATE_MAX = 200 deg/s).
    rate, yaw_rate : RateGains
        rate PID per unit inertia, roll and pitch, yaw: :func:`rate_pid_design` (PX4's I/P
        ratios MC_ROLLRATE_I / MC_ROLLRATE_P = 0.2 / 0.15, MC_YAWRATE_I / MC_YAWRATE_P = 0.1 / 0.2).
    rate_i_limit : float
        rate integral bound as a fraction of the axis' full torque [-] (MC_RR_INT_LIM = 0.3).
    vel_d_cutoff, rate_d_cutoff : float
        low-pass cutoffs of the differenced velocity and rate [Hz] (MPC_VELD_LP = 5,
        IMU_DGYRO_CUTOFF = 30).

    Examples
    --------
    >>> c = Cascade()
    >>> c.gains().shape, c.memory().shape
    ((27,), (19,))
    >>> Cascade(thrust_min=1.5)
    Traceback (most recent call last):
        ...
    quadcruise.errors.InputError: cascade parameter 'thrust_min' (least thrust over the weight m g, -) must be ...
    """

    name = "cascade"
    memory_size = CASCADE_MEMORY.size

    xy_p: float = _f(0.95, "1/s", "horizontal position P", "pos")
    z_p: float = _f(1.0, "1/s", "vertical position P", "pos")
    xy_vel_p: float = _f(1.8, "1/s", "horizontal velocity P", "pos")
    xy_vel_i: float = _f(0.4, "1/s^2", "horizontal velocity I", "nonneg")
    xy_vel_d: float = _f(0.2, "-", "horizontal velocity D", "nonneg")
    z_vel_p: float = _f(4.0, "1/s", "vertical velocity P", "pos")
    z_vel_i: float = _f(2.0, "1/s^2", "vertical velocity I", "nonneg")
    z_vel_d: float = _f(0.0, "-", "vertical velocity D", "nonneg")
    max_speed_xy: float = _f(12.0, "m/s", "horizontal speed limit", "pos")
    max_speed_up: float = _f(3.0, "m/s", "climb speed limit", "pos")
    max_speed_down: float = _f(1.5, "m/s", "descent speed limit", "pos")
    max_tilt: float = _f(math.radians(45.0), "rad", "thrust tilt limit", TILT)
    thrust_min: float = _f(0.24, "-", "least thrust over the weight m g", between(0.0, 1.0, "[)"))
    thrust_max: float = _f(1.0, "-", "most thrust over the full thrust 4 K", between(0.0, 1.0, "(]"))
    roll_p: float = _f(6.5, "1/s", "roll and pitch attitude P", "pos")
    yaw_p: float = _f(2.8, "1/s", "yaw attitude P", "pos")
    max_rate_rp: float = _f(math.radians(220.0), "rad/s", "roll and pitch rate limit", "pos")
    max_rate_yaw: float = _f(math.radians(200.0), "rad/s", "yaw rate limit", "pos")
    rate: RateGains = _f(unit="-", doc="roll and pitch rate PID", check=instance_of(RateGains), factory=rate_pid_design)
    yaw_rate: RateGains = _f(
        unit="-", doc="yaw rate PID", check=instance_of(RateGains), factory=lambda: rate_pid_design(yaw=True)
    )
    rate_i_limit: float = _f(0.3, "-", "rate integral bound over the axis' full torque", "pos")
    vel_d_cutoff: float = _f(5.0, "Hz", "low-pass cutoff of the differenced velocity", "pos")
    rate_d_cutoff: float = _f(30.0, "Hz", "low-pass cutoff of the differenced rate", "pos")

    @property
    def function(self):
        """The compiled law, :func:`cascade` (``CONTROLLER_SIG``)."""
        return cascade

    def gains(self) -> np.ndarray:
        """The parameter vector :func:`cascade` reads.

        Returns
        -------
        numpy.ndarray
            CASCADE_GAINS (27) float64 entries at the ``C_*`` offsets: position P of xy and
            z [1/s]; velocity P [1/s], I [1/s^2], D [-] of xy, then of z; the speed limits
            xy, up, down [m/s]; max_tilt [rad]; thrust_min, thrust_max [-]; attitude P of
            roll/pitch and yaw [1/s]; the rate limits of roll/pitch and yaw [rad/s]; rate
            P [1/s], I [1/s^2], D [-] of roll/pitch, then of yaw; rate_i_limit [-]; the
            velocity and rate derivative cutoffs [Hz].
        """
        return CASCADE_GAINS.pack(
            {
                "pos_xy": self.xy_p,
                "pos_z": self.z_p,
                "vel_p_xy": self.xy_vel_p,
                "vel_i_xy": self.xy_vel_i,
                "vel_d_xy": self.xy_vel_d,
                "vel_p_z": self.z_vel_p,
                "vel_i_z": self.z_vel_i,
                "vel_d_z": self.z_vel_d,
                "vmax_xy": self.max_speed_xy,
                "vmax_up": self.max_speed_up,
                "vmax_down": self.max_speed_down,
                "max_tilt": self.max_tilt,
                "thr_min": self.thrust_min,
                "thr_max": self.thrust_max,
                "att_rp": self.roll_p,
                "att_yaw": self.yaw_p,
                "rmax_rp": self.max_rate_rp,
                "rmax_yaw": self.max_rate_yaw,
                "rate_p": self.rate.kp,
                "rate_i": self.rate.ki,
                "rate_d": self.rate.kd,
                "yrate_p": self.yaw_rate.kp,
                "yrate_i": self.yaw_rate.ki,
                "yrate_d": self.yaw_rate.kd,
                "rate_i_lim": self.rate_i_limit,
                "vel_d_lp": self.vel_d_cutoff,
                "rate_d_lp": self.rate_d_cutoff,
            }
        )
