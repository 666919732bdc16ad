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

``ext`` is an external force [N] (earth frame) and torque [N m] (body frame) per vehicle,
(fx, fy, fz, tx, ty, tz); zero unless a disturbance model supplies one.
"""

from __future__ import annotations

import math

from numba import njit

from ..layout import (
    F1, F2, F3, F4, P, PHI, PSI, Q, R, THETA, VX, VY, VZ, X, Y, Z,
    P_D, P_G, P_JXX, P_JYY, P_JZZ, P_K, P_K1, P_K2, P_K3, P_K4, P_K5, P_K6, P_M, P_OMEGA,
)
from .actuators import mix


@njit(cache=True, error_model="numpy")
def derivative(x, u, vp, ext, dx):
    """Write dx/dt of one vehicle into ``dx``.

    Parameters
    ----------
    x : (16,) state; u : (4,) PWM duties, already in [0, 1];
    vp : (PARAM_SIZE,) vehicle parameter row; ext : (6,) external force and torque;
    dx : (16,) output.
    """
    m = vp[P_M]
    phi, theta, psi = x[PHI], x[THETA], x[PSI]
    p, q, r = x[P], x[Q], x[R]
    U1, U2, U3, U4 = mix(x[F1], x[F2], x[F3], x[F4], vp[P_D])             # (1)-(4)

    sphi, cphi = math.sin(phi), math.cos(phi)
    sth, cth = math.sin(theta), math.cos(theta)
    spsi, cpsi = math.sin(psi), math.cos(psi)
    a = U1 / m

    dx[X] = x[VX]
    dx[Y] = x[VY]
    dx[Z] = x[VZ]
    dx[VX] = (sphi * spsi + cphi * sth * cpsi) * a + ext[0] / m             # (5)
    dx[VY] = (-sphi * cpsi + cphi * sth * spsi) * a + ext[1] / m            # (6)
    dx[VZ] = cphi * cth * a - vp[P_G] + ext[2] / m                          # (7)
    dx[PHI] = p
    dx[THETA] = q
    dx[PSI] = r
    dx[P] = vp[P_K1] * q * r + vp[P_K2] * U2 + ext[3] / vp[P_JXX]           # (11) roll
    dx[Q] = vp[P_K3] * p * r + vp[P_K4] * U3 + ext[4] / vp[P_JYY]           # (11) pitch
    dx[R] = vp[P_K5] * p * q + vp[P_K6] * U4 + ext[5] / vp[P_JZZ]           # (11) yaw
    w, K = vp[P_OMEGA], vp[P_K]
    dx[F1] = w * (K * u[0] - x[F1])                                         # rotor lag
    dx[F2] = w * (K * u[1] - x[F2])
    dx[F3] = w * (K * u[2] - x[F3])
    dx[F4] = w * (K * u[3] - x[F4])
