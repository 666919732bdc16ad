"""A magnetometer: the earth's field in the body frame, with a hard-iron bias and noise.

The world field (ENU) of strength F, declination D (east of north) and inclination I (down
from horizontal) is ``B = F (cos I sin D, cos I cos D, -sin I)``; a reading is
``R^T B + b + sigma w`` with ``R`` the attitude (FLU body to ENU world), ``b`` a bias drawn
once per vehicle (std ``bias_std`` per axis) and w standard normal.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
from numba import njit
from scipy.spatial.transform import Rotation

from quadcruise.fields import unit_field
from quadcruise.sensors.model import SensorModel
from quadcruise.sensors.noise import noisy, sample_times
from quadcruise.sim.rng import vehicle_states


@dataclass(frozen=True)
class Magnetometer(SensorModel):
    """A magnetometer's parameters and the field it sits in.

    Parameters
    ----------
    rate : float
        Sample rate [Hz], > 0.
    strength : float
        Field strength [G] (gauss, PX4's unit; 1 G = 100 uT), > 0.
    declination : float
        Angle of the field's horizontal part east of north [rad].
    inclination : float
        Angle of the field below the horizontal [rad] (positive in the northern hemisphere).
    noise_std : float
        White noise std per axis [G], >= 0.
    bias_std : float
        Std of the hard-iron bias per axis, drawn once [G], >= 0.

    Examples
    --------
    >>> import numpy as np
    >>> np.round(Magnetometer(declination=0.0, inclination=0.0).world_field(), 3).tolist()
    [0.0, 0.5, -0.0]
    """

    rate: float = unit_field(50.0, "Hz", "sample rate", "pos")
    strength: float = unit_field(0.5, "G", "field strength", "pos")
    declination: float = unit_field(0.0, "rad", "declination (east of north)", "real")
    inclination: float = unit_field(math.radians(60.0), "rad", "inclination (below horizontal)", "real")
    noise_std: float = unit_field(0.005, "G", "noise std", "nonneg")
    bias_std: float = unit_field(0.0, "G", "hard-iron bias std", "nonneg")
    name = "mag"

    def world_field(self) -> np.ndarray:
        """The field in the ENU world frame [G].

        Returns
        -------
        numpy.ndarray
            (3,) float64: ``F (cos I sin D, cos I cos D, -sin I)``.
        """
        d, i = self.declination, self.inclination
        return self.strength * np.array([math.cos(i) * math.sin(d), math.cos(i) * math.cos(d), -math.sin(i)])

    def measure(self, t: np.ndarray, quaternion: np.ndarray, seed: int, vehicle: int = 0) -> tuple:
        """The readings along a true attitude history, from an explicit seed.

        Parameters
        ----------
        t : numpy.ndarray
            (L,) increasing times [s].
        quaternion : numpy.ndarray
            (L, 4) attitude, w first, FLU body to ENU world; held from the last instant at or
            before each sample.
        seed : int
            The run's seed, >= 0.
        vehicle : int
            The vehicle's index (its own stream).

        Returns
        -------
        tuple of numpy.ndarray
            Sample times (K,) [s], readings (K, 3) [G] (FLU), the bias (3,) [G].

        Examples
        --------
        >>> import numpy as np
        >>> m = Magnetometer(rate=1.0, noise_std=0.0, declination=0.0, inclination=0.0)
        >>> ts, z, b = m.measure(np.array([0.0, 1.0]), np.array([[1.0, 0, 0, 0]] * 2), seed=1)
        >>> np.round(z[0], 3).tolist()                     # nose east: north is on the left
        [0.0, 0.5, 0.0]
        """
        ts = sample_times(float(t[0]), float(t[-1]), self.rate)
        k = np.clip(np.searchsorted(t, ts + 1e-12, side="right") - 1, 0, len(t) - 1)
        q = np.asarray(quaternion, float)[k]
        out = Rotation.from_quat(q[:, [1, 2, 3, 0]]).inv().apply(self.world_field())
        bias = np.zeros(3)
        mag_series(self.row(), out, bias, vehicle_states(seed, 1, first=vehicle)[0, 0])
        return ts, out, bias


MAG_ROW = Magnetometer.layout("MAG_")
"""The compiled functions' parameter row: :class:`Magnetometer`'s fields in order
(:meth:`Magnetometer.row`)."""
MAG_RATE, MAG_STRENGTH, MAG_DECLINATION, MAG_INCLINATION, MAG_NOISE_STD, MAG_BIAS_STD = MAG_ROW.offsets


@njit(cache=True)
def mag_read(row, bias, bx, by, bz, out, s):
    """One reading of the true body field (bx, by, bz) [G] into ``out`` (3,).

    Parameters
    ----------
    row : numpy.ndarray
        :meth:`Magnetometer.row`.
    bias : numpy.ndarray
        (3,) the hard-iron bias [G].
    bx, by, bz : float
        The true field in the body frame [G], ``R^T B``.
    out : numpy.ndarray
        (3,) float64, written.
    s : numpy.uint64
        Generator state.

    Returns
    -------
    numpy.uint64
        The advanced generator state.
    """
    out[0], s = noisy(bx, bias[0], row[MAG_NOISE_STD], s)
    out[1], s = noisy(by, bias[1], row[MAG_NOISE_STD], s)
    out[2], s = noisy(bz, bias[2], row[MAG_NOISE_STD], s)
    return s


@njit(cache=True)
def mag_series(row, field, bias, s):
    """Readings in place of the true body fields ``field`` (K, 3); the drawn bias into ``bias``.

    Parameters
    ----------
    row : numpy.ndarray
        :meth:`Magnetometer.row`.
    field : numpy.ndarray
        (K, 3) true field in the body frame [G], overwritten by the readings.
    bias : numpy.ndarray
        (3,) float64, written.
    s : numpy.uint64
        Generator state.

    Returns
    -------
    numpy.uint64
        The advanced generator state.
    """
    for i in range(3):
        bias[i], s = noisy(0.0, 0.0, row[MAG_BIAS_STD], s)
    for k in range(field.shape[0]):
        s = mag_read(row, bias, field[k, 0], field[k, 1], field[k, 2], field[k], s)
    return s
