"""``quadcruise.identify``: a flight log in, the vehicle's parameters out, checked on held-out data.

The path (each stage reported to ``progress``): read the log (:mod:`quadcruise.io.flightlog`),
filter it (:func:`quadcruise.sysid.equations.signals`), fit the equation-error regressions on
the first ``1 - holdout`` of the airborne time (:func:`quadcruise.sysid.estimate.fit`), turn
the coefficients into the vehicle's parameters with 95 % intervals
(:func:`quadcruise.sysid.physical.parameters`), and predict the held-out tail
(:func:`quadcruise.sysid.validate.validate`). docs/identify.md says why this estimator.
"""

from __future__ import annotations

import math
import os
from collections.abc import Callable
from typing import Any

import numpy as np

from quadcruise import checks
from quadcruise.errors import InputError
from quadcruise.io.flightlog import FlightLog, parse_commands, read_flight_log
from quadcruise.model.vehicle import Vehicle
from quadcruise.sim import plants
from quadcruise.sysid.basis import BASES
from quadcruise.sysid.equations import signals
from quadcruise.sysid.estimate import fit
from quadcruise.sysid.logprep import (
    CAUTION_SHARE,
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
    log_rates,
    noise_level,
    split_rows,
)
from quadcruise.sysid.physical import Z95, parameters
from quadcruise.sysid.result import IdentifyResult
from quadcruise.sysid.validate import validate
from quadcruise.sysid.verdict import paper_verdict, withhold

SHAPE_SPAN = 0.25
"""The least spread (5th to 95th percentile) of the rotor commands over which the thrust
curve's shape f is fitted; over a narrower span u and u^2 cannot be told apart."""
UNITS = {
    "K": "N",
    "Jxx": "kg m^2",
    "Jyy": "kg m^2",
    "Jzz": "kg m^2",
    "d": "m",
    "omega": "rad/s",
    "hover_duty": "-",
    "thrust_curve_f": "-",
    "K_per_m": "N/kg",
    "Jxx_per_m": "m^2",
    "Jyy_per_m": "m^2",
    "Jzz_per_m": "m^2",
}
"""Each parameter's unit."""


def identify(
    log: str | os.PathLike | FlightLog,
    vehicle: Vehicle | None = None,
    *,
    mass: float | None = None,
    frame: str | None = None,
    commands: str = "duty",
    holdout: float = 0.3,
    progress: Callable[[int, int], None] | None = None,
) -> IdentifyResult:
    """Identify the paper's plant from a flight log by equation error; validate on a held-out tail.

    Parameters
    ----------
    log : str, os.PathLike or FlightLog
        A PX4 log (``.ulg``), a CSV (see :mod:`quadcruise.io.flightlog`), or a log already read.
    vehicle : Vehicle, RotorVehicle or str, optional
        The base vehicle (the paper's Table I by default; a preset's name): the rotor arm when the
        log has no ``CA_ROTOR*`` geometry, gravity, the starting rotor bandwidth, and the values
        reported for what the log cannot identify. A rotor-plant vehicle (``"iris"``,
        ``"crazyflie"``, ...) identifies the rotor plant (kf, km, J, tau_up, tau_down, k_d, ...)
        from a log with measured rotor speeds (:mod:`quadcruise.sysid.rotor_identify`).
    mass : float, optional
        The vehicle's mass [kg]. Without it, K and the inertias are identified per unit mass
        (``K_per_m``, ``Jxx_per_m``, ...), and the result says so.
    frame : {"enu", "ned"}, optional
        A CSV's frames (ENU/FLU by default); a ULog is always PX4's NED/FRD.
    commands : str
        ``duty``, ``rad/s`` (rotor plant only) or ``pwm:MIN:MAX`` (see
        :func:`quadcruise.io.flightlog.read_flight_log`).
    holdout : float
        The fraction of the airborne time, at its end, kept out of the fit and predicted.
    progress : callable, optional
        ``progress(done, total, stage)`` after each of :data:`STAGES`.

    Returns
    -------
    IdentifyResult

    Raises
    ------
    InputError
        A bad argument or log (one line, before any work), or a log too short to fit.

    Examples
    --------
    >>> identify("flight.ulg", holdout=1.5)
    Traceback (most recent call last):
        ...
    quadcruise.errors.InputError: holdout must be a fraction in [0.05, 0.6], got float 1.5
    """
    where = "identify()"
    checks.instance(where, "log", log, (str, os.PathLike, FlightLog), optional=False, want="a path or a FlightLog")
    checks.instance(where, "frame", frame, str, want="'enu' or 'ned'")
    checks.instance(where, "commands", commands, str, optional=False, want="'duty', 'rad/s' or 'pwm:MIN:MAX'")
    checks.callback(where, "progress", progress)  # before the log is read
    if isinstance(holdout, bool) or not isinstance(holdout, (int, float)) or not 0.05 <= holdout <= 0.6:
        raise InputError(f"holdout must be a fraction in [0.05, 0.6], got {checks.describe(holdout)}")
    if mass is not None and (
        isinstance(mass, bool) or not isinstance(mass, (int, float)) or not math.isfinite(mass) or mass <= 0
    ):
        raise InputError(f"mass must be a positive number of kg, got {checks.describe(mass)}")
    from quadcruise.model.rotor_vehicle import RotorVehicle

    if isinstance(vehicle, str):
        vehicle = Vehicle.preset(vehicle)
    if vehicle is not None and not isinstance(vehicle, (Vehicle, RotorVehicle)):
        raise InputError(f"vehicle must be a quadcruise Vehicle or RotorVehicle, got {type(vehicle).__name__}")
    base = vehicle or Vehicle.paper()
    plant = plants.of(base)
    if plant.count(base) is not None:
        raise InputError("vehicle: the base vehicle must be one vehicle, not a batch")
    kind = parse_commands(commands)[0]
    if kind == "rad/s" and not plant.takes_speeds:
        raise InputError(
            "commands 'rad/s' are rotor speeds, which only the rotor plant has: give a rotor-plant base "
            "vehicle (vehicle='iris', 'crazyflie' or a vehicle file with plant = \"rotor\")"
        )
    report = progress or (lambda done, total, stage="": None)

    flight = log if isinstance(log, FlightLog) else read_flight_log(log, frame=frame, commands=commands)
    done, basis = BASES[plant.name](flight, base, mass, holdout, kind, report)  # sysid/basis.py
    if done is not None:  # the base's plant identified on its own (the rotor plant, with rotor speeds)
        return done
    base = basis.vehicle
    report(1, len(STAGES), STAGES[0])
    rotors = flight.rotors if flight.rotors is not None else basis.geometry(flight)
    g = float(base.g)
    flight, lag_of = basis.commands(flight), basis.lag_of
    force_z = _specific_force_z(flight, g)
    cmd_hz = command_rate(flight)
    hold = command_hold(flight, cmd_hz)
    sig = signals(flight.t, flight.segment, flight.u, flight.rates, force_z, WINDOW_S, hold, lag_of)
    report(2, len(STAGES), STAGES[1])

    omega0 = float(base.omega)
    fit_rows, held = split_rows(flight, sig.window, omega0, holdout)
    if fit_rows.sum() * sig.dt < MIN_FIT_S or held.sum() * sig.dt < MIN_HELD_S:
        raise InputError(
            f"{flight.source}: {flight.duration:.1f} s airborne is too short to fit and hold out {holdout:g} of it "
            f"(usable after the filter's edges: {fit_rows.sum() * sig.dt:.2f} s to fit, "
            f"{held.sum() * sig.dt:.2f} s held out; "
            f"at least {MIN_FIT_S:g} s and {MIN_HELD_S:g} s)"
        )
    lag_seen = cmd_hz >= 2.0 * omega0  # a sample at least every tau/2
    u_fit = sig.u[fit_rows]
    span = float(np.percentile(u_fit, 95) - np.percentile(u_fit, 5))
    meaning, f0 = command_meaning(flight)
    fit_shape = span >= SHAPE_SPAN and meaning == "signal"
    bounds = (0.5, min(500.0, 0.5 / sig.dt))
    result = fit(sig, fit_rows, rotors, omega0, f0, fit_omega=lag_seen, fit_shape=fit_shape, omega_bounds=bounds)
    report(3, len(STAGES), STAGES[2])

    signal_share = coupling_signal(flight, sig, fit_rows)
    signal_share.update(_command_signal(sig, fit_rows, rotors, result.omega))
    coupling = (signal_share["qr"] >= MIN_SIGNAL_SHARE, signal_share["pr"] >= MIN_SIGNAL_SHARE)
    found = parameters(
        result,
        mass,
        flight.n_rotors,
        g,
        covariance=(joint := {}),
        systematic=_sensitivity(
            flight, force_z, fit_rows, rotors, result, mass, g, cmd_hz, bounds, coupling, hold, lag_of
        ),
        coupling=coupling,
    )
    notes: dict[str, str] = {}
    cautions = []
    jittery = [a for a in ("roll", "pitch", "yaw") if signal_share[a] < CAUTION_SHARE]
    if jittery:
        cautions.append(
            "the "
            + ", ".join(f"{a} ({100 * (1 - signal_share[a]):.1f} %)" for a in jittery)
            + " commands carry sample-to-sample jitter: commands that change faster than they are "
            "logged bias Jzz and d low (errors in variables) beyond their intervals; see docs/identify.md"
        )
    jitter_axes = {"roll": ("Jxx",), "pitch": ("Jyy",), "yaw": ("d",)}
    for axis, names in jitter_axes.items():
        if signal_share[axis] < MIN_SIGNAL_SHARE:
            for name in names:
                key = name if mass is not None or name == "d" else f"{name}_per_m"
                notes[key] = (
                    f"the {axis} commands are {100 * (1 - signal_share[axis]):.0f} % sample-to-sample "
                    "jitter (commands logged slower than they change): their effect is underestimated"
                )
    jzz_key = "Jzz" if mass is not None else "Jzz_per_m"
    if signal_share["roll"] < MIN_SIGNAL_SHARE or signal_share["pitch"] < MIN_SIGNAL_SHARE:
        coupling = (False, False)
        notes[jzz_key] = notes["d"] = (
            "Jzz and d come through the roll and pitch equations, whose commands are "
            "jitter-dominated here (see Jxx, Jyy)"
        )
    elif not any(coupling):
        why = (
            "the gyroscopic terms that separate Jzz from d (q r, p r) are too noisy here: signal "
            f"{100 * signal_share['qr']:.0f} % and {100 * signal_share['pr']:.0f} % of their variance, under "
            f"{100 * MIN_SIGNAL_SHARE:.0f} % (roll or pitch while yawing to see them)"
        )
        notes[jzz_key] = why
        notes["d"] = why
    excited = _excitation(sig.u[fit_rows], rotors)
    needs = {
        "Jxx": ("roll",),
        "Jyy": ("pitch",),
        "Jzz": ("roll", "pitch"),
        "d": ("roll", "pitch", "yaw"),
        "omega": ("thrust", "roll", "pitch", "yaw"),
    }
    for name, axes in needs.items():
        key = name if name in found or name == "omega" else f"{name}_per_m"
        flat = [a for a in axes if excited[a] < MIN_EXCITATION]
        if (name == "omega" and len(flat) == len(axes)) or (name != "omega" and flat):
            notes[key] = (
                "no variation on the "
                + " and ".join(flat)
                + " axis: the commands there vary by "
                + ", ".join(f"{100 * excited[a]:.2g} %" for a in flat)
                + " of their mean"
            )
    if not lag_seen:
        notes["omega"] = (
            f"commands logged at {cmd_hz:g} Hz: too slow to see a rotor lag of {1 / omega0:.3g} s "
            "(a sample every half time constant at least)"
        )
    elif result.omega <= bounds[0] * 1.01 or result.omega >= bounds[1] * 0.99:
        found["omega"]["identifiable"] = False
        notes["omega"] = f"the fit ran to the end of its search interval {bounds[0]:g}..{bounds[1]:g} rad/s"
    if meaning == "thrust" and "actuator_outputs" in flight.commands:
        notes["thrust_curve_f"] = (
            "the commands are PX4's PWM (actuator_outputs) read back to relative thrust through the log's "
            "THR_MDL_FAC: thrust is linear in that"
        )
    elif meaning == "thrust":
        notes["thrust_curve_f"] = (
            "the commands are PX4's relative thrust (actuator_motors; THR_MDL_FAC maps thrust to the "
            "output signal after it): thrust is linear in them"
        )
    elif not fit_shape:
        notes["thrust_curve_f"] = (
            f"the commands span only {span:.2f} (5th to 95th percentile): the thrust curve's "
            f"shape is not seen; f fixed at {f0:g} (the log's THR_MDL_FAC, else 0)"
        )
    f0_source = "the log's THR_MDL_FAC" if "THR_MDL_FAC" in flight.parameters else "linear thrust, f = 0"
    f0_source = "relative thrust: linear" if meaning == "thrust" else f0_source
    table = _table(found, base, notes, f0, f0_source)
    report(4, len(STAGES), STAGES[3])

    validation, traces = validate(sig, held, result, rotors, flight, g)
    # a log whose command changes identify nothing (a hover) is judged on its commands' level
    changes = [k for k in table if k.removesuffix("_per_m") in ("Jxx", "Jyy", "Jzz", "d", "omega")]
    level = None
    if not any(table[k]["identifiable"] for k in changes):
        level = float(np.max(np.std(u_fit, axis=0) / np.maximum(np.abs(np.mean(u_fit, axis=0)), 1e-12)))
    verdict = paper_verdict(flight, sig, fit_rows, held, rotors, result, mass, g, cmd_hz, log_rates(flight), level)
    if not verdict["fits"]:
        table = withhold(table, verdict)
    # the joint covariance of what is reported with an interval (montecarlo --population draws from it)
    listed = [n for n in joint.get("names", []) if n in table and table[n]["identifiable"]]
    if listed and basis.covariance:
        pick = [joint["names"].index(n) for n in listed]
        full = np.asarray(joint["matrix"])
        joint = {"names": listed, "matrix": full[np.ix_(pick, pick)].tolist()}
    else:
        joint = None
    report(5, len(STAGES), STAGES[4])
    result = IdentifyResult(
        verdict=verdict,
        parameters=table,
        validation=validation,
        traces=traces,
        log=log_info(flight, sig),
        fit={
            "rows": result.rows,
            "held_out_rows": int(held.sum()),
            "holdout": float(holdout),
            "window_samples": sig.window,
            "window_s": sig.window * sig.dt,
            "excitation": excited,
            "signal_share": signal_share,
            "cautions": cautions,
            "newey_west_bandwidth": result.bandwidth,
            "omega_fitted": result.omega_fitted,
            "omega_used": result.omega,
            "command_hold": hold,
            "thrust_curve_fitted": fit_shape,
            "commands_are": "relative thrust" if meaning == "thrust" else f"signal (thrust curve f = {f0:g})",
            "residual_std": result.sigma,
            "coefficients": dict(zip(result.names, result.values.tolist(), strict=False)),
            "covariance": joint,
        },
        base=base,
        mass=mass,
        rotors=rotors,
    )
    return basis.finish(result)


def _excitation(u: np.ndarray, rotors: np.ndarray) -> dict[str, float]:
    """How much the commands move each axis: the standard deviation of the thrust command and
    of each moment's command combination, relative to the mean rotor command (times the arm)."""
    mean = max(float(np.mean(u)), 1e-12)
    arm = max(float(np.mean(np.hypot(rotors[:, 0], rotors[:, 1]))), 1e-12)
    return {
        "thrust": float(np.std(u.sum(1))) / (u.shape[1] * mean),
        "roll": float(np.std(u @ rotors[:, 1])) / (arm * mean),
        "pitch": float(np.std(u @ -rotors[:, 0])) / (arm * mean),
        "yaw": float(np.std(u @ rotors[:, 2])) / mean,
    }


def _command_signal(sig, rows: np.ndarray, rotors: np.ndarray, omega: float) -> dict[str, float]:
    """The share of each moment regressor's filtered variance that is not sample-to-sample jitter
    of the logged commands (a command changing faster than it is logged is sampled, not seen:
    that part of the regressor is noise, and biases its coefficient toward zero)."""
    from quadcruise.sysid.equations import lagged, smooth

    n = sig.window + int(np.ceil(8.0 / (omega * sig.dt)))
    impulse = np.zeros((2 * n, 1))
    impulse[n // 2, 0] = 1.0
    seg = np.zeros(2 * n, int)
    response = smooth(
        lagged(impulse, seg, omega, sig.dt, sig.hold) - lagged(np.zeros_like(impulse), seg, omega, sig.dt, sig.hold),
        seg,
        sig.window,
    )
    gain = float(np.nansum(response**2))
    combos = {"roll": rotors[:, 1], "pitch": -rotors[:, 0], "yaw": rotors[:, 2]}
    out = {}
    for axis, weights in combos.items():
        command = sig.u @ weights
        noise_var = gain * noise_level(command, sig.segment) ** 2
        lag = lagged(command[:, None], sig.segment, omega, sig.dt, sig.hold)
        regressor = smooth(lag, sig.segment, sig.window)[rows, 0]
        total = float(np.var(regressor))
        out[axis] = max(0.0, 1.0 - noise_var / total) if total > 0 else 0.0
    return out


def _sensitivity(
    flight,
    force_z,
    rows,
    rotors,
    result,
    mass,
    g,
    cmd_hz,
    bounds,
    coupling=(True, True),
    hold="linear",
    lag_of="thrust",
) -> dict[str, float]:
    """Systematic half-ranges: each parameter refitted (1) with the commands shifted by half
    their logging interval either way (a log that samples its commands says when they changed
    to that much) and (2) with the filter window halved and doubled (the model holds at every
    time scale, or the estimate moves: commands that change faster than they are logged, unmodelled
    dynamics). The two half-ranges are combined in quadrature."""

    def refit(u, window_s):
        sig = signals(flight.t, flight.segment, u, flight.rates, force_z, window_s, hold, lag_of)
        again = fit(
            sig,
            rows,
            rotors,
            result.omega,
            result.shape_f,
            fit_omega=result.omega_fitted,
            fit_shape="KQ" in result.names,
            omega_bounds=bounds,
        )
        return {k: v["value"] for k, v in parameters(again, mass, flight.n_rotors, g, coupling=coupling).items()}

    shift = 0.5 / cmd_hz
    shifted = []
    for sign in (-1.0, 1.0):
        moved = np.empty_like(flight.u)
        for k in np.unique(flight.segment):
            seg = flight.segment == k
            for j in range(flight.u.shape[1]):
                moved[seg, j] = np.interp(flight.t[seg] - sign * shift, flight.t[seg], flight.u[seg, j])
        shifted.append(refit(moved, WINDOW_S))
    windows = [refit(flight.u, WINDOW_S * factor) for factor in (0.5, 2.0)]
    out = {}
    for k in shifted[0]:
        timing = 0.5 * abs(shifted[1][k] - shifted[0][k])
        spread = [w[k] for w in windows] + [float(np.mean([x[k] for x in shifted]))]
        window = 0.5 * (max(spread) - min(spread)) if np.all(np.isfinite(spread)) else np.inf
        out[k] = float(np.hypot(timing, window))
    return out


def _specific_force_z(flight: FlightLog, g: float) -> np.ndarray:
    if flight.specific_force is not None:
        return flight.specific_force[:, 2]
    accel = np.zeros_like(flight.velocity)
    for k in np.unique(flight.segment):
        rows = flight.segment == k
        accel[rows] = np.gradient(flight.velocity[rows], flight.t[rows], axis=0)
    body = flight.rotation().inv().apply(accel + np.array([0.0, 0.0, g]))
    return body[:, 2]


def _table(found: dict, base: Vehicle, notes: dict, f0: float, f0_source: str) -> dict[str, dict]:
    prior = {
        "K": base.K,
        "Jxx": base.Jxx,
        "Jyy": base.Jyy,
        "Jzz": base.Jzz,
        "d": base.d,
        "omega": base.omega,
        "thrust_curve_f": f0,
        "hover_duty": base.hover_duty,
    }
    out: dict[str, dict[str, Any]] = {}
    order = list(found) + [n for n in ("omega", "thrust_curve_f") if n not in found]
    for name in order:
        field = name.removesuffix("_per_m")
        entry = found.get(name)
        base_value = float(prior[field]) / (float(base.m) if name.endswith("_per_m") else 1.0)
        row: dict[str, Any] = {"unit": UNITS[name]}
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
            source = "base vehicle"
            if name == "thrust_curve_f":
                source = f0_source
            row.update(value=base_value, ci95=[None, None], identifiable=False, source=source, note=why or "not fitted")
            if entry is not None:
                row["estimate"] = entry["value"]
        out[name] = row
    return out
