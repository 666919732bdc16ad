"""The simulation engine: fixed-step RK4 for one vehicle or N, in one compiled function.

Time runs on a grid of control instants t_0 < t_1 < ... < t_M shared by the batch. At
each t_k the engine asks the mission for the reference and the controller for a command,
then holds the command over [t_k, t_{k+1}] while RK4 integrates the plant in equal
substeps no longer than ``max_step``. After every period it checks the state; a vehicle
whose state turns non-finite or leaves the bounds in :class:`Limits` stops there, with its
status, time and reason recorded, while the rest of the batch flies on.

The single-vehicle flight is the N = 1 case of the same kernel. Vehicles are independent,
so the kernel runs them in parallel (numba ``prange``); each vehicle's arithmetic does not
depend on the batch it is in, so a batch reproduces single flights bit for bit.

Controllers and missions are compiled functions with the signatures in
:mod:`quadcruise.layout`, passed as first-class function values: one cached kernel
serves every controller, a user's own included.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
from numba import njit, prange, types

from .errors import InputError
from .layout import (
    CMD_FLAGS, CMD_SIZE, DISTURBANCE_SIG, EXT_E1, EXT_SIZE, ControllerType, DisturbanceType,
    MissionType, P, PHI, PSI, Q, R, REF_SIZE, STATE_SIZE, THETA, VX, VY, VZ, X, Y, Z,
)
from .model.plant import derivative_at
from .rng import gauss, vehicle_states
from .result import STATUS_REASONS, SimResult

# exit status of each vehicle (the reasons live in result.STATUS_REASONS)
FINISHED, NONFINITE, POSITION_BOUND, SPEED_BOUND, RATE_BOUND, TILT_BOUND, BAD_COMMAND = range(7)


@dataclass(frozen=True)
class Limits:
    """Bounds beyond which a flight counts as diverged (and stops).

    Attributes
    ----------
    max_position : float
        |x|, |y| or |z| above this [m] ends the flight.
    max_speed : float
        any velocity component above this [m/s].
    max_rate : float
        any body rate above this [rad/s].
    max_tilt : float
        |roll| or |pitch| above this [rad]; infinite by default, since the paper's
        model has no singularity at 90 degrees.
    """

    max_position: float = 1.0e4
    max_speed: float = 1.0e3
    max_rate: float = 1.0e3
    max_tilt: float = math.inf

    def __post_init__(self) -> None:
        for name in ("max_position", "max_speed", "max_rate", "max_tilt"):
            value = getattr(self, name)
            if not value > 0:
                raise InputError(f"limit '{name}' must be > 0, got {value!r}")

    def array(self) -> np.ndarray:
        return np.array([self.max_position, self.max_speed, self.max_rate, self.max_tilt])


SMALL_TURN = 0.03
"""Largest change of an angle over an RK4 stage [rad] for which :func:`turned` uses the
angle-addition series (beyond it, the library's sine and cosine)."""


@njit(cache=True, inline="always")
def turned(angle, s, c, d):
    """sin and cos of ``angle`` = a + d, given s = sin a and c = cos a.

    For |d| <= SMALL_TURN by the angle-addition formulas with the series of sin d and
    cos d - 1 (truncation below 1e-20 there, so the result is the library's to a rounding),
    at a fraction of the cost of a sine and a cosine; else from ``angle`` directly.
    """
    if abs(d) > SMALL_TURN:
        return math.sin(angle), math.cos(angle)
    d2 = d * d
    sd = d * (1.0 - d2 * (1.0 / 6.0) * (1.0 - d2 * (1.0 / 20.0) * (1.0 - d2 * (1.0 / 42.0))))
    cm1 = -d2 * 0.5 * (1.0 - d2 * (1.0 / 12.0) * (1.0 - d2 * (1.0 / 30.0) * (1.0 - d2 * (1.0 / 56.0))))
    return s + (s * cm1 + c * sd), c + (c * cm1 - s * sd)


# rows of the RK4 workspace: the four stage derivatives, the stage state, and the sines
# and cosines of the state's phi, theta and psi carried from one step to the next
K1, K2, K3, K4, XT, TRIG = range(6)
WORK_ROWS = 6
TRIG_REFRESH = 256
"""The engine computes the angles' sines and cosines afresh every this many RK4 steps and
carries them by :func:`turned` in between (each turn adds a rounding, ~1e-16)."""


@njit(cache=True, error_model="numpy")
def rk4_step(x, u, vp, ext, full, h, work, fresh):
    """One classical Runge-Kutta step of length h [s], in place on x.

    ``work`` is a (WORK_ROWS, STATE_SIZE) scratch array: the stage derivatives k1..k4, the
    stage state and, in row TRIG, sin and cos of x's phi, theta and psi.

    The plant needs those sines and cosines at every stage. With ``fresh`` they are
    computed from x; otherwise they are the ones the previous step left in row TRIG. A
    stage's angles differ from x's by w k[angle] (w = 0, h/2, h/2, h), and the next step's
    by the step's increment, so their sines and cosines follow by :func:`turned`. The four
    stages run through one loop, so the step holds one copy of the plant: it compiles once,
    and the engine calls it as one function with few arguments.
    """
    xt, trig = work[XT], work[TRIG]
    if fresh:
        trig[0], trig[1] = math.sin(x[PHI]), math.cos(x[PHI])
        trig[2], trig[3] = math.sin(x[THETA]), math.cos(x[THETA])
        trig[4], trig[5] = math.sin(x[PSI]), math.cos(x[PSI])
    sa, ca, sb, cb, sc, cc = trig[0], trig[1], trig[2], trig[3], trig[4], trig[5]
    for stage in range(4):
        s1, c1, s2, c2, s3, c3 = sa, ca, sb, cb, sc, cc
        if stage == 0:
            for j in range(STATE_SIZE):
                xt[j] = x[j]
        else:
            w = h if stage == 3 else 0.5 * h
            k_in = work[stage - 1]
            for j in range(STATE_SIZE):
                xt[j] = x[j] + w * k_in[j]
            s1, c1 = turned(xt[PHI], sa, ca, w * k_in[PHI])
            s2, c2 = turned(xt[THETA], sb, cb, w * k_in[THETA])
            s3, c3 = turned(xt[PSI], sc, cc, w * k_in[PSI])
        derivative_at(xt, s1, c1, s2, c2, s3, c3, u, vp, ext, full, work[stage])
    c = h / 6.0
    for j in range(STATE_SIZE):
        xt[j] = c * (work[K1, j] + 2.0 * (work[K2, j] + work[K3, j]) + work[K4, j])   # the increment
        x[j] += xt[j]
    trig[0], trig[1] = turned(x[PHI], sa, ca, xt[PHI])
    trig[2], trig[3] = turned(x[THETA], sb, cb, xt[THETA])
    trig[4], trig[5] = turned(x[PSI], sc, cc, xt[PSI])


@njit(DISTURBANCE_SIG, cache=True)
def still_air(t, dt, x, dp, dmem, rng, ext):
    """No disturbance: no force, torque or wind; every rotor healthy."""
    for j in range(EXT_SIZE):
        ext[j] = 0.0
    for j in range(EXT_E1, EXT_E1 + 4):
        ext[j] = 1.0


@njit(cache=True, inline="always")
def check_state(x, limits):
    """0 if the state is sound, else the divergence status code."""
    for j in range(x.shape[0]):
        if not math.isfinite(x[j]):
            return NONFINITE
    if abs(x[X]) > limits[0] or abs(x[Y]) > limits[0] or abs(x[Z]) > limits[0]:
        return POSITION_BOUND
    if abs(x[VX]) > limits[1] or abs(x[VY]) > limits[1] or abs(x[VZ]) > limits[1]:
        return SPEED_BOUND
    if abs(x[P]) > limits[2] or abs(x[Q]) > limits[2] or abs(x[R]) > limits[2]:
        return RATE_BOUND
    if abs(x[PHI]) > limits[3] or abs(x[THETA]) > limits[3]:
        return TILT_BOUND
    return FINISHED


@njit(cache=True, inline="always")
def hold_duties(cmd, u):
    """Clip the commanded duties into u (in [0, 1]); return (clipped?, finite?)."""
    clipped = False
    for j in range(4):
        v = cmd[j]
        if not math.isfinite(v):
            return clipped, False
        if v < 0.0:
            v = 0.0
            clipped = True
        elif v > 1.0:
            v = 1.0
            clipped = True
        u[j] = v
    return clipped, True


@njit(cache=True, inline="always")
def log_row(log, i, row, v):
    """log[i, row, :] = v, element by element (a slice would take a reference on the shared
    log array at every logged period)."""
    for j in range(v.shape[0]):
        log[i, row, j] = v[j]


@njit(cache=True, inline="always")
def blank_rows(log, i, first):
    """NaN in the rows of vehicle i from ``first`` on: the log is allocated empty, and a
    vehicle that stopped early leaves its last rows unwritten."""
    for row in range(first, log.shape[1]):
        for j in range(log.shape[2]):
            log[i, row, j] = np.nan


_f8v = types.float64[::1]
_f8m = types.float64[:, ::1]
_f8c = types.float64[:, :, ::1]
_i8v = types.int64[::1]
_u8m = types.uint64[:, ::1]

KERNEL_SIG = types.void(
    _f8v, _f8m, _f8m, _f8m, ControllerType, _f8m, _f8m, MissionType, _f8m,
    DisturbanceType, _f8m, _f8m, _u8m, _f8m, types.int64, types.boolean,
    types.float64, types.int64, _f8v,
    _f8c, _f8c, _f8c, _f8m, _i8v, _f8v, _f8m,
)


@njit(KERNEL_SIG, cache=True, parallel=True, error_model="numpy")
def _kernel(t_grid, x0, vp, vp_ctrl, controller, gains, mem, mission, mp,
            disturbance, dp, dmem, rng, sensor_std, sensor_delay, full,
            max_step, log_every, limits,
            log_x, log_cmd, log_ref, x_final, status, t_stop, saturated):
    n_vehicles = x0.shape[0]
    n_periods = t_grid.shape[0] - 1
    for i in prange(n_vehicles):
        x = x0[i].copy()
        seen = np.empty(STATE_SIZE)
        history = np.empty((sensor_delay + 1, STATE_SIZE))   # ring buffer of past states
        for d in range(sensor_delay + 1):
            history[d, :] = x
        ref = np.zeros(REF_SIZE)
        cmd = np.zeros(CMD_SIZE)
        u = np.zeros(4)
        ext = np.zeros(EXT_SIZE)
        work = np.empty((WORK_ROWS, STATE_SIZE))
        vpi, vci, gi, mi, mpi = vp[i], vp_ctrl[i], gains[i], mem[i], mp[i]
        dpi, dmi, rngi, stdi = dp[i], dmem[i], rng[i], sensor_std[i]
        noisy = False
        for j in range(STATE_SIZE):
            if stdi[j] != 0.0:
                noisy = True
        code = FINISHED
        t_end = t_grid[n_periods]
        rows_x = rows = 0
        slot = 0                       # = k % (sensor_delay + 1), kept as a counter: the
        next_log = 0                   # step has no integer division in it
        steps = 0                      # RK4 steps since the angles' trig was computed afresh
        for k in range(n_periods + 1):
            t = t_grid[k]
            dt = t_grid[k + 1] - t if k < n_periods else t - t_grid[k - 1]
            mission(t, mpi, ref)
            # what the controller sees: the state sensor_delay periods ago, plus noise
            if sensor_delay == 0:
                for j in range(STATE_SIZE):
                    seen[j] = x[j]
            else:
                for j in range(STATE_SIZE):
                    history[slot, j] = x[j]
                slot = slot + 1 if slot < sensor_delay else 0
                old = slot if k >= sensor_delay else 0     # the oldest state kept
                for j in range(STATE_SIZE):
                    seen[j] = history[old, j]
            if noisy:
                for j in range(STATE_SIZE):
                    if stdi[j] != 0.0:
                        seen[j] += stdi[j] * gauss(rngi)
            for j in range(CMD_SIZE):
                cmd[j] = 0.0
            controller(t, dt, seen, ref, vci, gi, mi, cmd)
            if k == next_log:
                log_row(log_x, i, rows, x)
                log_row(log_cmd, i, rows, cmd)
                log_row(log_ref, i, rows, ref)
                rows += 1
                rows_x = rows
                next_log += log_every
            if k == n_periods:
                break
            clipped, finite = hold_duties(cmd, u)
            if not finite:
                code = BAD_COMMAND
                t_end = t
                break
            if clipped:
                saturated[i, 0] += dt
            if cmd[CMD_FLAGS] != 0.0:
                saturated[i, 1] += dt
            disturbance(t, dt, x, dpi, dmi, rngi, ext)
            n_sub = max(1, int(math.ceil(dt / max_step - 1e-9)))
            h = dt / n_sub
            for _ in range(n_sub):
                rk4_step(x, u, vpi, ext, full, h, work, steps == 0)
                steps = steps + 1 if steps < TRIG_REFRESH - 1 else 0
            code = check_state(x, limits)
            if code != FINISHED:
                t_end = t_grid[k + 1]
                if k + 1 == next_log:           # keep the state that broke the bound
                    log_row(log_x, i, rows, x)
                    rows_x += 1
                break
        blank_rows(log_x, i, rows_x)               # rows after a stop: NaN
        blank_rows(log_cmd, i, rows)
        blank_rows(log_ref, i, rows)
        x_final[i, :] = x
        status[i] = code
        t_stop[i] = t_end


def time_grid(duration: float, dt: float, t0: float = 0.0) -> np.ndarray:
    """Uniform control instants t0, t0 + dt, ..., t0 + duration.

    ``duration`` must be a whole number of periods (to 1e-9 relative) so the grid ends
    exactly at t0 + duration.
    """
    if not (math.isfinite(duration) and duration > 0):
        raise InputError(f"duration must be a positive number of seconds, got {duration!r}")
    if not (math.isfinite(dt) and dt > 0):
        raise InputError(f"dt must be a positive number of seconds, got {dt!r}")
    if dt > duration:
        raise InputError(f"dt ({dt:g} s) is larger than the duration ({duration:g} s)")
    n = round(duration / dt)
    if abs(n * dt - duration) > 1e-9 * max(1.0, duration):
        raise InputError(f"duration ({duration:g} s) is not a whole number of dt ({dt:g} s) periods")
    return t0 + dt * np.arange(n + 1, dtype=float)


def _batch(name: str, a, n: int, width: int | None) -> np.ndarray:
    """Broadcast a vector or (N, w) array to a C-contiguous (n, w) float64 array."""
    arr = np.asarray(a, dtype=float)
    if arr.ndim == 1:
        arr = np.broadcast_to(arr, (n, arr.shape[0]))
    if arr.ndim != 2 or arr.shape[0] != n or (width is not None and arr.shape[1] != width):
        want = f"({n}, {width})" if width is not None else f"({n}, w)"
        raise InputError(f"{name} has shape {np.shape(a)}, expected {want} or one row")
    return np.array(arr, dtype=float, order="C")  # a writable copy, never a broadcast view


def simulate(t_grid, x0, vp, controller, gains, mission, mp, *, memory=None,
             vp_ctrl=None, disturbance=None, disturbance_params=None, disturbance_memory=None,
             seed: int = 0, first_vehicle: int = 0, sensor_std=None, sensor_delay: int = 0,
             full_dynamics: bool = False,
             max_step: float = 1e-3, log_every: int = 1, limits: Limits | None = None,
             meta: dict | None = None) -> SimResult:
    """Fly N vehicles over the control instants ``t_grid`` and return a :class:`SimResult`.

    This is the array-level entry point that :func:`quadcruise.fly` and
    :func:`quadcruise.replay` build on.

    Parameters
    ----------
    t_grid : (M+1,) array
        Strictly increasing control instants [s]; the command is held in between.
    x0 : (16,) or (N, 16) array
        Initial states (one row is shared by all vehicles).
    vp : (N, PARAM_SIZE) array
        Vehicle parameter rows, from :meth:`Vehicle.rows`.
    controller : compiled function with ``CONTROLLER_SIG``
    gains : (G,) or (N, G) array
        The controller's parameters.
    mission : compiled function with ``MISSION_SIG``
    mp : (Mp,) or (N, Mp) array
        The mission's parameters.
    memory : (C,) or (N, C) array, optional
        The controller's initial memory (integrators); zeros of width 0 by default.
    vp_ctrl : (N, PARAM_SIZE) array, optional
        The parameters the controller believes in (its model); ``vp`` by default. With
        model error the plant flies ``vp`` while the controller computes with these.
    disturbance : compiled function with ``DISTURBANCE_SIG``, optional
        External force, torque, wind and rotor effectiveness; still air by default.
    disturbance_params, disturbance_memory : (D,) / (N, D) arrays, optional
        Its parameters and initial state.
    seed, first_vehicle : int
        Vehicle i's random stream is seeded from (seed, first_vehicle + i) only, so a
        population split into chunks draws the same numbers (see :mod:`quadcruise.rng`).
    sensor_std : (16,) or (N, 16) array, optional
        Standard deviation of white noise added to each state the controller sees.
    sensor_delay : int
        The controller sees the state this many control periods late.
    full_dynamics : bool
        Exact Euler-angle kinematics instead of the paper's phi' = p, theta' = q, psi' = r.
    max_step : float
        Longest RK4 substep [s]; each period is split into equal substeps.
    log_every : int
        Log every this many control periods (1: all). The first instant is always logged.
    limits : Limits
        Divergence bounds.
    meta : dict
        Recorded in the result (config, seed, version).
    """
    t_grid = np.ascontiguousarray(t_grid, dtype=float)
    if t_grid.ndim != 1 or t_grid.shape[0] < 2:
        raise InputError("the time grid needs at least two instants")
    if not np.all(np.isfinite(t_grid)) or np.any(np.diff(t_grid) <= 0):
        raise InputError("the time grid must be finite and strictly increasing")
    if not (math.isfinite(max_step) and max_step > 0):
        raise InputError(f"max_step must be a positive number of seconds, got {max_step!r}")
    if int(log_every) != log_every or log_every < 1:
        raise InputError(f"log_every must be a positive integer, got {log_every!r}")
    vp = np.ascontiguousarray(vp, dtype=float)
    n = vp.shape[0]
    x0 = _batch("initial state", x0, n, STATE_SIZE)
    if not np.all(np.isfinite(x0)):
        raise InputError("the initial state must be finite")
    gains = _batch("controller gains", gains, n, None)
    mp = _batch("mission parameters", mp, n, None)
    mem = _batch("controller memory", np.zeros(0) if memory is None else memory, n, None)
    vp_ctrl = vp if vp_ctrl is None else _batch("controller parameters", vp_ctrl, n, vp.shape[1])
    dp = _batch("disturbance parameters", np.zeros(0) if disturbance_params is None else disturbance_params, n, None)
    dmem = _batch("disturbance memory", np.zeros(0) if disturbance_memory is None else disturbance_memory, n, None)
    std = _batch("sensor noise", np.zeros(STATE_SIZE) if sensor_std is None else sensor_std, n, STATE_SIZE)
    if not np.all(np.isfinite(std)) or np.any(std < 0):
        raise InputError("sensor noise standard deviations must be finite and >= 0")
    if int(sensor_delay) != sensor_delay or sensor_delay < 0:
        raise InputError(f"sensor delay must be a whole number of periods >= 0, got {sensor_delay!r}")
    rng = vehicle_states(seed, n, first_vehicle)
    limits = limits or Limits()

    n_periods = t_grid.shape[0] - 1
    n_log = n_periods // log_every + 1
    log_x = np.empty((n, n_log, STATE_SIZE))      # every row is written by the kernel:
    log_cmd = np.empty((n, n_log, CMD_SIZE))      # logged, or NaN after a stop
    log_ref = np.empty((n, n_log, REF_SIZE))
    x_final = np.empty((n, STATE_SIZE))
    status = np.zeros(n, dtype=np.int64)
    t_stop = np.empty(n)
    saturated = np.zeros((n, 2))
    _kernel(t_grid, x0, vp, vp_ctrl, controller, gains, mem, mission, mp,
            disturbance or still_air, dp, dmem, rng, std, int(sensor_delay), bool(full_dynamics),
            float(max_step), int(log_every), limits.array(),
            log_x, log_cmd, log_ref, x_final, status, t_stop, saturated)
    return SimResult(
        t=t_grid[::log_every][:n_log].copy(), states=log_x, commands=log_cmd, references=log_ref,
        final_state=x_final, status=status, t_stop=t_stop, memory=mem, disturbance_memory=dmem,
        duty_clipped_s=saturated[:, 0].copy(), controller_limited_s=saturated[:, 1].copy(),
        meta=dict(meta or {}),
    )


__all__ = ["Limits", "simulate", "time_grid", "rk4_step", "STATUS_REASONS"]
