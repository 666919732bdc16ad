"""The paper's plant, described once: :data:`PAPER`.

Its state is the paper layout itself (:data:`quadcruise.layout.STATE`: position, velocity, ZYX
Euler angles, body rates and the four rotor thrusts lagging their duties), its vehicle row
:data:`quadcruise.layout.PARAMS` (:meth:`quadcruise.Vehicle.rows`, one row per vehicle of a
batched Vehicle), its kernel :func:`quadcruise.sim.engine.fly_vehicles`'s, which carries the
sensor ring buffer alone (:func:`quadcruise.sim.inputs.fresh_carry`). The controller's duties
are clipped to [0, 1]; the controller and the log see the state as it is. It refuses nothing
of ``fly``'s options (a Monte Carlo population's ``aero_spread``: it has no aerodynamic
coefficients); wind acts through the drag it is given; a named controller flies its default gains
(designed for this vehicle).

Examples
--------
>>> from quadcruise.model.vehicle import Vehicle
>>> PAPER.vehicle_class is Vehicle, PAPER.state.size, PAPER.log_width((Vehicle.paper(),))
(True, 16, 0)
"""

from __future__ import annotations

import warnings
from typing import Any

import numpy as np

from quadcruise.errors import InputError
from quadcruise.layout import PARAMS, STATE
from quadcruise.model.vehicle import Vehicle
from quadcruise.sim.engine import fly_vehicles, simulate
from quadcruise.sim.inputs import batch_inputs, fresh_carry
from quadcruise.sim.kernel_args import KernelArgs
from quadcruise.sim.plants.base import Plant

HOVER_DUTY_WARNING = 0.7
"""A hover duty above this leaves less than 30 % of the rotors' thrust for control: ``fly`` warns."""


def hover_check(vehicle: Vehicle, stacklevel: int = 2) -> None:
    """Refuse a paper vehicle that cannot lift itself; warn when hovering leaves little for control
    (:func:`quadcruise.workflows.fly_inputs.check_can_hover`, the warning ``stacklevel`` frames up)."""
    duty = np.atleast_1d(np.asarray(vehicle.hover_duty, dtype=float))
    m = np.broadcast_to(np.asarray(vehicle.m, dtype=float), duty.shape)
    k = np.broadcast_to(np.asarray(vehicle.K, dtype=float), duty.shape)
    g = np.broadcast_to(np.asarray(vehicle.g, dtype=float), duty.shape)
    bad = np.flatnonzero(~(duty <= 1.0))
    if bad.size:
        i = int(bad[0])
        which = f"vehicle {i} (mass {m[i]:g} kg)" if duty.size > 1 else f"the vehicle of mass {m[i]:g} kg"
        raise InputError(
            f"{which} cannot lift itself: hovering needs {m[i] * g[i]:.4g} N, its four rotors "
            f"give at most {4 * k[i]:g} N (K = {k[i]:g} N each)"
        )
    close = np.flatnonzero(duty > HOVER_DUTY_WARNING)
    if close.size:
        i = int(close[0])
        warnings.warn(
            f"the vehicle{'' if duty.size == 1 else f' {i}'} hovers at {100 * duty[i]:.0f} % duty, "
            f"leaving {100 * (1 - duty[i]):.0f} % of its thrust for control",
            stacklevel=stacklevel + 1,
        )


class PaperPlant(Plant):
    """The paper's plant (:data:`PAPER`)."""

    def count(self, vehicle: Any) -> int | None:
        """A batched Vehicle's ``batch_size`` (one value per vehicle); None for one vehicle."""
        return vehicle.batch_size

    def n_rotors(self, vehicle: Any) -> int:
        """Four: the paper's "+" quadrotor."""
        return 4

    def file_fields(self, fields: dict) -> dict:
        """``preset = "paper"`` and the fields as floats."""
        return {"preset": "paper", **{k: float(x) for k, x in fields.items()}}

    def check_vehicles(self, vehicles: tuple) -> None:
        """A vehicle that cannot lift itself refused, one that barely can warned of."""
        hover_check(vehicles[0], stacklevel=3)  # the warning points at fly's caller

    def flight(self, grid, vehicle, controller_vehicle, controller, gains, mission, mp, n, *, x0, paper_x0, meta, **kw):
        """:func:`~quadcruise.sim.engine.simulate`'s arguments: the rows of ``vehicle`` (and of the
        controller's vehicle), ``paper_x0`` the initial states, ``full_dynamics`` from ``kw``."""
        args = (grid, paper_x0, vehicle.rows(n), controller, gains, mission.function, mp)
        vp_ctrl = None if controller_vehicle is None else controller_vehicle.rows(n)
        return args, dict(vp_ctrl=vp_ctrl, full_dynamics=kw.get("full_dynamics", False))

    def fly(self, args: tuple, options: dict) -> Any:
        """:func:`~quadcruise.sim.engine.simulate`."""
        return simulate(*args, **options)

    def stepper_inputs(self, stepper, t_grid, x0, vp, gains, mp, vp_ctrl, shared: dict, own: dict) -> dict:
        """``batch_inputs``; the carry is the sensor ring buffer, filled with the initial state."""
        inp = batch_inputs(t_grid, x0, vp, gains, mp, vp_ctrl=vp_ctrl, **shared)
        stepper.carry = fresh_carry(inp["x0"], int(shared["sensor_delay"]))
        return inp

    def restart(self, stepper, rows: np.ndarray, start: np.ndarray) -> None:
        """The ring buffer of ``rows`` filled with their new initial state."""
        stepper.carry[rows] = fresh_carry(np.ascontiguousarray(start), stepper.sensor_delay)

    def step_args(self, stepper, shared: dict) -> tuple:
        """:class:`~quadcruise.sim.kernel_args.KernelArgs`."""
        return KernelArgs(**shared, vp=stepper.vp, full=stepper.full_dynamics)


PAPER = PaperPlant(
    name="paper",
    vehicle_class=Vehicle,
    state=STATE,
    params=PARAMS,
    carry=None,
    fly_pieces=fly_vehicles,
    kernel_args=KernelArgs,
    command="PWM duties, clipped to [0, 1]",
    saturation="rotor duties were clipped to [0, 1]",
    takes_speeds=False,
    replay_step=1e-3,
    default_preset="paper",
    refuses={
        "aero_spread": "perturbs a rotor-plant vehicle's aerodynamic coefficients; the paper's vehicle has none to "
        "spread (give a rotor-plant vehicle: iris, crazyflie, ...)",
        "vibration": "shakes the IMU at the rotors' speeds; the paper's plant has none (give a rotor-plant vehicle: "
        "iris, crazyflie, ...)",
        "ground": "the paper's plant has no ground to stand on or take off from (give a rotor-plant vehicle: "
        "iris, crazyflie, ...)",
        **{
            option: "the rotor plant's (give alloc, the rotor plant's allocation rows, with its rotor states and rows)"
            for option in ("psi0", "touchdown_speed", "rotor_names")
        },
    },
    drag_for_wind=True,
)
"""The paper's plant (Table I's vehicle, :class:`quadcruise.Vehicle`)."""

__all__ = ["PAPER", "PaperPlant", "hover_check", "HOVER_DUTY_WARNING"]
