"""Scenario files: a whole run described in TOML, validated with messages that name the
file, the key and what is wrong. Loading parses data only (``tomllib``); it never runs code.

A scenario has up to ten tables; every one is optional::

    title = "Circle in moderate turbulence"

    [vehicle]                 # the paper's Table I, with any field overridden
    m = 1.4
    drag_linear = 0.3

    [controller_vehicle]      # the vehicle the controller believes it flies (its model);
    m = 3.499                 # the flown [vehicle] when left out

    [controller]              # a built-in controller and its parameters
    name = "nlpd"
    position_poles = [-0.7, -4.3]     # any gain set from poles: <field>_poles
    attitude = { kp = 88.2, ki = 40.5, kd = 14.9 }   # or the gains themselves
    accel_feedforward = true

    [mission]                 # a mission kind and its fields
    kind = "circle"
    radius = 2.0
    period = 20.0             # a waypoint table: kind = "waypoints", table = "path.csv"

    [disturbances]
    wind = [3.0, 0.0, 0.0]                                  # constant wind [m/s]
    gust = { amplitude = [2.0, 0.0, 0.0], start = 5.0, duration = 2.0 }
    turbulence = { intensity = "moderate", altitude = 10.0 }
    rotor_loss = { rotor = 1, fraction = 0.3, time = 5.0 }
    sensor_noise = { position_std = 0.01, delay = 0.005 }

    [sensors]                 # sensor models the vehicle carries (docs/sensors.md)
    imu = "bmi088"
    gps = { preset = "typical", latency = 0.2 }

    [estimator]               # between them and the controller
    kind = "ekf"

    [simulation]
    duration = 30.0
    dt = 0.001
    full_dynamics = false
    seed = 1                  # also: max_step, log_every, n, max_track_error, max_steady_error,
                              # max_altitude_error, initial_state

    [montecarlo]              # read by `quadcruise montecarlo` (quadcruise.montecarlo.scenario)
    n = 1000
    mass_spread = 0.1
    requirements = ["steady_max_error_m<=0.2"]   # each METRIC<=VALUE (<, >=, > too)

    [compare]                 # read by `quadcruise compare`
    controllers = ["nlpd", "se3"]
    population = { n = 20, seed = 1, mass_spread = 0.1 }   # also the same perturbed vehicles

Relative file names (a waypoint table) are taken relative to the scenario file.

Examples
--------
>>> import pathlib, tempfile
>>> path = pathlib.Path(tempfile.mkdtemp()) / "s.toml"
>>> _ = path.write_text('[mission]\\nkind = "step"\\nsize = 0.5\\n[simulation]\\nduration = 8.0\\n')
>>> sc = load_scenario(path)
>>> sc.mission.name, sc.mission.size, sc.duration
('step', 0.5, 8.0)
>>> _ = path.write_text('[mission]\\nkind = "circle"\\nradiu = 2\\n')
>>> load_scenario(path)
Traceback (most recent call last):
    ...
quadcruise.errors.InputError: ...s.toml: [mission] unknown key 'radiu' (did you mean 'radius'?) (known: ...)
"""

from __future__ import annotations

import tomllib
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

from quadcruise.control import Controller
from quadcruise.errors import InputError
from quadcruise.io.files import not_a_file
from quadcruise.missions import Mission
from quadcruise.model.vehicle import Vehicle
from quadcruise.workflows.scenario_controller import COMPARE_POPULATION_KEYS, compare_table, controller_table
from quadcruise.workflows.scenario_flight import (
    DISTURBANCE_KEYS,
    OFF_WHEN_INFINITE,
    SIMULATION_KEYS,
    disturbances_table,
    mission_table,
    simulation_table,
)
from quadcruise.workflows.scenario_onboard import check_sensor_tables, estimator_from_spec, sensors_from_spec
from quadcruise.workflows.scenario_values import Where, check_keys
from quadcruise.workflows.scenario_vehicle import VEHICLE_PRESETS, read_vehicle_file, vehicle_preset, vehicle_table

TABLES = (
    "vehicle",
    "controller",
    "mission",
    "disturbances",
    "simulation",
    "montecarlo",
    "controller_vehicle",
    "compare",
    "sensors",
    "estimator",
)


@dataclass(frozen=True)
class Scenario:
    """A validated scenario: objects ready to fly, and the source it came from.

    Parameters
    ----------
    vehicle : Vehicle
        The flown vehicle: Table I (:meth:`Vehicle.paper`) with the ``[vehicle]`` overrides.
    controller_vehicle : Vehicle or None
        The vehicle the controller believes it flies (its model); None: ``vehicle``.
    controller : Controller or None
        The controller; None flies ``nlpd`` with its defaults.
    mission : Mission or None
        The mission; None flies the default ``circle``.
    environment : Environment or None
        The disturbances of ``[disturbances]`` (wind [m/s], gust, turbulence, rotor loss,
        external force [N]), or None.
    sensor_noise : SensorNoise or None
        Noise on what the controller sees (position [m], velocity [m/s], angle [rad] ...)
        and its delay [s], or None.
    sensors : Sensors or None
        The sensor models of ``[sensors]`` (:mod:`quadcruise.workflows.scenario_onboard`), or None.
    estimator : Ekf or None
        The filter of ``[estimator]``, or None.
    simulation : dict
        The checked ``[simulation]`` table: ``duration`` [s], ``dt`` [s], ``max_step`` [s],
        ``full_dynamics``, ``seed``, ``log_every``, ``n``, ``max_track_error`` [m],
        ``max_steady_error`` [m], ``max_altitude_error`` [m] and ``initial_state`` (16 state values in the units of
        :data:`quadcruise.layout.STATE_UNITS`, or one row per vehicle), each only if given.
    montecarlo : dict
        The ``[montecarlo]`` table as written (checked by ``quadcruise montecarlo``).
    compare : dict
        ``[compare]``'s controllers: label -> controller, in order (``quadcruise compare``).
    compare_population : dict
        ``[compare] population`` as written: ``n``, ``seed`` and the population's spreads
        (:data:`COMPARE_POPULATION_KEYS`), which ``quadcruise compare`` flies every controller on.
    title : str
        The scenario's title.
    source : str
        Where it came from (the file name), for messages and the flight's ``meta``.

    Examples
    --------
    >>> sc = Scenario(simulation={"duration": 2.0})
    >>> sc.duration, sc.dt, sorted(sc.fly_kwargs())
    (2.0, 0.001, ['dt', 'duration', 'vehicle'])
    """

    vehicle: Vehicle = field(default_factory=Vehicle.paper)
    controller_vehicle: Vehicle | None = None
    controller: Controller | None = None
    mission: Mission | None = None
    environment: Any = None
    sensor_noise: Any = None
    sensors: Any = None
    estimator: Any = None
    simulation: dict = field(default_factory=dict)
    montecarlo: dict = field(default_factory=dict)
    compare: dict = field(default_factory=dict)
    compare_population: dict = field(default_factory=dict)
    title: str = ""
    source: str = "scenario"

    @property
    def duration(self) -> float | None:
        """Flight time [s] from ``[simulation]``, or None (``fly`` then takes the mission's)."""
        return self.simulation.get("duration")

    @property
    def dt(self) -> float:
        """Control period [s] from ``[simulation]``, 1e-3 by default."""
        return self.simulation.get("dt", 1e-3)

    def fly_kwargs(self, drag: bool = True) -> dict:
        """Keyword arguments of :func:`quadcruise.fly` for this scenario (all but the mission
        and the controller).

        Wind, gusts and turbulence act only through drag: with any of them, a vehicle without
        drag is given :data:`~quadcruise.disturbances.DEFAULT_DRAG`, with a warning saying so
        (:func:`~quadcruise.disturbances.with_drag`).

        Parameters
        ----------
        drag : bool
            False: leave the vehicle as written (a caller that changes the vehicle or the wind
            first gives it drag itself).

        Returns
        -------
        dict
            ``duration`` [s] (None if not given), ``dt`` [s], ``vehicle``, and those of
            ``max_step``, ``full_dynamics``, ``seed``, ``log_every``, ``n``,
            ``max_track_error``, ``max_steady_error``, ``max_altitude_error``, ``x0`` (the initial
            state), ``controller_vehicle``,
            ``environment``, ``sensors`` and ``estimator`` the scenario gives.
        """
        sim = self.simulation
        kw: dict[str, Any] = {"duration": sim.get("duration"), "dt": self.dt}
        bounds = ("max_track_error", "max_steady_error", "max_altitude_error")
        for key in ("max_step", "full_dynamics", "seed", "log_every", "n", *bounds):
            if key in sim:
                kw[key] = sim[key]
        if "initial_state" in sim:
            kw["x0"] = sim["initial_state"]
        if self.controller_vehicle is not None:
            kw["controller_vehicle"] = self.controller_vehicle
        vehicle = self.vehicle
        if self.environment is not None:
            if drag and self.environment.needs_drag:
                from quadcruise.disturbances import with_drag

                vehicle = with_drag(vehicle, warn=True)
            kw["environment"] = self.environment
        if self.sensor_noise is not None:
            kw["sensors"] = self.sensor_noise
        if self.sensors is not None:
            kw["sensors"] = self.sensors
        if self.estimator is not None:
            kw["estimator"] = self.estimator
        kw["vehicle"] = vehicle
        return kw

    def fly(self):
        """Fly the scenario: :func:`quadcruise.fly` with everything it describes.

        Returns
        -------
        SimResult
            The flight, with ``meta["scenario"]`` holding the source and the title.
        """
        from quadcruise.workflows.fly import fly

        result = fly(self.mission or "circle", self.controller or "nlpd", **self.fly_kwargs())
        result.meta["scenario"] = {"source": self.source, "title": self.title}
        return result


def load_scenario(path: str | Path) -> Scenario:
    """Read and validate a TOML scenario; any problem is one InputError naming file and key.

    Parameters
    ----------
    path : str or pathlib.Path
        The TOML file; relative file names inside it are taken relative to its folder.

    Returns
    -------
    Scenario

    Raises
    ------
    InputError
        No such file, not valid TOML, or a table, key or value that is wrong.
    """
    path = Path(path)
    if path.is_dir():
        raise InputError(f"{path}: is a folder, not a scenario file")
    if not path.is_file():
        raise InputError(f"{path}: {not_a_file(path)}")
    try:
        doc = tomllib.loads(path.read_text(encoding="utf-8-sig"))  # a byte-order mark is dropped
    except (tomllib.TOMLDecodeError, UnicodeDecodeError) as exc:
        raise InputError(f"{path}: not valid TOML ({exc})") from None
    return scenario_from_dict(doc, source=str(path), base=path.parent)


def scenario_from_dict(doc: dict, *, source: str = "scenario", base: Path | None = None) -> Scenario:
    """Build a Scenario from the parsed tables (see the module docstring).

    Parameters
    ----------
    doc : dict
        The parsed TOML document: ``title`` and the tables of :data:`TABLES`.
    source : str
        The name messages and the result give the scenario (the file name).
    base : pathlib.Path, optional
        Folder that relative file names (a waypoint table) are taken relative to; None
        leaves them as written.

    Returns
    -------
    Scenario

    Raises
    ------
    InputError
        An unknown table or key, or a bad value, naming ``source`` and the table.

    Examples
    --------
    >>> sc = scenario_from_dict({"title": "hover", "mission": {"kind": "hover", "z": 2.0}})
    >>> sc.title, sc.mission.z, sc.controller
    ('hover', 2.0, None)
    """
    where = Where(source)
    check_keys(where, "", doc, set(TABLES) | {"title"})
    for name in TABLES:
        if name in doc and not isinstance(doc[name], dict):
            raise InputError(f"{source}: [{name}] must be a table, got {type(doc[name]).__name__}")
    title = doc.get("title", "")
    if not isinstance(title, str):
        raise InputError(f"{source}: 'title' must be a string")
    vehicle = vehicle_table(where.at("vehicle"), doc.get("vehicle", {}))
    model = (
        vehicle_table(where.at("controller_vehicle"), doc["controller_vehicle"])
        if "controller_vehicle" in doc
        else None
    )
    controller = controller_table(where.at("controller"), doc.get("controller"), base) if "controller" in doc else None
    compared = compare_table(where.at("compare"), doc.get("compare", {}))
    mission = mission_table(where.at("mission"), doc.get("mission"), base) if "mission" in doc else None
    environment, noise = disturbances_table(where.at("disturbances"), doc.get("disturbances", {}))
    simulation = simulation_table(where.at("simulation"), doc.get("simulation", {}))
    sensors = sensors_from_spec(doc.get("sensors", {}), where.at("sensors"))
    estimator = estimator_from_spec(doc.get("estimator", {}), where.at("estimator"))
    check_sensor_tables(where, sensors, noise)
    _consistent(where, doc, vehicle, model, mission, simulation)
    return Scenario(
        vehicle=vehicle,
        controller_vehicle=model,
        controller=controller,
        mission=mission,
        environment=environment,
        sensor_noise=noise,
        sensors=sensors,
        estimator=estimator,
        simulation=simulation,
        montecarlo=dict(doc.get("montecarlo", {})),
        compare=compared,
        compare_population=dict(doc.get("compare", {}).get("population", {})),
        title=title,
        source=source,
    )


def _consistent(
    where: Where, doc: dict, vehicle: Vehicle, model: Vehicle | None, mission: Mission | None, simulation: dict
) -> None:
    """Refuse a scenario whose tables contradict each other (one hand-edited after the tool wrote
    it), naming the file and the keys: the number of vehicles given by per-vehicle values, ``n``
    and ``initial_state``; and, when the file gives both ``duration`` and ``dt``, a ``dt`` that
    does not divide the duration or a ``log_every`` that does not divide the flight's control
    periods (as :func:`~quadcruise.workflows.fly_inputs.check_log_every`)."""
    counts: dict[str, int] = {}
    for table, v in (("vehicle", vehicle), ("controller_vehicle", model)):
        if v is not None and getattr(v, "batch_size", None) is not None:
            key = next((k for k, x in doc.get(table, {}).items() if isinstance(x, list)), "?")
            counts[f"[{table}] {key}"] = v.batch_size
    if "n" in simulation:
        counts["[simulation] n"] = simulation["n"]
    state = simulation.get("initial_state")
    if state is not None and state.ndim == 2:
        counts["[simulation] initial_state"] = state.shape[0]
    if len(set(counts.values())) > 1:
        told = ", ".join(f"{k} gives {v}" for k, v in counts.items())
        raise InputError(f"{where.source}: the number of vehicles contradicts itself: {told}")
    if "duration" not in simulation or "dt" not in simulation:  # else the command line may give them
        return
    sim, duration, dt = where.at("simulation"), simulation["duration"], simulation["dt"]
    periods = round(duration / dt)  # as sim.inputs.time_grid counts them, without the grid
    if dt > duration or abs(periods * dt - duration) > 1e-9 * max(1.0, duration):
        raise sim.error(f"'dt' = {dt:g} s does not divide 'duration' = {duration:g} s into whole control periods")
    every = simulation.get("log_every", 1)
    if periods % every:
        from quadcruise.workflows.fly_inputs import nearest_divisors

        near = nearest_divisors(every, periods)
        raise sim.error(
            f"'log_every' = {every} does not divide the flight's {periods:,} control periods "
            f"('duration' / 'dt'): the log would end before the flight does; the nearest that do: "
            f"{near[0]}, {near[1]}"
        )


__all__ = [
    "COMPARE_POPULATION_KEYS",
    "DISTURBANCE_KEYS",
    "OFF_WHEN_INFINITE",
    "SIMULATION_KEYS",
    "TABLES",
    "VEHICLE_PRESETS",
    "Scenario",
    "load_scenario",
    "read_vehicle_file",
    "scenario_from_dict",
    "vehicle_preset",
]
