"""The rotor-speed plant: a rigid body with any number of rotors, its attitude a unit
quaternion, its motors first-order in rotor speed, its aerodynamics those of RotorPy's
``Multirotor`` (RotorPy 3.0); one compiled derivative for one vehicle, on scalars, like
:mod:`quadcruise.model.plant` is for the paper's plant.

State (``ROTOR_STATE_NAMES``; SI units, world frame z up, body frame x forward, y left, z up):
position x, y, z; velocity vx, vy, vz; the unit quaternion qw, qx, qy, qz (scalar first, body
to world); body rates p, q, r; rotor speeds w1..wn [rad/s], n = the vehicle's rotor count.

With R(q) the body-to-world rotation, Omega = (p, q, r), r_i rotor i's position in the body
frame, s_i its direction (+1: its drag moment pushes the body about +z, i.e. the rotor spins
clockwise seen from above), e_i its effectiveness (1 when healthy) and w the wind (world):

    v_b   = R^T (v - w)                                  airspeed, body frame
    v_i   = v_b + Omega x r_i                            airspeed at rotor i's hub
    T_i   = e_i kf w_i^2 + k_h (v_i,x^2 + v_i,y^2)       thrust, along body z (+ translational lift)
    H_i   = -w_i diag(k_d, k_d, k_z) v_i                 rotor drag and induced inflow
    D     = -|v_b| diag(c_Dx, c_Dy, c_Dz) v_b            parasitic drag, at the centre of mass
    F_b   = sum_i (T_i e3 + H_i) + D
    M_b   = sum_i [ r_i x (T_i e3 + H_i) - k_flap w_i (v_i x e3) + s_i e_i km w_i^2 e3 ]
    x'    = v
    v'    = (R F_b + F_ext) / m - g e3
    q'    = q (x) (0, Omega) / 2
    J Omega' = M_b + tau_ext - Omega x (J Omega + h e3) - h' e3,   h = -J_r sum_i s_i w_i
    w_i'  = (w_cmd,i - w_i) / tau,   tau = tau_up if w_cmd,i > w_i else tau_down

J = diag(Jxx, Jyy, Jzz). h is the rotors' own angular momentum about body z (J_r: one rotor's
inertia about its axis; RotorPy has none, so its presets set J_r = 0): Omega x h e3 is their
gyroscopic torque and -h' e3 the motors' reaction while they speed up or slow down. The
thrust and aerodynamic terms are RotorPy's ``Multirotor.compute_body_wrench`` term by term.
The command w_cmd is held in [w_min, w_max] by whoever gives it (the replay refuses one
outside); then w_i stays in that range too. R is the rotation of q / |q| (as RotorPy's
``Rotation.from_quat``), so an RK4 stage state a little off the unit sphere still rotates.

``ext`` follows :mod:`quadcruise.layout`'s ``EXT_*`` columns: an external force [N] (world),
a torque [N m] (body), the wind [m/s] (world), then one effectiveness per rotor
(``EXT_E1 + i``), so ``9 + n`` entries.

The vehicle's parameters reach the compiled code as one flat row (``ROTOR_PARAMS`` below, ``ROTOR_P_*``,
then ``ROTOR_ARM`` per rotor: x, y, z [m] and s), built by :meth:`quadcruise.model.rotor_vehicle.RotorVehicle.row`.
"""

from __future__ import annotations

import math

from numba import njit

from quadcruise.layout import EXT_E1, EXT_FX, EXT_FY, EXT_FZ, EXT_TX, EXT_TY, EXT_TZ, EXT_WX, EXT_WY, EXT_WZ, Row

# --- state row: 13 columns, then one rotor speed per rotor ------------------------------------
_ROTOR_BODY_UNITS = {
    "x": "m",
    "y": "m",
    "z": "m",
    "vx": "m/s",
    "vy": "m/s",
    "vz": "m/s",
    "qw": "-",
    "qx": "-",
    "qy": "-",
    "qz": "-",
    "p": "rad/s",
    "q": "rad/s",
    "r": "rad/s",
}
ROTOR_BODY = Row.of("rotor-plant state", *_ROTOR_BODY_UNITS, prefix="R")
"""The rotor state's rigid-body part; the rotor speeds w1..wn [rad/s] follow it."""
RX, RY, RZ, RVX, RVY, RVZ, RQW, RQX, RQY, RQZ, RP, RQ, RR = ROTOR_BODY.offsets
QW, QX, QY, QZ = RQW, RQX, RQY, RQZ
"""The quaternion's columns, scalar first."""
ROTOR_W1 = ROTOR_BODY.size
"""Column of rotor 1's speed; rotor i (from 0) is at ``ROTOR_W1 + i``."""
ROTOR_BODY_NAMES = ROTOR_BODY.names
ROTOR_BODY_UNITS = tuple(_ROTOR_BODY_UNITS[name] for name in ROTOR_BODY_NAMES)

# --- parameter row: 20 columns (RotorVehicle's field names), then four per rotor ---------------
ROTOR_PARAM_UNITS = {
    "m": "kg",
    "Jxx": "kg m^2",
    "Jyy": "kg m^2",
    "Jzz": "kg m^2",
    "kf": "N/(rad/s)^2",
    "km": "N m/(rad/s)^2",
    "tau_up": "s",
    "tau_down": "s",
    "w_min": "rad/s",
    "w_max": "rad/s",
    "g": "m/s^2",
    "c_Dx": "N/(m/s)^2",
    "c_Dy": "N/(m/s)^2",
    "c_Dz": "N/(m/s)^2",
    "k_d": "N/(rad/s m/s)",
    "k_z": "N/(rad/s m/s)",
    "k_h": "N/(m/s)^2",
    "k_flap": "N m/(rad/s m/s)",
    "J_rotor": "kg m^2",
    "n_rotors": "-",
}
ROTOR_PARAMS = Row.of("rotor vehicle parameters", *ROTOR_PARAM_UNITS, prefix="ROTOR_P_")
"""The vehicle's row (:meth:`quadcruise.model.rotor_vehicle.RotorVehicle.row`), each field named as
the vehicle's; then :data:`ROTOR_ARM` per rotor from :data:`ROTOR_P_ROTORS` on."""
(
    ROTOR_P_M,
    ROTOR_P_JXX,
    ROTOR_P_JYY,
    ROTOR_P_JZZ,
    ROTOR_P_KF,
    ROTOR_P_KM,
    ROTOR_P_TAU_UP,
    ROTOR_P_TAU_DOWN,
    ROTOR_P_W_MIN,
    ROTOR_P_W_MAX,
    ROTOR_P_G,
    ROTOR_P_C_DX,
    ROTOR_P_C_DY,
    ROTOR_P_C_DZ,
    ROTOR_P_K_D,
    ROTOR_P_K_Z,
    ROTOR_P_K_H,
    ROTOR_P_K_FLAP,
    ROTOR_P_J_ROTOR,
    ROTOR_P_N_ROTORS,
) = ROTOR_PARAMS.offsets
ROTOR_P_ROTORS = ROTOR_PARAMS.size
"""First column of the rotors: rotor i's :data:`ROTOR_ARM` at ``ROTOR_P_ROTORS + ROTOR_ARM.size i``."""
ROTOR_ARM = Row.of("rotor", "x", "y", "z", "s", prefix="ARM_")
"""One rotor's entries of the parameter row: its hub x, y, z [m] (body frame) and direction s (+1 or -1)."""
ARM_X, ARM_Y, ARM_Z, ARM_S = ROTOR_ARM.offsets
ARM_SIZE = ROTOR_ARM.size


def state_names(n_rotors: int) -> tuple[str, ...]:
    """The state's column names for a vehicle with ``n_rotors`` rotors.

    Parameters
    ----------
    n_rotors : int
        Number of rotors.

    Returns
    -------
    tuple of str
        ``x, y, z, vx, vy, vz, qw, qx, qy, qz, p, q, r, w1 .. wn``.

    Examples
    --------
    >>> state_names(4)[-5:]
    ('r', 'w1', 'w2', 'w3', 'w4')
    """
    return ROTOR_BODY_NAMES + tuple(f"w{i + 1}" for i in range(n_rotors))


@njit(cache=True, error_model="numpy")
def rotor_derivative(x, w_cmd, rp, ext, dx):
    """Write dx/dt of one rotor-speed vehicle into ``dx`` (the equations of this module).

    The RK4 step computes it stage by stage with :func:`rotor_stage`; this is the stage at the
    state itself.

    Parameters
    ----------
    x : ndarray, shape (13 + n,)
        The state: position [m], velocity [m/s], quaternion [-], body rates [rad/s], rotor
        speeds [rad/s].
    w_cmd : ndarray, shape (n,)
        Commanded rotor speeds [rad/s], within [w_min, w_max].
    rp : ndarray, shape (ROTOR_P_ROTORS + 4 n,)
        The vehicle's parameter row.
    ext : ndarray, shape (9 + n,)
        External force [N] (world), torque [N m] (body), wind [m/s] (world), rotor
        effectiveness [-].
    dx : ndarray, shape (13 + n,), contiguous
        Output: the state's time derivative.
    """
    rotor_stages(x, w_cmd, rp, ext, 0.0, dx.reshape((1, dx.shape[0])), 1)


@njit(cache=True, inline="always", error_model="numpy")
def rotor_stages(x, w_cmd, rp, ext, h, k, stages):
    """The first ``stages`` (1 to 4) stages of a classical RK4 step of length h [s] from x:
    ``k[s] = f(x + a_s k[s - 1])``, a_s = 0, h/2, h/2, h for s = 0, 1, 2, 3, with f the equations
    of this module (``stages=1``: k[0] = f(x), the derivative).

    Each stage state is formed entry by entry as it is read (scalars, no array of it), and a term
    whose coefficient is zero is not computed (k_h and k_z: lift and inflow; k_flap; J_rotor;
    c_D: parasitic drag), which leaves every sum as it was: the same numbers, fewer operations.
    ``k`` is indexed by row and column, never sliced, and the stages are one loop in this body,
    not a helper called per stage: a row view (``k[stage]``) or an array handed to a helper each
    stage costs numba's reference counting of it (an atomic increment and decrement) each time,
    which took more time than the arithmetic.

    Parameters
    ----------
    x : ndarray, shape (13 + n,)
        The state at the start of the step (:func:`rotor_derivative`'s ``x``).
    w_cmd, rp, ext : ndarray
        As :func:`rotor_derivative` takes them.
    h : float
        The step length [s] (not read with ``stages=1``).
    k : ndarray, shape (>= stages, 13 + n)
        Output: the stage derivatives, row s for stage s.
    stages : int
        How many stages, from the first.
    """
    n = int(rp[ROTOR_P_N_ROTORS])
    kf, km, kd, kz, kh, kflap = (
        rp[ROTOR_P_KF],
        rp[ROTOR_P_KM],
        rp[ROTOR_P_K_D],
        rp[ROTOR_P_K_Z],
        rp[ROTOR_P_K_H],
        rp[ROTOR_P_K_FLAP],
    )
    tau_up, tau_down, j_rotor = rp[ROTOR_P_TAU_UP], rp[ROTOR_P_TAU_DOWN], rp[ROTOR_P_J_ROTOR]
    cdx, cdy, cdz = rp[ROTOR_P_C_DX], rp[ROTOR_P_C_DY], rp[ROTOR_P_C_DZ]
    jxx, jyy, jzz = rp[ROTOR_P_JXX], rp[ROTOR_P_JYY], rp[ROTOR_P_JZZ]
    inv_m, g = 1.0 / rp[ROTOR_P_M], rp[ROTOR_P_G]
    lift_inflow = kh != 0.0 or kz != 0.0
    body_drag = cdx != 0.0 or cdy != 0.0 or cdz != 0.0
    for stage in range(stages):
        if stage == 0:  # the stage state
            a = 0.0
            vx, vy, vz = x[RVX], x[RVY], x[RVZ]
            qw, qx, qy, qz = x[QW], x[QX], x[QY], x[QZ]
            p, q, r = x[RP], x[RQ], x[RR]
        else:
            a = h if stage == 3 else 0.5 * h
            j = stage - 1
            vx, vy, vz = x[RVX] + a * k[j, RVX], x[RVY] + a * k[j, RVY], x[RVZ] + a * k[j, RVZ]
            qw, qx = x[QW] + a * k[j, QW], x[QX] + a * k[j, QX]
            qy, qz = x[QY] + a * k[j, QY], x[QZ] + a * k[j, QZ]
            p, q, r = x[RP] + a * k[j, RP], x[RQ] + a * k[j, RQ], x[RR] + a * k[j, RR]
        s = 2.0 / (qw * qw + qx * qx + qy * qy + qz * qz)  # R of q / |q|
        r00, r01, r02 = 1.0 - s * (qy * qy + qz * qz), s * (qx * qy - qw * qz), s * (qx * qz + qw * qy)
        r10, r11, r12 = s * (qx * qy + qw * qz), 1.0 - s * (qx * qx + qz * qz), s * (qy * qz - qw * qx)
        r20, r21, r22 = s * (qx * qz - qw * qy), s * (qy * qz + qw * qx), 1.0 - s * (qx * qx + qy * qy)
        ax, ay, az = vx - ext[EXT_WX], vy - ext[EXT_WY], vz - ext[EXT_WZ]
        ub = r00 * ax + r10 * ay + r20 * az  # airspeed, body frame: R^T (v - w)
        vb = r01 * ax + r11 * ay + r21 * az
        wb = r02 * ax + r12 * ay + r22 * az
        fx = fy = fz = 0.0  # body force [N]
        mx = my = mz = 0.0  # body moment [N m]
        h_r = h_dot = 0.0  # rotors' angular momentum about body z
        for i in range(n):
            base = ROTOR_P_ROTORS + ARM_SIZE * i
            px, py, pz, sign = rp[base + ARM_X], rp[base + ARM_Y], rp[base + ARM_Z], rp[base + ARM_S]
            w = x[ROTOR_W1 + i]
            if stage != 0:
                w += a * k[stage - 1, ROTOR_W1 + i]
            e = ext[EXT_E1 + i]
            lx = ub + q * pz - r * py  # airspeed at the hub: v_b + Omega x r_i
            ly = vb + r * px - p * pz
            f_x = -w * kd * lx  # rotor drag (H force) ...
            f_y = -w * kd * ly
            f_z = e * kf * w * w  # ... thrust, lift, inflow
            if lift_inflow:
                lz = wb + p * py - q * px
                f_z = f_z + kh * (lx * lx + ly * ly) - w * kz * lz
            fx += f_x
            fy += f_y
            fz += f_z
            m_x = py * f_z - pz * f_y  # r_i x F_i, and flapping
            m_y = pz * f_x - px * f_z
            if kflap != 0.0:
                m_x -= kflap * w * ly
                m_y += kflap * w * lx
            mx += m_x
            my += m_y
            mz += px * f_y - py * f_x + sign * e * km * w * w  # and the rotor's drag moment
            c = w_cmd[i]
            w_dot = (c - w) / (tau_up if c > w else tau_down)
            k[stage, ROTOR_W1 + i] = w_dot
            if j_rotor != 0.0:
                h_r -= sign * j_rotor * w
                h_dot -= sign * j_rotor * w_dot
        if body_drag:  # parasitic drag
            speed = math.sqrt(ub * ub + vb * vb + wb * wb)
            fx -= speed * cdx * ub
            fy -= speed * cdy * vb
            fz -= speed * cdz * wb
        k[stage, RX] = vx
        k[stage, RY] = vy
        k[stage, RZ] = vz
        k[stage, RVX] = (r00 * fx + r01 * fy + r02 * fz + ext[EXT_FX]) * inv_m
        k[stage, RVY] = (r10 * fx + r11 * fy + r12 * fz + ext[EXT_FY]) * inv_m
        k[stage, RVZ] = (r20 * fx + r21 * fy + r22 * fz + ext[EXT_FZ]) * inv_m - g
        k[stage, QW] = -0.5 * (qx * p + qy * q + qz * r)  # q (x) (0, Omega) / 2
        k[stage, QX] = 0.5 * (qw * p + qy * r - qz * q)
        k[stage, QY] = 0.5 * (qw * q + qz * p - qx * r)
        k[stage, QZ] = 0.5 * (qw * r + qx * q - qy * p)
        lx_, ly_, lz_ = jxx * p, jyy * q, jzz * r + h_r  # body and rotors' angular momentum
        k[stage, RP] = (mx + ext[EXT_TX] - (q * lz_ - r * ly_)) / jxx
        k[stage, RQ] = (my + ext[EXT_TY] - (r * lx_ - p * lz_)) / jyy
        k[stage, RR] = (mz + ext[EXT_TZ] - (p * ly_ - q * lx_) - h_dot) / jzz
