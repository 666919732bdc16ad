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

from numba import njit

from quadcruise.layout import FLAG_INTEGRATOR_HOLD, P_K1, P_K2, P_K3, P_K4, P_K5, P_K6, PHI, PSI, THETA, P, Q, R, Row
from quadcruise.numeric import clamp, wrap_angle

ATTITUDE_GAINS = Row.of("attitude gains", "att_kp", "att_ki", "att_kd", "yaw_kp", "yaw_ki", "yaw_kd", "att_i_limit")
"""The block that starts the gains of every controller built on this loop: kp [1/s^2], ki
[1/s^3], kd [1/s] of roll and pitch, the same of yaw, and i_limit [rad/s^2]."""
ATT_KP, ATT_KI, ATT_KD, YAW_KP, YAW_KI, YAW_KD, ATT_I_LIMIT = ATTITUDE_GAINS.offsets
ATT_GAINS = ATTITUDE_GAINS.size
ATTITUDE_MEMORY = Row.of("attitude memory", ("att_integral", 3))
"""The block that starts their memory: the integrals of the roll, pitch and yaw errors [rad s]."""
(ATT_INTEGRAL,) = ATTITUDE_MEMORY.offsets
ATT_MEMORY = ATTITUDE_MEMORY.size


def attitude_fields(attitude, yaw, i_limit: float) -> dict[str, float]:
    """The fields of :data:`ATTITUDE_GAINS`, for :meth:`Row.pack <quadcruise.layout.Row.pack>`.

    Examples
    --------
    >>> from quadcruise.control.design import PIDGains
    >>> fields = attitude_fields(PIDGains(kp=1.0, ki=2.0, kd=3.0), PIDGains(kp=4.0, ki=5.0, kd=6.0), 7.0)
    >>> ATTITUDE_GAINS.pack(fields).tolist()
    [1.0, 2.0, 3.0, 4.0, 5.0, 6.0, 7.0]
    """
    return {
        "att_kp": attitude.kp,
        "att_ki": attitude.ki,
        "att_kd": attitude.kd,
        "yaw_kp": yaw.kp,
        "yaw_ki": yaw.ki,
        "yaw_kd": yaw.kd,
        "att_i_limit": i_limit,
    }


@njit(cache=True, inline="always", error_model="numpy")
def pid_axis(e, rate, integral, kp, ki, kd, i_limit, dt):
    """PID on one angle error with the derivative on the measured rate; anti-windup holds
    ``ki * integral`` within +-``i_limit`` (:func:`quadcruise.numeric.clamp`).

    Examples
    --------
    >>> u, integral, held = pid_axis(0.1, 0.0, 0.0, 88.2, 40.5, 14.9, 5.0, 0.001)
    >>> round(u, 6), integral, held
    (8.82405, 0.0001, False)
    >>> pid_axis(1.0, 0.0, 0.12, 1.0, 50.0, 0.0, 5.0, 0.001)[1:]
    (0.1, True)
    """
    held = False
    if ki > 0.0:
        bound = i_limit / ki
        integral, held = clamp(integral + e * dt, -bound, bound)
    return kp * e + ki * integral - kd * rate, integral, held


@njit(cache=True, inline="always", error_model="numpy")
def attitude_law(phi_d, theta_d, psi_d, phi, theta, psi, p, q, r, k, g, integrals, dt):
    """Eqs (13)-(15) with PID, on scalars: returns ((U2, U3, U4), new integrals, flags).

    Examples
    --------
    >>> k = (0.0, 6.0, 0.0, 6.0, 0.0, 25.0)     # k2 = k4 = l / J, k6 = 1 / Jzz; zero rates
    >>> g = (88.2, 40.5, 14.9, 88.2, 40.5, 14.9, 5.0)
    >>> U, integrals, flags = attitude_law(0.1, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, k, g,
    ...                                    (0.0, 0.0, 0.0), 0.001)
    >>> round(U[0], 6), integrals[0], flags
    (1.470675, 0.0001, 0)
    """
    k1, k2, k3, k4, k5, k6 = k
    i_phi, i_theta, i_psi = integrals
    lim = g[ATT_I_LIMIT]
    u2s, i_phi, h1 = pid_axis(phi_d - phi, p, i_phi, g[ATT_KP], g[ATT_KI], g[ATT_KD], lim, dt)
    u3s, i_theta, h2 = pid_axis(theta_d - theta, q, i_theta, g[ATT_KP], g[ATT_KI], g[ATT_KD], lim, dt)
    u4s, i_psi, h3 = pid_axis(wrap_angle(psi_d - psi), r, i_psi, g[YAW_KP], g[YAW_KI], g[YAW_KD], lim, dt)
    U2 = (u2s - k1 * q * r) / k2  # (13)
    U3 = (u3s - k3 * p * r) / k4  # (13)
    U4 = (u4s - k5 * p * q) / k6  # (13)
    flags = FLAG_INTEGRATOR_HOLD if (h1 or h2 or h3) else 0
    return (U2, U3, U4), (i_phi, i_theta, i_psi), flags


@njit(cache=True, inline="always", error_model="numpy")
def decoupling_constants(vp):
    """(k1, ..., k6) of a vehicle parameter row."""
    return vp[P_K1], vp[P_K2], vp[P_K3], vp[P_K4], vp[P_K5], vp[P_K6]


@njit(cache=True, inline="always", error_model="numpy")
def attitude_gains(gains):
    """The attitude block (the first ATT_GAINS entries) of a gains vector, as a tuple."""
    return (
        gains[ATT_KP],
        gains[ATT_KI],
        gains[ATT_KD],
        gains[YAW_KP],
        gains[YAW_KI],
        gains[YAW_KD],
        gains[ATT_I_LIMIT],
    )


@njit(cache=True, inline="always", error_model="numpy")
def decoupled_attitude(x, phi_d, theta_d, psi_d, vp, g, mem, dt):
    """Eqs (13)-(15) with PID from arrays: the roll, pitch and yaw inputs (U2, U3, U4) and a
    flag word; updates the integrals in ``mem[:ATT_MEMORY]``."""
    U, integrals, flags = attitude_law(
        phi_d,
        theta_d,
        psi_d,
        x[PHI],
        x[THETA],
        x[PSI],
        x[P],
        x[Q],
        x[R],
        decoupling_constants(vp),
        attitude_gains(g),
        (mem[ATT_INTEGRAL], mem[ATT_INTEGRAL + 1], mem[ATT_INTEGRAL + 2]),
        dt,
    )
    mem[ATT_INTEGRAL], mem[ATT_INTEGRAL + 1], mem[ATT_INTEGRAL + 2] = integrals
    return U[0], U[1], U[2], flags
