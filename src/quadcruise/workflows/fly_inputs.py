"""What :func:`quadcruise.workflows.fly.fly` does before it flies: its arguments checked and given
their defaults (the duration, the hover start, per-vehicle controllers, missions and initial
states), the run's size and log cadence held within memory, the vehicle able to hover, the
reference within the limits, and the environment and sensors as the engine's arrays. Each
refusal is one :class:`~quadcruise.errors.InputError` line, before any work."""

from __future__ import annotations

import math
import os
import warnings
from typing import Any

import numpy as np

from quadcruise import checks
from quadcruise.checks import describe
from quadcruise.control import as_controller
from quadcruise.disturbances import CustomDisturbance, Environment, SensorNoise
from quadcruise.errors import InputError
from quadcruise.layout import F1, P_G, P_M, PSI, REF_PSI, REF_X, REF_Z, STATE_SIZE, Z
from quadcruise.missions import Mission
from quadcruise.model.vehicle import Vehicle
from quadcruise.sim.inputs import Limits


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
    "estimator",
    "seed",
    "first_vehicle",
    "max_track_error",
    "max_steady_error",
    "max_altitude_error",
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


def log_bytes(n: int, periods: int, log_every: int, extra: int = 0) -> int:
    """Bytes of a flight's log: states, commands and references at every ``log_every``-th period.

    Parameters
    ----------
    n : int
        Number of vehicles.
    periods : int
        Control periods of the flight.
    log_every : int
        Log every this many periods.
    extra : int
        More numbers logged per row (a rotor-plant flight's own state: 13 + rotors; a flight on
        sensors, their observation log: ``OBSERVATION_SIZE``).

    Returns
    -------
    int
        312 bytes (+ 8 ``extra``) per vehicle and logged instant.
    """
    from quadcruise.layout import CMD_SIZE, REF_SIZE

    return n * (periods // log_every + 1) * 8 * (STATE_SIZE + CMD_SIZE + REF_SIZE + extra)


def batch_log_every(n: int, periods: int, extra: int = 0) -> int:
    """The ``log_every`` a flight gets by default: 1 (every period) for one vehicle or a log within
    :data:`LOG_BUDGET`, else the smallest divisor of the periods that keeps the log within it.

    Parameters
    ----------
    n : int
        Number of vehicles.
    periods : int
        Control periods of the flight.
    extra : int
        More numbers logged per row (:func:`log_bytes`).

    Returns
    -------
    int

    Examples
    --------
    >>> batch_log_every(1, 10**6), batch_log_every(200, 1000), batch_log_every(2000, 10_000)
    (1, 1, 25)
    """
    if n <= 1 or log_bytes(n, periods, 1, extra) <= LOG_BUDGET:
        return 1
    small = [d for d in range(1, math.isqrt(periods) + 1) if periods % d == 0]
    divisors = sorted(set(small + [periods // d for d in small]))
    return next((d for d in divisors if log_bytes(n, periods, d, extra) <= LOG_BUDGET), periods)


WATCH_BYTES = 8 * 8 + 17 * 8 + 6 + 8 + 8
"""Bytes per vehicle that the track checks at every period keep, whatever the flight's length
(:class:`~quadcruise.workflows.track_watch.TrackWatch`: 8 periods, 17 figures, 6 flags, the
bounds' step response and its index); the head of a vehicle flown again is read in groups of
at most :data:`~quadcruise.workflows.track_watch.HEAD_BYTES`."""


def check_run_size(
    n: int, steps: int, log_every: int, substeps: int = 1, watched: bool = False, extra: int = 0
) -> None:
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
    extra : int
        More numbers logged per row (:func:`log_bytes`).

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
        raise InputError(f"log_every must be a whole number >= 1, got {describe(log_every)}")

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
    row = 8 * (STATE_SIZE + CMD_SIZE + REF_SIZE + extra)
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
    watching = n * WATCH_BYTES if watched else 0
    if watched and need + watching > MAX_LOG_FRACTION * memory:
        raise InputError(
            f"the flight's track checks at every period would keep {watching / 2**30:.1f} GiB ({n:,} vehicles x "
            f"{WATCH_BYTES} bytes) beside its {need / 2**30:.2f} GiB log, more than half of this machine's "
            f"{memory / 2**30:.0f} GiB: fly fewer vehicles"
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
