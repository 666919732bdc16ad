"""The scenario's ``[vehicle]`` and ``[controller_vehicle]`` tables, a vehicle file and the vehicles
known by name."""

from __future__ import annotations

import dataclasses
import tomllib
from pathlib import Path

from quadcruise.errors import InputError
from quadcruise.io.files import not_a_file
from quadcruise.model.rotor_vehicle import RotorVehicle
from quadcruise.model.vehicle import Vehicle
from quadcruise.model.vehicle_files import PRESETS, vehicle_from_table
from quadcruise.workflows.scenario_values import Where, check_keys, read_number, read_numbers

VEHICLE_PRESETS = {"paper": Vehicle.paper}
"""Vehicles by name: ``preset = "paper"`` in a ``[vehicle]`` table, ``--vehicle paper`` on the command line."""


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
        raise InputError(f"{path}: {not_a_file(path)}")
    try:
        doc = tomllib.loads(path.read_text(encoding="utf-8-sig"))
    except (tomllib.TOMLDecodeError, UnicodeDecodeError) as exc:
        raise InputError(f"{path}: not valid TOML ({exc})") from None
    if isinstance(doc.get("vehicle"), dict):
        return vehicle_table(Where(str(path), "vehicle"), doc["vehicle"])
    return vehicle_table(Where(str(path)), doc)


def vehicle_table(where: Where, table: dict) -> Vehicle | RotorVehicle:
    """``[vehicle]`` or ``[controller_vehicle]``: a preset with fields changed, or a rotor-plant vehicle."""
    preset = table.get("preset", "paper")
    if "plant" in table or "rotors" in table or (isinstance(preset, str) and preset in set(PRESETS) - {"paper"}):
        # a rotor-plant vehicle, or a preset file's: the vehicle file's reader (one vehicle, not a batch)
        return vehicle_from_table(table, {"paper": Vehicle, "rotor": RotorVehicle}, where.source)
    fields = {f.name for f in dataclasses.fields(Vehicle)}
    check_keys(where, "", table, fields | {"preset"})
    base = where.wrap(vehicle_preset, table.get("preset", "paper"))
    values = {
        k: read_numbers(where, k, v) if isinstance(v, list) else read_number(where, k, v)
        for k, v in table.items()
        if k != "preset"
    }
    return where.wrap(base.replace, **values)


__all__ = ["VEHICLE_PRESETS", "read_vehicle_file", "vehicle_preset"]
