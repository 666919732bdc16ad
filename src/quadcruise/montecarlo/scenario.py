"""A sweep from options and a scenario file: its :class:`MonteCarloSpec` and its number of
flights, the options given explicitly winning over the scenario's ``[montecarlo]`` table,
``[simulation]`` and disturbances, which win over the defaults.

This is the scenario reader of the ``[montecarlo]`` table, so it also reads the text form of a
requirement, ``"steady_max_error_m<=0.2"`` (:func:`parse_requirement`), which the table holds
and the command line's ``--require`` takes; the library itself takes
:class:`~quadcruise.montecarlo.requirements.Requirement` objects.
"""

from __future__ import annotations

import dataclasses
import math
import re
from collections.abc import Iterable

from quadcruise.errors import InputError
from quadcruise.io.scenario_file import SPEC_KEYS
from quadcruise.montecarlo.population import Population
from quadcruise.montecarlo.requirements import Requirement
from quadcruise.montecarlo.schema import METRICS
from quadcruise.montecarlo.spec import MonteCarloSpec
from quadcruise.workflows.scenario import Scenario, load_scenario

__all__ = ["merge_scenario", "parse_requirement", "parse_requirements", "sweep_spec"]

_REQUIREMENT = re.compile(r"^\s*([A-Za-z_][A-Za-z0-9_]*)\s*(<=|>=|<|>)\s*([^<>=\s]+)\s*$")


def parse_requirement(text: str, where: str = "") -> Requirement:
    """A requirement from its text, ``"metric<=value"`` (``<``, ``>=``, ``>`` too; spaces allowed).

    Examples
    --------
    >>> parse_requirement("overshoot_pct <= 5")
    Requirement(metric='overshoot_pct', op='<=', value=5.0)
    >>> parse_requirement("steady_max_error <= 0.2")      # doctest: +ELLIPSIS
    Traceback (most recent call last):
        ...
    quadcruise.errors.InputError: requirement 'steady_max_error <= 0.2': unknown metric 'steady_max_error'; choose ...
    """
    what = (f"{where}: " if where else "") + f"requirement {text!r}"
    if not isinstance(text, str):
        raise InputError(f"{what}: a requirement is text such as 'steady_max_error_m<=0.2'")
    match = _REQUIREMENT.match(text)
    if match is None:
        raise InputError(
            f"{what}: expected METRIC<=VALUE (or <, >=, >), e.g. "
            f"steady_max_error_m<=0.2, with METRIC one of {', '.join(METRICS)}"
        )
    metric, op, number = match.groups()
    if metric not in METRICS:
        raise InputError(f"{what}: unknown metric {metric!r}; choose one of {', '.join(METRICS)}")
    try:
        value = float(number)
    except ValueError:
        value = math.nan
    if not math.isfinite(value):
        raise InputError(f"{what}: {number!r} is not a finite number")
    return Requirement(metric, op, value)


def parse_requirements(texts: str | Iterable[str] | None, where: str = "") -> tuple[Requirement, ...]:
    """Requirements from their texts, each read by :func:`parse_requirement`.

    Examples
    --------
    >>> [r.text for r in parse_requirements(["rmse_m<0.5", "overshoot_pct <= 10"])]
    ['rmse_m<0.5', 'overshoot_pct<=10']
    """
    if texts is None:
        return ()
    if isinstance(texts, str):
        texts = [texts]
    elif not isinstance(texts, Iterable):
        raise InputError(f"{where + ': ' if where else ''}requirements must be a list of texts, got {texts!r}")
    return tuple(parse_requirement(t, where) for t in texts)


def merge_scenario(path, given: dict) -> tuple[Scenario, dict]:
    """A scenario, and its ``[montecarlo]`` table (and ``[simulation]`` seed) under the options given explicitly."""
    sc = load_scenario(path)
    table = dict(sc.montecarlo)
    known = ({f.name for f in dataclasses.fields(Population)} - {"environment", "noise", "sensors", "estimator"}) | set(
        SPEC_KEYS
    )
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
    sensors=None,
    estimator=None,
    scenario=None,
    requirements=(),
    max_track_error_m: float | None = None,
    vehicle=None,
    controller_vehicle=None,
    log_every: int | None = None,
    **population,
) -> tuple[MonteCarloSpec, int]:
    """The spec of a sweep and its number of flights; None means "not given" (``estimator=False``:
    none, over a scenario's)."""
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
        sensors = sensors if sensors is not None else sc.sensors
        estimator = estimator if estimator is not None else sc.estimator
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
            if key == "requirements":
                value = parse_requirements(value, f"{scenario}: [montecarlo] requirements")
                if requirements:
                    continue
            if key == "max_track_error_m" and max_track_error_m is not None:
                continue
            options[key] = value
    if vehicle is not None:
        options["vehicle"] = vehicle
    if controller_vehicle is not None:
        options["controller_vehicle"] = controller_vehicle
    if log_every is not None:
        options["log_dt"] = log_every * options["dt"]
    estimator = None if estimator is False else estimator  # False: none, whatever the scenario says
    mission = "circle" if mission is None else mission
    controller = "nlpd" if controller is None else controller
    pop = Population(
        **given,
        environment=environment if environment is not None and environment.parts else None,
        noise=noise,
        sensors=sensors,
        estimator=estimator,
    )
    return MonteCarloSpec(mission=mission, controller=controller, population=pop, seed=seed, **options), n
