"""The inverse model of the position controllers: eqs (5), (6), (16) and (19) solved for the
roll and pitch setpoints that give a wanted acceleration, the tilt-compensated thrust, and the
tilt limit with its flags (the steps of :mod:`quadcruise.control.position`'s docstring).

Compiled building blocks, inlined into ``nlpd`` and ``gonzalez``; ``theta_from_eq5`` and
``phi_from_eq6`` are the angle forms the tests check against the paper.
"""

from __future__ import annotations

import math

from numba import njit

from quadcruise.layout import FLAG_ASIN_CLIP, FLAG_THRUST_LIMIT, FLAG_TILT_LIMIT
from quadcruise.numeric import clamp, wrap_angle


@njit(cache=True, inline="always", error_model="numpy")
def tilt_joint(ux, uy, spsi, cpsi, a, max_tilt, flags):
    """Eqs (5) and (6) solved together for the roll and pitch setpoints, each limited to max_tilt.

    Examples
    --------
    >>> phi, theta, flags = tilt_joint(0.981, 0.0, 0.0, 1.0, 9.81, 0.7, 0)    # yaw 0: x'' from pitch alone
    >>> round(phi, 6), round(theta, 6), flags
    (0.0, 0.100167, 0)
    >>> phi, theta, flags = tilt_joint(0.981, 0.0, 1.0, 0.0, 9.81, 0.7, 0)    # yaw 90 deg: from roll alone
    >>> round(phi, 6), round(theta, 6) + 0.0, flags
    (0.100167, 0.0, 0)
    """
    if a < 1e-9:  # no thrust: no tilt can help
        return 0.0, 0.0, flags | FLAG_ASIN_CLIP
    sphi, clipped = clamp((ux * spsi - uy * cpsi) / a, -1.0, 1.0)  # (6) in the yaw frame
    phi_d, flags = tilt_setpoint(math.asin(sphi), clipped, max_tilt, flags)
    stheta, clipped = clamp((ux * cpsi + uy * spsi) / (a * math.cos(phi_d)), -1.0, 1.0)  # (5), (16)
    theta_d, flags = tilt_setpoint(math.asin(stheta), clipped, max_tilt, flags)
    return phi_d, theta_d, flags


@njit(cache=True, inline="always", error_model="numpy")
def pitch_eq16(ux, sphi, cphi, spsi, cpsi, a):
    """Eq (16) from the sines and cosines of roll and yaw (see :func:`theta_from_eq5`).

    Examples
    --------
    >>> theta, s, clipped = pitch_eq16(0.981, 0.0, 1.0, 0.0, 1.0, 9.81)
    >>> round(theta, 6), round(s, 6), clipped
    (0.100167, 0.1, False)
    >>> pitch_eq16(20.0, 0.0, 1.0, 0.0, 1.0, 9.81)[1:]
    (1.0, True)
    """
    den = cphi * cpsi * a
    if abs(den) < 1e-9:
        return 0.0, 0.0, True
    s, clipped = clamp((ux - sphi * spsi * a) / den, -1.0, 1.0)
    return math.asin(s), s, clipped


@njit(cache=True, inline="always", error_model="numpy")
def roll_eq19(uy, stheta, spsi, cpsi, a):
    """Eq (19), sign kept, from sin(theta) and the yaw's sine and cosine (see :func:`phi_from_eq6`).

    Examples
    --------
    >>> phi, clipped = roll_eq19(0.981, 0.0, 0.0, 1.0, 9.81)
    >>> round(phi, 6), clipped
    (-0.100167, False)
    """
    A = cpsi
    B = stheta * spsi
    R = math.sqrt(A * A + B * B)  # |A|, |B| <= 1: no overflow to guard against
    if R * a < 1e-9:
        return 0.0, True
    s, clipped = clamp(uy / (a * R), -1.0, 1.0)
    r1 = math.asin(s)
    if A > 0.0:
        # |gamma| < pi/2 and |r1| <= pi/2: gamma - r1 lies in (-pi, pi) and, cos phi1 -
        # cos phi2 = 2 A sqrt(1 - s^2) / R >= 0, it is the root nearest level (a kept trick,
        # see quadcruise.sim.fastmath; plain: the general case below)
        return math.atan(B / A) - r1, clipped
    gamma = math.atan2(B, A)
    phi1 = gamma - r1
    phi2 = gamma + math.pi + r1
    phi1, phi2 = wrap_angle(phi1), wrap_angle(phi2)
    return (phi1 if abs(phi1) <= abs(phi2) else phi2), clipped


@njit(cache=True, error_model="numpy")
def theta_from_eq5(ux, phi, psi, a):
    """Eq (16): the pitch that gives x'' = ux at roll phi, yaw psi and a = U1/m [m/s^2].

    Examples
    --------
    >>> theta, clipped = theta_from_eq5(0.981, 0.0, 0.0, 9.81)
    >>> round(theta, 6), clipped
    (0.100167, False)
    """
    theta, _, clipped = pitch_eq16(ux, math.sin(phi), math.cos(phi), math.sin(psi), math.cos(psi), a)
    return theta, clipped


@njit(cache=True, error_model="numpy")
def phi_from_eq6(uy, theta, psi, a):
    """Eq (19), sign-preserving: the roll that gives y'' = uy at pitch theta, yaw psi.

    Examples
    --------
    >>> phi, clipped = phi_from_eq6(0.981, 0.0, 0.0, 9.81)     # y'' > 0 needs a negative roll
    >>> round(phi, 6), clipped
    (-0.100167, False)
    """
    return roll_eq19(uy, math.sin(theta), math.sin(psi), math.cos(psi), a)


@njit(cache=True, inline="always", error_model="numpy")
def thrust_for_tilt(uz, cos_tilt, m, g, K, cos_max_tilt):
    """Altitude law: U1 = m (g + u_z) / (cos phi cos theta), limited to [0, 4 K] [N], and its
    flag. ``cos_tilt`` is cos phi cos theta; the compensation uses at most 1/cos(max_tilt) so
    that it cannot blow up.

    Examples
    --------
    >>> U1, flag = thrust_for_tilt(0.0, 1.0, 3.499, 9.81, 120.0, 0.7)
    >>> round(U1, 6), flag
    (34.32519, 0)
    >>> thrust_for_tilt(-20.0, 1.0, 3.499, 9.81, 120.0, 0.7)
    (0.0, 4)
    """
    c = max(cos_tilt, cos_max_tilt)
    U1, limited = clamp(m * (g + uz) / c, 0.0, 4.0 * K)
    return U1, FLAG_THRUST_LIMIT if limited else 0


@njit(cache=True, inline="always", error_model="numpy")
def tilt_setpoint(angle, clipped, max_tilt, flags):
    """Limit a roll/pitch setpoint to max_tilt and add the flags that apply.

    Examples
    --------
    >>> tilt_setpoint(1.0, False, 0.5, 0)
    (0.5, 1)
    >>> tilt_setpoint(-0.2, True, 0.5, 0)
    (-0.2, 2)
    """
    if clipped:
        flags |= FLAG_ASIN_CLIP
    angle, limited = clamp(angle, -max_tilt, max_tilt)
    if limited:
        flags |= FLAG_TILT_LIMIT
    return angle, flags
