"""The first periods of some vehicles of a flight flown again, in chunks, every period's rows
handed to a watcher: the head of the vehicles whose track verdict the kernel's running figures
leave open (:class:`~quadcruise.workflows.track_watch.TrackWatch`, rare), read at every period.

The chunks go through :class:`~quadcruise.sim.stepper.Stepper` (the kernel's resume arguments),
so those vehicles fly bit for bit as the whole flight flew them, in a chunk buffer of about
:data:`CHUNK_VEHICLE_STEPS` rows.

Examples
--------
>>> import numpy as np
>>> from quadcruise.control import NLPD
>>> from quadcruise.missions import Circle
>>> from quadcruise.model.vehicle import Vehicle
>>> from quadcruise.sim.inputs import time_grid
>>> t, c, m, v = time_grid(0.2, 1e-3), NLPD(), Circle(), Vehicle.paper()
>>> x0 = np.zeros(16); x0[2] = 1.0; x0[12:] = v.m * v.g / 4     # hovering at 1 m
>>> args = (t, x0, v.rows(3), c.function, c.gains(), m.function, m.params())
>>> seen = []
>>> def watch(k0, first, stop, x, r): seen.append(int(np.isfinite(x[first:stop, :, 0]).sum()))
>>> watch_again(*args, memory=c.memory(), vehicles=np.array([True, False, True]), periods=50, watch=watch)
>>> sum(seen) >= 2 * 50                                  # the two vehicles' first 50 instants, at least
True
"""

from __future__ import annotations

from collections.abc import Callable

import numpy as np

from quadcruise.sim.status import ExitStatus
from quadcruise.sim.stepper import Stepper

CHUNK_VEHICLE_STEPS = 2**18
"""Vehicle-steps per chunk (vehicles x periods): a chunk buffer of about 80 MB (312 bytes a row)."""
PIECES_PER_THREAD = 16
"""Ranges of vehicles per thread in a chunk: about 2.5 MB of rows each at 2 threads."""


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
    :func:`~quadcruise.sim.engine.simulate` (or the rotor plant's kernel) flew them, each chunk's
    rows handed to ``watch``; nothing logged.

    The other vehicles are stopped before the first period (the kernel passes over them), and
    each vehicle's arithmetic does not depend on the others, nor on how the flight is cut.

    Parameters
    ----------
    t_grid, x0, vp, controller, gains, mission, mp
        As the flight's (:func:`~quadcruise.sim.engine.simulate`; for the rotor plant, the
        rotor arrays as :class:`~quadcruise.sim.stepper.Stepper` takes them).
    vehicles : numpy.ndarray
        (N,) bool: the vehicles to fly again.
    periods : int
        Fly until at least the instants ``0 .. periods - 1`` have been watched.
    watch : callable
        Called as ``watch(k0, first, stop, states, references)`` for each chunk and piece of
        vehicles, chunks in order, on the thread that flew the piece: vehicles first..stop-1 of
        the (N, C, 16) states and (N, C, 11) references at the control instants
        ``k0 .. k0 + C - 1`` (NaN for the vehicles not flown and after a vehicle stopped). Views
        of a buffer reused by the next chunk: copy what is kept.
    chunk_vehicle_steps : int, optional
        Vehicles x periods per chunk; :data:`CHUNK_VEHICLE_STEPS` by default.
    pieces_per_thread : int, optional
        Ranges of vehicles per thread and chunk; :data:`PIECES_PER_THREAD` by default.
    **options
        The flight's other keywords for :class:`~quadcruise.sim.stepper.Stepper` (``log_every``,
        ``meta``, ``rotor_names`` and ``track`` are not used).
    """
    for unused in ("log_every", "meta", "rotor_names", "track"):
        options.pop(unused, None)
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


__all__ = ["CHUNK_VEHICLE_STEPS", "watch_again"]
