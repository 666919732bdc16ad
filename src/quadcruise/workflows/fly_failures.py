"""What :func:`quadcruise.workflows.fly.fly` checks after a flight: the bounds on the tracking
error (the transient's, the steady one's and the altitude's), vehicles marked off track or as
having lost the track in their status, and the warnings naming the vehicles that did not finish."""

from __future__ import annotations

import contextlib
import dataclasses
import warnings

import numpy as np

from quadcruise.errors import FlightWarning
from quadcruise.layout import REF_X, REF_Z, X
from quadcruise.missions import Mission
from quadcruise.sim import plants
from quadcruise.sim.result import SimResult
from quadcruise.sim.status import ExitStatus


def track_bound(missions: list[Mission], x0: np.ndarray, n: int) -> np.ndarray:
    """The default tracking bound of each vehicle [m]: 1 m, plus the diagonal of the box its
    mission's reference path spans over the mission's default duration, plus its initial
    position error, so that neither the start offset nor the mission's own size counts.

    Parameters
    ----------
    missions : list of Mission
        One mission for every vehicle, or one for all.
    x0 : numpy.ndarray
        (N, 16) initial states.
    n : int
        Number of vehicles.

    Returns
    -------
    numpy.ndarray
        (N,) bounds [m].

    Examples
    --------
    >>> from quadcruise.missions import Circle
    >>> x0 = np.zeros((1, 16)); x0[0, 2] = 1.0
    >>> track_bound([Circle()], x0, 1).round(3)          # 1 + 4 sqrt(2) + the 2 m start offset
    array([8.657])
    """
    sizes, starts = [], []
    for mission in missions:
        ref = mission.reference(np.linspace(0.0, float(mission.duration), 1001))
        path = ref[:, REF_X : REF_X + 3]
        sizes.append(float(np.linalg.norm(path.max(axis=0) - path.min(axis=0))))
        starts.append(path[0])
    size = np.broadcast_to(np.asarray(sizes), (n,))
    start = np.broadcast_to(np.asarray(starts), (n, 3))
    offset = np.linalg.norm(np.asarray(x0, dtype=float).reshape(n, -1)[:, X : X + 3] - start, axis=1)
    return 1.0 + size + offset


def steady_bound(mission: Mission, duration: float) -> float:
    """The default steady bound [m] of a flight (``fly(max_steady_error=)``) and of a Monte
    Carlo sweep (``MonteCarloSpec.max_track_error_m``): the larger of 1 m and a quarter of
    the mission's extent.

    Parameters
    ----------
    mission : Mission
        The mission flown.
    duration : float
        Flight time [s].

    Returns
    -------
    float
        The bound [m]; the extent is the longest side of the box holding the reference
        position at 1,001 instants over the flight.

    Examples
    --------
    >>> from quadcruise.missions import mission_from_name
    >>> steady_bound(mission_from_name("circle"), 20.0)
    1.0
    >>> steady_bound(mission_from_name("circle", radius=10.0), 20.0)
    5.0
    """
    return _steady_from(reference_span(mission, duration)[0])


def _steady_from(extent: float) -> float:
    return max(1.0, 0.25 * extent)


def reference_span(mission: Mission, duration: float) -> tuple[float, float]:
    """The longest side [m] of the box holding the mission's reference position, and its lowest
    altitude [m], from the reference at 1,001 instants over the flight (one evaluation for both
    bounds)."""
    ref = mission.reference(np.linspace(0.0, float(duration), 1001))
    position = ref[:, REF_X : REF_X + 3]
    return float(np.max(position.max(axis=0) - position.min(axis=0))), float(ref[:, REF_Z].min())


ALTITUDE_FRACTION = 0.5
"""A vehicle that sags (or climbs) by more than this fraction of its mission's lowest reference
altitude after the transient is off track: half-way to the ground is not flying the mission."""
MIN_ALTITUDE_BOUND = 0.1
"""The vertical bound [m] is never below this (a mission flown at or near the ground)."""


def altitude_bound(mission: Mission, duration: float) -> float:
    """The default vertical steady bound [m] of a flight and of a Monte Carlo sweep: half the
    lowest altitude the mission's reference flies at, at least :data:`MIN_ALTITUDE_BOUND`
    and at most :func:`steady_bound`.

    Parameters
    ----------
    mission : Mission
        The mission flown.
    duration : float
        Flight time [s].

    Returns
    -------
    float
        The bound [m] on the altitude error after the transient, from the reference at
        1,001 instants over the flight.

    Examples
    --------
    >>> from quadcruise.missions import mission_from_name
    >>> altitude_bound(mission_from_name("circle"), 20.0)             # at 1 m
    0.5
    >>> altitude_bound(mission_from_name("circle", altitude=30.0), 20.0)  # capped by the 3-D bound
    1.0
    """
    extent, lowest = reference_span(mission, duration)
    return min(_steady_from(extent), max(MIN_ALTITUDE_BOUND, ALTITUDE_FRACTION * lowest))


def off_track_since(
    t: np.ndarray,
    err: np.ndarray,
    dz: np.ndarray,
    measured: np.ndarray,
    settled_at: np.ndarray,
    bound: np.ndarray,
    zbound: np.ndarray,
) -> np.ndarray:
    """The first instant after the transient at which each vehicle was off track: the one rule
    of ``fly`` (:func:`mark_off_track`) and of a Monte Carlo sweep.

    After the transient: from its settling into :data:`~quadcruise.metrics.flight.STEADY_BAND`
    on (``settled_at``); the whole flight where no transient is measured; the last instant
    if it never settled (the error at the end).

    Parameters
    ----------
    t : numpy.ndarray
        (L,) logged instants [s].
    err, dz : numpy.ndarray
        (N, L) 3-D position error and altitude error [m].
    measured : numpy.ndarray
        (N,) bool: a transient was measured.
    settled_at : numpy.ndarray
        (N,) end of the transient [s]; NaN if it did not settle.
    bound, zbound : numpy.ndarray
        (N,) bounds on the 3-D error and on the altitude error [m]; ``inf`` turns one off.

    Returns
    -------
    numpy.ndarray
        (N,) the first instant [s] beyond either bound; NaN for a vehicle never beyond.

    Examples
    --------
    >>> t = np.arange(4.0)
    >>> err = np.array([[2.0, 0.1, 0.2, 1.5], [2.0, 0.1, 0.1, 0.1]])
    >>> off_track_since(t, err, 0 * err, np.array([True, True]), np.array([1.0, np.nan]),
    ...                 np.array([1.0, 1.0]), np.array([0.5, 0.5]))
    array([ 3., nan])
    """
    start = np.where(~measured, t[0], np.where(np.isnan(settled_at), t[-1], settled_at))
    with np.errstate(invalid="ignore"):
        beyond = (err > bound[:, None]) | (np.abs(dz) > zbound[:, None])
    beyond &= t[None, :] >= start[:, None] - 1e-12
    return np.where(beyond.any(axis=1), t[np.argmax(beyond, axis=1)], np.nan)


def mark_off_track(
    result: SimResult, bound: np.ndarray, err: np.ndarray | None = None, zbound: np.ndarray | None = None
) -> SimResult:
    """The result, with ``off track`` as the status of each finished vehicle whose position
    error after the transient exceeded the bound, or whose altitude error exceeded the
    vertical bound, and the first instant it did as its ``t_stop`` (:func:`off_track_since`,
    the rule a Monte Carlo sweep applies).

    Parameters
    ----------
    result : SimResult
    bound : numpy.ndarray
        (N,) bounds on the 3-D error [m]; ``inf`` skips a vehicle.
    err : numpy.ndarray, optional
        (N, L) position errors [m] (:func:`position_error`), if already computed.
    zbound : numpy.ndarray, optional
        (N,) bounds on the altitude error [m]; ``bound`` by default.

    Returns
    -------
    SimResult
        The same object when no vehicle is off track.
    """
    from quadcruise.metrics.batch import transient_batch

    zbound = bound if zbound is None else zbound
    live = np.flatnonzero((result.status == int(ExitStatus.FINISHED)) & (np.isfinite(bound) | np.isfinite(zbound)))
    t = result.t
    if not live.size or t.size < 2:
        return result
    err = (position_error(result) if err is None else err)[live]
    if not np.isfinite(err).all():
        return result
    pos, ref = result.states[live, :, X : X + 3], result.references[live, :, REF_X : REF_X + 3]
    mission = result.meta.get("mission")
    got = transient_batch(t, pos, ref, mission if isinstance(mission, dict) else {}, [], err=err)
    first = off_track_since(
        t, err, pos[:, :, 2] - ref[:, :, 2], got["axis"] >= 0, got["settled_at"], bound[live], zbound[live]
    )
    off = np.isfinite(first)
    if not off.any():
        return result
    status, t_stop = result.status.copy(), result.t_stop.copy()
    status[live[off]] = int(ExitStatus.OFF_TRACK)
    t_stop[live[off]] = first[off]
    return dataclasses.replace(result, status=status, t_stop=t_stop)


def position_error(result: SimResult) -> np.ndarray:
    """The 3-D position error of every vehicle at every logged instant.

    Parameters
    ----------
    result : SimResult

    Returns
    -------
    numpy.ndarray
        (N, L) [m]; NaN after a vehicle stopped. Written out per axis: the same sums as
        ``numpy.linalg.norm(..., axis=2)``, a few times faster on the log's strided rows.
    """
    s, r = result.states, result.references
    dx, dy, dz = (s[:, :, X + k] - r[:, :, REF_X + k] for k in range(3))
    return np.sqrt(dx * dx + dy * dy + dz * dz)


def mark_lost_track(result: SimResult, bound: np.ndarray, err: np.ndarray | None = None) -> SimResult:
    """The result, with ``lost track`` as the status of each finished vehicle whose position
    error left the bound, and the first logged instant it did as its ``t_stop``.

    Parameters
    ----------
    result : SimResult
    bound : numpy.ndarray
        (N,) bounds [m].
    err : numpy.ndarray, optional
        (N, L) position errors [m] (:func:`position_error`), if already computed.

    Returns
    -------
    SimResult
        The same object when no vehicle lost track.
    """
    err = position_error(result) if err is None else err
    beyond = (err > bound[:, None]) & (result.status == int(ExitStatus.FINISHED))[:, None]
    lost = np.flatnonzero(beyond.any(axis=1))
    if not lost.size:
        return result
    status, t_stop = result.status.copy(), result.t_stop.copy()
    status[lost] = int(ExitStatus.LOST_TRACK)
    t_stop[lost] = result.t[np.argmax(beyond[lost], axis=1)]
    return dataclasses.replace(result, status=status, t_stop=t_stop)


@contextlib.contextmanager
def flight_warnings_named(label: str):
    """Within it, the warnings of the flights flown say whose flight they are: each
    :class:`~quadcruise.errors.FlightWarning` (a vehicle that did not finish, clipped duties)
    gets ``label: `` in front; the others (the vehicle's own) pass as they were, once.

    Parameters
    ----------
    label : str
        Whose flights, e.g. a controller's label or ``"circle with nlpd"``.

    Yields
    ------
    None
    """
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        yield
    for w in caught:
        text = f"{label}: {w.message}" if issubclass(w.category, FlightWarning) else str(w.message)
        warnings.warn(text, w.category, stacklevel=3)


def warn_about(result: SimResult) -> None:
    """Warn (:class:`~quadcruise.errors.FlightWarning`) of the vehicles that did not finish and of clipped duties."""
    bad = np.flatnonzero(~result.ok)
    if bad.size:
        first = int(bad[0])
        more = f" ({bad.size} of {result.n} vehicles)" if result.n > 1 else ""
        warnings.warn(f"vehicle {first} {result.status_text(first)}{more}", FlightWarning, stacklevel=3)
    clipped = result.duty_clipped_s
    if np.any(clipped > 0):
        what = plants.of_result(result).saturation  # duties clipped, or a rotor plant's speeds held
        warnings.warn(
            f"{what} for up to {clipped.max():.3f} s ({np.count_nonzero(clipped)} of {result.n} vehicles)",
            FlightWarning,
            stacklevel=3,
        )
