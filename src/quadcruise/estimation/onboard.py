"""The observation stage, compiled into the engine's period: a vehicle's sensors sample the truth,
its EKF predicts and updates, and the controller sees the estimate.

At each control period k (instant t) of one vehicle, :func:`onboard`:

1. samples each sensor whose period has come (``k % every == 0``, :func:`quadcruise.sensors.timing.periods_per_sample`):
   the GPS (a fix queued until it arrives ``latency`` later, none during an outage), the barometer
   and the magnetometer (their readings held until the next IMU instant);
2. at an IMU instant: reads the IMU, the trapezoid average of the body's angular velocity and
   specific force over the IMU period just ended (PX4's ``sensor_combined`` meaning: the average
   over the last sampling period; the kernel takes both from the plant's derivative at each
   period's end: :mod:`quadcruise.sim.observe`), propagates the filter over that period with it
   (:func:`~quadcruise.estimation.ekf.predict`), then fuses the GPS fixes that have arrived, the
   barometer's and the magnetometer's readings (GPS position and velocity, altitude, heading, in
   that order, each gated), so the in-loop filter is :func:`~quadcruise.estimation.run.run_ekf`
   fed the same samples (its reading k, covering ``[t_k, t_k+1]``, is the one read at t_k+1). A
   GPS fix arrives ``latency`` late: it is moved on by the estimate's change since the IMU
   instant at or before it was taken (kept in a short history), so its innovation is taken
   against the estimate of its own time, not against the present one (a cheap form of PX4's
   delayed fusion horizon; ``Ekf(latency_compensation=False)`` fuses it as if it were fresh);
3. writes what the controller sees (:data:`quadcruise.layout.STATE`): the estimate's position,
   velocity and ZYX Euler angles (yaw unwrapped), its body rates the gyro minus the estimated
   bias (through a first-order low-pass of cutoff ``rate_cutoff`` if one is given, as PX4
   filters the rates its rate loop reads, ``IMU_GYRO_CUTOFF``), and F1..F4, the actuator
   state, as the truth (no sensor reads it; PX4 knows its own commands). Between IMU instants
   it is held.

Its memory (:func:`memory_row`) carries the sensors' biases, the filter's state and covariance,
the GPS queue, the estimate's recent history and the log row, so a flight cut into calls is the
flight flown in one; its stream is the vehicle's own
(:func:`~quadcruise.sim.observe.sensor_streams`), apart from the disturbance's. At period 0 it
starts: the sensors switch on (their biases drawn), and the filter starts from the truth plus an
error drawn from its initial covariance (position, velocity, attitude; its bias estimates 0, their
variances the sensors' switch-on spreads), so the NEES is chi-square from the first instant.
"""

from __future__ import annotations

import math

import numpy as np
from numba import njit

from quadcruise import layout as L
from quadcruise.estimation.ekf import (
    E_SIZE,
    EP,
    ETH,
    EV,
    WORK_ROWS,
    X_SIZE,
    XBA,
    XBG,
    XP,
    XQ,
    XV,
    heading_innovation,
    predict,
    qmul4,
    quat_exp,
    quat_mul,
    rot9,
    update,
    update_states,
)
from quadcruise.estimation.run import M_BARO, M_BARO_OFF, M_G, M_HEAD, M_POS_H, M_POS_V, M_SIZE, M_VEL_H, M_VEL_V
from quadcruise.layout import Row
from quadcruise.sensors.baro import BARO_ROW, baro_read
from quadcruise.sensors.gps import GPS_OUTAGE_DURATION, GPS_OUTAGE_START, GPS_ROW, gps_read
from quadcruise.sensors.imu import IMU_ROW, IMU_VIBRATION, imu_read, imu_start
from quadcruise.sensors.imu import STATE_SIZE as IMU_STATE_SIZE
from quadcruise.sensors.mag import MAG_BIAS_STD, MAG_ROW, mag_read
from quadcruise.sensors.noise import noisy
from quadcruise.sim.rng import next_unit

PARAMS = Row.of(
    "onboard parameters",
    *("imu_on", "gps_on", "baro_on", "mag_on", "ekf_on"),
    *("imu_every", "gps_every", "baro_every", "mag_every", "gps_delay", "gps_slots", "history"),
    ("imu", IMU_ROW.size),
    ("gps", GPS_ROW.size),
    ("baro", BARO_ROW.size),
    ("mag", MAG_ROW.size),
    ("field", 3),
    ("noise", 4),
    ("meas", M_SIZE),
    ("gates", 4),
    ("p0", E_SIZE),
    "rate_alpha",
    prefix="OP_",
)
"""A vehicle's stage parameters: which sensors and whether the EKF run (1/0), each sensor's
period in control periods, the GPS latency in periods, its queue's length and the length of the
estimate's history the GPS fixes are fused against (0: latency not compensated), each sensor's
parameter row (:meth:`quadcruise.sensors.model.SensorModel.row`), the world magnetic field (ENU,
[G]), the filter's densities (:meth:`~quadcruise.estimation.run.EkfNoise.noise_row`), measurement
settings (:data:`~quadcruise.estimation.run.MEAS`), gates per degree of freedom, initial standard
deviations of its 15 error states and the rate filter's gain per IMU sample [-]."""
IMU_SIZE, GPS_SIZE, BARO_SIZE, MAG_SIZE = IMU_ROW.size, GPS_ROW.size, BARO_ROW.size, MAG_ROW.size
KERNEL_SIZE = L.OBSERVER_KERNEL.size
(
    OP_IMU_ON, OP_GPS_ON, OP_BARO_ON, OP_MAG_ON, OP_EKF_ON,
    OP_IMU_EVERY, OP_GPS_EVERY, OP_BARO_EVERY, OP_MAG_EVERY, OP_GPS_DELAY, OP_GPS_SLOTS, OP_HISTORY,
    OP_IMU, OP_GPS, OP_BARO, OP_MAG, OP_FIELD, OP_NOISE, OP_MEAS, OP_GATES, OP_P0, OP_RATE_ALPHA,
) = PARAMS.offsets  # fmt: skip

GPS_ENTRY = 8
"""A queued GPS fix: its arrival period, its sample time [s], position [m] and velocity [m/s]."""
HISTORY_ENTRY = 7
"""An entry of the estimate's history: its IMU instant's period, position [m], velocity [m/s]."""


def memory_row(slots: int, history: int = 0) -> Row:
    """The stage's memory with a GPS queue of ``slots`` fixes: the kernel's part
    (:data:`quadcruise.layout.OBSERVER_KERNEL`), then the IMU's state, its last reading, the
    trapezoid sum of the true specific force and rates over its period, the sum of the rotors'
    vibration's period means (:func:`quadcruise.sim.observe.rotor_shake`), its last instant [s],
    the barometer's offset [m], the magnetometer's bias [G], the filter's state (16) and
    covariance (15 x 15, row-major), the rates filter [rad/s], the yaw [rad] last written, the
    truth at the last IMU instant (position, velocity, Euler angles) and whether its errors are
    still to be logged, the pending barometer and magnetometer readings (a flag, then the value),
    the log row, the GPS queue (head, count, then ``slots`` entries of :data:`GPS_ENTRY`) and the
    estimate's history at the last ``history`` IMU instants (:data:`HISTORY_ENTRY` each).

    Parameters
    ----------
    slots : int
        The GPS queue's length.
    history : int
        The history's length.

    Returns
    -------
    Row

    Examples
    --------
    >>> memory_row(2).size - memory_row(1).size
    8
    """
    return Row.of(
        "onboard memory",
        ("imu", IMU_STATE_SIZE),
        ("imu_last", 6),
        ("imu_sum", 6),
        ("shake_sum", 3),
        "t_imu",
        "baro_bias",
        ("mag_bias", 3),
        ("x", X_SIZE),
        ("cov", E_SIZE * E_SIZE),
        ("rates", 3),
        "psi",
        ("truth", 9),
        "errors_due",
        "baro_due",
        "baro",
        "mag_due",
        ("mag", 3),
        ("log", L.OBSERVATION_SIZE),
        "gps_head",
        "gps_count",
        ("gps_queue", GPS_ENTRY * int(slots)),
        *((("history", HISTORY_ENTRY * int(history)),) if history else ()),
        parent=L.OBSERVER_KERNEL,
        prefix="OM_",
    )


(
    OM_IMU, OM_IMU_LAST, OM_IMU_SUM, OM_SHAKE_SUM, OM_T_IMU, OM_BARO_BIAS, OM_MAG_BIAS, OM_X, OM_COV, OM_RATES,
    OM_PSI, OM_TRUTH, OM_ERRORS_DUE, OM_BARO_DUE, OM_BARO, OM_MAG_DUE, OM_MAG, OM_LOG, OM_GPS_HEAD, OM_GPS_COUNT,
    OM_GPS_QUEUE,
) = memory_row(1).offsets  # fmt: skip


@njit(cache=True)
def euler_rotation(phi, theta, psi):
    """R = Rz(psi) Ry(theta) Rx(phi) (body to world) of ZYX Euler angles [rad], (3, 3).

    Examples
    --------
    >>> euler_rotation(0.0, 0.0, 0.0).tolist()[2]
    [-0.0, 0.0, 1.0]
    """
    sa, ca, sb, cb, sc, cc = (
        math.sin(phi),
        math.cos(phi),
        math.sin(theta),
        math.cos(theta),
        math.sin(psi),
        math.cos(psi),
    )
    r = np.empty((3, 3))
    r[0, 0], r[0, 1], r[0, 2] = cc * cb, cc * sb * sa - sc * ca, cc * sb * ca + sc * sa
    r[1, 0], r[1, 1], r[1, 2] = sc * cb, sc * sb * sa + cc * ca, sc * sb * ca - cc * sa
    r[2, 0], r[2, 1], r[2, 2] = -sb, cb * sa, cb * ca
    return r


@njit(cache=True)
def euler_quaternion(phi, theta, psi):
    """The w-first unit quaternion of ZYX Euler angles [rad]: ``qz(psi) qy(theta) qx(phi)``.

    Examples
    --------
    >>> [round(float(c), 6) for c in euler_quaternion(0.0, 0.0, 3.141592653589793)]
    [0.0, 0.0, 0.0, 1.0]
    """
    return quat_mul(quat_mul(quat_exp(0.0, 0.0, psi), quat_exp(0.0, theta, 0.0)), quat_exp(phi, 0.0, 0.0))


@njit(cache=True, inline="always")
def euler_quaternion4(phi, theta, psi):
    """:func:`euler_quaternion` as four scalars."""
    a, b, c = 0.5 * phi, 0.5 * theta, 0.5 * psi
    ca, sa, cb, sb, cc, sc = math.cos(a), math.sin(a), math.cos(b), math.sin(b), math.cos(c), math.sin(c)
    return (
        cc * cb * ca + sc * sb * sa,
        cc * cb * sa - sc * sb * ca,
        cc * sb * ca + sc * cb * sa,
        sc * cb * ca - cc * sb * sa,
    )


@njit(cache=True)
def quadratic_form3(P, a, e0, e1, e2):
    """``e^T B^-1 e`` with B the 3 x 3 block of P at (a, a) [the NEES of one 3-dof part]; NaN
    when B is singular.

    Examples
    --------
    >>> import numpy as np
    >>> float(quadratic_form3(np.eye(15) * 4.0, 0, 2.0, 0.0, 0.0))
    1.0
    """
    b00, b01, b02 = P[a, a], P[a, a + 1], P[a, a + 2]
    b11, b12, b22 = P[a + 1, a + 1], P[a + 1, a + 2], P[a + 2, a + 2]
    c00, c01, c02 = b11 * b22 - b12 * b12, b02 * b12 - b01 * b22, b01 * b12 - b02 * b11
    c11, c12, c22 = b00 * b22 - b02 * b02, b01 * b02 - b00 * b12, b00 * b11 - b01 * b01
    det = b00 * c00 + b01 * c01 + b02 * c02
    if det <= 0.0:
        return np.nan
    q = c00 * e0 * e0 + c11 * e1 * e1 + c22 * e2 * e2 + 2.0 * (c01 * e0 * e1 + c02 * e0 * e2 + c12 * e1 * e2)
    return q / det


@njit(cache=True)
def start(x, op, om, s):
    """Switch the vehicle's sensors on and start its filter at period 0 (see the module); returns
    the generator state."""
    for j in range(KERNEL_SIZE, om.shape[0]):
        if j < OM_LOG or j >= OM_LOG + L.OBSERVATION_SIZE:
            om[j] = 0.0
        else:
            om[j] = np.nan
    for j in (L.O_IMU_COUNT, L.O_GPS_COUNT, L.O_BARO_COUNT, L.O_MAG_COUNT):
        om[OM_LOG + j] = 0.0
    if op[OP_IMU_ON] != 0.0:
        om[L.OM_VIBRATION] = op[OP_IMU + IMU_VIBRATION]
        if om[L.OM_VIBRATION] != 0.0:  # the rotors' angles, uniform, first from the stream
            for r in range(L.MAX_VIBRATING_ROTORS):
                u, s = next_unit(s)
                om[L.OM_PHASE + r] = 2.0 * math.pi * u
        s = imu_start(op[OP_IMU : OP_IMU + IMU_SIZE], om[OM_IMU : OM_IMU + IMU_STATE_SIZE], s)
    else:
        om[L.OM_VIBRATION] = 0.0
    if op[OP_BARO_ON] != 0.0:
        om[OM_BARO_BIAS], s = noisy(0.0, 0.0, op[OP_BARO + 2], s)  # the switch-on offset (Baro.bias_init)
    if op[OP_MAG_ON] != 0.0:
        for i in range(3):
            om[OM_MAG_BIAS + i], s = noisy(0.0, 0.0, op[OP_MAG + MAG_BIAS_STD], s)
    om[OM_PSI] = x[L.PSI]
    if op[OP_EKF_ON] != 0.0:  # the truth plus an error drawn from P0
        p0 = op[OP_P0 : OP_P0 + E_SIZE]
        xe = om[OM_X : OM_X + X_SIZE]
        for i in range(3):
            xe[XP + i], s = noisy(x[L.X + i], 0.0, p0[EP + i], s)
            xe[XV + i], s = noisy(x[L.VX + i], 0.0, p0[EV + i], s)
        d = np.empty(3)
        for i in range(3):
            d[i], s = noisy(0.0, 0.0, p0[6 + i], s)
        q = quat_mul(euler_quaternion(x[L.PHI], x[L.THETA], x[L.PSI]), quat_exp(-d[0], -d[1], -d[2]))
        for i in range(4):
            xe[XQ + i] = q[i]
        for i in range(E_SIZE):
            om[OM_COV + i * E_SIZE + i] = p0[i] * p0[i]
    return s


@njit(cache=True)
def write_estimate(x, om):
    """The estimate into the log row (as the controller sees it, quaternion, biases), and the
    truth x (paper layout) of this IMU instant kept for :func:`write_errors`."""
    xe = om[OM_X : OM_X + X_SIZE]
    log = om[OM_LOG : OM_LOG + L.OBSERVATION_SIZE]
    qw, qx, qy, qz = xe[XQ], xe[XQ + 1], xe[XQ + 2], xe[XQ + 3]
    phi = math.atan2(2.0 * (qw * qx + qy * qz), 1.0 - 2.0 * (qx * qx + qy * qy))
    theta = math.asin(max(-1.0, min(1.0, 2.0 * (qw * qy - qx * qz))))
    raw = math.atan2(2.0 * (qw * qz + qx * qy), 1.0 - 2.0 * (qy * qy + qz * qz))
    turn = raw - om[OM_PSI]
    psi = om[OM_PSI] + turn - 2.0 * math.pi * math.floor(turn / (2.0 * math.pi) + 0.5)
    om[OM_PSI] = psi
    for i in range(3):
        log[L.O_X + i] = xe[XP + i]
        log[L.O_VX + i] = xe[XV + i]
        log[L.O_P + i] = om[OM_RATES + i]
        log[L.O_BG + i] = xe[XBG + i]
        log[L.O_BA + i] = xe[XBA + i]
    log[L.O_PHI], log[L.O_PHI + 1], log[L.O_PHI + 2] = phi, theta, psi
    for i in range(4):
        log[L.O_QW + i] = xe[XQ + i]
    for j in range(9):
        om[OM_TRUTH + j] = x[L.X + j]
    om[OM_ERRORS_DUE] = 1.0


@njit(cache=True)
def write_errors(om):
    """The standard deviations and the NEES of the last IMU instant into the log row (made when
    a row is logged: they cost more than the rest of the row)."""
    om[OM_ERRORS_DUE] = 0.0
    xe = om[OM_X : OM_X + X_SIZE]
    P = om[OM_COV : OM_COV + E_SIZE * E_SIZE].reshape((E_SIZE, E_SIZE))
    log = om[OM_LOG : OM_LOG + L.OBSERVATION_SIZE]
    tr = om[OM_TRUTH : OM_TRUTH + 9]  # x, y, z, vx, vy, vz, phi, theta, psi
    for i in range(E_SIZE):
        log[L.O_SD + i] = math.sqrt(P[i, i])
    log[L.O_NEES] = quadratic_form3(P, EP, tr[0] - xe[XP], tr[1] - xe[XP + 1], tr[2] - xe[XP + 2])
    log[L.O_NEES + 1] = quadratic_form3(P, EV, tr[3] - xe[XV], tr[4] - xe[XV + 1], tr[5] - xe[XV + 2])
    qw, qx, qy, qz = xe[XQ], xe[XQ + 1], xe[XQ + 2], xe[XQ + 3]
    tw, tx, ty, tz = euler_quaternion4(tr[6], tr[7], tr[8])
    dw, dx, dy, dz = qmul4(qw, -qx, -qy, -qz, tw, tx, ty, tz)  # R_true = R_est Exp(d): d = Log(q_est^* q_true)
    if dw < 0.0:
        dw, dx, dy, dz = -dw, -dx, -dy, -dz
    n = math.sqrt(dx * dx + dy * dy + dz * dz)
    c = 2.0 if n < 1e-12 else 2.0 * math.atan2(n, dw) / n
    log[L.O_NEES + 2] = quadratic_form3(P, ETH, c * dx, c * dy, c * dz)


@njit(cache=True, inline="always")
def arrived(k, op, om):
    """Whether the GPS queue's oldest fix has arrived by period k."""
    if om[OM_GPS_COUNT] <= 0.0:
        return False
    return om[OM_GPS_QUEUE + GPS_ENTRY * int(om[OM_GPS_HEAD])] <= k


@njit(cache=True)
def fuse(t, k, op, om):
    """The readings that have come, fused at an IMU instant: GPS fixes arrived by period k
    (position then velocity), the barometer, the magnetometer (as :func:`~quadcruise.estimation.run.filter_series`)."""
    xe = om[OM_X : OM_X + X_SIZE]
    P = om[OM_COV : OM_COV + E_SIZE * E_SIZE].reshape((E_SIZE, E_SIZE))
    log = om[OM_LOG : OM_LOG + L.OBSERVATION_SIZE]
    meas, gates = op[OP_MEAS : OP_MEAS + M_SIZE], op[OP_GATES : OP_GATES + 4]
    slots = int(op[OP_GPS_SLOTS])
    ekf = op[OP_EKF_ON] != 0.0
    scratch = np.empty((WORK_ROWS + 1, E_SIZE))  # one allocation: the updates' scratch, the heading's H
    work, H1 = scratch[:WORK_ROWS], scratch[WORK_ROWS : WORK_ROWS + 1]
    rv = work[6]  # r (3), then var (3): a row update() leaves alone
    r3, var3, r1, var1 = rv[0:3], rv[3:6], rv[6:7], rv[7:8]
    while om[OM_GPS_COUNT] > 0.0:
        at = OM_GPS_QUEUE + GPS_ENTRY * int(om[OM_GPS_HEAD])
        if om[at] > k:
            break
        om[OM_GPS_HEAD] = (om[OM_GPS_HEAD] + 1.0) % slots
        om[OM_GPS_COUNT] -= 1.0
        log[L.O_GPS_T] = om[at + 1]
        for i in range(6):
            log[L.O_GPS + i] = om[at + 2 + i]
        log[L.O_GPS_COUNT] += 1.0
        if not ekf:
            continue
        delta = np.zeros(6)  # the estimate's change since the fix was taken: the fix moved on by it
        history = int(op[OP_HISTORY])
        if history:
            imu_every = int(op[OP_IMU_EVERY])
            ks = int(om[at] - op[OP_GPS_DELAY])  # the period the fix was taken at
            k_imu = (ks // imu_every) * imu_every  # the IMU instant at or before it
            if k_imu < k:
                h = OM_GPS_QUEUE + GPS_ENTRY * slots + HISTORY_ENTRY * ((k_imu // imu_every) % history)
                if om[h] == k_imu:
                    for i in range(3):
                        delta[i] = xe[XP + i] - om[h + 1 + i]
                        delta[3 + i] = xe[XV + i] - om[h + 4 + i]
        for part in range(2):  # position, then velocity
            base = XP if part == 0 else XV
            var3[0] = var3[1] = meas[M_POS_H if part == 0 else M_VEL_H] ** 2
            var3[2] = meas[M_POS_V if part == 0 else M_VEL_V] ** 2
            for i in range(3):
                r3[i] = om[at + 2 + 3 * part + i] + delta[3 * part + i] - xe[base + i]
                log[L.O_INNOV + 3 * part + i] = r3[i]
                log[L.O_INNOV_VAR + 3 * part + i] = P[base + i, base + i] + var3[i]
            log[L.O_NIS + part] = update_states(xe, P, EP if part == 0 else EV, r3, var3, gates[3], work)
    if om[OM_BARO_DUE] != 0.0:
        om[OM_BARO_DUE] = 0.0
        if ekf:
            r1[0] = om[OM_BARO] - meas[M_BARO_OFF] - xe[XP + 2]
            var1[0] = meas[M_BARO] ** 2
            log[L.O_INNOV + 6], log[L.O_INNOV_VAR + 6] = r1[0], P[EP + 2, EP + 2] + var1[0]
            log[L.O_NIS + 2] = update_states(xe, P, EP + 2, r1, var1, gates[1], work)
    if om[OM_MAG_DUE] != 0.0:
        om[OM_MAG_DUE] = 0.0
        if ekf:
            Hm = H1
            r = heading_innovation(xe, om[OM_MAG], om[OM_MAG + 1], om[OM_MAG + 2], op[OP_FIELD : OP_FIELD + 3], Hm)
            r1[0] = r
            var1[0] = meas[M_HEAD] ** 2
            hph = 0.0
            for i in range(ETH, ETH + 3):
                for j in range(ETH, ETH + 3):
                    hph += Hm[0, i] * P[i, j] * Hm[0, j]
            log[L.O_INNOV + 7], log[L.O_INNOV_VAR + 7] = r, hph + var1[0]
            log[L.O_NIS + 3] = update(xe, P, Hm, r1, var1, gates[1], work)


@njit(cache=True, inline="always")
def due(k, op):
    """Whether the GPS, the barometer or the magnetometer samples at period k."""
    return (
        (op[OP_GPS_ON] != 0.0 and k % int(op[OP_GPS_EVERY]) == 0)
        or (op[OP_BARO_ON] != 0.0 and k % int(op[OP_BARO_EVERY]) == 0)
        or (op[OP_MAG_ON] != 0.0 and k % int(op[OP_MAG_EVERY]) == 0)
    )


@njit(cache=True)
def sample(t, k, x, op, om, s):
    """The GPS (queued), barometer and magnetometer samples due at period k, from the truth x."""
    log = om[OM_LOG : OM_LOG + L.OBSERVATION_SIZE]
    if op[OP_GPS_ON] != 0.0 and k % int(op[OP_GPS_EVERY]) == 0:
        start_, span = op[OP_GPS + GPS_OUTAGE_START], op[OP_GPS + GPS_OUTAGE_DURATION]
        slots = int(op[OP_GPS_SLOTS])
        if not (span > 0.0 and start_ <= t < start_ + span) and om[OM_GPS_COUNT] < slots:
            at = OM_GPS_QUEUE + GPS_ENTRY * int((om[OM_GPS_HEAD] + om[OM_GPS_COUNT]) % slots)
            om[at], om[at + 1] = k + op[OP_GPS_DELAY], t
            s = gps_read(
                op[OP_GPS : OP_GPS + GPS_SIZE], x[L.X], x[L.Y], x[L.Z], x[L.VX], x[L.VY], x[L.VZ],
                om[at + 2 : at + 8], s,
            )  # fmt: skip
            om[OM_GPS_COUNT] += 1.0
    if op[OP_BARO_ON] != 0.0 and k % int(op[OP_BARO_EVERY]) == 0:
        om[OM_BARO], s = baro_read(op[OP_BARO : OP_BARO + BARO_SIZE], om[OM_BARO_BIAS : OM_BARO_BIAS + 1], x[L.Z], s)
        om[OM_BARO_DUE] = 1.0
        log[L.O_BARO] = om[OM_BARO]
        log[L.O_BARO_COUNT] += 1.0
    if op[OP_MAG_ON] != 0.0 and k % int(op[OP_MAG_EVERY]) == 0:
        tw, tx, ty, tz = euler_quaternion4(x[L.PHI], x[L.THETA], x[L.PSI])
        r00, r01, r02, r10, r11, r12, r20, r21, r22 = rot9(tw, tx, ty, tz)
        f0, f1, f2 = op[OP_FIELD], op[OP_FIELD + 1], op[OP_FIELD + 2]
        s = mag_read(
            op[OP_MAG : OP_MAG + MAG_SIZE], om[OM_MAG_BIAS : OM_MAG_BIAS + 3],
            r00 * f0 + r10 * f1 + r20 * f2, r01 * f0 + r11 * f1 + r21 * f2, r02 * f0 + r12 * f1 + r22 * f2,
            om[OM_MAG : OM_MAG + 3], s,
        )  # fmt: skip
        om[OM_MAG_DUE] = 1.0
        for i in range(3):
            log[L.O_MAG + i] = om[OM_MAG + i]
        log[L.O_MAG_COUNT] += 1.0
    return s


@njit(L.OBSERVER_SIG, cache=True)
def onboard(t, k, logging, x, op, om, rng, seen, obs):
    """The observation stage of one vehicle at period k (``OBSERVER_SIG``; the module says what
    it does).

    Parameters
    ----------
    t : float
        The instant [s].
    k : int
        The period of the grid (0: switch on).
    logging : bool
        Write the log row into ``obs``.
    x : numpy.ndarray
        (STATE_SIZE,) the true state, paper layout.
    op : numpy.ndarray
        (:data:`PARAMS` size,) parameters.
    om : numpy.ndarray
        Memory (:func:`memory_row`), its force written by the kernel.
    rng : numpy.ndarray
        (1,) uint64 the stream.
    seen : numpy.ndarray
        (STATE_SIZE,) output: what the controller sees.
    obs : numpy.ndarray
        (OBSERVATION_SIZE,) output with ``logging``: the log row.
    """
    imu_every = int(op[OP_IMU_EVERY])
    log = om[OM_LOG : OM_LOG + L.OBSERVATION_SIZE]
    ekf = op[OP_EKF_ON] != 0.0
    imu_now = k % imu_every == 0
    shaken = om[L.OM_VIBRATION] != 0.0
    if k > 0 and not imu_now:  # the trapezoid of the true rates and forces over the IMU period
        for i in range(6):
            om[OM_IMU_SUM + i] += om[L.OM_FORCE + i]  # force, then rate: OBSERVER_KERNEL's order
        if shaken:  # the vibration's period means: their plain mean over the IMU period
            for i in range(3):
                om[OM_SHAKE_SUM + i] += om[L.OM_SHAKE + i]
    if imu_now or logging or not ekf or due(k, op):
        s = rng[0]
        if k == 0:
            s = start(x, op, om, s)
        s = sample(t, k, x, op, om, s)
        if op[OP_IMU_ON] != 0.0 and imu_now:
            last = om[OM_IMU_LAST : OM_IMU_LAST + 6]
            total = om[OM_IMU_SUM : OM_IMU_SUM + 6]
            for i in range(6):  # the average over the period, as PX4's sensor_combined gives it
                v = om[L.OM_FORCE + i]
                total[i] = v if k == 0 else (total[i] + 0.5 * v) / imu_every
            if shaken and k > 0:  # the force read: the vibration's mean over the period added
                for i in range(3):
                    total[i] += (om[OM_SHAKE_SUM + i] + om[L.OM_SHAKE + i]) / imu_every
                    om[OM_SHAKE_SUM + i] = 0.0
            s = imu_read(
                op[OP_IMU : OP_IMU + IMU_SIZE], om[OM_IMU : OM_IMU + IMU_STATE_SIZE],
                total[3], total[4], total[5], total[0], total[1], total[2], last, s,
            )  # fmt: skip
            for i in range(6):
                total[i] = 0.5 * om[L.OM_FORCE + i]  # the next period's first end
            if ekf and k > 0:  # from the last IMU instant to this one, with the period's reading
                xe = om[OM_X : OM_X + X_SIZE]
                P = om[OM_COV : OM_COV + E_SIZE * E_SIZE].reshape((E_SIZE, E_SIZE))
                dt = t - om[OM_T_IMU]
                g = op[OP_MEAS + M_G]
                predict(xe, P, last[0], last[1], last[2], last[3], last[4], last[5], dt, op[OP_NOISE : OP_NOISE + 4], g)
            om[OM_T_IMU] = t
            for i in range(6):
                log[L.O_GYRO + i] = last[i]
            first = log[L.O_IMU_COUNT] == 0.0
            log[L.O_IMU_COUNT] += 1.0
            if ekf:
                if om[OM_BARO_DUE] != 0.0 or om[OM_MAG_DUE] != 0.0 or arrived(k, op, om):
                    fuse(t, k, op, om)
                a = 1.0 if first else op[OP_RATE_ALPHA]
                for i in range(3):
                    w = last[i] - om[OM_X + XBG + i]
                    om[OM_RATES + i] += a * (w - om[OM_RATES + i])
                write_estimate(x, om)
                history = int(op[OP_HISTORY])
                if history:  # the estimate at this IMU instant, for the fixes taken now
                    h = OM_GPS_QUEUE + GPS_ENTRY * int(op[OP_GPS_SLOTS]) + HISTORY_ENTRY * ((k // imu_every) % history)
                    om[h] = k
                    for i in range(6):
                        om[h + 1 + i] = om[OM_X + XP + i]  # position, then velocity: the state's order
        elif not ekf and (om[OM_BARO_DUE] != 0.0 or om[OM_MAG_DUE] != 0.0 or arrived(k, op, om)):
            fuse(t, k, op, om)  # the GPS fixes that arrived, logged (no filter to fuse them)
        rng[0] = s
        if logging:
            if om[OM_ERRORS_DUE] != 0.0:
                write_errors(om)
            for j in range(L.OBSERVATION_SIZE):
                obs[j] = log[j]
    if ekf:  # the estimate of the last IMU instant, held until the next
        for i in range(3):
            seen[L.X + i] = log[L.O_X + i]
            seen[L.VX + i] = log[L.O_VX + i]
            seen[L.PHI + i] = log[L.O_PHI + i]
            seen[L.P + i] = log[L.O_P + i]
        for i in range(4):
            seen[L.F1 + i] = x[L.F1 + i]
    else:
        for j in range(L.STATE_SIZE):
            seen[j] = x[j]


__all__ = ["GPS_ENTRY", "PARAMS", "euler_quaternion", "euler_rotation", "memory_row", "onboard", "quadratic_form3"]
