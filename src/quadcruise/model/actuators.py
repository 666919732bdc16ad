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
    """Eqs (1)-(4): rotor thrusts to the generalized inputs.

    Parameters
    ----------
    F1, F2, F3, F4 : float
        Rotor thrusts [N].
    d : float
        Yaw arm: rotor drag torque per unit thrust [m].

    Returns
    -------
    U1, U2, U3 : float
        Collective thrust, roll and pitch inputs [N].
    U4 : float
        Yaw torque [N m].

    Examples
    --------
    >>> mix(1.0, 2.0, 3.0, 4.0, 0.5)
    (10.0, -2.0, -2.0, -1.0)
    """
    return F1 + F2 + F3 + F4, F2 - F4, F1 - F3, d * (F1 + F3 - F2 - F4)


@njit(cache=True, inline="always")
def unmix(U1, U2, U3, U4, d):
    """Inverse of eqs (1)-(4): the generalized inputs to rotor thrusts.

    The solution is exact and unique for d > 0; it may ask for a negative thrust, which
    :func:`duties` passes on and the engine clips (and reports).

    Parameters
    ----------
    U1, U2, U3 : float
        Collective thrust, roll and pitch inputs [N].
    U4 : float
        Yaw torque [N m].
    d : float
        Yaw arm [m], > 0.

    Returns
    -------
    F1, F2, F3, F4 : float
        Rotor thrusts [N].

    Examples
    --------
    >>> unmix(10.0, -2.0, -2.0, -1.0, 0.5)
    (1.0, 2.0, 3.0, 4.0)
    """
    s13 = 0.25 * (U1 + U4 / d)  # (F1 + F3) / 2
    s24 = 0.25 * (U1 - U4 / d)  # (F2 + F4) / 2
    return s13 + 0.5 * U3, s24 + 0.5 * U2, s13 - 0.5 * U3, s24 - 0.5 * U2


@njit(cache=True, inline="always")
def duties(U1, U2, U3, U4, d, K):
    """The PWM duties that give (U1..U4) in steady state: F_i / K.

    They are *not* clipped here: the engine clips them to [0, 1] and counts the periods in
    which it had to, so saturation is always reported.

    Parameters
    ----------
    U1, U2, U3 : float
        Collective thrust, roll and pitch inputs [N].
    U4 : float
        Yaw torque [N m].
    d : float
        Yaw arm [m], > 0.
    K : float
        PWM gain: a rotor's steady thrust at duty 1 [N].

    Returns
    -------
    u1, u2, u3, u4 : float
        The duties [-] (not clipped to [0, 1]).

    Examples
    --------
    >>> duties(10.0, -2.0, -2.0, -1.0, 0.5, 4.0)
    (0.25, 0.5, 0.75, 1.0)
    """
    F1, F2, F3, F4 = unmix(U1, U2, U3, U4, d)
    inv_k = 1.0 / K
    return F1 * inv_k, F2 * inv_k, F3 * inv_k, F4 * inv_k
