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


@njit(cache=True, inline="always")
def qmul4(aw, ax, ay, az, bw, bx, by, bz):
    """The Hamilton product of two w-first quaternions given as scalars: four scalars.

    Examples
    --------
    >>> qmul4(1.0, 0.0, 0.0, 0.0, 0.0, 1.0, 0.0, 0.0)
    (0.0, 1.0, 0.0, 0.0)
    """
    return (
        aw * bw - ax * bx - ay * by - az * bz,
        aw * bx + ax * bw + ay * bz - az * by,
        aw * by - ax * bz + ay * bw + az * bx,
        aw * bz + ax * by - ay * bx + az * bw,
    )


@njit(cache=True, inline="always")
def qexp4(rx, ry, rz):
    """:func:`quat_exp` as four scalars.

    Examples
    --------
    >>> qexp4(0.0, 0.0, 0.0)
    (1.0, 0.0, 0.0, 0.0)
    """
    a = math.sqrt(rx * rx + ry * ry + rz * rz)
    if a < 1e-12:
        c = 1.0 / math.sqrt(1.0 + 0.25 * a * a)
        return c, 0.5 * rx * c, 0.5 * ry * c, 0.5 * rz * c
    s = math.sin(0.5 * a) / a
    return math.cos(0.5 * a), rx * s, ry * s, rz * s


@njit(cache=True, inline="always")
def rot9(w, x, y, z):
    """:func:`rotation` as nine scalars, row by row.

    Examples
    --------
    >>> rot9(1.0, 0.0, 0.0, 0.0)[:3]
    (1.0, 0.0, 0.0)
    """
    return (
        1 - 2 * (y * y + z * z), 2 * (x * y - w * z), 2 * (x * z + w * y),
        2 * (x * y + w * z), 1 - 2 * (x * x + z * z), 2 * (y * z - w * x),
        2 * (x * z - w * y), 2 * (y * z + w * x), 1 - 2 * (x * x + y * y),
    )  # fmt: skip


@njit(cache=True)
def predict(x, P, gx, gy, gz, ax, ay, az, dt, noise, gravity):
    """Propagate the state ``x`` (16,) and covariance ``P`` (15, 15) in place over ``dt`` [s]
    with one IMU reading (rates [rad/s], specific force [m/s^2], FLU).

    ``P <- F P F^T + Q`` is computed by blocks (F is the identity but for the blocks of the
    module's transition), in place and without allocating: the filter runs in the engine's
    period, where a dense 15 x 15 product cost more than the vehicle's own flight.

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
    qw, qx, qy, qz = x[XQ], x[XQ + 1], x[XQ + 2], x[XQ + 3]
    r00, r01, r02, r10, r11, r12, r20, r21, r22 = rot9(qw, qx, qy, qz)
    hw, hx, hy, hz = qexp4(0.5 * wx * dt, 0.5 * wy * dt, 0.5 * wz * dt)
    mw, mx, my, mz = qmul4(qw, qx, qy, qz, hw, hx, hy, hz)
    m00, m01, m02, m10, m11, m12, m20, m21, m22 = rot9(mw, mx, my, mz)
    a0 = m00 * fx + m01 * fy + m02 * fz
    a1 = m10 * fx + m11 * fy + m12 * fz
    a2 = m20 * fx + m21 * fy + m22 * fz - gravity
    x[XP] += x[XV] * dt + 0.5 * a0 * dt * dt
    x[XP + 1] += x[XV + 1] * dt + 0.5 * a1 * dt * dt
    x[XP + 2] += x[XV + 2] * dt + 0.5 * a2 * dt * dt
    x[XV] += a0 * dt
    x[XV + 1] += a1 * dt
    x[XV + 2] += a2 * dt
    ew, ex, ey, ez = qexp4(wx * dt, wy * dt, wz * dt)
    nw, nx, ny, nz = qmul4(qw, qx, qy, qz, ew, ex, ey, ez)
    c = 1.0 / math.sqrt(nw * nw + nx * nx + ny * ny + nz * nz)
    x[XQ], x[XQ + 1], x[XQ + 2], x[XQ + 3] = nw * c, nx * c, ny * c, nz * c
    # A = -R [f]x dt, B = -R dt, C = Exp(w dt)^T: the blocks of F
    blocks = np.empty((3, 3, 3))
    A, B, C = blocks[0], blocks[1], blocks[2]
    for i in range(3):
        if i == 0:
            ri0, ri1, ri2 = r00, r01, r02
        elif i == 1:
            ri0, ri1, ri2 = r10, r11, r12
        else:
            ri0, ri1, ri2 = r20, r21, r22
        A[i, 0] = -(ri1 * fz - ri2 * fy) * dt
        A[i, 1] = -(ri2 * fx - ri0 * fz) * dt
        A[i, 2] = -(ri0 * fy - ri1 * fx) * dt
        B[i, 0], B[i, 1], B[i, 2] = -ri0 * dt, -ri1 * dt, -ri2 * dt
    e00, e01, e02, e10, e11, e12, e20, e21, e22 = rot9(ew, ex, ey, ez)
    C[0, 0], C[0, 1], C[0, 2] = e00, e10, e20
    C[1, 0], C[1, 1], C[1, 2] = e01, e11, e21
    C[2, 0], C[2, 1], C[2, 2] = e02, e12, e22
    for j in range(E_SIZE):  # P <- F P, column by column
        t0, t1, t2 = P[ETH, j], P[ETH + 1, j], P[ETH + 2, j]
        b0, b1, b2 = P[EBA, j], P[EBA + 1, j], P[EBA + 2, j]
        for i in range(3):
            v = P[EV + i, j]
            P[EP + i, j] += dt * v
            P[EV + i, j] = v + A[i, 0] * t0 + A[i, 1] * t1 + A[i, 2] * t2 + B[i, 0] * b0 + B[i, 1] * b1 + B[i, 2] * b2
        for i in range(3):
            P[ETH + i, j] = C[i, 0] * t0 + C[i, 1] * t1 + C[i, 2] * t2 - dt * P[EBG + i, j]
    for j in range(EBG):  # then P <- P F^T, row by row (the bias rows below: by symmetry)
        t0, t1, t2 = P[j, ETH], P[j, ETH + 1], P[j, ETH + 2]
        b0, b1, b2 = P[j, EBA], P[j, EBA + 1], P[j, EBA + 2]
        for i in range(3):
            v = P[j, EV + i]
            P[j, EP + i] += dt * v
            P[j, EV + i] = v + A[i, 0] * t0 + A[i, 1] * t1 + A[i, 2] * t2 + B[i, 0] * b0 + B[i, 1] * b1 + B[i, 2] * b2
        for i in range(3):
            P[j, ETH + i] = C[i, 0] * t0 + C[i, 1] * t1 + C[i, 2] * t2 - dt * P[j, EBG + i]
    for j in range(EBG, E_SIZE):  # F leaves the bias columns as they are: (F P F^T)[b, :9] = (F P)[:9, b]^T
        for c in range(EBG):
            P[j, c] = P[c, j]
    for i in range(3):
        P[EV + i, EV + i] += noise[1] ** 2 * dt
        P[ETH + i, ETH + i] += noise[0] ** 2 * dt
        P[EBG + i, EBG + i] += noise[2] ** 2 * dt
        P[EBA + i, EBA + i] += noise[3] ** 2 * dt


@njit(cache=True)
def inject(x, P, dx):
    """Add the error estimate ``dx`` (15,) to the nominal state and reset the error to 0
    (the covariance through the reset's Jacobian ``G = I - [dtheta / 2]x``, which touches only
    the attitude's rows and columns).

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
    ew, ex, ey, ez = qexp4(dx[ETH], dx[ETH + 1], dx[ETH + 2])
    nw, nx, ny, nz = qmul4(x[XQ], x[XQ + 1], x[XQ + 2], x[XQ + 3], ew, ex, ey, ez)
    c = 1.0 / math.sqrt(nw * nw + nx * nx + ny * ny + nz * nz)
    x[XQ], x[XQ + 1], x[XQ + 2], x[XQ + 3] = nw * c, nx * c, ny * c, nz * c
    h0, h1, h2 = 0.5 * dx[ETH], 0.5 * dx[ETH + 1], 0.5 * dx[ETH + 2]
    for j in range(E_SIZE):  # G P: (I - [h]x) on the attitude rows
        t0, t1, t2 = P[ETH, j], P[ETH + 1, j], P[ETH + 2, j]
        P[ETH, j] = t0 + h2 * t1 - h1 * t2
        P[ETH + 1, j] = t1 - h2 * t0 + h0 * t2
        P[ETH + 2, j] = t2 + h1 * t0 - h0 * t1
    for j in range(E_SIZE):  # then (G P) G^T on the attitude columns
        t0, t1, t2 = P[j, ETH], P[j, ETH + 1], P[j, ETH + 2]
        P[j, ETH] = t0 + h2 * t1 - h1 * t2
        P[j, ETH + 1] = t1 - h2 * t0 + h0 * t2
        P[j, ETH + 2] = t2 + h1 * t0 - h0 * t1


@njit(cache=True)
def inverse_small(S, out):
    """The inverse of a 1 x 1 or 3 x 3 matrix in closed form (cofactors) into ``out``, else
    numpy's.

    Examples
    --------
    >>> import numpy as np
    >>> inverse_small(np.diag([2.0, 4.0, 5.0]), np.empty((3, 3))).diagonal().tolist()
    [0.5, 0.25, 0.2]
    """
    m = S.shape[0]
    if m == 1:
        out[0, 0] = 1.0 / S[0, 0]
        return out
    if m != 3:
        out[:, :] = np.linalg.inv(S)
        return out
    a, b, c, d, e, f, g, h, i = S[0, 0], S[0, 1], S[0, 2], S[1, 0], S[1, 1], S[1, 2], S[2, 0], S[2, 1], S[2, 2]
    c00, c01, c02 = e * i - f * h, c * h - b * i, b * f - c * e
    c10, c11, c12 = f * g - d * i, a * i - c * g, c * d - a * f
    c20, c21, c22 = d * h - e * g, b * g - a * h, a * e - b * d
    det = a * c00 + b * c10 + c * c20
    out[0, 0], out[0, 1], out[0, 2] = c00 / det, c01 / det, c02 / det
    out[1, 0], out[1, 1], out[1, 2] = c10 / det, c11 / det, c12 / det
    out[2, 0], out[2, 1], out[2, 2] = c20 / det, c21 / det, c22 / det
    return out


WORK_ROWS = 9
"""Rows of :func:`update`'s scratch (``(WORK_ROWS, 15)``): P H^T (3), the error's estimate, P h,
the gain, S and its inverse (row-major)."""


@njit(cache=True)
def update(x, P, H, r, var, gate, work):
    """One Kalman update with the innovation ``r`` (m,), its Jacobian ``H`` (m, 15) and the
    measurement's variances ``var`` (m,); refused when the NIS passes ``gate``.

    The gate and the NIS are the whole measurement's (``S = H P H^T + R``); an accepted one is
    fused a row at a time (R diagonal: the same as all at once), each in the Joseph form
    ``(I - k h) P (I - k h)^T + k r k^T`` expanded as ``P - k (P h)^T - (P h) k^T + s k k^T``, so
    that it costs O(15^2 m) and no dense 15 x 15 product; the error's estimate is injected once.

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
    work : numpy.ndarray
        (WORK_ROWS, 15) scratch (the filter runs in the engine's period: no allocation).

    Returns
    -------
    float
        The NIS ``r^T S^-1 r``; negative when refused (its magnitude is the NIS).
    """
    m = r.shape[0]
    for a in range(m):  # P H^T, row a of work: P h_a
        for i in range(E_SIZE):
            acc = 0.0
            for j in range(E_SIZE):
                if H[a, j] != 0.0:
                    acc += P[i, j] * H[a, j]
            work[a, i] = acc
    S = work[7, : m * m].reshape((m, m))
    Si = work[8, : m * m].reshape((m, m))
    for a in range(m):
        for b in range(m):
            acc = 0.0
            for j in range(E_SIZE):
                if H[a, j] != 0.0:
                    acc += H[a, j] * work[b, j]
            S[a, b] = acc
        S[a, a] += var[a]
    inverse_small(S, Si)
    nis = 0.0
    for a in range(m):
        for b in range(m):
            nis += r[a] * Si[a, b] * r[b]
    if nis > gate:
        return -nis
    # accepted: the m rows one after another (R diagonal: the same update as all at once)
    dx, ph, k = work[3], work[4], work[5]
    for i in range(E_SIZE):
        dx[i] = 0.0
        ph[i] = work[0, i]
    for a in range(m):
        if a > 0:
            for i in range(E_SIZE):
                acc = 0.0
                for j in range(E_SIZE):
                    if H[a, j] != 0.0:
                        acc += P[i, j] * H[a, j]
                ph[i] = acc
        s = var[a]
        innov = r[a]
        for j in range(E_SIZE):
            if H[a, j] != 0.0:
                s += H[a, j] * ph[j]
                innov -= H[a, j] * dx[j]
        for i in range(E_SIZE):
            k[i] = ph[i] / s
            dx[i] += k[i] * innov
        for i in range(E_SIZE):  # Joseph: P - k ph^T - ph k^T + s k k^T
            for j in range(i, E_SIZE):
                v = P[i, j] + s * k[i] * k[j] - k[i] * ph[j] - ph[i] * k[j]
                P[i, j] = v
                P[j, i] = v
    inject(x, P, dx)
    return nis


@njit(cache=True)
def update_states(x, P, first, r, var, gate, work):
    """:func:`update` for a measurement of ``m`` consecutive error states from ``first`` (the GPS's
    position or velocity, the barometer's altitude: ``H`` unit rows), without forming ``H``: the
    same gate, NIS and row-by-row Joseph update, at a fraction of the cost.

    Parameters
    ----------
    x, P : numpy.ndarray
        Nominal state (16,) and covariance (15, 15), updated when accepted.
    first : int
        The first error state measured.
    r, var : numpy.ndarray
        (m,) innovation and measurement variances.
    gate : float
        Largest NIS accepted.
    work : numpy.ndarray
        (WORK_ROWS, 15) scratch.

    Returns
    -------
    float
        The NIS; negative when refused.

    Examples
    --------
    >>> import numpy as np
    >>> x, P = np.r_[np.zeros(6), 1.0, np.zeros(9)], np.eye(15)
    >>> nis = update_states(x, P, 2, np.array([1.0]), np.array([1.0]), np.inf, np.empty((WORK_ROWS, 15)))
    >>> nis, float(x[2]), float(P[2, 2])                  # half-way, half the variance
    (0.5, 0.5, 0.5)
    """
    m = r.shape[0]
    S = work[7, : m * m].reshape((m, m))
    Si = work[8, : m * m].reshape((m, m))
    for a in range(m):
        for b in range(m):
            S[a, b] = P[first + a, first + b]
        S[a, a] += var[a]
    inverse_small(S, Si)
    nis = 0.0
    for a in range(m):
        for b in range(m):
            nis += r[a] * Si[a, b] * r[b]
    if nis > gate:
        return -nis
    dx, ph, k = work[3], work[4], work[5]
    for i in range(E_SIZE):
        dx[i] = 0.0
    for a in range(m):
        c = first + a
        s = P[c, c] + var[a]
        innov = r[a] - dx[c]
        for i in range(E_SIZE):
            ph[i] = P[i, c]
            k[i] = ph[i] / s
            dx[i] += k[i] * innov
        for i in range(E_SIZE):  # Joseph: P - k ph^T - ph k^T + s k k^T
            ki, pi = k[i], ph[i]
            for j in range(i, E_SIZE):
                v = P[i, j] + s * ki * k[j] - ki * ph[j] - pi * k[j]
                P[i, j] = v
                P[j, i] = v
    inject(x, P, dx)
    return nis


@njit(cache=True)
def heading_innovation(x, mx, my, mz, field, H):
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
    H : numpy.ndarray
        (1, 15) output: the Jacobian.

    Returns
    -------
    float
        The innovation [rad].
    """
    r00, r01, r02, r10, r11, r12, r20, r21, r22 = rot9(x[XQ], x[XQ + 1], x[XQ + 2], x[XQ + 3])
    me = r00 * mx + r01 * my + r02 * mz
    mn = r10 * mx + r11 * my + r12 * mz
    r = math.atan2(me, mn) - math.atan2(field[0], field[1])
    r = (r + math.pi) % (2.0 * math.pi) - math.pi
    h2 = field[0] ** 2 + field[1] ** 2
    h0, h1 = -field[2] * field[0] / h2, -field[2] * field[1] / h2  # (h0, h1, 1) R: the body frame's
    for j in range(E_SIZE):
        H[0, j] = 0.0
    H[0, ETH] = h0 * r00 + h1 * r10 + r20
    H[0, ETH + 1] = h0 * r01 + h1 * r11 + r21
    H[0, ETH + 2] = h0 * r02 + h1 * r12 + r22
    return r
