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
from quadcruise.montecarlo.population import Draw
from quadcruise.montecarlo.schema import COLUMNS, FAILURES, METRICS
from quadcruise.montecarlo.spec import MonteCarloSpec

__all__ = ["Case", "fly_chunk", "montecarlo_case", "reduce_chunk", "replay_case", "run_chunk", "sweep_metrics"]


# --- one chunk --------------------------------------------------------------------------
def fly_chunk(spec: MonteCarloSpec, first: int, count: int, log_every: int | None = None):
    """Fly vehicles first .. first + count - 1 of the population as one batch:
    ``(SimResult, Draw)``. Divergence and clipping are not warned about (they are in the
    table)."""
    from quadcruise.workflows.fly import fly, hover_state

    draw = spec.population.draw(spec.seed, first, count, spec.vehicle, spec.dt)
    x0 = hover_state(draw.vehicle, count, spec.mission)
    x0[:, X:X + 3] += draw.offsets
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        res = fly(spec.mission, spec.controller, vehicle=draw.vehicle,
                  controller_vehicle=spec.vehicle if spec.population.model_error else None,
                  duration=spec.duration, dt=spec.dt, max_step=spec.max_step, x0=x0,
                  log_every=spec.log_every if log_every is None else log_every,
                  full_dynamics=spec.full_dynamics, seed=spec.seed, first_vehicle=first,
                  environment=draw.environment, sensors=draw.sensors)
    return res, draw


def run_chunk(spec: MonteCarloSpec, first: int, count: int, threads: int | None = None) -> dict:
    """Vehicles first .. first + count - 1, flown and reduced to a chunk (dict of arrays).

    Keys: ``first``, ``count``, ``hash``, one array per column of
    :data:`~quadcruise.montecarlo.result.COLUMNS`, and the kept paths: ``trace_vehicle``
    (k,), ``trace_t`` (L,), ``trace_pos`` and ``trace_ref`` (k, L, 3), ``trace_sample`` (k,)
    (True: one of the first ``max_traces`` vehicles; else kept as one of the first
    ``max_failure_traces`` failures). A pure function of its arguments: this is the Dask
    task. ``threads`` sets numba's threads for this call (1 on a Dask worker).
    """
    if threads is not None:
        import numba

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
    failed = np.flatnonzero((cols["failure"] != 0) & ~sample)[:spec.max_failure_traces]
    keep = np.union1d(np.flatnonzero(sample), failed).astype(np.int64)
    step = spec.trace_every
    out["trace_vehicle"] = cols["vehicle"][keep]
    out["trace_sample"] = sample[keep]
    out["trace_t"] = res.t[::step].copy()
    out["trace_pos"] = np.ascontiguousarray(res.states[keep, ::step, X:X + 3])
    out["trace_ref"] = np.ascontiguousarray(res.references[keep, ::step, REF_X:REF_X + 3])
    return out


# --- metrics of a chunk -----------------------------------------------------------------
def sweep_metrics(result, spec: MonteCarloSpec) -> dict[str, np.ndarray]:
    """Per-vehicle metrics of a batch, vectorised: the columns of
    :data:`~quadcruise.montecarlo.result.COLUMNS` but the vehicle index and the drawn values.

    ``rmse_m``, ``max_error_m``, ``rise_time_s``, ``settling_time_s`` (2 %),
    ``settling_time_5pct_s``, ``overshoot_pct``, ``effort``, ``duty_clipped_s`` and
    ``controller_limited_s`` equal :func:`quadcruise.metrics.flight_metrics` on the same
    result (to rounding; the transient is measured on the same axis with the same rules,
    by :func:`quadcruise.metrics.batch.flight_metrics_batch`); ``final_error_m`` is the
    position error at the end. Every metric of a vehicle that stopped early is NaN. Each
    vehicle's numbers depend on its own rows only, so they do not change with the batch a
    vehicle is flown in. The failure of each vehicle follows the spec's rules.
    """
    t = result.t
    n = result.n
    status = np.asarray(result.status, dtype=np.int64)
    out: dict[str, Any] = {m: np.full(n, np.nan) for m in METRICS}
    out["duty_clipped_s"] = np.asarray(result.duty_clipped_s, dtype=float).copy()
    out["controller_limited_s"] = np.asarray(result.controller_limited_s, dtype=float).copy()
    out["transient_axis"] = np.full(n, -1, dtype=np.int64)
    out["status"] = status
    out["stop_time_s"] = np.asarray(result.t_stop, dtype=float).copy()
    refs = result.references[:, :, REF_X:REF_X + 3]
    live = np.flatnonzero((status == 0) & np.isfinite(refs).all(axis=(1, 2)))
    not_settled = np.zeros(n, dtype=bool)
    if live.size:
        mission = result.meta.get("mission") if isinstance(result.meta.get("mission"), dict) else {}
        got = flight_metrics_batch(t, result.states[live, :, X:X + 3], refs[live],
                                   result.commands[live, :, CMD_U1:CMD_U1 + 4], mission=mission,
                                   bands=(0.02, 0.05, spec.settle_band), transient_until=spec.transient_until)
        for key in ("rmse_m", "max_error_m", "final_error_m", "effort", "transient_axis", "rise_time_s",
                    "overshoot_pct"):
            out[key][live] = got[key]
        out["settling_time_s"][live], out["settling_time_5pct_s"][live] = got["settling_s"][:2]
        not_settled[live] = (got["transient_axis"] >= 0) & np.isnan(got["settling_s"][2])
    diverged = status != 0
    saturated = out["duty_clipped_s"] > spec.max_clipped_s
    out.update(diverged=diverged, saturated=saturated, not_settled=not_settled)
    out["failure"] = np.select([diverged, saturated, not_settled], [1, 2, 3], 0).astype(np.int64)
    return out


# --- one case ---------------------------------------------------------------------------
@dataclass
class Case:
    """One vehicle of a sweep flown again alone: its flight and its table row."""

    vehicle: int
    result: Any
    row: dict


def montecarlo_case(spec: MonteCarloSpec, i: int, *, log_every: int | None = None) -> Case:
    """Fly vehicle i of a sweep alone (the draws and random streams of (seed, i)): its row
    of the table, equal to the sweep's row whatever chunk it was flown in, and its flight,
    logged at the spec's rate (or every ``log_every`` periods: 1 for all; the row is
    always computed at the spec's rate).

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
    """:func:`montecarlo_case` of vehicle i of a finished sweep."""
    if not 0 <= i < result.n:
        raise InputError(f"vehicle {i} is not in this sweep of {result.n} flights")
    return montecarlo_case(result.spec, i, **kw)
