"""Closed-loop flights of rotor-plant vehicles: the engine's controllers, missions, disturbances
and sensors around :func:`quadcruise.model.rotor_plant.rotor_derivative`, one vehicle or N, in
one compiled function.

Each control period t_k, for each vehicle:

1. the mission gives the reference;
2. the rotor state becomes the paper-layout state (:func:`paper_state`): position, velocity,
   the ZYX Euler angles of the quaternion (the rotation R = Rz(psi) Ry(theta) Rx(phi) of eqs
   (5)-(7); yaw unwrapped, continuous from period to period), the body rates, and F1..F4 the
   thrusts e_i kf w_i^2 of rotors 1..4 (rotors beyond the fourth are in the rotor log only);
   the controller sees it ``sensor_delay`` periods late, with noise, exactly as in the paper's
   kernel (the same ring buffer and random stream);
3. the controller computes the duties of its "+" equivalent vehicle
   (:mod:`quadcruise.model.equivalent`); they are not clipped: the matrix of
   :func:`~quadcruise.model.equivalent.duty_to_thrust` turns them into the controller vehicle's
   rotor thrusts, and each thrust into a speed sqrt(f / kf) held in the flown vehicle's
   [w_min, w_max] (the time any speed is held is counted, as the paper's clipped duties are);
   a non-finite duty stops the vehicle (``BAD_COMMAND``);
4. the disturbance function (``DISTURBANCE_SIG``, read with the paper-layout true state) gives
   force, torque, wind and the effectiveness of rotors 1..4 (rotors beyond stay at 1);
5. RK4 substeps no longer than ``max_step`` fly the commanded speeds on the true vehicle, the
   quaternion renormalised after each, and with a ground each step that ends below z = 0 meets
   it (:func:`quadcruise.sim.rotor_engine.ground_contact`): held, or ``CRASHED``;
6. the state is checked against :class:`~quadcruise.sim.inputs.Limits`: non-finite, position,
   speed, body rate, and tilt: the angle between body z and world z above ``max_tilt``.

The paper-layout states, commands and references are logged as the paper kernel logs them, and
the rotor state beside them. The per-vehicle code it shares with the paper kernel
(:func:`quadcruise.sim.engine._kernel`) is in :mod:`quadcruise.sim.period`, inlined into both.
"""

from __future__ import annotations

import math

import numpy as np
from numba import njit

from quadcruise import layout as L
from quadcruise.layout import Row
from quadcruise.model.rotor_plant import (
    QW,
    QX,
    QY,
    QZ,
    ROTOR_P_KF,
    ROTOR_P_N_ROTORS,
    ROTOR_P_W_MAX,
    ROTOR_P_W_MIN,
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
)
from quadcruise.sim.engine import still_air
from quadcruise.sim.kernel_args import ROTOR_KERNEL_SIG
from quadcruise.sim.observe import rotor_force, rotor_shake
from quadcruise.sim.period import (
    blank_logs,
    blank_rows,
    body_bounds,
    close_vehicle,
    give_back,
    log_row,
    put_row,
    read_history,
    substeps,
    take,
    take_row,
    write_history,
)
from quadcruise.sim.rng import next_normal
from quadcruise.sim.rotor_engine import ROTOR_WORK_ROWS, ground_contact, rotor_rk4_step
from quadcruise.sim.status import ExitStatus
from quadcruise.sim.threads import PIECES_PER_THREAD, fly_in_pieces
from quadcruise.sim.track_figures import TP_ON, put_track, take_plan, take_track, track_period

FINISHED, NONFINITE, POSITION_BOUND, SPEED_BOUND, RATE_BOUND, TILT_BOUND, BAD_COMMAND, CRASHED = (
    int(ExitStatus[name])
    for name in (
        "FINISHED",
        "NONFINITE",
        "POSITION_BOUND",
        "SPEED_BOUND",
        "RATE_BOUND",
        "TILT_BOUND",
        "BAD_COMMAND",
        "CRASHED",
    )
)


@njit(cache=True, inline="always")
def paper_state(xr, rp, ext, psi_last, out):
    """The paper-layout state (:data:`quadcruise.layout.STATE_NAMES`) of a rotor-plant state.

    Parameters
    ----------
    xr : numpy.ndarray
        (13 + n,) the rotor state, its quaternion of unit length.
    rp : numpy.ndarray
        The vehicle's parameter row (its kf and rotor count).
    ext : numpy.ndarray
        (EXT_SIZE,) the external inputs held over the last period (its rotor effectiveness).
    psi_last : float
        The yaw [rad] of the previous call: the new yaw is the one within pi of it.
    out : numpy.ndarray
        (STATE_SIZE,) output: x, y, z, vx, vy, vz, phi, theta, psi (ZYX), p, q, r, and
        F1..F4 = e_i kf w_i^2 [N] of rotors 1..4 (0 for a rotor that does not exist).

    Returns
    -------
    float
        The yaw written [rad].
    """
    qw, qx, qy, qz = xr[QW], xr[QX], xr[QY], xr[QZ]
    for j in range(6):
        out[L.X + j] = xr[RX + j]
    out[L.PHI] = math.atan2(2.0 * (qw * qx + qy * qz), 1.0 - 2.0 * (qx * qx + qy * qy))
    s = 2.0 * (qw * qy - qx * qz)
    out[L.THETA] = math.asin(max(-1.0, min(1.0, s)))
    raw = math.atan2(2.0 * (qw * qz + qx * qy), 1.0 - 2.0 * (qy * qy + qz * qz))
    turn = raw - psi_last
    psi = psi_last + turn - 2.0 * math.pi * math.floor(turn / (2.0 * math.pi) + 0.5)
    out[L.PSI] = psi
    out[L.P], out[L.Q], out[L.R] = xr[RP], xr[RQ], xr[RR]
    n = int(rp[ROTOR_P_N_ROTORS])
    kf = rp[ROTOR_P_KF]
    for i in range(4):
        if i < n:
            w = xr[ROTOR_W1 + i]
            out[L.F1 + i] = ext[L.EXT_E1 + i] * kf * w * w
        else:
            out[L.F1 + i] = 0.0
    return psi


@njit(cache=True)
def paper_states(x, rp, psi0):
    """The paper-layout states of N rotor states at rest from disturbances (every rotor healthy).

    Parameters
    ----------
    x : numpy.ndarray
        (N, 13 + n) rotor states.
    rp : numpy.ndarray
        (N, P) their vehicles' parameter rows.
    psi0 : numpy.ndarray
        (N,) the yaws [rad] each quaternion's is read near.

    Returns
    -------
    numpy.ndarray
        (N, 16) as :func:`paper_state` writes them.
    """
    out = np.empty((x.shape[0], L.STATE_SIZE))
    ext = np.zeros(L.EXT_SIZE)
    for j in range(4):
        ext[L.EXT_E1 + j] = 1.0
    for i in range(x.shape[0]):
        paper_state(x[i], rp[i], ext, psi0[i], out[i])
    return out


ROTOR_CARRY = Row.of("rotor kernel carry", "psi", ("true", L.STATE_SIZE), ("ext", L.EXT_SIZE), prefix="C_")
"""A row of the rotor kernel's ``carry``: the unwrapped yaw [rad], the paper-layout true state, the
external inputs of the last period; the sensor-delay ring buffer follows at ``C_HISTORY``."""
C_PSI, C_TRUE, C_EXT = ROTOR_CARRY.offsets
C_HISTORY = ROTOR_CARRY.size


def rotor_carry_width(sensor_delay: int) -> int:
    """Width of the rotor kernel's ``carry`` rows.

    Parameters
    ----------
    sensor_delay : int
        The sensor delay [control periods].

    Returns
    -------
    int
        1 + 16 + EXT_SIZE + (sensor_delay + 1) 16.

    Examples
    --------
    >>> rotor_carry_width(0) - rotor_carry_width(1)
    -16
    """
    return C_HISTORY + (int(sensor_delay) + 1) * L.STATE_SIZE


@njit(ROTOR_KERNEL_SIG, cache=True, nogil=True, error_model="numpy")
def _rotor_flight_kernel(
    first,
    stop,
    t_grid,
    x0,
    psi0,
    rp,
    alloc,
    vp_ctrl,
    controller,
    gains,
    mem,
    mission,
    mp,
    disturbance,
    disturbed,
    dp,
    dmem,
    rng,
    sensor_std,
    sensor_delay,
    observer,
    observed,
    op,
    omem,
    orng,
    max_step,
    log_every,
    limits,
    ground,
    touchdown,
    n_step,
    clock,
    carry,
    track,
    track_plan,
    log_x,
    log_rotor,
    log_cmd,
    log_ref,
    log_obs,
    x_final,
    seen_final,
    status,
    t_stop,
    saturated,
):
    """Fly vehicles first .. stop - 1 of the batch (the module's steps; the other arguments are
    :class:`~quadcruise.sim.kernel_args.RotorKernelArgs`, one row per vehicle, ``alloc`` the n x 4 duty-to-thrust matrix
    row by row and the controller vehicle's kf).

    The resume contract of the paper kernel (:func:`quadcruise.sim.engine._kernel`): each
    vehicle flies on from its period ``clock[i, 0]`` for at most ``n_step`` periods, and
    everything it carries from one period to the next is read at the start and written back at
    the end: its rotor state (``x0`` in, ``x_final`` out: they may be one array), ``clock`` (the
    period reached, the RK4 steps flown), ``carry`` (:func:`rotor_carry_width`: the unwrapped yaw,
    the paper-layout true state, the external inputs of the last period, the sensor-delay ring
    buffer), ``mem``, ``dmem``, ``rng``, ``saturated`` (accumulated) and ``status`` (a vehicle
    whose status is not FINISHED, or whose grid is flown, is left as it is). A vehicle at period
    0 starts afresh from ``x0`` and ``psi0``. The log rows count from the first instant flown in
    this call."""
    n_periods = t_grid.shape[0] - 1
    size = x0.shape[1]
    n = size - ROTOR_W1
    x = np.empty(size)
    true = np.empty(L.STATE_SIZE)
    seen = np.empty(L.STATE_SIZE)
    history = np.empty((sensor_delay + 1, L.STATE_SIZE))
    ref = np.empty(L.REF_SIZE)
    cmd = np.empty(L.CMD_SIZE)
    ext = np.empty(L.EXT_SIZE)
    ext_r = np.empty(9 + n)
    w_cmd = np.empty(n)
    work = np.empty((ROTOR_WORK_ROWS, size))
    mi, dmi, rngi = np.empty(mem.shape[1]), np.empty(dmem.shape[1]), np.empty(rng.shape[1], dtype=np.uint64)
    watching, plan = track_plan[TP_ON] != 0.0, take_plan(track_plan)  # the track checks, or none
    omi, orngi, obs = np.empty(omem.shape[1]), np.empty(orng.shape[1], dtype=np.uint64), np.empty(L.OBSERVATION_SIZE)
    max_position, max_speed, max_rate, cos_tilt = limits[0], limits[1], limits[2], math.cos(limits[3])
    for i in range(first, stop):
        k0 = clock[i, 0]
        if status[i] != FINISHED or k0 >= n_periods:  # stopped, or its grid flown
            blank_logs(i, 0, 0, log_x, log_cmd, log_ref)
            blank_rows(log_rotor, i, 0)
            blank_rows(log_obs, i, 0)
            continue
        k1 = min(k0 + n_step, n_periods)
        k_reached = k1
        take_row(x0, i, x)
        rpi, ai, vci, gi, mpi, dpi, stdi = rp[i], alloc[i], vp_ctrl[i], gains[i], mp[i], dp[i], sensor_std[i]
        take(i, mem, dmem, rng, mi, dmi, rngi)
        opi = op[i]
        if observed:  # the observation stage's memory and stream (quadcruise.sim.observe)
            take_row(omem, i, omi)
            take_row(orng, i, orngi)
        kf_ctrl = ai[4 * n]
        w_min, w_max = rpi[ROTOR_P_W_MIN], rpi[ROTOR_P_W_MAX]
        if k0 == 0:  # a fresh start: the true state of x0, seen through an empty delay line
            still_air(0.0, 0.0, true, dpi, dmi, rngi, ext)
            psi = paper_state(x, rpi, ext, psi0[i], true)
            for d in range(sensor_delay + 1):
                for j in range(L.STATE_SIZE):
                    history[d, j] = true[j]
        else:
            psi = carry[i, C_PSI]
            for j in range(L.STATE_SIZE):
                true[j] = carry[i, C_TRUE + j]
            for j in range(L.EXT_SIZE):
                ext[j] = carry[i, C_EXT + j]
            read_history(carry, i, C_HISTORY, history)
        clipped_s, limited_s = saturated[i, 0], saturated[i, 1]
        fig = take_track(track, i, watching)
        steps = clock[i, 1]
        code = FINISHED
        t_end = t_grid[n_periods]
        rows_x = rows = 0
        for k in range(k0, k1 + 1 if k1 == n_periods else k1):
            t = t_grid[k]
            dt = t_grid[k + 1] - t if k < n_periods else t - t_grid[k - 1]
            mission(t, mpi, ref)
            if observed:  # what the controller sees: the estimate from the vehicle's sensors
                if k == 0:  # the specific force at the start (then at each period's end, below)
                    for j in range(9):
                        ext_r[j] = ext[j]
                    for r in range(n):
                        ext_r[9 + r] = ext[L.EXT_E1 + r] if r < 4 else 1.0
                        w_cmd[r] = x[ROTOR_W1 + r]
                    rotor_force(x, w_cmd, rpi, ext_r, work[0], omi)
                    rotor_shake(x, rpi, 0.0, omi)
                observer(t, k, k % log_every == 0, true, opi, omi, orngi, seen, obs)
            else:  # what the controller sees: the state sensor_delay periods ago, plus noise
                newest = k % (sensor_delay + 1)  # in the ring buffer
                oldest = (k + 1) % (sensor_delay + 1) if k >= sensor_delay else 0
                for j in range(L.STATE_SIZE):
                    history[newest, j] = true[j]
                state = rngi[0]
                for j in range(L.STATE_SIZE):
                    seen[j] = history[oldest, j]
                    if stdi[j] != 0.0:
                        draw, state = next_normal(state)
                        seen[j] += stdi[j] * draw
                rngi[0] = state
            for j in range(L.CMD_SIZE):
                cmd[j] = 0.0
            controller(t, dt, seen, ref, vci, gi, mi, cmd)
            if watching:  # lost track, off track: at every period, whatever the log keeps
                fig = track_period(
                    k, t, true[L.X], true[L.Y], true[L.Z], ref[L.REF_X], ref[L.REF_X + 1], ref[L.REF_X + 2], fig, plan
                )
            if k % log_every == 0:
                log_row(log_x, i, rows, true)
                log_row(log_cmd, i, rows, cmd)
                log_row(log_ref, i, rows, ref)
                log_row(log_rotor, i, rows, x)
                if observed:
                    log_row(log_obs, i, rows, obs)
                rows += 1
                rows_x = rows
            if k == n_periods:
                break
            u0, u1, u2, u3 = cmd[0], cmd[1], cmd[2], cmd[3]
            if not (math.isfinite(u0) and math.isfinite(u1) and math.isfinite(u2) and math.isfinite(u3)):
                code = BAD_COMMAND
                t_end = t
                k_reached = k
                break
            held = False
            for r in range(n):
                f = ai[4 * r] * u0 + ai[4 * r + 1] * u1 + ai[4 * r + 2] * u2 + ai[4 * r + 3] * u3
                w = math.sqrt(f / kf_ctrl) if f > 0.0 else 0.0
                if f < 0.0 or w < w_min or w > w_max:
                    held = True
                    w = min(max(w, w_min), w_max)
                w_cmd[r] = w
            if held:
                clipped_s += dt
            if cmd[L.CMD_FLAGS] != 0.0:
                limited_s += dt
            if disturbed:
                disturbance(t, dt, true, dpi, dmi, rngi, ext)
            for j in range(9):
                ext_r[j] = ext[j]
            for r in range(n):
                ext_r[9 + r] = ext[L.EXT_E1 + r] if r < 4 else 1.0
            n_sub, h = substeps(dt, max_step)
            for sub in range(n_sub):
                rotor_rk4_step(x, w_cmd, rpi, ext_r, h, work)
                steps += 1
                if ground and x[RZ] < 0.0 and ground_contact(x, touchdown[i]):
                    code = CRASHED
                    t_end = t + (sub + 1) * h
                    k_reached = k + 1
                    break
            if code == CRASHED:  # mid-period: its state is the final one, at t_stop
                psi = paper_state(x, rpi, ext, psi, true)
                break
            psi = paper_state(x, rpi, ext, psi, true)
            if observed:  # what the IMU will read at the next instant
                rotor_force(x, w_cmd, rpi, ext_r, work[0], omi)
                rotor_shake(x, rpi, dt, omi)
            finite = True
            for j in range(size):
                finite = finite and math.isfinite(x[j])
            code = body_bounds(
                finite,
                x[RX],
                x[RY],
                x[RZ],
                x[RVX],
                x[RVY],
                x[RVZ],
                x[RP],
                x[RQ],
                x[RR],
                max_position,
                max_speed,
                max_rate,
            )
            if code == FINISHED and 1.0 - 2.0 * (x[QX] * x[QX] + x[QY] * x[QY]) < cos_tilt:
                code = TILT_BOUND
            if code != FINISHED:
                t_end = t_grid[k + 1]
                k_reached = k + 1
                if (k + 1) % log_every == 0:  # keep the state that broke the bound
                    log_row(log_x, i, rows, true)
                    log_row(log_rotor, i, rows, x)
                    rows_x += 1
                break
        blank_logs(i, rows_x, rows, log_x, log_cmd, log_ref)
        blank_rows(log_rotor, i, rows_x)
        if observed:
            blank_rows(log_obs, i, rows)
            put_row(omem, i, omi)
            put_row(orng, i, orngi)
        put_row(x_final, i, x)
        put_row(seen_final, i, true)
        give_back(i, mi, dmi, rngi, mem, dmem, rng)
        carry[i, C_PSI] = psi
        for j in range(L.STATE_SIZE):
            carry[i, C_TRUE + j] = true[j]
        for j in range(L.EXT_SIZE):
            carry[i, C_EXT + j] = ext[j]
        write_history(carry, i, C_HISTORY, history)
        put_track(track, i, watching, fig)
        close_vehicle(i, k_reached, steps, clipped_s, limited_s, code, t_end, clock, saturated, status, t_stop)


def fly_rotor_pieces(
    n: int, args: tuple, pieces_per_thread: int = PIECES_PER_THREAD, after_piece=None, threads=None
) -> None:
    """The rotor kernel over vehicles 0..n-1 on numba's number of threads, in ranges handed out in
    turn (as :func:`quadcruise.sim.engine.fly_vehicles` does for the paper's kernel); each
    vehicle's arithmetic does not depend on its range, so a batch reproduces single flights bit
    for bit.

    Parameters
    ----------
    n : int
        Number of vehicles.
    args : RotorKernelArgs
        The kernel's arguments after the vehicle range (:class:`~quadcruise.sim.kernel_args.RotorKernelArgs`).
    pieces_per_thread : int
        Ranges per thread: fewer for short calls (a step), where each call's fixed cost counts.
    after_piece : callable, optional
        Called as ``after_piece(first, stop)`` on the thread that flew vehicles first..stop-1,
        right after it (as :func:`quadcruise.sim.engine.fly_vehicles` calls it).
    threads : int, optional
        At most this many threads; numba's number by default.
    """
    fly_in_pieces(_rotor_flight_kernel, n, args, pieces_per_thread, after_piece, threads)


__all__ = ["fly_rotor_pieces", "paper_state", "paper_states", "rotor_carry_width"]
