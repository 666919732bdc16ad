"""Rotations for the geometric (SE(3)) and the PX4-style cascade controllers.

The model's attitude (eqs 5-7) is the ZYX Euler rotation R = Rz(psi) Ry(theta) Rx(phi),
body to earth coordinates, z up; its third column b3 = R e3 is the thrust direction,

    b3 = (sin phi sin psi + cos phi sin theta cos psi,
          -sin phi cos psi + cos phi sin theta sin psi,  cos phi cos theta),

exactly the factors of U1/m in eqs (5)-(7). Roll torque l U2 acts about body x, pitch l U3
about body y and yaw U4 about body z (eq 11), so (p, q, r) is the body angular velocity.

Compiled scalar code (the scalar-only rule of :mod:`quadcruise.sim.fastmath`). A matrix is a
tuple of its three rows, each a tuple of three floats (``R[i][j]``): a value, not an array, so
the controllers allocate nothing per control period. Also here: :func:`command_from_rotation`, the
shared tail of these controllers (duties, logged inputs and setpoints). Limits use
:func:`quadcruise.numeric.clamp`.

>>> import numpy as np
>>> R = rotation_zyx(0.1, -0.2, 0.3)
>>> M = np.array(R)
>>> bool(np.allclose(M.T @ M, np.eye(3))), [round(float(a), 12) for a in euler_zyx(R)]
(True, [0.1, -0.2, 0.3])
"""

from __future__ import annotations

import math

from numba import njit

from quadcruise.control.base import write_command
from quadcruise.numeric import clamp


@njit(cache=True, error_model="numpy")
def rotation_zyx(phi, theta, psi):
    """Rz(psi) Ry(theta) Rx(phi): the body-to-earth rotation of the paper's angles.

    Examples
    --------
    >>> import math
    >>> R = rotation_zyx(0.0, 0.0, math.pi / 2)
    >>> [round(R[i][0], 12) + 0.0 for i in range(3)]       # yaw 90 deg: body x along earth y
    [0.0, 1.0, 0.0]
    """
    sf, cf = math.sin(phi), math.cos(phi)
    st, ct = math.sin(theta), math.cos(theta)
    sp, cp = math.sin(psi), math.cos(psi)
    return (
        (cp * ct, cp * st * sf - sp * cf, cp * st * cf + sp * sf),
        (sp * ct, sp * st * sf + cp * cf, sp * st * cf - cp * sf),
        (-st, ct * sf, ct * cf),
    )


@njit(cache=True, error_model="numpy")
def euler_zyx(Rm):
    """(phi, theta, psi) of a rotation R = Rz(psi) Ry(theta) Rx(phi), |theta| <= pi/2.

    Examples
    --------
    >>> [round(a, 12) for a in euler_zyx(rotation_zyx(0.1, -0.2, 0.3))]
    [0.1, -0.2, 0.3]
    """
    s, _ = clamp(-Rm[2][0], -1.0, 1.0)
    return math.atan2(Rm[2][1], Rm[2][2]), math.asin(s), math.atan2(Rm[1][0], Rm[0][0])


@njit(cache=True, error_model="numpy")
def limit_tilt(hx, hy, vz, max_tilt):
    """Scale the horizontal part (hx, hy) of a vector with vertical part vz so that the
    vector is at most ``max_tilt`` from the vertical; returns (hx, hy, limited).

    Examples
    --------
    >>> import math
    >>> limit_tilt(3.0, 4.0, 10.0, 0.5)                    # 26.6 deg from the vertical: kept
    (3.0, 4.0, False)
    >>> hx, hy, limited = limit_tilt(6.0, 8.0, 5.0, math.radians(45.0))
    >>> round(hx, 6), round(hy, 6), limited
    (3.0, 4.0, True)
    >>> limit_tilt(3.0, 4.0, -1.0, 0.5)
    (0.0, 0.0, True)
    """
    if vz <= 0.0:
        return 0.0, 0.0, True
    h = math.hypot(hx, hy)
    hmax = vz * math.tan(max_tilt)
    if h > hmax:
        k = hmax / h
        return hx * k, hy * k, True
    return hx, hy, False


@njit(cache=True, error_model="numpy")
def attitude_lee(b3x, b3y, b3z, psi):
    """Desired rotation of Lee et al. (2010): b3 given (unit), b1 the projection of the
    heading c1 = (cos psi, sin psi, 0) on the plane normal to b3: b2 = b3 x c1 / |b3 x c1|,
    b1 = b2 x b3. Needs b3 away from the horizontal heading (true for any tilt < 90 deg).

    Examples
    --------
    >>> [round(a, 12) + 0.0 for a in euler_zyx(attitude_lee(0.0, 0.0, 1.0, 0.3))]
    [0.0, 0.0, 0.3]
    """
    cx, cy = math.cos(psi), math.sin(psi)
    b2x, b2y, b2z = -b3z * cy, b3z * cx, b3x * cy - b3y * cx  # b3 x c1, c1z = 0
    n = math.sqrt(b2x * b2x + b2y * b2y + b2z * b2z)
    b2x, b2y, b2z = b2x / n, b2y / n, b2z / n
    return _columns(b2y * b3z - b2z * b3y, b2z * b3x - b2x * b3z, b2x * b3y - b2y * b3x, b2x, b2y, b2z, b3x, b3y, b3z)


@njit(cache=True, error_model="numpy")
def attitude_px4(b3x, b3y, b3z, psi):
    """Desired rotation as PX4's ``bodyzToAttitude``: b3 given (unit), b1 normal to the
    yaw frame's y axis c2 = (-sin psi, cos psi, 0): b1 = c2 x b3 / |c2 x b3|, b2 = b3 x b1.
    Its ZYX yaw is exactly psi (b1 stays in the vertical plane of the heading).

    Examples
    --------
    >>> import math
    >>> b3 = (math.sin(0.2), 0.0, math.cos(0.2))             # tilted 0.2 rad towards +x
    >>> [round(a, 12) + 0.0 for a in euler_zyx(attitude_px4(*b3, 0.5))][2]
    0.5
    """
    cx, cy = -math.sin(psi), math.cos(psi)
    b1x, b1y, b1z = cy * b3z, -cx * b3z, cx * b3y - cy * b3x  # c2 x b3, c2z = 0
    n = math.sqrt(b1x * b1x + b1y * b1y + b1z * b1z)
    b1x, b1y, b1z = b1x / n, b1y / n, b1z / n
    return _columns(b1x, b1y, b1z, b3y * b1z - b3z * b1y, b3z * b1x - b3x * b1z, b3x * b1y - b3y * b1x, b3x, b3y, b3z)


@njit(cache=True, inline="always")
def _columns(ax, ay, az, bx, by, bz, cx, cy, cz):
    """The matrix whose columns are a, b and c."""
    return (ax, bx, cx), (ay, by, cy), (az, bz, cz)


@njit(cache=True, inline="always")
def _tn(A, B, i, j):
    """(A^T B)[i, j]."""
    return A[0][i] * B[0][j] + A[1][i] * B[1][j] + A[2][i] * B[2][j]


@njit(cache=True, error_model="numpy")
def error_lee(Rm, Rd):
    """Lee's attitude error e_R = vee(Rd^T R - R^T Rd) / 2 (body frame): sin(angle) times
    the axis of the rotation from the desired to the current attitude.

    Examples
    --------
    >>> e = error_lee(rotation_zyx(0.1, 0.0, 0.0), rotation_zyx(0.0, 0.0, 0.0))
    >>> [round(v, 6) + 0.0 for v in e]                      # sin 0.1 about body x
    [0.099833, 0.0, 0.0]
    """
    return (
        0.5 * (_tn(Rd, Rm, 2, 1) - _tn(Rd, Rm, 1, 2)),
        0.5 * (_tn(Rd, Rm, 0, 2) - _tn(Rd, Rm, 2, 0)),
        0.5 * (_tn(Rd, Rm, 1, 0) - _tn(Rd, Rm, 0, 1)),
    )


@njit(cache=True, error_model="numpy")
def error_quaternion(Rm, Rd):
    """PX4's attitude error 2 sign(w) (x, y, z) of the quaternion of R^T Rd (body frame):
    2 sin(angle / 2) times the axis of the rotation from the current to the desired
    attitude, angle in [0, pi]. The quaternion is taken by Shepperd's method.

    Examples
    --------
    >>> e = error_quaternion(rotation_zyx(0.1, 0.0, 0.0), rotation_zyx(0.0, 0.0, 0.0))
    >>> [round(v, 6) + 0.0 for v in e]                      # 2 sin(-0.05) about body x
    [-0.099958, 0.0, 0.0]
    """
    m00, m11, m22 = _tn(Rm, Rd, 0, 0), _tn(Rm, Rd, 1, 1), _tn(Rm, Rd, 2, 2)
    d21, d02, d10 = (
        _tn(Rm, Rd, 2, 1) - _tn(Rm, Rd, 1, 2),
        _tn(Rm, Rd, 0, 2) - _tn(Rm, Rd, 2, 0),
        _tn(Rm, Rd, 1, 0) - _tn(Rm, Rd, 0, 1),
    )
    s01, s02, s12 = (
        _tn(Rm, Rd, 0, 1) + _tn(Rm, Rd, 1, 0),
        _tn(Rm, Rd, 0, 2) + _tn(Rm, Rd, 2, 0),
        _tn(Rm, Rd, 1, 2) + _tn(Rm, Rd, 2, 1),
    )
    tr = m00 + m11 + m22
    if tr > 0.0:
        S = 2.0 * math.sqrt(tr + 1.0)
        w, x, y, z = 0.25 * S, d21 / S, d02 / S, d10 / S
    elif m00 >= m11 and m00 >= m22:
        S = 2.0 * math.sqrt(1.0 + m00 - m11 - m22)
        w, x, y, z = d21 / S, 0.25 * S, s01 / S, s02 / S
    elif m11 >= m22:
        S = 2.0 * math.sqrt(1.0 + m11 - m00 - m22)
        w, x, y, z = d02 / S, s01 / S, 0.25 * S, s12 / S
    else:
        S = 2.0 * math.sqrt(1.0 + m22 - m00 - m11)
        w, x, y, z = d10 / S, s02 / S, s12 / S, 0.25 * S
    k = 2.0 if w >= 0.0 else -2.0
    return k * x, k * y, k * z


@njit(cache=True, inline="always", error_model="numpy")
def command_from_rotation(U1, U2, U3, U4, Rd, flags, d, K, cmd):
    """Write the command (:func:`~quadcruise.control.base.write_command`) with the ZYX angles
    of the desired rotation Rd as the attitude setpoints (phi_d, theta_d, psi_d).

    Examples
    --------
    >>> import numpy as np
    >>> cmd = np.zeros(12)
    >>> command_from_rotation(10.0, 0.0, 0.0, 0.0, rotation_zyx(0.1, 0.2, 0.3), 0, 0.5, 4.0, cmd)
    >>> [round(float(v), 12) for v in cmd[8:11]]            # phi_d, theta_d, psi_d
    [0.1, 0.2, 0.3]
    """
    phi_d, theta_d, psi_d = euler_zyx(Rd)
    write_command(cmd, U1, U2, U3, U4, phi_d, theta_d, psi_d, flags, d, K)
