"""The EKF over a whole flight's sensor streams, compiled: the IMU drives the prediction, and
each GPS, barometer and magnetometer reading is fused at its time stamp, in time order.

:func:`run_ekf` takes the streams as arrays (ENU world, FLU body), the filter's own noise
settings (:class:`EkfNoise`) and the initial state and covariance, and gives an
:class:`EkfRun`: the estimate at every IMU sample, the covariance, and every update's NIS.
Readings are fused at the IMU sample at or after their time stamp; a latency is not
compensated (the filter assumes the reading's stamp is when it was taken).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from numba import njit
from scipy.stats import chi2

from quadcruise.estimation.ekf import (
    E_SIZE,
    EP,
    EV,
    WORK_ROWS,
    X_SIZE,
    XP,
    XV,
    heading_innovation,
    predict,
    update,
    update_states,
)
from quadcruise.fields import Validated, unit_field
from quadcruise.layout import Row

MEAS = Row.of(
    "ekf measurement settings", "pos_h", "pos_v", "vel_h", "vel_v", "baro", "head", "baro_off", "g", prefix="M_"
)
"""The measurement settings row the compiled filter reads: GPS position and velocity stds
(horizontal, vertical) [m], [m/s], barometer std [m], heading std [rad], the barometer's offset
from z [m], gravity [m/s^2] (:meth:`EkfNoise.meas_row`)."""
M_POS_H, M_POS_V, M_VEL_H, M_VEL_V, M_BARO, M_HEAD, M_BARO_OFF, M_G = MEAS.offsets
M_SIZE = MEAS.size


@dataclass(frozen=True)
class EkfNoise(Validated):
    """What the filter assumes of its sensors: noise densities and standard deviations.

    Parameters
    ----------
    gyro_noise : float
        Gyro noise density [rad/s/sqrt(Hz)], >= 0.
    accel_noise : float
        Accelerometer noise density [m/s^2/sqrt(Hz)], >= 0.
    gyro_bias_walk : float
        Gyro bias random walk [rad/s^2/sqrt(Hz)], >= 0.
    accel_bias_walk : float
        Accelerometer bias random walk [m/s^3/sqrt(Hz)], >= 0.
    gps_horizontal_std, gps_vertical_std : float
        GPS position noise [m], > 0.
    gps_velocity_std, gps_vertical_velocity_std : float
        GPS velocity noise [m/s], > 0.
    baro_std : float
        Barometer noise [m], > 0.
    heading_std : float
        Magnetometer heading noise [rad], > 0.
    gate : float
        Chi-square probability of the innovation gate, in [0, 1] (1: no gate).
    gravity : float
        g [m/s^2], > 0.

    Examples
    --------
    >>> EkfNoise().gate
    0.999
    """

    gyro_noise: float = unit_field(3e-4, "rad/s/sqrt(Hz)", "gyro noise density", "nonneg")
    accel_noise: float = unit_field(3e-3, "m/s^2/sqrt(Hz)", "accelerometer noise density", "nonneg")
    gyro_bias_walk: float = unit_field(1e-5, "rad/s^2/sqrt(Hz)", "gyro bias random walk", "nonneg")
    accel_bias_walk: float = unit_field(1e-4, "m/s^3/sqrt(Hz)", "accelerometer bias random walk", "nonneg")
    gps_horizontal_std: float = unit_field(0.5, "m", "GPS horizontal position std", "pos")
    gps_vertical_std: float = unit_field(0.8, "m", "GPS vertical position std", "pos")
    gps_velocity_std: float = unit_field(0.1, "m/s", "GPS horizontal velocity std", "pos")
    gps_vertical_velocity_std: float = unit_field(0.15, "m/s", "GPS vertical velocity std", "pos")
    baro_std: float = unit_field(0.1, "m", "barometer std", "pos")
    heading_std: float = unit_field(0.02, "rad", "magnetometer heading std", "pos")
    gate: float = unit_field(0.999, "-", "innovation gate probability", "frac")
    gravity: float = unit_field(9.80665, "m/s^2", "gravity", "pos")
    name = "ekf"

    def noise_row(self) -> np.ndarray:
        """The prediction's densities.

        Returns
        -------
        numpy.ndarray
            (4,): gyro, accel, gyro bias walk, accel bias walk.
        """
        return np.array([self.gyro_noise, self.accel_noise, self.gyro_bias_walk, self.accel_bias_walk])

    def meas_row(self, baro_offset: float = 0.0) -> np.ndarray:
        """The measurement settings as the compiled filter reads them (:data:`MEAS`).

        Parameters
        ----------
        baro_offset : float
            The barometer's offset from z [m].

        Returns
        -------
        numpy.ndarray
            (M_SIZE,).

        Examples
        --------
        >>> float(EkfNoise().meas_row()[M_G])
        9.80665
        """
        return MEAS.pack(
            {
                "pos_h": self.gps_horizontal_std,
                "pos_v": self.gps_vertical_std,
                "vel_h": self.gps_velocity_std,
                "vel_v": self.gps_vertical_velocity_std,
                "baro": self.baro_std,
                "head": self.heading_std,
                "baro_off": baro_offset,
                "g": self.gravity,
            }
        )

    def gates(self) -> np.ndarray:
        """The largest NIS accepted per degrees of freedom.

        Returns
        -------
        numpy.ndarray
            (4,): index = degrees of freedom (0..3); inf where nothing is refused.
        """
        if self.gate >= 1.0:
            return np.full(4, np.inf)
        return np.array([np.inf] + [float(chi2.ppf(self.gate, m)) for m in (1, 2, 3)])


@dataclass(frozen=True, eq=False)
class EkfRun:
    """What one run of the filter gives.

    Parameters
    ----------
    t : numpy.ndarray
        (K,) IMU instants [s].
    x : numpy.ndarray
        (K, 16) the estimate after the updates at each (p, v, q w first, b_g, b_a).
    sigma : numpy.ndarray
        (K, 15) the error state's standard deviations.
    cov_t : numpy.ndarray
        (J,) every ``stride``-th instant [s].
    cov : numpy.ndarray
        (J, 15, 15) the error covariance at those.
    nis : dict
        Per stream (``gps_pos``, ``gps_vel``, ``baro``, ``mag``) each update's NIS (K_s,),
        negative where the gate refused it.
    """

    t: np.ndarray
    x: np.ndarray
    sigma: np.ndarray
    cov_t: np.ndarray
    cov: np.ndarray
    nis: dict


@njit(cache=True)
def filter_series(
    imu_t, imu, gps_t, gps, gps_s, baro_t, baro, mag_t, mag, noise, meas, field, gates, x, P, stride, xs, sd, covs, nis
):
    """The filter over the streams, in place: see :func:`run_ekf` (``nis`` (4, max count),
    rows gps_pos, gps_vel, baro, mag; ``gps_s`` the fixes' sample times, or empty)."""
    ig = ib = im = 0
    var3 = np.empty(3)
    r3 = np.empty(3)
    var1 = np.empty(1)
    r1 = np.empty(1)
    work = np.empty((WORK_ROWS, E_SIZE))
    for k in range(imu_t.shape[0]):
        t = imu_t[k] + 1e-9
        while ig < gps_t.shape[0] and gps_t[ig] <= t:
            delta = np.zeros(6)  # the estimate's change since the fix was taken (its latency)
            if gps_s.shape[0]:
                ks = k
                while ks > 0 and imu_t[ks] > gps_s[ig] + 1e-9:
                    ks -= 1
                if ks < k:
                    for i in range(3):
                        delta[i] = x[XP + i] - xs[ks, XP + i]
                        delta[3 + i] = x[XV + i] - xs[ks, XV + i]
            for i in range(3):
                r3[i] = gps[ig, i] + delta[i] - x[XP + i]
            var3[0] = var3[1] = meas[M_POS_H] ** 2
            var3[2] = meas[M_POS_V] ** 2
            nis[0, ig] = update_states(x, P, EP, r3, var3, gates[3], work)
            for i in range(3):
                r3[i] = gps[ig, 3 + i] + delta[3 + i] - x[XV + i]
            var3[0] = var3[1] = meas[M_VEL_H] ** 2
            var3[2] = meas[M_VEL_V] ** 2
            nis[1, ig] = update_states(x, P, EV, r3, var3, gates[3], work)
            ig += 1
        while ib < baro_t.shape[0] and baro_t[ib] <= t:
            r1[0] = baro[ib] - meas[M_BARO_OFF] - x[XP + 2]
            var1[0] = meas[M_BARO] ** 2
            nis[2, ib] = update_states(x, P, EP + 2, r1, var1, gates[1], work)
            ib += 1
        while im < mag_t.shape[0] and mag_t[im] <= t:
            Hm = np.zeros((1, E_SIZE))
            r = heading_innovation(x, mag[im, 0], mag[im, 1], mag[im, 2], field, Hm)
            r1[0] = r
            var1[0] = meas[M_HEAD] ** 2
            nis[3, im] = update(x, P, Hm, r1, var1, gates[1], work)
            im += 1
        xs[k] = x
        for i in range(E_SIZE):
            sd[k, i] = np.sqrt(P[i, i])
        if k % stride == 0:
            covs[k // stride] = P
        if k + 1 < imu_t.shape[0]:
            dt = imu_t[k + 1] - imu_t[k]
            predict(x, P, imu[k, 0], imu[k, 1], imu[k, 2], imu[k, 3], imu[k, 4], imu[k, 5], dt, noise, meas[M_G])


def _stream(s, width):
    if s is None:
        return np.zeros(0), np.zeros((0, width)) if width else np.zeros(0)
    t, z = s
    return np.ascontiguousarray(t, float), np.ascontiguousarray(z, float)


def run_ekf(
    imu_t: np.ndarray,
    imu: np.ndarray,
    x0: np.ndarray,
    P0: np.ndarray,
    settings: EkfNoise,
    *,
    gps: tuple | None = None,
    baro: tuple | None = None,
    mag: tuple | None = None,
    field: np.ndarray | None = None,
    baro_offset: float = 0.0,
    stride: int = 1,
    gps_sample_t: np.ndarray | None = None,
) -> EkfRun:
    """Run the error-state EKF over one flight's sensor streams.

    Parameters
    ----------
    imu_t : numpy.ndarray
        (K,) increasing IMU instants [s].
    imu : numpy.ndarray
        (K, 6) gyro [rad/s] and accelerometer [m/s^2] readings, FLU; reading k covers
        ``[imu_t[k], imu_t[k + 1]]``.
    x0 : numpy.ndarray
        (16,) initial state at ``imu_t[0]``: p [m], v [m/s], q (w first), b_g, b_a (ENU, FLU).
    P0 : numpy.ndarray
        (15, 15) its error covariance.
    settings : EkfNoise
        The filter's noise settings.
    gps : tuple, optional
        (times (G,) [s], fixes (G, 6): ENU position [m] and velocity [m/s]).
    baro : tuple, optional
        (times (B,) [s], altitudes (B,) [m]); the reading is ``z + baro_offset``.
    mag : tuple, optional
        (times (M,) [s], readings (M, 3) FLU [G]); needs ``field``.
    field : numpy.ndarray, optional
        (3,) the world magnetic field, ENU [G].
    baro_offset : float
        The barometer's offset from the ENU z [m].
    stride : int
        Keep the full covariance every ``stride`` IMU samples.
    gps_sample_t : numpy.ndarray, optional
        (G,) when each fix was taken [s] (``gps``'s times being when it arrived): it is fused
        against the estimate of the IMU instant at or before then, moved on to now (the
        estimate's change since added to the fix); None: as if taken when it arrived.

    Returns
    -------
    EkfRun
        The estimates, their standard deviations, covariances and each update's NIS.

    Examples
    --------
    >>> import numpy as np
    >>> t = np.arange(0, 1.0, 0.01)
    >>> imu = np.tile([0.0, 0, 0, 0, 0, 9.80665], (t.size, 1))      # at rest, level
    >>> x0 = np.r_[np.zeros(6), 1.0, np.zeros(9)]
    >>> run = run_ekf(t, imu, x0, np.eye(15) * 1e-4, EkfNoise())
    >>> bool(np.abs(run.x[-1, :6]).max() < 1e-9)
    True
    """
    imu_t, imu = np.ascontiguousarray(imu_t, float), np.ascontiguousarray(imu, float)
    gps_t, gps_z = _stream(gps, 6)
    baro_t, baro_z = _stream(baro, 0)
    mag_t, mag_z = _stream(mag, 3)
    if mag is not None and field is None:
        raise ValueError("a magnetometer stream needs the world field")
    field = np.zeros(3) if field is None else np.asarray(field, float)
    s = settings
    meas = s.meas_row(baro_offset)
    K = imu_t.size
    x, P = np.array(x0, float), np.array(P0, float)
    xs, sd = np.empty((K, X_SIZE)), np.empty((K, E_SIZE))
    covs = np.empty(((K - 1) // stride + 1, E_SIZE, E_SIZE))
    nis = np.full((4, max(gps_t.size, baro_t.size, mag_t.size, 1)), np.nan)
    gps_s = np.zeros(0) if gps_sample_t is None else np.ascontiguousarray(gps_sample_t, float)
    filter_series(
        imu_t, imu, gps_t, gps_z, gps_s, baro_t, baro_z, mag_t, mag_z, s.noise_row(), meas, field, s.gates(),
        x, P, int(stride), xs, sd, covs, nis,
    )  # fmt: skip
    counts = (gps_t.size, gps_t.size, baro_t.size, mag_t.size)
    names = ("gps_pos", "gps_vel", "baro", "mag")
    return EkfRun(
        imu_t,
        xs,
        sd,
        imu_t[::stride],
        covs,
        {n: nis[i, :c] for i, (n, c) in enumerate(zip(names, counts, strict=True))},
    )
