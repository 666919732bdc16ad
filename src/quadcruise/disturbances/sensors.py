"""What the controller sees: white noise on the state and a delay."""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any

import numpy as np

from quadcruise.disturbances.part import Part
from quadcruise.disturbances.part import batch_field as _f
from quadcruise.errors import InputError
from quadcruise.layout import PHI, STATE_SIZE, VX, P, X


@dataclass(frozen=True)
class SensorNoise(Part):
    """White noise on what the controller sees, and a delay (a whole number of periods).

    Parameters
    ----------
    position_std : float or array
        Standard deviation of the noise on x, y and z [m], >= 0.
    velocity_std : float or array
        On the velocity [m/s], >= 0.
    angle_std : float or array
        On roll, pitch and yaw [rad], >= 0.
    rate_std : float or array
        On the body rates p, q, r [rad/s], >= 0.
    delay : float
        Sensor delay [s], >= 0, a whole number of control periods, the same for every
        vehicle.
    """

    position_std: Any = _f(0.0, "m", "position noise std", "nonneg")
    velocity_std: Any = _f(0.0, "m/s", "velocity noise std", "nonneg")
    angle_std: Any = _f(0.0, "rad", "angle noise std", "nonneg")
    rate_std: Any = _f(0.0, "rad/s", "body rate noise std", "nonneg")
    delay: Any = _f(0.0, "s", "sensor delay", "nonneg")
    name = "sensor"

    def std_vector(self) -> np.ndarray:
        """(16,) standard deviations per state ((N, 16) if a field is per-vehicle); rotors 0.

        Returns
        -------
        numpy.ndarray
            (STATE_SIZE,) or (N, STATE_SIZE) float64, in the state's units ([m], [m/s],
            [rad], [rad/s]); 0 for the rotor thrusts.

        Examples
        --------
        >>> SensorNoise(position_std=0.01).std_vector()[:4].tolist()
        [0.01, 0.01, 0.01, 0.0]
        """
        size = self.one_size(self.sizes(), "sensor")
        out = np.zeros((size or 1, STATE_SIZE))
        for name, j in (("position_std", X), ("velocity_std", VX), ("angle_std", PHI), ("rate_std", P)):
            out[:, j : j + 3] = np.asarray(getattr(self, name))[..., None]
        return out if size else out[0]

    def delay_periods(self, dt: float) -> int:
        """The delay in control periods; it must be a whole number of dt (to 1e-9 s).

        Parameters
        ----------
        dt : float
            Control period [s], > 0.

        Returns
        -------
        int
            delay / dt.

        Raises
        ------
        InputError
            A per-vehicle delay, or one that is not a whole number of periods.

        Examples
        --------
        >>> SensorNoise(delay=0.005).delay_periods(0.001)
        5
        """
        if np.ndim(self.delay):
            raise InputError("sensor field 'delay' must be one number for the whole batch")
        k = round(self.delay / dt)
        if abs(k * dt - self.delay) > 1e-9:
            raise InputError(f"sensor field 'delay' ({self.delay:g} s) is not a whole number of dt ({dt:g} s) periods")
        return int(k)

    def check_fits(self, duration: float) -> None:
        """Refuse a delay longer than the flight (its history buffer would be allocated first).

        Parameters
        ----------
        duration : float
            Flight time [s].

        Raises
        ------
        InputError
            Saying the delay and the flight time.

        Examples
        --------
        >>> SensorNoise(delay=30.0).check_fits(20.0)
        Traceback (most recent call last):
            ...
        quadcruise.errors.InputError: sensor field 'delay' (30 s) is longer than the flight (20 s)
        """
        if np.max(self.delay) > duration:
            raise InputError(
                f"sensor field 'delay' ({np.max(self.delay):g} s) is longer than the flight ({float(duration):g} s)"
            )

    def kwargs(self, dt: float) -> dict:
        """``sensor_std`` and ``sensor_delay`` for simulate/fly.

        Parameters
        ----------
        dt : float
            Control period [s], > 0.

        Returns
        -------
        dict
            ``sensor_std``: :meth:`std_vector`; ``sensor_delay``: :meth:`delay_periods`.
        """
        return {"sensor_std": self.std_vector(), "sensor_delay": self.delay_periods(dt)}
