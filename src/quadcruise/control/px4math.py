"""PX4's quaternion arithmetic and ``ControlMath``, compiled, on 3- and 4-tuples of floats.

As PX4's ``matrix`` library and ``src/modules/mc_pos_control/PositionControl/ControlMath.cpp``
(release v1.15) compute them, in PX4's frames (NED world, FRD body). A quaternion is
``(w, x, y, z)``, Hamilton's product, rotating body vectors into the world (``R(q) v_body``).
The tuples keep a compiled caller free of array allocations. quadcruise's own frames (ENU
world, FLU body) are converted at the edge: :func:`enu_to_ned`, :func:`flu_to_frd`,
:func:`quat_enu_flu_to_ned_frd` (the swaps :mod:`quadcruise.sim.px4` writes logs with).
"""

from __future__ import annotations

import math

from numba import njit

__all__ = [
    "qmul",
    "qinv",
    "qnormalize",
    "qcanonical",
    "dcm_z",
    "quat_between",
    "quat_from_dcm",
    "euler_from_dcm",
    "dcm_from_quat",
    "limit_tilt",
    "constrain_xy",
    "body_z_to_attitude",
    "add_if_not_nan",
    "enu_to_ned",
    "flu_to_frd",
    "quat_enu_flu_to_ned_frd",
]

_EPS32 = 1.1920929e-07
"""FLT_EPSILON, PX4's float epsilon."""


@njit(cache=True, inline="always")
def qmul(a, b):
    """Hamilton product ``a * b`` of two quaternions (w, x, y, z)."""
    aw, ax, ay, az = a
    bw, bx, by, bz = b
    return (
        aw * bw - ax * bx - ay * by - az * bz,
        aw * bx + ax * bw + ay * bz - az * by,
        aw * by - ax * bz + ay * bw + az * bx,
        aw * bz + ax * by - ay * bx + az * bw,
    )


@njit(cache=True, inline="always")
def qinv(q):
    """Inverse of a quaternion: its conjugate over its squared norm."""
    n2 = q[0] * q[0] + q[1] * q[1] + q[2] * q[2] + q[3] * q[3]
    return (q[0] / n2, -q[1] / n2, -q[2] / n2, -q[3] / n2)


@njit(cache=True, inline="always")
def qnormalize(q):
    """``q / |q|``."""
    n = math.sqrt(q[0] * q[0] + q[1] * q[1] + q[2] * q[2] + q[3] * q[3])
    return (q[0] / n, q[1] / n, q[2] / n, q[3] / n)


@njit(cache=True)
def qcanonical(q):
    """PX4's ``canonical()``: ``q`` or ``-q``, whichever has its first entry above 1e-6 in size
    positive (the unique one of the two quaternions of a rotation)."""
    for i in range(4):
        if abs(q[i]) > 1e-6:
            if q[i] < 0.0:
                return (-q[0], -q[1], -q[2], -q[3])
            return q
    return q


@njit(cache=True, inline="always")
def dcm_z(q):
    """Third column of ``R(q)``: the body z axis in the world."""
    w, x, y, z = q
    return (2.0 * (w * y + x * z), 2.0 * (y * z - w * x), w * w - x * x - y * y + z * z)


@njit(cache=True, inline="always")
def dcm_from_quat(q):
    """``R(q)`` as three rows of three (PX4's ``Dcm(q)``)."""
    w, x, y, z = q
    ww, xx, yy, zz = w * w, x * x, y * y, z * z
    return (
        (ww + xx - yy - zz, 2.0 * (x * y - w * z), 2.0 * (w * y + x * z)),
        (2.0 * (x * y + w * z), ww - xx + yy - zz, 2.0 * (y * z - w * x)),
        (2.0 * (x * z - w * y), 2.0 * (w * x + y * z), ww - xx - yy + zz),
    )


@njit(cache=True)
def quat_between(src, dst):
    """PX4's ``Quaternion(src, dst)``: the shortest rotation turning ``src`` into ``dst``.

    The half-way solution ``(src . dst + |src||dst|, src x dst)`` normalised; for opposite
    vectors a rotation of pi about the axis least aligned with ``src``.
    """
    cx = src[1] * dst[2] - src[2] * dst[1]
    cy = src[2] * dst[0] - src[0] * dst[2]
    cz = src[0] * dst[1] - src[1] * dst[0]
    dot = src[0] * dst[0] + src[1] * dst[1] + src[2] * dst[2]
    if math.sqrt(cx * cx + cy * cy + cz * cz) < 1e-5 and dot < 0.0:
        ax, ay, az = abs(src[0]), abs(src[1]), abs(src[2])
        if ax < ay:
            e = (1.0, 0.0, 0.0) if ax < az else (0.0, 0.0, 1.0)
        else:
            e = (0.0, 1.0, 0.0) if ay < az else (0.0, 0.0, 1.0)
        w = 0.0
        cx = src[1] * e[2] - src[2] * e[1]
        cy = src[2] * e[0] - src[0] * e[2]
        cz = src[0] * e[1] - src[1] * e[0]
    else:
        n_src = src[0] * src[0] + src[1] * src[1] + src[2] * src[2]
        n_dst = dst[0] * dst[0] + dst[1] * dst[1] + dst[2] * dst[2]
        w = dot + math.sqrt(n_src * n_dst)
    return qnormalize((w, cx, cy, cz))


@njit(cache=True)
def quat_from_dcm(r):
    """PX4's ``Quaternion(Dcm)`` (Shepperd's method, the largest of the four first)."""
    t = r[0][0] + r[1][1] + r[2][2]
    if t > 0.0:
        s = math.sqrt(t + 1.0)
        w = 0.5 * s
        s = 0.5 / s
        return (w, (r[2][1] - r[1][2]) * s, (r[0][2] - r[2][0]) * s, (r[1][0] - r[0][1]) * s)
    if r[0][0] > r[1][1] and r[0][0] > r[2][2]:
        s = math.sqrt(1.0 + r[0][0] - r[1][1] - r[2][2])
        x = 0.5 * s
        s = 0.5 / s
        return ((r[2][1] - r[1][2]) * s, x, (r[1][0] + r[0][1]) * s, (r[0][2] + r[2][0]) * s)
    if r[1][1] > r[2][2]:
        s = math.sqrt(1.0 - r[0][0] + r[1][1] - r[2][2])
        y = 0.5 * s
        s = 0.5 / s
        return ((r[0][2] - r[2][0]) * s, (r[1][0] + r[0][1]) * s, y, (r[2][1] + r[1][2]) * s)
    s = math.sqrt(1.0 - r[0][0] - r[1][1] + r[2][2])
    z = 0.5 * s
    s = 0.5 / s
    return ((r[1][0] - r[0][1]) * s, (r[0][2] + r[2][0]) * s, (r[2][1] + r[1][2]) * s, z)


@njit(cache=True)
def euler_from_dcm(r):
    """PX4's ``Eulerf(Dcm)``: (roll, pitch, yaw) [rad], Tait-Bryan 3-2-1, yaw alone at +-90 deg pitch."""
    theta = math.asin(-r[2][0])
    if abs(theta - 0.5 * math.pi) < 1.0e-3:
        return (0.0, theta, math.atan2(r[1][2], r[0][2]))
    if abs(theta + 0.5 * math.pi) < 1.0e-3:
        return (0.0, theta, math.atan2(-r[1][2], -r[0][2]))
    return (math.atan2(r[2][1], r[2][2]), theta, math.atan2(r[1][0], r[0][0]))


@njit(cache=True)
def limit_tilt(body_unit, world_unit, max_angle):
    """``ControlMath::limitTilt``: ``body_unit`` turned towards ``world_unit`` to at most
    ``max_angle`` [rad] from it (both unit vectors); an exactly opposite one is turned about x."""
    dot = body_unit[0] * world_unit[0] + body_unit[1] * world_unit[1] + body_unit[2] * world_unit[2]
    angle = min(math.acos(max(-1.0, min(1.0, dot))), max_angle)
    rx = body_unit[0] - dot * world_unit[0]
    ry = body_unit[1] - dot * world_unit[1]
    rz = body_unit[2] - dot * world_unit[2]
    if rx * rx + ry * ry + rz * rz < _EPS32:
        rx = 1.0
    n = math.sqrt(rx * rx + ry * ry + rz * rz)
    c, s = math.cos(angle), math.sin(angle)
    return (c * world_unit[0] + s * rx / n, c * world_unit[1] + s * ry / n, c * world_unit[2] + s * rz / n)


@njit(cache=True)
def constrain_xy(v0, v1, vmax):
    """``ControlMath::constrainXY``: ``v0 + v1`` (2-tuples) limited to ``vmax`` in length,
    ``v0`` keeping priority: ``v0 + s v1/|v1|`` with ``s`` the largest that fits."""
    sx, sy = v0[0] + v1[0], v0[1] + v1[1]
    n0 = math.sqrt(v0[0] * v0[0] + v0[1] * v0[1])
    if math.sqrt(sx * sx + sy * sy) <= vmax:
        return (sx, sy)
    if n0 >= vmax:
        return (v0[0] / n0 * vmax, v0[1] / n0 * vmax)
    dx, dy = v1[0] - v0[0], v1[1] - v0[1]
    if abs(math.sqrt(dx * dx + dy * dy)) < 0.001:
        return (v0[0] / n0 * vmax, v0[1] / n0 * vmax)
    n1 = math.sqrt(v1[0] * v1[0] + v1[1] * v1[1])
    if n0 < 0.001:
        return (v1[0] / n1 * vmax, v1[1] / n1 * vmax)
    ux, uy = v1[0] / n1, v1[1] / n1
    m = ux * v0[0] + uy * v0[1]
    c = v0[0] * v0[0] + v0[1] * v0[1] - vmax * vmax
    s = -m + math.sqrt(m * m - c)
    return (v0[0] + ux * s, v0[1] + uy * s)


@njit(cache=True)
def body_z_to_attitude(body_z, yaw_sp):
    """``ControlMath::bodyzToAttitude``: the attitude quaternion whose body z axis is
    ``body_z`` (world frame, any length) and whose x axis points to heading ``yaw_sp`` [rad]."""
    bz0, bz1, bz2 = body_z
    if bz0 * bz0 + bz1 * bz1 + bz2 * bz2 < _EPS32:
        bz2 = 1.0
    n = math.sqrt(bz0 * bz0 + bz1 * bz1 + bz2 * bz2)
    bz0, bz1, bz2 = bz0 / n, bz1 / n, bz2 / n
    yc0, yc1, yc2 = -math.sin(yaw_sp), math.cos(yaw_sp), 0.0
    bx0 = yc1 * bz2 - yc2 * bz1
    bx1 = yc2 * bz0 - yc0 * bz2
    bx2 = yc0 * bz1 - yc1 * bz0
    if bz2 < 0.0:
        bx0, bx1, bx2 = -bx0, -bx1, -bx2
    if abs(bz2) < 0.000001:
        bx0, bx1, bx2 = 0.0, 0.0, 1.0
    n = math.sqrt(bx0 * bx0 + bx1 * bx1 + bx2 * bx2)
    bx0, bx1, bx2 = bx0 / n, bx1 / n, bx2 / n
    by0 = bz1 * bx2 - bz2 * bx1
    by1 = bz2 * bx0 - bz0 * bx2
    by2 = bz0 * bx1 - bz1 * bx0
    r = ((bx0, by0, bz0), (bx1, by1, bz1), (bx2, by2, bz2))
    return quat_from_dcm(r)


@njit(cache=True, inline="always")
def add_if_not_nan(setpoint, addition):
    """``ControlMath::addIfNotNan``: the sum; the addition alone where the setpoint is NaN; the
    setpoint where the addition is NaN."""
    if math.isfinite(setpoint) and math.isfinite(addition):
        return setpoint + addition
    if not math.isfinite(setpoint):
        return addition
    return setpoint


_H = math.sqrt(0.5)


@njit(cache=True, inline="always")
def enu_to_ned(v):
    """A world vector from ENU to NED (its own inverse): ``(y, x, -z)``."""
    return (v[1], v[0], -v[2])


@njit(cache=True, inline="always")
def flu_to_frd(v):
    """A body vector from FLU to FRD (its own inverse): ``(x, -y, -z)``."""
    return (v[0], -v[1], -v[2])


@njit(cache=True, inline="always")
def quat_enu_flu_to_ned_frd(q):
    """An attitude (FLU body to ENU world) as PX4's (FRD body to NED world), its own inverse.

    ``R_ned_frd = A R_enu_flu B`` with ``A`` the ENU/NED swap (a half turn about
    ``(1, 1, 0)/sqrt 2``) and ``B = diag(1, -1, -1)`` (a half turn about x): the quaternion
    ``q_A q q_B``, ``q_A = (0, 1/sqrt 2, 1/sqrt 2, 0)``, ``q_B = (0, 1, 0, 0)``.
    """
    return qmul(qmul((0.0, _H, _H, 0.0), q), (0.0, 1.0, 0.0, 0.0))
