"""The simulation engine: fixed-step RK4 for one vehicle or N, in one compiled function.

Time runs on a grid of control instants t_0 < t_1 < ... < t_M shared by the batch. At
each t_k the engine asks the mission for the reference and the controller for a command,
then holds the command over [t_k, t_{k+1}] while RK4 integrates the plant in equal
substeps no longer than ``max_step``. After every period it checks the state; a vehicle
whose state turns non-finite or leaves the bounds in :class:`~quadcruise.sim.inputs.Limits` stops there, with its
status, time and reason recorded, while the rest of the batch flies on.

The single-vehicle flight is the N = 1 case of the same kernel. The kernel flies the
vehicles of one range of the batch, one after another, without the GIL; vehicles are
independent, so :func:`fly_vehicles` splits a batch into pieces that numba's number of
threads fly at once (:mod:`quadcruise.sim.threads`), and a batch reproduces single flights bit
for bit. Its inputs are checked and laid out by :mod:`quadcruise.sim.inputs`.

Controllers and missions are compiled functions with the signatures in
:mod:`quadcruise.layout`, passed as first-class function values: one cached kernel
serves every controller, a user's own included.
"""

from __future__ import annotations

import math

import numpy as np
from numba import njit

from quadcruise import layout as L
from quadcruise.model.plant import EULER_PITCH_LIMIT, derivative_at
from quadcruise.sim.fastmath import TRIG_REFRESH, turned
from quadcruise.sim.inputs import TRIG_WIDTH, Limits, batch_inputs, carry_width, fresh_carry, time_grid
from quadcruise.sim.kernel_args import KERNEL_SIG, KernelArgs
from quadcruise.sim.observe import Observation, paper_force
from quadcruise.sim.period import (
    beyond,
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
from quadcruise.sim.result import SimResult
from quadcruise.sim.rng import next_normal
from quadcruise.sim.status import STATUS_REASONS, ExitStatus
from quadcruise.sim.threads import PIECES_PER_THREAD, fly_in_pieces
from quadcruise.sim.track_figures import TP_ON, put_track, take_plan, take_track, track_arrays, track_period

# exit status codes as plain ints, which the kernel compiles as constants (see sim/status.py)
FINISHED, NONFINITE, POSITION_BOUND, SPEED_BOUND, RATE_BOUND, TILT_BOUND, BAD_COMMAND, PITCH_SINGULAR = (
    int(ExitStatus[name])
    for name in (
        "FINISHED",
        "NONFINITE",
        "POSITION_BOUND",
        "SPEED_BOUND",
        "RATE_BOUND",
        "TILT_BOUND",
        "BAD_COMMAND",
        "PITCH_SINGULAR",
    )
)


# rows of the RK4 workspace: the four stage derivatives, the stage state, and the sines
# and cosines of the state's phi, theta and psi carried from one step to the next
K1, K2, K3, K4, XT, TRIG = range(6)
WORK_ROWS = 6


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

    Parameters
    ----------
    x : numpy.ndarray
        (16,) the state (SI units of :data:`quadcruise.layout.STATE_UNITS`), advanced in place.
    u : numpy.ndarray
        (4,) PWM duties [-], held over the step.
    vp : numpy.ndarray
        The vehicle parameter row (PARAM_SIZE).
    ext : numpy.ndarray
        (EXT_SIZE,) external inputs held over the step: force [N], torque [N m], wind [m/s],
        rotor effectiveness [-].
    full : bool
        Exact Euler-angle kinematics instead of the paper's.
    h : float
        Step length [s].
    work : numpy.ndarray
        (WORK_ROWS, STATE_SIZE) scratch array, its row TRIG carried between steps.
    fresh : bool
        Compute the angles' sines and cosines from x instead of carrying them.
    """
    xt, trig = work[XT], work[TRIG]
    if fresh:
        trig[0], trig[1] = math.sin(x[L.PHI]), math.cos(x[L.PHI])
        trig[2], trig[3] = math.sin(x[L.THETA]), math.cos(x[L.THETA])
        trig[4], trig[5] = math.sin(x[L.PSI]), math.cos(x[L.PSI])
    sa, ca, sb, cb, sc, cc = trig[0], trig[1], trig[2], trig[3], trig[4], trig[5]
    for stage in range(4):
        s1, c1, s2, c2, s3, c3 = sa, ca, sb, cb, sc, cc
        if stage == 0:
            for j in range(L.STATE_SIZE):
                xt[j] = x[j]
        else:
            w = h if stage == 3 else 0.5 * h
            k_in = work[stage - 1]
            for j in range(L.STATE_SIZE):
                xt[j] = x[j] + w * k_in[j]
            s1, c1 = turned(xt[L.PHI], sa, ca, w * k_in[L.PHI])
            s2, c2 = turned(xt[L.THETA], sb, cb, w * k_in[L.THETA])
            s3, c3 = turned(xt[L.PSI], sc, cc, w * k_in[L.PSI])
        derivative_at(xt, s1, c1, s2, c2, s3, c3, u, vp, ext, full, work[stage])
    c = h / 6.0
    for j in range(L.STATE_SIZE):
        xt[j] = c * (work[K1, j] + 2.0 * (work[K2, j] + work[K3, j]) + work[K4, j])  # the increment
        x[j] += xt[j]
    trig[0], trig[1] = turned(x[L.PHI], sa, ca, xt[L.PHI])
    trig[2], trig[3] = turned(x[L.THETA], sb, cb, xt[L.THETA])
    trig[4], trig[5] = turned(x[L.PSI], sc, cc, xt[L.PSI])


@njit(L.DISTURBANCE_SIG, cache=True)
def still_air(t, dt, x, dp, dmem, rng, ext):
    """No disturbance: no force, torque or wind; every rotor healthy (``DISTURBANCE_SIG``).

    Parameters
    ----------
    t, dt : float
        The period's start and length [s] (not read).
    x : numpy.ndarray
        The true state (not read).
    dp, dmem : numpy.ndarray
        The disturbance's parameters and memory (not read).
    rng : numpy.ndarray
        The vehicle's random generator state (not read).
    ext : numpy.ndarray
        (EXT_SIZE,) output: zeros, and the four rotor effectiveness entries 1.
    """
    for j in range(L.EXT_SIZE):
        ext[j] = 0.0
    for j in range(L.EXT_E1, L.EXT_E1 + 4):
        ext[j] = 1.0


# The per-period helpers below follow the scalar-only rule of quadcruise.sim.fastmath; those
# both plants' kernels share are in quadcruise.sim.period.


@njit(cache=True, inline="always")
def clip_duty(v):
    """A commanded duty held in [0, 1].

    Parameters
    ----------
    v : float
        The duty the controller asked for [-].

    Returns
    -------
    (float, bool, bool)
        The duty applied, whether it was clipped, whether the command was finite (a
        non-finite one applies 0 and stops the vehicle).
    """
    if not math.isfinite(v):
        return 0.0, False, False
    if v < 0.0:
        return 0.0, True, True
    if v > 1.0:
        return 1.0, True, True
    return v, False, True


@njit(KERNEL_SIG, cache=True, nogil=True, error_model="numpy")
def _kernel(
    first,
    stop,
    t_grid,
    x0,
    vp,
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
    full,
    max_step,
    log_every,
    limits,
    n_step,
    clock,
    carry,
    track,
    track_plan,
    log_x,
    log_cmd,
    log_ref,
    log_obs,
    x_final,
    status,
    t_stop,
    saturated,
):
    """Fly vehicles first .. stop - 1 of the batch; the other arguments are
    :class:`~quadcruise.sim.kernel_args.KernelArgs`, by role.

    Each vehicle flies on from its period ``clock[i, 0]`` for at most ``n_step`` periods,
    then stops at the next instant without asking for its command there, unless that
    instant ends the grid (then its reference and command are logged, as a whole flight's
    last row). Everything a vehicle carries from one period to the next is read at the start
    and written back at the end, so that a flight cut into calls is bit for bit the flight
    flown in one: its state (``x0`` in, ``x_final`` out: they may be one array), ``clock``
    (the period reached and the RK4 steps flown, for the ``TRIG_REFRESH`` count), ``carry``
    (:func:`carry_width`: the sines and cosines of row TRIG, then the sensor-delay ring
    buffer), ``mem``, ``dmem``, ``rng``, ``saturated`` (accumulated) and ``status`` (a
    vehicle whose status is not FINISHED, or whose grid is flown, is left as it is). The log
    rows count from the first instant flown in this call.

    A flat list: grouped into tuples (numba allows tuples of arrays, and of functions, though
    with a warning at every call) the kernel ran slower (docs/performance.md).
    """
    n_periods = t_grid.shape[0] - 1
    # scratch of this call, reused by its vehicles (a step of one period would otherwise spend
    # more on allocating it than on flying); every entry is set for each vehicle before use
    x = np.empty(L.STATE_SIZE)
    seen = np.empty(L.STATE_SIZE)
    history = np.empty((sensor_delay + 1, L.STATE_SIZE))  # ring buffer of past states
    ref = np.empty(L.REF_SIZE)
    cmd = np.empty(L.CMD_SIZE)
    u = np.empty(4)
    ext = np.empty(L.EXT_SIZE)
    work = np.empty((WORK_ROWS, L.STATE_SIZE))
    mi, dmi, rngi = np.empty(mem.shape[1]), np.empty(dmem.shape[1]), np.empty(rng.shape[1], dtype=np.uint64)
    watching, plan = track_plan[TP_ON] != 0.0, take_plan(track_plan)  # the track checks, or none
    omi, orngi, obs = np.empty(omem.shape[1]), np.empty(orng.shape[1], dtype=np.uint64), np.empty(L.OBSERVATION_SIZE)
    for i in range(first, stop):
        k0 = clock[i, 0]
        if status[i] != FINISHED or k0 >= n_periods:  # stopped, or its grid flown
            blank_logs(i, 0, 0, log_x, log_cmd, log_ref)
            blank_rows(log_obs, i, 0)
            continue
        k1 = min(k0 + n_step, n_periods)
        k_reached = k1
        take_row(x0, i, x)
        read_history(carry, i, TRIG_WIDTH, history)
        for j in range(L.REF_SIZE):
            ref[j] = 0.0
        for j in range(4):
            u[j] = 0.0
        for j in range(L.EXT_SIZE):
            ext[j] = 0.0
        for j in range(TRIG_WIDTH):
            work[TRIG, j] = carry[i, j]
        vpi, vci, gi, mpi, dpi, stdi = vp[i], vp_ctrl[i], gains[i], mp[i], dp[i], sensor_std[i]
        take(i, mem, dmem, rng, mi, dmi, rngi)
        opi = op[i]
        if observed:  # the observation stage's memory and stream (quadcruise.sim.observe)
            take_row(omem, i, omi)
            take_row(orng, i, orngi)
        clipped_s, limited_s = saturated[i, 0], saturated[i, 1]
        fig = take_track(track, i, watching)
        max_position, max_speed, max_rate, max_tilt = limits[0], limits[1], limits[2], limits[3]
        code = FINISHED
        t_end = t_grid[n_periods]
        rows_x = rows = 0
        steps = clock[i, 1]  # RK4 steps flown
        if not disturbed:  # set once (a kept trick: quadcruise.sim.fastmath)
            still_air(0.0, 0.0, x, dpi, dmi, rngi, ext)
        for k in range(k0, k1 + 1 if k1 == n_periods else k1):
            t = t_grid[k]
            dt = t_grid[k + 1] - t if k < n_periods else t - t_grid[k - 1]
            mission(t, mpi, ref)
            if observed:  # what the controller sees: the estimate from the vehicle's sensors
                if k == 0:  # the specific force at the start (then at each period's end, below)
                    paper_force(x, u, vpi, ext, full, work[K1], omi)
                observer(t, k, k % log_every == 0, x, opi, omi, orngi, seen, obs)
            else:  # what the controller sees: the state sensor_delay periods ago, plus noise
                newest = k % (sensor_delay + 1)  # in the ring buffer
                oldest = (k + 1) % (sensor_delay + 1) if k >= sensor_delay else 0
                for j in range(L.STATE_SIZE):
                    history[newest, j] = x[j]
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
                    k, t, x[L.X], x[L.Y], x[L.Z], ref[L.REF_X], ref[L.REF_X + 1], ref[L.REF_X + 2], fig, plan
                )
            if k % log_every == 0:
                log_row(log_x, i, rows, x)
                log_row(log_cmd, i, rows, cmd)
                log_row(log_ref, i, rows, ref)
                if observed:
                    log_row(log_obs, i, rows, obs)
                rows += 1
                rows_x = rows
            if k == n_periods:
                break
            clipped, finite = False, True
            for j in range(4):
                u[j], c, f = clip_duty(cmd[j])
                clipped, finite = clipped or c, finite and f
            if not finite:
                code = BAD_COMMAND
                t_end = t
                k_reached = k
                break
            if clipped:
                clipped_s += dt
            if cmd[L.CMD_FLAGS] != 0.0:
                limited_s += dt
            if disturbed:
                disturbance(t, dt, x, dpi, dmi, rngi, ext)
            n_sub, h = substeps(dt, max_step)
            for _ in range(n_sub):
                rk4_step(x, u, vpi, ext, full, h, work, steps % TRIG_REFRESH == 0)
                steps += 1
            if observed:  # what the IMU will read at the next instant
                paper_force(x, u, vpi, ext, full, work[K1], omi)
            finite = True
            for j in range(L.STATE_SIZE):
                finite = finite and math.isfinite(x[j])
            code = body_bounds(
                finite,
                x[L.X],
                x[L.Y],
                x[L.Z],
                x[L.VX],
                x[L.VY],
                x[L.VZ],
                x[L.P],
                x[L.Q],
                x[L.R],
                max_position,
                max_speed,
                max_rate,
            )
            if code == FINISHED and beyond(x[L.PHI], x[L.THETA], 0.0, max_tilt):
                code = TILT_BOUND
            elif code == FINISHED and full and abs(x[L.THETA]) > EULER_PITCH_LIMIT:  # the full plant's 1/cos theta
                code = PITCH_SINGULAR
            if code != FINISHED:
                t_end = t_grid[k + 1]
                k_reached = k + 1
                if (k + 1) % log_every == 0:  # keep the state that broke the bound
                    log_row(log_x, i, rows, x)
                    rows_x += 1
                break
        blank_logs(i, rows_x, rows, log_x, log_cmd, log_ref)  # rows after a stop: NaN
        put_row(x_final, i, x)
        give_back(i, mi, dmi, rngi, mem, dmem, rng)
        if observed:
            blank_rows(log_obs, i, rows)
            put_row(omem, i, omi)
            put_row(orng, i, orngi)
        for j in range(TRIG_WIDTH):
            carry[i, j] = work[TRIG, j]
        write_history(carry, i, TRIG_WIDTH, history)
        put_track(track, i, watching, fig)
        close_vehicle(i, k_reached, steps, clipped_s, limited_s, code, t_end, clock, saturated, status, t_stop)


def fly_vehicles(
    n: int, args: tuple, pieces_per_thread: int = PIECES_PER_THREAD, after_piece=None, threads=None
) -> None:
    """Fly vehicles 0..n-1 of the batch arrays in ``args`` with the kernel, on numba's threads.

    Parameters
    ----------
    n, args, pieces_per_thread, after_piece, threads
        As in :func:`quadcruise.sim.threads.fly_in_pieces`.
    """
    fly_in_pieces(_kernel, n, args, pieces_per_thread, after_piece, threads)


def simulate(
    t_grid,
    x0,
    vp,
    controller,
    gains,
    mission,
    mp,
    *,
    memory=None,
    vp_ctrl=None,
    disturbance=None,
    disturbance_params=None,
    disturbance_memory=None,
    seed: int = 0,
    first_vehicle: int = 0,
    sensor_std=None,
    sensor_delay: int = 0,
    full_dynamics: bool = False,
    max_step: float = 1e-3,
    log_every: int = 1,
    limits: Limits | None = None,
    meta: dict | None = None,
    track: tuple | None = None,
    observation: Observation | None = None,
) -> SimResult:
    """Fly N vehicles over the control instants ``t_grid`` and return a :class:`SimResult`.

    This is the array-level entry point that :func:`quadcruise.fly` and
    :func:`quadcruise.workflows.replay` build on.

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
        population split into chunks draws the same numbers (see :mod:`quadcruise.sim.rng`).
        ``first_vehicle`` may also be an (N,) array: vehicle i's stream is then
        (seed, first_vehicle[i]).
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
    track : tuple of numpy.ndarray, optional
        ``(rows, plan)``: the track checks' running figures of each vehicle, updated in place at
        every period whatever ``log_every`` keeps, and the flight's plan
        (:mod:`quadcruise.sim.track_figures`); none by default.
    observation : Observation, optional
        The vehicles' sensors and estimator (:mod:`quadcruise.sim.observe`; built by
        :func:`quadcruise.estimation.onboard.observation`): the controller then sees their
        estimate instead of the truth (``sensor_std`` and ``sensor_delay`` are not used), and
        the result's ``observations`` hold their log (the arrays given are not written).

    Returns
    -------
    SimResult
        The logged flight of every vehicle, its exit status and saturation times.
    """
    inp = batch_inputs(
        t_grid,
        x0,
        vp,
        gains,
        mp,
        memory=memory,
        vp_ctrl=vp_ctrl,
        disturbance=disturbance,
        disturbance_params=disturbance_params,
        disturbance_memory=disturbance_memory,
        seed=seed,
        first_vehicle=first_vehicle,
        sensor_std=sensor_std,
        sensor_delay=sensor_delay,
        max_step=max_step,
        log_every=log_every,
    )
    t_grid, x0, vp, n = inp["t_grid"], inp["x0"], inp["vp"], inp["n"]
    mem, dmem, rng, disturbed = inp["memory"], inp["disturbance_memory"], inp["rng"], inp["disturbed"]
    vp_ctrl, gains, mp, dp = inp["vp_ctrl"], inp["gains"], inp["mp"], inp["disturbance_params"]
    std = inp["sensor_std"]
    limits = limits or Limits()
    n_periods = t_grid.shape[0] - 1
    n_log = n_periods // log_every + 1
    log_x = np.empty((n, n_log, L.STATE_SIZE))  # every row is written by the kernel:
    log_cmd = np.empty((n, n_log, L.CMD_SIZE))  # logged, or NaN after a stop
    log_ref = np.empty((n, n_log, L.REF_SIZE))
    x_final = np.empty((n, L.STATE_SIZE))
    status = np.zeros(n, dtype=np.int64)
    t_stop = np.empty(n)
    saturated = np.zeros((n, 2))
    track_rows, track_plan = track_arrays(track, n)
    obs = (observation or Observation.none(n)).take(np.arange(n))  # copies: the flight writes them
    log_obs = obs.log(n, n_log)
    fly_vehicles(
        n,
        KernelArgs(
            t_grid=t_grid,
            x0=x0,
            vp=vp,
            vp_ctrl=vp_ctrl,
            controller=controller,
            gains=gains,
            mem=mem,
            mission=mission,
            mp=mp,
            disturbance=disturbance or still_air,
            disturbed=disturbed,
            dp=dp,
            dmem=dmem,
            rng=rng,
            sensor_std=std,
            sensor_delay=int(sensor_delay),
            observer=obs.function,
            observed=obs.active,
            op=obs.params,
            omem=obs.memory,
            orng=obs.rng,
            full=bool(full_dynamics),
            max_step=float(max_step),
            log_every=int(log_every),
            limits=limits.array(),
            n_step=n_periods,
            clock=np.zeros((n, 2), dtype=np.int64),
            carry=fresh_carry(x0, int(sensor_delay)),
            track=track_rows,
            track_plan=track_plan,
            log_x=log_x,
            log_cmd=log_cmd,
            log_ref=log_ref,
            log_obs=log_obs,
            x_final=x_final,
            status=status,
            t_stop=t_stop,
            saturated=saturated,
        ),
    )
    return SimResult(
        t=t_grid[::log_every][:n_log].copy(),
        states=log_x,
        commands=log_cmd,
        references=log_ref,
        final_state=x_final,
        status=status,
        t_stop=t_stop,
        memory=mem,
        disturbance_memory=dmem,
        duty_clipped_s=saturated[:, 0].copy(),
        controller_limited_s=saturated[:, 1].copy(),
        meta=dict(meta or {}),
        observations=log_obs if obs.active else None,
    )


__all__ = [
    "Limits",
    "fly_vehicles",
    "simulate",
    "time_grid",
    "rk4_step",
    "STATUS_REASONS",
    "batch_inputs",
    "carry_width",
    "fresh_carry",
]
