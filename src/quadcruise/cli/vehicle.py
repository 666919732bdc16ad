"""Vehicles from command-line options: ``--vehicle`` and ``--controller-vehicle`` (a preset, fields
or a file), and a vehicle's field given to the mission by mistake."""

from __future__ import annotations

from quadcruise.errors import InputError

__all__ = ["refuse_vehicle_fields", "vehicle_from_option"]


def vehicle_from_option(text: str | None, option: str, base=None):
    """The vehicle that ``--vehicle`` or ``--controller-vehicle`` describes: a preset (``paper``), ``KEY=VALUE,...``
    fields changing ``base``, both (``paper,m=1.4``), or a TOML file.

    Examples
    --------
    >>> vehicle_from_option("m=1.4,K=48", "--vehicle").m
    1.4
    >>> vehicle_from_option("jumbo", "--vehicle")
    Traceback (most recent call last):
        ...
    quadcruise.errors.InputError: --vehicle 'jumbo': unknown vehicle preset 'jumbo' (known: paper, crazyflie, \
hummingbird, iris, qball-x4); or give the vehicle's fields, KEY=VALUE,..., or a FILE.toml
    """
    if text is None:
        return None
    import dataclasses

    from quadcruise.cli.assignments import parse_assignments
    from quadcruise.model.vehicle import Vehicle
    from quadcruise.workflows.scenario_vehicle import read_vehicle_file, vehicle_preset

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
        fields = [f.name for f in dataclasses.fields(type(vehicle))]
        values = parse_assignments(text, option, keys=fields, numbers=True)
        many = [k for k, v in values.items() if isinstance(v, tuple)]
        if many:
            raise InputError(f"{many[0]} must be one number")
        return vehicle.replace(**values)
    except InputError as exc:
        message = str(exc)
        if message.startswith(option):
            raise
        hint = (
            "; or give the vehicle's fields, KEY=VALUE,..., or a FILE.toml"
            if message.startswith("unknown vehicle preset")
            else ""
        )
        raise InputError(f"{option} {text!r}: {message}{hint}") from None


def refuse_vehicle_fields(mission_params: dict, mission_cls, option: str = "-m") -> None:
    """Refuse a vehicle's field given as a mission parameter, pointing to ``--vehicle``."""
    import dataclasses

    from quadcruise.model.vehicle import Vehicle

    own = {f.name for f in dataclasses.fields(mission_cls)}
    for key, value in mission_params.items():
        if key in {f.name for f in dataclasses.fields(Vehicle)} and key not in own:
            shown = ",".join(f"{v:g}" for v in value) if isinstance(value, tuple) else f"{value}"
            raise InputError(
                f"{option} {key}={shown}: {key} is a field of the vehicle, not of the mission: "
                f"give it as --vehicle {key}={shown}"
            )
