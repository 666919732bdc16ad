"""A GNSS receiver: position and velocity at its own rate, late, noisy, with an optional outage.

A fix sampled at ``t`` (``k / rate``) reads the truth at ``t`` plus white noise (horizontal
and vertical standard deviations apart) and arrives ``latency`` seconds later; none is given
in ``[outage_start, outage_start + outage_duration)``. Noise is white: a real receiver's
position error is correlated over seconds to minutes, which this model leaves out.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from numba import njit

from quadcruise.fields import unit_field
from quadcruise.sensors.model import SensorModel
from quadcruise.sensors.noise import noisy, sample_times
from quadcruise.sim.rng import vehicle_states


@dataclass(frozen=True)
class Gps(SensorModel):
    """A GNSS receiver's parameters.

    Parameters
    ----------
    rate : float
        Fix rate [Hz], > 0 (5-10 Hz typical).
    latency : float
        Time from the sample to its arrival [s], >= 0.
    horizontal_std : float
        Position noise std, east and north [m], >= 0.
    vertical_std : float
        Position noise std, up [m], >= 0.
    velocity_std : float
        Velocity noise std, east and north [m/s], >= 0.
    vertical_velocity_std : float
        Velocity noise std, up [m/s], >= 0.
    outage_start : float
        Start of an outage [s] (flight time), >= 0.
    outage_duration : float
        Its length [s], >= 0 (0: none).

    Examples
    --------
    >>> float(Gps(rate=5.0).row()[0])
    5.0
    """

    rate: float = unit_field(10.0, "Hz", "fix rate", "pos")
    latency: float = unit_field(0.0, "s", "latency", "nonneg")
    horizontal_std: float = unit_field(0.5, "m", "horizontal position noise std", "nonneg")
    vertical_std: float = unit_field(0.8, "m", "vertical position noise std", "nonneg")
    velocity_std: float = unit_field(0.1, "m/s", "horizontal velocity noise std", "nonneg")
    vertical_velocity_std: float = unit_field(0.15, "m/s", "vertical velocity noise std", "nonneg")
    outage_start: float = unit_field(0.0, "s", "outage start", "nonneg")
    outage_duration: float = unit_field(0.0, "s", "outage duration", "nonneg")
    name = "gps"

    def measure(self, t: np.ndarray, position: np.ndarray, velocity: np.ndarray, seed: int, vehicle: int = 0) -> tuple:
        """The fixes of a true trajectory, from an explicit seed.

        Parameters
        ----------
        t : numpy.ndarray
            (L,) increasing times [s] of the truth.
        position, velocity : numpy.ndarray
            (L, 3) true ENU position [m] and velocity [m/s], linearly interpolated.
        seed : int
            The run's seed, >= 0.
        vehicle : int
            The vehicle's index (its own stream).

        Returns
        -------
        tuple of numpy.ndarray
            Sample times (K,) [s], arrival times (K,) [s] and the fixes (K, 6): position [m],
            velocity [m/s].

        Examples
        --------
        >>> import numpy as np
        >>> t = np.linspace(0.0, 1.0, 11)
        >>> ts, ta, z = Gps(rate=5.0, latency=0.1).measure(t, np.zeros((11, 3)), np.zeros((11, 3)), seed=1)
        >>> ts.tolist(), (ta - ts).round(3).tolist()[0], z.shape
        ([0.0, 0.2, 0.4, 0.6, 0.8, 1.0], 0.1, (6, 6))
        """
        ts = sample_times(float(t[0]), float(t[-1]), self.rate)
        if self.outage_duration > 0:
            ts = ts[(ts < self.outage_start) | (ts >= self.outage_start + self.outage_duration)]
        truth = np.column_stack([np.interp(ts, t, c) for c in np.column_stack([position, velocity]).T])
        out = np.empty_like(truth)
        gps_series(self.row(), truth, out, vehicle_states(seed, 1, first=vehicle)[0, 0])
        return ts, ts + self.latency, out


GPS_ROW = Gps.layout("GPS_")
"""The compiled functions' parameter row: :class:`Gps`'s fields in order (:meth:`Gps.row`)."""
(
    GPS_RATE,
    GPS_LATENCY,
    GPS_HORIZONTAL_STD,
    GPS_VERTICAL_STD,
    GPS_VELOCITY_STD,
    GPS_VERTICAL_VELOCITY_STD,
    GPS_OUTAGE_START,
    GPS_OUTAGE_DURATION,
) = GPS_ROW.offsets


@njit(cache=True)
def gps_read(row, px, py, pz, vx, vy, vz, out, s):
    """One fix of the true ENU position and velocity into ``out`` (6,).

    Parameters
    ----------
    row : numpy.ndarray
        :meth:`Gps.row`.
    px, py, pz, vx, vy, vz : float
        True position [m] and velocity [m/s], ENU.
    out : numpy.ndarray
        (6,) float64, written.
    s : numpy.uint64
        Generator state.

    Returns
    -------
    numpy.uint64
        The advanced generator state.
    """
    out[0], s = noisy(px, 0.0, row[GPS_HORIZONTAL_STD], s)
    out[1], s = noisy(py, 0.0, row[GPS_HORIZONTAL_STD], s)
    out[2], s = noisy(pz, 0.0, row[GPS_VERTICAL_STD], s)
    out[3], s = noisy(vx, 0.0, row[GPS_VELOCITY_STD], s)
    out[4], s = noisy(vy, 0.0, row[GPS_VELOCITY_STD], s)
    out[5], s = noisy(vz, 0.0, row[GPS_VERTICAL_VELOCITY_STD], s)
    return s


@njit(cache=True)
def gps_series(row, truth, out, s):
    """:func:`gps_read` over (K, 6) true rows into ``out`` (K, 6); returns the generator state."""
    for k in range(truth.shape[0]):
        s = gps_read(row, truth[k, 0], truth[k, 1], truth[k, 2], truth[k, 3], truth[k, 4], truth[k, 5], out[k], s)
    return s
