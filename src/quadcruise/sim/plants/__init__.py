"""The plants the engine flies, each described once (:class:`~quadcruise.sim.plants.base.Plant`):
the paper's (:data:`~quadcruise.sim.plants.paper.PAPER`) and the rotor-speed plant
(:data:`~quadcruise.sim.plants.rotor.ROTOR`). Code elsewhere asks :func:`of` for a vehicle's
plant and asks the plant, rather than asking which plant it has.

Examples
--------
>>> from quadcruise.model.vehicle import Vehicle
>>> of(Vehicle.paper()).name, of(Vehicle.preset("iris")).name, of((Vehicle.preset("iris"),)).name
('paper', 'rotor', 'rotor')
"""

from __future__ import annotations

from typing import Any

from quadcruise.errors import InputError
from quadcruise.sim.plants.base import Plant
from quadcruise.sim.plants.paper import PAPER
from quadcruise.sim.plants.rotor import ROTOR

PLANTS: dict[str, Plant] = {p.name: p for p in (PAPER, ROTOR)}
"""Each plant by the name a vehicle file's ``plant`` key and a flight's record give it."""


def of(vehicle: Any, where: str = "vehicle") -> Plant:
    """The plant a vehicle flies: its class's (a tuple of vehicles: its first entry's).

    Parameters
    ----------
    vehicle : Vehicle, RotorVehicle or tuple of RotorVehicle
        The vehicle(s).
    where : str
        How a message names the argument.

    Returns
    -------
    Plant

    Raises
    ------
    InputError
        Not a vehicle of any plant.
    """
    first = vehicle[0] if isinstance(vehicle, tuple) and vehicle else vehicle
    for plant in PLANTS.values():
        if isinstance(first, plant.vehicle_class):
            return plant
    raise InputError(f"{where} must be a Vehicle or a RotorVehicle, got {type(vehicle).__name__}")


def named(name: str) -> Plant:
    """The plant of a record's ``plant`` name (``"paper"`` where none is given).

    Parameters
    ----------
    name : str or None
        ``"paper"`` or ``"rotor"``.

    Returns
    -------
    Plant
    """
    return PLANTS[name or "paper"]


def of_result(result: Any) -> Plant:
    """The plant a flight's result flew: the rotor plant's where it logged rotor states.

    Parameters
    ----------
    result : SimResult
        A flight.

    Returns
    -------
    Plant
    """
    return PAPER if getattr(result, "rotor_states", None) is None else ROTOR


def of_arrays(alloc: Any) -> Plant:
    """The plant of a Stepper's arrays.

    Parameters
    ----------
    alloc : numpy.ndarray or None
        The Stepper's ``alloc`` (the rotor plant's allocation rows), or None.

    Returns
    -------
    Plant
        The rotor plant's where ``alloc`` is given, else the paper's.
    """
    return PAPER if alloc is None else ROTOR


__all__ = ["PAPER", "PLANTS", "ROTOR", "Plant", "named", "of", "of_arrays", "of_result"]
