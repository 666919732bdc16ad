"""Vehicle presets from published data, each a TOML file the user can copy, and the reader
of a vehicle file. The vehicle classes build on it: :meth:`quadcruise.Vehicle.preset`,
:meth:`quadcruise.Vehicle.load`, :meth:`quadcruise.model.rotor_vehicle.RotorVehicle.preset`.

A vehicle file holds one ``[vehicle]`` table: either every field (as the preset files do,
``src/quadcruise/model/preset_files/*.toml``), or ``preset = "<name>"`` and the fields to
change::

    [vehicle]
    preset = "iris"
    Jxx = 0.03
    k_d = 0

``plant`` says which plant flies it: ``"paper"`` (:class:`~quadcruise.model.vehicle.Vehicle`,
the paper's Euler-angle plant) or ``"rotor"`` (:class:`~quadcruise.model.rotor_vehicle.RotorVehicle`,
the rotor-speed plant); a file without it is a rotor vehicle when it lists ``rotors``. Every
problem is one :class:`~quadcruise.errors.InputError` naming the file and the key.

This module reads tables and imports no vehicle class: the classes come in as ``plants``
(so that the classes can read presets without an import cycle).

Examples
--------
>>> sorted(PRESETS)
['crazyflie', 'hummingbird', 'iris', 'paper', 'qball-x4']
>>> preset_source("iris")[:23]
'PX4-SITL_gazebo-classic'
>>> preset_path("irs")
Traceback (most recent call last):
    ...
quadcruise.errors.InputError: unknown vehicle preset 'irs' (did you mean 'iris'?); presets: crazyflie, ...
"""

from __future__ import annotations

import dataclasses
import difflib
import functools
import tomllib
from collections.abc import Mapping
from pathlib import Path
from typing import Any

from quadcruise.errors import InputError
from quadcruise.io.files import not_a_file

PRESET_DIR = Path(__file__).with_name("preset_files")
"""Where the preset files are."""

PRESETS = {p.stem: p for p in sorted(PRESET_DIR.glob("*.toml"))}
"""Preset name -> its TOML file."""


def preset_path(name: str) -> Path:
    """The TOML file of a preset.

    Parameters
    ----------
    name : str
        The preset's name (``paper``, ``crazyflie``, ``hummingbird``, ``iris``).

    Returns
    -------
    pathlib.Path

    Raises
    ------
    InputError
        An unknown name, with the closest one and the list.
    """
    if name not in PRESETS:
        close = difflib.get_close_matches(str(name), list(PRESETS), n=1)
        hint = f" (did you mean '{close[0]}'?)" if close else ""
        raise InputError(f"unknown vehicle preset {name!r}{hint}; presets: {', '.join(sorted(PRESETS))}")
    return PRESETS[name]


@functools.cache
def _preset_table(name: str) -> dict:
    return _read_table(preset_path(name))


def preset_source(name: str) -> str:
    """Where a preset's numbers come from (its ``source``).

    Parameters
    ----------
    name : str
        The preset's name.

    Returns
    -------
    str
    """
    return str(_preset_table(name).get("source", ""))


def preset_plant(name: str) -> str:
    """Which plant flies a preset: ``"paper"`` or ``"rotor"``.

    Parameters
    ----------
    name : str
        The preset's name.

    Returns
    -------
    str
    """
    return str(_preset_table(name)["plant"])


def preset_table() -> list[dict]:
    """Every preset, one row each: what ``quadcruise vehicles`` lists.

    Returns
    -------
    list of dict
        ``name``, ``plant``, ``m`` [kg], ``rotors`` (their number; 4 for the paper's "+"),
        ``source``, ``file`` (the TOML file to copy), in name order.

    Examples
    --------
    >>> [(r["name"], r["plant"], r["m"]) for r in preset_table()][:2]
    [('crazyflie', 'rotor', 0.03), ('hummingbird', 'rotor', 0.5)]
    """
    rows = []
    for name in sorted(PRESETS):
        table = _preset_table(name)
        rows.append(
            {
                "name": name,
                "plant": table["plant"],
                "m": float(table["m"]),
                "rotors": len(table.get("rotors", ())) or 4,
                "source": str(table.get("source", "")),
                "file": str(PRESETS[name]),
            }
        )
    return rows


def load_vehicle(name_or_path: str | Path, plants: Mapping[str, type]) -> Any:
    """A vehicle from a preset's name or a vehicle file.

    Parameters
    ----------
    name_or_path : str or pathlib.Path
        A preset's name, or a TOML file with a ``[vehicle]`` table (a name ending in ``.toml``).
    plants : mapping of str to type
        ``plant`` -> the vehicle class that plant flies (``{"paper": Vehicle, "rotor": RotorVehicle}``).

    Returns
    -------
    object
        An instance of one of ``plants``' classes.

    Raises
    ------
    InputError
        An unknown preset, a missing or unreadable file, an unknown key or a bad value.
    """
    text = str(name_or_path)
    if isinstance(name_or_path, Path) or text.lower().endswith(".toml"):
        return vehicle_from_table(_read_table(Path(text)), plants, text)
    return vehicle_from_table({"preset": text}, plants, str(preset_path(text)))


def _read_table(path: Path) -> dict:
    """The ``[vehicle]`` table of a TOML file."""
    if path.is_dir():
        raise InputError(f"{path}: is a folder, not a vehicle file")
    if not path.is_file():
        raise InputError(f"{path}: {not_a_file(path)}")
    try:
        doc = tomllib.loads(path.read_text(encoding="utf-8-sig"))
    except (tomllib.TOMLDecodeError, UnicodeDecodeError) as exc:
        raise InputError(f"{path}: not valid TOML ({exc})") from None
    extra = sorted(set(doc) - {"vehicle"})
    if extra:
        raise InputError(f"{path}: unknown table or key '{extra[0]}' (a vehicle file holds one [vehicle] table)")
    table = doc.get("vehicle")
    if not isinstance(table, dict):
        raise InputError(f"{path}: no [vehicle] table")
    return table


def vehicle_from_table(table: dict, plants: Mapping[str, type], where: str = "vehicle") -> Any:
    """A vehicle from a ``[vehicle]`` table: a preset with overrides, or every field.

    Parameters
    ----------
    table : dict
        The table's keys: ``preset`` (optional), ``plant`` (optional), the fields.
    plants : mapping of str to type
        ``plant`` -> the vehicle class that plant flies (frozen dataclasses whose fields are
        the table's keys); a plant left out is refused.
    where : str
        The file (or other source) that messages name.

    Returns
    -------
    object
        An instance of one of ``plants``' classes.

    Raises
    ------
    InputError
        One line naming ``where`` and the key: an unknown preset, plant or field, a bad value,
        or a vehicle that cannot fly.

    Examples
    --------
    >>> from quadcruise.model.rotor_vehicle import RotorVehicle
    >>> vehicle_from_table({"preset": "crazyflie", "m": 0.035}, {"rotor": RotorVehicle}, "my.toml").m
    0.035
    >>> vehicle_from_table({"preset": "crazyflie", "k_dd": 0.0}, {"rotor": RotorVehicle}, "my.toml")
    Traceback (most recent call last):
        ...
    quadcruise.errors.InputError: my.toml: [vehicle] has no key 'k_dd' for the rotor plant (did you mean 'k_d'?)
    """
    table = dict(table)
    name = table.pop("preset", None)
    if name is not None:
        if not isinstance(name, str):
            raise InputError(f"{where}: [vehicle] 'preset' must be a preset's name, got {name!r}")
        base = dict(_preset_table(name))
        if table.get("plant", base["plant"]) != base["plant"]:
            raise InputError(
                f"{where}: [vehicle] 'plant' = {table['plant']!r} does not match preset '{name}', "
                f"which the {base['plant']} plant flies"
            )
        base.update(table)
        table = base
    plant = table.pop("plant", "rotor" if "rotors" in table else "paper")
    if not isinstance(plant, str):
        raise InputError(
            f"{where}: [vehicle] 'plant' must be the name of a plant ({' or '.join(plants)}), got "
            f"{type(plant).__name__} {plant!r}"
        )
    if plant not in plants:
        raise InputError(
            f"{where}: [vehicle] 'plant' = {plant!r}: here the vehicle must be for the {' or '.join(plants)} plant"
        )
    cls = plants[plant]
    fields = {f.name for f in dataclasses.fields(cls)}
    if "source" not in fields:
        table.pop("source", None)  # a class that keeps no source (the paper's Vehicle)
    for key in table:
        if key not in fields:
            close = difflib.get_close_matches(key, sorted(fields), n=1)
            hint = f" (did you mean '{close[0]}'?)" if close else ""
            raise InputError(f"{where}: [vehicle] has no key '{key}' for the {plant} plant{hint}")
    missing = [
        f.name
        for f in dataclasses.fields(cls)
        if f.name not in table and f.default is dataclasses.MISSING and f.default_factory is dataclasses.MISSING
    ]
    if missing:
        raise InputError(
            f"{where}: [vehicle] lacks {', '.join(repr(k) for k in missing)}, which the {plant} plant "
            f'needs (or start from a preset: preset = "{min(PRESETS)}")'
        )
    try:
        return cls(**_plain(table))
    except InputError as exc:
        raise InputError(f"{where}: [vehicle] {exc}") from None


def _plain(table: dict) -> dict[str, Any]:
    """TOML integers as floats for the number fields (``k_d = 0``), the rest as they are."""
    return {
        k: float(v) if isinstance(v, int) and not isinstance(v, bool) and k != "source" else v for k, v in table.items()
    }
