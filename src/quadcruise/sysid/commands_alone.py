"""A rotor-plant vehicle identified from its commands alone: a log without ESC telemetry.

Most PX4 vehicles log no rotor speeds. Their ``actuator_motors`` is each rotor's relative thrust
(thrust over its thrust at full command), so the paper plant's equations, with the log's own rotor
geometry, identify what such a log determines (:func:`quadcruise.sysid.api.identify`): ``K``, one
rotor's thrust at full command; the inertias from the rate derivatives; ``d``, the yaw moment per
thrust; ``omega``, the thrust's lag (where the commands excite it). :func:`rotor_table` turns them
into the rotor plant's fields:

- ``kf = K / w_max^2``: the log shows the thrust of a full command, not the speed it takes, so
  ``w_max`` is the base vehicle's, and ``kf`` is known up to that scale (said in the table);
- ``km = d kf``;
- ``tau_up = tau_down = 1 / omega`` (thrust ``kf w^2`` linearised about hover lags a speed step by
  the motor's time constant; the two directions are not told apart without the speeds);
- the rest (rotor inertia, rotor drag, ...) the base vehicle's, not identified.

Intervals carry over exactly for ``kf`` (a scale of ``K``) and ``tau`` (a monotone map of
``omega``); ``km``'s combines ``d``'s and ``K``'s relative half-widths in quadrature.
"""

from __future__ import annotations

import dataclasses
import math

ROTOR_UNITS = {
    "kf": "N/(rad/s)^2",
    "km": "N m/(rad/s)^2",
    "tau_up": "s",
    "tau_down": "s",
    "w_max": "rad/s",
}
"""Units of the rotor plant's fields this module adds."""


def rotor_table(parameters: dict, base, mass_given: bool) -> dict:
    """The paper plant's identified ``parameters`` as the rotor plant's fields.

    Parameters
    ----------
    parameters : dict
        :func:`quadcruise.identify`'s table of the paper plant (``K`` or ``K_per_m``, ``d``,
        ``omega``, the inertias, ``hover_duty``, ``thrust_curve_f``).
    base : RotorVehicle
        The base rotor-plant vehicle: ``w_max``, and the values of what is not identified.
    mass_given : bool
        Whether the table is in absolute units (else per unit mass).

    Returns
    -------
    dict
        Name -> row, the rotor plant's (``kf``, ``km``, ``Jxx``, ..., ``tau_up``, ``tau_down``,
        ``w_max``, ``hover_duty``) with ``K`` and ``d`` kept as what the log determines.

    Examples
    --------
    >>> from quadcruise.model.rotor_vehicle import RotorVehicle
    >>> row = lambda v, lo, hi: {"value": v, "ci95": [lo, hi], "identifiable": True, "unit": "-", "source": "log"}
    >>> table = rotor_table({"K": row(7.0, 6.9, 7.1), "d": row(0.06, 0.059, 0.061), "omega": row(40.0, 39.0, 41.0)},
    ...                     RotorVehicle.preset("iris"), True)
    >>> round(table["kf"]["value"] * 1100.0**2, 6), table["tau_up"]["ci95"] == [1 / 41.0, 1 / 39.0]
    (7.0, True)
    """
    suffix = "" if mass_given else "_per_m"
    scale = 1.0 if mass_given else float(base.m)
    w2 = float(base.w_max) ** 2
    out = {}
    k_row = parameters[f"K{suffix}"]
    d_row = parameters["d"]
    omega_row = parameters["omega"]
    out[f"kf{suffix}"] = _scaled(k_row, 1.0 / w2, ROTOR_UNITS["kf"] + ("/kg" if suffix else ""))
    if not _from_log(k_row):
        out[f"kf{suffix}"]["value"] = float(base.kf) / scale
    km = dict(out[f"kf{suffix}"], unit=ROTOR_UNITS["km"] + ("/kg" if suffix else ""))
    km["value"] = out[f"kf{suffix}"]["value"] * d_row["value"]
    if k_row["identifiable"] and d_row["identifiable"]:
        rel = math.hypot(_half(k_row), _half(d_row))
        km["ci95"] = [km["value"] * (1.0 - rel), km["value"] * (1.0 + rel)]
    elif _from_log(k_row) and _from_log(d_row):  # a model that does not fit: the best fit, no interval
        km.update(identifiable=False, ci95=[None, None], note=d_row.get("note") or k_row.get("note"))
        km["estimate"] = km["value"]
    else:
        km.update(identifiable=False, ci95=[None, None], value=float(base.km) / scale, source="base vehicle")
        km["note"] = d_row.get("note") or k_row.get("note") or "not identified"
        km.pop("estimate", None)
    out[f"km{suffix}"] = km
    for name in ("Jxx", "Jyy", "Jzz"):
        out[f"{name}{suffix}"] = dict(parameters[f"{name}{suffix}"])
        if not _from_log(out[f"{name}{suffix}"]):
            out[f"{name}{suffix}"]["value"] = float(getattr(base, name)) / scale
    for name in ("tau_up", "tau_down"):
        row = dict(omega_row, unit="s")
        row["value"] = 1.0 / omega_row["value"]
        if "estimate" in omega_row:
            row["estimate"] = 1.0 / omega_row["estimate"]
        if omega_row["identifiable"]:
            lo, hi = omega_row["ci95"]
            row["ci95"] = [1.0 / hi, 1.0 / lo]
        elif not _from_log(omega_row):
            row["value"] = float(getattr(base, name))
            row["source"] = "base vehicle"
        out[name] = row
    out["w_max"] = {
        "value": float(base.w_max),
        "unit": "rad/s",
        "ci95": [None, None],
        "identifiable": False,
        "source": "base vehicle",
        "note": "no rotor speeds in the log: it determines the thrust at full command (kf w_max^2), "
        "not the speed; kf is given at the base vehicle's w_max",
    }
    for name in (f"K{suffix}", "d", "hover_duty", "thrust_curve_f"):
        if name in parameters:
            out[name] = dict(parameters[name])
    return out


def _scaled(row: dict, factor: float, unit: str) -> dict:
    out = dict(row, unit=unit)
    out["value"] = row["value"] * factor
    if row.get("ci95") and row["ci95"][0] is not None:
        out["ci95"] = [row["ci95"][0] * factor, row["ci95"][1] * factor]
    if "estimate" in row:
        out["estimate"] = row["estimate"] * factor
    return out


def _from_log(row: dict) -> bool:
    """Whether a row's value is the log's (identified, or the best fit of a model that does not fit)."""
    return bool(row["identifiable"]) or str(row.get("source", "")).startswith("log")


def _half(row: dict) -> float:
    lo, hi = row["ci95"]
    return 0.5 * (hi - lo) / abs(row["value"]) if row["value"] else math.inf


def as_rotor_result(result, base):
    """The paper plant's :class:`~quadcruise.sysid.result.IdentifyResult` as the rotor plant's
    (:func:`rotor_table`; the vehicle written is ``base`` with the identified fields and the log's
    rotors).

    Parameters
    ----------
    result : IdentifyResult
        :func:`quadcruise.identify`'s on the paper plant, with the log's geometry.
    base : RotorVehicle
        The rotor-plant base vehicle.

    Returns
    -------
    IdentifyResult
    """
    import numpy as np

    table = rotor_table(result.parameters, base, result.mass is not None)
    z = {len(base.rotors): np.asarray(base.rotors, dtype=float)[:, 2]}.get(len(result.rotors))
    hubs = np.column_stack(
        [
            result.rotors[:, 0],
            result.rotors[:, 1],
            z if z is not None else np.zeros(len(result.rotors)),
            result.rotors[:, 2],
        ]
    )
    fit = dict(result.fit, plant="rotor", rotor_speeds="none: identified from the commands alone")
    log = dict(result.log, rotor_speeds_hz=None)
    return dataclasses.replace(result, parameters=table, fit=fit, log=log, base=base, rotors=hubs)
