"""The scenario's tables of the flight itself: ``[mission]``, ``[disturbances]`` and ``[simulation]``."""

from __future__ import annotations

import dataclasses
import math
from pathlib import Path
from typing import Any

from quadcruise.missions import MISSIONS, Mission
from quadcruise.workflows.scenario_values import Where, check_keys, read_number, read_numbers

SIMULATION_KEYS = {
    "duration": float,
    "dt": float,
    "max_step": float,
    "full_dynamics": bool,
    "seed": int,
    "log_every": int,
    "n": int,
    "max_track_error": float,
    "max_steady_error": float,
    "max_altitude_error": float,
    "initial_state": list,
}
DISTURBANCE_KEYS = ("wind", "gust", "turbulence", "rotor_loss", "force", "sensor_noise")


def mission_table(where: Where, table: dict, base: Path | None) -> Mission:
    """``[mission]``: a mission of its ``kind``; a relative waypoint table is taken relative to ``base``."""
    kind = table.get("kind")
    if not isinstance(kind, str) or kind not in MISSIONS:
        raise where.error(f"'kind' must be one of {', '.join(MISSIONS)}, got {kind!r}")
    cls = MISSIONS[kind]
    fields = {f.name for f in dataclasses.fields(cls)}
    check_keys(where, "", table, fields | {"kind"})
    params = {k: v for k, v in table.items() if k != "kind"}
    if isinstance(params.get("table"), dict):  # a waypoint table written inline
        from quadcruise.missions import WaypointTable

        params["table"] = where.wrap(WaypointTable.from_dict, params["table"])
    if "table" in params and isinstance(params["table"], str) and base is not None:
        params["table"] = (
            str((base / params["table"]).resolve()) if not Path(params["table"]).is_absolute() else params["table"]
        )
    for k, v in params.items():
        if isinstance(v, list):
            params[k] = tuple(v)
    return where.wrap(cls, **params)


def disturbances_table(where: Where, table: dict):
    """``[disturbances]``: the environment (or None) and the sensor noise (or None)."""
    check_keys(where, "", table, set(DISTURBANCE_KEYS))
    if not table:
        return None, None
    import quadcruise.disturbances as d

    parts: dict[str, Any] = {}
    if "wind" in table:
        wind = table["wind"]
        parts["wind"] = (
            where.wrap(d.ConstantWind, velocity=tuple(wind))
            if isinstance(wind, list)
            else where.wrap(d.ConstantWind, **_table(where, "wind", wind, d.ConstantWind))
        )
    for key, cls in (
        ("gust", d.Gust),
        ("turbulence", d.Turbulence),
        ("rotor_loss", d.RotorLoss),
        ("force", d.ExternalForce),
    ):
        if key in table:
            values = {k: tuple(v) if isinstance(v, list) else v for k, v in _table(where, key, table[key], cls).items()}
            parts[key] = where.wrap(cls, **values)
    noise = None
    if "sensor_noise" in table:
        noise = where.wrap(d.SensorNoise, **_table(where, "sensor_noise", table["sensor_noise"], d.SensorNoise))
    environment = where.wrap(d.Environment, **parts) if parts else None
    return environment, noise


def _table(where: Where, key: str, value, cls: type) -> dict:
    """An inline table whose keys are the fields of ``cls``: an unknown one is named with the
    table and the keys known, before ``cls`` is made."""
    if not isinstance(value, dict):
        raise where.error(f"'{key}' must be a table, e.g. {key} = {{ ... }}")
    check_keys(where, f"{key}.", value, {f.name for f in dataclasses.fields(cls) if f.init})
    return value


OFF_WHEN_INFINITE = ("max_track_error", "max_steady_error", "max_altitude_error")
"""[simulation] bounds that ``inf`` turns off (as in :func:`quadcruise.fly`); every other number is finite."""


def simulation_table(where: Where, table: dict) -> dict:
    """``[simulation]``: its keys checked by kind and range, as a dict."""
    check_keys(where, "", table, set(SIMULATION_KEYS))
    out = {
        k: read_numbers(where, k, v)
        if SIMULATION_KEYS[k] is list
        else (
            math.inf
            if k in OFF_WHEN_INFINITE and isinstance(v, float) and v == math.inf
            else read_number(where, k, v, SIMULATION_KEYS[k])
        )
        for k, v in table.items()
    }
    for key in ("duration", "dt", "max_step"):
        if key in out and out[key] <= 0:
            raise where.error(f"'{key}' must be > 0 seconds, got {out[key]!r}")
    for key in OFF_WHEN_INFINITE:
        if key in out and out[key] <= 0:
            raise where.error(f"'{key}' must be > 0 metres, got {out[key]!r}")
    if "initial_state" in out and out["initial_state"].shape[-1:] != (16,):
        raise where.error("'initial_state' must be 16 numbers (x, y, z, vx, ..., F4), or one such list per vehicle")
    if out.get("seed", 0) < 0:
        raise where.error(f"'seed' must be >= 0, got {out['seed']!r}")
    for key in ("log_every", "n"):
        if key in out and out[key] < 1:
            raise where.error(f"'{key}' must be >= 1, got {out[key]!r}")
    return out


__all__ = ["DISTURBANCE_KEYS", "OFF_WHEN_INFINITE", "SIMULATION_KEYS"]
