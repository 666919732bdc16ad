"""``fly``'s sensors and estimator: the flight's :class:`~quadcruise.sim.observe.Observation` from
the objects a user gives (:class:`~quadcruise.estimation.Sensors`, :class:`~quadcruise.estimation.Ekf`),
checked before any work, and what the output folder records of them.

Examples
--------
>>> from quadcruise.estimation import Ekf, Sensors
>>> obs, record = onboard_inputs(Sensors.typical(), Ekf(), g=9.81, n=1, dt=1e-3, seed=0, first_vehicle=0)
>>> obs.active, sorted(record)
(True, ['estimator', 'sensor_models'])
"""

from __future__ import annotations

from typing import Any

import numpy as np

from quadcruise.errors import InputError
from quadcruise.estimation.onboard import PARAMS
from quadcruise.estimation.stage import Ekf, Sensors, check_estimator, observation
from quadcruise.sim.observe import Observation


def onboard_inputs(
    sensors: Any, estimator: Any, *, g: float, n: int, dt: float, seed: int, first_vehicle: Any, where: str = "fly()"
) -> tuple[Observation | None, dict]:
    """The observation stage of a flight and its record, or (None, {}) without sensor models.

    Parameters
    ----------
    sensors : Sensors, tuple of Sensors, SensorNoise or None
        Sensor models (a :class:`Sensors`, or one per vehicle: a population's spread sensors,
        the same sensors and rates), or the white noise on the truth (handled by the engine's
        ``sensor_std``: not here).
    estimator : Ekf or None
        The filter (needs :class:`Sensors` with an IMU and a GPS).
    g : float
        The vehicle's gravity [m/s^2], which the filter assumes.
    n : int
        Vehicles.
    dt : float
        Control period [s].
    seed : int
        The flight's seed.
    first_vehicle : int or (n,) array of int
        The vehicles' indices (their sensor streams).
    where : str
        How messages name the call.

    Returns
    -------
    tuple
        (Observation or None, ``{"sensor_models": ..., "estimator": ...}`` for the result's meta:
        each sensor's fields, the filter's settings, as a scenario's ``[sensors]`` and
        ``[estimator]`` tables read them back).

    Raises
    ------
    InputError
        An estimator that is not an :class:`Ekf`, or without the sensor models it needs; a sensor
        rate that does not divide the control rate.
    """
    if estimator is not None and not isinstance(estimator, Ekf):
        raise InputError(f"{where} argument estimator: expected an Ekf, got {type(estimator).__name__}")
    if isinstance(sensors, (tuple, list)):
        return _each_vehicle(
            tuple(sensors), estimator, g=g, n=n, dt=dt, seed=seed, first_vehicle=first_vehicle, where=where
        )
    if not isinstance(sensors, Sensors):
        if estimator is not None:
            check_estimator(None, estimator, f"{where} argument estimator:")
        return None, {}
    check_estimator(sensors, estimator, f"{where} argument estimator:")
    obs = observation(sensors, estimator, n=n, dt=dt, seed=seed, first_vehicle=first_vehicle, g=float(g))
    return obs, {"sensor_models": sensors.to_dict(), "estimator": None if estimator is None else estimator.to_dict()}


def _each_vehicle(sensors: tuple, estimator, *, g, n, dt, seed, first_vehicle, where) -> tuple[Observation, dict]:
    """The observation stage of one :class:`Sensors` per vehicle (a population's spread sensors):
    the same sensors carried at the same rates and latency, each vehicle's own models' rows; the
    filter's settings the first's (give :attr:`Ekf.noise` to match it to another)."""
    if len(sensors) != n or not all(isinstance(s, Sensors) for s in sensors):
        raise InputError(f"{where} argument sensors: a sequence must hold one Sensors per vehicle ({n})")
    first = sensors[0]
    timing = [(name, getattr(first, name).rate) for name in first.names()]
    for k, s in enumerate(sensors):
        if [(name, getattr(s, name).rate) for name in s.names()] != timing or (
            first.gps is not None and s.gps.latency != first.gps.latency
        ):
            raise InputError(
                f"{where} argument sensors: vehicle {k} carries other sensors, rates or GPS latency than vehicle 0"
            )
    obs, record = onboard_inputs(first, estimator, g=g, n=n, dt=dt, seed=seed, first_vehicle=first_vehicle, where=where)
    for name in first.names():  # each vehicle's own noise, bias and range
        width = getattr(first, name).row().size
        at = dict(zip((f for f, _ in PARAMS.fields), PARAMS.offsets, strict=True))[name]
        obs.params[:, at : at + width] = np.stack([getattr(s, name).row() for s in sensors])
    record["sensor_models_each"] = [s.to_dict() for s in sensors]
    return obs, record


def vehicle_gravity(vehicle: Any) -> float:
    """The gravity [m/s^2] of a vehicle, a batch's first, or a list's first.

    Examples
    --------
    >>> from quadcruise.model.vehicle import Vehicle
    >>> vehicle_gravity(Vehicle.paper())
    9.81
    """
    first = vehicle[0] if isinstance(vehicle, tuple) else vehicle
    return float(np.ravel(first.g)[0])


__all__ = ["onboard_inputs", "vehicle_gravity"]
