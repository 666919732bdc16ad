"""Objects from command-line options: a controller from ``--controller``, ``-c KEY=VALUE`` and
``--poles``; a mission from a name or a waypoint CSV and ``-m KEY=VALUE``."""

from __future__ import annotations

from quadcruise.cli.vehicle import refuse_vehicle_fields
from quadcruise.errors import InputError

__all__ = ["controller_from_options", "controller_params", "flight_from_options", "mission_from_options"]


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
