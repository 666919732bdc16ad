"""The rotor-speed plant's compiled path: fixed-step RK4 of
:func:`quadcruise.model.rotor_plant.rotor_derivative`, open loop, for one vehicle or N.

A schedule of commanded rotor speeds is held piecewise constant: row k from t_k until
t_{k+1}. Each interval is split into equal RK4 substeps no longer than ``max_step``, as the
paper plant's engine (:mod:`quadcruise.sim.engine`) splits a control period. After each step
the quaternion is scaled back to unit length (RK4 keeps it there only to its own order);
after each interval the state is logged and checked against the same :class:`Limits` and
exit codes as the paper plant's flights (:class:`quadcruise.ExitStatus`). A vehicle that
leaves them stops there, its later log rows NaN. With a ground (``touchdown_speed``), each
step that ends below z = 0 meets it (:func:`ground_contact`): held there, or ``CRASHED`` at
that step, its state then in ``final_state`` at ``t_stop`` and its log NaN from the next row
on (the row's time is not the crash's).

This path stands beside the engine's kernel and shares no code with its hot loop, so the
paper plant's flights and speed are untouched.
"""

from __future__ import annotations

import math

import numpy as np
from numba import njit

from quadcruise.checks import describe
from quadcruise.errors import InputError
from quadcruise.model.rotor_plant import (
    QW,
    QX,
    QY,
    QZ,
    ROTOR_P_N_ROTORS,
    ROTOR_W1,
    RP,
    RQ,
    RR,
    RVX,
    RVY,
    RVZ,
    RX,
    RY,
    RZ,
    rotor_stages,
)
from quadcruise.sim.inputs import Limits
from quadcruise.sim.period import body_bounds
from quadcruise.sim.rotor_result import RotorResult
from quadcruise.sim.status import ExitStatus

FINISHED, NONFINITE, POSITION_BOUND, SPEED_BOUND, RATE_BOUND, CRASHED = (
    int(ExitStatus[name])
    for name in ("FINISHED", "NONFINITE", "POSITION_BOUND", "SPEED_BOUND", "RATE_BOUND", "CRASHED")
)

ROTOR_WORK_ROWS = 4
"""Rows of the RK4 workspace: the four stage derivatives."""


@njit(cache=True, error_model="numpy")
def rotor_rk4_step(x, w_cmd, rp, ext, h, work):
    """One classical Runge-Kutta step of length h [s] of the rotor plant, in place on x,
    then the quaternion scaled to unit length.

    The stages are :func:`quadcruise.model.rotor_plant.rotor_stages`, which forms each stage
    state as it reads it; ``work`` is only indexed, never sliced (a row view costs numba's
    reference counting each time it is made: the step took twice as long with them). The
    kernels call it, as the paper kernel calls :func:`quadcruise.sim.engine.rk4_step`: inlined
    into them by numba, its arrays would be reference-counted at every substep.

    Parameters
    ----------
    x : numpy.ndarray
        (13 + n,) the state (:mod:`quadcruise.model.rotor_plant`), advanced in place.
    w_cmd : numpy.ndarray
        (n,) commanded rotor speeds [rad/s], held over the step.
    rp : numpy.ndarray
        The vehicle's parameter row.
    ext : numpy.ndarray
        (9 + n,) external force [N], torque [N m], wind [m/s], rotor effectiveness [-].
    h : float
        Step length [s].
    work : numpy.ndarray
        (ROTOR_WORK_ROWS, 13 + n) scratch array: the stage derivatives.
    """
    size = x.shape[0]
    rotor_stages(x, w_cmd, rp, ext, h, work, 4)
    c = h / 6.0
    for j in range(size):
        x[j] += c * (work[0, j] + 2.0 * (work[1, j] + work[2, j]) + work[3, j])
    norm = math.sqrt(x[QW] * x[QW] + x[QX] * x[QX] + x[QY] * x[QY] + x[QZ] * x[QZ])
    for j in range(QW, QZ + 1):
        x[j] /= norm


@njit(cache=True, error_model="numpy")
def ground_contact(x, touchdown_speed):
    """Meet the ground at z = 0 after a step that ended below it: True for a crash (the state
    is left as it is), else the vehicle is set on the ground, in place on x.

    A crash is a descent faster than ``touchdown_speed`` or the body's z axis pointing below
    the horizon (upside down). Otherwise the landing gear holds the vehicle: z = 0, no
    descent, no sliding (vx = vy = 0), no rotation, roll and pitch zero, yaw kept (as RotorPy's
    ground does). A vehicle at rest on the ground whose thrust is under its weight stays there;
    one whose thrust is over it lifts off in its next step.

    Parameters
    ----------
    x : numpy.ndarray
        (13 + n,) the state after the step, z < 0.
    touchdown_speed : float
        The fastest descent its gear survives [m/s].

    Returns
    -------
    bool
        Whether it crashed.
    """
    qw, qx, qy, qz = x[QW], x[QX], x[QY], x[QZ]
    if -x[RVZ] > touchdown_speed or 1.0 - 2.0 * (qx * qx + qy * qy) < 0.0:
        return True
    yaw = math.atan2(2.0 * (qw * qz + qx * qy), 1.0 - 2.0 * (qy * qy + qz * qz))
    x[RZ] = 0.0
    x[RVX] = x[RVY] = 0.0
    x[RVZ] = max(x[RVZ], 0.0)
    x[RP] = x[RQ] = x[RR] = 0.0
    x[QW], x[QX], x[QY], x[QZ] = math.cos(0.5 * yaw), 0.0, 0.0, math.sin(0.5 * yaw)
    return False


@njit(cache=True, nogil=True, error_model="numpy")
def _replay_kernel(t, w_cmd, x0, rp, ext, max_step, limits, ground, touchdown, log_x, x_final, status, t_stop):
    """Fly every vehicle of the batch through the schedule (arguments: :func:`replay_rotor_speeds`'s,
    one row per vehicle; outputs ``log_x``, ``x_final``, ``status``, ``t_stop``)."""
    n_rows = t.shape[0]
    size = x0.shape[1]
    max_position, max_speed, max_rate = limits[0], limits[1], limits[2]
    for i in range(x0.shape[0]):
        x = x0[i].copy()
        work = np.empty((ROTOR_WORK_ROWS, size))
        rpi, exti = rp[i], ext[i]
        code = FINISHED
        t_end = t[n_rows - 1]
        for j in range(size):
            log_x[i, 0, j] = x[j]
        logged = 1
        for k in range(n_rows - 1):
            dt = t[k + 1] - t[k]
            n_sub = max(1, int(math.ceil(dt / max_step - 1e-9)))
            h = dt / n_sub
            cmd = w_cmd[k]
            for sub in range(n_sub):
                rotor_rk4_step(x, cmd, rpi, exti, h, work)
                if ground and x[RZ] < 0.0 and ground_contact(x, touchdown[i]):
                    code = CRASHED
                    t_end = t[k] + (sub + 1) * h
                    break
            if code == CRASHED:  # mid-interval: its state is x_final at t_stop, not row k + 1's
                break
            finite = True
            for j in range(size):
                finite = finite and math.isfinite(x[j])
            code = body_bounds(  # the checks of both closed-loop kernels (sim/period.py): no tilt bound here
                finite, x[RX], x[RY], x[RZ], x[RVX], x[RVY], x[RVZ], x[RP], x[RQ], x[RR],
                max_position, max_speed, max_rate,
            )  # fmt: skip
            for j in range(size):
                log_x[i, k + 1, j] = x[j]
            logged = k + 2
            if code != FINISHED:
                t_end = t[k + 1]
                break
        for row in range(logged, n_rows):
            for j in range(size):
                log_x[i, row, j] = np.nan
        for j in range(size):
            x_final[i, j] = x[j]
        status[i] = code
        t_stop[i] = t_end


def replay_rotor_speeds(
    t,
    w_cmd,
    x0,
    rp,
    *,
    ext=None,
    max_step: float = 1e-3,
    limits: Limits | None = None,
    touchdown_speed=None,
    names: tuple[str, ...] = (),
    meta: dict | None = None,
) -> RotorResult:
    """Fly N rotor-plant vehicles open loop through a schedule of rotor speeds.

    The array-level entry point that :func:`quadcruise.workflows.replay.replay` builds on.

    Parameters
    ----------
    t : (L,) array
        Strictly increasing schedule times [s], L >= 2.
    w_cmd : (L, n) array
        Commanded rotor speeds [rad/s], row k held from t[k] to t[k+1] (the last row only
        marks the end), each within the vehicles' [w_min, w_max] (not checked here).
    x0 : (13 + n,) or (N, 13 + n) array
        Initial states.
    rp : (P,) or (N, P) array
        Parameter rows (:meth:`quadcruise.model.rotor_vehicle.RotorVehicle.row`).
    ext : (9 + n,) or (N, 9 + n) array, optional
        External force [N], torque [N m], wind [m/s], rotor effectiveness [-], held throughout;
        by default none, still air, every rotor healthy.
    max_step : float
        Longest RK4 substep [s].
    limits : Limits, optional
        Divergence bounds (position, speed, body rate; tilt is not bounded: a flip flies on).
    touchdown_speed : float or (N,) array, optional
        With it, a ground at z = 0 (:func:`ground_contact`): the fastest descent [m/s] each
        vehicle may meet it at; faster, or upside down, ends the flight ``CRASHED``. None:
        free flight, no ground.
    names : tuple of str
        The state's column names, kept in the result.
    meta : dict, optional
        Recorded in the result.

    Returns
    -------
    RotorResult
        One logged state per schedule row.

    Raises
    ------
    InputError
        Arrays whose shapes do not fit, a bad time grid or step.
    """
    t = np.ascontiguousarray(t, dtype=float)
    if t.ndim != 1 or t.shape[0] < 2 or not np.all(np.isfinite(t)) or np.any(np.diff(t) <= 0):
        raise InputError("the schedule's times must be at least two, finite and strictly increasing")
    if not (math.isfinite(max_step) and max_step > 0):
        raise InputError(f"max_step must be a positive number of seconds, got {describe(max_step)}")
    rp = np.atleast_2d(np.ascontiguousarray(rp, dtype=float))
    n = int(rp[0, ROTOR_P_N_ROTORS])
    if np.any(rp[:, ROTOR_P_N_ROTORS] != n):
        raise InputError("the vehicles of one replay must have the same number of rotors")
    x0 = np.array(np.broadcast_to(np.atleast_2d(x0), (rp.shape[0], ROTOR_W1 + n)), dtype=float, order="C")
    w_cmd = np.ascontiguousarray(w_cmd, dtype=float)
    if w_cmd.shape != (t.shape[0], n):
        raise InputError(f"rotor speeds have shape {w_cmd.shape}, expected ({t.shape[0]}, {n})")
    if ext is None:
        ext = np.r_[np.zeros(9), np.ones(n)]
    ext = np.array(np.broadcast_to(np.atleast_2d(ext), (rp.shape[0], 9 + n)), dtype=float, order="C")
    if not (np.all(np.isfinite(x0)) and np.all(np.isfinite(ext)) and np.all(np.isfinite(w_cmd))):
        raise InputError("the initial state, external inputs and rotor speeds must be finite")
    limits = limits or Limits()
    N = rp.shape[0]
    log_x = np.empty((N, t.shape[0], ROTOR_W1 + n))
    x_final = np.empty((N, ROTOR_W1 + n))
    status = np.zeros(N, dtype=np.int64)
    t_stop = np.empty(N)
    ground = touchdown_speed is not None
    touchdown = np.ascontiguousarray(
        np.broadcast_to(np.inf if touchdown_speed is None else touchdown_speed, (N,)), dtype=float
    )
    if ground and not np.all(touchdown > 0):
        raise InputError(f"touchdown speed must be > 0 m/s, got {describe(touchdown_speed)}")
    _replay_kernel(
        t, w_cmd, x0, rp, ext, float(max_step), limits.array(), ground, touchdown, log_x, x_final, status, t_stop
    )
    return RotorResult(
        t=t.copy(),
        states=log_x,
        final_state=x_final,
        status=status,
        t_stop=t_stop,
        names=tuple(names),
        meta=dict(meta or {}),
    )
