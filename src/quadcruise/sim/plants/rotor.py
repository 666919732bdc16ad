"""The rotor-speed plant, described once: :data:`ROTOR`.

Its state is the rigid body with a quaternion and one speed a rotor
(:data:`~quadcruise.model.rotor_plant.ROTOR_BODY`, then ``w1 .. wn`` from ``ROTOR_W1``), its
vehicle row :data:`~quadcruise.model.rotor_plant.ROTOR_PARAMS` and a ``ROTOR_ARM`` per rotor
(:meth:`~quadcruise.model.rotor_vehicle.RotorVehicle.row`), its kernel's carry
:data:`~quadcruise.sim.rotor_flight.ROTOR_CARRY` ahead of the sensor ring buffer
(:func:`~quadcruise.sim.rotor_flight.fly_rotor_pieces`). The controller believes the vehicle's
"+" equivalent (:mod:`quadcruise.model.equivalent`): its duties become thrusts through the
allocation and speeds held in [w_min, w_max]; the controller and the log see the paper layout
(:func:`~quadcruise.sim.rotor_flight.paper_state`), and the log keeps the rotor state beside it
(13 + n columns). A controller given by name gets gains designed for the believed vehicle's
motor bandwidth. It refuses ``full_dynamics`` (it flies the quaternion, exact already), wind on
a vehicle without aerodynamics, and initial thrusts its rotors cannot give.

The functions below build a rotor flight's arrays for :func:`quadcruise.fly` and the Stepper
(they were ``workflows/rotor_fly.py``'s, which still exports them).

Examples
--------
>>> from quadcruise.model.rotor_vehicle import RotorVehicle
>>> v = RotorVehicle.preset("iris")
>>> ROTOR.vehicle_class is RotorVehicle, ROTOR.log_width((v,)), ROTOR.vehicles(v) == (v,)
(True, 17, True)
"""

from __future__ import annotations

import math
from typing import Any

import numpy as np

from quadcruise.errors import InputError
from quadcruise.layout import PARAMS, PSI, REF_PSI, REF_Z
from quadcruise.model.equivalent import duty_to_thrust, paper_equivalent
from quadcruise.model.rotor_plant import QW, QZ, ROTOR_ARM, ROTOR_BODY, ROTOR_PARAMS, ROTOR_W1, RZ, state_names
from quadcruise.model.rotor_plant import RP as RATE_P
from quadcruise.model.rotor_vehicle import AERO_FIELDS, RotorVehicle
from quadcruise.model.vehicle import Vehicle
from quadcruise.sim.kernel_args import RotorKernelArgs
from quadcruise.sim.plants.base import Plant
from quadcruise.sim.result import SimResult
from quadcruise.sim.rotor_batch import fly_rotor_vehicles, rotor_inputs
from quadcruise.sim.rotor_flight import ROTOR_CARRY, fly_rotor_pieces, paper_states, rotor_carry_width


def rotor_batch(vehicle: Any) -> tuple[RotorVehicle, ...] | None:
    """The flown rotor-plant vehicles as a tuple (one entry for one vehicle), or None for the paper plant.

    Parameters
    ----------
    vehicle : Vehicle, RotorVehicle or tuple of RotorVehicle
        ``fly``'s vehicle after :func:`as_vehicle`.

    Returns
    -------
    tuple of RotorVehicle or None
    """
    if isinstance(vehicle, RotorVehicle):
        return (vehicle,)
    return vehicle if isinstance(vehicle, tuple) else None


def batch_equivalent(vehicles: tuple[RotorVehicle, ...]) -> Vehicle:
    """The paper equivalents (:func:`~quadcruise.model.equivalent.paper_equivalent`) of rotor vehicles.

    Parameters
    ----------
    vehicles : tuple of RotorVehicle
        One or more vehicles.

    Returns
    -------
    Vehicle
        One Vehicle for one vehicle, else a batched Vehicle (one value per vehicle).
    """
    if len(vehicles) == 1:
        return paper_equivalent(vehicles[0])
    return Vehicle.stack([paper_equivalent(v) for v in vehicles])


def vehicle_record(vehicles: tuple[RotorVehicle, ...]) -> dict:
    """The flown rotor vehicles as a result records them: ``plant`` and each field, one value
    where all vehicles share it, else a list of one value per vehicle.

    Parameters
    ----------
    vehicles : tuple of RotorVehicle
        One or more vehicles.

    Returns
    -------
    dict
        ``{"plant": "rotor", field: value or list}``.
    """
    dicts = [v.to_dict() for v in vehicles]
    out: dict = {"plant": "rotor"}
    for key, value in dicts[0].items():
        values = [d[key] for d in dicts]
        out[key] = value if all(v == value for v in values) else values
    return out


def check_wind_acts(vehicle: Any, environment: Any) -> None:
    """Refuse wind on a rotor-plant vehicle without aerodynamics: it would blow through it unfelt.

    Parameters
    ----------
    vehicle : Vehicle, RotorVehicle or tuple of RotorVehicle
        The flown vehicle(s) (a paper Vehicle is the paper plant's business: it is given drag).
    environment : Environment, CustomDisturbance or None
        The disturbances.

    Raises
    ------
    InputError
        Wind, gusts or turbulence, and every aerodynamic coefficient of a RotorVehicle zero.
    """
    flown = rotor_batch(vehicle)
    if flown is None or not getattr(environment, "needs_drag", False):
        return
    if any(all(getattr(v, name) == 0.0 for name in AERO_FIELDS) for v in flown):
        raise InputError(
            "fly(): wind acts on a rotor-plant vehicle through its aerodynamics, and this one has none "
            f"({', '.join(AERO_FIELDS)} all 0): give it some, or fly without wind"
        )


def rotor_hover_state(vehicle: RotorVehicle, mission: Any) -> np.ndarray:
    """The rotor state hovering level at x = y = 0, at the mission's start altitude and yaw.

    Parameters
    ----------
    vehicle : RotorVehicle
        The vehicle: each rotor at its hover speed sqrt(m g / (n kf)).
    mission : Mission
        Its reference at t = 0.

    Returns
    -------
    numpy.ndarray
        (13 + n,) position, zero velocity, the yaw's quaternion, zero rates, rotor speeds.
    """
    ref0 = mission.reference(0.0)[0]
    x0 = np.zeros(ROTOR_W1 + vehicle.n_rotors)
    x0[RZ] = ref0[REF_Z]
    x0[QW], x0[QZ] = math.cos(0.5 * ref0[REF_PSI]), math.sin(0.5 * ref0[REF_PSI])
    x0[ROTOR_W1:] = vehicle.hover_speed
    return x0


def rotor_initial_states(vehicles: tuple[RotorVehicle, ...], x0: np.ndarray, n: int) -> np.ndarray:
    """Rotor-plant initial states from ``fly(x0=)``'s paper-layout states (:data:`~quadcruise.layout.STATE_NAMES`).

    Position, velocity and body rates are copied, the ZYX Euler angles become the quaternion
    ``q = qz(psi) qy(theta) qx(phi)``; a rotor starts at ``w_i = sqrt(F_i / kf)``, the inverse of
    the paper layout's ``F_i = kf w_i^2`` (:func:`~quadcruise.sim.rotor_flight.paper_state`), and
    at its hover speed exactly where F1..F4 are all the hover thrust ``m g / 4`` that
    :func:`~quadcruise.workflows.fly_inputs.hover_state` gives.

    Parameters
    ----------
    vehicles : tuple of RotorVehicle
        One vehicle for all, or one per vehicle.
    x0 : numpy.ndarray
        (16,) or (n, 16) paper-layout states.
    n : int
        Number of vehicles.

    Returns
    -------
    numpy.ndarray
        (n, 13 + rotors) rotor states.

    Raises
    ------
    InputError
        A negative thrust, or thrusts other than the hover's for a vehicle without four rotors
        (the paper layout holds four rotors' thrusts).

    Examples
    --------
    >>> from quadcruise.model.rotor_vehicle import RotorVehicle
    >>> v = RotorVehicle.preset("iris")
    >>> x = np.zeros(16); x[2] = 1.0; x[8] = np.pi / 2; x[12:] = v.m * v.g / 4
    >>> r = rotor_initial_states((v,), x, 1)[0]
    >>> float(r[2]), np.round(r[6:10], 6).tolist(), bool(np.all(r[13:] == v.hover_speed))
    (1.0, [0.707107, 0.0, 0.0, 0.707107], True)
    """
    from quadcruise.layout import F1, PHI, THETA, P, X

    x0 = np.broadcast_to(np.atleast_2d(np.asarray(x0, dtype=float)), (n, 16))
    flown = vehicles if len(vehicles) == n else vehicles[:1] * n
    out = np.zeros((n, ROTOR_W1 + flown[0].n_rotors))
    out[:, :6] = x0[:, X : X + 6]
    out[:, RATE_P : RATE_P + 3] = x0[:, P : P + 3]
    h = 0.5 * x0[:, [PHI, THETA, PSI]]
    (cf, ct, cp), (sf, st, sp) = np.cos(h).T, np.sin(h).T
    out[:, QW] = cf * ct * cp + sf * st * sp
    out[:, QW + 1] = sf * ct * cp - cf * st * sp
    out[:, QW + 2] = cf * st * cp + sf * ct * sp
    out[:, QZ] = cf * ct * sp - sf * st * cp
    thrust = x0[:, F1 : F1 + 4]
    for v in dict.fromkeys(flown):  # each distinct vehicle once, over its rows
        rows = np.array([u == v for u in flown]) if len(vehicles) > 1 else np.ones(n, dtype=bool)
        hover = np.all(thrust[rows] == v.m * v.g / 4.0, axis=1)
        bad = ~hover & ((v.n_rotors != 4) | np.any(thrust[rows] < 0, axis=1))
        if bad.any():
            i = int(np.flatnonzero(rows)[np.argmax(bad)])
            raise InputError(
                f"fly() argument x0, row {i}: rotor thrusts {thrust[i].tolist()} cannot start "
                + (
                    f"a {v.n_rotors}-rotor vehicle (x0 holds four rotors' thrusts F1..F4): give its hover, "
                    f"F1..F4 = m g / 4 = {v.m * v.g / 4.0:.6g} N, as hover_state does"
                    if v.n_rotors != 4
                    else "its rotors (a thrust must be >= 0 N)"
                )
            )
        speed = np.full((int(rows.sum()), v.n_rotors), v.hover_speed)
        if v.n_rotors == 4:
            speed[~hover] = np.sqrt(thrust[rows][~hover] / v.kf)
        out[rows, ROTOR_W1:] = speed
    return out


def rotor_engine_inputs(
    grid: np.ndarray,
    vehicle: RotorVehicle,
    controller_vehicle: RotorVehicle | None,
    controller_function: Any,
    gains: np.ndarray,
    mission: Any,
    mp: np.ndarray,
    n: int,
    x0: np.ndarray | None = None,
    meta: dict | None = None,
) -> tuple[tuple, dict]:
    """The arrays of ``n`` rotor-plant flights, as :class:`~quadcruise.sim.stepper.Stepper`
    (and so :func:`~quadcruise.sim.chunked.watch_again`) takes them, for :func:`quadcruise.fly`.

    Parameters
    ----------
    grid : numpy.ndarray
        The control instants [s].
    vehicle : RotorVehicle or tuple of RotorVehicle
        The flown vehicle, or one per vehicle (``n`` of them), with a ground at z = 0 (its
        ``touchdown_speed``).
    controller_vehicle : RotorVehicle or None
        The vehicle the controller believes; each flown vehicle its own by default.
    controller_function : compiled function
        The controller's law (``CONTROLLER_SIG``).
    gains : numpy.ndarray
        Its gains, one row or one per vehicle.
    mission : Mission
        The (first) mission: its start gives the initial hover.
    mp : numpy.ndarray
        Mission parameter rows.
    n : int
        Number of vehicles.
    x0 : numpy.ndarray, optional
        (16,) or (n, 16) paper-layout initial states (:func:`rotor_initial_states`); hovering
        at the mission's start by default.
    meta : dict, optional
        The flight's record: the flown vehicle's "+" equivalent is added to it.

    Returns
    -------
    tuple
        ``(args, options)``: the positional arguments (grid, rotor x0, rotor rows, controller,
        gains, mission, mp) and ``vp_ctrl``, ``alloc``, ``psi0``, ``touchdown_speed``, ``rotor_names``.
    """
    flown = rotor_batch(vehicle)
    believed = (controller_vehicle,) if controller_vehicle is not None else flown
    if meta is not None:  # the flown vehicle's "+" equivalent: its hover duty (effort), a log's K, l, d
        meta["paper_equivalent"] = batch_equivalent(flown).to_dict()

    def rows(make, vehicles):  # one row per distinct vehicle, spread over the n vehicles
        made = {v: make(v) for v in dict.fromkeys(vehicles)}
        return np.stack([made[v] for v in vehicles]) if len(vehicles) > 1 else next(iter(made.values()))

    psi = float(mission.reference(0.0)[0][REF_PSI])
    start = rows(lambda v: rotor_hover_state(v, mission), flown) if x0 is None else rotor_initial_states(flown, x0, n)
    args = (
        grid,
        start,
        np.broadcast_to(rows(RotorVehicle.row, flown), (n, flown[0].row().size)),
        controller_function,
        gains,
        mission.function,
        mp,
    )
    plant = dict(
        alloc=rows(lambda v: np.r_[duty_to_thrust(v).ravel(), v.kf], believed),
        vp_ctrl=rows(lambda v: paper_equivalent(v).rows(1)[0], believed),
        psi0=psi if x0 is None else np.broadcast_to(np.atleast_2d(x0)[:, PSI], (n,)).copy(),
        touchdown_speed=np.array([v.touchdown_speed for v in flown]) if len(flown) > 1 else flown[0].touchdown_speed,
        rotor_names=state_names(flown[0].n_rotors),
    )
    return args, plant


def fly_rotor(
    grid: np.ndarray,
    vehicle: RotorVehicle,
    controller_vehicle: RotorVehicle | None,
    controller_function: Any,
    gains: np.ndarray,
    mission: Any,
    mp: np.ndarray,
    n: int,
    *,
    x0: np.ndarray | None = None,
    **engine: Any,
) -> SimResult:
    """The closed-loop flight of ``n`` rotor-plant vehicles with their whole log (at ``log_every``).

    Parameters
    ----------
    grid, vehicle, controller_vehicle, controller_function, gains, mission, mp, n, x0
        As in :func:`rotor_engine_inputs`.
    **engine : Any
        :func:`quadcruise.sim.rotor_batch.fly_rotor_vehicles`'s other keywords (memory,
        disturbance, sensors, seed, first_vehicle, max_step, log_every, limits, meta).

    Returns
    -------
    SimResult
    """
    args, plant = rotor_engine_inputs(
        grid, vehicle, controller_vehicle, controller_function, gains, mission, mp, n, x0, engine.get("meta")
    )
    t, start, rp, function, gains, mission_function, mp = args
    alloc, vp_ctrl = plant.pop("alloc"), plant.pop("vp_ctrl")
    return fly_rotor_vehicles(
        t, start, rp, alloc, vp_ctrl, function, gains, mission_function, mp, **plant, **engine
    )  # fmt: skip


class RotorPlant(Plant):
    """The rotor-speed plant (:data:`ROTOR`)."""

    def vehicles(self, vehicle: Any) -> tuple:
        """One RotorVehicle, or the tuple of one per vehicle, as a tuple."""
        return rotor_batch(vehicle)

    def count(self, vehicle: Any) -> int | None:
        """The length of a tuple of vehicles (one per flown vehicle); None for one vehicle."""
        return len(vehicle) if isinstance(vehicle, tuple) else None

    def describe(self, vehicle: Any) -> str | None:
        """``the rotor-speed plant, n rotors (its source)``."""
        return f"the rotor-speed plant, {vehicle.n_rotors} rotors ({vehicle.source or 'user'})"

    def longest_step(self, vehicle: Any, dt: float) -> float:
        """No longer than half the faster motor time constant (docs/gym.md: RK4 on the motor lag)."""
        return min(dt, 0.5 * min(vehicle.tau_up, vehicle.tau_down))

    def px4_fields(self, vehicle: Any) -> dict:
        """The vehicle's rotors (CA_ROTOR*) and THR_MDL_FAC 1 (thrust kf w^2: the speed's square)."""
        return {"rotors": tuple(tuple(map(float, r)) for r in vehicle.rotors), "thrust_curve": 1.0}

    def log_width(self, vehicles: tuple) -> int:
        """The rotor state's 13 + n columns."""
        return vehicles[0].n_rotors + ROTOR_W1

    def check_environment(self, vehicles: tuple, environment: Any) -> None:
        """Wind refused on a vehicle without aerodynamics (:func:`check_wind_acts`)."""
        check_wind_acts(vehicles, environment)

    def check_x0(self, vehicles: tuple, x0: np.ndarray, n: int) -> None:
        """Paper-layout thrusts the rotors cannot give refused (:func:`rotor_initial_states`)."""
        rotor_initial_states(vehicles, x0, n)

    def equivalent(self, vehicles: tuple) -> Any:
        """The vehicles' "+" equivalents (:func:`batch_equivalent`): one Vehicle, batched for several."""
        return batch_equivalent(vehicles)

    def record(self, vehicles: tuple) -> dict:
        """``plant = "rotor"`` and each field (:func:`vehicle_record`)."""
        return vehicle_record(vehicles)

    def controller_record(self, vehicle: Any) -> dict:
        """``plant = "rotor"`` and the controller vehicle's fields."""
        return {"plant": "rotor", **vehicle.to_dict()}

    def check_controller_vehicle(self, flown: tuple, believed: Any, where: str = "fly():") -> None:
        """Of this plant, and with as many rotors as the flown vehicle; a layout the mixer serves."""
        super().check_controller_vehicle(flown, believed, where)
        believed = (believed,) if believed is not None else flown
        if believed[0].n_rotors != flown[0].n_rotors:
            raise InputError(
                f"{where} the controller vehicle has {believed[0].n_rotors} rotors, the flown vehicle "
                f"{flown[0].n_rotors}: the controller's rotor commands would not fit".lstrip()
            )
        for b in dict.fromkeys(believed):  # a layout the mixer cannot serve: one line, before any work
            duty_to_thrust(b)

    def bandwidths(self, believed: tuple) -> list[float]:
        """Each believed vehicle's "+" equivalent's omega = 1 / tau_up [rad/s]."""
        return [paper_equivalent(b).omega for b in believed]

    def flight(self, grid, vehicle, controller_vehicle, controller, gains, mission, mp, n, *, x0, paper_x0, meta, **kw):
        """:func:`rotor_engine_inputs`, from the rotor states of ``x0`` (the given paper-layout
        initial states, or None: hovering at the mission's start)."""
        return rotor_engine_inputs(grid, vehicle, controller_vehicle, controller, gains, mission, mp, n, x0, meta)

    def check_arrays(self, where: str, args: tuple, options: dict) -> None:
        """The rotor plant's arrays: ``alloc`` of 4 n + 1 columns (n rotors), ``vp`` rows of
        :meth:`~quadcruise.model.rotor_vehicle.RotorVehicle.row`'s width for n rotors, ``x0`` of
        13 + n, ``vp_ctrl`` given (the controller's equivalent paper row)."""
        alloc, vp_ctrl = options["alloc"], options.get("vp_ctrl")
        width = np.shape(alloc)[-1] if np.ndim(alloc) else 0
        n = (width - 1) // 4
        if np.ndim(alloc) not in (1, 2) or width < 13 or (width - 1) % 4:
            raise InputError(
                f"{where} argument alloc: shape {np.shape(alloc)}; the rotor plant's allocation rows have 4 n + 1 "
                "columns (n >= 3 rotors; quadcruise.model.equivalent.duty_to_thrust(v).ravel(), then kf)"
            )
        fits = {
            "x0": (args[1], ROTOR_W1 + n, f"rotor states of {n} rotors"),
            "vp": (args[2], ROTOR_PARAMS.size + ROTOR_ARM.size * n, f"RotorVehicle.row() rows of {n} rotors"),
            "vp_ctrl": (vp_ctrl, PARAMS.size, "the controller's equivalent paper row (paper_equivalent(v).rows(1))"),
        }
        for name, (value, columns, what) in fits.items():
            if value is None:
                raise InputError(f"{where} argument {name} is needed on the rotor plant (alloc given): {what}")
            shape = np.shape(value)
            if len(shape) not in (1, 2) or shape[-1] != columns:
                raise InputError(
                    f"{where} argument {name}: shape {shape}; alloc is given (the rotor plant, {n} rotors): "
                    f"{what}, {columns} columns"
                )

    def fly(self, args: tuple, options: dict) -> SimResult:
        """:func:`~quadcruise.sim.rotor_batch.fly_rotor_vehicles`."""
        t, start, rp, function, gains, mission_function, mp = args
        options = dict(options)
        alloc, vp_ctrl = options.pop("alloc"), options.pop("vp_ctrl")
        return fly_rotor_vehicles(t, start, rp, alloc, vp_ctrl, function, gains, mission_function, mp, **options)

    def stepper_inputs(self, stepper, t_grid, x0, vp, gains, mp, vp_ctrl, shared: dict, own: dict) -> dict:
        """``rotor_inputs``; the Stepper keeps the allocation, the initial yaws, the ground, the
        carry, the paper-layout state it shows and the rotor log."""
        if vp_ctrl is None:
            raise InputError("Stepper: a rotor-plant flight needs vp_ctrl, the controller's equivalent paper row")
        self.refuse("Stepper:", "full_dynamics", own.get("full_dynamics"))
        touchdown_speed = own.get("touchdown_speed")
        inp = rotor_inputs(
            t_grid, x0, vp, own["alloc"], vp_ctrl, gains, mp, psi0=own.get("psi0", 0.0),
            touchdown_speed=touchdown_speed, **shared,
        )  # fmt: skip
        stepper.alloc, stepper.psi0, stepper.touchdown = inp["alloc"], inp["psi0"], inp["touchdown"]
        stepper.ground = touchdown_speed is not None
        stepper.carry = np.zeros((inp["n"], rotor_carry_width(int(shared["sensor_delay"]))))
        stepper._paper_state = paper_states(inp["x0"], inp["vp"], stepper.psi0)  # then written by each step
        stepper.log_rotor = np.empty((inp["n"], int(own["periods"]) + 1, inp["x0"].shape[1]))
        return inp

    def observed(self, stepper) -> np.ndarray:
        """The paper-layout state the kernel wrote at the last step
        (:func:`~quadcruise.sim.rotor_flight.paper_state`)."""
        return stepper._paper_state

    def restart(self, stepper, rows: np.ndarray, start: np.ndarray) -> None:
        """The kernel starts a vehicle at period 0 afresh, its carry unread: only its paper-layout state."""
        stepper._paper_state[rows] = paper_states(np.ascontiguousarray(start), stepper.vp[rows], stepper.psi0[rows])

    def step_args(self, stepper, shared: dict) -> tuple:
        """:class:`~quadcruise.sim.kernel_args.RotorKernelArgs`."""
        return RotorKernelArgs(
            **shared,
            psi0=stepper.psi0,
            rp=stepper.vp,
            alloc=stepper.alloc,
            ground=stepper.ground,
            touchdown=stepper.touchdown,
            log_rotor=stepper.log_rotor,
            seen_final=stepper._paper_state,
        )

    def own_logs(self, stepper) -> tuple:
        """The rotor state's log."""
        return (stepper.log_rotor,)

    def result_parts(self, stepper, logs: tuple, names: tuple) -> dict:
        """``rotor_states``, ``rotor_final_state`` and ``rotor_names``."""
        return {"rotor_states": logs[0], "rotor_final_state": stepper.state, "rotor_names": tuple(names)}


ROTOR = RotorPlant(
    name="rotor",
    vehicle_class=RotorVehicle,
    state=ROTOR_BODY,
    params=ROTOR_PARAMS,
    carry=ROTOR_CARRY,
    fly_pieces=fly_rotor_pieces,
    kernel_args=RotorKernelArgs,
    command='the duties of the believed vehicle\'s "+" equivalent, through its allocation to rotor speeds held in '
    "[w_min, w_max]",
    saturation="rotor speed commands were held in [w_min, w_max]",
    takes_speeds=True,
    replay_step=1e-4,
    refuses={
        "full_dynamics": "not for a rotor-plant vehicle (its plant has no Euler-angle kinematics to choose: it "
        "flies the quaternion)",
    },
    designs_gains=True,
)
"""The rotor-speed plant (:class:`quadcruise.model.rotor_vehicle.RotorVehicle`)."""

__all__ = [
    "ROTOR",
    "RotorPlant",
    "batch_equivalent",
    "check_wind_acts",
    "fly_rotor",
    "rotor_batch",
    "rotor_engine_inputs",
    "rotor_hover_state",
    "rotor_initial_states",
    "vehicle_record",
]
