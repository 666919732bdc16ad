"""An error-state extended Kalman filter for one vehicle: its prediction from the IMU and its
updates, compiled.

Frames: ENU world, FLU body, as the engine's (docs/architecture.md); gravity ``(0, 0, -g)``.
The nominal state ``x`` (16,) is position p [m], velocity v [m/s], attitude q (w first, body to
world), gyro bias b_g [rad/s] and accelerometer bias b_a [m/s^2]; the error state (15,) is
``(dp, dv, dtheta, db_g, db_a)`` with the attitude error a body-frame rotation vector,
``R_true = R Exp(dtheta)`` (Sola, "Quaternion kinematics for the error-state Kalman filter",
2017, sections 5 and 7). With the IMU's rate ``w_m`` and specific force ``a_m``:

    w = w_m - b_g,  a = a_m - b_a,  q+ = q (x) Exp(w dt),  v+ = v + (R_mid a + g) dt,
    p+ = p + v dt + (R_mid a + g) dt^2 / 2,     R_mid = R Exp(w dt / 2)

and the error's transition ``I + F dt`` with ``dv' = -R [a]x dtheta - R db_a``,
``dtheta' = -[w]x dtheta - db_g``; process noise from the densities (velocity ``n_a^2 dt``,
angle ``n_g^2 dt``, biases ``r^2 dt``). Updates use the Joseph form and are refused when the
normalised innovation squared (NIS) passes the chi-square gate.
"""

from __future__ import annotations

import math

import numpy as np
from numba import njit

# nominal state offsets
XP, XV, XQ, XBG, XBA, X_SIZE = 0, 3, 6, 10, 13, 16
# error state offsets
EP, EV, ETH, EBG, EBA, E_SIZE = 0, 3, 6, 9, 12, 15


@njit(cache=True)
def quat_mul(a, b):
    """The Hamilton product ``a (x) b`` of two w-first quaternions (4,).

    Examples
    --------
    >>> import numpy as np
    >>> quat_mul(np.array([1.0, 0, 0, 0]), np.array([0.0, 1, 0, 0])).tolist()
    [0.0, 1.0, 0.0, 0.0]
    """
    out = np.empty(4)
    out[0] = a[0] * b[0] - a[1] * b[1] - a[2] * b[2] - a[3] * b[3]
    out[1] = a[0] * b[1] + a[1] * b[0] + a[2] * b[3] - a[3] * b[2]
    out[2] = a[0] * b[2] - a[1] * b[3] + a[2] * b[0] + a[3] * b[1]
    out[3] = a[0] * b[3] + a[1] * b[2] - a[2] * b[1] + a[3] * b[0]
    return out


@njit(cache=True)
def quat_exp(rx, ry, rz):
    """The unit quaternion of the rotation vector (rx, ry, rz) [rad].

    Examples
    --------
    >>> import math
    >>> [round(float(c), 6) for c in quat_exp(0.0, 0.0, math.pi)]
    [0.0, 0.0, 0.0, 1.0]
    """
    out = np.empty(4)
    a = math.sqrt(rx * rx + ry * ry + rz * rz)
    if a < 1e-12:
        out[0], out[1], out[2], out[3] = 1.0, 0.5 * rx, 0.5 * ry, 0.5 * rz
        return out / math.sqrt(1.0 + 0.25 * a * a)
    s = math.sin(0.5 * a) / a
    out[0], out[1], out[2], out[3] = math.cos(0.5 * a), rx * s, ry * s, rz * s
    return out


@njit(cache=True)
def quat_log(q):
    """The rotation vector [rad] of a unit quaternion (w first), in (-pi, pi].

    Examples
    --------
    >>> import numpy as np
    >>> [round(float(c), 6) for c in quat_log(quat_exp(0.1, -0.2, 0.3))]
    [0.1, -0.2, 0.3]
    """
    w = q[0]
    v = q[1:4].copy()
    if w < 0.0:
        w, v = -w, -v
    n = math.sqrt(v[0] * v[0] + v[1] * v[1] + v[2] * v[2])
    if n < 1e-12:
        return 2.0 * v
    return v * (2.0 * math.atan2(n, w) / n)


@njit(cache=True)
def rotation(q):
    """The rotation matrix (3, 3) of a w-first unit quaternion (body to world).

    Examples
    --------
    >>> import numpy as np
    >>> rotation(np.array([1.0, 0, 0, 0])).tolist()[0]
    [1.0, 0.0, 0.0]
    """
    w, x, y, z = q[0], q[1], q[2], q[3]
    r = np.empty((3, 3))
    r[0, 0], r[0, 1], r[0, 2] = 1 - 2 * (y * y + z * z), 2 * (x * y - w * z), 2 * (x * z + w * y)
    r[1, 0], r[1, 1], r[1, 2] = 2 * (x * y + w * z), 1 - 2 * (x * x + z * z), 2 * (y * z - w * x)
    r[2, 0], r[2, 1], r[2, 2] = 2 * (x * z - w * y), 2 * (y * z + w * x), 1 - 2 * (x * x + y * y)
    return r


@njit(cache=True)
def skew(a, b, c):
    """The cross-product matrix ``[v]x`` of v = (a, b, c).

    Examples
    --------
    >>> skew(1.0, 2.0, 3.0).tolist()[0]
    [0.0, -3.0, 2.0]
    """
    m = np.zeros((3, 3))
    m[0, 1], m[0, 2], m[1, 0], m[1, 2], m[2, 0], m[2, 1] = -c, b, c, -a, -b, a
    return m


@njit(cache=True)
def predict(x, P, gx, gy, gz, ax, ay, az, dt, noise, gravity):
    """Propagate the state ``x`` (16,) and covariance ``P`` (15, 15) in place over ``dt`` [s]
    with one IMU reading (rates [rad/s], specific force [m/s^2], FLU).

    Parameters
    ----------
    x, P : numpy.ndarray
        Nominal state and error covariance, updated.
    gx, gy, gz, ax, ay, az : float
        The IMU's reading.
    dt : float
        The period it covers [s].
    noise : numpy.ndarray
        (4,) densities: gyro [rad/s/sqrt(Hz)], accel [m/s^2/sqrt(Hz)], gyro bias walk
        [rad/s^2/sqrt(Hz)], accel bias walk [m/s^3/sqrt(Hz)].
    gravity : float
        g [m/s^2].
    """
    wx, wy, wz = gx - x[XBG], gy - x[XBG + 1], gz - x[XBG + 2]
    fx, fy, fz = ax - x[XBA], ay - x[XBA + 1], az - x[XBA + 2]
    q = x[XQ : XQ + 4].copy()
    R = rotation(q)
    Rm = rotation(quat_mul(q, quat_exp(0.5 * wx * dt, 0.5 * wy * dt, 0.5 * wz * dt)))
    acc = np.empty(3)
    for i in range(3):
        acc[i] = Rm[i, 0] * fx + Rm[i, 1] * fy + Rm[i, 2] * fz
    acc[2] -= gravity
    for i in range(3):
        x[XP + i] += x[XV + i] * dt + 0.5 * acc[i] * dt * dt
        x[XV + i] += acc[i] * dt
    qn = quat_mul(q, quat_exp(wx * dt, wy * dt, wz * dt))
    x[XQ : XQ + 4] = qn / math.sqrt(qn[0] ** 2 + qn[1] ** 2 + qn[2] ** 2 + qn[3] ** 2)
    F = np.eye(E_SIZE)
    for i in range(3):
        F[EP + i, EV + i] = dt
        F[ETH + i, EBG + i] = -dt
    F[EV : EV + 3, ETH : ETH + 3] = -(R @ skew(fx, fy, fz)) * dt
    F[EV : EV + 3, EBA : EBA + 3] = -R * dt
    F[ETH : ETH + 3, ETH : ETH + 3] = rotation(quat_exp(wx * dt, wy * dt, wz * dt)).T
    P[:, :] = F @ P @ F.T
    for i in range(3):
        P[EV + i, EV + i] += noise[1] ** 2 * dt
        P[ETH + i, ETH + i] += noise[0] ** 2 * dt
        P[EBG + i, EBG + i] += noise[2] ** 2 * dt
        P[EBA + i, EBA + i] += noise[3] ** 2 * dt


@njit(cache=True)
def inject(x, P, dx):
    """Add the error estimate ``dx`` (15,) to the nominal state and reset the error to 0
    (the covariance through the reset's Jacobian ``I - [dtheta / 2]x``).

    Parameters
    ----------
    x, P : numpy.ndarray
        Nominal state (16,) and covariance (15, 15), updated.
    dx : numpy.ndarray
        (15,) the error estimate.
    """
    for i in range(3):
        x[XP + i] += dx[EP + i]
        x[XV + i] += dx[EV + i]
        x[XBG + i] += dx[EBG + i]
        x[XBA + i] += dx[EBA + i]
    qn = quat_mul(x[XQ : XQ + 4].copy(), quat_exp(dx[ETH], dx[ETH + 1], dx[ETH + 2]))
    x[XQ : XQ + 4] = qn / math.sqrt(qn[0] ** 2 + qn[1] ** 2 + qn[2] ** 2 + qn[3] ** 2)
    G = np.eye(E_SIZE)
    G[ETH : ETH + 3, ETH : ETH + 3] -= skew(0.5 * dx[ETH], 0.5 * dx[ETH + 1], 0.5 * dx[ETH + 2])
    P[:, :] = G @ P @ G.T


@njit(cache=True)
def update(x, P, H, r, var, gate):
    """One Kalman update with the innovation ``r`` (m,), its Jacobian ``H`` (m, 15) and the
    measurement's variances ``var`` (m,); refused when the NIS passes ``gate``.

    Parameters
    ----------
    x, P : numpy.ndarray
        Nominal state (16,) and covariance (15, 15), updated when accepted.
    H : numpy.ndarray
        (m, 15) Jacobian of the measurement with respect to the error state.
    r : numpy.ndarray
        (m,) innovation, measured minus predicted.
    var : numpy.ndarray
        (m,) measurement noise variances.
    gate : float
        Largest NIS accepted (a chi-square quantile with m degrees of freedom; inf: all).

    Returns
    -------
    float
        The NIS ``r^T S^-1 r``, ``S = H P H^T + diag(var)``; negative when refused (its
        magnitude is the NIS).
    """
    S = H @ P @ H.T
    for i in range(r.shape[0]):
        S[i, i] += var[i]
    Si = np.linalg.inv(S)
    nis = r @ Si @ r
    if nis > gate:
        return -nis
    K = P @ H.T @ Si
    A = np.eye(E_SIZE) - K @ H
    Rm = np.diag(var)
    P[:, :] = A @ P @ A.T + K @ Rm @ K.T
    P[:, :] = 0.5 * (P + P.T)
    inject(x, P, K @ r)
    return nis


@njit(cache=True)
def heading_innovation(x, mx, my, mz, field):
    """The heading innovation of a magnetometer reading (FLU) and its Jacobian (15,).

    The reading turned into the world by the estimate, ``m = R m_b``, points its horizontal part
    ``atan2(m_E, m_N)`` east of north; the innovation is that minus the field's own
    (``field``: ENU, (3,)), wrapped to (-pi, pi]. To first order in the world-frame error
    ``phi = R dtheta`` it is ``phi_z - B_U (B_E phi_x + B_N phi_y) / H^2`` (H the field's
    horizontal strength), so a tilt error enters as the inclination makes it.

    Parameters
    ----------
    x : numpy.ndarray
        Nominal state (16,).
    mx, my, mz : float
        The reading [G].
    field : numpy.ndarray
        (3,) the world field [G], ENU.

    Returns
    -------
    tuple
        (innovation [rad], H (1, 15)).
    """
    R = rotation(x[XQ : XQ + 4])
    me = R[0, 0] * mx + R[0, 1] * my + R[0, 2] * mz
    mn = R[1, 0] * mx + R[1, 1] * my + R[1, 2] * mz
    r = math.atan2(me, mn) - math.atan2(field[0], field[1])
    r = (r + math.pi) % (2.0 * math.pi) - math.pi
    h2 = field[0] ** 2 + field[1] ** 2
    hphi = np.array([-field[2] * field[0] / h2, -field[2] * field[1] / h2, 1.0])
    H = np.zeros((1, E_SIZE))
    H[0, ETH : ETH + 3] = hphi @ R
    return r, H
