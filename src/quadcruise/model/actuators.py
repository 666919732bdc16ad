"""Rotors: the mixer of eqs (1)-(4), its inverse, and the PWM gain.

Rotor i makes thrust F_i [N]. Its dynamics (the first-order lag F = K w / (s + w) u of the
Qball-X4, Table I) live in the plant's derivative; here is only the algebra that maps the
four thrusts to the paper's generalized inputs and back.

    U1 = F1 + F2 + F3 + F4                (1)  collective thrust [N]
    U2 = F2 - F4                          (2)  roll input [N]  (torque U2 * l)
    U3 = F1 - F3                          (3)  pitch input [N] (torque U3 * l)
    U4 = d (F1 + F3 - F2 - F4)            (4)  yaw torque [N m]

All functions are compiled scalar code for one vehicle.
"""

from __future__ import annotations

from numba import njit


@njit(cache=True, inline="always")
def mix(F1, F2, F3, F4, d):
    """Eqs (1)-(4): rotor thrusts [N] to (U1, U2, U3, U4)."""
    return F1 + F2 + F3 + F4, F2 - F4, F1 - F3, d * (F1 + F3 - F2 - F4)


@njit(cache=True, inline="always")
def unmix(U1, U2, U3, U4, d):
    """Inverse of eqs (1)-(4): (U1, U2, U3, U4) to rotor thrusts (F1, F2, F3, F4) [N].

    The solution is exact and unique for d > 0; it may ask for a negative thrust, which
    :func:`duties` passes on and the engine clips (and reports).
    """
    s13 = 0.25 * (U1 + U4 / d)   # (F1 + F3) / 2
    s24 = 0.25 * (U1 - U4 / d)   # (F2 + F4) / 2
    return s13 + 0.5 * U3, s24 + 0.5 * U2, s13 - 0.5 * U3, s24 - 0.5 * U2


@njit(cache=True, inline="always")
def duties(U1, U2, U3, U4, d, K):
    """The PWM duties (u1, u2, u3, u4) that give (U1..U4) in steady state: F_i / K, with
    yaw arm d [m] and PWM gain K [N].

    They are *not* clipped here: the engine clips them to [0, 1] and counts the periods in
    which it had to, so saturation is always reported.
    """
    F1, F2, F3, F4 = unmix(U1, U2, U3, U4, d)
    inv_k = 1.0 / K
    return F1 * inv_k, F2 * inv_k, F3 * inv_k, F4 * inv_k
