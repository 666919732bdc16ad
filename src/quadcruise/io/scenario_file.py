"""A run's recorded configuration (the ``meta`` of a result) as a scenario file that
``quadcruise fly`` reads back (:func:`quadcruise.workflows.scenario.load_scenario`).

The configuration is plain data already: the vehicle, controller, mission, environment and
sensors as their ``to_dict()``, and the simulation settings. This module only reshapes it into
the scenario's tables and writes TOML (with ``tomli_w``): floats are written so that they read
back to the same bits, so the file flies the same numbers. TOML has no null: an absent value is
left out, and a missing entry of a waypoint column is written as ``nan``.
"""

from __future__ import annotations

import math
from typing import Any

__all__ = ["comparison_document", "montecarlo_document", "scenario_document", "scenario_text"]

SPEC_KEYS = (
    "requirements",
    "max_track_error_m",
    "max_altitude_error_m",
    "settle_band",
    "max_clipped_s",
    "transient_until",
    "log_dt",
    "trace_dt",
    "max_traces",
    "max_failure_traces",
)
"""The Monte Carlo spec's settings a scenario's [montecarlo] table holds beside n, seed and the
population's spreads."""

SIMULATION_FROM_META = {
    "duration_s": "duration",
    "dt_s": "dt",
    "max_step_s": "max_step",
    "full_dynamics": "full_dynamics",
    "seed": "seed",
    "log_every": "log_every",
    "max_track_error": "max_track_error",
    "max_steady_error": "max_steady_error",
    "max_altitude_error": "max_altitude_error",
    "initial_state": "initial_state",
}
"""Keys of a flight's meta and the [simulation] keys they become."""


def _plain(value: Any) -> Any:
    """A value TOML can hold: None dropped from tables, NaN kept in lists, tuples as lists."""
    if isinstance(value, dict):
        return {k: _plain(v) for k, v in value.items() if v is not None}
    if isinstance(value, (list, tuple)):
        return [math.nan if v is None else _plain(v) for v in value]
    if hasattr(value, "tolist"):
        return _plain(value.tolist())
    return value


def _part(d: dict | None) -> dict | None:
    """A disturbance part's dict without its ``model`` tag (the table's key names the part)."""
    if d is None:
        return None
    return {k: v for k, v in d.items() if k != "model"}


def scenario_document(meta: dict, *, title: str = "") -> dict:
    """The scenario tables of a flight's recorded configuration.

    Examples
    --------
    >>> doc = scenario_document({"mission": {"kind": "step", "size": 0.5}, "controller": {"name": "nlpd"},
    ...                          "vehicle": {"m": 1.4}, "duration_s": 8.0, "seed": 0})
    >>> doc["mission"], doc["simulation"]
    ({'kind': 'step', 'size': 0.5}, {'duration': 8.0, 'seed': 0})
    """
    doc: dict[str, Any] = {}
    if title or meta.get("title"):
        doc["title"] = title or meta["title"]
    for table in ("vehicle", "controller", "mission", "controller_vehicle"):
        if meta.get(table) is not None:
            doc[table] = dict(meta[table])
    disturbances = {}
    env = meta.get("environment") or {}
    if "custom" in env:
        raise ValueError("a compiled disturbance of one's own (CustomDisturbance) cannot be written to a scenario")
    for key in ("wind", "gust", "turbulence", "rotor_loss", "force"):
        if env.get(key) is not None:
            disturbances[key] = _part(env[key])
    if meta.get("sensors") is not None:
        disturbances["sensor_noise"] = _part(meta["sensors"])
    if disturbances:
        doc["disturbances"] = disturbances
    if meta.get("sensor_models"):  # the sensor models and the filter of a flight on an estimate
        doc["sensors"] = {name: dict(fields) for name, fields in meta["sensor_models"].items()}
        doc["estimator"] = dict(meta.get("estimator") or {"kind": "none"})
    simulation = {key: meta[k] for k, key in SIMULATION_FROM_META.items() if meta.get(k) is not None}
    if meta.get("log_every_chosen"):  # fly chose it (a batch's log within budget): it chooses it again,
        simulation.pop("log_every", None)
    if meta.get("n", 1) != 1 and not any(isinstance(v, list) for v in (meta.get("vehicle") or {}).values()):
        simulation["n"] = meta["n"]
    if simulation:
        doc["simulation"] = simulation
    return _plain(doc)


def montecarlo_document(spec: dict, n: int, *, title: str = "") -> dict:
    """The scenario tables of a Monte Carlo sweep: what ``quadcruise montecarlo --scenario`` reads."""
    population = spec["population"]
    meta = {
        "mission": spec["mission"],
        "controller": spec["controller"],
        "vehicle": spec["vehicle"],
        "controller_vehicle": spec.get("controller_vehicle"),
        "environment": population.get("environment"),
        "sensors": population.get("noise"),
        "sensor_models": population.get("sensors"),
        "estimator": population.get("estimator"),
        "duration_s": spec.get("duration"),
        "dt_s": spec.get("dt"),
        "max_step_s": spec.get("max_step"),
        "full_dynamics": spec.get("full_dynamics"),
    }
    doc = scenario_document(meta, title=title)
    table = {"n": int(n), "seed": spec["seed"]}
    table.update({k: v for k, v in population.items() if k not in ("environment", "noise", "sensors", "estimator")})
    table.update({k: spec[k] for k in SPEC_KEYS if spec.get(k) is not None})
    doc["montecarlo"] = _plain(table)
    return doc


def comparison_document(meta: dict, controllers: dict, *, title: str = "") -> dict:
    """The scenario tables of a comparison: what ``quadcruise compare`` reads."""
    doc = scenario_document({k: v for k, v in meta.items() if k != "controller"}, title=title)
    doc["compare"] = {"controllers": [_plain({"label": label, **record}) for label, record in controllers.items()]}
    return doc


def ulog_note(meta: dict, command: str) -> str:
    """The scenario header's line naming the PX4 logs a run wrote (``meta["ulog"]``), or "".

    Examples
    --------
    >>> print(ulog_note({"ulog": {"path": "f.ulg", "files": ["f.ulg"]}}, "fly").strip())
    written as PX4 logs too (f.ulg): `quadcruise fly THIS_FILE --ulog f.ulg` writes the same bytes again
    >>> ulog_note({}, "fly")
    ''
    """
    logs = meta.get("ulog")
    if not logs:
        return ""
    return (
        f"\nwritten as PX4 logs too ({', '.join(logs['files'])}): "
        f"`quadcruise {command} THIS_FILE --ulog {logs['path']}` writes the same bytes again"
    )


def scenario_text(doc: dict, *, header: str = "") -> str:
    """The scenario tables as TOML text.

    Examples
    --------
    >>> print(scenario_text({"mission": {"kind": "circle", "radius": 3.0}}, header="flown by hand"))
    # flown by hand
    <BLANKLINE>
    [mission]
    kind = "circle"
    radius = 3.0
    <BLANKLINE>
    """
    import tomli_w

    lines = "".join(f"# {line}\n" for line in header.splitlines())
    return (lines + "\n" if lines else "") + tomli_w.dumps(_plain(doc))
