"""Objects from command-line options: a controller from ``--controller``, ``-c KEY=VALUE`` and
``--poles``; a mission from a name or a waypoint CSV and ``-m KEY=VALUE``."""

from __future__ import annotations

from quadcruise.errors import InputError

__all__ = ["controller_from_options", "controller_params", "environment_from_options", "flight_from_options",
           "flight_world", "mission_from_options", "refuse_vehicle_fields", "vehicle_from_option"]


def _poles(text: str | None, option: str):
    """Parse comma-separated poles, e.g. ``-0.7,-4.3`` or ``-1+2j,-1-2j``.

    Parameters
    ----------
    text : str or None
        The option's value; None when it was not given.
    option : str
        The option's name, for the error message.

    Returns
    -------
    list of complex or float, or None
        The poles (:func:`quadcruise.control.design.parse_pole` of each); None for None.

    Raises
    ------
    InputError
        A pole is not a number.
    """
    if text is None:
        return None
    from quadcruise.control.design import parse_pole

    try:
        return [parse_pole(p) for p in text.split(",")]
    except ValueError:
        raise InputError(f"{option} {text!r}: expected comma-separated poles, e.g. -0.7,-4.3") from None


def controller_params(params: tuple[str, ...], poles_text: str | None) -> dict:
    """The controller parameters that ``-c KEY=VALUE`` and ``--poles`` give.

    Parameters
    ----------
    params : tuple of str
        ``KEY=VALUE`` parameters.
    poles_text : str or None
        Closed-loop poles of the x/y loops; their PD gains become the ``position`` gains.

    Returns
    -------
    dict
    """
    from quadcruise.control.design import pd_from_poles
    from quadcruise.fields import parse_assignments

    out = parse_assignments(params, "--controller-param")
    poles = _poles(poles_text, "--poles")
    if poles is not None:
        out["position"] = pd_from_poles(poles)
    return out


def controller_from_options(name: str | None, params: tuple[str, ...], poles_text: str | None, base=None):
    """The controller that ``--controller``, ``-c KEY=VALUE`` and ``--poles`` describe.

    Parameters
    ----------
    name : str or None
        The controller's name (:func:`quadcruise.control.controller_from_name`): a new one,
        whatever ``base`` is. None: ``base`` changed by the parameters, else ``nlpd``.
    params : tuple of str
        ``KEY=VALUE`` parameters of the controller.
    poles_text : str or None
        Closed-loop poles of the x/y loops; their PD gains become the ``position`` gains.
    base : Controller, optional
        A controller (a scenario's) that the parameters change when no name is given.

    Returns
    -------
    Controller
    """
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
    """A mission from a name or a waypoint CSV, with KEY=VALUE parameters.

    Parameters
    ----------
    text : str
        A mission name, or a path ending in ``.csv`` (a waypoint table).
    params : tuple of str
        ``KEY=VALUE`` parameters of the mission.
    smooth : bool
        Fly a waypoint table as a minimum-snap path instead of constant-speed legs.

    Returns
    -------
    Mission
    """
    from quadcruise.fields import parse_assignments
    from quadcruise.missions import MISSIONS, mission_from_name

    mparams = parse_assignments(params, "--mission-param")
    if text.lower().endswith(".csv"):
        mparams["table"] = text
        text = "minsnap" if smooth else "waypoints"
    if text in MISSIONS:
        refuse_vehicle_fields(mparams, MISSIONS[text])
    return mission_from_name(text, **mparams)


def flight_from_options(mission: str, controller: str | None, mission_params: tuple[str, ...],
                        controller_params: tuple[str, ...], poles_text: str | None, smooth: bool):
    """What ``quadcruise fly MISSION ...`` flies: from a mission name, a waypoint CSV or a scenario
    file, with the options applied to it.

    Parameters
    ----------
    mission : str
        A mission name, a waypoint CSV (``.csv``) or a scenario file (``.toml``).
    controller : str or None
        ``--controller``; None: the scenario's controller, else ``nlpd``.
    mission_params, controller_params : tuple of str
        ``-m`` and ``-c`` ``KEY=VALUE`` parameters (with a scenario, they change its mission and controller).
    poles_text : str or None
        ``--poles`` of the x/y loops.
    smooth : bool
        ``--smooth``: a waypoint CSV as a minimum-snap path.

    Returns
    -------
    (Mission, Controller, dict, Scenario or None)
        The mission, the controller, the keywords of :func:`quadcruise.fly`, and the scenario read.
    """
    from quadcruise.fields import parse_assignments
    from quadcruise.missions import mission_from_name

    if not mission.lower().endswith(".toml"):
        if smooth and not mission.lower().endswith(".csv"):
            raise InputError(f"--smooth turns a waypoint CSV into a minimum-snap path; {mission!r} is not one")
        return (mission_from_options(mission, mission_params, smooth),
                controller_from_options(controller, controller_params, poles_text), {}, None)
    from quadcruise.workflows.scenario import load_scenario

    if smooth:
        raise InputError("--smooth turns a waypoint CSV into a minimum-snap path; a scenario file "
                         "says its mission kind itself (kind = \"minsnap\")")
    scenario = load_scenario(mission)
    the_mission = scenario.mission or mission_from_name("circle")
    if mission_params:
        changes = parse_assignments(mission_params, "--mission-param")
        refuse_vehicle_fields(changes, type(the_mission))
        the_mission = the_mission.replace(**changes)
    the_controller = controller_from_options(controller, controller_params, poles_text, base=scenario.controller)
    return the_mission, the_controller, scenario.fly_kwargs(drag=False), scenario



def vehicle_from_option(text: str | None, option: str, base=None):
    """The vehicle that ``--vehicle`` or ``--controller-vehicle`` describes.

    The value is a preset's name (``paper``), ``KEY=VALUE,...`` fields of the vehicle changing
    ``base``, both (``paper,m=1.4``: the preset changed), or a TOML file (``.toml``: the fields
    at the top level, or a scenario's ``[vehicle]`` table).

    Parameters
    ----------
    text : str or None
        The option's value; None when it was not given.
    option : str
        The option's name, for the messages.
    base : Vehicle, optional
        The vehicle that bare ``KEY=VALUE`` fields change (a scenario's); Table I by default.

    Returns
    -------
    Vehicle or None
        None for None.

    Raises
    ------
    InputError
        An unknown preset or field, a value that is not one number, or a vehicle that
        cannot be (e.g. a negative mass), naming the option.

    Examples
    --------
    >>> vehicle_from_option("m=1.4,K=48", "--vehicle").m
    1.4
    >>> vehicle_from_option("jumbo", "--vehicle")
    Traceback (most recent call last):
        ...
    quadcruise.errors.InputError: --vehicle 'jumbo': unknown vehicle preset 'jumbo' (known: paper); \
or give the vehicle's fields, KEY=VALUE,..., or a FILE.toml
    """
    if text is None:
        return None
    import dataclasses

    from quadcruise.fields import parse_assignments
    from quadcruise.model.vehicle import Vehicle
    from quadcruise.workflows.scenario import read_vehicle_file, vehicle_preset

    text = str(text).strip()
    if text.lower().endswith(".toml"):
        try:
            return read_vehicle_file(text)
        except InputError as exc:
            raise InputError(f"{option} {exc}") from None
    head, _, rest = text.partition(",")
    vehicle = Vehicle.paper() if base is None else base
    try:
        if head.strip() and "=" not in head:
            vehicle, text = vehicle_preset(head.strip()), rest
            if not text.strip():
                return vehicle
        fields = [f.name for f in dataclasses.fields(Vehicle)]
        values = parse_assignments(text, option, keys=fields, numbers=True)
        many = [k for k, v in values.items() if isinstance(v, tuple)]
        if many:
            raise InputError(f"{many[0]} must be one number")
        return vehicle.replace(**values)
    except InputError as exc:
        message = str(exc)
        if message.startswith(option):
            raise
        hint = ("; or give the vehicle's fields, KEY=VALUE,..., or a FILE.toml"
                if message.startswith("unknown vehicle preset") else "")
        raise InputError(f"{option} {text!r}: {message}{hint}") from None


def refuse_vehicle_fields(mission_params: dict, mission_cls, option: str = "-m") -> None:
    """Refuse a vehicle's field given as a mission parameter, pointing to ``--vehicle``.

    Parameters
    ----------
    mission_params : dict
        The parsed ``-m KEY=VALUE`` parameters.
    mission_cls : type
        The mission's class: its own fields are not refused.
    option : str
        The option's name, for the message.

    Raises
    ------
    InputError
        A key that is a field of the vehicle and not of the mission.
    """
    import dataclasses

    from quadcruise.model.vehicle import Vehicle

    own = {f.name for f in dataclasses.fields(mission_cls)}
    for key, value in mission_params.items():
        if key in {f.name for f in dataclasses.fields(Vehicle)} and key not in own:
            shown = ",".join(f"{v:g}" for v in value) if isinstance(value, tuple) else f"{value}"
            raise InputError(f"{option} {key}={shown}: {key} is a field of the vehicle, not of the mission: "
                             f"give it as --vehicle {key}={shown}")


def environment_from_options(wind: str | None, turbulence: str | None, base=None):
    """The disturbances that ``--wind`` and ``--turbulence`` describe.

    Parameters
    ----------
    wind : str or None
        A :func:`~quadcruise.disturbances.parse_wind` spec: it replaces ``base`` (``none``: still air).
    turbulence : str or None
        ``LEVEL[@ALTITUDE[/AIRSPEED]]``, LEVEL light, moderate or severe (or w20 [m/s]), as
        the wind spec's ``dryden:`` part: it adds Dryden turbulence or replaces the base's.
    base : Environment, optional
        The disturbances otherwise flown (a scenario's).

    Returns
    -------
    Environment or None
        None when there is none.

    Raises
    ------
    InputError
        A bad spec, or turbulence given both in ``--wind`` and by ``--turbulence``.

    Examples
    --------
    >>> sorted(environment_from_options("constant:3,0,0", "moderate").parts)
    ['turbulence', 'wind']
    """
    import dataclasses

    from quadcruise.disturbances import Environment, parse_wind

    env = parse_wind(wind) if wind is not None else base
    if turbulence is not None:
        spec = str(turbulence).strip()
        if not spec or ":" in spec or "," in spec:
            raise InputError(f"--turbulence {turbulence!r}: expected light, moderate or severe "
                             "(or LEVEL@ALTITUDE[/AIRSPEED])")
        try:
            part = parse_wind(f"dryden:{spec}").turbulence
        except InputError as exc:
            raise InputError(f"--turbulence {turbulence!r}: {str(exc).partition(': ')[2] or exc}") from None
        if wind is not None and env.turbulence is not None:
            raise InputError(f"--turbulence {turbulence} and --wind {wind} both give turbulence: give it once")
        env = dataclasses.replace(env or Environment(), turbulence=part)
    return env if env is not None and env.parts else None


def flight_world(*, vehicle: str | None, controller_vehicle: str | None, wind: str | None,
                 turbulence: str | None, scenario=None) -> tuple[dict, list[str]]:
    """The flown vehicle, the controller's model of it and the disturbances that the options
    describe, a scenario's changed by them; and the notes to print before flying.

    Parameters
    ----------
    vehicle, controller_vehicle : str or None
        ``--vehicle``, ``--controller-vehicle`` (:func:`vehicle_from_option`); ``KEY=VALUE``
        fields change the scenario's ``[vehicle]`` and ``[controller_vehicle]`` (Table I
        where it has none).
    wind, turbulence : str or None
        ``--wind``, ``--turbulence`` (:func:`environment_from_options`).
    scenario : Scenario, optional
        The scenario flown.

    Returns
    -------
    dict
        ``vehicle`` (given the default drag where wind meets a vehicle without any),
        ``controller_vehicle`` (None: the flown vehicle) and ``environment`` (or None).
    list of str
        One line each: the default drag given, or a changed vehicle whose controller is told
        the truth.
    """
    from quadcruise.disturbances.environment import default_drag_text, with_drag
    from quadcruise.model.vehicle import Vehicle

    base = scenario.vehicle if scenario is not None else Vehicle.paper()
    flown = vehicle_from_option(vehicle, "--vehicle", base) or base
    believed_base = scenario.controller_vehicle if scenario is not None else None
    believed = vehicle_from_option(controller_vehicle, "--controller-vehicle",
                                   believed_base or Vehicle.paper()) or believed_base
    env = environment_from_options(wind, turbulence, scenario.environment if scenario is not None else None)
    notes = []
    if vehicle is not None and believed is None and flown != Vehicle.paper():
        notes.append(f"the controller is told the flown vehicle ({vehicle}), so it flies without model error; "
                     "--controller-vehicle paper (or KEY=VALUE,...) gives it another belief")
    if env is not None and env.needs_drag and flown.drag_linear == 0 and flown.drag_quadratic == 0:
        flown = with_drag(flown)
        notes.append(default_drag_text())
    return {"vehicle": flown, "controller_vehicle": believed, "environment": env}, notes
