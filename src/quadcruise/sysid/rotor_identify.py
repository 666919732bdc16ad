"""``quadcruise.identify`` for a rotor-plant base vehicle: the stages of :func:`identify_rotor`.

Read the measured rotor speeds, fit the rigid body's equations and the motors'
(:mod:`quadcruise.sysid.rotor`), turn the coefficients into the vehicle's fields with 95 %
intervals, say what the log cannot identify, and predict the held-out tail. docs/identify.md,
"A rotor-plant vehicle", says why.
"""

from __future__ import annotations

import math
from typing import Any

import numpy as np

from quadcruise.errors import InputError
from quadcruise.model.rotor_vehicle import RotorVehicle
from quadcruise.sysid.equations import signals, smooth
from quadcruise.sysid.logprep import (
    MIN_EXCITATION,
    MIN_FIT_S,
    MIN_HELD_S,
    MIN_SIGNAL_SHARE,
    STAGES,
    WINDOW_S,
    command_hold,
    command_meaning,
    command_rate,
    coupling_signal,
    log_info,
    split_rows,
)
from quadcruise.sysid.physical import RELATIVE_HALF_WIDTH, Z95
from quadcruise.sysid.result import IdentifyResult
from quadcruise.sysid.rotor import (
    ROTOR_UNITS,
    command_speeds,
    fit_motors,
    fit_rigid_body,
    regressions,
    rigid_body_mapping,
)
from quadcruise.sysid.rotor import rigid_body_parameters as physical
from quadcruise.sysid.validate import scores
from quadcruise.sysid.verdict import rotor_verdict, withhold

MASS_FREE = ("tau_up", "tau_down", "w_max", "hover_speed", "hover_duty")
"""Parameters that do not scale with the mass."""
RPM_RESOLUTION = 0.5
"""Half the resolution of a logged rotor speed [rpm] (PX4's ``esc_rpm`` is an integer)."""
SPEED_SCALE_POWER = {"kf": 2, "km": 2, "k_d": 1, "k_z": 1, "J_rotor": 1, "hover_speed": 1}
"""How each parameter scales with an error in the speeds' scale (w measured (1 + e) w: kf as
(1 + e)^-2, ...): the resolution's systematic term, a uniform half-range of power x e."""
MIN_SPEED_SAMPLES = 10
"""The fewest logged rotor-speed samples per filter window (:data:`quadcruise.sysid.logprep.WINDOW_S`):
slower ESC telemetry (PX4's default profile logs ``esc_status`` at a few Hz) is interpolated
over the doublets, and the equations would fit a shape the rotors never had."""


def geometry(flight, base: RotorVehicle) -> tuple[np.ndarray, str]:
    """(n, 4) rotor x, y, z [m] (FLU) and direction s: the log's ``CA_ROTOR*`` (z from the base
    vehicle when it has as many rotors, else 0), or else the base vehicle's rotors."""
    base_rotors = np.asarray(base.rotors, dtype=float)
    if flight.rotors is not None:
        z = base_rotors[:, 2] if len(base_rotors) == flight.n_rotors else np.zeros(flight.n_rotors)
        return np.column_stack([flight.rotors[:, 0], flight.rotors[:, 1], z, flight.rotors[:, 2]]), "log (CA_ROTOR*)"
    if len(base_rotors) != flight.n_rotors:
        raise InputError(
            f"{flight.source}: {flight.n_rotors} rotor commands and no CA_ROTOR* geometry: the base vehicle "
            f"has {len(base_rotors)} rotors"
        )
    return base_rotors, "base vehicle"


def identify_rotor(flight, base: RotorVehicle, mass: float | None, holdout: float, kind: str, report) -> IdentifyResult:
    """Identify a rotor-plant vehicle (see :func:`quadcruise.identify`, which calls it)."""
    if flight.speeds is None:
        raise InputError(
            f"{flight.source}: the rotor plant is identified from measured rotor speeds, and this log has none "
            "(PX4 esc_status with esc_rpm, or a CSV's w1..wn)"
        )
    if flight.specific_force is None:
        raise InputError(f"{flight.source}: the rotor plant needs the accelerometer (sensor_combined, or ax, ay, az)")
    speed_hz = float(flight.rates_hz.get("esc_status", flight.rates_hz.get("csv", 0.0)))
    if speed_hz < MIN_SPEED_SAMPLES / WINDOW_S:
        raise InputError(
            f"{flight.source}: rotor speeds (esc_status) logged at {speed_hz:g} Hz, too slow for the rotor "
            f"plant's equations (at least {MIN_SPEED_SAMPLES / WINDOW_S:g} Hz: {MIN_SPEED_SAMPLES:g} samples "
            "per filter window); identify the paper plant from it (--vehicle paper)"
        )
    report(1, len(STAGES), STAGES[0])
    hubs, where = geometry(flight, base)
    n = flight.n_rotors
    g = float(base.g)
    m_known = float(mass) if mass is not None else float(base.m)
    dt = float(np.median(np.diff(flight.t)))
    window = max(5, round(WINDOW_S / dt) | 1)
    slow = max(base.tau_up, base.tau_down)
    fit_rows, held = split_rows(flight, window, 1.0 / slow, holdout)
    if fit_rows.sum() * dt < MIN_FIT_S or held.sum() * dt < MIN_HELD_S:
        raise InputError(
            f"{flight.source}: {flight.duration:.1f} s airborne is too short to fit and hold out {holdout:g} of it "
            f"(usable after the filter's edges: {fit_rows.sum() * dt:.2f} s to fit, {held.sum() * dt:.2f} s held out; "
            f"at least {MIN_FIT_S:g} s and {MIN_HELD_S:g} s)"
        )
    gyro = base.J_rotor > 0.0
    c_d = np.array([base.c_Dx, base.c_Dy, base.c_Dz])

    def rigid(k_d, k_z, win, speeds=flight.speeds, covariance=True):
        data = regressions(flight, speeds, hubs, win, dt, (k_d, k_z, base.k_h, base.k_flap, c_d, m_known), gyro)
        return data, fit_rigid_body(data, fit_rows, flight.segment, win, covariance)

    report(2, len(STAGES), STAGES[1])
    data, (names, values, cov, sigma, bandwidth, betas) = rigid(base.k_d, base.k_z, window)
    # the aerodynamic moments again at the identified drag where the log shows it
    aero = {"k_d": base.k_d, "k_z": base.k_z}
    idx = {nm: i for i, nm in enumerate(names)}
    for key, coef in (("k_d", "kd_m"), ("k_z", "kz_m")):
        value, se = -values[idx[coef]] * m_known, math.sqrt(cov[idx[coef], idx[coef]]) * m_known
        if np.isfinite(se) and value > 0 and Z95 * se <= RELATIVE_HALF_WIDTH * value:
            aero[key] = value
    if aero != {"k_d": base.k_d, "k_z": base.k_z}:
        data, (names, values, cov, sigma, bandwidth, betas) = rigid(aero["k_d"], aero["k_z"], window)
    report(3, len(STAGES), STAGES[2])

    force_z = flight.specific_force[:, 2]
    sig = signals(flight.t, flight.segment, np.zeros((len(flight.t), 1)), flight.rates, force_z, WINDOW_S)
    share = coupling_signal(flight, sig, fit_rows)
    coupling = (share["qr"] >= MIN_SIGNAL_SHARE, share["pr"] >= MIN_SIGNAL_SHARE)
    found, weights = physical(names, values, cov, mass, n, g, coupling=coupling)

    def refit(win, speeds):
        again = rigid(aero["k_d"], aero["k_z"], win, speeds, covariance=False)[1]
        with np.errstate(all="ignore"):  # an unexcited axis's coefficient may be 0: inf, said below
            return rigid_body_mapping(again[0], mass, n, g, weights)(again[1])

    others = [refit(max(5, round(WINDOW_S * factor / dt) | 1), flight.speeds) for factor in (0.5, 2.0)]
    shifted = []
    for sign in (-1.0, 1.0):  # when a speed was measured is known to half its logging interval
        moved = np.empty_like(flight.speeds)
        for k in np.unique(flight.segment):
            seg = flight.segment == k
            for j in range(n):
                moved[seg, j] = np.interp(flight.t[seg] - sign * 0.5 / speed_hz, flight.t[seg], flight.speeds[seg, j])
        shifted.append(refit(window, moved))
    spread = {}
    for key in found:
        vals = [found[key]["value"]] + [o[key] for o in others]
        with np.errstate(invalid="ignore"):  # inf - inf: an unexcited axis, not identifiable anyway
            timing = 0.5 * abs(shifted[1][key] - shifted[0][key])
        window_spread = 0.5 * (max(vals) - min(vals)) if np.all(np.isfinite(vals)) else np.inf
        spread[key] = float(np.hypot(timing, window_spread))
    # the speeds' resolution (integer rpm): a scale error of up to +-RPM_RESOLUTION / the hover speed
    scale = RPM_RESOLUTION * 2.0 * math.pi / 60.0 / float(np.median(flight.speeds[fit_rows]))
    for key in found:
        power = SPEED_SCALE_POWER.get(key.removesuffix("_per_m"), 0)
        spread[key] = float(np.hypot(spread[key], power * scale * abs(found[key]["value"])))
    found, _ = physical(names, values, cov, mass, n, g, systematic=spread, coupling=coupling)

    # motors
    cmd_hz = command_rate(flight)
    hold = command_hold(flight, cmd_hz)
    csv_speeds = flight.speed_commands
    # rad/s: u is the signal, the speed over w_max; else relative thrust (speed sqrt(u)) or the signal through f
    shape_f = 1.0 if kind == "rad/s" else command_meaning(flight)[1]
    commands = flight.u if csv_speeds else command_speeds(flight.u, shape_f)
    hover = float(np.median(flight.speeds[fit_rows]))
    motors = fit_motors(
        flight.t,
        flight.segment,
        fit_rows,
        flight.speeds,
        commands,
        scale0=1.0 if csv_speeds else float(base.w_max),
        fit_scale=not csv_speeds,
        tau0=float(base.tau_up),
        hover=hover,
    )
    grid_hz = 1.0 / dt
    motor_note = None
    if hold != "zero" and not csv_speeds:
        motor_note = (
            f"the commands are sampled ({cmd_hz:g} Hz, not every command the controller computed): a lag of a few "
            "ms cannot be told from when the commands changed (log with PX4's system-identification profile)"
        )
    elif speed_hz < 0.9 * grid_hz or speed_hz < 2.0 / min(base.tau_up, base.tau_down):
        motor_note = f"rotor speeds logged at {speed_hz:g} Hz: too slow to see the motors' lag"
    for key in ("tau_up", "tau_down", "w_max"):
        entry = motors.get(key)
        if entry is None:
            continue
        ok = np.isfinite(entry["se"]) and Z95 * entry["se"] <= RELATIVE_HALF_WIDTH * entry["value"]
        found[key] = {
            "value": entry["value"],
            "se": entry["se"],
            "ci95": [entry["value"] - Z95 * entry["se"], entry["value"] + Z95 * entry["se"]],
            "identifiable": bool(ok) and motor_note is None,
        }
    w_max = found["w_max"]["value"] if found.get("w_max", {}).get("identifiable") else float(base.w_max)
    h = found["hover_speed"]
    # the hover's relative thrust (speed over full speed, squared: PX4's actuator_motors and
    # hover_thrust_estimate), not the output signal THR_MDL_FAC makes of it
    duty = (h["value"] / w_max) ** 2
    found["hover_duty"] = {
        "value": duty,
        "se": 2.0 * h["se"] * duty / h["value"] if h["value"] else np.inf,
        "identifiable": h["identifiable"],
    }
    found["hover_duty"]["ci95"] = [duty - Z95 * found["hover_duty"]["se"], duty + Z95 * found["hover_duty"]["se"]]

    notes: dict[str, str] = {}
    suffix = "" if mass is not None else "_per_m"
    for direction in ("up", "down"):
        if f"tau_{direction}" not in found:
            notes[f"tau_{direction}"] = (
                f"the log never commands the rotors {direction} by more than 1 % of the hover speed for "
                f"more than a few samples ({motors['samples'][direction]}): only the other time constant is seen"
            )
        elif motor_note:
            notes[f"tau_{direction}"] = motor_note
    if motor_note and "w_max" in found:
        notes["w_max"] = motor_note
    if csv_speeds:
        notes["w_max"] = "the commands are rotor speeds (rad/s): the log does not show the speed of a full command"
    if not any(coupling):
        why = (
            "the gyroscopic terms that give Jzz (q r, p r) are mostly sensor noise here: signal "
            f"{100 * share['qr']:.0f} % and {100 * share['pr']:.0f} % of their variance"
        )
        for key in ("Jzz", "km", "J_rotor"):
            notes[key + suffix] = why
    excited = _excitation(flight.speeds[fit_rows], hubs)
    for key, axis in (("Jxx", "roll"), ("Jyy", "pitch"), ("km", "yaw")):
        if excited[axis] < MIN_EXCITATION:
            notes[key + suffix] = (
                f"no variation on the {axis} axis: the rotor speeds' combination varies by "
                f"{100 * excited[axis]:.2g} % of their mean"
            )
    table = _table(found, base, notes, mass)
    report(4, len(STAGES), STAGES[3])

    validation, traces = _validate(flight, data, betas, held, hubs, g, window, dt, motors, commands)

    def refit_half(rows):
        again = fit_rigid_body(data, rows, flight.segment, window)
        return physical(again[0], again[1], again[2], mass, n, g, coupling=coupling)[0]

    verdict = rotor_verdict(data, betas, fit_rows, held, flight.segment, window, refit_half)
    if not verdict["fits"]:
        table = withhold(table, verdict)
    report(5, len(STAGES), STAGES[4])
    log = log_info(flight, sig)
    log["rotor_geometry"] = where
    log["rotor_speeds_hz"] = speed_hz
    return IdentifyResult(
        verdict=verdict,
        parameters=table,
        validation=validation,
        traces=traces,
        log=log,
        fit={
            "plant": "rotor",
            "rows": int(fit_rows.sum()),
            "held_out_rows": int(held.sum()),
            "holdout": float(holdout),
            "window_samples": window,
            "window_s": window * dt,
            "excitation": excited,
            "signal_share": share,
            "cautions": [],
            "newey_west_bandwidth": bandwidth,
            "command_hold": hold,
            "thrust_model_factor": shape_f,
            "aerodynamic_moments_at": aero,
            "motor_samples": motors["samples"],
            "motor_rmse_rad_s": motors["rmse"],
            "residual_std": sigma,
            "coefficients": dict(zip(names, values.tolist(), strict=False)),
        },
        base=base,
        mass=mass,
        rotors=hubs,
    )


def _excitation(speeds: np.ndarray, hubs: np.ndarray) -> dict[str, float]:
    """Each moment's rotor-speed combination's standard deviation relative to the mean squared speed."""
    w2 = speeds**2
    mean = max(float(np.mean(w2)), 1e-12)
    arm = max(float(np.mean(np.hypot(hubs[:, 0], hubs[:, 1]))), 1e-12)
    return {
        "thrust": float(np.std(w2.sum(1))) / (len(hubs) * mean),
        "roll": float(np.std(w2 @ hubs[:, 1])) / (arm * mean),
        "pitch": float(np.std(w2 @ -hubs[:, 0])) / (arm * mean),
        "yaw": float(np.std(w2 @ hubs[:, 3])) / mean,
    }


def _table(found: dict, base: RotorVehicle, notes: dict, mass: float | None) -> dict[str, dict]:
    order = ["kf", "km", "Jxx", "Jyy", "Jzz", "tau_up", "tau_down", "k_d", "k_z", "J_rotor", "w_max"]
    order += ["hover_speed", "hover_duty"]
    out: dict[str, dict[str, Any]] = {}
    for field in order:
        name = field if mass is not None or field in MASS_FREE else f"{field}_per_m"
        if field == "J_rotor" and name not in found:
            continue
        entry = found.get(name)
        if field == "hover_speed":
            prior = base.hover_speed
        elif field == "hover_duty":
            prior = (base.hover_speed / base.w_max) ** 2
        else:
            prior = float(getattr(base, field)) / (float(base.m) if name.endswith("_per_m") else 1.0)
        unit = ROTOR_UNITS[field] + ("/kg" if name.endswith("_per_m") else "")
        row: dict[str, Any] = {"unit": unit}
        if entry is not None and entry["identifiable"] and name not in notes:
            row.update(value=entry["value"], ci95=entry["ci95"], identifiable=True, source="log")
        else:
            why = notes.get(name) or (entry or {}).get("inconsistent")
            if why is None and entry is not None:
                half = Z95 * entry["se"] / abs(entry["value"]) if entry["value"] else float("inf")
                why = (
                    f"the log does not excite it enough: estimate {entry['value']:.4g} with a 95 % half-width of "
                    f"{100 * half:.0f} %"
                    if np.isfinite(half)
                    else "no excitation"
                )
            row.update(value=prior, ci95=[None, None], identifiable=False, source="base vehicle", note=why or "")
            if entry is not None:
                row["estimate"] = entry["value"]
        out[name] = row
    return out


def _validate(flight, data, betas, held, hubs, g, window, dt, motors, commands) -> tuple[dict, dict]:
    """The held-out tail: linear accelerations (world), angular accelerations, rates open loop."""
    n_all = len(flight.t)
    pred = {c: data[c][1] @ betas[c] for c in data}
    body = np.column_stack([pred["drag"][:n_all], pred["drag"][n_all:], pred["thrust"]])
    accel = smooth(flight.velocity, flight.segment, window, deriv=1, dt=dt)
    world = flight.rotation().apply(np.nan_to_num(body)) - np.array([0.0, 0.0, g])
    ok = held & np.all(np.isfinite(body), axis=1)
    out: dict = {}
    traces: dict = {"t": flight.t[ok]}
    for j, name in enumerate(("ax", "ay", "az")):
        out[name] = {**scores(accel[ok, j], world[ok, j]), "unit": "m/s^2"}
        traces[name] = (accel[ok, j], world[ok, j])
    for name, c in (("p_dot", "roll"), ("q_dot", "pitch"), ("r_dot", "yaw")):
        out[name] = {**scores(data[c][0][ok], pred[c][ok]), "unit": "rad/s^2"}
        traces[name] = (data[c][0][ok], pred[c][ok])
    # rates open loop over short windows: the fitted equations integrated from the logged rates
    rates = smooth(flight.rates, flight.segment, window)
    steps = max(1, round(0.25 / dt))
    idx = np.flatnonzero(ok)
    starts = [
        i
        for i in idx[::steps]
        if i + steps < n_all and ok[i + steps] and flight.segment[i + steps] == flight.segment[i]
    ]
    effect = {c: pred[c] - data[c][1][:, 0] * betas[c][0] for c in ("roll", "pitch", "yaw")}
    k = (betas["roll"][0], betas["pitch"][0], betas["yaw"][0])
    ends, truth = [], []
    for i in starts:
        w = rates[i].copy()
        for s in range(i, i + steps):
            p, q, r = w
            w = w + dt * np.array(
                [k[0] * q * r + effect["roll"][s], k[1] * p * r + effect["pitch"][s], k[2] * p * q + effect["yaw"][s]]
            )
        ends.append(w)
        truth.append(rates[i + steps])
    ol: dict = {"window_s": steps * dt, "windows": len(starts)}
    if starts:
        for j, name in enumerate("pqr"):
            ol[name] = {**scores(np.array(truth)[:, j], np.array(ends)[:, j]), "unit": "rad/s"}
    out["open_loop"] = ol
    return out, traces
