"""What ``quadcruise compare`` runs once its options are parsed: the mission and controllers from
them (or a scenario file), and the population that ``--population`` flies. The command, its
options and its help are in :mod:`quadcruise.cli.compare`."""

from __future__ import annotations

import click

from quadcruise.cli.common import Bar
from quadcruise.cli.objects import mission_from_options
from quadcruise.errors import InputError

__all__ = ["DEFAULT_COMPARED", "compared_from_options", "population_from_options", "echo_population_comparison"]


def population_from_options(n: int | None, seed: int, mass_spread: float, wind: str | None):
    """The population that ``--population``, ``--seed``, ``--mass-spread`` and ``--wind`` describe,
    checked even when ``--population`` is not given (so that no bad value passes unseen).

    Parameters
    ----------
    n : int or None
        ``--population``: number of vehicles; None: none flown.
    seed : int
        ``--seed``.
    mass_spread : float
        ``--mass-spread``: relative standard deviation of the mass.
    wind : str or None
        ``--wind``: a :func:`~quadcruise.disturbances.environment.parse_wind` spec.

    Returns
    -------
    Population

    Raises
    ------
    InputError
        A bad value, or ``--seed``, ``--mass-spread`` or ``--wind`` without ``--population``.
    """
    from quadcruise.disturbances.environment import parse_wind
    from quadcruise.errors import whole_number
    from quadcruise.montecarlo.api import Population

    if n is not None:
        whole_number(n, "--population", minimum=1)
    whole_number(seed, "--seed")
    if n is None:
        defaults = (("--seed", seed, 0), ("--mass-spread", mass_spread, 0.1), ("--wind", wind, None))
        given = [option for option, value, default in defaults if value != default]
        if given:
            raise InputError(f"{given[0]} describes the population that --population N flies; without it, "
                             "it would change nothing")
    env = parse_wind(wind) if wind else None
    return Population(mass_spread=mass_spread, environment=env if env is not None and env.parts else None)


def echo_population_comparison(mission, controllers: str, n: int, seed: int, pop, wind: str | None,
                               flight: dict) -> None:
    """Fly the controllers on the same perturbed vehicles, in this process; print one row each.

    Parameters
    ----------
    mission : Mission
    controllers : str
        Comma-separated controller names.
    n : int
        Number of vehicles.
    seed : int
        Seed of the population.
    pop : Population
        The population (:func:`population_from_options`).
    wind : str or None
        The ``--wind`` spec, for the printed headline.
    flight : dict
        The nominal flights' keywords (a scenario's): its ``vehicle`` is the population's
        nominal, its ``environment`` and ``sensors`` act unless ``--wind`` replaces the
        first; ``duration``, ``dt``, ``max_step`` and ``full_dynamics`` as the nominal flights.
    """
    import dataclasses

    from quadcruise.montecarlo.compare import compare_population

    if pop.environment is None and flight.get("environment") is not None and flight["environment"].parts:
        pop = dataclasses.replace(pop, environment=flight["environment"])
    if pop.noise is None and flight.get("sensors") is not None:
        pop = dataclasses.replace(pop, noise=flight["sensors"])
    same = {k: flight[k] for k in ("vehicle", "max_step", "full_dynamics") if flight.get(k) is not None}
    table = compare_population(mission, controllers, pop, n, seed, duration=flight.get("duration"),
                               dt=flight.get("dt", 1e-3), scheduler="none",
                               progress=Bar("flying the population", unit="flight"), **same)
    click.echo(f"\nthe same {n} perturbed vehicles (seed {seed}, mass spread {pop.mass_spread:g}"
               + (f", wind {wind}" if wind else "") + "):")
    click.echo(table.to_string(float_format=lambda v: f"{v:.4g}"))


DEFAULT_COMPARED = "nlpd,gonzalez,se3,cascade"
"""The controllers ``quadcruise compare`` flies when neither the options nor a scenario name any."""


def compared_from_options(mission: str, controllers: str | None, mission_params: tuple[str, ...]):
    """What ``quadcruise compare MISSION ...`` flies: the mission, controllers and keywords.

    Parameters
    ----------
    mission : str
        A mission name, a waypoint CSV (``.csv``) or a scenario file (``.toml``).
    controllers : str or None
        ``--controllers``, comma-separated names; None: the scenario's ``[compare]`` controllers,
        else its ``[controller]``, else :data:`DEFAULT_COMPARED`.
    mission_params : tuple of str
        ``-m KEY=VALUE`` parameters of the mission.

    Returns
    -------
    (Mission, str or dict, dict)
        The mission, the controllers (names, or label -> controller) and the keywords.
    """
    from quadcruise.fields import parse_assignments

    if not mission.lower().endswith(".toml"):
        chosen = DEFAULT_COMPARED if controllers is None else controllers
        return mission_from_options(mission, mission_params, smooth=False), chosen, {}
    from quadcruise.missions import mission_from_name
    from quadcruise.workflows.scenario import load_scenario

    scenario = load_scenario(mission)
    the_mission = scenario.mission or mission_from_name("circle")
    if mission_params:
        the_mission = the_mission.replace(**parse_assignments(mission_params, "--mission-param"))
    chosen = controllers if controllers is not None else scenario.compare or (
        {scenario.controller.name: scenario.controller} if scenario.controller is not None else DEFAULT_COMPARED)
    return the_mission, chosen, scenario.fly_kwargs()
