"""A flight flown in chunks of control periods, every period's rows handed to a watcher while
only every ``log_every``-th is kept: the same :class:`~quadcruise.sim.result.SimResult`, bit for
bit, as :func:`~quadcruise.sim.engine.simulate` at that ``log_every``.

The chunks go through :class:`~quadcruise.sim.stepper.Stepper` (the kernel's resume arguments),
so the whole flight's log never exists: a batch keeps a coarse log and a chunk buffer of about
:data:`CHUNK_VEHICLE_STEPS` rows, and a watcher (``fly``'s track checks) still sees each period.

Examples
--------
>>> import numpy as np
>>> from quadcruise.control import NLPD
>>> from quadcruise.missions import Circle
>>> from quadcruise.model.vehicle import Vehicle
>>> from quadcruise.sim.engine import simulate
>>> from quadcruise.sim.inputs import time_grid
>>> t, c, m, v = time_grid(0.2, 1e-3), NLPD(), Circle(), Vehicle.paper()
>>> x0 = np.zeros(16); x0[2] = 1.0; x0[12:] = v.m * v.g / 4     # hovering at 1 m
>>> args = (t, x0, v.rows(2), c.function, c.gains(), m.function, m.params())
>>> seen = []
>>> def watch(k0, first, stop, x, r): seen.append((stop - first) * x.shape[1])
>>> a = simulate_watched(*args, memory=c.memory(), log_every=50, watch=watch)
>>> b = simulate(*args, memory=c.memory(), log_every=50)
>>> bool(np.array_equal(a.states, b.states, equal_nan=True)), sum(seen)   # every vehicle's every period seen once
(True, 402)
"""

from __future__ import annotations

from collections.abc import Callable

import numpy as np

from quadcruise.layout import CMD_SIZE, OBSERVATION_SIZE, REF_SIZE, STATE_SIZE
from quadcruise.sim.result import SimResult
from quadcruise.sim.status import ExitStatus
from quadcruise.sim.stepper import Stepper

CHUNK_VEHICLE_STEPS = 2**18
"""Vehicle-steps per chunk (vehicles x periods): a chunk buffer of about 80 MB (312 bytes a row)."""
PIECES_PER_THREAD = 16
"""Ranges of vehicles per thread in a chunk: about 2.5 MB of rows each at 2 threads."""


def simulate_watched(
    t_grid,
    x0,
    vp,
    controller,
    gains,
    mission,
    mp,
    *,
    watch: Callable[[int, int, int, np.ndarray, np.ndarray], None],
    log_every: int = 1,
    meta: dict | None = None,
    chunk_vehicle_steps: int | None = None,
    pieces_per_thread: int | None = None,
    rotor_names: tuple[str, ...] = (),
    **options,
) -> SimResult:
    """:func:`~quadcruise.sim.engine.simulate`, flown in chunks, with every instant's state and
    reference shown to ``watch`` before only every ``log_every``-th is kept.

    Parameters
    ----------
    t_grid, x0, vp, controller, gains, mission, mp
        As in :func:`~quadcruise.sim.engine.simulate`.
    watch : callable
        Called as ``watch(k0, first, stop, states, references)`` for each chunk and piece of
        vehicles, chunks in order, on the thread that flew the piece: vehicles first..stop-1 of
        the (N, C, 16) states and (N, C, 11) references at the control instants
        ``k0 .. k0 + C - 1`` (the whole flight's rows at ``log_every=1``: NaN after a vehicle
        stopped, the state that broke a bound in the row after its last period). Views of a
        buffer reused by the next chunk: copy what is kept.
    log_every : int
        Keep every this many periods in the result (a divisor of the grid's periods).
    meta : dict, optional
        Recorded in the result.
    chunk_vehicle_steps : int, optional
        Vehicles x periods per chunk; :data:`CHUNK_VEHICLE_STEPS` by default.
    pieces_per_thread : int, optional
        Ranges of vehicles per thread and chunk, each watched and logged by its thread right
        after it is flown; :data:`PIECES_PER_THREAD` by default.
    rotor_names : tuple of str
        The rotor plant's state names (with ``alloc``: the result's ``rotor_names``).
    **options
        The other keywords of :func:`~quadcruise.sim.engine.simulate` (``memory``, ``vp_ctrl``,
        ``disturbance``, ``disturbance_params``, ``disturbance_memory``, ``seed``,
        ``first_vehicle``, ``sensor_std``, ``sensor_delay``, ``full_dynamics``, ``max_step``, ``observation``,
        ``limits``); or, for the rotor plant, :class:`~quadcruise.sim.stepper.Stepper`'s
        (``alloc``, ``psi0``, ``touchdown_speed``; ``vp`` the rotor parameter rows).

    Returns
    -------
    SimResult
        Bit for bit what ``simulate(..., log_every=log_every)`` returns (for the rotor plant,
        :func:`~quadcruise.sim.rotor_batch.fly_rotor_vehicles`'s, its rotor states too).
    """
    n_periods = np.shape(t_grid)[0] - 1
    n = np.shape(vp)[0]
    chunk_vehicle_steps = chunk_vehicle_steps or CHUNK_VEHICLE_STEPS  # read at the call (benchmarks/batchlog.py)
    pieces_per_thread = pieces_per_thread or PIECES_PER_THREAD
    periods = int(max(1, min(n_periods, chunk_vehicle_steps // max(n, 1))))
    s = Stepper(t_grid, x0, vp, controller, gains, mission, mp, periods=periods, **options)
    t_grid = s.t_grid
    n_log = n_periods // log_every + 1
    widths = (STATE_SIZE, CMD_SIZE, REF_SIZE) + ((s.state.shape[1],) if s.rotor else ())
    widths += (OBSERVATION_SIZE,) if s.observation.active else ()
    logs = [np.empty((n, n_log, w)) for w in widths]  # every row is written below
    small = (s.log_x, s.log_cmd, s.log_ref) + ((s.log_rotor,) if s.rotor else ())
    small += (s.log_obs,) if s.observation.active else ()
    held = None  # the row after the chunk of vehicles that stopped in its last period, and where it goes
    k0 = 0
    while k0 < n_periods:
        flying = s.status == int(ExitStatus.FINISHED)
        if not flying.any():  # all stopped: the rest of the log is blank, as the kernel leaves it
            for big in logs:
                big[:, -(-k0 // log_every) :] = np.nan
        else:
            k1 = min(k0 + periods, n_periods)
            seen = k1 - k0 + (k1 == n_periods)  # the last instant of the grid is flown by the last chunk
            first = -(-k0 // log_every) * log_every  # the kept periods in k0 .. k0 + seen - 1
            rows = slice(first // log_every, (k0 + seen - 1) // log_every + 1)
            cols = slice(first - k0, seen, log_every)

            def after_piece(lo: int, hi: int, k0=k0, seen=seen, rows=rows, cols=cols) -> None:
                watch(k0, lo, hi, s.log_x[:, :seen], s.log_ref[:, :seen])
                for big, part in zip(logs, small, strict=True):
                    big[lo:hi, rows] = part[lo:hi, cols]

            s.step(after_piece=after_piece, pieces_per_thread=pieces_per_thread)
        if held is not None:  # written over the blank rows that followed
            for big, (who, row, part) in zip(logs, held, strict=True):
                big[who, row] = part
            held = None
        if not flying.any():
            break
        stopped = np.flatnonzero(flying & (s.status != int(ExitStatus.FINISHED)))
        if k1 < n_periods and k1 % log_every == 0 and stopped.size:  # the state that broke a bound, at k1
            held = [(stopped, k1 // log_every, part[stopped, k1 - k0].copy()) for part in small]
        k0 = k1
    log_x, log_cmd, log_ref = logs[:3]
    rotor = {}
    if s.rotor:  # the rotor plant's own state, logged and final
        rotor = {"rotor_states": logs[3], "rotor_final_state": s.state, "rotor_names": tuple(rotor_names)}
    if s.observation.active:
        rotor["observations"] = logs[-1]
    return SimResult(
        t=t_grid[::log_every][:n_log].copy(),
        states=log_x,
        commands=log_cmd,
        references=log_ref,
        final_state=s.paper_state,
        status=s.status,
        t_stop=s.t_stop,
        memory=s.memory,
        disturbance_memory=s.disturbance_memory,
        duty_clipped_s=s.saturated[:, 0].copy(),
        controller_limited_s=s.saturated[:, 1].copy(),
        meta=dict(meta or {}),
        **rotor,
    )


def watch_again(
    t_grid,
    x0,
    vp,
    controller,
    gains,
    mission,
    mp,
    *,
    vehicles: np.ndarray,
    periods: int,
    watch: Callable[[int, int, int, np.ndarray, np.ndarray], None],
    chunk_vehicle_steps: int | None = None,
    pieces_per_thread: int | None = None,
    **options,
) -> None:
    """The first instants of some vehicles of a flight flown again, bit for bit as
    :func:`simulate_watched` flew them, each chunk's rows handed to ``watch``; nothing logged.

    The other vehicles are stopped before the first period (the kernel passes over them), and
    each vehicle's arithmetic does not depend on the others, nor on how the flight is cut.

    Parameters
    ----------
    t_grid, x0, vp, controller, gains, mission, mp
        As the flight's (:func:`simulate_watched`).
    vehicles : numpy.ndarray
        (N,) bool: the vehicles to fly again.
    periods : int
        Fly until at least the instants ``0 .. periods - 1`` have been watched.
    watch : callable
        As in :func:`simulate_watched` (the rows of the other vehicles are NaN).
    chunk_vehicle_steps, pieces_per_thread : int, optional
        As in :func:`simulate_watched`.
    **options
        As in :func:`simulate_watched` (``log_every`` and ``meta`` are not used).
    """
    options.pop("log_every", None), options.pop("meta", None), options.pop("rotor_names", None)
    n_periods = np.shape(t_grid)[0] - 1
    n = np.shape(vp)[0]
    chunk_vehicle_steps = chunk_vehicle_steps or CHUNK_VEHICLE_STEPS
    pieces_per_thread = pieces_per_thread or PIECES_PER_THREAD
    chunk = int(max(1, min(n_periods, chunk_vehicle_steps // max(n, 1), periods)))  # the buffer holds all N
    s = Stepper(t_grid, x0, vp, controller, gains, mission, mp, periods=chunk, **options)
    s.status[~np.asarray(vehicles, dtype=bool)] = int(ExitStatus.LOST_TRACK)  # not flown
    k0 = 0
    while k0 < periods and (s.status == int(ExitStatus.FINISHED)).any():
        k1 = min(k0 + chunk, n_periods)
        seen = k1 - k0 + (k1 == n_periods)

        def after_piece(lo: int, hi: int, k0=k0, seen=seen) -> None:
            watch(k0, lo, hi, s.log_x[:, :seen], s.log_ref[:, :seen])

        s.step(after_piece=after_piece, pieces_per_thread=pieces_per_thread)
        if k1 >= n_periods:
            break
        k0 = k1


__all__ = ["CHUNK_VEHICLE_STEPS", "simulate_watched", "watch_again"]
