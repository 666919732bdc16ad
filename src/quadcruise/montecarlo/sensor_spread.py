"""A population's sensors: the sensor models every vehicle carries
(:class:`~quadcruise.estimation.Sensors`), the estimator it flies on
(:class:`~quadcruise.estimation.Ekf`), and their spreads drawn per vehicle.

A spread is relative, as the vehicle's are: vehicle i's IMU has its noise densities, bias walks
and switch-on bias spreads each times ``1 + imu_noise_spread * z[14]``, its GPS its four noise
standard deviations times ``1 + gps_noise_spread * z[15]``, with ``z`` the vehicle's unit draws
(:meth:`~quadcruise.montecarlo.population.Population.unit_draws`, the two spare slots: turning
a sensor spread on moves no other draw). The filter stays matched to the *nominal* sensors (its
noise settings are the datasheet's, given outright: :attr:`~quadcruise.estimation.Ekf.noise`), as
on a real fleet whose units scatter around the datasheet.

Examples
--------
>>> import numpy as np
>>> from quadcruise.estimation import Ekf, Sensors
>>> z = np.zeros((2, 16)); z[:, IMU_SLOT] = [-1.0, 1.0]
>>> each, ekf, cols = drawn_sensors(Sensors.typical(), Ekf(), 0.2, 0.0, z, g=9.81)
>>> [round(s.imu.gyro_noise / Sensors.typical().imu.gyro_noise, 3) for s in each], cols["imu_noise_factor"].tolist()
([0.8, 1.2], [0.8, 1.2])
"""

from __future__ import annotations

import dataclasses
from typing import Any

import numpy as np

from quadcruise.errors import InputError

__all__ = ["GPS_FIELDS", "GPS_SLOT", "IMU_FIELDS", "IMU_SLOT", "SENSOR_SPREADS", "check_sensors", "drawn_sensors"]

IMU_SLOT, GPS_SLOT = 14, 15
"""The unit draws of a vehicle (:data:`~quadcruise.montecarlo.population.N_DRAWS`) that feed its
IMU's and its GPS's noise factor."""
IMU_FIELDS = ("gyro_noise", "gyro_bias_walk", "gyro_bias_init", "accel_noise", "accel_bias_walk", "accel_bias_init")
"""The IMU's fields ``imu_noise_spread`` scales (densities [../sqrt(Hz)], walks, switch-on spreads)."""
GPS_FIELDS = ("horizontal_std", "vertical_std", "velocity_std", "vertical_velocity_std")
"""The GPS's fields ``gps_noise_spread`` scales [m], [m/s]."""
SENSOR_SPREADS = {"imu_noise_spread": ("imu", IMU_SLOT, IMU_FIELDS), "gps_noise_spread": ("gps", GPS_SLOT, GPS_FIELDS)}
"""Each sensor spread: the sensor it perturbs, its unit draw's slot, the fields scaled."""


def check_sensors(sensors: Any, estimator: Any, noise: Any, spreads: dict) -> None:
    """Refuse, in one line, a population's sensors that cannot fly.

    Parameters
    ----------
    sensors : Sensors or None
    estimator : Ekf or None
    noise : SensorNoise or None
        The white noise on the truth (the other way to perturb what the controller sees).
    spreads : dict
        ``imu_noise_spread`` and ``gps_noise_spread`` (already checked numbers >= 0).

    Raises
    ------
    InputError
        Sensors that are not a Sensors, an estimator not an Ekf or without the sensors it needs,
        both sensor models and sensor noise, a spread of a sensor not carried.
    """
    from quadcruise.estimation.stage import Ekf, Sensors, check_estimator

    if sensors is not None and not isinstance(sensors, Sensors):
        raise InputError(f"population field 'sensors' must be a Sensors or None, got {type(sensors).__name__}")
    if estimator is not None and not isinstance(estimator, Ekf):
        raise InputError(f"population field 'estimator' must be an Ekf or None, got {type(estimator).__name__}")
    if sensors is not None and noise is not None:
        raise InputError(
            "population fields 'sensors' and 'noise' both perturb what the controller sees: give one "
            "(sensor models, or white noise on the truth)"
        )
    check_estimator(sensors, estimator, "population field 'estimator':")
    for name, (kind, _, _) in SENSOR_SPREADS.items():
        if spreads[name] > 0 and (sensors is None or getattr(sensors, kind) is None):
            raise InputError(
                f"population field '{name}' spreads the {kind}'s noise; the population's sensors carry no {kind}"
            )


def drawn_sensors(sensors, estimator, imu_spread: float, gps_spread: float, z: np.ndarray, g: float):
    """Each vehicle's sensors and the filter they fly on.

    Parameters
    ----------
    sensors : Sensors
        The nominal sensors.
    estimator : Ekf or None
        The filter (matched to the nominal sensors when spreads are drawn).
    imu_spread, gps_spread : float
        Relative standard deviations [-] of the IMU's and the GPS's noise.
    z : numpy.ndarray
        (count, 16) the vehicles' unit draws.
    g : float
        Gravity [m/s^2] the filter assumes.

    Returns
    -------
    (Sensors or tuple of Sensors, Ekf or None, dict)
        The nominal sensors themselves when nothing is spread, else one per vehicle; the filter;
        the table's columns ``imu_noise_factor`` and ``gps_noise_factor`` [-].
    """
    count = z.shape[0]
    factors = {
        "imu": 1.0 + imu_spread * z[:, IMU_SLOT] if imu_spread > 0 else np.ones(count),
        "gps": 1.0 + gps_spread * z[:, GPS_SLOT] if gps_spread > 0 else np.ones(count),
    }
    columns = {"imu_noise_factor": factors["imu"].copy(), "gps_noise_factor": factors["gps"].copy()}
    if imu_spread == 0 and gps_spread == 0:
        return sensors, estimator, columns
    if estimator is not None and estimator.noise is None:  # matched to the datasheet, not to each unit
        estimator = dataclasses.replace(estimator, noise=estimator.settings(sensors, g))
    each = []
    for k in range(count):
        changes = {}
        for _, (kind, _, fields) in SENSOR_SPREADS.items():
            model = getattr(sensors, kind)
            if model is not None and factors[kind][k] != 1.0:
                changes[kind] = dataclasses.replace(model, **{f: getattr(model, f) * factors[kind][k] for f in fields})
        each.append(dataclasses.replace(sensors, **changes))
    return tuple(each), estimator, columns
