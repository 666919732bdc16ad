"""What :func:`quadcruise.fly` does differently for a rotor-plant vehicle
(:class:`~quadcruise.model.rotor_vehicle.RotorVehicle`): the vehicle by preset name, the
controller's gains designed for the vehicle it believes, the initial hover, and the flight
through :func:`quadcruise.sim.rotor_batch.fly_rotor_vehicles`.

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
import math
from typing import Any

import numpy as np

from quadcruise.control import CONTROLLERS, controller_from_name
from quadcruise.control.registry import rotor_gains
from quadcruise.errors import InputError
from quadcruise.layout import PSI, REF_PSI, REF_Z
from quadcruise.missions import Mission
from quadcruise.model.equivalent import duty_to_thrust, paper_equivalent
from quadcruise.model.rotor_plant import QW, QZ, ROTOR_W1, RZ, state_names
from quadcruise.model.rotor_plant import RP as RATE_P
from quadcruise.model.rotor_vehicle import AERO_FIELDS, RotorVehicle
from quadcruise.model.vehicle import Vehicle
from quadcruise.sim.result import SimResult
from quadcruise.sim.rotor_batch import fly_rotor_vehicles


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


def rotor_flight_setup(vehicle: Any, controller_vehicle: Any, controller: Any) -> tuple[bool, Any]:
    """Whether a flight is of a rotor-plant vehicle, and its controller (designed when named).

    Parameters
    ----------
    vehicle, controller_vehicle : Vehicle or RotorVehicle or None
        The flown vehicle and the one the controller believes.
    controller : str, Controller or list
        ``fly``'s controller argument.

    Returns
    -------
    rotor : bool
        The flown vehicle is a RotorVehicle.
    controller : str, Controller or list
        A built-in name turned into that controller with gains for the controller vehicle's
        bandwidth (:func:`designed_controller`); anything else as given.

    Raises
    ------
    InputError
        A rotor vehicle believed as a paper vehicle or the other way round, or a controller
        vehicle with another number of rotors: the controller's rotor commands would not fit.
    """
    flown = rotor_batch(vehicle)
    rotor = flown is not None
    if controller_vehicle is not None and isinstance(controller_vehicle, RotorVehicle) != rotor:
        raise InputError(
            "fly(): vehicle and controller_vehicle must be of one plant: a RotorVehicle flown with a "
            "RotorVehicle as the controller's model, or a paper Vehicle with a paper Vehicle"
        )
    if not rotor:
        return False, controller
    believed = (controller_vehicle,) if controller_vehicle is not None else flown
    if believed[0].n_rotors != flown[0].n_rotors:
        raise InputError(
            f"fly(): the controller vehicle has {believed[0].n_rotors} rotors, the flown vehicle "
            f"{flown[0].n_rotors}: the controller's rotor commands would not fit"
        )
    for b in dict.fromkeys(believed):  # a layout the mixer cannot serve: one line, before any work
        duty_to_thrust(b)
    if isinstance(controller, str) and controller in CONTROLLERS:
        bandwidths = [paper_equivalent(b).omega for b in believed]
        designs = {w: designed_controller(controller, w) for w in dict.fromkeys(bandwidths)}
        controller = designs[bandwidths[0]] if len(designs) == 1 else [designs[w] for w in bandwidths]
    return True, controller


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


def rotor_hover_state(vehicle: RotorVehicle, mission: Mission) -> np.ndarray:
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
    mission: Mission,
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
    mission: Mission,
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


__all__ = [
    "as_vehicle",
    "batch_equivalent",
    "rotor_batch",
    "vehicle_record",
    "check_wind_acts",
    "designed_controller",
    "fly_rotor",
    "rotor_engine_inputs",
    "rotor_initial_states",
    "rotor_flight_setup",
    "rotor_hover_state",
]
