"""What ``quadcruise compare`` runs once its options are parsed: the mission and controllers from
them (or a scenario file), and the population that ``--population`` flies. The command, its
options and its help are in :mod:`quadcruise.cli.compare`."""

from __future__ import annotations

import click

from quadcruise.cli.common import Bar
from quadcruise.cli.objects import mission_from_options
from quadcruise.cli.vehicle import refuse_vehicle_fields
from quadcruise.errors import InputError

__all__ = [
    "default_compared",
    "compared_from_options",
    "echo_population_comparison",
    "population_from_options",
    "population_record",
]


def population_from_options(
    n: int | None,
    seed: int | None,
    mass_spread: float | None,
    scenario=None,
    environment=None,
    sensors=None,
    estimator=None,
):
    """The population that ``--population``, ``--seed`` and ``--mass-spread`` describe, a
    scenario's ``[compare] population`` changed by them; checked before anything flies.

    Parameters
    ----------
    n : int or None
        ``--population``: number of vehicles; None: the scenario's, else none flown.
    seed : int or None
        ``--seed``: the population's seed (and the flights'); None: the scenario's, else 0.
    mass_spread : float or None
        ``--mass-spread``: relative standard deviation of the mass; None: the scenario's, else 0.1.
    scenario : Scenario, optional
        Its ``compare_population`` (n, seed, the spreads) is the starting point.
    environment, sensors, estimator : optional
        The flights' disturbances, sensor noise or sensor models and estimator, which the
        population meets too.

    Returns
    -------
    (int or None, int, Population or None)
        The number of vehicles, the seed, the population (None when none is flown).

    Raises
    ------
    InputError
        A bad value; ``--mass-spread`` without a population; a population that perturbs nothing.
    """
    from quadcruise.errors import whole_number
    from quadcruise.montecarlo.api import Population

    table = dict(scenario.compare_population) if scenario is not None else {}
    if n is not None:
        whole_number(n, "--population", minimum=1)
        table["n"] = n
    if seed is not None:
        whole_number(seed, "--seed")
        table["seed"] = seed
    if mass_spread is not None:
        table["mass_spread"] = mass_spread
    if "n" not in table:
        if mass_spread is not None:
            raise InputError(
                "--mass-spread describes the population that --population N flies; without it, it would change nothing"
            )
        return None, table.get("seed", 0), None
    count, pop_seed = table.pop("n"), table.pop("seed", 0)
    table.setdefault("mass_spread", 0.1)
    from quadcruise.estimation.stage import Sensors

    models = sensors if isinstance(sensors, Sensors) else None
    pop = Population(
        **table,
        environment=environment if environment is not None and environment.parts else None,
        noise=None if models is not None else sensors,
        sensors=models,
        estimator=estimator,
    )
    pop.check_perturbs(
        count,
        hint="a --mass-spread > 0, turbulence (--turbulence "
        "moderate) or a scenario's sensor noise or spreads ([compare] population)",
    )
    return count, pop_seed, pop


def population_record(n: int, seed: int, pop) -> dict:
    """``[compare] population`` of a scenario: what :func:`population_from_options` reads back.

    Parameters
    ----------
    n, seed : int
        Number of vehicles and seed.
    pop : Population
        The population (its disturbances are the flights' own, recorded with them).

    Returns
    -------
    dict
        ``n``, ``seed`` and the population's fields that differ from the defaults (the mass
        spread always).
    """
    import dataclasses

    from quadcruise.montecarlo.api import Population

    default = Population()
    flights = ("environment", "noise", "sensors", "estimator")  # the flights' own, recorded with them
    fields = {f.name: getattr(pop, f.name) for f in dataclasses.fields(pop) if f.name not in flights}
    kept = {k: v for k, v in fields.items() if k == "mass_spread" or v != getattr(default, k)}
    return {"n": int(n), "seed": int(seed), **kept}


def echo_population_comparison(mission, controllers, n: int, seed: int, pop, flight: dict):
    """Fly the controllers on the same perturbed vehicles, in this process; print one row each.

    Parameters
    ----------
    mission : Mission
    controllers : str or dict
        Comma-separated controller names, or label -> controller.
    n : int
        Number of vehicles.
    seed : int
        Seed of the population.
    pop : Population
        The population (:func:`population_from_options`), its disturbances the flights'.
    flight : dict
        The nominal flights' keywords: its ``vehicle`` is the population's nominal (given
        drag already where wind meets it), its ``controller_vehicle`` the controllers' model;
        ``duration``, ``dt``, ``max_step`` and ``full_dynamics`` as the nominal flights.

    Returns
    -------
    pandas.DataFrame
        :func:`quadcruise.montecarlo.compare.compare_population`'s table.
    """
    from quadcruise.montecarlo.compare import compare_population

    same = {
        k: flight[k]
        for k in ("vehicle", "controller_vehicle", "max_step", "full_dynamics")
        if flight.get(k) is not None
    }
    table = compare_population(
        mission,
        controllers,
        pop,
        n,
        seed,
        duration=flight.get("duration"),
        dt=flight.get("dt", 1e-3),
        scheduler="none",
        progress=Bar("flying the population", unit="flight"),
        **same,
    )
    world = ", ".join(pop.environment.parts) if pop.environment is not None else ""
    click.echo(
        f"\nthe same {n} perturbed vehicles (seed {seed}, mass spread {pop.mass_spread:g}"
        + (f", {world}" if world else "")
        + "):"
    )
    click.echo(table.to_string(float_format=lambda v: f"{v:.4g}"))
    return table


def default_compared() -> str:
    """The controllers (comma-separated) ``quadcruise compare`` flies when neither the options nor a
    scenario name any: those declared ``compared=True`` (:func:`~quadcruise.control.registry.compared_names`)."""
    from quadcruise.control.registry import compared_names

    return ",".join(compared_names())


def compared_from_options(mission: str, controllers: str | None, mission_params: tuple[str, ...]):
    """What ``quadcruise compare MISSION ...`` flies: the mission, controllers and keywords.

    Parameters
    ----------
    mission : str
        A mission name, a waypoint CSV (``.csv``) or a scenario file (``.toml``).
    controllers : str or None
        ``--controllers``, comma-separated names; None: the scenario's ``[compare]`` controllers,
        else its ``[controller]``, else :func:`default_compared`.
    mission_params : tuple of str
        ``-m KEY=VALUE`` parameters of the mission.

    Returns
    -------
    (Mission, str or dict, dict, Scenario or None)
        The mission, the controllers (names, or label -> controller), the keywords (the
        scenario's vehicle as written, without drag added) and the scenario read.
    """
    from quadcruise.cli.assignments import parse_assignments

    if not mission.lower().endswith(".toml"):
        chosen = default_compared() if controllers is None else controllers
        return mission_from_options(mission, mission_params, smooth=False), chosen, {}, None
    from quadcruise.missions import mission_from_name
    from quadcruise.workflows.scenario import load_scenario

    scenario = load_scenario(mission)
    the_mission = scenario.mission or mission_from_name("circle")
    if mission_params:
        changes = parse_assignments(mission_params, "--mission-param")
        refuse_vehicle_fields(changes, type(the_mission))
        the_mission = the_mission.replace(**changes)
    chosen = (
        controllers
        if controllers is not None
        else scenario.compare
        or ({scenario.controller.name: scenario.controller} if scenario.controller is not None else default_compared())
    )
    return the_mission, chosen, scenario.fly_kwargs(drag=False), scenario
