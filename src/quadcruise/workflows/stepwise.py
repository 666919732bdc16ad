"""``stepper``: the step-wise engine built from the same objects as :func:`~quadcruise.fly`.

The arrays are the ones ``fly`` hands the engine (initial hover state, gains, memory,
mission parameters, disturbance and sensor arrays, seeds), so stepping the result through
the flight's grid flies the flight ``fly`` flies, period by period. A rotor-plant vehicle
(:class:`~quadcruise.model.rotor_vehicle.RotorVehicle` or a preset's name) flies the rotor
plant, with what ``fly`` hands its kernel (:meth:`quadcruise.sim.plants.rotor.RotorPlant.flight`):
the controller designed for the vehicle it believes, the hover at the mission's start, a ground.
"""

from __future__ import annotations

from typing import Any

import numpy as np

from quadcruise.checks import describe
from quadcruise.errors import InputError
from quadcruise.missions import Mission, mission_from_name, stack_params
from quadcruise.model.rotor_vehicle import RotorVehicle
from quadcruise.model.vehicle import Vehicle
from quadcruise.protocols import ControllerLike
from quadcruise.sim.inputs import Limits, time_grid
from quadcruise.sim.stepper import Stepper
from quadcruise.workflows.fly_inputs import default_duration, engine_inputs, hover_state, per_vehicle_controllers
from quadcruise.workflows.rotor_fly import as_vehicle, flight_setup


def stepper(
    mission: Mission | str = "circle",
    controller: ControllerLike | str = "nlpd",
    *,
    vehicle: Vehicle | RotorVehicle | str | None = None,
    duration: float | None = None,
    dt: float = 1e-3,
    max_step: float | None = None,
    n: int | None = None,
    x0: Any = None,
    limits: Limits | None = None,
    controller_vehicle: Vehicle | RotorVehicle | None = None,
    full_dynamics: bool = False,
    environment=None,
    sensors=None,
    seed: int = 0,
    first_vehicle: int | np.ndarray = 0,
    periods: int = 1,
    setpoint_width: int = 0,
) -> Stepper:
    """A :class:`~quadcruise.sim.stepper.Stepper` of the flight ``fly`` would fly with these arguments.

    Parameters
    ----------
    mission : Mission or str
        The mission (or its name), as in :func:`~quadcruise.fly`.
    controller : Controller or str
        The controller (or its name).
    vehicle, duration, dt, max_step, n, x0, limits, controller_vehicle, full_dynamics : optional
        As in :func:`~quadcruise.fly` (a RotorVehicle or a preset's name flies the rotor plant;
        ``x0`` then a rotor state, and no ``full_dynamics``).
    environment, sensors, seed, first_vehicle : optional
        As in :func:`~quadcruise.fly`.
    periods : int
        Control periods per :meth:`Stepper.step`.
    setpoint_width : int
        Leading gains entries that ``step(commands)`` writes (an action-mode controller's setpoint).

    Returns
    -------
    Stepper
        At the first instant of every vehicle's grid.

    Raises
    ------
    InputError
        As ``fly`` for the same arguments.
    """
    if isinstance(mission, str):
        mission = mission_from_name(mission)
    vehicle = as_vehicle(vehicle) or Vehicle.paper()
    if not isinstance(vehicle, (Vehicle, RotorVehicle)):
        raise InputError(
            f"stepper: vehicle must be a Vehicle, a RotorVehicle or a preset's name, got {describe(vehicle)}"
        )
    plant, controller = flight_setup(vehicle, controller_vehicle, controller)  # a name: designed for it
    flown = plant.vehicles(vehicle)
    controllers = per_vehicle_controllers(controller)
    if len(controllers) != 1:
        raise InputError("stepper: give one controller (its gains rows may be written between steps)")
    controller = controllers[0]
    plant.refuse("stepper:", "full_dynamics", full_dynamics)
    plant.check_environment(flown, environment)
    count = plant.count(vehicle)
    n = n or count or (np.shape(x0)[0] if x0 is not None and np.ndim(x0) == 2 else 1)
    if count not in (None, n):
        raise InputError(f"the number of vehicles is ambiguous: n = {n}, vehicle has {count}")
    duration = default_duration(mission) if duration is None else duration
    if not (isinstance(max_step, (int, float)) and max_step > 0) and max_step is not None:
        raise InputError(f"max_step must be a positive number of seconds, got {describe(max_step)}")
    grid = time_grid(float(duration), float(dt))
    if sensors is not None:
        sensors.check_fits(duration)
    plant.check_vehicles(flown)
    gains, mp = controller.gains(), stack_params(mission, n=n)
    hover = hover_state(plant.equivalent(flown[:1]), n, mission)
    args, own = plant.flight(
        grid, vehicle, controller_vehicle, controller.function, gains, mission, mp, n,
        x0=None, paper_x0=hover, meta=None, full_dynamics=full_dynamics,
    )  # fmt: skip
    own.pop("rotor_names", None)  # a result's column names: the Stepper keeps none
    if x0 is not None:  # the plant's own state (the rotor plant's: 13 + n entries)
        args = (args[0], x0, *args[2:])
    return Stepper(
        *args,
        memory=controller.memory(),
        seed=seed,
        first_vehicle=first_vehicle,
        max_step=max_step or dt,
        limits=limits,
        periods=periods,
        setpoint_width=setpoint_width,
        **own,
        **engine_inputs(environment, sensors, n, dt),
    )


__all__ = ["stepper"]
