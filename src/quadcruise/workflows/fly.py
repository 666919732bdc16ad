"""``fly``: a mission flown by a controller on one vehicle or N, through the engine.

Examples
--------
>>> import quadcruise as qc
>>> res = qc.fly("step", duration=10.0)
>>> res.ok.tolist()
[True]
>>> bool(abs(res.final_state[0, 0] - 1.0) < 0.02)      # the 1 m step in x is reached
True
"""

from __future__ import annotations

import dataclasses
import math
import warnings
from typing import Any

import numpy as np

from quadcruise import checks
from quadcruise._version import __version__
from quadcruise.control import controller_record
from quadcruise.disturbances import CustomDisturbance, Environment, SensorNoise
from quadcruise.errors import InputError, LogWarning, reject_unknown
from quadcruise.estimation.stage import Ekf, Sensors
from quadcruise.layout import OBSERVATION_SIZE, STATE_SIZE
from quadcruise.missions import Mission, as_mission, stack_params
from quadcruise.model.rotor_vehicle import RotorVehicle
from quadcruise.model.vehicle import Vehicle
from quadcruise.protocols import ControllerLike
from quadcruise.sim.chunked import watch_again
from quadcruise.sim.inputs import Limits, time_grid
from quadcruise.sim.result import SimResult
from quadcruise.workflows.fly_failures import (
    altitude_bound,
    flight_warnings_named,
    mark_lost_track,
    mark_off_track,
    off_track_since,
    position_error,
    steady_bound,
    track_bound,
)
from quadcruise.workflows.fly_failures import warn_about as _warn_about  # the name fly() calls
from quadcruise.workflows.fly_inputs import (
    FLY_OPTIONS,
    batch_log_every,
    check_log_every,
    check_reference_fits,
    check_run_size,
    default_duration,
    engine_inputs,
    fly_missions,
    hover_state,
    initial_states,
    log_bytes,
    per_vehicle_controllers,
    vehicle_indices,
)
from quadcruise.workflows.onboard import onboard_inputs, vehicle_gravity
from quadcruise.workflows.rotor_fly import as_vehicle, flight_setup
from quadcruise.workflows.track_watch import TrackWatch


def fly(
    mission: Mission | str = "circle",
    controller: ControllerLike | str | list = "nlpd",
    *,
    vehicle: Vehicle | None = None,
    duration: float | None = None,
    dt: float = 1e-3,
    max_step: float | None = None,
    n: int | None = None,
    x0: Any = None,
    log_every: int | None = None,
    limits: Limits | None = None,
    missions: list[Mission] | None = None,
    controller_vehicle: Vehicle | None = None,
    full_dynamics: bool = False,
    environment: Environment | None = None,
    sensors: SensorNoise | Sensors | None = None,
    estimator: Ekf | None = None,
    seed: int = 0,
    first_vehicle: int | np.ndarray = 0,
    max_track_error: float | None = None,
    max_steady_error: float | None = None,
    max_altitude_error: float | None = None,
    **unknown: Any,
) -> SimResult:
    """Fly a mission with a controller and return the logged flight.

    Parameters
    ----------
    mission : Mission or str
        A mission object, or a name ('hover', 'step', 'circle', 'square') for its defaults.
    controller : Controller or str, or list of Controller
        A controller object, or a name ('nlpd', ...) for its defaults; or one controller per
        vehicle, all of one kind (the same class, the same memory size and gains layout),
        so that each vehicle flies its own gains in the one batch (a tuner's generation).
    vehicle : Vehicle, RotorVehicle, list of RotorVehicle or str, optional
        Table I by default; a batched Vehicle gives each of the N vehicles its own values. A
        :class:`~quadcruise.model.rotor_vehicle.RotorVehicle` or a preset's name (``"iris"``)
        flies the rotor-speed plant (:mod:`quadcruise.workflows.rotor_fly`; docs/vehicles.md):
        the controller believes its paper equivalent, and a controller given by name gets
        gains designed for it; a list of RotorVehicle (one rotor count) flies one per vehicle.
    duration : float, optional
        Flight time [s]; one lap (circle, square), step time + 10 s, or 5 s by default.
    dt : float
        Control period [s] (1 kHz by default); the command is held in between.
    max_step : float, optional
        Longest RK4 substep [s]; ``dt`` by default.
    n : int, optional
        Number of vehicles; taken from ``vehicle``, ``x0`` or ``missions`` if they are batched.
    x0 : (16,) or (N, 16) array, optional
        Initial states; by default each vehicle hovers at x = y = 0 at the mission's
        starting altitude and yaw. A rotor-plant vehicle takes them in the same layout
        (:func:`~quadcruise.workflows.rotor_fly.rotor_initial_states`: the Euler angles as its
        quaternion, F1..F4 as its rotor speeds, or its hover for the hover thrusts).
    log_every : int, optional
        Log every this many control periods (a divisor of them). By default every period,
        unless a batch's log would exceed :data:`LOG_BUDGET` (256 MiB): then the smallest divisor
        that fits, said in a :class:`~quadcruise.errors.LogWarning`. A ``log_every`` given is
        kept (a log over half the memory is refused). Either way the track checks (``lost
        track``, ``off track``) are made at every period as the flight goes, so the statuses
        and times are those of the full log, whatever the log keeps (on both plants).
    limits : Limits, optional
        Divergence bounds.
    missions : list of Mission, optional
        One mission of the same kind per vehicle (instead of ``mission``).
    controller_vehicle : Vehicle or RotorVehicle, optional
        The vehicle the controller believes it flies (its model); ``vehicle`` by default; of
        the flown vehicle's plant.
        Give the nominal vehicle here and a perturbed one as ``vehicle`` to fly with model error.
    full_dynamics : bool
        Fly the higher-fidelity plant (exact Euler-angle kinematics) instead of the paper's.
    environment : Environment or CustomDisturbance, optional
        Wind, gusts, turbulence, rotor loss, external force (any field may hold one value per
        vehicle). Wind acts through drag: give a vehicle with drag (:func:`~quadcruise.disturbances.with_drag`).
    sensors : SensorNoise or Sensors, optional
        Noise on what the controller sees and its delay [s], turned into whole control periods
        of this flight's ``dt``; or the sensor models the vehicle carries
        (:class:`~quadcruise.estimation.Sensors`: IMU, GPS, barometer, magnetometer), sampled
        in the compiled period (each rate a divisor of the control rate) and logged in the
        result's ``observations`` (``to_pandas()``'s ``*_est`` and sensor columns).
    estimator : Ekf, optional
        The error-state EKF between the :class:`~quadcruise.estimation.Sensors` and the
        controller (docs/sensors.md): the controller sees its estimate instead of the truth;
        needs an IMU and a GPS. ``metrics()`` then reports the estimation error.
    seed : int
        Seed of every random draw (turbulence, sensor noise).
    first_vehicle : int or array of int
        Index of the first vehicle in a larger population: vehicle i's random stream comes from
        (seed, first_vehicle + i) only, so a batch split in parts flies the same numbers. An
        (N,) array gives each vehicle's index itself (repeats allowed: vehicles that share an
        index share their noise and turbulence).
    max_track_error : float, optional
        Tracking bound [m]: a vehicle whose position error (3-D, at the logged instants) exceeds
        it gets the status ``lost track`` from the first such instant on (it flies on; the
        result says so, and ``fly`` warns). By default :func:`track_bound`: 1 m, plus the
        diagonal of the box the mission's reference path spans, plus the vehicle's initial
        position error (the default circle of radius 2 m: 8.66 m; a 1 m step: 2 m; hover:
        1 m); ``numpy.inf`` turns it off. It catches a runaway.
    max_steady_error : float, optional
        Steady bound [m]: a vehicle that flew the whole mission within ``max_track_error``
        but whose position error after the transient (from its settling into 5 % on; the
        whole flight without a step; the error at the end if it never settles) exceeds it
        gets the status ``off track``, from the first such instant: it never got onto its
        path, or left it (a circle too fast to fly, a vehicle that sags or falls, a limit
        cycle). By default :func:`steady_bound`: the larger of 1 m and a quarter of the
        longest side of the box the reference spans over the flight (1 m for the built-in
        missions), and on the altitude error alone :func:`altitude_bound` (half the
        mission's lowest altitude: 0.5 m for the built-in missions at 1 m), the rule a Monte
        Carlo sweep applies; a value given here bounds both; ``numpy.inf`` turns it off.
    max_altitude_error : float, optional
        The bound [m] on the altitude error alone after the transient (``off track`` too): by
        default :func:`altitude_bound`, or ``max_steady_error`` where that is given; a Monte
        Carlo sweep gives its ``max_altitude_error_m`` here; ``numpy.inf`` turns it off.
    **unknown : Any
        Refused: any other keyword is an InputError naming the options (see
        :data:`FLY_OPTIONS`), so a misspelt one is not silently ignored.

    Returns
    -------
    SimResult
        With ``metrics()``, ``to_pandas()`` and ``plot()``. A vehicle that diverged stops
        and its status says why and when (a warning says so too), as does any clipping
        of the rotor duties.

    Raises
    ------
    ArgumentTypeError
        An argument of the wrong type (a TypeError too): text for a number, a class for an
        object, a float or a bool for ``seed``, ``n`` or ``log_every``, anything but a bool for
        ``full_dynamics``, a controller whose ``function`` is not compiled with ``CONTROLLER_SIG``
        (:mod:`quadcruise.checks`); before any work.
    InputError
        A value out of range (a ValueError), e.g. ``dt <= 0``, ``seed < 0``, a ``log_every``
        that does not divide the flight's control periods, a flight too large to log.
    """
    reject_unknown("fly()", unknown, FLY_OPTIONS)
    w = "fly()"  # every argument checked before any work
    mission = as_mission(mission, w)
    missions = fly_missions(missions)
    vehicle = checks.instance(w, "vehicle", as_vehicle(vehicle), (Vehicle, RotorVehicle, tuple)) or Vehicle.paper()
    controller_vehicle = checks.instance(w, "controller_vehicle", controller_vehicle, (Vehicle, RotorVehicle))
    plant, controller = flight_setup(vehicle, controller_vehicle, controller)  # the plant asked (sim/plants)
    flown = plant.vehicles(vehicle)
    controllers = per_vehicle_controllers(controller)
    controller = controllers[0]
    duration = checks.number(w, "duration", duration, "pos", unit="s", optional=True)
    dt = checks.number(w, "dt", dt, "pos", unit="s")
    max_step = checks.number(w, "max_step", max_step, "pos", unit="s", optional=True)
    n = checks.whole(w, "n", n, 1, optional=True)
    log_every = checks.whole(w, "log_every", log_every, 1, optional=True)
    checks.instance(w, "limits", limits, Limits)
    full_dynamics = checks.flag(w, "full_dynamics", full_dynamics)
    checks.instance(w, "environment", environment, (Environment, CustomDisturbance))
    checks.instance(w, "sensors", sensors, (SensorNoise, Sensors, tuple))  # a tuple: one Sensors per vehicle
    checks.instance(w, "estimator", estimator, Ekf)
    plant.check_environment(flown, environment)
    seed = checks.whole(w, "seed", seed)
    first_vehicle = vehicle_indices(first_vehicle)
    bounds = (("max_track_error", max_track_error), ("max_steady_error", max_steady_error))
    for name, value in (*bounds, ("max_altitude_error", max_altitude_error)):
        checks.number(w, name, value, "pos", unit="m", optional=True, infinite=True)
    x0 = initial_states(x0)
    plant.refuse(w, "full_dynamics", full_dynamics)
    plant.refuse_sensors(f"{w} argument sensors", sensors)
    sizes = {
        s
        for s in (
            plant.count(vehicle),
            None if x0 is None or np.ndim(x0) < 2 else np.shape(x0)[0],
            None if missions is None else len(missions),
            n,
            len(controllers) if len(controllers) > 1 else None,
            None if np.ndim(first_vehicle) == 0 else np.size(first_vehicle),
        )
        if s is not None
    }
    if len(sizes) > 1:
        raise InputError(f"the number of vehicles is ambiguous: {sorted(sizes)}")
    n = sizes.pop() if sizes else 1
    if n < 1:
        raise InputError(f"the number of vehicles must be at least 1, got {n}")
    if x0 is not None:  # what cannot start the plant, refused before any work
        plant.check_x0(flown, x0, n)
    mp = stack_params(missions if missions is not None else mission, n=None if missions else n)
    first = missions[0] if missions else mission
    duration = default_duration(first) if duration is None else duration
    d, h = duration, dt
    extra = plant.log_width(flown)  # a plant's own state logged beside the paper layout (rotor: 13 + n)
    extra += OBSERVATION_SIZE if isinstance(sensors, Sensors) else 0  # and a flight on sensors their log
    steps = round(d / h) if 0 < h <= d < math.inf else 0
    chosen = log_every is None and n > 1 and steps > 0 and batch_log_every(n, steps, extra) > 1
    # a batch whose full log would not fit in LOG_BUDGET: a coarser log, checked at every period
    log_every = batch_log_every(n, steps, extra) if chosen else 1 if log_every is None else log_every
    # the track checks see every period whatever the log keeps: a flight's status and time do not
    # depend on its log (a Monte Carlo sweep's 10 ms log, `montecarlo --case`, `fly` alone agree)
    watched = log_every > 1 and steps > 0
    if steps:  # sized before the grid is allocated
        substeps = max(1, math.ceil(h / float(max_step or h) - 1e-9))
        check_run_size(n, steps, int(log_every), substeps, watched, extra)
    if chosen:
        full, kept = (log_bytes(n, steps, k, extra) / 2**30 for k in (1, log_every))
        warnings.warn(
            f"fly(): the log of {n:,} vehicles x {round(d / h) + 1:,} instants would take {full:.1f} GiB: logging "
            f"every {log_every} periods ({kept:.2f} GiB; the track checks still see every period); give log_every "
            "to choose",
            LogWarning,
            stacklevel=2,
        )
    observation, onboard_record = onboard_inputs(
        sensors, estimator, g=vehicle_gravity(flown), n=n, dt=float(dt),
        seed=seed, first_vehicle=first_vehicle, where=w,
    )  # fmt: skip
    grid = time_grid(float(duration), float(dt))
    check_log_every(log_every, grid.size - 1)
    if isinstance(sensors, SensorNoise):
        sensors.check_fits(duration)
    plant.check_vehicles(flown)
    check_reference_fits(missions or [first], float(duration), limits or Limits())
    given_x0 = None if x0 is None else np.asarray(x0, dtype=float).tolist()
    given = x0  # a plant with a state of its own starts from it: hovering at the mission's start unless given
    x0 = hover_state(plant.equivalent(flown[:1]), n, first) if x0 is None else x0
    meta = {
        "workflow": "fly",
        "mission": [m.to_dict() for m in missions] if missions else mission.to_dict(),
        "controller": controller_record(controller),
        **({"controllers": [controller_record(c) for c in controllers]} if len(controllers) > 1 else {}),
        "vehicle": plant.record(flown),
        "duration_s": float(duration),
        "dt_s": float(dt),
        "max_step_s": float(max_step or dt),
        "n": n,
        "version": __version__,
        "full_dynamics": bool(full_dynamics),
        "seed": seed,
        "log_every": int(log_every),
        **({"log_every_chosen": True} if chosen else {}),
        "max_track_error": None if max_track_error is None else float(max_track_error),
        "max_steady_error": None if max_steady_error is None else float(max_steady_error),
        **({} if max_altitude_error is None else {"max_altitude_error": float(max_altitude_error)}),
        "initial_state": given_x0,
    }
    if environment is not None:
        meta["environment"] = (
            environment.to_dict()
            if isinstance(environment, Environment)
            else {"custom": getattr(environment.function, "__name__", "disturbance")}
        )
    if isinstance(sensors, SensorNoise):
        meta["sensors"] = sensors.to_dict()
    meta.update(onboard_record)  # sensor models and the estimator
    if controller_vehicle is not None:
        meta["controller_vehicle"] = plant.controller_record(controller_vehicle)
    if len(controllers) == 1 and hasattr(controller, "log_parameters") and len(flown) == 1:
        from quadcruise.model.equivalent import paper_equivalent  # PX4's parameters as flown, for to_ulog

        meta["px4_parameters"] = controller.log_parameters(paper_equivalent(controller_vehicle or flown[0]))
        if not controller.rotors and plant.designs_gains:  # the by-name px4, designed for the vehicle
            meta["px4_parameters_note"] = (
                "holds the px4 design as PX4 parameters, but the px4 controller by name allocates on PX4's "
                "quadrotor x, not the vehicle's rotors: fly --params of the log flies the vehicle's rotors (as "
                "PX4 would), another flight; fly with --params FILE for a log that flies back the same"
            )
    gains, memory = (
        (controller.gains(), controller.memory())
        if len(controllers) == 1
        else (np.stack([c.gains() for c in controllers]), np.stack([c.memory() for c in controllers]))
    )
    bound = (
        track_bound(missions or [first], np.broadcast_to(x0, (n, STATE_SIZE)), n)
        if max_track_error is None
        else np.full(n, float(max_track_error))
    )
    steady = (
        (
            np.array([steady_bound(m, duration) for m in missions])
            if missions
            else np.full(n, steady_bound(first, duration))
        )
        if max_steady_error is None
        else np.full(n, float(max_steady_error))
    )
    vertical = (
        (
            np.array([altitude_bound(m, duration) for m in missions])
            if missions
            else np.full(n, altitude_bound(first, duration))
        )
        if max_steady_error is None
        else steady
    )
    if max_altitude_error is not None:
        vertical = np.full(n, float(max_altitude_error))
    options = dict(
        memory=memory,
        max_step=max_step or dt,
        log_every=log_every,
        limits=limits,
        meta=meta,
        seed=seed,
        first_vehicle=first_vehicle,
        **engine_inputs(environment, sensors if isinstance(sensors, SensorNoise) else None, n, dt),
        **({} if observation is None else {"observation": observation}),
    )
    args, own = plant.flight(
        grid, vehicle, controller_vehicle, controller.function, gains, first, mp, n,
        x0=given, paper_x0=x0, meta=meta, full_dynamics=full_dynamics,
    )  # fmt: skip
    options.update(own)
    watch = None
    if watched:  # the log keeps every log_every-th period; the kernel's checks see every one
        mission_record = meta["mission"] if isinstance(meta["mission"], dict) else {}
        watch = TrackWatch(grid, mission_record, bound, steady, vertical)
    result = plant.fly(args, {**options, "track": None if watch is None else watch.arrays})
    if watch is not None:

        def again(vehicles, periods, feed):  # the head of some vehicles, flown again (track_watch.py)
            watch_again(*args, vehicles=vehicles, periods=periods, watch=feed, **options)

        status, t_stop = watch.verdict(result.status, result.t_stop, again)
        result = dataclasses.replace(result, status=status, t_stop=t_stop)
    result.meta["max_track_error_m"] = bound.tolist() if n > 1 else float(bound[0])
    result.meta["max_steady_error_m"] = steady.tolist() if n > 1 else float(steady[0])
    result.meta["max_altitude_error_m"] = vertical.tolist() if n > 1 else float(vertical[0])
    if not watched:
        err = position_error(result)
        result = mark_lost_track(result, bound, err)
        result = mark_off_track(result, steady, err, vertical)
    _warn_about(result)
    return result


def write_flight(result: SimResult, out, fmt: str = "csv", metrics=None) -> None:
    """:meth:`SimResult.write` into a folder the caller has already checked (``force``).

    Parameters
    ----------
    result : SimResult
        The flight.
    out : str or os.PathLike
        The folder.
    fmt : {"csv", "parquet"}
        Format of the traces.
    metrics : pandas.DataFrame, optional
        The flight's metrics, if already computed.
    """
    result.write(out, fmt=fmt, force=True, metrics=metrics)


__all__ = [
    "fly",
    "default_duration",
    "flight_warnings_named",
    "hover_state",
    "per_vehicle_controllers",
    "steady_bound",
    "altitude_bound",
    "off_track_since",
    "write_flight",
]
