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
>>> from quadcruise.sim.engine import simulate, time_grid
>>> t, c, m, v = time_grid(0.2, 1e-3), NLPD(), Circle(), Vehicle.paper()
>>> x0 = np.zeros(16); x0[2] = 1.0; x0[12:] = v.m * v.g / 4     # hovering at 1 m
>>> args = (t, x0, v.rows(2), c.function, c.gains(), m.function, m.params())
>>> seen = []
>>> a = simulate_watched(*args, log_every=50, watch=lambda k0, x, r: seen.append(x.shape[1]))
>>> b = simulate(*args, log_every=50)
>>> bool(np.array_equal(a.states, b.states, equal_nan=True)), sum(seen)   # every period seen once
(True, 201)
"""

from __future__ import annotations

from collections.abc import Callable

import numpy as np

from quadcruise.layout import CMD_SIZE, REF_SIZE, STATE_SIZE
from quadcruise.sim.result import SimResult
from quadcruise.sim.status import ExitStatus
from quadcruise.sim.stepper import Stepper

CHUNK_VEHICLE_STEPS = 2**17
"""Vehicle-steps per chunk (vehicles x periods): a chunk buffer of about 40 MB (312 bytes a row)."""


def simulate_watched(
    t_grid,
    x0,
    vp,
    controller,
    gains,
    mission,
    mp,
    *,
    watch: Callable[[int, np.ndarray, np.ndarray], None],
    log_every: int = 1,
    meta: dict | None = None,
    chunk_vehicle_steps: int = CHUNK_VEHICLE_STEPS,
    **options,
) -> SimResult:
    """:func:`~quadcruise.sim.engine.simulate`, flown in chunks, with every instant's state and
    reference shown to ``watch`` before only every ``log_every``-th is kept.

    Parameters
    ----------
    t_grid, x0, vp, controller, gains, mission, mp
        As in :func:`~quadcruise.sim.engine.simulate`.
    watch : callable
        Called as ``watch(k0, states, references)`` once per chunk, in order: the (N, C, 16)
        states and (N, C, 11) references at the control instants ``k0 .. k0 + C - 1`` (the
        whole flight's rows at ``log_every=1``: NaN after a vehicle stopped, the state that
        broke a bound in the row after its last period). Views of a buffer reused by the next
        chunk: copy what is kept.
    log_every : int
        Keep every this many periods in the result (a divisor of the grid's periods).
    meta : dict, optional
        Recorded in the result.
    chunk_vehicle_steps : int
        Vehicles x periods per chunk.
    **options
        The other keywords of :func:`~quadcruise.sim.engine.simulate` (``memory``, ``vp_ctrl``,
        ``disturbance``, ``disturbance_params``, ``disturbance_memory``, ``seed``,
        ``first_vehicle``, ``sensor_std``, ``sensor_delay``, ``full_dynamics``, ``max_step``,
        ``limits``).

    Returns
    -------
    SimResult
        Bit for bit what ``simulate(..., log_every=log_every)`` returns.
    """
    n_periods = np.shape(t_grid)[0] - 1
    n = np.shape(vp)[0]
    periods = int(max(1, min(n_periods, chunk_vehicle_steps // max(n, 1))))
    s = Stepper(t_grid, x0, vp, controller, gains, mission, mp, periods=periods, **options)
    t_grid = s.t_grid
    n_log = n_periods // log_every + 1
    log_x = np.full((n, n_log, STATE_SIZE), np.nan)  # rows never written stay NaN, as the kernel
    log_cmd = np.full((n, n_log, CMD_SIZE), np.nan)  # blanks them after a stop
    log_ref = np.full((n, n_log, REF_SIZE), np.nan)
    k0 = 0
    while k0 < n_periods:
        flying = np.flatnonzero(s.status == int(ExitStatus.FINISHED))
        if not flying.size:
            break
        s.step()
        k1 = min(k0 + periods, n_periods)
        seen = k1 - k0 + (k1 == n_periods)  # the last instant of the grid is flown by the last chunk
        watch(k0, s.log_x[:, :seen], s.log_ref[:, :seen])
        # kept rows: periods k0 .. k1 (k1: the row of a vehicle that stopped at k1 - 1; a vehicle
        # flying on writes it again in the next chunk)
        first = -(-k0 // log_every) * log_every
        kept = np.arange(first, k1 + 1, log_every)
        if kept.size:
            rows, src = kept // log_every, kept - k0
            for big, small in ((log_x, s.log_x), (log_cmd, s.log_cmd), (log_ref, s.log_ref)):
                big[flying[:, None], rows[None, :]] = small[flying[:, None], src[None, :]]
        k0 = k1
    return SimResult(
        t=t_grid[::log_every][:n_log].copy(),
        states=log_x,
        commands=log_cmd,
        references=log_ref,
        final_state=s.state,
        status=s.status,
        t_stop=s.t_stop,
        memory=s.memory,
        disturbance_memory=s.disturbance_memory,
        duty_clipped_s=s.saturated[:, 0].copy(),
        controller_limited_s=s.saturated[:, 1].copy(),
        meta=dict(meta or {}),
    )


__all__ = ["CHUNK_VEHICLE_STEPS", "simulate_watched"]
