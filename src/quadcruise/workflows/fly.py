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

import contextlib
import dataclasses
import math
import os
import warnings
from typing import Any

import numpy as np

from quadcruise import checks
from quadcruise._version import __version__
from quadcruise.control import as_controller, controller_record
from quadcruise.disturbances import CustomDisturbance, Environment, SensorNoise
from quadcruise.errors import FlightWarning, InputError, LogWarning, reject_unknown
from quadcruise.layout import F1, P_G, P_M, PSI, REF_PSI, REF_X, REF_Z, STATE_SIZE, X, Z
from quadcruise.missions import Mission, as_mission, stack_params
from quadcruise.model.equivalent import paper_equivalent
from quadcruise.model.rotor_vehicle import RotorVehicle
from quadcruise.model.vehicle import Vehicle
from quadcruise.protocols import ControllerLike
from quadcruise.sim.chunked import simulate_watched
from quadcruise.sim.engine import simulate
from quadcruise.sim.inputs import Limits, time_grid
from quadcruise.sim.result import SimResult
from quadcruise.sim.status import ExitStatus
from quadcruise.workflows.rotor_fly import as_vehicle, check_wind_acts, fly_rotor, rotor_flight_setup
from quadcruise.workflows.track_watch import TrackWatch


def default_duration(mission: Mission) -> float:
    """The mission's default flight time (:attr:`Mission.duration`).

    Parameters
    ----------
    mission : Mission
        The mission.

    Returns
    -------
    float
        Flight time [s]: one lap of a circle or square, 10 s after a step, the last
        waypoint and a settling time, 5 s of hover.

    Examples
    --------
    >>> from quadcruise.missions import Hover
    >>> default_duration(Hover())
    5.0
    """
    return float(mission.duration)


def hover_state(vehicle: Vehicle, n: int, mission: Mission) -> np.ndarray:
    """Initial states hovering level at the origin's x, y at the mission's start altitude and yaw.

    Parameters
    ----------
    vehicle : Vehicle
        The vehicle (batched or not): its mass and gravity set the hover thrust.
    n : int
        Number of vehicles.
    mission : Mission
        Its reference at t = 0 gives the altitude [m] and yaw [rad].

    Returns
    -------
    ndarray, shape (n, 16)
        Zero velocities, angles and rates but the yaw; each rotor at the hover thrust
        m g / 4 [N].
    """
    vp = vehicle.rows(n)
    ref0 = mission.reference(0.0)[0]
    x0 = np.zeros((n, STATE_SIZE))
    x0[:, Z] = ref0[REF_Z]
    x0[:, PSI] = ref0[REF_PSI]
    x0[:, F1 : F1 + 4] = (vp[:, P_M] * vp[:, P_G] / 4.0)[:, None]
    return x0


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
    sensors: SensorNoise | None = None,
    seed: int = 0,
    first_vehicle: int | np.ndarray = 0,
    max_track_error: float | None = None,
    max_steady_error: float | None = None,
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
    vehicle : Vehicle, RotorVehicle or str, optional
        Table I by default; a batched Vehicle gives each of the N vehicles its own values. A
        :class:`~quadcruise.model.rotor_vehicle.RotorVehicle` or a preset's name (``"iris"``)
        flies the rotor-speed plant (:mod:`quadcruise.workflows.rotor_fly`; docs/vehicles.md):
        the controller believes its paper equivalent, and a controller given by name gets
        gains designed for it.
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
        starting altitude and yaw.
    log_every : int, optional
        Log every this many control periods (a divisor of them). By default every period,
        unless a batch's log would exceed :data:`LOG_BUDGET` (256 MiB): then the smallest divisor
        that fits, said in a :class:`~quadcruise.errors.LogWarning`, and the track checks
        (``lost track``, ``off track``) are made at every period as the flight goes, so the
        statuses and times are those of the full log. A ``log_every`` given is kept, and the
        checks read its log (a log over half the memory is refused).
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
    sensors : SensorNoise, optional
        Noise on what the controller sees and its delay [s], turned into whole control periods
        of this flight's ``dt``.
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
    vehicle = checks.instance(w, "vehicle", as_vehicle(vehicle), (Vehicle, RotorVehicle)) or Vehicle.paper()
    controller_vehicle = checks.instance(w, "controller_vehicle", controller_vehicle, (Vehicle, RotorVehicle))
    rotor, controller = rotor_flight_setup(vehicle, controller_vehicle, controller)  # rotor_fly.py
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
    checks.instance(w, "sensors", sensors, SensorNoise)
    check_wind_acts(vehicle, environment)  # rotor_fly.py
    seed = checks.whole(w, "seed", seed)
    first_vehicle = vehicle_indices(first_vehicle)
    for name, value in (("max_track_error", max_track_error), ("max_steady_error", max_steady_error)):
        checks.number(w, name, value, "pos", unit="m", optional=True, infinite=True)
    x0 = initial_states(x0)
    if rotor and (x0 is not None or full_dynamics):
        raise InputError(
            f"fly() argument {'x0' if x0 is not None else 'full_dynamics'}: not for a rotor-plant vehicle "
            "(it starts hovering at the mission's start; its plant has no Euler-angle kinematics to choose)"
        )
    sizes = {
        s
        for s in (
            getattr(vehicle, "batch_size", None),
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
    mp = stack_params(missions if missions is not None else mission, n=None if missions else n)
    first = missions[0] if missions else mission
    duration = default_duration(first) if duration is None else duration
    d, h = duration, dt
    watched = log_every is None and n > 1 and 0 < h <= d < math.inf and batch_log_every(n, round(d / h)) > 1
    watched = watched and not rotor  # a rotor flight keeps its whole log (rotor_fly.py)
    # a batch whose full log would not fit in LOG_BUDGET: a coarser log, checked at every period
    log_every = batch_log_every(n, round(d / h)) if watched else 1 if log_every is None else log_every
    if 0 < h <= d < math.inf:  # sized before the grid is allocated
        substeps = max(1, math.ceil(h / float(max_step or h) - 1e-9))
        check_run_size(n, round(d / h), int(log_every), substeps, watched)
    if watched:
        full, kept = log_bytes(n, round(d / h), 1) / 2**30, log_bytes(n, round(d / h), log_every) / 2**30
        warnings.warn(
            f"fly(): the log of {n:,} vehicles x {round(d / h) + 1:,} instants would take {full:.1f} GiB: logging "
            f"every {log_every} periods ({kept:.2f} GiB; the track checks still see every period); give log_every "
            "to choose",
            LogWarning,
            stacklevel=2,
        )
    grid = time_grid(float(duration), float(dt))
    check_log_every(log_every, grid.size - 1)
    if sensors is not None:
        sensors.check_fits(duration)
    if not rotor:  # a RotorVehicle that cannot lift itself cannot be made
        check_can_hover(vehicle)
    check_reference_fits(missions or [first], float(duration), limits or Limits())
    given_x0 = None if x0 is None else np.asarray(x0, dtype=float).tolist()
    x0 = hover_state(paper_equivalent(vehicle) if rotor else vehicle, n, first) if x0 is None else x0
    meta = {
        "workflow": "fly",
        "mission": [m.to_dict() for m in missions] if missions else mission.to_dict(),
        "controller": controller_record(controller),
        **({"controllers": [controller_record(c) for c in controllers]} if len(controllers) > 1 else {}),
        "vehicle": {"plant": "rotor", **vehicle.to_dict()} if rotor else vehicle.to_dict(),
        "duration_s": float(duration),
        "dt_s": float(dt),
        "max_step_s": float(max_step or dt),
        "n": n,
        "version": __version__,
        "full_dynamics": bool(full_dynamics),
        "seed": seed,
        "log_every": int(log_every),
        **({"log_every_chosen": True} if watched else {}),
        "max_track_error": None if max_track_error is None else float(max_track_error),
        "max_steady_error": None if max_steady_error is None else float(max_steady_error),
        "initial_state": given_x0,
    }
    if environment is not None:
        meta["environment"] = (
            environment.to_dict()
            if isinstance(environment, Environment)
            else {"custom": getattr(environment.function, "__name__", "disturbance")}
        )
    if sensors is not None:
        meta["sensors"] = sensors.to_dict()
    if controller_vehicle is not None:
        meta["controller_vehicle"] = (
            {"plant": "rotor", **controller_vehicle.to_dict()} if rotor else controller_vehicle.to_dict()
        )
    vp_ctrl = None if controller_vehicle is None or rotor else controller_vehicle.rows(n)
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
    options = dict(
        memory=memory,
        max_step=max_step or dt,
        log_every=log_every,
        limits=limits,
        meta=meta,
        seed=seed,
        first_vehicle=first_vehicle,
        **engine_inputs(environment, sensors, n, dt),
    )
    if rotor:  # the rotor plant's own path (rotor_fly.py), its log whole
        result = fly_rotor(grid, vehicle, controller_vehicle, controller.function, gains, first, mp, n, **options)
    else:
        args = (grid, x0, vehicle.rows(n), controller.function, gains, first.function, mp)
        options.update(vp_ctrl=vp_ctrl, full_dynamics=full_dynamics)
        if watched:  # the log keeps every log_every-th period; the checks see every one
            mission_record = meta["mission"] if isinstance(meta["mission"], dict) else {}
            watch = TrackWatch(grid, mission_record, bound, steady, vertical)
            result = simulate_watched(*args, watch=watch.feed, **options)
            status, t_stop = watch.verdict(result.status, result.t_stop)
            result = dataclasses.replace(result, status=status, t_stop=t_stop)
        else:
            result = simulate(*args, **options)
    result.meta["max_track_error_m"] = bound.tolist() if n > 1 else float(bound[0])
    result.meta["max_steady_error_m"] = steady.tolist() if n > 1 else float(steady[0])
    result.meta["max_altitude_error_m"] = vertical.tolist() if n > 1 else float(vertical[0])
    if not watched:
        err = position_error(result)
        result = mark_lost_track(result, bound, err)
        result = mark_off_track(result, steady, err, vertical)
    _warn_about(result)
    return result


def per_vehicle_controllers(controller: Any) -> list:
    """The controllers of a flight: one for all vehicles, or one per vehicle, all of one kind.

    Parameters
    ----------
    controller : ControllerLike or str, or list or tuple of them
        One controller (or name), or one per vehicle.

    Returns
    -------
    list of ControllerLike
        One entry for a single controller; else one per vehicle, each checked by
        :func:`~quadcruise.control.as_controller`.

    Raises
    ------
    InputError
        An empty list, or controllers of different kinds: another class, compiled function,
        memory size or number of gains.

    Examples
    --------
    >>> from quadcruise.control import NLPD, Gonzalez
    >>> len(per_vehicle_controllers([NLPD(), NLPD(max_tilt=0.5)]))
    2
    >>> per_vehicle_controllers([NLPD(), Gonzalez()])
    Traceback (most recent call last):
        ...
    quadcruise.errors.InputError: the controllers of one flight must be of one kind: vehicle 1 flies a Gonzalez ...
    """
    if not isinstance(controller, (list, tuple)):
        return [as_controller(controller)]
    if not controller:
        raise InputError("the list of controllers is empty: give one controller per vehicle")
    out = [as_controller(c) for c in controller]
    first = out[0]
    shape = (np.shape(first.gains()), np.shape(first.memory()))
    for i, c in enumerate(out[1:], start=1):
        if type(c) is not type(first) or c.function is not first.function:
            raise InputError(
                f"the controllers of one flight must be of one kind: vehicle {i} flies a "
                f"{type(c).__name__} ({c.name}), vehicle 0 a {type(first).__name__} ({first.name})"
            )
        if (np.shape(c.gains()), np.shape(c.memory())) != shape:
            raise InputError(
                f"the controllers of one flight must have the same gains and memory sizes: "
                f"vehicle {i} has {np.size(c.gains())} gains and memory {np.size(c.memory())}, "
                f"vehicle 0 {np.size(first.gains())} and {np.size(first.memory())}"
            )
    return out


def fly_missions(missions: Any) -> list | None:
    """``fly(missions=)`` checked: None, or a non-empty list or tuple of Mission objects.

    Parameters
    ----------
    missions : Any
        The value given.

    Returns
    -------
    list of Mission or None

    Raises
    ------
    ArgumentTypeError
        Not a list or tuple, or an entry that is not a Mission (named by its index).
    InputError
        An empty list.
    """
    if missions is None:
        return None
    if not isinstance(missions, (list, tuple)):
        checks.fail("fly()", "missions", missions, "a list of Mission objects (one per vehicle) or None")
    if not missions:
        checks.fail("fly()", "missions", missions, "a non-empty list of Mission objects", kind=False)
    for i, m in enumerate(missions):
        checks.instance("fly()", f"missions[{i}]", m, Mission, optional=False)
    return list(missions)


def vehicle_indices(first_vehicle: Any) -> int | np.ndarray:
    """``fly(first_vehicle=)`` checked: a whole number >= 0, or a 1-D array of them.

    Parameters
    ----------
    first_vehicle : Any
        The value given.

    Returns
    -------
    int or numpy.ndarray
        The index, or an int64 array of indices.

    Raises
    ------
    ArgumentTypeError
        Not a whole number nor a 1-D array of whole numbers.
    InputError
        A negative index.
    """
    if np.ndim(first_vehicle) == 0:
        return checks.whole("fly()", "first_vehicle", first_vehicle)
    arr = np.asarray(first_vehicle)
    if arr.ndim != 1 or arr.size == 0 or arr.dtype.kind not in "iu":
        checks.fail("fly()", "first_vehicle", first_vehicle, "a whole number >= 0 or a 1-D array of them")
    if arr.min() < 0:
        checks.fail("fly()", "first_vehicle", first_vehicle, "a whole number >= 0 or a 1-D array of them", kind=False)
    return arr.astype(np.int64)


def initial_states(x0: Any) -> np.ndarray | None:
    """``fly(x0=)`` checked: None, or finite numbers of shape (16,) or (N, 16).

    Parameters
    ----------
    x0 : Any
        The value given.

    Returns
    -------
    numpy.ndarray or None
        A float copy.

    Raises
    ------
    ArgumentTypeError
        Not numbers, or another shape.
    InputError
        A value that is not finite.
    """
    if x0 is None:
        return None
    want = f"None or finite numbers of shape ({STATE_SIZE},) or (N, {STATE_SIZE})"
    try:
        arr = np.array(x0, dtype=float)
    except (TypeError, ValueError):
        checks.fail("fly()", "x0", x0, want)
    if isinstance(x0, (str, bytes)) or arr.ndim not in (1, 2) or arr.shape[-1] != STATE_SIZE or arr.size == 0:
        checks.fail("fly()", "x0", x0, want)
    if not np.isfinite(arr).all():
        checks.fail("fly()", "x0", x0, want, kind=False)
    return arr


FLY_OPTIONS = (
    "vehicle",
    "duration",
    "dt",
    "max_step",
    "n",
    "x0",
    "log_every",
    "limits",
    "missions",
    "controller_vehicle",
    "full_dynamics",
    "environment",
    "sensors",
    "seed",
    "first_vehicle",
    "max_track_error",
    "max_steady_error",
)
"""The keywords :func:`fly` takes besides the mission and the controller."""

MAX_LOG_FRACTION = 0.5
"""Largest share of the machine's memory a flight's log may take: :func:`check_run_size`."""
MAX_VEHICLE_STEPS = 2.0e10
"""Most vehicle-steps (vehicles x control periods) a flight may have: at the engine's few million
vehicle-steps per second on two cores, about two hours or more."""


LOG_BUDGET = 2**28
"""Largest log [bytes] a batch keeps when ``fly`` chooses ``log_every`` itself: 256 MiB, a quarter of
the 1 GiB the issue allows, because writing the log is most of what a coarser log costs (about 2 s
of CPU for 0.73 GB against a 6 s flight; docs/performance.md)."""


def log_bytes(n: int, periods: int, log_every: int) -> int:
    """Bytes of a flight's log: states, commands and references at every ``log_every``-th period.

    Parameters
    ----------
    n : int
        Number of vehicles.
    periods : int
        Control periods of the flight.
    log_every : int
        Log every this many periods.

    Returns
    -------
    int
        312 bytes per vehicle and logged instant.
    """
    from quadcruise.layout import CMD_SIZE, REF_SIZE

    return n * (periods // log_every + 1) * 8 * (STATE_SIZE + CMD_SIZE + REF_SIZE)


def batch_log_every(n: int, periods: int) -> int:
    """The ``log_every`` a flight gets by default: 1 (every period) for one vehicle or a log within
    :data:`LOG_BUDGET`, else the smallest divisor of the periods that keeps the log within it.

    Parameters
    ----------
    n : int
        Number of vehicles.
    periods : int
        Control periods of the flight.

    Returns
    -------
    int

    Examples
    --------
    >>> batch_log_every(1, 10**6), batch_log_every(200, 1000), batch_log_every(2000, 10_000)
    (1, 1, 25)
    """
    if n <= 1 or log_bytes(n, periods, 1) <= LOG_BUDGET:
        return 1
    small = [d for d in range(1, math.isqrt(periods) + 1) if periods % d == 0]
    divisors = sorted(set(small + [periods // d for d in small]))
    return next((d for d in divisors if log_bytes(n, periods, d) <= LOG_BUDGET), periods)


WATCH_BYTES = 9
"""Bytes per vehicle-period that the track checks at every period keep over the first half of a
batch's flight (a moving reference's error and beyond-the-bounds flag: :mod:`~quadcruise.workflows.track_watch`)."""


def check_run_size(n: int, steps: int, log_every: int, substeps: int = 1, watched: bool = False) -> None:
    """Refuse, before anything is allocated, a flight whose log would not fit in memory or that
    would run for hours; the message says what to change.

    Parameters
    ----------
    n : int
        Number of vehicles.
    steps : int
        Control periods of the flight.
    log_every : int
        Log every this many periods.
    substeps : int
        RK4 substeps per control period (``ceil(dt / max_step)``).
    watched : bool
        The track checks are made at every period as the flight goes (:data:`WATCH_BYTES`).

    Raises
    ------
    InputError
        The log (and what the checks keep) would take more than :data:`MAX_LOG_FRACTION` of the
        memory, or the flight more than :data:`MAX_VEHICLE_STEPS` vehicle-steps.

    Examples
    --------
    >>> check_run_size(10_000, 3_600_000, 1)
    Traceback (most recent call last):
        ...
    quadcruise.errors.InputError: 10,000 vehicles x 3,600,000 control periods is 3.6e+10 vehicle-steps, hours ...
    """
    from quadcruise.layout import CMD_SIZE, REF_SIZE

    if log_every < 1:
        raise InputError(f"log_every must be a whole number >= 1, got {log_every!r}")

    def many(k: int) -> str:  # a count as a message writes it: short, whatever its size
        return f"{k:,}" if k < 10**12 else f"{float(k):.3g}"

    if n * steps > MAX_VEHICLE_STEPS:
        raise InputError(
            f"{many(n)} vehicles x {many(steps)} control periods is {n * steps:.2g} vehicle-steps, "
            f"hours of computing: fly fewer vehicles or a shorter duration"
        )
    if n * steps * substeps > MAX_VEHICLE_STEPS:
        raise InputError(
            f"{many(n)} vehicles x {many(steps)} control periods x {many(substeps)} RK4 substeps each is "
            f"{n * steps * substeps:.2g} substeps, hours of computing: a larger max_step, fewer "
            "vehicles or a shorter duration"
        )
    row = 8 * (STATE_SIZE + CMD_SIZE + REF_SIZE)
    need = n * (steps // log_every + 2) * row
    try:
        memory = os.sysconf("SC_PAGE_SIZE") * os.sysconf("SC_PHYS_PAGES")
    except (ValueError, OSError, AttributeError):  # not a POSIX system: assume 8 GiB
        memory = 8 * 2**30
    if need > MAX_LOG_FRACTION * memory:
        every = int(math.ceil(n * (steps + 2) * row / (0.1 * memory)))
        raise InputError(
            f"the flight's log would take {need / 2**30:.1f} GiB ({n:,} vehicle(s) x "
            f"{steps // log_every + 1:,} logged instants), more than half of this machine's "
            f"{memory / 2**30:.0f} GiB: log less often (log_every={every:,}: in Python, or a scenario's "
            "[simulation]) or fly shorter"
        )
    watching = n * (steps // 2 + 2) * WATCH_BYTES if watched else 0
    if watched and need + watching > MAX_LOG_FRACTION * memory:
        raise InputError(
            f"the flight's track checks at every period would keep {watching / 2**30:.1f} GiB ({n:,} vehicles x "
            f"{steps // 2 + 1:,} periods of the first half x {WATCH_BYTES} bytes) beside its "
            f"{need / 2**30:.2f} GiB log, more than half of this machine's {memory / 2**30:.0f} GiB: fly fewer "
            "vehicles or shorter, or give log_every (the checks then read the log)"
        )


def check_log_every(log_every: int, periods: int) -> None:
    """Refuse a ``log_every`` that does not divide the flight's control periods: the log would
    end before the flight does (``log_every=1500`` on a 2 s flight at 1 kHz logs 0 and 1.5 s
    only, and the result would read as a 1.5 s flight). A Monte Carlo sweep picks such a
    divisor itself (``MonteCarloSpec.log_every``).

    Parameters
    ----------
    log_every : int
        Control periods between logged instants.
    periods : int
        The flight's control periods.

    Raises
    ------
    InputError
        Naming the nearest divisors below and above.

    Examples
    --------
    >>> check_log_every(1500, 2000)
    Traceback (most recent call last):
        ...
    quadcruise.errors.InputError: fly() argument log_every must be a divisor of the flight's 2,000 control ...
    """
    if periods % log_every == 0:
        return
    below, above = nearest_divisors(log_every, periods)
    hint = f"at most {periods:,}" if log_every > periods else f"the nearest: {below:,}, {above:,}"
    checks.fail(
        "fly()",
        "log_every",
        log_every,
        f"a divisor of the flight's {periods:,} control periods (so that the log ends where the flight does)",
        kind=False,
        hint=hint,
    )


def nearest_divisors(k: int, n: int) -> tuple[int, int]:
    """The divisors of ``n`` nearest to ``k``, below and above (``n`` itself above all).

    Parameters
    ----------
    k : int
        A whole number >= 1.
    n : int
        A whole number >= 1.

    Returns
    -------
    tuple of int
        (the largest divisor <= k, the smallest divisor >= k), in sqrt(n) steps.

    Examples
    --------
    >>> nearest_divisors(1500, 2000), nearest_divisors(3, 2000)
    ((1000, 2000), (2, 4))
    """
    small = [d for d in range(1, math.isqrt(n) + 1) if n % d == 0]
    divisors = sorted(set(small + [n // d for d in small]))
    below = max((d for d in divisors if d <= k), default=1)
    above = min((d for d in divisors if d >= k), default=n)
    return below, above


HOVER_DUTY_WARNING = 0.7
"""A hover duty above this leaves less than 30 % of the rotors' thrust for control: ``fly`` warns."""


def check_can_hover(vehicle: Vehicle) -> None:
    """Refuse a vehicle that cannot lift itself; warn when hovering leaves little for control.

    Parameters
    ----------
    vehicle : Vehicle
        One vehicle or a batch.

    Raises
    ------
    InputError
        If the hover duty m g / (4 K) of any vehicle is above 1: its four rotors at full duty
        cannot hold its weight. The message names the vehicle, its mass and the thrust available.

    Examples
    --------
    >>> import quadcruise as qc
    >>> check_can_hover(qc.Vehicle.paper().replace(m=60.0))
    Traceback (most recent call last):
        ...
    quadcruise.errors.InputError: the vehicle of mass 60 kg cannot lift itself: hovering needs 588.6 N, its ...
    """
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
            stacklevel=3,
        )


def check_reference_fits(missions: list[Mission], duration: float, limits: Limits) -> None:
    """Refuse, before flying, a mission whose reference leaves the position bound (and the
    default one, 10 km: a tighter bound given is the engine's to apply, as a divergence): the
    vehicle would be stopped as diverged for following it, and its numbers could overflow.

    Parameters
    ----------
    missions : list of Mission
        One mission for every vehicle, or one for all.
    duration : float
        Flight time [s].
    limits : Limits
        The divergence bounds (``max_position`` [m]).

    Raises
    ------
    InputError
        Naming the mission, how far its reference goes and the bound.

    Examples
    --------
    >>> from quadcruise.missions import mission_from_name
    >>> check_reference_fits([mission_from_name("circle", radius=1e200)], 20.0, Limits())
    Traceback (most recent call last):
        ...
    quadcruise.errors.InputError: the circle's reference goes 1e+200 m from the origin, beyond the position ...
    """
    for mission in missions:
        with np.errstate(all="ignore"):
            ref = mission.reference(np.linspace(0.0, duration, 1001))[:, REF_X : REF_X + 3]
            reach = float(np.max(np.abs(ref))) if np.isfinite(ref).all() else math.inf
        if reach > max(limits.max_position, Limits().max_position):  # a tighter bound given: the engine stops it
            kind = mission.to_dict().get("kind", type(mission).__name__.lower())
            raise InputError(
                f"the {kind}'s reference goes {reach:.3g} m from the origin, beyond the position bound "
                f"of {limits.max_position:.3g} m (Limits.max_position)"
            )


def track_bound(missions: list[Mission], x0: np.ndarray, n: int) -> np.ndarray:
    """The default tracking bound of each vehicle [m]: 1 m, plus the diagonal of the box its
    mission's reference path spans over the mission's default duration, plus its initial
    position error, so that neither the start offset nor the mission's own size counts.

    Parameters
    ----------
    missions : list of Mission
        One mission for every vehicle, or one for all.
    x0 : numpy.ndarray
        (N, 16) initial states.
    n : int
        Number of vehicles.

    Returns
    -------
    numpy.ndarray
        (N,) bounds [m].

    Examples
    --------
    >>> from quadcruise.missions import Circle
    >>> x0 = np.zeros((1, 16)); x0[0, 2] = 1.0
    >>> track_bound([Circle()], x0, 1).round(3)          # 1 + 4 sqrt(2) + the 2 m start offset
    array([8.657])
    """
    sizes, starts = [], []
    for mission in missions:
        ref = mission.reference(np.linspace(0.0, float(mission.duration), 1001))
        path = ref[:, REF_X : REF_X + 3]
        sizes.append(float(np.linalg.norm(path.max(axis=0) - path.min(axis=0))))
        starts.append(path[0])
    size = np.broadcast_to(np.asarray(sizes), (n,))
    start = np.broadcast_to(np.asarray(starts), (n, 3))
    offset = np.linalg.norm(np.asarray(x0, dtype=float).reshape(n, -1)[:, X : X + 3] - start, axis=1)
    return 1.0 + size + offset


def steady_bound(mission: Mission, duration: float) -> float:
    """The default steady bound [m] of a flight (``fly(max_steady_error=)``) and of a Monte
    Carlo sweep (``MonteCarloSpec.max_track_error_m``): the larger of 1 m and a quarter of
    the mission's extent.

    Parameters
    ----------
    mission : Mission
        The mission flown.
    duration : float
        Flight time [s].

    Returns
    -------
    float
        The bound [m]; the extent is the longest side of the box holding the reference
        position at 1,001 instants over the flight.

    Examples
    --------
    >>> from quadcruise.missions import mission_from_name
    >>> steady_bound(mission_from_name("circle"), 20.0)
    1.0
    >>> steady_bound(mission_from_name("circle", radius=10.0), 20.0)
    5.0
    """
    return _steady_from(reference_span(mission, duration)[0])


def _steady_from(extent: float) -> float:
    return max(1.0, 0.25 * extent)


def reference_span(mission: Mission, duration: float) -> tuple[float, float]:
    """The longest side [m] of the box holding the mission's reference position, and its lowest
    altitude [m], from the reference at 1,001 instants over the flight (one evaluation for both
    bounds)."""
    ref = mission.reference(np.linspace(0.0, float(duration), 1001))
    position = ref[:, REF_X : REF_X + 3]
    return float(np.max(position.max(axis=0) - position.min(axis=0))), float(ref[:, REF_Z].min())


ALTITUDE_FRACTION = 0.5
"""A vehicle that sags (or climbs) by more than this fraction of its mission's lowest reference
altitude after the transient is off track: half-way to the ground is not flying the mission."""
MIN_ALTITUDE_BOUND = 0.1
"""The vertical bound [m] is never below this (a mission flown at or near the ground)."""


def altitude_bound(mission: Mission, duration: float) -> float:
    """The default vertical steady bound [m] of a flight and of a Monte Carlo sweep: half the
    lowest altitude the mission's reference flies at, at least :data:`MIN_ALTITUDE_BOUND`
    and at most :func:`steady_bound`.

    Parameters
    ----------
    mission : Mission
        The mission flown.
    duration : float
        Flight time [s].

    Returns
    -------
    float
        The bound [m] on the altitude error after the transient, from the reference at
        1,001 instants over the flight.

    Examples
    --------
    >>> from quadcruise.missions import mission_from_name
    >>> altitude_bound(mission_from_name("circle"), 20.0)             # at 1 m
    0.5
    >>> altitude_bound(mission_from_name("circle", altitude=30.0), 20.0)  # capped by the 3-D bound
    1.0
    """
    extent, lowest = reference_span(mission, duration)
    return min(_steady_from(extent), max(MIN_ALTITUDE_BOUND, ALTITUDE_FRACTION * lowest))


def off_track_since(
    t: np.ndarray,
    err: np.ndarray,
    dz: np.ndarray,
    measured: np.ndarray,
    settled_at: np.ndarray,
    bound: np.ndarray,
    zbound: np.ndarray,
) -> np.ndarray:
    """The first instant after the transient at which each vehicle was off track: the one rule
    of ``fly`` (:func:`mark_off_track`) and of a Monte Carlo sweep.

    After the transient: from its settling into :data:`~quadcruise.metrics.flight.STEADY_BAND`
    on (``settled_at``); the whole flight where no transient is measured; the last instant
    if it never settled (the error at the end).

    Parameters
    ----------
    t : numpy.ndarray
        (L,) logged instants [s].
    err, dz : numpy.ndarray
        (N, L) 3-D position error and altitude error [m].
    measured : numpy.ndarray
        (N,) bool: a transient was measured.
    settled_at : numpy.ndarray
        (N,) end of the transient [s]; NaN if it did not settle.
    bound, zbound : numpy.ndarray
        (N,) bounds on the 3-D error and on the altitude error [m]; ``inf`` turns one off.

    Returns
    -------
    numpy.ndarray
        (N,) the first instant [s] beyond either bound; NaN for a vehicle never beyond.

    Examples
    --------
    >>> t = np.arange(4.0)
    >>> err = np.array([[2.0, 0.1, 0.2, 1.5], [2.0, 0.1, 0.1, 0.1]])
    >>> off_track_since(t, err, 0 * err, np.array([True, True]), np.array([1.0, np.nan]),
    ...                 np.array([1.0, 1.0]), np.array([0.5, 0.5]))
    array([ 3., nan])
    """
    start = np.where(~measured, t[0], np.where(np.isnan(settled_at), t[-1], settled_at))
    with np.errstate(invalid="ignore"):
        beyond = (err > bound[:, None]) | (np.abs(dz) > zbound[:, None])
    beyond &= t[None, :] >= start[:, None] - 1e-12
    return np.where(beyond.any(axis=1), t[np.argmax(beyond, axis=1)], np.nan)


def mark_off_track(
    result: SimResult, bound: np.ndarray, err: np.ndarray | None = None, zbound: np.ndarray | None = None
) -> SimResult:
    """The result, with ``off track`` as the status of each finished vehicle whose position
    error after the transient exceeded the bound, or whose altitude error exceeded the
    vertical bound, and the first instant it did as its ``t_stop`` (:func:`off_track_since`,
    the rule a Monte Carlo sweep applies).

    Parameters
    ----------
    result : SimResult
    bound : numpy.ndarray
        (N,) bounds on the 3-D error [m]; ``inf`` skips a vehicle.
    err : numpy.ndarray, optional
        (N, L) position errors [m] (:func:`position_error`), if already computed.
    zbound : numpy.ndarray, optional
        (N,) bounds on the altitude error [m]; ``bound`` by default.

    Returns
    -------
    SimResult
        The same object when no vehicle is off track.
    """
    from quadcruise.metrics.batch import transient_batch

    zbound = bound if zbound is None else zbound
    live = np.flatnonzero((result.status == int(ExitStatus.FINISHED)) & (np.isfinite(bound) | np.isfinite(zbound)))
    t = result.t
    if not live.size or t.size < 2:
        return result
    err = (position_error(result) if err is None else err)[live]
    if not np.isfinite(err).all():
        return result
    pos, ref = result.states[live, :, X : X + 3], result.references[live, :, REF_X : REF_X + 3]
    mission = result.meta.get("mission")
    got = transient_batch(t, pos, ref, mission if isinstance(mission, dict) else {}, [], err=err)
    first = off_track_since(
        t, err, pos[:, :, 2] - ref[:, :, 2], got["axis"] >= 0, got["settled_at"], bound[live], zbound[live]
    )
    off = np.isfinite(first)
    if not off.any():
        return result
    status, t_stop = result.status.copy(), result.t_stop.copy()
    status[live[off]] = int(ExitStatus.OFF_TRACK)
    t_stop[live[off]] = first[off]
    return dataclasses.replace(result, status=status, t_stop=t_stop)


def position_error(result: SimResult) -> np.ndarray:
    """The 3-D position error of every vehicle at every logged instant.

    Parameters
    ----------
    result : SimResult

    Returns
    -------
    numpy.ndarray
        (N, L) [m]; NaN after a vehicle stopped. Written out per axis: the same sums as
        ``numpy.linalg.norm(..., axis=2)``, a few times faster on the log's strided rows.
    """
    s, r = result.states, result.references
    dx, dy, dz = (s[:, :, X + k] - r[:, :, REF_X + k] for k in range(3))
    return np.sqrt(dx * dx + dy * dy + dz * dz)


def mark_lost_track(result: SimResult, bound: np.ndarray, err: np.ndarray | None = None) -> SimResult:
    """The result, with ``lost track`` as the status of each finished vehicle whose position
    error left the bound, and the first logged instant it did as its ``t_stop``.

    Parameters
    ----------
    result : SimResult
    bound : numpy.ndarray
        (N,) bounds [m].
    err : numpy.ndarray, optional
        (N, L) position errors [m] (:func:`position_error`), if already computed.

    Returns
    -------
    SimResult
        The same object when no vehicle lost track.
    """
    err = position_error(result) if err is None else err
    beyond = (err > bound[:, None]) & (result.status == int(ExitStatus.FINISHED))[:, None]
    lost = np.flatnonzero(beyond.any(axis=1))
    if not lost.size:
        return result
    status, t_stop = result.status.copy(), result.t_stop.copy()
    status[lost] = int(ExitStatus.LOST_TRACK)
    t_stop[lost] = result.t[np.argmax(beyond[lost], axis=1)]
    return dataclasses.replace(result, status=status, t_stop=t_stop)


def engine_inputs(environment: Environment | None, sensors: SensorNoise | None, n: int, dt: float) -> dict:
    """The engine's disturbance and sensor arrays for ``n`` vehicles at control period ``dt`` [s].

    Parameters
    ----------
    environment : Environment or CustomDisturbance or None
        The disturbances, if any.
    sensors : SensorNoise or None
        The sensor noise and delay, if any.
    n : int
        Number of vehicles.
    dt : float
        The flight's control period [s]: a sensor delay becomes a whole number of them.

    Returns
    -------
    dict
        Keywords of :func:`quadcruise.simulate` (none for a missing or empty part).

    Raises
    ------
    InputError
        If ``environment`` or ``sensors`` is of another type.
    """
    out: dict = {}
    if environment is not None:
        if not isinstance(environment, (Environment, CustomDisturbance)):
            raise InputError(
                f"environment must be an Environment or a CustomDisturbance, got {type(environment).__name__}"
            )
        if environment.parts:
            out.update(environment.kwargs(n))
    if sensors is not None:
        if not isinstance(sensors, SensorNoise):
            raise InputError(f"sensors must be a SensorNoise, got {type(sensors).__name__}")
        out.update(sensors.kwargs(dt))
    return out


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


@contextlib.contextmanager
def flight_warnings_named(label: str):
    """Within it, the warnings of the flights flown say whose flight they are: each
    :class:`~quadcruise.errors.FlightWarning` (a vehicle that did not finish, clipped duties)
    gets ``label: `` in front; the others (the vehicle's own) pass as they were, once.

    Parameters
    ----------
    label : str
        Whose flights, e.g. a controller's label or ``"circle with nlpd"``.

    Yields
    ------
    None
    """
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        yield
    for w in caught:
        text = f"{label}: {w.message}" if issubclass(w.category, FlightWarning) else str(w.message)
        warnings.warn(text, w.category, stacklevel=3)


def _warn_about(result: SimResult) -> None:
    bad = np.flatnonzero(~result.ok)
    if bad.size:
        first = int(bad[0])
        more = f" ({bad.size} of {result.n} vehicles)" if result.n > 1 else ""
        warnings.warn(f"vehicle {first} {result.status_text(first)}{more}", FlightWarning, stacklevel=3)
    clipped = result.duty_clipped_s
    if np.any(clipped > 0):
        what = "rotor duties were clipped to [0, 1]"
        if result.rotor_states is not None:  # a rotor-plant flight: its speeds, not duties (rotor_flight.py)
            what = "rotor speed commands were held in [w_min, w_max]"
        warnings.warn(
            f"{what} for up to {clipped.max():.3f} s ({np.count_nonzero(clipped)} of {result.n} vehicles)",
            FlightWarning,
            stacklevel=3,
        )


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
