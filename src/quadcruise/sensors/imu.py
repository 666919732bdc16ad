"""An inertial measurement unit: gyroscope and accelerometer, as a flight controller reads them.

Per axis, with the true body rate w and specific force f (FLU body frame, [rad/s], [m/s^2]):

    reading = digitise(M (true) + b + n * sqrt(rate) * w_k),    b_{k+1} = b_k + r * sqrt(dt) * v_k

``M = I + diag(scale) + skew-free misalignment`` (drawn once per vehicle), ``b`` the bias
(drawn at switch-on with ``*_bias_init``, then a random walk of density ``r``), ``n`` the
white-noise density, w_k, v_k standard normal; ``digitise`` clips to the range and rounds to
the least significant bit (:func:`quadcruise.sensors.noise.digitise`).

Presets (:data:`BMI088`, :data:`ICM42688P`) carry the noise densities of their datasheets; the
docstrings say which numbers were checked against which source.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
from numba import njit

from quadcruise.fields import unit_field
from quadcruise.sensors.model import SensorModel
from quadcruise.sensors.noise import digitise, noisy, sample_std, walk
from quadcruise.sim.rng import vehicle_states

DEG = math.pi / 180.0
G0 = 9.80665
"""Standard gravity [m/s^2], to turn datasheet g into m/s^2."""

# the parameter row's offsets
# the state's offsets: gyro bias, accel bias, gyro matrix (row-major), accel matrix
ST_BG, ST_BA, ST_MG, ST_MA, STATE_SIZE = 0, 3, 6, 15, 24


@dataclass(frozen=True)
class Imu(SensorModel):
    """An IMU's parameters: rate, noise densities, bias walk, range and resolution.

    Parameters
    ----------
    rate : float
        Output rate [Hz], > 0 (PX4 reads 250-1000 Hz after its own filters).
    gyro_noise : float
        Gyro white-noise density [rad/s/sqrt(Hz)], >= 0.
    gyro_bias_walk : float
        Gyro bias random walk [rad/s^2/sqrt(Hz)], >= 0 (rate random walk).
    gyro_bias_init : float
        Standard deviation of the gyro's switch-on bias per axis [rad/s], >= 0.
    gyro_range : float
        Full scale [rad/s], >= 0 (0: no saturation).
    gyro_lsb : float
        Resolution [rad/s], >= 0 (0: no quantisation).
    accel_noise : float
        Accelerometer white-noise density [m/s^2/sqrt(Hz)], >= 0.
    accel_bias_walk : float
        Accelerometer bias random walk [m/s^3/sqrt(Hz)], >= 0.
    accel_bias_init : float
        Standard deviation of the switch-on accelerometer bias per axis [m/s^2], >= 0.
    accel_range : float
        Full scale [m/s^2], >= 0 (0: none).
    accel_lsb : float
        Resolution [m/s^2], >= 0 (0: none).
    scale_error : float
        Standard deviation of each axis' scale-factor error [-], >= 0, drawn once.
    misalignment : float
        Standard deviation of each off-diagonal cross-axis term [rad], >= 0, drawn once.
    vibration : float
        Each rotor's imbalance acceleration at the vehicle's hover speed [m/s^2], >= 0 (0: none;
        rotor plant only): rotor i shakes the body in its plane at its own angle with the amplitude
        ``vibration (w_i / w_hover)^2``, averaged over the IMU's period
        (:func:`quadcruise.sim.observe.rotor_shake`). PX4's Flight Review shades its
        ``accel_vibration_metric`` [m/s^2] green below g/2 (4.9), orange to g, red above.

    Examples
    --------
    >>> float(Imu(rate=400.0).row()[0])
    400.0
    >>> round(BMI088.gyro_noise / DEG, 3)       # 0.014 deg/s/sqrt(Hz)
    0.014
    """

    rate: float = unit_field(250.0, "Hz", "output rate", "pos")
    gyro_noise: float = unit_field(0.0, "rad/s/sqrt(Hz)", "gyro noise density", "nonneg")
    gyro_bias_walk: float = unit_field(0.0, "rad/s^2/sqrt(Hz)", "gyro bias random walk", "nonneg")
    gyro_bias_init: float = unit_field(0.0, "rad/s", "gyro switch-on bias std", "nonneg")
    gyro_range: float = unit_field(0.0, "rad/s", "gyro full scale", "nonneg")
    gyro_lsb: float = unit_field(0.0, "rad/s", "gyro resolution", "nonneg")
    accel_noise: float = unit_field(0.0, "m/s^2/sqrt(Hz)", "accelerometer noise density", "nonneg")
    accel_bias_walk: float = unit_field(0.0, "m/s^3/sqrt(Hz)", "accelerometer bias random walk", "nonneg")
    accel_bias_init: float = unit_field(0.0, "m/s^2", "accelerometer switch-on bias std", "nonneg")
    accel_range: float = unit_field(0.0, "m/s^2", "accelerometer full scale", "nonneg")
    accel_lsb: float = unit_field(0.0, "m/s^2", "accelerometer resolution", "nonneg")
    scale_error: float = unit_field(0.0, "-", "scale-factor error std", "nonneg")
    misalignment: float = unit_field(0.0, "rad", "cross-axis misalignment std", "nonneg")
    vibration: float = unit_field(0.0, "m/s^2", "each rotor's imbalance acceleration at hover", "nonneg")
    name = "imu"

    def measure(self, rates: np.ndarray, forces: np.ndarray, seed: int, vehicle: int = 0) -> tuple:
        """The IMU's readings of a true series sampled at its rate, from an explicit seed.

        Parameters
        ----------
        rates, forces : numpy.ndarray
            (K, 3) true body rates [rad/s] and specific forces [m/s^2], FLU, one row per period.
        seed : int
            The run's seed, >= 0.
        vehicle : int
            The vehicle's index: its stream is ``SeedSequence([seed, vehicle])``'s.

        Returns
        -------
        tuple of numpy.ndarray
            (K, 6) readings (gyro [rad/s], accelerometer [m/s^2]) and the final state
            (STATE_SIZE,): biases (gyro, accel) then the two 3x3 matrices.

        Examples
        --------
        >>> import numpy as np
        >>> z = np.zeros((4, 3))
        >>> out, st = Imu(rate=100.0).measure(z, z + [0, 0, 9.8], seed=1)
        >>> out[0].tolist()                  # no noise, no bias: the truth
        [0.0, 0.0, 0.0, 0.0, 0.0, 9.8]
        """
        rates, forces = np.ascontiguousarray(rates, float), np.ascontiguousarray(forces, float)
        row, st = self.row(), np.zeros(STATE_SIZE)
        s = imu_start(row, st, vehicle_states(seed, 1, first=vehicle)[0, 0])
        out = np.empty((rates.shape[0], 6))
        imu_series(row, st, rates, forces, out, np.uint64(s))  # a Python int would type as int64
        return out, st


IMU_ROW = Imu.layout("IMU_")
"""The compiled functions' parameter row: :class:`Imu`'s fields in order (:meth:`Imu.row`)."""
(
    IMU_RATE,
    IMU_GYRO_NOISE,
    IMU_GYRO_BIAS_WALK,
    IMU_GYRO_BIAS_INIT,
    IMU_GYRO_RANGE,
    IMU_GYRO_LSB,
    IMU_ACCEL_NOISE,
    IMU_ACCEL_BIAS_WALK,
    IMU_ACCEL_BIAS_INIT,
    IMU_ACCEL_RANGE,
    IMU_ACCEL_LSB,
    IMU_SCALE_ERROR,
    IMU_MISALIGNMENT,
    IMU_VIBRATION,
) = IMU_ROW.offsets


BMI088 = Imu(
    rate=400.0,
    gyro_noise=0.014 * DEG,
    gyro_bias_walk=0.0,
    gyro_bias_init=1.0 * DEG,
    gyro_range=2000.0 * DEG,
    gyro_lsb=2000.0 * DEG / 32767.0,
    accel_noise=175e-6 * G0,
    accel_bias_walk=0.0,
    accel_bias_init=20e-3 * G0,
    accel_range=24.0 * G0,
    accel_lsb=24.0 * G0 / 32767.0,
)
"""Bosch BMI088 (BST-BMI088-DS001): gyro noise density 0.014 deg/s/sqrt(Hz) (checked: the datasheet's
value as Bosch's community moderators quote it), range 2000 deg/s on 16 bits (checked: datasheet
section 5.5.2), accelerometer range 24 g on 16 bits (checked: datasheet "up to 24 g"). Not checked
against the datasheet here: the accelerometer density 175 ug/sqrt(Hz) and the switch-on biases
(1 deg/s, 20 mg) are typical values as commonly quoted; the bias walks are left at 0 (datasheets
give no random-walk figure; set them from an Allan deviation of your own unit)."""

ICM42688P = Imu(
    rate=1000.0,
    gyro_noise=2.8e-3 * DEG,
    gyro_bias_walk=0.0,
    gyro_bias_init=0.5 * DEG,
    gyro_range=2000.0 * DEG,
    gyro_lsb=2000.0 * DEG / 32767.0,
    accel_noise=70e-6 * G0,
    accel_bias_walk=0.0,
    accel_bias_init=20e-3 * G0,
    accel_range=16.0 * G0,
    accel_lsb=16.0 * G0 / 32767.0,
)
"""TDK InvenSense ICM-42688-P: gyro 2.8 mdps/sqrt(Hz), accelerometer 70 ug/sqrt(Hz), 2000 deg/s and
16 g on 16 bits. Not checked against the ICM-42688-P datasheet here (its sibling ICM-42605's
DS-000292 rev 1.5, which was found, gives 3.8 mdps/sqrt(Hz) and 70 ug/sqrt(Hz)); the switch-on
biases are typical values, the bias walks 0 as for :data:`BMI088`."""


@njit(cache=True)
def imu_start(row, st, s):
    """Switch an IMU on: draw its biases, scale factors and misalignment into ``st``.

    Parameters
    ----------
    row : numpy.ndarray
        :meth:`Imu.row`.
    st : numpy.ndarray
        (STATE_SIZE,) float64, written.
    s : numpy.uint64
        Generator state (:func:`quadcruise.sim.rng.vehicle_states`).

    Returns
    -------
    numpy.uint64
        The advanced generator state.
    """
    for i in range(3):
        b, s = noisy(0.0, 0.0, row[IMU_GYRO_BIAS_INIT], s)
        st[ST_BG + i] = b
        b, s = noisy(0.0, 0.0, row[IMU_ACCEL_BIAS_INIT], s)
        st[ST_BA + i] = b
    for m in (ST_MG, ST_MA):
        for i in range(3):
            for j in range(3):
                if i == j:
                    e, s = noisy(1.0, 0.0, row[IMU_SCALE_ERROR], s)
                else:
                    e, s = noisy(0.0, 0.0, row[IMU_MISALIGNMENT], s)
                st[m + 3 * i + j] = e
    return s


@njit(cache=True)
def imu_read(row, st, wx, wy, wz, fx, fy, fz, out, s):
    """One IMU sample of the true rates and specific force (FLU) into ``out`` (gyro, accel);
    the biases then walk by one period ``1 / rate``.

    Parameters
    ----------
    row, st : numpy.ndarray
        :meth:`Imu.row`; the IMU's state from :func:`imu_start`, updated.
    wx, wy, wz : float
        True body rates [rad/s].
    fx, fy, fz : float
        True specific force [m/s^2] (acceleration minus gravity, in the body frame).
    out : numpy.ndarray
        (6,) float64, written: gyro [rad/s], accelerometer [m/s^2].
    s : numpy.uint64
        Generator state.

    Returns
    -------
    numpy.uint64
        The advanced generator state.
    """
    rate = row[IMU_RATE]
    gstd, astd = sample_std(row[IMU_GYRO_NOISE], rate), sample_std(row[IMU_ACCEL_NOISE], rate)
    for i in range(3):
        g = st[ST_MG + 3 * i] * wx + st[ST_MG + 3 * i + 1] * wy + st[ST_MG + 3 * i + 2] * wz
        a = st[ST_MA + 3 * i] * fx + st[ST_MA + 3 * i + 1] * fy + st[ST_MA + 3 * i + 2] * fz
        g, s = noisy(g, st[ST_BG + i], gstd, s)
        a, s = noisy(a, st[ST_BA + i], astd, s)
        out[i] = digitise(g, row[IMU_GYRO_LSB], row[IMU_GYRO_RANGE])
        out[3 + i] = digitise(a, row[IMU_ACCEL_LSB], row[IMU_ACCEL_RANGE])
    for i in range(3):
        st[ST_BG + i], s = walk(st[ST_BG + i], row[IMU_GYRO_BIAS_WALK], 1.0 / rate, s)
        st[ST_BA + i], s = walk(st[ST_BA + i], row[IMU_ACCEL_BIAS_WALK], 1.0 / rate, s)
    return s


@njit(cache=True)
def imu_series(row, st, rates, forces, out, s):
    """:func:`imu_read` over a series: ``rates``, ``forces`` (K, 3) sampled at the IMU's rate.

    Parameters
    ----------
    row, st : numpy.ndarray
        :meth:`Imu.row`; the state from :func:`imu_start`, updated.
    rates, forces : numpy.ndarray
        (K, 3) true body rates [rad/s] and specific forces [m/s^2].
    out : numpy.ndarray
        (K, 6) float64, written.
    s : numpy.uint64
        Generator state.

    Returns
    -------
    numpy.uint64
        The advanced generator state.
    """
    for k in range(rates.shape[0]):
        s = imu_read(
            row, st, rates[k, 0], rates[k, 1], rates[k, 2], forces[k, 0], forces[k, 1], forces[k, 2], out[k], s
        )
    return s
