"""A barometric altimeter: the altitude with an offset that drifts, and white noise.

    h_k = z(t_k) + b_k + sigma * w_k,    b_0 ~ N(0, bias_init^2),    b_{k+1} = b_k + r * sqrt(dt) * v_k

``r`` (``drift``, [m/sqrt(s)]) models the weather's and the board's temperature drift as a
random walk; ``w``, ``v`` standard normal.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from numba import njit

from quadcruise.fields import unit_field
from quadcruise.sensors.model import SensorModel
from quadcruise.sensors.noise import noisy, sample_times, walk
from quadcruise.sim.rng import vehicle_states


@dataclass(frozen=True)
class Baro(SensorModel):
    """A barometer's parameters.

    Parameters
    ----------
    rate : float
        Sample rate [Hz], > 0.
    noise_std : float
        White noise std of one reading [m], >= 0.
    bias_init : float
        Std of the offset at switch-on [m], >= 0.
    drift : float
        Random walk of the offset [m/sqrt(s)], >= 0.

    Examples
    --------
    >>> Baro().rate
    50.0
    """

    rate: float = unit_field(50.0, "Hz", "sample rate", "pos")
    noise_std: float = unit_field(0.1, "m", "altitude noise std", "nonneg")
    bias_init: float = unit_field(0.0, "m", "switch-on offset std", "nonneg")
    drift: float = unit_field(0.0, "m/sqrt(s)", "offset random walk", "nonneg")
    name = "baro"

    def measure(self, t: np.ndarray, z: np.ndarray, seed: int, vehicle: int = 0) -> tuple:
        """The readings of a true altitude, from an explicit seed.

        Parameters
        ----------
        t : numpy.ndarray
            (L,) increasing times [s].
        z : numpy.ndarray
            (L,) true altitude (ENU z) [m], linearly interpolated.
        seed : int
            The run's seed, >= 0.
        vehicle : int
            The vehicle's index (its own stream).

        Returns
        -------
        tuple of numpy.ndarray
            Sample times (K,) [s], readings (K,) [m], the offset at each (K,) [m].

        Examples
        --------
        >>> import numpy as np
        >>> ts, h, b = Baro(rate=2.0, noise_std=0.0).measure(np.array([0.0, 1.0]), np.array([1.0, 2.0]), seed=1)
        >>> h.tolist()
        [1.0, 1.5, 2.0]
        """
        ts = sample_times(float(t[0]), float(t[-1]), self.rate)
        out, bias = np.interp(ts, t, z), np.empty(ts.size)
        baro_series(
            self.row(),
            out,
            bias,
            vehicle_states(seed, 1, first=vehicle)[0, 0],
        )
        return ts, out, bias


BARO_ROW = Baro.layout("BARO_")
"""The compiled functions' parameter row: :class:`Baro`'s fields in order (:meth:`Baro.row`)."""
BARO_RATE, BARO_NOISE_STD, BARO_BIAS_INIT, BARO_DRIFT = BARO_ROW.offsets


@njit(cache=True)
def baro_read(row, st, z, s):
    """One reading of the true altitude ``z`` [m]; the offset ``st[0]`` then walks one period.

    Parameters
    ----------
    row : numpy.ndarray
        :meth:`Baro.row` (rate, noise_std, bias_init, drift).
    st : numpy.ndarray
        (1,) the offset [m] (drawn at switch-on with std ``bias_init`` by the caller), updated.
    z : float
        True altitude [m].
    s : numpy.uint64
        Generator state.

    Returns
    -------
    tuple
        (the reading [m], the advanced generator state).
    """
    h, s = noisy(z, st[0], row[BARO_NOISE_STD], s)
    st[0], s = walk(st[0], row[BARO_DRIFT], 1.0 / row[BARO_RATE], s)
    return h, s


@njit(cache=True)
def baro_series(row, h, bias, s):
    """Readings in place of the true altitudes ``h`` (K,) and their offsets into ``bias``.

    Parameters
    ----------
    row : numpy.ndarray
        :meth:`Baro.row` (rate, noise_std, bias_init, drift).
    h : numpy.ndarray
        (K,) true altitude [m], overwritten by the readings.
    bias : numpy.ndarray
        (K,) float64, written: the offset of each reading [m].
    s : numpy.uint64
        Generator state.

    Returns
    -------
    numpy.uint64
        The advanced generator state.
    """
    st = np.empty(1)
    st[0], s = noisy(0.0, 0.0, row[BARO_BIAS_INIT], s)
    for k in range(h.shape[0]):
        bias[k] = st[0]
        h[k], s = baro_read(row, st, h[k], s)
    return s
