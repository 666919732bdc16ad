"""A sweep from options and a scenario file: its :class:`MonteCarloSpec` and its number of
flights, the options given explicitly winning over the scenario's ``[montecarlo]`` table,
``[simulation]`` and disturbances, which win over the defaults."""

from __future__ import annotations

import dataclasses

from quadcruise.errors import InputError
from quadcruise.io.scenario_file import SPEC_KEYS
from quadcruise.montecarlo.population import Population
from quadcruise.montecarlo.spec import MonteCarloSpec
from quadcruise.workflows.scenario import Scenario, load_scenario

__all__ = ["merge_scenario", "sweep_spec"]


def merge_scenario(path, given: dict) -> tuple[Scenario, dict]:
    """A scenario, and its ``[montecarlo]`` table (and ``[simulation]`` seed) under the
    options given explicitly.

    Parameters
    ----------
    path : str or path-like
        The TOML scenario file (:func:`~quadcruise.workflows.scenario.load_scenario`).
    given : dict
        Options given explicitly: ``n``, ``seed`` and :class:`Population` fields (not
        ``environment`` nor ``noise``). They win over the scenario's.

    Returns
    -------
    scenario : Scenario
    options : dict
        The scenario's table updated with ``given``.

    Raises
    ------
    InputError
        The table has a key that is none of ``n``, ``seed`` and the Population fields.
    """
    sc = load_scenario(path)
    table = dict(sc.montecarlo)
    known = ({f.name for f in dataclasses.fields(Population)} - {"environment", "noise"}) | set(SPEC_KEYS)
    unknown = set(table) - known - {"n", "seed"}
    if unknown:
        raise InputError(
            f"{path}: [montecarlo] unknown key(s) {', '.join(sorted(unknown))} "
            f"(known: n, seed, {', '.join(sorted(known))})"
        )
    if "seed" in sc.simulation:
        table.setdefault("seed", sc.simulation["seed"])
    return sc, {**table, **given}


def sweep_spec(
    *,
    mission=None,
    controller=None,
    n: int | None = None,
    seed: int | None = None,
    duration: float | None = None,
    dt: float | None = None,
    environment=None,
    noise=None,
    scenario=None,
    requirements=(),
    max_track_error_m: float | None = None,
    vehicle=None,
    controller_vehicle=None,
    log_every: int | None = None,
    **population,
) -> tuple[MonteCarloSpec, int]:
    """The spec of a sweep and its number of flights; None means "not given".

    Parameters
    ----------
    mission, controller : names or objects, optional
        Given, else those of ``scenario``, else the circle and nlpd.
    n, seed : int, optional
        Number of flights and seed: given, else the scenario's, else 1000 and 0.
    duration : float, optional
        Flight time [s]: given, else the scenario's, else the mission's.
    dt : float, optional
        Control period [s]: given, else the scenario's, else 1 ms.
    environment : Environment, optional
        Disturbances (an empty one: none): given, else the scenario's.
    noise : SensorNoise, optional
        Sensor noise: given, else the scenario's.
    scenario : str or path-like, optional
        A TOML scenario file: mission, controller, nominal vehicle, disturbances, sensor
        noise, simulation settings, and a ``[montecarlo]`` table (:func:`merge_scenario`).
    requirements : sequence of str
        The user's pass criteria (:class:`MonteCarloSpec`'s ``requirements``).
    max_track_error_m : float, optional
        The "lost track" bound [m]; the spec's default if None.
    vehicle, controller_vehicle : Vehicle, optional
        The nominal vehicle and the controllers' model of it: given, else the scenario's
        ``[vehicle]`` and ``[controller_vehicle]``, else Table I and the nominal vehicle.
    log_every : int, optional
        Control periods between the logged instants the metrics are measured on (the
        spec's ``log_dt`` is ``log_every * dt``): given, else the scenario's ``log_dt``, else 10 ms.
    **population
        :class:`Population` fields (spreads, offset, distribution, model_error): given, else
        the scenario's, else the Population's defaults.

    Returns
    -------
    spec : MonteCarloSpec
    n : int

    Raises
    ------
    InputError
        An unknown or bad option, or a bad scenario.
    """
    given = {key: value for key, value in {**population, "n": n, "seed": seed}.items() if value is not None}
    options: dict = dict(
        duration=duration, dt=1e-3 if dt is None else dt, requirements=requirements, max_track_error_m=max_track_error_m
    )
    if scenario is not None:
        sc, given = merge_scenario(scenario, given)
        mission = sc.mission if mission is None else mission
        controller = sc.controller if controller is None else controller
        environment = environment if environment is not None else sc.environment
        noise = noise if noise is not None else sc.sensor_noise
        options.update(
            vehicle=sc.vehicle,
            controller_vehicle=sc.controller_vehicle,
            duration=duration or sc.duration,
            dt=sc.dt if dt is None else dt,
            max_step=sc.simulation.get("max_step"),
            full_dynamics=sc.simulation.get("full_dynamics", False),
        )
    n, seed = given.pop("n", 1000), given.pop("seed", 0)
    for key in SPEC_KEYS:  # the scenario's settings; options given win
        if key in given:
            value = given.pop(key)
            if key == "requirements" and requirements:
                continue
            if key == "max_track_error_m" and max_track_error_m is not None:
                continue
            options[key] = tuple(value) if key == "requirements" else value
    if vehicle is not None:
        options["vehicle"] = vehicle
    if controller_vehicle is not None:
        options["controller_vehicle"] = controller_vehicle
    if log_every is not None:
        options["log_dt"] = log_every * options["dt"]
    mission = "circle" if mission is None else mission
    controller = "nlpd" if controller is None else controller
    pop = Population(
        **given, environment=environment if environment is not None and environment.parts else None, noise=noise
    )
    return MonteCarloSpec(mission=mission, controller=controller, population=pop, seed=seed, **options), n
