"""Scenario files: a whole run described in TOML, validated with messages that name the
file, the key and what is wrong. Loading parses data only (``tomllib``); it never runs code.

A scenario has up to seven tables; every one is optional::

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

    [simulation]
    duration = 30.0
    dt = 0.001
    full_dynamics = false
    seed = 1                  # also: max_step, log_every, n, max_track_error, max_steady_error, initial_state

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

import dataclasses
import math
import tomllib
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

from quadcruise.control import CONTROLLERS, Controller
from quadcruise.control.design import PDGains, PIDGains, parse_pole, pd_from_poles, pid_from_poles
from quadcruise.errors import InputError
from quadcruise.missions import MISSIONS, Mission
from quadcruise.model.rotor_vehicle import RotorVehicle
from quadcruise.model.vehicle import Vehicle
from quadcruise.model.vehicle_files import PRESETS, vehicle_from_table

VEHICLE_PRESETS = {"paper": Vehicle.paper}
"""Vehicles by name: ``preset = "paper"`` in a ``[vehicle]`` table, ``--vehicle paper`` on the command line."""
COMPARE_POPULATION_KEYS = (
    "n",
    "seed",
    "mass_spread",
    "inertia_spread",
    "thrust_spread",
    "bandwidth_spread",
    "yaw_arm_spread",
    "offset",
    "wind_spread",
    "distribution",
    "model_error",
)
"""Keys of ``[compare] population``: the number of vehicles, the seed and the
:class:`~quadcruise.montecarlo.Population` fields (its disturbances are the scenario's)."""
TABLES = (
    "vehicle",
    "controller",
    "mission",
    "disturbances",
    "simulation",
    "montecarlo",
    "controller_vehicle",
    "compare",
)
SIMULATION_KEYS = {
    "duration": float,
    "dt": float,
    "max_step": float,
    "full_dynamics": bool,
    "seed": int,
    "log_every": int,
    "n": int,
    "max_track_error": float,
    "max_steady_error": float,
    "initial_state": list,
}
DISTURBANCE_KEYS = ("wind", "gust", "turbulence", "rotor_loss", "force", "sensor_noise")


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
    simulation : dict
        The checked ``[simulation]`` table: ``duration`` [s], ``dt`` [s], ``max_step`` [s],
        ``full_dynamics``, ``seed``, ``log_every``, ``n``, ``max_track_error`` [m],
        ``max_steady_error`` [m] and ``initial_state`` (16 state values in the units of
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
            ``max_track_error``, ``max_steady_error``, ``x0`` (the initial state), ``controller_vehicle``,
            ``environment`` and ``sensors`` the scenario gives.
        """
        sim = self.simulation
        kw: dict[str, Any] = {"duration": sim.get("duration"), "dt": self.dt}
        for key in ("max_step", "full_dynamics", "seed", "log_every", "n", "max_track_error", "max_steady_error"):
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
        raise InputError(f"{path}: no such file")
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
    where = _Where(source)
    _known(where, "", doc, set(TABLES) | {"title"})
    for name in TABLES:
        if name in doc and not isinstance(doc[name], dict):
            raise InputError(f"{source}: [{name}] must be a table, got {type(doc[name]).__name__}")
    title = doc.get("title", "")
    if not isinstance(title, str):
        raise InputError(f"{source}: 'title' must be a string")
    vehicle = _vehicle(where.at("vehicle"), doc.get("vehicle", {}))
    model = _vehicle(where.at("controller_vehicle"), doc["controller_vehicle"]) if "controller_vehicle" in doc else None
    controller = _controller(where.at("controller"), doc.get("controller")) if "controller" in doc else None
    compared = _compare(where.at("compare"), doc.get("compare", {}))
    mission = _mission(where.at("mission"), doc.get("mission"), base) if "mission" in doc else None
    environment, noise = _disturbances(where.at("disturbances"), doc.get("disturbances", {}))
    simulation = _simulation(where.at("simulation"), doc.get("simulation", {}))
    _consistent(where, doc, vehicle, model, mission, simulation)
    return Scenario(
        vehicle=vehicle,
        controller_vehicle=model,
        controller=controller,
        mission=mission,
        environment=environment,
        sensor_noise=noise,
        simulation=simulation,
        montecarlo=dict(doc.get("montecarlo", {})),
        compare=compared,
        compare_population=dict(doc.get("compare", {}).get("population", {})),
        title=title,
        source=source,
    )


def _consistent(
    where: _Where, doc: dict, vehicle: Vehicle, model: Vehicle | None, mission: Mission | None, simulation: dict
) -> None:
    """Refuse a scenario whose tables contradict each other (one hand-edited after the tool wrote
    it), naming the file and the keys: the number of vehicles given by per-vehicle values, ``n``
    and ``initial_state``; and, when the file gives both ``duration`` and ``dt``, a ``dt`` that
    does not divide the duration or a ``log_every`` that does not divide the flight's control
    periods (as :func:`~quadcruise.workflows.fly.check_log_every`)."""
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
        from quadcruise.workflows.fly import nearest_divisors

        near = nearest_divisors(every, periods)
        raise sim.error(
            f"'log_every' = {every} does not divide the flight's {periods:,} control periods "
            f"('duration' / 'dt'): the log would end before the flight does; the nearest that do: "
            f"{near[0]}, {near[1]}"
        )


class _Where:
    """Prefixes messages with the file and table: ``file: [table] ...``."""

    def __init__(self, source: str, table: str = "") -> None:
        self.source, self.table = source, table

    def at(self, table: str) -> _Where:
        return _Where(self.source, table)

    def error(self, message: str) -> InputError:
        return InputError(f"{self.source}: [{self.table}] {message}" if self.table else f"{self.source}: {message}")

    def wrap(self, func, *args, **kwargs):
        """Call func; re-raise its InputError (or TypeError) with the file and table in front."""
        try:
            return func(*args, **kwargs)
        except (InputError, TypeError) as exc:
            raise self.error(str(exc)) from None


def _known(where: _Where, prefix: str, table: dict, known: set) -> None:
    import difflib

    for key in table:
        if key not in known:
            close = difflib.get_close_matches(str(key), sorted(known), n=1)
            hint = f" (did you mean '{prefix}{close[0]}'?)" if close else ""
            raise where.error(f"unknown key '{prefix}{key}'{hint} (known: {', '.join(sorted(known))})")


def _number(where: _Where, key: str, value, kind=float):
    if kind is bool:
        if not isinstance(value, bool):
            raise where.error(f"'{key}' must be true or false, got {value!r}")
        return value
    if isinstance(value, bool) or not isinstance(value, (int, float)) or (kind is int and not isinstance(value, int)):
        raise where.error(f"'{key}' must be {'an integer' if kind is int else 'a number'}, got {value!r}")
    if not math.isfinite(value):
        raise where.error(f"'{key}' must be finite, got {value!r}")
    return kind(value)


def vehicle_preset(name: str) -> Vehicle:
    """A vehicle by its name (:data:`VEHICLE_PRESETS`).

    Parameters
    ----------
    name : str
        The preset's name, e.g. ``"paper"`` (Table I).

    Returns
    -------
    Vehicle

    Raises
    ------
    InputError
        No preset has this name.

    Examples
    --------
    >>> vehicle_preset("paper").m
    3.499
    """
    if isinstance(name, str) and name in VEHICLE_PRESETS:
        return VEHICLE_PRESETS[name]()
    if isinstance(name, str) and name in PRESETS:  # the other presets: a file each
        return Vehicle.preset(name)
    known = ", ".join([*VEHICLE_PRESETS, *sorted(set(PRESETS) - set(VEHICLE_PRESETS))])
    raise InputError(f"unknown vehicle preset {name!r} (known: {known})")


def read_vehicle_file(path: str | Path) -> Vehicle:
    """A vehicle from a TOML file: its fields (and ``preset``) at the top level, or a scenario's
    ``[vehicle]`` table (an output folder's ``scenario.toml`` gives the vehicle it flew).

    Parameters
    ----------
    path : str or pathlib.Path
        The TOML file.

    Returns
    -------
    Vehicle
        The preset (Table I by default) with the file's fields.

    Raises
    ------
    InputError
        No such file, not valid TOML, or a key or value that is wrong, naming the file.

    Examples
    --------
    >>> import pathlib, tempfile
    >>> path = pathlib.Path(tempfile.mkdtemp()) / "light.toml"
    >>> _ = path.write_text("m = 1.4\\nK = 48.0\\n")
    >>> read_vehicle_file(path).m
    1.4
    """
    path = Path(path)
    if not path.is_file():
        raise InputError(f"{path}: no such file")
    try:
        doc = tomllib.loads(path.read_text(encoding="utf-8-sig"))
    except (tomllib.TOMLDecodeError, UnicodeDecodeError) as exc:
        raise InputError(f"{path}: not valid TOML ({exc})") from None
    if isinstance(doc.get("vehicle"), dict):
        return _vehicle(_Where(str(path), "vehicle"), doc["vehicle"])
    return _vehicle(_Where(str(path)), doc)


def _vehicle(where: _Where, table: dict) -> Vehicle | RotorVehicle:
    preset = table.get("preset", "paper")
    if "plant" in table or "rotors" in table or (isinstance(preset, str) and preset in set(PRESETS) - {"paper"}):
        # a rotor-plant vehicle, or a preset file's: the vehicle file's reader (one vehicle, not a batch)
        return vehicle_from_table(table, {"paper": Vehicle, "rotor": RotorVehicle}, where.source)
    fields = {f.name for f in dataclasses.fields(Vehicle)}
    _known(where, "", table, fields | {"preset"})
    base = where.wrap(vehicle_preset, table.get("preset", "paper"))
    values = {
        k: _numbers(where, k, v) if isinstance(v, list) else _number(where, k, v)
        for k, v in table.items()
        if k != "preset"
    }
    return where.wrap(base.replace, **values)


def _numbers(where: _Where, key: str, value: list):
    """A list of numbers (one per vehicle, or a row of a table) as a float array."""
    import numpy as np

    if not isinstance(value, list) or not value:
        raise where.error(f"'{key}' must be a list of numbers, got {value!r}")
    rows = [_numbers(where, key, v) if isinstance(v, list) else _number(where, key, v) for v in value]
    if len({np.shape(r) for r in rows}) > 1:
        raise where.error(f"'{key}' must be a list of numbers or of equal lists of numbers (one per vehicle)")
    return np.array(rows)


def _poles(where: _Where, key: str, value) -> list:
    if not isinstance(value, list) or not value:
        raise where.error(f"'{key}' must be a list of poles, e.g. [-0.7, -4.3]")
    out = []
    for p in value:
        try:
            out.append(parse_pole(p))
        except (TypeError, ValueError):
            raise where.error(f"'{key}': {p!r} is not a pole (a number, or a string like \"-1+2j\")") from None
    return out


def _controller(where: _Where, table: dict) -> Controller:
    name = table.get("name", "nlpd")
    if not isinstance(name, str) or name not in CONTROLLERS:
        raise where.error(f"unknown controller name {name!r} (known: {', '.join(CONTROLLERS)})")
    cls = CONTROLLERS[name]
    defaults = cls()
    fields = {f.name for f in dataclasses.fields(cls)}
    gain_fields = {n for n in fields if dataclasses.is_dataclass(getattr(defaults, n))}
    pole_fields = {n for n in gain_fields if isinstance(getattr(defaults, n), (PDGains, PIDGains))}
    known = fields | {f"{n}_poles" for n in pole_fields} | {"name"}
    _known(where, "", table, known)
    params: dict[str, Any] = {}
    for key, value in table.items():
        if key == "name":
            continue
        if key.endswith("_poles"):
            poles = _poles(where, key, value)
            design = pd_from_poles if len(poles) == 2 else pid_from_poles
            params[key[:-6]] = where.wrap(design, poles)
        elif key in gain_fields:
            if not isinstance(value, dict):
                raise where.error(f"'{key}' must be a table of gains, e.g. {{ kp = 3.01, kd = 5.0 }}")
            default = getattr(defaults, key)
            if isinstance(default, (PDGains, PIDGains)):
                cls_gains = PIDGains if "ki" in value else PDGains
            else:
                cls_gains = type(default)
            _known(
                where,
                f"{key}.",
                value,
                {f.name for f in dataclasses.fields(cls_gains)}
                | ({"kp", "kd", "ki"} if cls_gains in (PDGains, PIDGains) else set()),
            )
            params[key] = where.wrap(cls_gains, **{k: _number(where, f"{key}.{k}", v) for k, v in value.items()})
        elif isinstance(value, bool) or isinstance(value, str):
            params[key] = value
        else:
            params[key] = _number(where, key, value)
    return where.wrap(cls, **params)


def _compare(where: _Where, table: dict) -> dict:
    """``[compare]``: ``controllers``, a list of names or of controller tables with a ``label``;
    ``population``, checked here and kept as written (``quadcruise compare`` flies it)."""
    _known(where, "", table, {"controllers", "population"})
    if "population" in table:
        pop = table["population"]
        if not isinstance(pop, dict):
            raise where.error("'population' must be a table, e.g. population = { n = 100, mass_spread = 0.1 }")
        _known(where, "population.", pop, set(COMPARE_POPULATION_KEYS))
        if "n" not in pop:
            raise where.error("'population' needs n, the number of vehicles")
        for key, value in pop.items():
            if key == "distribution":
                if value not in ("normal", "uniform"):
                    raise where.error(f"'population.distribution' must be normal or uniform, got {value!r}")
            else:
                kind = int if key in ("n", "seed") else bool if key == "model_error" else float
                _number(where, f"population.{key}", value, kind)
        if isinstance(pop["n"], int) and pop["n"] < 1 or pop.get("seed", 0) < 0:
            raise where.error("'population' needs n >= 1 and seed >= 0")
    items = table.get("controllers", [])
    if not isinstance(items, list):
        raise where.error("'controllers' must be a list of names or of [[compare.controllers]] tables")
    out: dict = {}
    for k, item in enumerate(items):
        if isinstance(item, str):
            item = {"name": item}
        if not isinstance(item, dict):
            raise where.error(f"controllers[{k}] must be a name or a table, got {item!r}")
        item = dict(item)
        label = item.pop("label", item.get("name", "nlpd"))
        if not isinstance(label, str) or label in out:
            raise where.error(f"controllers[{k}]: label {label!r} must be a text given once")
        out[label] = _controller(where, item)
    return out


def _mission(where: _Where, table: dict, base: Path | None) -> Mission:
    kind = table.get("kind")
    if not isinstance(kind, str) or kind not in MISSIONS:
        raise where.error(f"'kind' must be one of {', '.join(MISSIONS)}, got {kind!r}")
    cls = MISSIONS[kind]
    fields = {f.name for f in dataclasses.fields(cls)}
    _known(where, "", table, fields | {"kind"})
    params = {k: v for k, v in table.items() if k != "kind"}
    if isinstance(params.get("table"), dict):  # a waypoint table written inline
        from quadcruise.missions import WaypointTable

        params["table"] = where.wrap(WaypointTable.from_dict, params["table"])
    if "table" in params and isinstance(params["table"], str) and base is not None:
        params["table"] = (
            str((base / params["table"]).resolve()) if not Path(params["table"]).is_absolute() else params["table"]
        )
    for k, v in params.items():
        if isinstance(v, list):
            params[k] = tuple(v)
    return where.wrap(cls, **params)


def _disturbances(where: _Where, table: dict):
    _known(where, "", table, set(DISTURBANCE_KEYS))
    if not table:
        return None, None
    import quadcruise.disturbances as d

    parts: dict[str, Any] = {}
    if "wind" in table:
        wind = table["wind"]
        parts["wind"] = (
            where.wrap(d.ConstantWind, velocity=tuple(wind))
            if isinstance(wind, list)
            else where.wrap(d.ConstantWind, **_table(where, "wind", wind, d.ConstantWind))
        )
    for key, cls in (
        ("gust", d.Gust),
        ("turbulence", d.Turbulence),
        ("rotor_loss", d.RotorLoss),
        ("force", d.ExternalForce),
    ):
        if key in table:
            values = {k: tuple(v) if isinstance(v, list) else v for k, v in _table(where, key, table[key], cls).items()}
            parts[key] = where.wrap(cls, **values)
    noise = None
    if "sensor_noise" in table:
        noise = where.wrap(d.SensorNoise, **_table(where, "sensor_noise", table["sensor_noise"], d.SensorNoise))
    environment = where.wrap(d.Environment, **parts) if parts else None
    return environment, noise


def _table(where: _Where, key: str, value, cls: type) -> dict:
    """An inline table whose keys are the fields of ``cls``: an unknown one is named with the
    table and the keys known, before ``cls`` is made."""
    if not isinstance(value, dict):
        raise where.error(f"'{key}' must be a table, e.g. {key} = {{ ... }}")
    _known(where, f"{key}.", value, {f.name for f in dataclasses.fields(cls) if f.init})
    return value


OFF_WHEN_INFINITE = ("max_track_error", "max_steady_error")
"""[simulation] bounds that ``inf`` turns off (as in :func:`quadcruise.fly`); every other number is finite."""


def _simulation(where: _Where, table: dict) -> dict:
    _known(where, "", table, set(SIMULATION_KEYS))
    out = {
        k: _numbers(where, k, v)
        if SIMULATION_KEYS[k] is list
        else (
            math.inf
            if k in OFF_WHEN_INFINITE and isinstance(v, float) and v == math.inf
            else _number(where, k, v, SIMULATION_KEYS[k])
        )
        for k, v in table.items()
    }
    for key in ("duration", "dt", "max_step"):
        if key in out and out[key] <= 0:
            raise where.error(f"'{key}' must be > 0 seconds, got {out[key]!r}")
    for key in ("max_track_error", "max_steady_error"):
        if key in out and out[key] <= 0:
            raise where.error(f"'{key}' must be > 0 metres, got {out[key]!r}")
    if "initial_state" in out and out["initial_state"].shape[-1:] != (16,):
        raise where.error("'initial_state' must be 16 numbers (x, y, z, vx, ..., F4), or one such list per vehicle")
    if out.get("seed", 0) < 0:
        raise where.error(f"'seed' must be >= 0, got {out['seed']!r}")
    for key in ("log_every", "n"):
        if key in out and out[key] < 1:
            raise where.error(f"'{key}' must be >= 1, got {out[key]!r}")
    return out
