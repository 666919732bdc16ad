"""``stepper``: the step-wise engine built from the same objects as :func:`~quadcruise.fly`.

The arrays are the ones ``fly`` hands the engine (initial hover state, gains, memory,
mission parameters, disturbance and sensor arrays, seeds), so stepping the result through
the flight's grid flies the flight ``fly`` flies, period by period. A rotor-plant vehicle
(:class:`~quadcruise.model.rotor_vehicle.RotorVehicle` or a preset's name) flies the rotor
plant, with what :func:`quadcruise.workflows.rotor_fly.fly_rotor` hands its kernel: the
controller designed for the vehicle it believes, the hover at the mission's start, a ground.
"""

from __future__ import annotations

from typing import Any

import numpy as np

from quadcruise.checks import describe
from quadcruise.errors import InputError
from quadcruise.layout import REF_PSI
from quadcruise.missions import Mission, mission_from_name, stack_params
from quadcruise.model.equivalent import duty_to_thrust, paper_equivalent
from quadcruise.model.rotor_vehicle import RotorVehicle
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
from quadcruise.workflows.rotor_fly import as_vehicle, check_wind_acts, rotor_flight_setup, rotor_hover_state


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
    rotor, controller = rotor_flight_setup(vehicle, controller_vehicle, controller)  # a name: designed for it
    controllers = per_vehicle_controllers(controller)
    if len(controllers) != 1:
        raise InputError("stepper: give one controller (its gains rows may be written between steps)")
    controller = controllers[0]
    if rotor:
        return _rotor_stepper(
            mission,
            controller,
            vehicle,
            controller_vehicle,
            duration=duration,
            dt=dt,
            max_step=max_step,
            n=n or 1,
            x0=x0,
            limits=limits,
            full_dynamics=full_dynamics,
            environment=environment,
            sensors=sensors,
            seed=seed,
            first_vehicle=first_vehicle,
            periods=periods,
            setpoint_width=setpoint_width,
        )
    n = n or vehicle.batch_size or (np.shape(x0)[0] if x0 is not None and np.ndim(x0) == 2 else 1)
    if vehicle.batch_size not in (None, n):
        raise InputError(f"the number of vehicles is ambiguous: n = {n}, vehicle has {vehicle.batch_size}")
    duration = default_duration(mission) if duration is None else duration
    if not (isinstance(max_step, (int, float)) and max_step > 0) and max_step is not None:
        raise InputError(f"max_step must be a positive number of seconds, got {describe(max_step)}")
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


def _rotor_stepper(mission, controller, vehicle, controller_vehicle, **kw: Any) -> Stepper:
    """:func:`stepper` of a rotor-plant vehicle (its keywords; ``controller`` already designed)."""
    if kw["full_dynamics"]:
        raise InputError("stepper: full_dynamics is the paper plant's option, not a rotor-plant vehicle's")
    check_wind_acts(vehicle, kw["environment"])
    n, dt = kw["n"], kw["dt"]
    duration = default_duration(mission) if kw["duration"] is None else kw["duration"]
    max_step = kw["max_step"]
    if not (isinstance(max_step, (int, float)) and max_step > 0) and max_step is not None:
        raise InputError(f"max_step must be a positive number of seconds, got {describe(max_step)}")
    grid = time_grid(float(duration), float(dt))
    if kw["sensors"] is not None:
        kw["sensors"].check_fits(duration)
    believed = controller_vehicle or vehicle
    return Stepper(
        grid,
        rotor_hover_state(vehicle, mission) if kw["x0"] is None else kw["x0"],
        np.broadcast_to(vehicle.row(), (n, vehicle.row().size)),
        controller.function,
        controller.gains(),
        mission.function,
        stack_params(mission, n=n),
        memory=controller.memory(),
        vp_ctrl=paper_equivalent(believed).rows(1)[0],
        seed=kw["seed"],
        first_vehicle=kw["first_vehicle"],
        max_step=max_step or dt,
        limits=kw["limits"],
        periods=kw["periods"],
        setpoint_width=kw["setpoint_width"],
        alloc=np.r_[duty_to_thrust(believed).ravel(), believed.kf],
        psi0=float(mission.reference(0.0)[0][REF_PSI]),
        touchdown_speed=vehicle.touchdown_speed,
        **engine_inputs(kw["environment"], kw["sensors"], n, dt),
    )


__all__ = ["stepper"]
