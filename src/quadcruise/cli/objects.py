"""Objects from command-line options: a controller from ``--controller``, ``-c KEY=VALUE`` and
``--poles``; a mission from a name or a waypoint CSV and ``-m KEY=VALUE``."""

from __future__ import annotations

import click

from quadcruise.cli.vehicle import refuse_vehicle_fields
from quadcruise.errors import InputError

PARAMS_OPTION = click.option(
    "--params",
    "px4_params",
    type=click.Path(dir_okay=False),
    metavar="LOG.ulg|FILE.params",
    help="PX4's parameters from a PX4 log or a QGroundControl file, flown by the px4 controller "
    "(the default controller with this option); parameters the px4 controller does not use are listed once.",
)

__all__ = ["with_px4_params", "PARAMS_OPTION", "controller_for_vehicle", "controller_with_params"]
__all__ += ["controller_from_options", "controller_params", "flight_from_options", "mission_from_options"]


def _poles(text: str | None, option: str):
    """Parse comma-separated poles, e.g. ``-0.7,-4.3`` or ``-1+2j,-1-2j``."""
    if text is None:
        return None
    from quadcruise.control.design import parse_pole

    try:
        return [parse_pole(p) for p in text.split(",")]
    except ValueError:
        raise InputError(f"{option} {text!r}: expected comma-separated poles, e.g. -0.7,-4.3") from None


def controller_params(params: tuple[str, ...], poles_text: str | None) -> dict:
    """The controller parameters that ``-c KEY=VALUE`` and ``--poles`` give."""
    from quadcruise.cli.assignments import parse_assignments
    from quadcruise.control.design import pd_from_poles

    out = parse_assignments(params, "--controller-param")
    poles = _poles(poles_text, "--poles")
    if poles is not None:
        out["position"] = pd_from_poles(poles, source="--poles")
    return out


def controller_from_options(name: str | None, params: tuple[str, ...], poles_text: str | None, base=None):
    """The controller that ``--controller``, ``-c KEY=VALUE`` and ``--poles`` describe."""
    import dataclasses

    from quadcruise.control import controller_from_name

    given = controller_params(params, poles_text)
    if name is not None or base is None:
        return controller_from_name("nlpd" if name is None else name, **given)
    known = [f.name for f in dataclasses.fields(base)]
    unknown = sorted(set(given) - set(known))
    if unknown:
        raise InputError(f"{base.name} has no parameter {unknown[0]!r}; its parameters: {', '.join(known)}")
    return dataclasses.replace(base, **given) if given else base


def controller_for_vehicle(
    controller, name: str | None, params: tuple[str, ...], poles_text: str | None, world, scenario
):
    """The controller of a flight on a rotor-plant vehicle: a name's gains designed for it, as ``fly`` designs them.

    Parameters
    ----------
    controller : Controller
        The controller the options made (:func:`controller_from_options`).
    name : str or None
        ``--controller``: None with a scenario keeps the scenario's controller and its gains.
    params : tuple of str
        ``-c KEY=VALUE`` parameters, applied over the designed gains.
    poles_text : str or None
        ``--poles`` of the x/y loops.
    world : dict
        :func:`quadcruise.cli.world.flight_world`'s: its ``vehicle`` and ``controller_vehicle``.
    scenario : Scenario or None
        The scenario read, if any.

    Returns
    -------
    Controller
        ``controller`` for the paper's plant or a scenario's controller; else the named controller
        (nlpd by default) with the gains :func:`quadcruise.workflows.rotor_fly.flight_setup`
        designs for the vehicle the controller believes, where its plant designs gains, changed by
        ``params`` and ``poles_text``.
    """
    from quadcruise.sim import plants
    from quadcruise.workflows.rotor_fly import flight_setup

    vehicle = world.get("vehicle")
    if vehicle is None or not plants.of(vehicle).designs_gains or (scenario is not None and name is None):
        return controller
    designed = flight_setup(vehicle, world.get("controller_vehicle"), name or controller.name)[1]
    return controller_from_options(None, params, poles_text, base=designed)


KEPT_PX4_FIELDS = ("thrust_curve", "position_rate", "hover_estimator", "takeoff", "takeoff_speed_up")
"""The px4 fields a scenario's controller keeps under ``--params`` (those that set no PX4 parameter)."""


def controller_with_params(controller, name: str | None, path: str | None, params, poles_text, world, scenario=None):
    """``--params``: the px4 controller with a log's or a ``.params`` file's PX4 parameters.

    Parameters
    ----------
    controller : Controller
        The controller the other options made (returned as it is without ``path``).
    name : str or None
        ``--controller``: None or ``px4`` (another name is refused with ``--params``).
    path : str or None
        ``--params``.
    params : tuple of str
        ``-c KEY=VALUE``, applied over the controller read (its fields: ``position_rate``, ...).
    poles_text : str or None
        ``--poles`` (refused: the px4 controller has no PD position gains).
    world : dict
        :func:`quadcruise.cli.world.flight_world`'s: the controller's vehicle gives the rotor layout.
    scenario : Scenario, optional
        A scenario file read: a px4 ``[controller]`` of it keeps its fields that set no PX4
        parameter (:data:`KEPT_PX4_FIELDS`: ``thrust_curve``, ``position_rate``, ...) under ``-c``.

    Returns
    -------
    Controller
        :meth:`quadcruise.control.px4.Px4.from_params` of the file, for the vehicle the controller believes.

    Raises
    ------
    InputError
        Another controller named, ``--poles``, or a bad file (one line naming the file and parameter).
    """
    if path is None:
        return controller
    if name not in (None, "px4"):
        raise InputError(f"--params sets PX4's parameters of the px4 controller; --controller {name} has none")
    if poles_text is not None:
        raise InputError("--poles: the px4 controller takes its position gains from --params (MPC_XY_P, ...)")
    from quadcruise.control.px4 import Px4
    from quadcruise.io.px4params import px4_constrained, read_params

    read = read_params(path)
    believed = world.get("controller_vehicle") or world.get("vehicle")
    kept = getattr(scenario, "controller", None)
    kept = {f: getattr(kept, f) for f in KEPT_PX4_FIELDS} if getattr(kept, "name", None) == "px4" else {}
    px4 = Px4.from_params(read, vehicle=believed, **kept)
    for note in read.notes:  # another release's log, older names
        click.echo(f"note: {note}", err=True)
    for note in px4_constrained(read)[1]:  # what PX4's parameters_update changes, as PX4 says it
        click.echo(f"note: {path}: {note}", err=True)
    if read.unused:
        names = ", ".join(read.unused)
        click.echo(
            f"note: {len(read.unused)} parameters of {path} are not used by the px4 controller: {names}", err=True
        )
    out = controller_from_options(None, params, None, base=px4)
    if out.params is not px4.params:
        raise InputError(
            f"-c params=...: --params {path} gives the px4 controller's parameters; give them once "
            "(one file, or a scenario's [controller] params)"
        )
    if out.hover_from_vehicle:  # the file's hover thrust not flown: said, not silently
        click.echo(
            f"note: -c hover_from_vehicle=true: the vehicle's hover thrust replaces {path}'s MPC_THR_HOVER "
            f"({read['MPC_THR_HOVER']:g}), MPC_THR_MIN at most half of it",
            err=True,
        )
    if out.rate_bandwidth > 0.0:
        click.echo(
            f"note: -c rate_bandwidth={out.rate_bandwidth:g}: rate gains designed for that rotor lag replace "
            f"{path}'s MC_*RATE_P, _I, _D (and _K)",
            err=True,
        )
    return out


def mission_from_options(text: str, params: tuple[str, ...], smooth: bool):
    """A mission from a name or a waypoint CSV, with KEY=VALUE parameters."""
    from quadcruise.cli.assignments import parse_assignments
    from quadcruise.missions import MISSIONS, mission_from_name

    mparams = parse_assignments(params, "--mission-param")
    if text.lower().endswith(".csv"):
        mparams["table"] = text
        text = "minsnap" if smooth else "waypoints"
    if text in MISSIONS:
        refuse_vehicle_fields(mparams, MISSIONS[text])
    return mission_from_name(text, **mparams)


def flight_from_options(
    mission: str,
    controller: str | None,
    mission_params: tuple[str, ...],
    controller_params: tuple[str, ...],
    poles_text: str | None,
    smooth: bool,
):
    """What ``quadcruise fly MISSION ...`` flies: from a mission name, a waypoint CSV or a scenario
    file, with the options applied to it."""
    from quadcruise.cli.assignments import parse_assignments
    from quadcruise.missions import mission_from_name

    if not mission.lower().endswith(".toml"):
        if smooth and not mission.lower().endswith(".csv"):
            raise InputError(f"--smooth turns a waypoint CSV into a minimum-snap path; {mission!r} is not one")
        return (
            mission_from_options(mission, mission_params, smooth),
            controller_from_options(controller, controller_params, poles_text),
            {},
            None,
        )
    from quadcruise.workflows.scenario import load_scenario

    if smooth:
        raise InputError(
            "--smooth turns a waypoint CSV into a minimum-snap path; a scenario file "
            'says its mission kind itself (kind = "minsnap")'
        )
    scenario = load_scenario(mission)
    the_mission = scenario.mission or mission_from_name("circle")
    if mission_params:
        changes = parse_assignments(mission_params, "--mission-param")
        refuse_vehicle_fields(changes, type(the_mission))
        the_mission = the_mission.replace(**changes)
    the_controller = controller_from_options(controller, controller_params, poles_text, base=scenario.controller)
    return the_mission, the_controller, scenario.fly_kwargs(drag=False), scenario


def with_px4_params(chosen, path: str | None, world: dict):
    """``compare --params``: the px4 entry of the compared controllers flown with a log's or a
    ``.params`` file's PX4 parameters (px4 added when not named).

    Parameters
    ----------
    chosen : str or dict
        :func:`compared_from_options`'s controllers: comma-separated names, or label -> controller.
    path : str or None
        ``--params``.
    world : dict
        :func:`quadcruise.cli.world.flight_world`'s: the controller's vehicle.

    Returns
    -------
    str or dict
        ``chosen`` without ``path``; else label -> controller, px4's read from ``path``.

    Raises
    ------
    InputError
        A bad parameter file (one line naming it).
    """
    if path is None:
        return chosen
    px4 = controller_with_params(None, None, path, (), None, world)
    if isinstance(chosen, str):
        names = [n.strip() for n in chosen.split(",") if n.strip()]
        chosen = {n: n for n in names}
    import dataclasses

    def flown(c):  # a px4 of a scenario keeps its fields that set no PX4 parameter
        if getattr(c, "name", c) != "px4":
            return c
        return px4 if isinstance(c, str) else dataclasses.replace(px4, **{f: getattr(c, f) for f in KEPT_PX4_FIELDS})

    out = {label: flown(c) for label, c in dict(chosen).items()}
    if not any(getattr(c, "name", c) == "px4" for c in out.values()):
        out["px4"] = px4
    return out
