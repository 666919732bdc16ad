"""``px4-check``: a PX4 log's own signals fed through quadcruise's PX4 loops, with the log's
parameters, and what the loops give compared with what PX4 logged.

Per loop, at each logged output sample while airborne (armed, ``vehicle_land_detected.landed``
false):

- attitude (:func:`~quadcruise.control.px4loops.attitude_control`): ``vehicle_attitude`` and
  ``vehicle_attitude_setpoint`` (``q_d``, ``yaw_sp_move_rate``), both slerped (the rate
  linearly) to the time of each ``vehicle_rates_setpoint``, which is compared;
- rate (:func:`~quadcruise.control.px4loops.rate_control`): ``vehicle_angular_velocity``
  (``xyz``, ``xyz_derivative``) at each ``vehicle_torque_setpoint``'s ``timestamp_sample``
  (the gyro sample it was computed from), ``vehicle_rates_setpoint`` and the integral of
  ``rate_ctrl_status`` interpolated to its time; ``vehicle_torque_setpoint`` is compared;
- rate integral: the same inputs at the logged gyro samples (50 Hz where PX4 integrates at the
  gyro rate), with the allocator's saturation (``control_allocator_status``) and the land
  detector, integrated by us from the log's first value; ``rate_ctrl_status`` is compared;
- allocation (:func:`~quadcruise.control.px4allocation.allocate`): ``vehicle_torque_setpoint``
  and ``vehicle_thrust_setpoint`` of each ``actuator_motors`` sample's gyro sample, through the
  log's own ``CA_ROTOR*`` geometry (always the log's, whatever the parameters given) and
  ``MC_AIRMODE``; ``actuator_motors`` is compared;
- position (:func:`~quadcruise.control.px4loops.position_control`), while
  ``takeoff_status`` says flying and the land detector sees no ground contact: ``vehicle_local_position`` and the last
  ``trajectory_setpoint`` and ``hover_thrust_estimate`` at each
  ``vehicle_local_position_setpoint`` (PX4 computes one per local position, same
  timestamp); the velocity integral starts from the one PX4's first flying output implies and
  is then our own; velocity, acceleration and thrust setpoints are compared.

R^2 = 1 - SS_res / SS_tot of ours against PX4's, and the RMSE, per axis. A log's topics are
logged at 5-50 Hz while the loops run at 50-250 Hz, so an input between its logged samples is
interpolated: that, not the loops, is what keeps R^2 below 1 (:attr:`Px4Check.limits`).
"""

from __future__ import annotations

import json
import math
import os
import struct
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import numpy as np
from scipy.spatial.transform import Rotation, Slerp

from quadcruise.control.px4allocation import allocate, mix_matrix, rotor_effectiveness, rotors_from_params
from quadcruise.control.px4loops import (
    G_TILT_MAX,
    G_VEL_D,
    G_VEL_P,
    attitude_control,
    hover_thrust_integral,
    position_control,
    px4_gains,
    rate_control,
)
from quadcruise.errors import InputError
from quadcruise.io.flightlog import ARMED, MULTICOPTER_TYPES
from quadcruise.io.px4defaults import RELEASE
from quadcruise.io.px4params import Px4Parameters, read_params

__all__ = ["Px4Check", "px4_check", "GOOD_FIT"]

GOOD_FIT = 0.8
"""R^2 from which PX4's autotune calls a model fit good."""
FLYING = 5
"""``takeoff_status.takeoff_state`` of a flying vehicle (PX4's TAKEOFF_STATE_FLIGHT)."""
TOPICS = (
    "vehicle_status",
    "vehicle_land_detected",
    "vehicle_attitude",
    "vehicle_attitude_setpoint",
    "vehicle_rates_setpoint",
    "vehicle_angular_velocity",
    "vehicle_torque_setpoint",
    "rate_ctrl_status",
    "control_allocator_status",
    "vehicle_thrust_setpoint",
    "actuator_motors",
    "vehicle_local_position",
    "vehicle_local_position_setpoint",
    "trajectory_setpoint",
    "hover_thrust_estimate",
    "takeoff_status",
)
"""The topics read."""
NO3 = (False, False, False)


def fit(logged: np.ndarray, ours: np.ndarray) -> dict[str, Any]:
    """R^2 and RMSE of ``ours`` against ``logged`` over the samples where both are finite.

    Examples
    --------
    >>> fit(np.array([0.0, 1.0, 2.0, 3.0]), np.array([0.0, 1.0, 2.0, 4.0]))
    {'r2': 0.8, 'rmse': 0.5, 'samples': 4}
    """
    ok = np.isfinite(logged) & np.isfinite(ours)
    y, yh = logged[ok], ours[ok]
    if y.size < 2:
        return {"r2": None, "rmse": None, "samples": int(y.size)}
    ss_tot = float(np.sum((y - y.mean()) ** 2))
    rmse = float(np.sqrt(np.mean((y - yh) ** 2)))
    r2 = None if ss_tot == 0.0 else 1.0 - float(np.sum((y - yh) ** 2)) / ss_tot
    return {"r2": r2, "rmse": rmse, "samples": int(y.size)}


@dataclass(frozen=True)
class Px4Check:
    """What :func:`px4_check` found: per loop and axis, R^2 and RMSE of ours against PX4's.

    Parameters
    ----------
    log : str
        The log.
    params : Px4Parameters
        The parameters the loops ran with (the log's, or a file's).
    loops : dict
        ``{loop: {"inputs", "output", "unit", "axes": {axis: {"r2", "rmse", "samples"}}}}``;
        a loop the log cannot feed has ``"absent"``: why.
    px4_version : str
        The PX4 version the log says it ran (``ver_sw_release``).
    limits : list of str
        What keeps the fit below 1, in words.
    command : str
        The command line that made it, if any.
    flight : TakeoffFlight, optional
        The log's takeoff flown and compared (``px4-check --fly``, :mod:`quadcruise.workflows.px4fly`).
    """

    log: str
    params: Px4Parameters
    loops: dict
    px4_version: str
    limits: list = field(default_factory=list)
    command: str = ""
    flight: Any = None

    def to_json(self) -> dict:
        """The document ``check.json`` holds."""
        return {
            "log": self.log,
            "log_px4_version": self.px4_version,
            "loops_px4_release": RELEASE,
            "parameters": self.params.source,
            "parameters_used": {k: self.params[k] for k in sorted(self.params)},
            "parameters_unused": list(self.params.unused),
            "parameters_notes": list(self.params.notes),
            "good_fit_r2": GOOD_FIT,
            "loops": self.loops,
            "limits": self.limits,
            **({"flight": self.flight.to_json()} if self.flight is not None else {}),
            "command": self.command,
        }

    def table(self) -> str:
        """A short text table: loop, axis, samples, R^2, RMSE with its unit, PX4's topic."""
        lines = [f"{'loop':<13} {'axis':<8} {'n':>5} {'R2':>7} {'RMSE':>10}  {'unit':<7} compared with"]
        for loop, info in self.loops.items():
            if "absent" in info:
                lines.append(f"{loop:<13} absent: {info['absent']}")
                continue
            for axis, f in info["axes"].items():
                r2 = "-" if f["r2"] is None else f"{f['r2']:.3f}"
                rmse = "-" if f["rmse"] is None else f"{f['rmse']:.3g}"
                unit = _unit(loop, axis)
                lines.append(f"{loop:<13} {axis:<8} {f['samples']:>5} {r2:>7} {rmse:>10}  {unit:<7} {info['output']}")
        if self.flight is not None:
            from quadcruise.workflows.px4fly import flight_table

            lines.append(flight_table(self.flight))
        return "\n".join(lines)

    def write(self, folder: str | os.PathLike, *, force: bool = False) -> Path:
        """Write ``check.json`` and the marker ``quadcruise.json`` into ``folder``, whole or not at all.

        Parameters
        ----------
        folder : str or os.PathLike
            The output folder.
        force : bool
            Replace a non-empty folder quadcruise did not write.

        Returns
        -------
        pathlib.Path
            The folder.
        """
        from quadcruise._version import __version__
        from quadcruise.io.files import MARKER, atomic_dir, check_output_dir

        out = check_output_dir(folder, force, inputs=[self.log])
        with atomic_dir(out) as tmp:
            (Path(tmp) / "check.json").write_text(json.dumps(self.to_json(), indent=2) + "\n")
            if self.flight is not None:
                from quadcruise.workflows.px4fly import write_flight

                write_flight(self.flight, tmp)
            marker = {"workflow": "px4-check", "version": __version__, "command": self.command, "log": self.log}
            (Path(tmp) / MARKER).write_text(json.dumps(marker, indent=2) + "\n")
        return out


def _unit(loop: str, axis: str) -> str:
    if loop == "attitude":
        return "rad/s"
    if loop.startswith("rate") or loop == "allocation" or axis.startswith("T_"):
        return "norm"
    return "m/s" if axis.startswith("v_") else "m/s^2"


def _read(path: Path, names: tuple = TOPICS) -> tuple[dict, dict, dict]:
    from pyulog import ULog
    from pyulog.core import ULogException

    from quadcruise.io.logchecks import check_ulog_framing

    if path.suffix.lower() != ".ulg":
        raise InputError(f"{path}: px4-check reads a PX4 log (.ulg), got {path.suffix!r}")
    if not path.is_file():
        raise InputError(f"{path}: no such file")
    check_ulog_framing(path)
    try:
        log = ULog(str(path), message_name_filter_list=list(names))
    except (ULogException, struct.error, ValueError, IndexError) as exc:
        raise InputError(f"{path}: not a readable PX4 log ({exc})") from None
    topics: dict[str, dict[str, np.ndarray]] = {}
    for d in log.data_list:
        if d.multi_id == 0 or d.name not in topics:
            topics[d.name] = {k: np.asarray(v) for k, v in d.data.items()}
    raw = dict(log.initial_parameters)
    for _, name, value in log.changed_parameters:
        raw[name] = value
    return topics, {**log.msg_info_dict, "start_timestamp_us": int(log.start_timestamp)}, raw


def _version(info: dict) -> str:
    v = info.get("ver_sw_release")
    if not v:
        return "unknown"
    kind = {0: " (dev)", 64: " (alpha)", 128: " (beta)", 192: " (rc)", 255: ""}.get(v & 0xFF, "")
    return f"{(v >> 24) & 0xFF}.{(v >> 16) & 0xFF}.{(v >> 8) & 0xFF}{kind}"


def _held(topic: dict, name: str, t: np.ndarray, before=np.nan) -> np.ndarray:
    i = np.searchsorted(topic["timestamp"], t, side="right") - 1
    return np.where(i >= 0, topic[name][np.clip(i, 0, None)], before)


def _vec(topic: dict, name: str, n: int = 3) -> np.ndarray:
    return np.stack([topic[f"{name}[{i}]"] for i in range(n)], axis=1).astype(float)


def _slerp(t_q: np.ndarray, q: np.ndarray, t: np.ndarray) -> np.ndarray:
    """Quaternions (w first) slerped to ``t`` (inside ``t_q``)."""
    keep = np.concatenate([[True], np.diff(t_q) > 0])
    return Slerp(t_q[keep], Rotation.from_quat(q[keep][:, [1, 2, 3, 0]]))(t).as_quat(scalar_first=True)


def _attitude(T: dict, g: np.ndarray, airborne) -> dict:
    att, sp, out = T["vehicle_attitude"], T["vehicle_attitude_setpoint"], T["vehicle_rates_setpoint"]
    ta, ts, t = att["timestamp"] * 1e-6, sp["timestamp"] * 1e-6, out["timestamp"] * 1e-6
    m = airborne(out["timestamp"]) & (t >= max(ta[0], ts[0])) & (t <= min(ta[-1], ts[-1]))
    q = _slerp(ta, _vec(att, "q", 4), t[m])
    qd = _slerp(ts, _vec(sp, "q_d", 4), t[m])
    yaw_rate = np.interp(t[m], ts, sp["yaw_sp_move_rate"].astype(float))
    ours = np.array(
        [attitude_control(tuple(a), tuple(b), float(c), g) for a, b, c in zip(q, qd, yaw_rate, strict=True)]
    )
    ours = ours.reshape(-1, 3)
    axes = {ax: fit(out[ax][m].astype(float), ours[:, i]) for i, ax in enumerate(("roll", "pitch", "yaw"))}
    return {
        "inputs": "vehicle_attitude, vehicle_attitude_setpoint (slerped to each output's time)",
        "output": "vehicle_rates_setpoint",
        "unit": "rad/s",
        "axes": axes,
    }


def _rate(T: dict, g: np.ndarray, airborne) -> dict:
    av, sp, out, st = (
        T["vehicle_angular_velocity"],
        T["vehicle_rates_setpoint"],
        T["vehicle_torque_setpoint"],
        T["rate_ctrl_status"],
    )
    tg = av["timestamp_sample"] * 1e-6
    t = out["timestamp"] * 1e-6
    t_sample = out["timestamp_sample"] * 1e-6 if "timestamp_sample" in out else t
    m = airborne(out["timestamp"]) & (t_sample >= tg[0]) & (t_sample <= tg[-1]) & (t >= sp["timestamp"][0] * 1e-6)
    w = np.stack([np.interp(t_sample[m], tg, av[f"xyz[{i}]"]) for i in range(3)], axis=1)
    dw = np.stack([np.interp(t_sample[m], tg, av[f"xyz_derivative[{i}]"]) for i in range(3)], axis=1)
    rsp = np.stack([np.interp(t[m], sp["timestamp"] * 1e-6, sp[a]) for a in ("roll", "pitch", "yaw")], axis=1)
    ts = st["timestamp"] * 1e-6
    integ = np.stack([np.interp(t[m], ts, st[f"{a}speed_integ"]) for a in ("roll", "pitch", "yaw")], axis=1)
    rows = zip(w, rsp, dw, integ, strict=True)
    ours = np.array(
        [rate_control(tuple(a), tuple(b), tuple(c), 0.0, True, g, NO3, NO3, tuple(d))[0] for a, b, c, d in rows]
    )
    ours = ours.reshape(-1, 3)
    axes = {ax: fit(out[f"xyz[{i}]"][m].astype(float), ours[:, i]) for i, ax in enumerate(("roll", "pitch", "yaw"))}
    return {
        "inputs": "vehicle_angular_velocity at the output's gyro sample, vehicle_rates_setpoint, rate_ctrl_status",
        "output": "vehicle_torque_setpoint",
        "unit": "normalised torque",
        "axes": axes,
    }


def _rate_integral(T: dict, g: np.ndarray, airborne) -> dict:
    av, sp, st, land = (
        T["vehicle_angular_velocity"],
        T["vehicle_rates_setpoint"],
        T["rate_ctrl_status"],
        T["vehicle_land_detected"],
    )
    tg = av["timestamp_sample"]
    held = _held(land, "landed", tg, 1) != 0  # PX4 holds the integral while landed or maybe landed
    if "maybe_landed" in land:
        held |= _held(land, "maybe_landed", tg, 1) != 0
    rsp = np.stack([np.interp(tg, sp["timestamp"], sp[a]) for a in ("roll", "pitch", "yaw")], axis=1)
    w, dw = _vec(av, "xyz"), _vec(av, "xyz_derivative")
    sat_pos = np.zeros((tg.size, 3), bool)
    sat_neg = np.zeros((tg.size, 3), bool)
    if "control_allocator_status" in T:  # as MulticopterRateControl reads it: unallocated torque when not achieved
        ca = T["control_allocator_status"]
        missed = _held(ca, "torque_setpoint_achieved", tg, 1) == 0
        for i in range(3):
            left = _held(ca, f"unallocated_torque[{i}]", tg, 0.0)
            sat_pos[:, i] = missed & (left > 1.1920929e-07)
            sat_neg[:, i] = missed & (left < -1.1920929e-07)
    names = ("rollspeed_integ", "pitchspeed_integ", "yawspeed_integ")
    integ = tuple(float(np.interp(tg[0], st["timestamp"], st[n])) for n in names)
    ours = np.empty((tg.size, 3))
    for k in range(tg.size):
        dt = (tg[k] - tg[k - 1]) * 1e-6 if k else 0.0
        _, integ = rate_control(
            tuple(w[k]), tuple(rsp[k]), tuple(dw[k]), dt, bool(held[k]), g,
            tuple(sat_pos[k]), tuple(sat_neg[k]), integ,
        )  # fmt: skip
        ours[k] = integ
    ts = st["timestamp"]
    m = airborne(ts) & (ts >= tg[0]) & (ts <= tg[-1])
    axes = {
        ax: fit(st[n][m].astype(float), np.interp(ts[m], tg, ours[:, i]))
        for i, (ax, n) in enumerate(zip(("roll", "pitch", "yaw"), names, strict=True))
    }
    return {
        "inputs": "vehicle_angular_velocity, vehicle_rates_setpoint, control_allocator_status, vehicle_land_detected "
        "(our integral from the log's first, at the logged gyro samples)",
        "output": "rate_ctrl_status",
        "unit": "normalised torque",
        "axes": axes,
    }


def _allocation(T: dict, raw: dict, airborne) -> dict:
    if "CA_ROTOR_COUNT" not in raw or int(raw["CA_ROTOR_COUNT"]) < 1:
        return {"absent": "the log has no CA_ROTOR_COUNT (no rotor geometry)"}
    try:
        geometry = rotors_from_params(raw)
    except KeyError as exc:
        return {"absent": f"the log has no {exc.args[0]}"}
    mix, _ = mix_matrix(rotor_effectiveness(*geometry))
    n = mix.shape[0]
    motors, torque, thrust = T["actuator_motors"], T["vehicle_torque_setpoint"], T["vehicle_thrust_setpoint"]
    row_t = {int(t): i for i, t in enumerate(torque["timestamp_sample"])}
    row_f = {int(t): i for i, t in enumerate(thrust["timestamp_sample"])}
    airmode = int(raw.get("MC_AIRMODE", 0))
    up = airborne(motors["timestamp"])
    lo, hi = np.zeros(n), np.ones(n)
    ours = np.full((motors["timestamp"].size, n), np.nan)
    for k, t in enumerate(motors["timestamp_sample"]):
        i, j = row_t.get(int(t)), row_f.get(int(t))
        if not up[k] or i is None or j is None:
            continue
        control = [torque[f"xyz[{a}]"][i] for a in range(3)] + [thrust[f"xyz[{a}]"][j] for a in range(3)]
        ours[k] = np.clip(allocate(mix, np.array(control, float), airmode, lo, hi), 0.0, 1.0)
    logged = _vec(motors, "control", n)
    return {
        "inputs": "vehicle_torque_setpoint and vehicle_thrust_setpoint of the same gyro sample, the log's CA_ROTOR*",
        "output": "actuator_motors",
        "unit": "normalised command",
        "axes": {f"motor{m + 1}": fit(logged[:, m], ours[:, m]) for m in range(n)},
    }


def _position(T: dict, g: np.ndarray, params: Px4Parameters, airborne) -> dict:
    lp, out, tr = T["vehicle_local_position"], T["vehicle_local_position_setpoint"], T["trajectory_setpoint"]
    t_us = out["timestamp"]
    flying = airborne(t_us)
    if "takeoff_status" in T:
        flying &= _held(T["takeoff_status"], "takeoff_state", t_us, 0) == FLYING
    land = T["vehicle_land_detected"]
    for flag in ("maybe_landed", "ground_contact"):  # PX4 overrides the setpoints on ground contact
        if flag in land:
            flying &= _held(land, flag, t_us, 1) == 0
    flying &= (t_us >= lp["timestamp"][0]) & (t_us >= tr["timestamp"][0])
    idx = np.flatnonzero(flying)
    if idx.size < 2:
        return {"absent": "the log has fewer than two flying position-controller samples"}
    tl = lp["timestamp"]
    state = {
        k: np.interp(t_us[idx], tl, lp[k].astype(float)) for k in ("x", "y", "z", "vx", "vy", "vz", "ax", "ay", "az")
    }
    sp = {
        k: np.stack([_held(tr, f"{k}[{i}]", t_us[idx]) for i in range(3)], axis=1)
        for k in ("position", "velocity", "acceleration")
    }
    use_hte = params["MPC_USE_HTE"] == 1 and "hover_thrust_estimate" in T
    hover = (
        _held(T["hover_thrust_estimate"], "hover_thrust", t_us[idx], params["MPC_THR_HOVER"])
        if use_hte
        else np.full(idx.size, params["MPC_THR_HOVER"])
    )
    hover = np.where(np.isfinite(hover), hover, params["MPC_THR_HOVER"])
    logged = {k: out[k][idx].astype(float) for k in ("vx", "vy", "vz")}
    acc_logged = _vec(out, "acceleration")[idx]
    # the velocity integral PX4 had at the first flying sample: its output less the P, D and feed-forward terms
    v0 = np.array([logged["vx"][0], logged["vy"][0], logged["vz"][0]])
    vel0 = np.array([state["vx"][0], state["vy"][0], state["vz"][0]])
    dv0 = np.array([state["ax"][0], state["ay"][0], state["az"][0]])
    ff0 = np.nan_to_num(sp["acceleration"][0])
    vel_int = acc_logged[0] - ff0 - g[G_VEL_P : G_VEL_P + 3] * (v0 - vel0) + g[G_VEL_D : G_VEL_D + 3] * dv0
    vel_int = tuple(float(v) if math.isfinite(v) else 0.0 for v in vel_int)
    ours = np.full((idx.size, 9), np.nan)
    for k in range(idx.size):
        if k > 0 and hover[k] != hover[k - 1]:
            last_a = ours[k - 1, 5] if math.isfinite(ours[k - 1, 5]) else 0.0  # our acceleration setpoint before
            vel_int = (vel_int[0], vel_int[1], hover_thrust_integral(vel_int[2], hover[k - 1], hover[k], last_a))
        dt = (t_us[idx[k]] - t_us[idx[k - 1]]) * 1e-6 if k > 0 else 0.0
        pos = (state["x"][k], state["y"][k], state["z"][k])
        vel = (state["vx"][k], state["vy"][k], state["vz"][k])
        acc = (state["ax"][k], state["ay"][k], state["az"][k])
        v, a, thr, new_int, valid = position_control(
            pos, vel, acc, tuple(sp["position"][k]), tuple(sp["velocity"][k]), tuple(sp["acceleration"][k]),
            dt, g, float(hover[k]), float(g[G_TILT_MAX]), vel_int,
        )  # fmt: skip
        if valid:
            vel_int = new_int
            ours[k] = v + a + thr
    thr_logged = _vec(out, "thrust")[idx]
    axes = {}
    for i, ax in enumerate(("north", "east", "down")):
        axes[f"v_{ax}"] = fit(logged[("vx", "vy", "vz")[i]], ours[:, i])
    for i, ax in enumerate(("north", "east", "down")):
        axes[f"a_{ax}"] = fit(acc_logged[:, i], ours[:, 3 + i])
    for i, ax in enumerate(("north", "east", "down")):
        axes[f"T_{ax}"] = fit(thr_logged[:, i], ours[:, 6 + i])
    return {
        "inputs": "vehicle_local_position, trajectory_setpoint, hover_thrust_estimate (while flying)",
        "output": "vehicle_local_position_setpoint",
        "unit": "m/s; m/s^2; normalised thrust",
        "axes": axes,
    }


def px4_check(
    log: str | os.PathLike, params: Px4Parameters | None = None, command: str = "", fly: dict | None = None
) -> Px4Check:
    """Feed a PX4 log's signals through the PX4 loops and compare their outputs with the log's.

    Parameters
    ----------
    log : str or os.PathLike
        A PX4 log (``.ulg``).
    params : Px4Parameters, optional
        The parameters to run with; the log's own by default.
    command : str
        The command line, recorded.
    fly : dict, optional
        Fly the log's takeoff too, with these keywords of
        :func:`~quadcruise.workflows.px4fly.fly_takeoff` (``vehicle``, ``hover_estimator``,
        ``thrust_curve``, ``until_s``): ``{}`` for its defaults.

    Returns
    -------
    Px4Check

    Raises
    ------
    InputError
        A file that is not a readable PX4 log, a log that was never airborne, or one that has
        none of the loops' topics; one line naming the file.
    """
    path = Path(log)
    T, info, raw = _read(path, TOPICS + (("vehicle_constraints", "sensor_combined") if fly is not None else ()))
    params = read_params(path) if params is None else params
    if fly is not None:  # a log without a takeoff is refused before any work
        from quadcruise.workflows.px4fly import takeoff_segment

        try:
            until = fly.get("until_s")
            start_us = int(info.get("start_timestamp_us", 0))
            takeoff_segment(T, None if until is None else start_us + int(round(until * 1e6)), start_us)
        except InputError as exc:
            raise InputError(f"{path}: {exc}") from None
    g = px4_gains(params)
    if "vehicle_land_detected" not in T:
        raise InputError(f"{path}: no vehicle_land_detected topic: cannot tell when the vehicle was airborne")
    land = T["vehicle_land_detected"]
    status = T.get("vehicle_status")
    if status is not None and "system_type" in status:
        kinds = set(np.unique(status["system_type"]).tolist())
        vtol = bool(np.any(status.get("is_vtol", np.zeros(1))))
        if vtol or not kinds <= set(MULTICOPTER_TYPES):
            what = "a VTOL" if vtol else f"MAV_TYPE {sorted(kinds)}"
            raise InputError(f"{path}: not a multicopter ({what}): px4-check checks PX4's multicopter loops")

    def airborne(t_us):
        up = _held(land, "landed", t_us, 1) == 0
        if status is not None and "arming_state" in status:
            up &= _held(status, "arming_state", t_us, 0) == ARMED
        return up

    needs = {
        "attitude": ("vehicle_attitude", "vehicle_attitude_setpoint", "vehicle_rates_setpoint"),
        "rate": ("vehicle_angular_velocity", "vehicle_rates_setpoint", "vehicle_torque_setpoint", "rate_ctrl_status"),
        "rate_integral": ("vehicle_angular_velocity", "vehicle_rates_setpoint", "rate_ctrl_status"),
        "allocation": ("vehicle_torque_setpoint", "vehicle_thrust_setpoint", "actuator_motors"),
        "position": ("vehicle_local_position", "vehicle_local_position_setpoint", "trajectory_setpoint"),
    }
    loops: dict[str, dict] = {}
    for loop, topics in needs.items():
        missing = [n for n in topics if n not in T or len(T[n]["timestamp"]) < 2]
        if missing:
            loops[loop] = {"absent": "the log has no " + ", ".join(missing)}
        elif loop == "attitude":
            loops[loop] = _attitude(T, g, airborne)
        elif loop == "rate":
            loops[loop] = _rate(T, g, airborne)
        elif loop == "rate_integral":
            loops[loop] = _rate_integral(T, g, airborne)
        elif loop == "allocation":
            loops[loop] = _allocation(T, raw, airborne)
        else:
            loops[loop] = _position(T, g, params, airborne)
    if all("absent" in v for v in loops.values()):
        raise InputError(
            f"{path}: none of the PX4 loops can be checked: " + "; ".join(v["absent"] for v in loops.values())
        )
    if not any(f["samples"] for v in loops.values() if "axes" in v for f in v["axes"].values()):
        raise InputError(f"{path}: nothing to check: the vehicle was never airborne in this log")
    rates = {n: _rate_hz(T[n]["timestamp"]) for n in TOPICS if n in T}
    version = _version(info)
    limits = [] if version.startswith("1.15.") else [f"the log ran PX4 {version}; the loops are PX4 v1.15's"]
    limits += [
        "logged rates [Hz]: " + ", ".join(f"{n} {r:.0f}" for n, r in rates.items() if r),
        "the loops run at 50-250 Hz: inputs between logged samples are interpolated (attitude, rates) or held "
        "(trajectory setpoint, hover thrust); a setpoint may come from an input that was never logged",
        "timestamps: the attitude loop's output is matched by publication time; the rate loop's by its gyro sample "
        "(timestamp_sample), which is exact",
        "position loop: the takeoff ramp and the land detector's setpoint overrides are not modelled (only flying "
        "samples are compared), and the D term uses the estimator's acceleration where PX4 differentiates the velocity",
    ]
    flight = None
    if fly is not None:
        from quadcruise.workflows.px4fly import compare_takeoff, fly_takeoff

        try:
            flight = fly_takeoff(T, params, log_start_us=int(info.get("start_timestamp_us", 0)), **fly)
        except InputError as exc:
            raise InputError(f"{path}: {exc}") from None
        compare_takeoff(flight, T)
    return Px4Check(str(path), params, loops, version, limits, command, flight)


def _rate_hz(t_us: np.ndarray) -> float:
    dt = np.diff(np.asarray(t_us, float)) * 1e-6
    dt = dt[dt > 0]
    return float(1.0 / np.median(dt)) if dt.size else 0.0
