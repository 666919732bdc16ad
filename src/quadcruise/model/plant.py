"""The paper's quadrotor: eqs (5)-(7) for translation, the k1..k6 form (11) for rotation,
and the rotor lag of Table I's actuator, as one compiled derivative for one vehicle.

State (see :mod:`quadcruise.layout`): x, y, z, vx, vy, vz (earth frame, z up), phi, theta,
psi (roll, pitch, yaw), p, q, r (body rates), F1..F4 (rotor thrusts).

    x''  = (sin phi sin psi + cos phi sin theta cos psi) U1 / m        (5)
    y''  = (-sin phi cos psi + cos phi sin theta sin psi) U1 / m       (6)
    z''  = cos phi cos theta U1 / m - g                                (7)
    phi' = p,   p' = k1 q r + k2 U2                                    (11)
    theta' = q, q' = k3 p r + k4 U3
    psi' = r,   r' = k5 p q + k6 U4
    F_i' = omega (K u_i - F_i),  u_i in [0, 1]                         (Table I actuator)

with k1 = (Jyy - Jzz)/Jxx, k2 = l/Jxx, k3 = (Jzz - Jxx)/Jyy, k4 = l/Jyy,
k5 = (Jxx - Jyy)/Jzz, k6 = 1/Jzz.

Deviation from the printed paper: eqs (8)-(10) print the inertia differences as
(Jxx - Jyy), (Jxx - Jzz), (Jyy - Jxx) with a minus sign in front; that is a typo (it does
not match the rigid-body Euler equations, nor the paper's own eq (11)). The k1..k6 form
above is the standard one (Bouabdallah and Siegwart, 2007) and is what we integrate.
Like the paper, we take the Euler-angle rates equal to the body rates (phi' = p, ...),
a small-angle simplification.

``ext`` (:data:`quadcruise.layout.EXT_SIZE`) holds what a disturbance model supplies: an
external force [N] (earth frame), torque [N m] (body frame), the wind velocity [m/s] and each
rotor's effectiveness. Beyond the paper's model, and zero unless the vehicle has them:

    aerodynamic drag  F_d = -(c1 + c2 |v - w|) (v - w)   (v - w: air-relative velocity)
    rotor damage      F_i' = omega (e_i K u_i - F_i)      (e_i = 1 when healthy)

With ``full`` set, the kinematics are the exact ZYX Euler-angle rates instead of the
paper's phi' = p, theta' = q, psi' = r:

    phi'   = p + (q sin phi + r cos phi) tan theta
    theta' = q cos phi - r sin phi
    psi'   = (q sin phi + r cos phi) / cos theta

which are singular at theta = +-90 degrees: near it, 1/cos theta magnifies every error. A
flight of the full plant therefore stops when |theta| passes :data:`EULER_PITCH_LIMIT`, with
its own exit status (``ExitStatus.PITCH_SINGULAR``), instead of going on with a silently
inaccurate attitude. The paper's kinematics have no such singularity.
"""

from __future__ import annotations

import math

from numba import njit

from quadcruise import layout as L
from quadcruise.model.actuators import mix

EULER_PITCH_LIMIT = math.radians(85.0)
"""|pitch| [rad] beyond which a flight of the full plant stops: there 1/cos theta = 11.5, and
the ZYX Euler-angle rates go singular at 90 degrees."""


@njit(cache=True, error_model="numpy")
def derivative(x, u, vp, ext, full, dx):
    """Write dx/dt of one vehicle into ``dx``.

    Parameters
    ----------
    x : ndarray, shape (16,)
        The state, in the SI units of :data:`quadcruise.layout.STATE_UNITS`.
    u : ndarray, shape (4,)
        PWM duties [-], already in [0, 1].
    vp : ndarray, shape (PARAM_SIZE,)
        The vehicle parameter row (:mod:`quadcruise.layout`).
    ext : ndarray, shape (EXT_SIZE,)
        External inputs: force [N], torque [N m], wind [m/s], rotor effectiveness [-].
    full : bool
        Exact Euler-angle kinematics instead of the paper's simplification.
    dx : ndarray, shape (16,)
        Output: the state's time derivative [unit/s].
    """
    derivative_at(
        x,
        math.sin(x[L.PHI]),
        math.cos(x[L.PHI]),
        math.sin(x[L.THETA]),
        math.cos(x[L.THETA]),
        math.sin(x[L.PSI]),
        math.cos(x[L.PSI]),
        u,
        vp,
        ext,
        full,
        dx,
    )


@njit(cache=True, inline="always", error_model="numpy")
def derivative_at(x, sphi, cphi, sth, cth, spsi, cpsi, u, vp, ext, full, dx):
    """:func:`derivative` given the sines and cosines of the state's phi, theta and psi.

    The integrator carries them from one RK4 stage to the next
    (:func:`quadcruise.sim.engine.rk4_step`).

    Parameters
    ----------
    x : ndarray, shape (16,)
        The state, in the SI units of :data:`quadcruise.layout.STATE_UNITS`.
    sphi, cphi : float
        sin and cos of ``x[PHI]`` [-].
    sth, cth : float
        sin and cos of ``x[THETA]`` [-].
    spsi, cpsi : float
        sin and cos of ``x[PSI]`` [-].
    u : ndarray, shape (4,)
        PWM duties [-], already in [0, 1].
    vp : ndarray, shape (PARAM_SIZE,)
        The vehicle parameter row.
    ext : ndarray, shape (EXT_SIZE,)
        External inputs: force [N], torque [N m], wind [m/s], rotor effectiveness [-].
    full : bool
        Exact Euler-angle kinematics instead of the paper's simplification.
    dx : ndarray, shape (16,)
        Output: the state's time derivative [unit/s].
    """
    m = vp[L.P_M]
    p, q, r = x[L.P], x[L.Q], x[L.R]
    U1, U2, U3, U4 = mix(x[L.F1], x[L.F2], x[L.F3], x[L.F4], vp[L.P_D])  # (1)-(4)
    a = U1 / m

    fx, fy, fz = ext[L.EXT_FX], ext[L.EXT_FY], ext[L.EXT_FZ]
    c1, c2 = vp[L.P_CD1], vp[L.P_CD2]
    if c1 != 0.0 or c2 != 0.0:  # drag, air-relative
        rx, ry, rz = x[L.VX] - ext[L.EXT_WX], x[L.VY] - ext[L.EXT_WY], x[L.VZ] - ext[L.EXT_WZ]
        c = c1 + c2 * math.sqrt(rx * rx + ry * ry + rz * rz)
        fx -= c * rx
        fy -= c * ry
        fz -= c * rz

    dx[L.X] = x[L.VX]
    dx[L.Y] = x[L.VY]
    dx[L.Z] = x[L.VZ]
    dx[L.VX] = (sphi * spsi + cphi * sth * cpsi) * a + fx / m  # (5)
    dx[L.VY] = (-sphi * cpsi + cphi * sth * spsi) * a + fy / m  # (6)
    dx[L.VZ] = cphi * cth * a - vp[L.P_G] + fz / m  # (7)
    if full:
        s = q * sphi + r * cphi
        dx[L.PHI] = p + s * sth / cth
        dx[L.THETA] = q * cphi - r * sphi
        dx[L.PSI] = s / cth
    else:  # the paper's
        dx[L.PHI] = p
        dx[L.THETA] = q
        dx[L.PSI] = r
    dx[L.P] = vp[L.P_K1] * q * r + vp[L.P_K2] * U2 + ext[L.EXT_TX] / vp[L.P_JXX]  # (11) roll
    dx[L.Q] = vp[L.P_K3] * p * r + vp[L.P_K4] * U3 + ext[L.EXT_TY] / vp[L.P_JYY]  # (11) pitch
    dx[L.R] = vp[L.P_K5] * p * q + vp[L.P_K6] * U4 + ext[L.EXT_TZ] / vp[L.P_JZZ]  # (11) yaw
    w, K = vp[L.P_OMEGA], vp[L.P_K]
    dx[L.F1] = w * (ext[L.EXT_E1] * K * u[0] - x[L.F1])  # rotor lag
    dx[L.F2] = w * (ext[L.EXT_E2] * K * u[1] - x[L.F2])
    dx[L.F3] = w * (ext[L.EXT_E3] * K * u[2] - x[L.F3])
    dx[L.F4] = w * (ext[L.EXT_E4] * K * u[3] - x[L.F4])
