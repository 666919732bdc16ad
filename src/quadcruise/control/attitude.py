"""Attitude: the paper's decoupling (eqs 11-15) closed by a PID on each angle.

Eq (11) couples the axes through k1 q r, k3 p r and k5 p q. Eq (13) chooses

    U2 = (U2* - k1 q r) / k2,   U3 = (U3* - k3 p r) / k4,   U4 = (U4* - k5 p q) / k6

so that eq (15) holds: phi'' = U2*, theta'' = U3*, psi'' = U4*, three independent double
integrators. Each is closed by

    U* = Kp e + Ki int(e) dt - Kd rate,      e = angle_d - angle

with the derivative acting on the measured body rate (p, q or r), not on the error: the
setpoint comes from the position loop and changes every period, and a derivative of it
would both kick and, through the 15 rad/s rotor lag, erode the damping of the cascade
(see :func:`quadcruise.control.design.attitude_pid_design`). Anti-windup clamps each
integral so that Ki * int(e) stays within ``i_limit`` [rad/s^2], and flags it.

These are compiled building blocks called by the position controllers; they are not
themselves engine controllers.
"""

from __future__ import annotations

import math

from numba import njit

from ..layout import FLAG_INTEGRATOR_HOLD, P, P_K1, P_K2, P_K3, P_K4, P_K5, P_K6, PHI, PSI, Q, R, THETA

# gains layout shared by every controller built on this loop (offsets into ``gains``)
ATT_KP, ATT_KI, ATT_KD, YAW_KP, YAW_KI, YAW_KD, ATT_I_LIMIT = range(7)
ATT_GAINS = 7
# memory: the integral of the roll, pitch and yaw errors [rad s]
ATT_MEMORY = 3


@njit(cache=True, inline="always", error_model="numpy")
def wrap_angle(a):
    """Angle wrapped into (-pi, pi]."""
    return a - 2.0 * math.pi * math.floor((a + math.pi) / (2.0 * math.pi))


@njit(cache=True, inline="always", error_model="numpy")
def _axis_pid(j, e, rate, kp, ki, kd, i_limit, dt, mem):
    """PID on one angle j (0 roll, 1 pitch, 2 yaw); returns (U*, integrator held?)."""
    held = False
    if ki > 0.0:
        integral = mem[j] + e * dt
        bound = i_limit / ki
        if integral > bound:
            integral, held = bound, True
        elif integral < -bound:
            integral, held = -bound, True
        mem[j] = integral
    return kp * e + ki * mem[j] - kd * rate, held


@njit(cache=True, error_model="numpy")
def decoupled_attitude(x, phi_d, theta_d, psi_d, vp, g, mem, dt):
    """Eqs (13)-(15) with PID: the roll, pitch and yaw inputs (U2, U3, U4) and a flag word.

    ``g`` and ``mem`` are the controller's gains and memory, whose first ATT_GAINS and
    ATT_MEMORY entries belong to the attitude loop (layout ATT_* above).
    """
    p, q, r = x[P], x[Q], x[R]
    lim = g[ATT_I_LIMIT]
    u2s, h1 = _axis_pid(0, phi_d - x[PHI], p, g[ATT_KP], g[ATT_KI], g[ATT_KD], lim, dt, mem)
    u3s, h2 = _axis_pid(1, theta_d - x[THETA], q, g[ATT_KP], g[ATT_KI], g[ATT_KD], lim, dt, mem)
    u4s, h3 = _axis_pid(2, wrap_angle(psi_d - x[PSI]), r, g[YAW_KP], g[YAW_KI], g[YAW_KD], lim, dt, mem)
    U2 = (u2s - vp[P_K1] * q * r) / vp[P_K2]                                 # (13)
    U3 = (u3s - vp[P_K3] * p * r) / vp[P_K4]                                 # (13)
    U4 = (u4s - vp[P_K5] * p * q) / vp[P_K6]                                 # (13)
    flags = FLAG_INTEGRATOR_HOLD if (h1 or h2 or h3) else 0
    return U2, U3, U4, flags
