"""The scenario's ``[controller]`` table (a built-in controller, its gains or its poles) and its
``[compare]`` table (the controllers to compare and the population they fly)."""

from __future__ import annotations

import dataclasses
from collections.abc import Mapping
from pathlib import Path
from typing import Any

from quadcruise.control import CONTROLLERS, Controller
from quadcruise.control.design import PDGains, PIDGains, parse_pole, pd_from_poles, pid_from_poles
from quadcruise.workflows.scenario_values import Where, check_keys, read_number

COMPARE_POPULATION_KEYS = (
    "n",
    "seed",
    "mass_spread",
    "inertia_spread",
    "thrust_spread",
    "bandwidth_spread",
    "yaw_arm_spread",
    "offset",
    "wind_spread",
    "distribution",
    "model_error",
)
"""Keys of ``[compare] population``: the number of vehicles, the seed and the
:class:`~quadcruise.montecarlo.Population` fields (its disturbances are the scenario's)."""


def _poles(where: Where, key: str, value) -> list:
    if not isinstance(value, list) or not value:
        raise where.error(f"'{key}' must be a list of poles, e.g. [-0.7, -4.3]")
    out = []
    for p in value:
        try:
            out.append(parse_pole(p))
        except (TypeError, ValueError):
            raise where.error(f"'{key}': {p!r} is not a pole (a number, or a string like \"-1+2j\")") from None
    return out


def controller_table(where: Where, table: dict, base: Path | None = None) -> Controller:
    """``[controller]`` (or one of ``[compare]``'s): a built-in controller from its name, gains and
    poles; a relative file name (px4's ``params = "x500.params"``) is taken relative to ``base``."""
    name = table.get("name", "nlpd")
    if not isinstance(name, str) or name not in CONTROLLERS:
        raise where.error(f"unknown controller name {name!r} (known: {', '.join(CONTROLLERS)})")
    cls = CONTROLLERS[name]
    defaults = cls()
    fields = {f.name for f in dataclasses.fields(cls)}
    gain_fields = {n for n in fields if dataclasses.is_dataclass(getattr(defaults, n))}
    pole_fields = {n for n in gain_fields if isinstance(getattr(defaults, n), (PDGains, PIDGains))}
    known = fields | {f"{n}_poles" for n in pole_fields} | {"name"}
    check_keys(where, "", table, known)
    params: dict[str, Any] = {}
    for key, value in table.items():
        if key == "name":
            continue
        if key.endswith("_poles"):
            poles = _poles(where, key, value)
            design = pd_from_poles if len(poles) == 2 else pid_from_poles
            params[key[:-6]] = where.wrap(design, poles)
        elif isinstance(getattr(defaults, key), (tuple, Mapping)):  # px4's rotors and params: its own checks
            if isinstance(value, str) and base is not None:  # a file beside the scenario, as a waypoint table
                path = Path(value) if Path(value).is_absolute() else (base / value).resolve()
                if not path.is_file():
                    raise where.error(f"'{key}' = {value!r}: no such file {path} (relative to the scenario's folder)")
                value = str(path)
            params[key] = value
        elif key in gain_fields:
            if not isinstance(value, dict):
                raise where.error(f"'{key}' must be a table of gains, e.g. {{ kp = 3.01, kd = 5.0 }}")
            default = getattr(defaults, key)
            if isinstance(default, (PDGains, PIDGains)):
                cls_gains = PIDGains if "ki" in value else PDGains
            else:
                cls_gains = type(default)
            check_keys(
                where,
                f"{key}.",
                value,
                {f.name for f in dataclasses.fields(cls_gains)}
                | ({"kp", "kd", "ki"} if cls_gains in (PDGains, PIDGains) else set()),
            )
            params[key] = where.wrap(cls_gains, **{k: read_number(where, f"{key}.{k}", v) for k, v in value.items()})
        elif isinstance(value, bool) or isinstance(value, str):
            params[key] = value
        else:
            params[key] = read_number(where, key, value)
    return where.wrap(cls, **params)


def compare_table(where: Where, table: dict) -> dict:
    """``[compare]``: ``controllers``, a list of names or of controller tables with a ``label``;
    ``population``, checked here and kept as written (``quadcruise compare`` flies it)."""
    check_keys(where, "", table, {"controllers", "population"})
    if "population" in table:
        pop = table["population"]
        if not isinstance(pop, dict):
            raise where.error("'population' must be a table, e.g. population = { n = 100, mass_spread = 0.1 }")
        check_keys(where, "population.", pop, set(COMPARE_POPULATION_KEYS))
        if "n" not in pop:
            raise where.error("'population' needs n, the number of vehicles")
        for key, value in pop.items():
            if key == "distribution":
                if value not in ("normal", "uniform"):
                    raise where.error(f"'population.distribution' must be normal or uniform, got {value!r}")
            else:
                kind = int if key in ("n", "seed") else bool if key == "model_error" else float
                read_number(where, f"population.{key}", value, kind)
        if isinstance(pop["n"], int) and pop["n"] < 1 or pop.get("seed", 0) < 0:
            raise where.error("'population' needs n >= 1 and seed >= 0")
    items = table.get("controllers", [])
    if not isinstance(items, list):
        raise where.error("'controllers' must be a list of names or of [[compare.controllers]] tables")
    out: dict = {}
    for k, item in enumerate(items):
        if isinstance(item, str):
            item = {"name": item}
        if not isinstance(item, dict):
            raise where.error(f"controllers[{k}] must be a name or a table, got {item!r}")
        item = dict(item)
        label = item.pop("label", item.get("name", "nlpd"))
        if not isinstance(label, str) or label in out:
            raise where.error(f"controllers[{k}]: label {label!r} must be a text given once")
        out[label] = controller_table(where, item)
    return out


__all__ = ["COMPARE_POPULATION_KEYS"]
