"""A flight log (PX4 ULog or CSV) read into one typed record in quadcruise's frames.

:func:`read_flight_log` gives a :class:`FlightLog`: ENU world, FLU body, quaternions w first
(body to world), seconds, rotor commands in [0, 1], only the armed, airborne stretches, on one
uniform grid (a ULog's body-rate topic's, a CSV's own rows). What is read, which samples count
as airborne, how commands are scaled and what is refused: docs/identify.md, "What is read".

Frames: with ``A`` the NED/ENU axis swap and ``B = diag(1, -1, -1)`` (FRD/FLU),
``v_enu = A v_ned``, ``w_flu = B w_frd``, ``R_enu_flu = A R_ned_frd B``.
"""

from __future__ import annotations

import contextlib
import io
import os
import struct
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import numpy as np
from scipy.spatial.transform import Rotation, Slerp

from quadcruise.errors import InputError
from quadcruise.io import logchecks
from quadcruise.io.files import not_a_file

NED_TO_ENU = np.array([[0.0, 1.0, 0.0], [1.0, 0.0, 0.0], [0.0, 0.0, -1.0]])
"""``A``: NED vectors to ENU (its own inverse)."""
FRD_TO_FLU = np.diag([1.0, -1.0, -1.0])
"""``B``: FRD body vectors to FLU (its own inverse)."""
ARMED = 2
"""``vehicle_status.arming_state`` of an armed vehicle (PX4's ARMING_STATE_ARMED)."""
MULTICOPTER_TYPES = {2: "quadrotor", 3: "coaxial", 4: "helicopter", 13: "hexarotor", 14: "octorotor", 15: "tricopter"}
"""MAVLink MAV_TYPE values of the multicopters this reader accepts."""
MIN_SEGMENT_S = 1.0
"""Shortest airborne segment kept [s]: shorter ones are left out (a bounce, not a flight)."""
MIN_HEIGHT = 0.3
"""Height above the ground [m] (``vehicle_local_position.dist_bottom``, where valid) under which a
sample is left out: touching the ground, or in its strongest effect on the rotors' thrust."""
CSV_COLUMNS = ("t", "vx", "vy", "vz", "qw", "qx", "qy", "qz", "p", "q", "r")
"""The columns a CSV log must have, besides its commands ``u1..un``."""
ULOG_TOPICS = (
    "vehicle_status",
    "vehicle_land_detected",
    "vehicle_attitude",
    "vehicle_angular_velocity",
    "sensor_combined",
    "vehicle_local_position",
    "actuator_motors",
    "actuator_outputs",
    "hover_thrust_estimate",
    "esc_status",
)
"""The topics read from a ULog (others are skipped)."""
NEEDED_FIELDS = {
    "vehicle_attitude": [f"q[{i}]" for i in range(4)],
    "vehicle_local_position": ["x", "y", "z", "vx", "vy", "vz"],
    "vehicle_angular_velocity": [f"xyz[{i}]" for i in range(3)],
    "sensor_combined": [f"gyro_rad[{i}]" for i in range(3)] + [f"accelerometer_m_s2[{i}]" for i in range(3)],
    "hover_thrust_estimate": ["hover_thrust"],
}
"""The fields read of each topic (a topic without one of them is refused)."""
SENSOR_FIELDS = {
    True: NEEDED_FIELDS["sensor_combined"],  # the rates' topic too
    False: [f"accelerometer_m_s2[{i}]" for i in range(3)],
}


RATE_INFO = ("quadcruise_control_rate_hz", "quadcruise_log_rate_hz", "IMU_GYRO_RATEMAX")
"""What a ULog may say of its own rates: a quadcruise log's information messages (its control
and logging rates), and PX4's ``IMU_GYRO_RATEMAX`` (its rate loop runs on each gyro sample)."""


@dataclass(frozen=True, eq=False)
class FlightLog:
    """A flight's airborne stretches on one time grid, in quadcruise's frames.

    Per sample: ``t`` [s] (uniform within each ``segment``), rotor commands ``u`` (L, n) in [0, 1],
    ``velocity`` and ``position`` (or None) [m/s, m] in ENU, ``quaternion`` (FLU to ENU, w first),
    body ``rates`` [rad/s] and ``specific_force`` (or None) [m/s^2] in FLU. Per log: ``source``,
    ``rotors`` (n, 3: x, y [m] FLU and yaw sign, from ``CA_ROTOR*``; or None), ``yaw_per_thrust``
    (``|CA_ROTOR0_KM|`` [m], or None), ``parameters`` (``THR_MDL_FAC``, ``MAV_TYPE``, ...),
    ``hover_thrust`` (PX4's own estimate: time, value; or None), ``rates_hz`` (each topic's median
    rate), and in words where the ``commands`` came from and the ``resampling``. ``speeds`` (L, n),
    or None: the rotors' measured speeds [rad/s] (ULog ``esc_status`` rpm, CSV ``w1..wn``);
    ``speed_commands``: the commands ``u`` are rotor speeds [rad/s] (a CSV read with
    ``commands="rad/s"``) rather than normalised. ``rate_info``: what a ULog says of its own
    rates (:data:`RATE_INFO`: ``IMU_GYRO_RATEMAX``, and a quadcruise log's information messages
    ``quadcruise_control_rate_hz`` and ``quadcruise_log_rate_hz``); empty for a CSV.

    A ULog's commands ``u`` are each rotor's *relative thrust* (thrust over its thrust at full
    command), PX4's meaning of ``actuator_motors``; ``actuator_outputs`` (PWM) are mapped to the
    signal x by the PWM range and to relative thrust through ``THR_MDL_FAC`` (``f x^2 + (1 - f)
    x``), which is applied here and kept as ``thrust_factor`` (not in ``parameters``). With
    ``commands="rad/s"`` ``u`` is the signal x instead (the commanded speed over ``w_max``).
    """

    source: str
    t: np.ndarray
    segment: np.ndarray
    u: np.ndarray
    velocity: np.ndarray
    quaternion: np.ndarray
    rates: np.ndarray
    specific_force: np.ndarray | None = None
    position: np.ndarray | None = None
    rotors: np.ndarray | None = None
    yaw_per_thrust: float | None = None
    parameters: dict = field(default_factory=dict)
    hover_thrust: tuple | None = None
    rates_hz: dict = field(default_factory=dict)
    commands: str = ""
    resampling: str = ""
    speeds: np.ndarray | None = None
    speed_commands: bool = False
    thrust_factor: float | None = None
    rate_info: dict = field(default_factory=dict)

    @property
    def n_rotors(self) -> int:
        """The number of rotor commands per sample."""
        return int(self.u.shape[1])

    @property
    def duration(self) -> float:
        """Airborne time [s], all segments together."""
        total = 0.0
        for k in np.unique(self.segment):
            tk = self.t[self.segment == k]
            total += float(tk[-1] - tk[0])
        return total

    def rotation(self) -> Rotation:
        """The attitudes as a scipy Rotation (body FLU to world ENU)."""
        return Rotation.from_quat(self.quaternion[:, [1, 2, 3, 0]])


def parse_commands(commands: str) -> tuple[str, float, float]:
    """``"duty"``, ``"rad/s"`` or ``"pwm:MIN:MAX"`` as ``(kind, min, max)``; InputError for anything
    else or MIN >= MAX.

    Examples
    --------
    >>> parse_commands("pwm:1000:2000")
    ('pwm', 1000.0, 2000.0)
    """
    text = str(commands).strip().lower()
    if text == "duty":
        return "duty", 0.0, 1.0
    if text == "rad/s":
        return "rad/s", float("nan"), float("nan")
    parts = text.split(":")
    if parts[0] == "pwm" and len(parts) in (1, 3):
        if len(parts) == 1:
            return "pwm", float("nan"), float("nan")
        try:
            lo, hi = float(parts[1]), float(parts[2])
        except ValueError:
            lo = hi = float("nan")
        if np.isfinite(lo) and np.isfinite(hi) and lo < hi:
            return "pwm", lo, hi
    raise InputError(f"commands must be 'duty', 'rad/s' or 'pwm:MIN:MAX' (MIN < MAX, in us), got {commands!r}")


def read_flight_log(path: str | os.PathLike, *, frame: str | None = None, commands: str = "duty") -> FlightLog:
    """Read a PX4 log (``.ulg``) or a CSV into a :class:`FlightLog`.

    Parameters
    ----------
    path : str or os.PathLike
        The log.
    frame : {"enu", "ned"}, optional
        A CSV's frames: ENU world / FLU body (default) or PX4's NED / FRD. A ULog is always
        PX4's: "ned" or None.
    commands : str
        ``duty`` (default: ``actuator_motors``, or a CSV's ``u`` columns in [0, 1]),
        ``rad/s`` (a CSV's ``u`` columns are commanded rotor speeds; a ULog's signal x, the
        relative thrust of ``actuator_motors`` through the inverse of ``THR_MDL_FAC``, is the
        commanded speed over ``w_max``) or ``pwm:MIN:MAX`` (``actuator_outputs``' PWM [us]).

    Returns
    -------
    FlightLog

    Raises
    ------
    InputError
        One line naming the file and what is wrong, before any work.

    Examples
    --------
    >>> read_flight_log("flight.txt")
    Traceback (most recent call last):
        ...
    quadcruise.errors.InputError: flight.txt: a flight log is a PX4 log (.ulg) or a CSV (.csv), got '.txt'
    """
    path = Path(path)
    kind = path.suffix.lower()
    if kind not in (".ulg", ".csv"):
        raise InputError(f"{path}: a flight log is a PX4 log (.ulg) or a CSV (.csv), got {path.suffix!r}")
    if not path.is_file():
        raise InputError(f"{path}: {not_a_file(path)}")
    frame_name = None if frame is None else str(frame).strip().lower()
    if frame_name not in (None, "enu", "ned"):
        raise InputError(f"{path}: frame must be 'enu' or 'ned', got {frame!r}")
    spec = parse_commands(commands)
    if kind == ".ulg":
        if frame_name == "enu":
            raise InputError(
                f"{path}: a PX4 log is always in PX4's frames (NED world, FRD body); frame 'enu' is for CSV logs"
            )
        return _read_ulog(path, spec)
    return _read_csv(path, frame_name or "enu", spec)


# --- ULog ---------------------------------------------------------------------------------


def _median_rate(t: np.ndarray) -> float:
    dt = np.diff(t)
    dt = dt[dt > 0]
    return float(1.0 / np.median(dt)) if dt.size else 0.0


def _held(t_msg: np.ndarray, values: np.ndarray, t: np.ndarray, before: Any) -> np.ndarray:
    """The last message's value at each time (``before`` ahead of the first message)."""
    idx = np.searchsorted(t_msg, t, side="right") - 1
    out = np.where(idx >= 0, values[np.clip(idx, 0, None)], before)
    return out


def _read_ulog(path: Path, spec: tuple[str, float, float]) -> FlightLog:
    from pyulog import ULog
    from pyulog.core import ULogException

    logchecks.check_ulog_framing(path)
    said = io.StringIO()  # pyulog prints what it finds damaged: said here, in one line, instead
    try:
        with contextlib.redirect_stdout(said):
            log = ULog(str(path), message_name_filter_list=list(ULOG_TOPICS))
    except (ULogException, struct.error, ValueError, IndexError, UnicodeDecodeError) as exc:
        raise InputError(f"{path}: not a readable PX4 log ({exc})") from None
    if log.file_corruption or "corrupt" in said.getvalue():
        first = next((line.strip() for line in said.getvalue().splitlines() if line.strip()), "")
        raise InputError(f"{path}: corrupt PX4 log (pyulog: {first or 'damaged messages'})")
    topics: dict[str, dict[str, np.ndarray]] = {}
    for d in log.data_list:
        if d.multi_id == 0 or d.name not in topics:
            topics[d.name] = d.data
    params = dict(log.initial_parameters)

    status = topics.get("vehicle_status")
    if status is None:
        raise InputError(f"{path}: no vehicle_status topic: cannot tell when the vehicle was armed")
    mav_type = int(params.get("MAV_TYPE", status.get("system_type", [2])[0]))
    system_types = set(np.unique(status["system_type"]).tolist()) if "system_type" in status else {mav_type}
    vtol = bool(np.any(status.get("is_vtol", np.zeros(1)))) or mav_type in range(19, 26)
    if vtol or mav_type not in MULTICOPTER_TYPES or not system_types <= set(MULTICOPTER_TYPES):
        what = "a VTOL" if vtol else f"MAV_TYPE {mav_type}"
        raise InputError(f"{path}: not a multicopter ({what}, MAV_TYPE {mav_type}): identify models multicopters")
    if not np.any(status["arming_state"] == ARMED):
        raise InputError(f"{path}: nothing to identify: the vehicle was never armed in this log")

    need = ["vehicle_attitude", "vehicle_local_position"]
    missing = [n for n in need if n not in topics]
    if "vehicle_angular_velocity" not in topics and "sensor_combined" not in topics:
        missing.append("vehicle_angular_velocity or sensor_combined")
    kind, lo, hi = spec
    if kind in ("duty", "rad/s") and "actuator_motors" in topics:
        cmd_topic = "actuator_motors"
    elif "actuator_outputs" in topics:
        cmd_topic = "actuator_outputs"
    else:
        cmd_topic = None
        missing.append("actuator_motors or actuator_outputs")
    if kind == "rad/s" and "esc_status" not in topics:
        missing.append("esc_status (the measured rotor speeds that commands 'rad/s' are fitted against)")
    if missing:
        raise InputError(f"{path}: missing topic(s) {', '.join(missing)}")
    logchecks.check_fields(path, topics, {**NEEDED_FIELDS, "vehicle_status": ["arming_state"]})

    def times(name: str) -> np.ndarray:
        return (topics[name]["timestamp"].astype(np.float64) - float(log.start_timestamp)) * 1e-6

    for name in topics:
        logchecks.check_clock(path, name, times(name))

    # commands
    n_rot = logchecks.check_rotor_count(path, params)
    cmd = topics[cmd_topic]
    prefix = "control" if cmd_topic == "actuator_motors" else "output"
    channels = list(range(n_rot))
    if cmd_topic == "actuator_outputs":  # PX4 >= 1.13: PWM_MAIN_FUNCi = 101 + k puts motor k on output i
        funcs = {int(params[f"PWM_MAIN_FUNC{i + 1}"]): i for i in range(16) if f"PWM_MAIN_FUNC{i + 1}" in params}
        if all(101 + k in funcs for k in range(n_rot)):
            channels = [funcs[101 + k] for k in range(n_rot)]
    cols = [f"{prefix}[{i}]" for i in channels]
    if any(c not in cmd for c in cols):
        raise InputError(f"{path}: {cmd_topic} has fewer than the {n_rot} rotor channels CA_ROTOR_COUNT says")
    raw = np.column_stack([cmd[c].astype(np.float64) for c in cols])
    factor = float(params.get("THR_MDL_FAC", 0.0) or 0.0)
    if not 0.0 <= factor <= 1.0:
        raise InputError(f"{path}: parameter THR_MDL_FAC = {factor:g} is outside PX4's range [0, 1]")
    if cmd_topic == "actuator_outputs":
        if kind == "pwm" and np.isfinite(lo):
            lows, highs = np.full(n_rot, lo), np.full(n_rot, hi)
            how = f"actuator_outputs PWM mapped with {lo:g}..{hi:g} us (given)"
        else:
            lows = np.array([_pwm_param(params, "MIN", i, 1000.0) for i in channels])
            highs = np.array([_pwm_param(params, "MAX", i, 2000.0) for i in channels])
            how = "actuator_outputs PWM mapped with the log's PWM_MAIN_MIN/MAX"
        signal = (raw - lows) / (highs - lows)
        rel = factor * signal**2 + (1.0 - factor) * signal  # PX4's thrust model, THR_MDL_FAC
        how += f", relative thrust through THR_MDL_FAC {factor:g}"
    else:
        rel = raw
        signal = _signal_of(rel, factor)
        how = "actuator_motors (relative thrust)"
    u_raw = signal if kind == "rad/s" else rel

    # airborne, armed
    t_status = times("vehicle_status")
    land = topics.get("vehicle_land_detected")
    rate_topic = "vehicle_angular_velocity"
    if "sensor_combined" in topics and (
        rate_topic not in topics or _median_rate(times("sensor_combined")) > 1.01 * _median_rate(times(rate_topic))
    ):
        rate_topic = "sensor_combined"
    t_rate = times(rate_topic)
    step = 1.0 / _median_rate(t_rate)
    used = ["vehicle_attitude", "vehicle_local_position", cmd_topic, rate_topic]
    accel_topic = "sensor_combined" if "sensor_combined" in topics else None
    if accel_topic:
        used.append(accel_topic)
    start = max(times(n)[0] for n in used)
    end = min(times(n)[-1] for n in used)
    grid = np.arange(start, end, step) if end > start else np.zeros(0)
    armed = _held(t_status, status["arming_state"], grid, 0) == ARMED
    landed = np.zeros(grid.shape, bool)
    if land is not None:
        for flag in ("landed", "maybe_landed", "ground_contact"):
            if flag in land:
                landed |= _held(times("vehicle_land_detected"), land[flag].astype(bool), grid, True)
    lp = topics["vehicle_local_position"]
    if "dist_bottom" in lp:  # PX4's estimate, also while its own valid flag is down (no range sensor)
        height = _interp(times("vehicle_local_position"), lp["dist_bottom"][:, None], grid)[:, 0]
        landed |= np.isfinite(height) & (height < MIN_HEIGHT)
    air = armed & ~landed & np.all(np.isfinite(_interp(times(cmd_topic), u_raw, grid)), axis=1)
    segment = _segments(air, grid, step)
    if not np.any(segment >= 0):
        raise InputError(
            f"{path}: nothing to identify: the vehicle was armed but never airborne for {MIN_SEGMENT_S:g} s"
        )
    keep = segment >= 0
    t = grid[keep]
    _check_values(path, topics, times, [rate_topic, accel_topic], t)

    att = topics["vehicle_attitude"]
    q_ned = np.column_stack([att[f"q[{i}]"] for i in range(4)]).astype(np.float64)
    used_att = logchecks.bracket(times("vehicle_attitude"), t[0], t[-1])
    r_ned = Rotation.from_quat(q_ned[used_att][:, [1, 2, 3, 0]])
    t_att, first = np.unique(times("vehicle_attitude")[used_att], return_index=True)
    r_enu = (
        Rotation.from_matrix(NED_TO_ENU)
        * Slerp(t_att, r_ned[first])(np.clip(t, t_att[0], t_att[-1]))
        * Rotation.from_matrix(FRD_TO_FLU)
    )
    xyzw = r_enu.as_quat()
    quat = np.column_stack([xyzw[:, 3], xyzw[:, :3]])

    t_lp = times("vehicle_local_position")
    vel = _interp(t_lp, np.column_stack([lp["vx"], lp["vy"], lp["vz"]]), t) @ NED_TO_ENU.T
    pos = _interp(t_lp, np.column_stack([lp["x"], lp["y"], lp["z"]]), t) @ NED_TO_ENU.T
    rt = topics[rate_topic]
    keys = (
        [f"xyz[{i}]" for i in range(3)]
        if rate_topic == "vehicle_angular_velocity"
        else [f"gyro_rad[{i}]" for i in range(3)]
    )
    rates = _interp(t_rate, np.column_stack([rt[k] for k in keys]), t) @ FRD_TO_FLU.T
    force = None
    if accel_topic:
        sc = topics[accel_topic]
        force = (
            _interp(times(accel_topic), np.column_stack([sc[f"accelerometer_m_s2[{i}]"] for i in range(3)]), t)
            @ FRD_TO_FLU.T
        )
    u = _interp(times(cmd_topic), u_raw, t)
    if kind != "rad/s":
        hint = (
            f"the PWM is outside its range {lows.min():g}..{highs.max():g} us"
            if cmd_topic == "actuator_outputs"
            else "PX4's actuator_motors holds each rotor's relative thrust, in [0, 1]"
        )
        names = [f"{cmd_topic}.{c}" for c in cols]
        # the log's own samples inside the airborne segments first (the value and time it holds),
        # then what the grid interpolates (the samples just outside a segment count there)
        t_cmd, seg = times(cmd_topic), segment[keep]
        inside = np.zeros(t_cmd.shape, bool)
        for k in np.unique(seg):
            inside |= (t_cmd >= t[seg == k][0]) & (t_cmd <= t[seg == k][-1])
        logchecks.check_duties(path, u_raw[inside], names, at=t_cmd[inside], hint=hint)
        logchecks.check_duties(path, u, names, at=t, hint=hint)

    speeds = None
    esc = topics.get("esc_status")
    if esc is not None and all(f"esc[{i}].esc_rpm" in esc for i in range(n_rot)):
        rpm = np.column_stack([esc[f"esc[{i}].esc_rpm"].astype(np.float64) for i in range(n_rot)])
        speeds = _interp(times("esc_status"), np.abs(rpm) * (2.0 * np.pi / 60.0), t)
    elif kind == "rad/s":
        raise InputError(
            f"{path}: commands 'rad/s' identify the rotor plant, which needs the rotor speeds: "
            "no esc_status topic with one esc_rpm per rotor"
        )
    rotors, km = _rotors(params, n_rot)
    logchecks.check_geometry(path, rotors)
    hover = None
    if "hover_thrust_estimate" in topics:
        h = topics["hover_thrust_estimate"]
        th = times("hover_thrust_estimate")
        valid = h.get("valid", np.ones(th.shape, bool)).astype(bool)
        seg = segment[keep]
        inside = valid & np.zeros(th.shape, bool)
        for k in np.unique(seg):
            tk = t[seg == k]
            inside |= valid & (th >= tk[0]) & (th <= tk[-1])
        if np.any(inside):
            hover = (th[inside], h["hover_thrust"][inside].astype(np.float64))
    rates_hz = {n: round(_median_rate(times(n)), 1) for n in topics}
    resampling = (
        f"uniform grid at the rate of {rate_topic} ({1 / step:.0f} Hz) over each airborne segment "
        f"(armed, not landed or touching the ground, "
        f"and >= {MIN_HEIGHT:g} m above the ground by dist_bottom, for >= {MIN_SEGMENT_S:g} s); "
        "vectors and commands interpolated linearly, "
        "attitude by slerp, arming and landed states held from their last message"
    )
    names = ("MAV_TYPE", "CA_ROTOR_COUNT", "SYS_AUTOSTART", "SDLOG_PROFILE")  # THR_MDL_FAC: applied here
    kept = {k: params[k] for k in names if k in params}
    said_rates = {**log.msg_info_dict, **params}
    return FlightLog(
        rate_info={k: said_rates[k] for k in RATE_INFO if k in said_rates},
        source=str(path),
        t=t,
        segment=segment[keep],
        u=u,
        velocity=vel,
        quaternion=quat,
        rates=rates,
        specific_force=force,
        position=pos,
        rotors=rotors,
        yaw_per_thrust=km,
        parameters=kept,
        hover_thrust=hover,
        rates_hz=rates_hz,
        commands=how
        + (f"; signal x (THR_MDL_FAC {factor:g}) x w_max: commanded rotor speeds" if kind == "rad/s" else ""),
        resampling=resampling,
        speeds=speeds,
        thrust_factor=factor,
    )


def _signal_of(rel: np.ndarray, factor: float) -> np.ndarray:
    """PX4's signal x of a relative thrust through ``THR_MDL_FAC`` f: the root of ``f x^2 + (1 - f) x = rel``."""
    if factor <= 0.0:
        return rel.copy()
    b = 1.0 - factor
    return -b / (2.0 * factor) + np.sqrt(b * b / (4.0 * factor**2) + np.clip(rel, 0.0, None) / factor)


def _check_values(path: Path, topics: dict, times, sources: list, t: np.ndarray) -> None:
    """Refuse non-finite values and non-unit quaternions where the airborne stretch ``t`` reads them."""
    att = topics["vehicle_attitude"]
    q = np.column_stack([att[f"q[{i}]"] for i in range(4)]).astype(np.float64)
    logchecks.check_quaternions(path, "vehicle_attitude", times("vehicle_attitude"), q, t[0], t[-1])
    for name in ["vehicle_local_position", *(n for n in sources if n)]:
        fields = NEEDED_FIELDS[name] if name != "sensor_combined" else SENSOR_FIELDS[name in sources[:1]]
        columns = {f: topics[name][f] for f in fields}
        logchecks.check_finite(path, name, times(name), columns, t[0], t[-1])


def _pwm_param(params: dict, which: str, i: int, default: float) -> float:
    for key in (f"PWM_MAIN_{which}{i + 1}", f"PWM_{which}"):
        value = params.get(key)
        if value is not None and value > 0:
            return float(value)
    return default


def _interp(t_src: np.ndarray, values: np.ndarray, t: np.ndarray) -> np.ndarray:
    t_src, first = np.unique(t_src, return_index=True)
    values = values[first].astype(np.float64)
    return np.column_stack([np.interp(t, t_src, values[:, j]) for j in range(values.shape[1])])


def _segments(air: np.ndarray, t: np.ndarray, step: float) -> np.ndarray:
    """Each sample's segment index (-1 outside): runs of ``air`` at least MIN_SEGMENT_S long."""
    out = np.full(air.shape, -1)
    edges = np.flatnonzero(np.diff(np.r_[0, air.astype(np.int8), 0]))
    k = 0
    for a, b in zip(edges[::2], edges[1::2], strict=False):
        if (b - a) * step >= MIN_SEGMENT_S:
            out[a:b] = k
            k += 1
    return out


def _rotors(params: dict, n: int) -> tuple[np.ndarray | None, float | None]:
    keys = [f"CA_ROTOR{i}_{w}" for i in range(n) for w in ("PX", "PY", "KM")]
    if not all(k in params for k in keys):
        return None, None
    rows = [
        (
            float(params[f"CA_ROTOR{i}_PX"]),
            -float(params[f"CA_ROTOR{i}_PY"]),
            -float(np.sign(params[f"CA_ROTOR{i}_KM"])),
        )
        for i in range(n)
    ]
    return np.array(rows), abs(float(params["CA_ROTOR0_KM"]))


# --- CSV ----------------------------------------------------------------------------------


def _read_csv(path: Path, frame: str, spec: tuple[str, float, float]) -> FlightLog:
    import pandas as pd

    try:
        table = pd.read_csv(path)
    except (pd.errors.ParserError, pd.errors.EmptyDataError, UnicodeDecodeError) as exc:
        raise InputError(f"{path}: not a readable CSV ({str(exc).splitlines()[0] if str(exc) else exc})") from None
    table.columns = [str(c).strip() for c in table.columns]
    missing = [c for c in CSV_COLUMNS if c not in table.columns]
    n_rot = 0
    while f"u{n_rot + 1}" in table.columns:
        n_rot += 1
    if n_rot == 0:
        missing.append("u1..un (rotor commands)")
    if missing:
        raise InputError(f"{path}: missing column(s) {', '.join(missing)}")
    optional = [c for c in ("x", "y", "z", "ax", "ay", "az", "landed") if c in table.columns]
    speed_cols = [f"w{i + 1}" for i in range(n_rot)]
    if any(c in table.columns for c in speed_cols):
        missing_w = [c for c in speed_cols if c not in table.columns]
        if missing_w:
            raise InputError(f"{path}: measured rotor speeds need w1..w{n_rot}: missing {', '.join(missing_w)}")
        optional += speed_cols
    names = list(CSV_COLUMNS) + [f"u{i + 1}" for i in range(n_rot)] + optional
    for name in names:
        col = pd.to_numeric(table[name], errors="coerce").to_numpy(np.float64)
        bad = np.flatnonzero(~np.isfinite(col))
        if bad.size:
            raise InputError(
                f"{path}: row {bad[0] + 2}, column {name}: not a finite number ({table[name].iloc[bad[0]]!r})"
            )
        table[name] = col
    t = table["t"].to_numpy(np.float64)
    if len(t) < 3:
        raise InputError(f"{path}: {len(t)} row(s): a flight log needs rows over at least {MIN_SEGMENT_S:g} s airborne")
    back = np.flatnonzero(np.diff(t) <= 0)
    if back.size:
        raise InputError(
            f"{path}: row {back[0] + 3}: time t={t[back[0] + 1]:g} does not increase "
            f"(previous {t[back[0]]:g}); the rows must be sorted by time"
        )
    for group in (("x", "y", "z"), ("ax", "ay", "az")):
        if 0 < sum(c in table.columns for c in group) < 3:
            raise InputError(f"{path}: give all of {', '.join(group)} or none of them")
    landed = table["landed"].to_numpy() > 0.5 if "landed" in table.columns else np.zeros(len(t), bool)
    step = float(np.median(np.diff(t))) if len(t) > 1 else 1.0
    segment = _segments(~landed, t, step)
    keep = segment >= 0
    if not np.any(keep):
        raise InputError(
            f"{path}: nothing to identify: no airborne stretch of {MIN_SEGMENT_S:g} s (landed column, or too few rows)"
        )
    kind, lo, hi = spec
    u_names = [f"u{i + 1}" for i in range(n_rot)]
    u = table[u_names].to_numpy()
    if kind == "pwm":
        if not np.isfinite(lo):
            raise InputError(f"{path}: a CSV's PWM commands need their range: commands='pwm:MIN:MAX'")
        u = (u - lo) / (hi - lo)
        how = f"CSV u columns, PWM mapped with {lo:g}..{hi:g} us"
        logchecks.check_duties(
            path, np.where(keep[:, None], u, 0.5), u_names, hint=f"outside the PWM range {lo:g}..{hi:g} us"
        )
    elif kind == "rad/s":
        how = "CSV u columns (commanded rotor speeds, rad/s)"
    else:
        how = "CSV u columns (normalised)"
        logchecks.check_duties(path, np.where(keep[:, None], u, 0.5), u_names)
    world = np.eye(3) if frame == "enu" else NED_TO_ENU
    body = np.eye(3) if frame == "enu" else FRD_TO_FLU
    q = table[["qw", "qx", "qy", "qz"]].to_numpy()
    norm = np.linalg.norm(q, axis=1)
    if np.any(np.abs(norm - 1.0) > 1e-2):
        row = int(np.flatnonzero(np.abs(norm - 1.0) > 1e-2)[0])
        raise InputError(f"{path}: row {row + 2}: the quaternion qw,qx,qy,qz has norm {norm[row]:.4g}, not 1")
    rot = Rotation.from_matrix(world) * Rotation.from_quat(q[:, [1, 2, 3, 0]]) * Rotation.from_matrix(body)
    xyzw = rot.as_quat()
    quat = np.column_stack([xyzw[:, 3], xyzw[:, :3]])

    def pick(cols):
        return table[list(cols)].to_numpy()[keep]

    position = pick(("x", "y", "z")) @ world.T if "x" in table.columns else None
    force = pick(("ax", "ay", "az")) @ body.T if "ax" in table.columns else None
    return FlightLog(
        source=str(path),
        t=t[keep],
        segment=segment[keep],
        u=u[keep],
        velocity=pick(("vx", "vy", "vz")) @ world.T,
        quaternion=quat[keep],
        rates=pick(("p", "q", "r")) @ body.T,
        specific_force=force,
        position=position,
        speeds=pick(speed_cols) if speed_cols[0] in table.columns else None,
        speed_commands=kind == "rad/s",
        rates_hz={"csv": round(1.0 / step, 1)},
        commands=how,
        resampling=f"the CSV's own rows ({frame.upper()} frames), landed rows left out",
    )
