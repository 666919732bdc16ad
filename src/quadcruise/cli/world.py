"""What is flown and in what world, said the same way by ``fly``, ``compare``, ``tune`` and
``montecarlo``: the options ``--vehicle``, ``--controller-vehicle``, ``--wind``, ``--turbulence``,
``--seed``, ``--log-every``, and the objects they make."""

from __future__ import annotations

import click

from quadcruise.cli.vehicle import vehicle_from_option
from quadcruise.errors import InputError

__all__ = ["WORLD_OPTIONS", "environment_from_options", "flight_world", "note", "world_options"]

VEHICLE_HELP = (
    "the paper's (or a preset's: paper) fields changed, e.g. m=1.4,K=48; or a FILE.toml of them "
    "(a scenario's [vehicle] too)"
)


def world_options(
    wind_help: str = "Wind, gusts, turbulence, rotor loss, force: constant:WX,WY,WZ | "
    "gust:AX,AY,AZ@START+DURATION | dryden:light|moderate|severe@ALTITUDE | loss:ROTOR,FRACTION@TIME "
    "(comma-separable; none: still air).",
    seed: bool = True,
):
    """The options that say what is flown and in what world, shared by ``fly``, ``compare``,
    ``tune`` and ``montecarlo``: ``--vehicle``, ``--controller-vehicle``, ``--wind``,
    ``--turbulence``, ``--seed`` and ``--log-every``."""
    options = [
        click.option(
            "--vehicle",
            metavar="KEY=VALUE,...|NAME|FILE.toml",
            help=f"The flown vehicle: {VEHICLE_HELP}; with a scenario, its [vehicle] changed.",
        ),
        click.option(
            "--controller-vehicle",
            "controller_vehicle",
            metavar="KEY=VALUE,...|NAME|FILE.toml",
            help="The vehicle the controller believes it flies (its model), as --vehicle; default: the "
            "flown one (no model error).",
        ),
        click.option("--wind", metavar="SPEC", help=wind_help),
        click.option(
            "--turbulence",
            metavar="light|moderate|severe[@ALTITUDE]",
            help="Dryden turbulence (MIL-F-8785C level; altitude [m], default 10).",
        ),
        click.option(
            "--log-every",
            "log_every",
            type=int,
            metavar="N",
            help="Log every N control periods (default 1; a scenario's).",
        ),
    ]
    if seed:
        options.append(
            click.option(
                "--seed",
                type=int,
                help="Seed of every random draw: turbulence, sensor noise (default 0, or the scenario's).",
            )
        )

    def add(func):
        for option in reversed(options):
            func = option(func)
        return func

    return add


WORLD_OPTIONS = world_options()


def note(text: str) -> None:
    """Print one line of information on stderr, ``note: ...`` (not a warning: nothing is wrong)."""
    click.echo(f"note: {text}", err=True)


def environment_from_options(wind: str | None, turbulence: str | None, base=None):
    """The disturbances that ``--wind`` and ``--turbulence`` describe.

    Examples
    --------
    >>> sorted(environment_from_options("constant:3,0,0", "moderate").parts)
    ['turbulence', 'wind']
    """
    import dataclasses

    from quadcruise.cli.wind import parse_wind
    from quadcruise.disturbances import INTENSITIES, Environment

    env = parse_wind(wind) if wind is not None else base
    if turbulence is not None:
        spec = str(turbulence).strip()
        level = spec.partition("@")[0].strip().lower()
        if not spec or ":" in spec or "," in spec or not (level in INTENSITIES or _is_number(level)):
            raise InputError(
                f"--turbulence {turbulence!r}: expected light, moderate or severe (or w20 in m/s), "
                "optionally @ALTITUDE[/AIRSPEED], e.g. moderate@10"
            )
        try:
            part = parse_wind(f"dryden:{spec}").turbulence
        except InputError as exc:
            raise InputError(f"--turbulence {turbulence!r}: {str(exc).partition(': ')[2] or exc}") from None
        if wind is not None and env.turbulence is not None:
            raise InputError(f"--turbulence {turbulence} and --wind {wind} both give turbulence: give it once")
        env = dataclasses.replace(env or Environment(), turbulence=part)
    return env if env is not None and env.parts else None


def _is_number(text: str) -> bool:
    try:
        float(text)
    except ValueError:
        return False
    return True


def flight_world(
    *, vehicle: str | None, controller_vehicle: str | None, wind: str | None, turbulence: str | None, scenario=None
) -> tuple[dict, list[str]]:
    """The flown vehicle, the controller's model of it and the disturbances that the options
    describe, a scenario's changed by them; and the notes to print before flying."""
    from quadcruise.disturbances import default_drag_text, with_drag
    from quadcruise.model.vehicle import Vehicle
    from quadcruise.sim import plants

    base = scenario.vehicle if scenario is not None else Vehicle.paper()
    flown = vehicle_from_option(vehicle, "--vehicle", base) or base
    plant = plants.of(flown, "--vehicle")
    believed_base = scenario.controller_vehicle if scenario is not None else None
    believed = (
        vehicle_from_option(
            controller_vehicle,
            "--controller-vehicle",
            # bare fields change the plant's default vehicle (the paper's), or the flown one
            believed_base or (Vehicle.preset(plant.default_preset) if plant.default_preset else flown),
        )
        or believed_base
    )
    env = environment_from_options(wind, turbulence, scenario.environment if scenario is not None else None)
    if vehicle is not None:
        import warnings

        with warnings.catch_warnings():  # the flight itself warns of a vehicle with little left for control
            warnings.simplefilter("ignore")
            plant.check_vehicles((flown,))  # before any note: a vehicle that cannot lift is bad input
    notes = []
    if vehicle is not None and believed is None and flown != Vehicle.paper():
        notes.append(
            f"the controller is told the flown vehicle ({vehicle}), so it flies without model error; "
            + (
                f"--controller-vehicle {plant.default_preset} (or KEY=VALUE,...) gives it another belief"
                if plant.default_preset
                else "--controller-vehicle KEY=VALUE,... (the flown vehicle changed), PRESET,KEY=VALUE,... or "
                "FILE.toml gives it another belief"
            )
        )
    if env is not None and env.needs_drag and plant.drag_for_wind and flown.drag_linear == flown.drag_quadratic == 0:
        flown = with_drag(flown)
        notes.append(default_drag_text())
    return {"vehicle": flown, "controller_vehicle": believed, "environment": env}, notes
