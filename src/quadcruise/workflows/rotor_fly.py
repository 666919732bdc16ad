"""``fly``'s vehicle and controller before a flight: the vehicle by preset name (or a list of
rotor-plant vehicles, :func:`as_vehicle`), its plant (:mod:`quadcruise.sim.plants`), and a named
controller's gains designed for the vehicle it believes where the plant asks for it
(:func:`flight_setup`). The rotor plant's own flight helpers (initial hover and states, its
arrays, its record) are described with the plant, :mod:`quadcruise.sim.plants.rotor`, and
exported here as before.

Gains: a controller given by name (``"se3"``) is designed for the controller vehicle's motor
bandwidth, the ``omega`` = 1 / tau_up of its equivalent paper vehicle
(:func:`quadcruise.model.equivalent.paper_equivalent`), by the same rules that give the
paper's vehicle its default gains at 15 rad/s (:func:`designed_controller`). The attitude
gains of every built-in controller are per unit inertia, so the bandwidth is the only vehicle
parameter they need; the position gains place the paper's poles for any mass. A controller
object is flown with the gains it has.

Examples
--------
>>> designed_controller("se3", 80.0).attitude.kp      # (0.6 x 80 rad/s)^2
2304.0
"""

from __future__ import annotations

import dataclasses
from typing import Any

from quadcruise.control import CONTROLLERS, controller_from_name
from quadcruise.control.registry import rotor_gains
from quadcruise.errors import InputError
from quadcruise.model.rotor_vehicle import RotorVehicle
from quadcruise.model.vehicle import Vehicle
from quadcruise.sim import plants
from quadcruise.sim.plants import Plant
from quadcruise.sim.plants.rotor import (  # the rotor plant's flight, described with the plant
    batch_equivalent,
    check_wind_acts,
    fly_rotor,
    rotor_batch,
    rotor_engine_inputs,
    rotor_hover_state,
    rotor_initial_states,
    vehicle_record,
)


def designed_controller(name: str, bandwidth: float) -> Any:
    """A controller by name with the gains its design rules give for a motor bandwidth (its
    ``rotor_design``, :func:`quadcruise.control.registry.register_controller`).

    Parameters
    ----------
    name : str
        A declared controller's name (``nlpd``, ``gonzalez``, ``se3``, ``cascade``, or a user's).
    bandwidth : float
        The rotor lag's bandwidth w [rad/s] (15 for the paper's vehicle: the defaults).

    Returns
    -------
    Controller
        nlpd and gonzalez: attitude and yaw PID by
        :func:`~quadcruise.control.design.attitude_pid_design`; se3: kR, kw by
        :func:`~quadcruise.control.se3.se3_attitude_design`; cascade: the rate PIDs by
        :func:`~quadcruise.control.cascade.rate_pid_design`; the rest their defaults.

    Raises
    ------
    InputError
        An unknown name, or a controller declared without a design for a rotor-plant vehicle.
    """
    base = controller_from_name(name)
    return dataclasses.replace(base, **rotor_gains(name, bandwidth))


def as_vehicle(vehicle: Any) -> Any:
    """``fly``'s vehicle: a preset's name read (:meth:`quadcruise.Vehicle.preset`), a list of
    rotor-plant vehicles as a tuple (one per flown vehicle: a Monte Carlo chunk), any other value as given.

    Parameters
    ----------
    vehicle : Vehicle, RotorVehicle, str, list of RotorVehicle or None
        The vehicle, a preset's name, or one RotorVehicle per vehicle of the batch (all with
        the same number of rotors).

    Returns
    -------
    Vehicle, RotorVehicle, tuple of RotorVehicle or None

    Raises
    ------
    InputError
        An unknown preset; an empty list, an entry that is not a RotorVehicle, or rotor counts
        that differ.
    """
    if isinstance(vehicle, str):
        return Vehicle.preset(vehicle)
    if not isinstance(vehicle, (list, tuple)):
        return vehicle
    if not vehicle:
        raise InputError("fly() argument 'vehicle': the list of vehicles is empty")
    for i, v in enumerate(vehicle):
        if not isinstance(v, RotorVehicle):
            raise InputError(
                f"fly() argument 'vehicle': entry {i} is a {type(v).__name__}; a list holds one RotorVehicle "
                "per vehicle (a batch of paper vehicles is one Vehicle with a value per vehicle)"
            )
        if v.n_rotors != vehicle[0].n_rotors:
            raise InputError(
                f"fly() argument 'vehicle': entry {i} has {v.n_rotors} rotors, entry 0 {vehicle[0].n_rotors}: "
                "the vehicles of one flight must have the same number of rotors"
            )
    return tuple(vehicle)


def flight_setup(vehicle: Any, controller_vehicle: Any, controller: Any) -> tuple[Plant, Any]:
    """A flight's plant, and its controller (designed when named, where the plant designs gains).

    Parameters
    ----------
    vehicle, controller_vehicle : Vehicle or RotorVehicle or None
        The flown vehicle (or a tuple of RotorVehicles, :func:`as_vehicle`) and the one the
        controller believes.
    controller : str, Controller or list
        ``fly``'s controller argument.

    Returns
    -------
    plant : Plant
        The flown vehicle's plant (:func:`quadcruise.sim.plants.of`).
    controller : str, Controller or list
        Where the plant designs gains (:attr:`Plant.designs_gains`), a built-in name turned into
        that controller with gains for the controller vehicle's bandwidth
        (:func:`designed_controller`); anything else as given.

    Raises
    ------
    InputError
        A rotor vehicle believed as a paper vehicle or the other way round, or a controller
        vehicle with another number of rotors: the controller's rotor commands would not fit.
    """
    plant = plants.of(vehicle)
    flown = plant.vehicles(vehicle)
    plant.check_controller_vehicle(flown, controller_vehicle)
    if plant.designs_gains and isinstance(controller, str) and controller in CONTROLLERS:
        believed = (controller_vehicle,) if controller_vehicle is not None else flown
        bandwidths = plant.bandwidths(believed)
        designs = {w: designed_controller(controller, w) for w in dict.fromkeys(bandwidths)}
        controller = designs[bandwidths[0]] if len(designs) == 1 else [designs[w] for w in bandwidths]
    return plant, controller


__all__ = [
    "as_vehicle",
    "batch_equivalent",
    "rotor_batch",
    "vehicle_record",
    "check_wind_acts",
    "designed_controller",
    "flight_setup",
    "fly_rotor",
    "rotor_engine_inputs",
    "rotor_initial_states",
    "rotor_hover_state",
]
