"""One chunk of a sweep: its vehicles flown through the batched engine and reduced to table
rows; one vehicle flown again alone (its row equal to the sweep's, whatever chunk it was in)."""

from __future__ import annotations

import warnings
from dataclasses import dataclass
from typing import Any

import numpy as np

from quadcruise.errors import InputError, whole_number
from quadcruise.layout import CMD_U1, REF_X, X
from quadcruise.metrics.batch import flight_metrics_batch
from quadcruise.metrics.estimate import estimate_metrics, flew_an_estimator
from quadcruise.metrics.flight import FAILED_FLIGHT_METRICS, hover_duties
from quadcruise.montecarlo.population import Draw
from quadcruise.montecarlo.schema import COLUMNS, FAILURES, METRICS
from quadcruise.montecarlo.spec import MonteCarloSpec
from quadcruise.sim.status import ExitStatus

__all__ = ["Case", "fly_chunk", "montecarlo_case", "reduce_chunk", "replay_case", "run_chunk", "sweep_metrics"]


# --- one chunk --------------------------------------------------------------------------
def fly_chunk(spec: MonteCarloSpec, first, count: int, log_every: int | None = None, controller=None):
    """Fly vehicles first .. first + count - 1 (or the indices ``first``) as one batch, with the spec's
    controller or one per vehicle: ``(SimResult, Draw)``; failures go in the table, not in warnings."""
    from quadcruise.workflows.fly import fly
    from quadcruise.workflows.fly_inputs import hover_state

    draw = spec.population.draw(spec.seed, first, count, spec.vehicle, spec.dt)
    x0 = None  # without an offset: hovering at the mission's start, fly's own start on either plant
    if np.any(draw.offsets):  # the paper layout's hover thrusts (a rotor plant's: each rotor at its hover speed)
        x0 = hover_state(spec.plant.equivalent(spec.plant.vehicles(draw.vehicle)), count, spec.mission)
        x0[:, X : X + 3] += draw.offsets
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        res = fly(
            spec.mission,
            spec.controller if controller is None else controller,
            vehicle=draw.vehicle,  # a rotor-plant population's: a tuple, one per vehicle
            controller_vehicle=spec.model_vehicle,
            duration=spec.duration,
            dt=spec.dt,
            max_step=spec.max_step,
            x0=x0,
            log_every=spec.log_every if log_every is None else log_every,
            full_dynamics=spec.full_dynamics,
            seed=spec.seed,
            first_vehicle=first,
            environment=draw.environment,
            sensors=draw.sensors,
            estimator=draw.estimator,
            max_steady_error=spec.max_track_error_m,
            max_altitude_error=spec.max_altitude_error_m,
        )  # fly's own verdict, by the spec's bounds, at every period whatever the log keeps
    return res, draw


def run_chunk(spec: MonteCarloSpec, first: int, count: int, threads: int | None = None) -> dict:
    """Vehicles first .. first + count - 1, flown and reduced to a chunk (dict of arrays): the Dask task, a
    pure function of its arguments."""
    if threads is not None:
        import numba
        from numba.core.config import reload_config

        # A Dask worker spawned from the ``quadcruise`` script imported numba (its thread count
        # from the CPUs) before the nanny set NUMBA_NUM_THREADS=1: read the environment again before
        # the threads are launched, else the first compile in the worker (an empty cache) re-reads it
        # and numba refuses to change the count of threads already running.
        reload_config()
        numba.set_num_threads(max(1, min(int(threads), numba.config.NUMBA_NUM_THREADS)))
    res, draw = fly_chunk(spec, first, count)
    return reduce_chunk(spec, first, res, draw)


def reduce_chunk(spec: MonteCarloSpec, first: int, res, draw: Draw) -> dict:
    """The chunk of :func:`run_chunk` from a flown batch and its draw."""
    count = res.n
    cols = sweep_metrics(res, spec)
    cols["vehicle"] = np.arange(first, first + count, dtype=np.int64)
    cols.update({k: np.asarray(v, dtype=float) for k, v in draw.columns.items()})
    out = {"first": np.int64(first), "count": np.int64(count), "hash": np.str_(spec.hash())}
    out.update({k: np.asarray(cols[k], dtype=t) for k, t in COLUMNS.items()})
    # paths: the random sample (the first max_traces vehicles) and the chunk's first failures
    sample = cols["vehicle"] < spec.max_traces
    failed = np.flatnonzero((cols["failure"] != 0) & ~sample)[: spec.max_failure_traces]
    keep = np.union1d(np.flatnonzero(sample), failed).astype(np.int64)
    step = spec.trace_every
    out["trace_vehicle"] = cols["vehicle"][keep]
    out["trace_sample"] = sample[keep]
    out["trace_t"] = res.t[::step].copy()
    out["trace_pos"] = np.ascontiguousarray(res.states[keep, ::step, X : X + 3])
    out["trace_ref"] = np.ascontiguousarray(res.references[keep, ::step, REF_X : REF_X + 3])
    return out


# --- metrics of a chunk -----------------------------------------------------------------
def sweep_metrics(result, spec: MonteCarloSpec) -> dict[str, np.ndarray]:
    """Per-vehicle metrics of a batch, vectorised (the columns of ``COLUMNS`` but the index and the draw): each
    equals :func:`quadcruise.metrics.flight_metrics` of that vehicle alone; NaN for one that stopped early."""
    t = result.t
    n = result.n
    status = np.asarray(result.status, dtype=np.int64)
    out: dict[str, Any] = {m: np.full(n, np.nan) for m in METRICS}
    out["duty_clipped_s"] = np.asarray(result.duty_clipped_s, dtype=float).copy()
    out["controller_limited_s"] = np.asarray(result.controller_limited_s, dtype=float).copy()
    out["transient_axis"] = np.full(n, -1, dtype=np.int64)
    out["status"] = status
    out["stop_time_s"] = np.asarray(result.t_stop, dtype=float).copy()
    refs = result.references[:, :, REF_X : REF_X + 3]
    stopped = np.asarray(result.stopped, dtype=bool)  # by the engine: later rows NaN
    live = np.flatnonzero(~stopped & np.isfinite(refs).all(axis=(1, 2)))
    not_settled = np.zeros(n, dtype=bool)
    if live.size:
        mission = result.meta.get("mission") if isinstance(result.meta.get("mission"), dict) else {}
        hover = hover_duties(result.meta, n)
        got = flight_metrics_batch(
            t,
            result.states[live, :, X : X + 3],
            refs[live],
            result.commands[live, :, CMD_U1 : CMD_U1 + 4],
            mission=mission,
            bands=(0.02, 0.05, spec.settle_band),
            transient_until=spec.transient_until,
            hover_duty=None if hover is None else hover[live],
        )
        for key in (*(m for m in METRICS if m in got), "transient_axis"):  # the batch's own, by name
            out[key][live] = got[key]
        out["settling_time_s"][live], out["settling_time_5pct_s"][live] = got["settling_s"][:2]
        not_settled[live] = (got["transient_axis"] >= 0) & np.isnan(got["settling_s"][2])
        if flew_an_estimator(result):  # how far the estimate the controller flew on was from the truth
            for i in live:
                for key, value in estimate_metrics(result.states, result.observations, int(i)).items():
                    out[key][i] = value
    diverged = stopped
    # lost track: fly's own status, the one rule of a flight alone (fly_chunk gives it the spec's
    # bounds): the error left the tracking bound (1 m + the mission's size) at some period, or
    # off track after the transient (status and time those of `fly` of the same vehicle)
    lost_track = ~diverged & np.isin(status, (int(ExitStatus.LOST_TRACK), int(ExitStatus.OFF_TRACK)))
    for key in FAILED_FLIGHT_METRICS:  # no transient or steady state to speak of
        out[key][lost_track] = np.nan
    saturated = out["duty_clipped_s"] > spec.max_clipped_s
    failed_requirement = np.zeros(n, dtype=bool)
    for req in spec.requirements:
        failed_requirement |= ~req.met(out[req.metric])
    out.update(
        diverged=diverged,
        lost_track=lost_track,
        saturated=saturated,
        failed_requirement=failed_requirement,
        not_settled=not_settled,
    )
    out["failure"] = np.select(
        [diverged, lost_track, saturated, failed_requirement], [FAILURES.index(r) for r in FAILURES[1:]], 0
    ).astype(np.int64)
    return out


# --- one case ---------------------------------------------------------------------------
@dataclass
class Case:
    """One vehicle of a sweep flown again alone: its flight and its table row.

    Parameters
    ----------
    vehicle : int
        Its index in the population.
    result : SimResult
        Its flight (one vehicle).
    row : dict
        Its row of the sweep's table: column -> plain value, with ``reason`` (the failure's
        name).
    """

    vehicle: int
    result: Any
    row: dict


def montecarlo_case(spec: MonteCarloSpec, i: int, *, log_every: int | None = None) -> Case:
    """Fly vehicle i of a sweep alone (the draws and random streams of (seed, i)): its row
    of the table, equal to the sweep's row whatever chunk it was flown in, and its flight,
    logged at the spec's rate (or every ``log_every`` periods: 1 for all; the row is
    always computed at the spec's rate).

    Parameters
    ----------
    spec : MonteCarloSpec
        The sweep.
    i : int
        The vehicle's index in the population, >= 0.
    log_every : int, optional
        Log the returned flight every this many control periods (1: every period); the
        spec's rate by default.

    Returns
    -------
    Case
        The vehicle's index, flight and row.

    Examples
    --------
    >>> from quadcruise.montecarlo import Population
    >>> spec = MonteCarloSpec("hover", population=Population(offset=0.2), seed=3, duration=0.5)
    >>> case = montecarlo_case(spec, 7)
    >>> case.row["vehicle"], case.result.n, case.row["dx0"] == float(case.result.states[0, 0, 0])
    (7, 1, True)
    """
    i = whole_number(i, "the vehicle index")
    res, draw = fly_chunk(spec, i, 1)
    chunk = reduce_chunk(spec, int(i), res, draw)
    row = {k: chunk[k][0].item() for k in COLUMNS}
    row["reason"] = FAILURES[row["failure"]]
    if log_every is not None and log_every != spec.log_every:
        res = fly_chunk(spec, int(i), 1, log_every)[0]
    return Case(vehicle=int(i), result=res, row=row)


def replay_case(result, i: int, **kw) -> Case:
    """:func:`montecarlo_case` of vehicle i of a finished sweep.

    Parameters
    ----------
    result : MonteCarloResult
        The sweep (its spec and its number of flights are used).
    i : int
        The vehicle's index, in [0, result.n).
    **kw
        Passed on to :func:`montecarlo_case` (``log_every``).

    Returns
    -------
    Case
        The vehicle flown again alone.

    Raises
    ------
    InputError
        If vehicle i is not in the sweep.
    """
    if not 0 <= i < result.n:
        raise InputError(f"vehicle {i} is not in this sweep of {result.n} flights")
    return montecarlo_case(result.spec, i, **kw)
