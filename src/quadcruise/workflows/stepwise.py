"""``stepper``: the step-wise engine built from the same objects as :func:`~quadcruise.fly`.

The arrays are the ones ``fly`` hands the engine (initial hover state, gains, memory,
mission parameters, disturbance and sensor arrays, seeds), so stepping the result through
the flight's grid flies the flight ``fly`` flies, period by period.
"""

from __future__ import annotations

from typing import Any

import numpy as np

from quadcruise.errors import InputError
from quadcruise.missions import Mission, mission_from_name, stack_params
from quadcruise.model.vehicle import Vehicle
from quadcruise.protocols import ControllerLike
from quadcruise.sim.inputs import Limits, time_grid
from quadcruise.sim.stepper import Stepper
from quadcruise.workflows.fly_inputs import (
    check_can_hover,
    default_duration,
    engine_inputs,
    hover_state,
    per_vehicle_controllers,
)


def stepper(
    mission: Mission | str = "circle",
    controller: ControllerLike | str = "nlpd",
    *,
    vehicle: Vehicle | None = None,
    duration: float | None = None,
    dt: float = 1e-3,
    max_step: float | None = None,
    n: int | None = None,
    x0: Any = None,
    limits: Limits | None = None,
    controller_vehicle: Vehicle | None = None,
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
        As in :func:`~quadcruise.fly`.
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
    controllers = per_vehicle_controllers(controller)
    if len(controllers) != 1:
        raise InputError("stepper: give one controller (its gains rows may be written between steps)")
    controller = controllers[0]
    vehicle = vehicle or Vehicle.paper()
    if not isinstance(vehicle, Vehicle) or not isinstance(controller_vehicle, (Vehicle, type(None))):
        raise InputError(
            "stepper: the step-wise engine flies the paper's plant: give a paper Vehicle, got "
            f"{type(vehicle).__name__} (a rotor-plant vehicle flies with fly and compare)"
        )
    n = n or vehicle.batch_size or (np.shape(x0)[0] if x0 is not None and np.ndim(x0) == 2 else 1)
    if vehicle.batch_size not in (None, n):
        raise InputError(f"the number of vehicles is ambiguous: n = {n}, vehicle has {vehicle.batch_size}")
    duration = default_duration(mission) if duration is None else duration
    if not (isinstance(max_step, (int, float)) and max_step > 0) and max_step is not None:
        raise InputError(f"max_step must be a positive number of seconds, got {max_step!r}")
    grid = time_grid(float(duration), float(dt))
    if sensors is not None:
        sensors.check_fits(duration)
    check_can_hover(vehicle)
    x0 = hover_state(vehicle, n, mission) if x0 is None else x0
    vp_ctrl = None if controller_vehicle is None else controller_vehicle.rows(n)
    return Stepper(
        grid,
        x0,
        vehicle.rows(n),
        controller.function,
        controller.gains(),
        mission.function,
        stack_params(mission, n=n),
        memory=controller.memory(),
        vp_ctrl=vp_ctrl,
        full_dynamics=full_dynamics,
        seed=seed,
        first_vehicle=first_vehicle,
        max_step=max_step or dt,
        limits=limits,
        periods=periods,
        setpoint_width=setpoint_width,
        **engine_inputs(environment, sensors, n, dt),
    )


__all__ = ["stepper"]
