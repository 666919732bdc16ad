"""The simulation engine: fixed-step RK4 for one vehicle or N, in one compiled function.

Time runs on a grid of control instants t_0 < t_1 < ... < t_M shared by the batch. At
each t_k the engine asks the mission for the reference and the controller for a command,
then holds the command over [t_k, t_{k+1}] while RK4 integrates the plant in equal
substeps no longer than ``max_step``. After every period it checks the state; a vehicle
whose state turns non-finite or leaves the bounds in :class:`Limits` stops there, with its
status, time and reason recorded, while the rest of the batch flies on.

The single-vehicle flight is the N = 1 case of the same kernel. The kernel flies the
vehicles of one range of the batch, one after another, without the GIL; vehicles are
independent, so :func:`fly_vehicles` splits a batch into pieces that numba's number of
threads (``numba.set_num_threads``) fly at once. Each vehicle's arithmetic does not depend on the
batch it is in or the piece it falls in, so a batch reproduces single flights bit for bit.
(A ``prange`` kernel would do the same, but numba's parallel passes on a body this size
lengthen the cold compile, and with one vehicle the idle OpenMP thread spins:
docs/performance.md.)

Controllers and missions are compiled functions with the signatures in
:mod:`quadcruise.layout`, passed as first-class function values: one cached kernel
serves every controller, a user's own included.
"""

from __future__ import annotations

import itertools
import math
from concurrent.futures import ThreadPoolExecutor
from dataclasses import dataclass

import numpy as np
from numba import config, get_num_threads, njit

from quadcruise import checks
from quadcruise.errors import InputError
from quadcruise.layout import (
    CMD_FLAGS,
    CMD_SIZE,
    DISTURBANCE_SIG,
    EXT_E1,
    EXT_SIZE,
    PHI,
    PSI,
    REF_SIZE,
    STATE_SIZE,
    THETA,
    VX,
    VY,
    VZ,
    P,
    Q,
    R,
    X,
    Y,
    Z,
)
from quadcruise.model.plant import EULER_PITCH_LIMIT, derivative_at
from quadcruise.sim.fastmath import TRIG_REFRESH, turned
from quadcruise.sim.kernel_args import KERNEL_SIG, KernelArgs
from quadcruise.sim.result import SimResult
from quadcruise.sim.rng import next_normal, vehicle_states
from quadcruise.sim.status import STATUS_REASONS, ExitStatus

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


@dataclass(frozen=True)
class Limits:
    """Bounds beyond which a flight counts as diverged (and stops).

    Parameters
    ----------
    max_position : float
        |x|, |y| or |z| above this [m] ends the flight.
    max_speed : float
        any velocity component above this [m/s].
    max_rate : float
        any body rate above this [rad/s].
    max_tilt : float
        |roll| or |pitch| above this [rad]; 90 degrees by default: beyond it the vehicle is
        on its side or upside down, its thrust pulls it towards the ground, and no mission
        is being flown (the paper's model has no singularity there: it is the flight that
        has failed, whatever the mission). (The full plant, ``full_dynamics=True``, stops
        anyway at |pitch| > :data:`quadcruise.model.plant.EULER_PITCH_LIMIT`, 85 degrees,
        with the status ``PITCH_SINGULAR``.)
    """

    max_position: float = 1.0e4
    max_speed: float = 1.0e3
    max_rate: float = 1.0e3
    max_tilt: float = math.pi / 2.0

    def __post_init__(self) -> None:
        for name in ("max_position", "max_speed", "max_rate", "max_tilt"):
            object.__setattr__(self, name, checks.number("Limits()", name, getattr(self, name), "pos", infinite=True))

    def array(self) -> np.ndarray:
        """The four bounds as the kernel reads them.

        Returns
        -------
        numpy.ndarray
            (4,) max_position [m], max_speed [m/s], max_rate [rad/s], max_tilt [rad].
        """
        return np.array([self.max_position, self.max_speed, self.max_rate, self.max_tilt])


# rows of the RK4 workspace: the four stage derivatives, the stage state, and the sines
# and cosines of the state's phi, theta and psi carried from one step to the next
K1, K2, K3, K4, XT, TRIG = range(6)
WORK_ROWS = 6
TRIG_WIDTH = 6  # the entries of row TRIG in use, carried from one call of the kernel to the next


def carry_width(sensor_delay: int) -> int:
    """Width of the kernel's ``carry`` rows: the 6 carried sines and cosines of the angles,
    then the sensor-delay ring buffer of ``sensor_delay + 1`` states.

    Parameters
    ----------
    sensor_delay : int
        The sensor delay [control periods].

    Returns
    -------
    int

    Examples
    --------
    >>> carry_width(0), carry_width(2)
    (22, 54)
    """
    return TRIG_WIDTH + (int(sensor_delay) + 1) * STATE_SIZE


def fresh_carry(x0: np.ndarray, sensor_delay: int) -> np.ndarray:
    """The ``carry`` rows of vehicles about to start from the states ``x0``: every slot of the
    ring buffer holds x0 (the controller sees the initial state until the delay has passed).

    Parameters
    ----------
    x0 : numpy.ndarray
        (N, 16) initial states.
    sensor_delay : int
        The sensor delay [control periods].

    Returns
    -------
    numpy.ndarray
        (N, :func:`carry_width`) rows; the sines and cosines are zero: a vehicle whose
        ``clock`` RK4 count is 0 computes them afresh.
    """
    n = x0.shape[0]
    out = np.zeros((n, carry_width(sensor_delay)))
    out[:, TRIG_WIDTH:] = np.tile(x0, (1, int(sensor_delay) + 1))
    return out


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
        xt[j] = c * (work[K1, j] + 2.0 * (work[K2, j] + work[K3, j]) + work[K4, j])  # the increment
        x[j] += xt[j]
    trig[0], trig[1] = turned(x[PHI], sa, ca, xt[PHI])
    trig[2], trig[3] = turned(x[THETA], sb, cb, xt[THETA])
    trig[4], trig[5] = turned(x[PSI], sc, cc, xt[PSI])


@njit(DISTURBANCE_SIG, cache=True)
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
    for j in range(EXT_SIZE):
        ext[j] = 0.0
    for j in range(EXT_E1, EXT_E1 + 4):
        ext[j] = 1.0


# The per-period helpers below follow the scalar-only rule of quadcruise.sim.fastmath.


@njit(cache=True, inline="always")
def beyond(a, b, c, bound):
    """Whether |a|, |b| or |c| exceeds bound.

    Parameters
    ----------
    a, b, c : float
        Three components (of a position [m], velocity [m/s], rates [rad/s] or angles [rad]).
    bound : float
        The bound, in their unit.

    Returns
    -------
    bool
    """
    return abs(a) > bound or abs(b) > bound or abs(c) > bound


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


@njit(cache=True, inline="always")
def log_row(log, i, row, v):
    """log[i, row, :] = v, element by element (a slice takes a reference on the shared log
    array: the scalar-only rule of :mod:`quadcruise.sim.fastmath`).

    Parameters
    ----------
    log : numpy.ndarray
        (N, L, W) log of the batch.
    i, row : int
        The vehicle and the logged instant.
    v : numpy.ndarray
        (W,) the values to log.
    """
    for j in range(v.shape[0]):
        log[i, row, j] = v[j]


@njit(cache=True, inline="always")
def put_row(a, i, v):
    """a[i, :] = v, element by element: numba compiles a slice assignment with a shape
    check of its own, which costs seconds of compile time.

    Parameters
    ----------
    a : numpy.ndarray
        (N, W) array of the batch.
    i : int
        The vehicle.
    v : numpy.ndarray
        (W,) the values.
    """
    for j in range(v.shape[0]):
        a[i, j] = v[j]


@njit(cache=True, inline="always")
def blank_rows(log, i, first):
    """NaN in the rows of vehicle i from ``first`` on: the log is allocated empty, and a
    vehicle that stopped early leaves its last rows unwritten.

    Parameters
    ----------
    log : numpy.ndarray
        (N, L, W) log of the batch.
    i : int
        The vehicle.
    first : int
        The first logged instant to blank.
    """
    for row in range(first, log.shape[1]):
        for j in range(log.shape[2]):
            log[i, row, j] = np.nan


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
    full,
    max_step,
    log_every,
    limits,
    n_step,
    clock,
    carry,
    log_x,
    log_cmd,
    log_ref,
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
    x = np.empty(STATE_SIZE)
    seen = np.empty(STATE_SIZE)
    history = np.empty((sensor_delay + 1, STATE_SIZE))  # ring buffer of past states
    ref = np.empty(REF_SIZE)
    cmd = np.empty(CMD_SIZE)
    u = np.empty(4)
    ext = np.empty(EXT_SIZE)
    work = np.empty((WORK_ROWS, STATE_SIZE))
    mi, dmi, rngi = np.empty(mem.shape[1]), np.empty(dmem.shape[1]), np.empty(rng.shape[1], dtype=np.uint64)
    for i in range(first, stop):
        k0 = clock[i, 0]
        if status[i] != FINISHED or k0 >= n_periods:  # stopped, or its grid flown
            blank_rows(log_x, i, 0)
            blank_rows(log_cmd, i, 0)
            blank_rows(log_ref, i, 0)
            continue
        k1 = min(k0 + n_step, n_periods)
        k_reached = k1
        for j in range(STATE_SIZE):
            x[j] = x0[i, j]
        for d in range(sensor_delay + 1):
            for j in range(STATE_SIZE):
                history[d, j] = carry[i, TRIG_WIDTH + d * STATE_SIZE + j]
        for j in range(REF_SIZE):
            ref[j] = 0.0
        for j in range(4):
            u[j] = 0.0
        for j in range(EXT_SIZE):
            ext[j] = 0.0
        for j in range(TRIG_WIDTH):
            work[TRIG, j] = carry[i, j]
        vpi, vci, gi, mpi, dpi, stdi = vp[i], vp_ctrl[i], gains[i], mp[i], dp[i], sensor_std[i]
        # what changes every period is this vehicle's own copy, the memories written back at
        # the end (a kept trick against false sharing: quadcruise.sim.fastmath)
        for j in range(mi.shape[0]):
            mi[j] = mem[i, j]
        for j in range(dmi.shape[0]):
            dmi[j] = dmem[i, j]
        for j in range(rngi.shape[0]):
            rngi[j] = rng[i, j]
        clipped_s, limited_s = saturated[i, 0], saturated[i, 1]
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
            # what the controller sees: the state sensor_delay periods ago, plus noise
            newest = k % (sensor_delay + 1)  # in the ring buffer
            oldest = (k + 1) % (sensor_delay + 1) if k >= sensor_delay else 0
            for j in range(STATE_SIZE):
                history[newest, j] = x[j]
            state = rngi[0]
            for j in range(STATE_SIZE):
                seen[j] = history[oldest, j]
                if stdi[j] != 0.0:
                    draw, state = next_normal(state)
                    seen[j] += stdi[j] * draw
            rngi[0] = state
            for j in range(CMD_SIZE):
                cmd[j] = 0.0
            controller(t, dt, seen, ref, vci, gi, mi, cmd)
            if k % log_every == 0:
                log_row(log_x, i, rows, x)
                log_row(log_cmd, i, rows, cmd)
                log_row(log_ref, i, rows, ref)
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
            if cmd[CMD_FLAGS] != 0.0:
                limited_s += dt
            if disturbed:
                disturbance(t, dt, x, dpi, dmi, rngi, ext)
            n_sub = max(1, int(math.ceil(dt / max_step - 1e-9)))
            h = dt / n_sub
            for _ in range(n_sub):
                rk4_step(x, u, vpi, ext, full, h, work, steps % TRIG_REFRESH == 0)
                steps += 1
            finite = True
            for j in range(STATE_SIZE):
                finite = finite and math.isfinite(x[j])
            if not finite:
                code = NONFINITE
            elif beyond(x[X], x[Y], x[Z], max_position):
                code = POSITION_BOUND
            elif beyond(x[VX], x[VY], x[VZ], max_speed):
                code = SPEED_BOUND
            elif beyond(x[P], x[Q], x[R], max_rate):
                code = RATE_BOUND
            elif beyond(x[PHI], x[THETA], 0.0, max_tilt):
                code = TILT_BOUND
            elif full and abs(x[THETA]) > EULER_PITCH_LIMIT:  # the full plant's 1/cos theta
                code = PITCH_SINGULAR
            if code != FINISHED:
                t_end = t_grid[k + 1]
                k_reached = k + 1
                if (k + 1) % log_every == 0:  # keep the state that broke the bound
                    log_row(log_x, i, rows, x)
                    rows_x += 1
                break
        blank_rows(log_x, i, rows_x)  # rows after a stop: NaN
        blank_rows(log_cmd, i, rows)
        blank_rows(log_ref, i, rows)
        put_row(x_final, i, x)
        put_row(mem, i, mi)
        put_row(dmem, i, dmi)
        put_row(rng, i, rngi)
        clock[i, 0], clock[i, 1] = k_reached, steps
        for j in range(TRIG_WIDTH):
            carry[i, j] = work[TRIG, j]
        for d in range(sensor_delay + 1):
            for j in range(STATE_SIZE):
                carry[i, TRIG_WIDTH + d * STATE_SIZE + j] = history[d, j]
        saturated[i, 0], saturated[i, 1] = clipped_s, limited_s
        status[i] = code
        t_stop[i] = t_end


PIECES_PER_THREAD = 8
"""A batch is cut into this many pieces per thread, taken in turn by whichever thread is
free, so a thread whose vehicles stopped early (or ran slower) does not leave the others
waiting at the end."""

_pool: ThreadPoolExecutor | None = None


def fly_vehicles(n: int, args: tuple, pieces_per_thread: int = PIECES_PER_THREAD, after_piece=None) -> None:
    """Run the kernel over vehicles 0..n-1 of the batch arrays in ``args``, on numba's
    number of threads (``numba.get_num_threads()``): one range on this thread when that is
    1 or n is 1, else ``pieces_per_thread`` ranges per thread, handed out in turn.

    Parameters
    ----------
    n : int
        Number of vehicles.
    args : KernelArgs
        The kernel's arguments after the vehicle range (its batch arrays, by role).
    pieces_per_thread : int
        Ranges per thread: fewer for short calls (a step), where each call's fixed cost counts.
    after_piece : callable, optional
        Called as ``after_piece(first, stop)`` on the thread that flew vehicles first..stop-1,
        right after it (their rows still in its cache).
    """
    global _pool
    threads = min(n, get_num_threads())
    if threads <= 1:
        _kernel(0, n, *args)
        if after_piece is not None:
            after_piece(0, n)
        return
    bounds = np.linspace(0, n, min(n, pieces_per_thread * threads) + 1).round().astype(np.int64)
    pieces = itertools.count()  # next() on it is atomic under the GIL

    def work() -> None:
        while (k := next(pieces)) < bounds.shape[0] - 1:
            first, stop = int(bounds[k]), int(bounds[k + 1])
            _kernel(first, stop, *args)
            if after_piece is not None:
                after_piece(first, stop)

    if _pool is None:  # numba's threads can never exceed this
        _pool = ThreadPoolExecutor(max_workers=max(1, config.NUMBA_NUM_THREADS - 1), thread_name_prefix="quadcruise")
    helpers = [_pool.submit(work) for _ in range(threads - 1)]
    work()
    for h in helpers:
        h.result()


MAX_STEPS = 1e9
"""Most control periods one flight may have (a day at 1 kHz is 8.6e7): beyond it the time grid
alone would need 8 GB."""


def time_grid(duration: float, dt: float, t0: float = 0.0) -> np.ndarray:
    """Uniform control instants t0, t0 + dt, ..., t0 + duration.

    ``duration`` must be a whole number of periods (to 1e-9 relative) so the grid ends
    exactly at t0 + duration.

    Parameters
    ----------
    duration : float
        Flight time [s], > 0.
    dt : float
        Control period [s], in (0, duration].
    t0 : float
        First instant [s].

    Returns
    -------
    numpy.ndarray
        The instants [s], duration / dt + 1 of them.

    Examples
    --------
    >>> time_grid(0.003, 0.001).tolist()
    [0.0, 0.001, 0.002, 0.003]
    """
    if not (math.isfinite(duration) and duration > 0):
        raise InputError(f"duration must be a positive number of seconds, got {duration!r}")
    if not (math.isfinite(dt) and dt > 0):
        raise InputError(f"dt must be a positive number of seconds, got {dt!r}")
    if dt > duration:
        raise InputError(f"dt ({dt:g} s) is larger than the duration ({duration:g} s)")
    if duration / dt > MAX_STEPS:
        raise InputError(
            f"{duration:g} s at dt = {dt:g} s is {duration / dt:.3g} control periods, more than "
            f"{MAX_STEPS:.0e}: shorten the duration or lengthen dt"
        )
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


def batch_inputs(
    t_grid,
    x0,
    vp,
    gains,
    mp,
    *,
    memory=None,
    vp_ctrl=None,
    disturbance=None,
    disturbance_params=None,
    disturbance_memory=None,
    seed: int = 0,
    first_vehicle=0,
    sensor_std=None,
    sensor_delay: int = 0,
    max_step: float = 1e-3,
    log_every: int = 1,
) -> dict:
    """The kernel's batch arrays, checked and made C-contiguous writable copies: what
    :func:`simulate` and :class:`quadcruise.sim.stepper.Stepper` hand to the kernel.

    Parameters
    ----------
    t_grid, x0, vp, gains, mp, memory, vp_ctrl, disturbance, disturbance_params, disturbance_memory : array or None
        As in :func:`simulate` (``disturbance`` only says whether there is one).
    seed, first_vehicle, sensor_std, sensor_delay, max_step, log_every : optional
        As in :func:`simulate`.

    Returns
    -------
    dict
        The arrays by name (``t_grid``, ``x0``, ``vp``, ``gains``, ``mp``, ``memory``, ``vp_ctrl``,
        ``disturbance_params``, ``disturbance_memory``, ``sensor_std``, ``rng``), the number of
        vehicles ``n``, ``disturbed`` and ``drawn`` (whether anything draws random numbers).

    Raises
    ------
    InputError
        One line naming the argument that is wrong.
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
    # the random streams, when anything draws from them (SeedSequence: ~25 us a vehicle)
    disturbed = disturbance is not None
    drawn = disturbed or bool(np.any(std))
    rng = vehicle_states(seed, n, first_vehicle) if drawn else np.zeros((n, 1), dtype=np.uint64)
    return {
        "t_grid": t_grid,
        "x0": x0,
        "vp": vp,
        "n": n,
        "gains": gains,
        "mp": mp,
        "memory": mem,
        "vp_ctrl": vp_ctrl,
        "disturbance_params": dp,
        "disturbance_memory": dmem,
        "sensor_std": std,
        "rng": rng,
        "disturbed": disturbed,
        "drawn": drawn,
    }


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
    log_x = np.empty((n, n_log, STATE_SIZE))  # every row is written by the kernel:
    log_cmd = np.empty((n, n_log, CMD_SIZE))  # logged, or NaN after a stop
    log_ref = np.empty((n, n_log, REF_SIZE))
    x_final = np.empty((n, STATE_SIZE))
    status = np.zeros(n, dtype=np.int64)
    t_stop = np.empty(n)
    saturated = np.zeros((n, 2))
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
            full=bool(full_dynamics),
            max_step=float(max_step),
            log_every=int(log_every),
            limits=limits.array(),
            n_step=n_periods,
            clock=np.zeros((n, 2), dtype=np.int64),
            carry=fresh_carry(x0, int(sensor_delay)),
            log_x=log_x,
            log_cmd=log_cmd,
            log_ref=log_ref,
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
    )


__all__ = [
    "Limits",
    "simulate",
    "time_grid",
    "rk4_step",
    "STATUS_REASONS",
    "batch_inputs",
    "carry_width",
    "fresh_carry",
]
