"""``px4-check --fly``: a PX4 log's takeoff flown again by quadcruise's PX4 controller, with the
log's parameters, on a vehicle, and compared with what the log recorded.

The segment: from the first ``takeoff_status`` of PX4's takeoff ramp (``takeoff_state`` 4,
ramp-up) to the first of: ``vehicle_status.nav_state`` becoming other than the mode at the
ramp's start, AUTO_TAKEOFF and the hold after it (AUTO_LOITER) (the SITL log: its return, RTL),
the land detector reporting landed again, the log's end.

The flight (:func:`fly_takeoff`): the rotor-speed plant with a ground at z = 0, starting on it at
the log's position and heading with its rotors stopped; the ``px4`` controller with the log's
parameters (:meth:`~quadcruise.control.px4.Px4.from_params`), PX4's takeoff ramp, land detector
and hover-thrust estimator on (``takeoff``, ``hover_estimator``), at the log's gyro rate; the
mission is the log's ``trajectory_setpoint`` stream (NED to ENU, heights over the ground where
the ramp started), linearly interpolated between its logged samples (5 Hz) where both are
given and held otherwise, NaN kept (PX4's "not controlled": a NaN yaw holds the current one).

The comparison (:func:`compare_takeoff`): the height over the ramp's start and roll, pitch and
yaw (NED, FRD: PX4's Euler angles) of the flight against ``vehicle_local_position`` and
``vehicle_attitude`` at their logged times in the segment: R^2, RMSE, the largest error and when.

The vehicle of the shared SITL log (:func:`jmavsim_iris`): PX4 v1.15's airframe 10017
``jmavsim_iris`` (``SYS_AUTOSTART`` 10017; ``PX4_SIMULATOR`` jmavsim) flies in jMAVSim, whose
``Simulator.buildMulticopter`` (github.com/PX4/jMAVSim, ``src/me/drton/jmavsim/Simulator.java``)
makes a quadrotor x of 0.8 kg, arm 0.33 / 2 m, 4.0 N and 0.05 N m per rotor at full command,
a 5 ms rotor time constant, inertia diag(0.005, 0.005, 0.009)
kg m^2, a drag ``-0.01 |v| v`` [N] (``setDragMove(0.01)``, ``getAirFlowForce``): hover at
0.8 g / 16 = 0.49 of full thrust, its thrust taken linear in PX4's command. ``quadcruise
identify`` of the log with ``--mass 0.8`` finds K = 3.99 N and a hover duty of 0.491 (its
verdict: the model does not fit, the commands being logged at 10 Hz), and PX4's own
``hover_thrust_estimate`` in the log says 0.49: the three agree (a thrust growing as the
command squared would hover at 0.70).
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import numpy as np
from numba import njit
from scipy.spatial.transform import Rotation

from quadcruise import layout as L
from quadcruise.control.px4 import Px4
from quadcruise.errors import InputError
from quadcruise.io.px4params import Px4Parameters
from quadcruise.model.rotor_vehicle import RotorVehicle

__all__ = ["jmavsim_iris", "takeoff_segment", "fly_takeoff", "compare_takeoff", "TakeoffFlight", "RAMPUP"]

RAMPUP = 4
"""``takeoff_status.takeoff_state`` of PX4's takeoff ramp."""
AUTO_LOITER = 4
"""``vehicle_status.nav_state`` of the hold after an automatic takeoff."""
AUTO_TAKEOFF = 17
"""``vehicle_status.nav_state`` of an automatic takeoff."""
_A = np.array([[0.0, 1.0, 0.0], [1.0, 0.0, 0.0], [0.0, 0.0, -1.0]])  # ENU <-> NED
_B = np.diag([1.0, -1.0, -1.0])  # FLU <-> FRD


def jmavsim_iris(m: float = 0.8) -> RotorVehicle:
    """jMAVSim's quadrotor, which PX4's SITL airframe 10017 (``jmavsim_iris``) flies (module docstring).

    Parameters
    ----------
    m : float
        Mass [kg] (jMAVSim's 0.8).

    Returns
    -------
    RotorVehicle
        Rotors in PX4's ``CA_ROTOR`` order (front right, rear left counter-clockwise; front left,
        rear right), ``w_max`` 1000 rad/s (jMAVSim gives thrust per command, not a speed: kf and
        km are set so that full speed gives its 4.0 N and 0.05 N m), its drag as ``c_D`` 0.01 on
        each axis (``-|v| c_D v``, isotropic as jMAVSim's).

    Examples
    --------
    >>> v = jmavsim_iris()
    >>> round(v.m * v.g / (4 * v.kf * v.w_max ** 2), 4)     # hover thrust over full thrust
    0.4905
    """
    a = 0.33 / 2.0 * math.sqrt(0.5)
    return RotorVehicle(
        m=m,
        Jxx=0.005,
        Jyy=0.005,
        Jzz=0.009,
        kf=4.0e-6,
        km=5.0e-8,
        tau_up=0.005,
        tau_down=0.005,
        w_min=0.0,
        w_max=1000.0,
        rotors=((a, -a, 0.0, -1.0), (-a, a, 0.0, -1.0), (a, a, 0.0, 1.0), (-a, -a, 0.0, 1.0)),
        c_Dx=0.01,
        c_Dy=0.01,
        c_Dz=0.01,
        source="jMAVSim Simulator.buildMulticopter (github.com/PX4/jMAVSim): PX4 SITL airframe 10017 jmavsim_iris",
    )


@njit(L.MISSION_SIG, cache=True, error_model="numpy")
def _log_setpoints(t, mp, out):
    """The logged setpoints ``mp = [n, t_0..t_{n-1}, ref_0 (11), ..]`` at ``t``: linear between two
    samples where both are finite, else the earlier one held (NaN kept)."""
    n = int(mp[0])
    k = 0
    if t >= mp[1]:
        lo, hi = 0, n - 1
        while lo < hi:  # the last sample at or before t
            mid = (lo + hi + 1) // 2
            if mp[1 + mid] <= t:
                lo = mid
            else:
                hi = mid - 1
        k = lo
    base = 1 + n + L.REF_SIZE * k
    if k + 1 < n and t > mp[1 + k]:
        w = (t - mp[1 + k]) / (mp[2 + k] - mp[1 + k])
        for j in range(L.REF_SIZE):
            a, b = mp[base + j], mp[base + L.REF_SIZE + j]
            out[j] = a + w * (b - a) if (math.isfinite(a) and math.isfinite(b)) else a
    else:
        for j in range(L.REF_SIZE):
            out[j] = mp[base + j]


class _Setpoints:
    """The log's setpoints as a mission for :func:`~quadcruise.workflows.rotor_fly.fly_rotor`."""

    function = staticmethod(_log_setpoints)

    def __init__(self, mp: np.ndarray):
        self.mp = np.ascontiguousarray(mp, dtype=float)

    def reference(self, t) -> np.ndarray:
        ts = np.atleast_1d(np.asarray(t, float))
        out = np.empty((ts.size, L.REF_SIZE))
        for i, ti in enumerate(ts):
            _log_setpoints(float(ti), self.mp, out[i])
        return out


def _held(topic: dict, name: str, t_us) -> np.ndarray:
    i = np.searchsorted(topic["timestamp"], t_us, side="right") - 1
    return np.asarray(topic[name])[np.clip(i, 0, None)]


def takeoff_segment(T: dict, until_us: int | None = None, log_start_us: int = 0) -> tuple[int, int]:
    """The takeoff segment of a log's topics (module docstring), in the log's microseconds.

    Parameters
    ----------
    T : dict
        Topics by name, fields by name (as :func:`quadcruise.workflows.px4check` reads them).
    until_us : int, optional
        End there instead [us, the log's clock]: after the ramp's start, within the log
        (``px4-check --fly-until``: more of the flight, e.g. the return's descent).
    log_start_us : int
        The log's start [us], for the times a refusal names.

    Returns
    -------
    (int, int)
        Start and end [us].

    Raises
    ------
    InputError
        No ``takeoff_status`` ramp-up, a topic the flight needs missing, or ``until_us`` outside
        (ramp start, log end].
    """
    for name in ("takeoff_status", "trajectory_setpoint", "vehicle_local_position", "vehicle_attitude"):
        if name not in T or len(T[name]["timestamp"]) < 2:
            raise InputError(f"the log has no {name}: cannot fly its takeoff")
    ts = T["takeoff_status"]
    ramp = np.flatnonzero(np.asarray(ts["takeoff_state"]) == RAMPUP)
    if ramp.size == 0:
        raise InputError("the log has no takeoff: takeoff_status never reports PX4's ramp-up (takeoff_state 4)")
    start = int(ts["timestamp"][ramp[0]])
    end = int(min(T["vehicle_local_position"]["timestamp"][-1], T["vehicle_attitude"]["timestamp"][-1]))
    status = T.get("vehicle_status")
    if status is not None and "nav_state" in status:
        t, nav = np.asarray(status["timestamp"]), np.asarray(status["nav_state"])
        first = int(_held(status, "nav_state", start))
        later = np.flatnonzero((t > start) & ~np.isin(nav, (first, AUTO_TAKEOFF, AUTO_LOITER)))
        if later.size:
            end = min(end, int(t[later[0]]))
    land = T.get("vehicle_land_detected")
    if land is not None:
        t, landed = np.asarray(land["timestamp"]), np.asarray(land["landed"])
        flown = np.flatnonzero((t > start) & (landed == 0))
        if flown.size:
            again = np.flatnonzero((t > t[flown[0]]) & (landed != 0))
            if again.size:
                end = min(end, int(t[again[0]]))
    if until_us is not None:
        last = int(min(T["vehicle_local_position"]["timestamp"][-1], T["vehicle_attitude"]["timestamp"][-1]))
        if not start < until_us <= last:
            raise InputError(
                f"--fly-until: the flight runs from the takeoff ramp's start to the log's end, "
                f"{(start - log_start_us) * 1e-6:.2f} to {(last - log_start_us) * 1e-6:.2f} s of the log"
            )
        end = until_us
    if end <= start:
        raise InputError("the log ends where its takeoff ramp starts: nothing to fly")
    return start, end


def _setpoint_mission(T: dict, start: int, end: int, ground: float) -> tuple[np.ndarray, float]:
    """The mission row of the log's ``trajectory_setpoint`` in the segment (times from ``start``)."""
    tr = T["trajectory_setpoint"]
    t_us = np.asarray(tr["timestamp"])
    keep = np.flatnonzero(t_us <= end)
    first = max(int(np.searchsorted(t_us, start, side="right")) - 1, 0)  # the one in force at the start
    keep = keep[keep >= first]
    if keep.size == 0:
        raise InputError("the log has no trajectory_setpoint in its takeoff")
    vec = {
        k: np.stack([np.asarray(tr[f"{k}[{i}]"], float)[keep] for i in range(3)], axis=1)
        for k in ("position", "velocity", "acceleration")
    }
    ref = np.empty((keep.size, L.REF_SIZE))
    pos = vec["position"].copy()
    pos[:, 2] -= ground
    ref[:, L.REF_X : L.REF_X + 3] = pos @ _A.T
    ref[:, L.REF_VX : L.REF_VX + 3] = vec["velocity"] @ _A.T
    ref[:, L.REF_AX : L.REF_AX + 3] = vec["acceleration"] @ _A.T
    ref[:, L.REF_PSI] = 0.5 * np.pi - np.asarray(tr["yaw"], float)[keep]
    ref[:, L.REF_PSI_DOT] = -np.asarray(tr["yawspeed"], float)[keep]
    times = np.maximum((t_us[keep].astype(np.int64) - start) * 1e-6, 0.0)
    times = times + np.arange(times.size) * 1e-9  # strictly increasing where two share the start
    return np.concatenate([[float(keep.size)], times, ref.ravel()]), float(times[0])


def _gyro_rate(T: dict) -> float:
    """The rate loop's rate [Hz], PX4's gyro rate: ``sensor_combined``'s sample rate where it is
    logged densely (every sample: 250 Hz in the SITL log), else ``vehicle_angular_velocity``'s
    ``timestamp_sample`` spacing, else 250 Hz (SITL's)."""
    for name, key in (("sensor_combined", "timestamp"), ("vehicle_angular_velocity", "timestamp_sample")):
        if name in T and key in T[name]:
            dt = np.diff(np.asarray(T[name][key], float)) * 1e-6
            dt = dt[dt > 0]
            if dt.size and np.median(dt) < 0.0061:
                return float(round(1.0 / np.median(dt)))
    return 250.0


@dataclass
class TakeoffFlight:
    """A log's takeoff flown (:func:`fly_takeoff`) and compared (:func:`compare_takeoff`).

    Parameters
    ----------
    result : SimResult
        The flight.
    start_us, end_us : int
        The segment in the log's time [us].
    ground : float
        The log's ``vehicle_local_position.z`` at the start [m, NED], height 0.
    log_start_us : int
        The log's start [us] (times are reported from it).
    vehicle : RotorVehicle
        The vehicle flown.
    controller : Px4
        The controller flown.
    rate_hz : float
        The control rate [Hz].
    fit : dict
        Filled by :func:`compare_takeoff`: per signal ``{"r2", "rmse", "samples", "max_error", "max_error_at_s"}``.
    series : dict
        The compared series (log and ours at the log's times), for the figure.
    """

    result: Any
    start_us: int
    end_us: int
    ground: float
    log_start_us: int
    vehicle: RotorVehicle
    controller: Px4
    rate_hz: float
    fit: dict = field(default_factory=dict)
    series: dict = field(default_factory=dict)

    @property
    def status(self) -> str:
        """The flight's exit status, in words ('finished' when it flew the whole segment)."""
        return self.result.status_text(0)

    def to_json(self) -> dict:
        """``check.json``'s ``flight`` entry."""
        v = self.vehicle
        return {
            "segment_s": [(self.start_us - self.log_start_us) * 1e-6, (self.end_us - self.log_start_us) * 1e-6],
            "duration_s": (self.end_us - self.start_us) * 1e-6,
            "status": self.status,
            "control_rate_hz": self.rate_hz,
            "vehicle": {"m": v.m, "hover_thrust": v.m * v.g / (v.n_rotors * v.kf * v.w_max**2), "source": v.source},
            "controller": {
                "hover_estimator": self.controller.hover_estimator,
                "takeoff": self.controller.takeoff,
                "takeoff_speed_up": self.controller.takeoff_speed_up,
                "thrust_curve": self.controller.thrust_curve,
            },
            "compared": "height over the ramp's start (vehicle_local_position.z), the collective thrust setpoint "
            "(vehicle_thrust_setpoint), roll, pitch, yaw (vehicle_attitude), NED/FRD, at the log's samples",
            "units": {"height": "m", "thrust": "normalised", "roll": "rad", "pitch": "rad", "yaw": "rad"},
            "fit": self.fit,
        }


def fly_takeoff(
    T: dict,
    params: Px4Parameters,
    vehicle: RotorVehicle | None = None,
    *,
    hover_estimator: bool = True,
    thrust_curve: float = 0.0,
    max_step: float = 1e-3,
    log_start_us: int = 0,
    until_s: float | None = None,
) -> TakeoffFlight:
    """Fly a log's takeoff segment (module docstring).

    Parameters
    ----------
    T : dict
        The log's topics (:func:`quadcruise.workflows.px4check` reads them).
    params : Px4Parameters
        PX4's parameters (the log's).
    vehicle : RotorVehicle, optional
        The vehicle; :func:`jmavsim_iris` by default.
    hover_estimator : bool
        PX4's hover-thrust estimator on (where ``MPC_USE_HTE`` is 1).
    thrust_curve : float
        The vehicle's thrust per command, ``(1 - a) u + a u^2`` (0: linear, jMAVSim's).
    max_step : float
        Longest RK4 substep [s].
    log_start_us : int
        The log's start [us] (``ULog.start_timestamp``), for the times reported.
    until_s : float, optional
        End the flight there [s from the log's start] instead of at the takeoff's end.

    Returns
    -------
    TakeoffFlight
    """
    from quadcruise.workflows.rotor_fly import fly_rotor

    vehicle = vehicle or jmavsim_iris()
    until = None if until_s is None else log_start_us + int(round(until_s * 1e6))
    start, end = takeoff_segment(T, until, log_start_us)
    lp, att = T["vehicle_local_position"], T["vehicle_attitude"]
    ground = float(np.interp(start, lp["timestamp"], np.asarray(lp["z"], float)))
    mp, _ = _setpoint_mission(T, start, end, ground)
    speed_up = 0.0
    if "vehicle_constraints" in T and "speed_up" in T["vehicle_constraints"]:
        value = float(_held(T["vehicle_constraints"], "speed_up", start))
        speed_up = value if math.isfinite(value) and value > 0 else 0.0
    controller = Px4.from_params(
        params, vehicle, thrust_curve=thrust_curve, takeoff=True, hover_estimator=hover_estimator,
        takeoff_speed_up=speed_up,
    )  # fmt: skip
    rate = _gyro_rate(T)
    dt = 1.0 / rate
    n_steps = int(math.floor((end - start) * 1e-6 / dt))
    grid = np.arange(n_steps + 1) * dt
    q = np.array([float(_held(att, f"q[{i}]", start)) for i in range(4)])
    yaw_ned = Rotation.from_quat(q[[1, 2, 3, 0]]).as_euler("ZYX")[0]
    x0 = np.zeros(L.STATE_SIZE)
    north, east = (float(np.interp(start, lp["timestamp"], np.asarray(lp[k], float))) for k in ("x", "y"))
    x0[L.X], x0[L.Y], x0[L.Z] = east, north, 0.0
    x0[L.PSI] = 0.5 * np.pi - yaw_ned  # level on the ground, rotors stopped (F = 0)
    mission = _Setpoints(mp)
    result = fly_rotor(
        grid, vehicle, None, controller.function, controller.gains(), mission, mission.mp, 1, x0=x0,
        memory=controller.memory(), max_step=min(max_step, dt), log_every=1,
        meta={"controller": "px4", "mission": "log trajectory_setpoint"},
    )  # fmt: skip
    return TakeoffFlight(result, start, end, ground, log_start_us, vehicle, controller, rate)


def _fit(logged: np.ndarray, ours: np.ndarray, t: np.ndarray) -> dict:
    ok = np.isfinite(logged) & np.isfinite(ours)
    y, yh, tt = logged[ok], ours[ok], t[ok]
    if y.size < 2:
        return {"r2": None, "rmse": None, "samples": int(y.size), "max_error": None, "max_error_at_s": None}
    err = yh - y
    ss_tot = float(np.sum((y - y.mean()) ** 2))
    k = int(np.argmax(np.abs(err)))
    return {
        "r2": None if ss_tot == 0.0 else 1.0 - float(np.sum(err**2)) / ss_tot,
        "rmse": float(np.sqrt(np.mean(err**2))),
        "samples": int(y.size),
        "max_error": float(abs(err[k])),
        "max_error_at_s": float(tt[k]),
    }


def _relative_thrust(flight: TakeoffFlight, force: np.ndarray) -> np.ndarray:
    """PX4's collective thrust setpoint (normalised) of the controller's total thrust command [N]:
    the rotors' mean force over a rotor's full thrust through the vehicle's thrust curve
    (``f = (1 - c) u + c u^2``) to the command u, then through ``THR_MDL_FAC`` back to PX4's relative
    thrust (``s = (1 - fac) u + fac u^2``). Exact while the rotors share the thrust evenly (a vertical
    takeoff); a mean otherwise."""
    v, c = flight.vehicle, flight.controller
    f = np.clip(np.asarray(force, float) / (v.n_rotors * v.kf * v.w_max**2), 0.0, None)
    curve, fac = c.thrust_curve, c.params["THR_MDL_FAC"]
    u = f if curve <= 0.0 else (-(1.0 - curve) + np.sqrt((1.0 - curve) ** 2 + 4.0 * curve * f)) / (2.0 * curve)
    return (1.0 - fac) * u + fac * u * u


def compare_takeoff(flight: TakeoffFlight, T: dict) -> dict:
    """Height and roll, pitch, yaw of the flight against the log (module docstring); fills
    ``flight.fit`` and ``flight.series`` and returns the fit.

    Parameters
    ----------
    flight : TakeoffFlight
    T : dict
        The log's topics.

    Returns
    -------
    dict
        ``{"height" | "thrust" | "roll" | "pitch" | "yaw": {"r2", "rmse", "samples", "max_error",
        "max_error_at_s"}}``, the largest error's time from the ramp's start [s]; ``thrust``: the
        collective thrust setpoint against ``vehicle_thrust_setpoint`` (normalised), where logged.
    """
    res = flight.result
    t_sim = res.t
    stop = float(res.t_stop[0]) if np.isfinite(res.t_stop[0]) else t_sim[-1]
    lp, att = T["vehicle_local_position"], T["vehicle_attitude"]
    fit, series = {}, {}
    t_lp = np.asarray(lp["timestamp"], np.int64)
    m = (t_lp >= flight.start_us) & (t_lp <= flight.end_us)
    tl = (t_lp[m] - flight.start_us) * 1e-6
    h_log = -(np.asarray(lp["z"], float)[m] - flight.ground)
    z = res.states[0, :, L.Z]
    h_ours = np.interp(tl, t_sim[np.isfinite(z)], z[np.isfinite(z)])
    h_ours[(tl > stop) | (tl > t_sim[np.isfinite(z)][-1])] = np.nan
    fit["height"] = _fit(h_log, h_ours, tl)
    series["height"] = (tl, h_log, h_ours)
    if "vehicle_thrust_setpoint" in T:  # the collective thrust setpoint, PX4's normalised thrust
        th = T["vehicle_thrust_setpoint"]
        t_th = np.asarray(th["timestamp"], np.int64)
        m = (t_th >= flight.start_us) & (t_th <= flight.end_us)
        tt = (t_th[m] - flight.start_us) * 1e-6
        thrust = _relative_thrust(flight, res.commands[0, :, L.CMD_THRUST])
        ok = np.isfinite(thrust)
        ours_t = np.interp(tt, t_sim[ok], thrust[ok]) if ok.any() else np.full(tt.size, np.nan)
        ours_t[(tt > stop) | (ok.any() and tt > t_sim[ok][-1])] = np.nan
        logged_t = -np.asarray(th["xyz[2]"], float)[m]
        fit["thrust"] = _fit(logged_t, ours_t, tt)
        series["thrust"] = (tt, logged_t, ours_t)
    t_att = np.asarray(att["timestamp"], np.int64)
    m = (t_att >= flight.start_us) & (t_att <= flight.end_us)
    ta = (t_att[m] - flight.start_us) * 1e-6
    q = np.stack([np.asarray(att[f"q[{i}]"], float)[m] for i in range(4)], axis=1)
    log_euler = Rotation.from_quat(q[:, [1, 2, 3, 0]]).as_euler("ZYX")[:, ::-1]  # roll, pitch, yaw
    ang = res.states[0, :, L.PHI : L.PSI + 1]
    flown = np.all(np.isfinite(ang), axis=1)  # a flight that stopped has NaN rows after its stop
    r_enu = Rotation.from_euler("ZYX", ang[flown, ::-1]).as_matrix()
    ours_all = Rotation.from_matrix(_A @ r_enu @ _B).as_euler("ZYX")[:, ::-1]
    ours_all[:, 2] = np.unwrap(ours_all[:, 2])
    t_flown = t_sim[flown]
    ours = np.stack([np.interp(ta, t_flown, ours_all[:, i]) for i in range(3)], axis=1)
    ours[ta > t_flown[-1]] = np.nan
    ours[ta > stop] = np.nan
    ours[:, 2] = log_euler[:, 2] + np.angle(np.exp(1j * (ours[:, 2] - log_euler[:, 2])))  # yaw error wrapped
    for i, name in enumerate(("roll", "pitch", "yaw")):
        fit[name] = _fit(log_euler[:, i], ours[:, i], ta)
        series[name] = (ta, log_euler[:, i], ours[:, i])
    flight.fit, flight.series = fit, series
    return fit


def takeoff_figure(flight: TakeoffFlight):
    """Height, thrust setpoint and roll, pitch, yaw of the log and of the flight, against the time
    from the ramp's start.

    Parameters
    ----------
    flight : TakeoffFlight
        A compared flight (:func:`compare_takeoff`).

    Returns
    -------
    matplotlib.figure.Figure
    """
    from matplotlib.figure import Figure

    panels = [("height", "m", 1.0), ("thrust", "norm", 1.0), ("roll", "deg", 180 / np.pi)]
    panels += [("pitch", "deg", 180 / np.pi), ("yaw", "deg", 180 / np.pi)]
    panels = [p for p in panels if p[0] in flight.series]
    fig = Figure(figsize=(8.0, 1.9 * len(panels) + 0.5))
    axes = fig.subplots(len(panels), 1, sharex=True)
    for ax, (name, unit, scale) in zip(axes, panels, strict=True):
        t, log, ours = flight.series[name]
        f = flight.fit[name]
        ax.plot(t, log * scale, "k.-", ms=3, lw=1, label="PX4 log")
        ax.plot(t, ours * scale, "C1-", lw=1.5, label="quadcruise px4")
        r2 = "-" if f["r2"] is None else f"{f['r2']:.3f}"
        rmse = "-" if f["rmse"] is None else f"{f['rmse'] * scale:.3g}"
        ax.set_ylabel(f"{name} [{unit}]")
        ax.set_title(f"{name}: R2 {r2}, RMSE {rmse} {unit}", fontsize=9, loc="left")
    axes[0].legend(loc="lower right", fontsize=8)
    axes[-1].set_xlabel("time from the takeoff ramp's start [s]")
    fig.tight_layout()
    return fig


def flight_table(flight: TakeoffFlight) -> str:
    """The flight's lines of ``px4-check``'s table: its status, then per signal R^2, RMSE and the largest error.

    Parameters
    ----------
    flight : TakeoffFlight
        A compared flight (:func:`compare_takeoff`).

    Returns
    -------
    str
    """
    v = flight.vehicle
    hover = v.m * v.g / (v.n_rotors * v.kf * v.w_max**2)
    a, b = (flight.start_us - flight.log_start_us) * 1e-6, (flight.end_us - flight.log_start_us) * 1e-6
    lines = [
        f"takeoff flight {b - a:.1f} s of the log ({a:.2f} to {b:.2f} s), {flight.status}; vehicle m {v.m:g} kg, "
        f"hover thrust {hover:.3f}, {flight.rate_hz:g} Hz, hover-thrust estimator "
        + ("on" if flight.controller.hover_estimator else "off"),
        f"{'flight':<13} {'signal':<8} {'n':>5} {'R2':>7} {'RMSE':>10}  {'unit':<7} largest error (from the ramp)",
    ]
    for name, f in flight.fit.items():
        scale, unit = {"height": (1.0, "m"), "thrust": (1.0, "norm")}.get(name, (180.0 / math.pi, "deg"))
        r2 = "-" if f["r2"] is None else f"{f['r2']:.3f}"
        rmse = "-" if f["rmse"] is None else f"{f['rmse'] * scale:.3g}"
        worst = (
            "-" if f["max_error"] is None else f"{f['max_error'] * scale:.3g} {unit} at +{f['max_error_at_s']:.2f} s"
        )
        lines.append(f"{'takeoff':<13} {name:<8} {f['samples']:>5} {r2:>7} {rmse:>10}  {unit:<7} {worst}")
    return "\n".join(lines)


def write_flight(flight: TakeoffFlight, folder: str | Path) -> list[str]:
    """Write ``takeoff.png`` (:func:`takeoff_figure`) and ``vehicle.toml`` (the vehicle flown, as
    ``fly --vehicle`` reads it) into ``folder``.

    Parameters
    ----------
    flight : TakeoffFlight
        A compared flight (:func:`compare_takeoff`).
    folder : str or pathlib.Path
        An existing folder.

    Returns
    -------
    list of str
        The files written.
    """
    import tomli_w

    folder = Path(folder)
    takeoff_figure(flight).savefig(folder / "takeoff.png", dpi=110)
    v = flight.vehicle
    fields = {"plant": "rotor", **{k: x for k, x in v.to_dict().items() if x is not None}}
    fields["rotors"] = [list(r) for r in v.rotors]
    head = (
        f"# the vehicle px4-check --fly flew: {v.source or 'given with --vehicle'}\n"
        f"# its thrust per PX4 command: thrust_curve {flight.controller.thrust_curve:g} (fly it with "
        f"-c thrust_curve={flight.controller.thrust_curve:g} beside --params)\n"
    )
    (folder / "vehicle.toml").write_text(head + tomli_w.dumps({"vehicle": fields}))
    return ["takeoff.png", "vehicle.toml"]
