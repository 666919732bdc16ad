"""The period code both plants' kernels share, once: what a vehicle carries in and out of a call
(its memories, the sensor ring buffer, its logs blanked after a stop, what it reached), the
substeps of a period and the body's bounds.

Each helper is compiled inline into the kernel that calls it (``inline="always"``: numba inlines
its IR before typing), so the kernels of :mod:`quadcruise.sim.engine` and
:mod:`quadcruise.sim.rotor_flight` run the same machine code as when these lines were written in
each; they follow the scalar-only rule of :mod:`quadcruise.sim.fastmath` (rows copied element
by element, no slice of a shared array). What runs every period takes scalars only: an array
handed to an inlined helper costs numba's reference counting (an atomic increment and decrement)
each time, which made the paper kernel 10 % slower when the sensor ring buffer, the period's
instant and the log were helpers too (docs/performance.md); those stay written in each kernel.
"""

from __future__ import annotations

import math

import numpy as np
from numba import njit

from quadcruise import layout as L
from quadcruise.sim.status import ExitStatus

FINISHED, NONFINITE, POSITION_BOUND, SPEED_BOUND, RATE_BOUND = (
    int(ExitStatus[name]) for name in ("FINISHED", "NONFINITE", "POSITION_BOUND", "SPEED_BOUND", "RATE_BOUND")
)


@njit(cache=True, inline="always")
def beyond(a, b, c, bound):
    """Whether |a|, |b| or |c| exceeds bound (a position [m], velocity [m/s], rates [rad/s] or
    angles [rad], and the bound in their unit)."""
    return abs(a) > bound or abs(b) > bound or abs(c) > bound


@njit(cache=True, inline="always")
def log_row(log, i, row, v):
    """log[i, row, :] = v, element by element (a slice takes a reference on the shared log)."""
    for j in range(v.shape[0]):
        log[i, row, j] = v[j]


@njit(cache=True, inline="always")
def put_row(a, i, v):
    """a[i, :] = v, element by element (a slice assignment compiles a shape check of its own)."""
    for j in range(v.shape[0]):
        a[i, j] = v[j]


@njit(cache=True, inline="always")
def take_row(a, i, v):
    """v[:] = a[i, :], element by element: a vehicle's own copy of its row."""
    for j in range(v.shape[0]):
        v[j] = a[i, j]


@njit(cache=True, inline="always")
def blank_rows(log, i, first):
    """NaN in the rows of vehicle i from ``first`` on (a vehicle that stopped early leaves them
    unwritten)."""
    for row in range(first, log.shape[1]):
        for j in range(log.shape[2]):
            log[i, row, j] = np.nan


@njit(cache=True, inline="always")
def blank_logs(i, rows_x, rows, log_x, log_cmd, log_ref):
    """NaN in vehicle i's rows not flown: its states from ``rows_x`` on, its commands and
    references from ``rows`` on."""
    blank_rows(log_x, i, rows_x)
    blank_rows(log_cmd, i, rows)
    blank_rows(log_ref, i, rows)


@njit(cache=True, inline="always")
def read_history(carry, i, at, history):
    """The sensor-delay ring buffer ``history`` (delay + 1 states) from vehicle i's carry row,
    where it starts at column ``at``."""
    for d in range(history.shape[0]):
        for j in range(L.STATE_SIZE):
            history[d, j] = carry[i, at + d * L.STATE_SIZE + j]


@njit(cache=True, inline="always")
def write_history(carry, i, at, history):
    """The ring buffer back into vehicle i's carry row, from column ``at``."""
    for d in range(history.shape[0]):
        for j in range(L.STATE_SIZE):
            carry[i, at + d * L.STATE_SIZE + j] = history[d, j]


@njit(cache=True, inline="always")
def substeps(dt, max_step):
    """The number of equal RK4 substeps no longer than ``max_step`` [s] in a period dt [s], and
    their length [s]."""
    n_sub = max(1, int(math.ceil(dt / max_step - 1e-9)))
    return n_sub, dt / n_sub


@njit(cache=True, inline="always")
def body_bounds(finite, px, py, pz, vx, vy, vz, p, q, r, max_position, max_speed, max_rate):
    """The status of a state after a period, from the checks both plants make: ``finite`` (every
    entry of the state), then position [m], velocity [m/s] and body rates [rad/s] within their
    bounds; FINISHED if all hold (the plant checks its tilt). Scalars only: an array handed to an
    inlined helper costs reference counting in every period."""
    if not finite:
        return NONFINITE
    if beyond(px, py, pz, max_position):
        return POSITION_BOUND
    if beyond(vx, vy, vz, max_speed):
        return SPEED_BOUND
    if beyond(p, q, r, max_rate):
        return RATE_BOUND
    return FINISHED


@njit(cache=True, inline="always")
def give_back(i, mi, dmi, rngi, mem, dmem, rng):
    """Vehicle i's memories written back: its controller's, its disturbance's and its stream."""
    put_row(mem, i, mi)
    put_row(dmem, i, dmi)
    put_row(rng, i, rngi)


@njit(cache=True, inline="always")
def take(i, mem, dmem, rng, mi, dmi, rngi):
    """Vehicle i's own copies of its memories (a kept trick against false sharing:
    :mod:`quadcruise.sim.fastmath`), written back by :func:`give_back`."""
    take_row(mem, i, mi)
    take_row(dmem, i, dmi)
    take_row(rng, i, rngi)


@njit(cache=True, inline="always")
def close_vehicle(i, k_reached, steps, clipped_s, limited_s, code, t_end, clock, saturated, status, t_stop):
    """What a vehicle reached, recorded: its period and RK4 steps, saturation times [s], status
    and stop time [s]."""
    clock[i, 0], clock[i, 1] = k_reached, steps
    saturated[i, 0], saturated[i, 1] = clipped_s, limited_s
    status[i] = code
    t_stop[i] = t_end


__all__ = [
    "beyond",
    "blank_logs",
    "blank_rows",
    "body_bounds",
    "close_vehicle",
    "give_back",
    "log_row",
    "put_row",
    "read_history",
    "substeps",
    "take",
    "write_history",
]
