"""Monte Carlo sweeps: a population of perturbed vehicles flown through the batched engine,
with the distribution of every metric, the failure rate and its reasons, the worst cases
(each replayable alone), histograms and an envelope of the paths.

This module holds the entry points; the pieces, from the bottom up:

- :class:`~quadcruise.population.Population` (:mod:`quadcruise.population`): relative
  spreads of the vehicle's parameters, an initial position offset, a random steady wind,
  an :class:`~quadcruise.disturbances.Environment` and
  :class:`~quadcruise.disturbances.SensorNoise`; where each vehicle's randomness comes from;
- :class:`~quadcruise.mcspec.MonteCarloSpec` (:mod:`quadcruise.mcspec`): the population
  with the mission, controller, nominal vehicle, seed, flight time and step: everything
  that fixes the flights (it has a :meth:`~quadcruise.mcspec.MonteCarloSpec.hash`);
- :func:`quadcruise.sweep.run_chunk`: vehicles ``first .. first + count - 1`` flown as one batch, reduced to
  one row of metrics each (:mod:`quadcruise.metrics_batch`) plus a few decimated paths. It
  is a pure function of ``(spec, first, count)``, and vehicle i's flight depends on
  ``(seed, i)`` only, so any split into chunks gives the same table;
- :func:`montecarlo`: the whole population, in process or on Dask (:mod:`quadcruise.sweep`),
  streamed to disk and resumable (:mod:`quadcruise.sweep_store`), returning a
  :class:`~quadcruise.montecarlo_result.MonteCarloResult` (:mod:`quadcruise.montecarlo_result`;
  its figures: :mod:`quadcruise.plots_montecarlo`; its folder:
  :mod:`quadcruise.montecarlo_output`);
- :func:`montecarlo_case` / :func:`replay_case`: one vehicle flown alone again;
- :func:`montecarlo_command`: what ``quadcruise montecarlo`` runs.

Examples
--------
>>> from quadcruise.montecarlo import Population, montecarlo
>>> res = montecarlo("hover", "nlpd", Population(mass_spread=0.05, offset=0.1), n=4, seed=1,
...                  duration=0.5, scheduler="none")
>>> len(res.table), res.table["vehicle"].tolist()
(4, [0, 1, 2, 3])
>>> res.summary()["failures"]["count"]             # 0.5 s is too short to settle
4
"""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path
from typing import Any, Callable

import numpy as np

from .control import Controller
from .errors import InputError, whole_number
from .io import check_output_dir
from .mcspec import MonteCarloSpec
from .missions import Mission
from .montecarlo_output import write_case
from .montecarlo_result import COLUMNS, FAILURES, METRICS, MonteCarloResult, Traces
from .population import Population
from .progress import ProgressBar
from .sweep import fly_chunk, reduce_chunk, run_sweep
from .sweep_store import holds_sweep

__all__ = ["Population", "MonteCarloSpec", "MonteCarloResult", "Traces", "Case", "montecarlo",
           "montecarlo_case", "replay_case", "montecarlo_command", "parse_noise", "FAILURES",
           "COLUMNS", "METRICS"]


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


def replay_case(result: MonteCarloResult, i: int, **kw) -> Case:
    """:func:`montecarlo_case` of vehicle i of a finished sweep."""
    if not 0 <= i < result.n:
        raise InputError(f"vehicle {i} is not in this sweep of {result.n} flights")
    return montecarlo_case(result.spec, i, **kw)


# --- the whole population ---------------------------------------------------------------
def montecarlo(mission: Mission | str = "circle", controller: Controller | str = "nlpd",
               population: Population | None = None, n: int = 100, seed: int = 0, *,
               chunk_size: int | str = "auto", scheduler: str | None = "local", workers: int | None = None,
               out: str | Path | None = None, resume: bool = True, force: bool = False, fmt: str = "csv",
               progress: Callable[[int, int], None] | None = None, connect_timeout: float = 10.0,
               **spec_options: Any) -> MonteCarloResult:
    """Fly a population of n vehicles and collect one row of metrics per flight.

    Parameters
    ----------
    mission, controller : names or objects
    population : Population
        The spreads; none (n identical vehicles) by default.
    n : int
        Number of flights (>= 1).
    seed : int
        Flight i depends on (seed, i) only.
    chunk_size : int or "auto"
        Vehicles per chunk (per task). "auto" keeps a chunk's log near 64 MB and gives each
        worker several chunks. The result does not depend on it.
    scheduler : "local", "none" or an address
        "local" (default): a Dask LocalCluster of ``workers`` processes (the machine's
        cores by default), one thread each; "none": in this process, numba using all cores;
        "tcp://host:port": an existing Dask cluster (unreachable: InputError). Worker
        processes are spawned, so a script using "local" needs the usual
        ``if __name__ == "__main__":`` guard.
    out : folder, optional
        Stream each chunk to ``out/chunks`` as it finishes and write the results at the end
        (see :mod:`quadcruise.sweep_store`). A folder holding part of the same sweep is resumed.
    resume, force : bool
        resume=False flies everything again; force replaces a folder holding something else.
    fmt : "csv" or "parquet"
        Format of the flights table.
    progress : callable, optional
        ``progress(done, total)`` after each chunk (flights done, resumed ones included);
        :class:`quadcruise.progress.ProgressBar` prints a line on stderr.
    connect_timeout : float
        Seconds to wait for a scheduler given by address.
    **spec_options
        More :class:`MonteCarloSpec` fields: duration, dt, vehicle, log_dt, settle_band, ...
    """
    spec = MonteCarloSpec(mission=mission, controller=controller, population=population or Population(),
                          seed=seed, **spec_options)
    return run_sweep(spec, n, chunk_size=chunk_size, scheduler=scheduler, workers=workers, out=out,
                     resume=resume, force=force, fmt=fmt, progress=progress, connect_timeout=connect_timeout)


# --- command line -----------------------------------------------------------------------
def _from_scenario(path: str, given: dict):
    """The scenario, and the options ``given`` explicitly (Population fields, n, seed) with
    its [montecarlo] table (and [simulation] seed) filling the ones not given."""
    import dataclasses

    from .scenario import load_scenario

    sc = load_scenario(path)
    table = dict(sc.montecarlo)
    known = {f.name for f in dataclasses.fields(Population)} - {"environment", "noise"}
    unknown = set(table) - known - {"n", "seed"}
    if unknown:
        raise InputError(f"{path}: [montecarlo] unknown key(s) {', '.join(sorted(unknown))} "
                         f"(known: n, seed, {', '.join(sorted(known))})")
    if "seed" in sc.simulation:
        table.setdefault("seed", sc.simulation["seed"])
    return sc, {**table, **given}


def parse_noise(text: str | None):
    """``position=STD,velocity=STD,angle=STD,rate=STD,delay=S`` -> SensorNoise (None: none).

    >>> parse_noise("position=0.01,delay=0.002").delay
    0.002
    """
    from .disturbances import SensorNoise

    if text is None or str(text).strip().lower() in ("", "none"):
        return None
    names = {"position": "position_std", "velocity": "velocity_std", "angle": "angle_std",
             "rate": "rate_std", "delay": "delay"}
    kw = {}
    for item in str(text).split(","):
        key, sep, value = item.partition("=")
        key = key.strip().lower()
        if not sep or key not in names:
            raise InputError(f"noise spec {text!r}: expected KEY=VALUE with KEY one of {', '.join(names)}")
        try:
            kw[names[key]] = float(value)
        except ValueError:
            raise InputError(f"noise spec {text!r}: {key} must be a number, got {value.strip()!r}") from None
    return SensorNoise(**kw)


def montecarlo_command(*, mission: str = "circle", controller: str = "nlpd", n: int | None = None,
                       seed: int | None = None, duration: float | None = None, dt: float | None = None,
                       wind: str | None = None, wind_spread: float | None = None,
                       mass_spread: float | None = None, inertia_spread: float | None = None,
                       thrust_spread: float | None = None, bandwidth_spread: float | None = None,
                       yaw_arm_spread: float | None = None, distribution: str | None = None,
                       offset: float | None = None, noise: str | None = None,
                       model_error: bool | None = None, chunk_size: str | int = "auto", scheduler: str = "local",
                       workers: int | None = None, connect_timeout: float = 10.0, out: str | None = None,
                       force: bool = False, resume: bool = True, fmt: str = "csv", case: int | None = None,
                       worst: int = 5, quiet: bool = False, scenario: str | None = None,
                       echo: Callable[[str], None] = print) -> MonteCarloResult | Case:
    """What ``quadcruise montecarlo`` runs: build the population, fly it, print the summary
    and the worst cases, write ``out``.

    With ``case=I`` only flight I is flown (alone; its row equals the sweep's) and, with
    ``out``, written with its traces and a figure: into ``out/case-00000I`` if ``out`` holds
    the sweep (whose options must be the same), else into ``out``. Bad input raises
    InputError before anything is written; ``chunk_size`` may be a number or "auto";
    ``wind`` is a :func:`~quadcruise.disturbances.parse_wind` spec and ``noise`` a
    :func:`parse_noise` one. A ``scenario`` file supplies the mission, controller, nominal
    vehicle, disturbances, sensor noise and simulation settings, and its ``[montecarlo]``
    table any of n, seed and the Population fields; options given explicitly win. None
    means "not given": n 1000, seed 0, dt 1 ms and the Population's defaults, unless the
    scenario sets them.
    """
    import sys

    from .disturbances import parse_wind

    if isinstance(chunk_size, str) and chunk_size != "auto":
        try:
            chunk_size = int(chunk_size)
        except ValueError:
            raise InputError(f"--chunk-size must be a whole number or auto, got {chunk_size!r}") from None
    env = parse_wind(wind) if wind is not None else None
    given = dict(mass_spread=mass_spread, inertia_spread=inertia_spread, thrust_spread=thrust_spread,
                 bandwidth_spread=bandwidth_spread, yaw_arm_spread=yaw_arm_spread, offset=offset,
                 wind_spread=wind_spread, distribution=distribution, model_error=model_error, n=n, seed=seed)
    given = {key: value for key, value in given.items() if value is not None}
    sensor = parse_noise(noise)
    options: dict = dict(duration=duration, dt=1e-3 if dt is None else dt)
    sc = None
    if scenario is not None:
        sc, given = _from_scenario(scenario, given)
    n, seed = given.pop("n", 1000), given.pop("seed", 0)
    spreads = given
    if sc is not None:
        mission = sc.mission or mission
        controller = sc.controller or controller
        env = env if env is not None else sc.environment
        sensor = sensor if sensor is not None else sc.sensor_noise
        options.update(vehicle=sc.vehicle, duration=duration or sc.duration,
                       dt=sc.dt if dt is None else dt, max_step=sc.simulation.get("max_step"),
                       full_dynamics=sc.simulation.get("full_dynamics", False))
    population = Population(**spreads, environment=env if env is not None and env.parts else None, noise=sensor)
    if case is not None:
        spec = MonteCarloSpec(mission=mission, controller=controller, population=population, seed=seed, **options)
        if isinstance(case, bool) or not isinstance(case, (int, np.integer)) or not 0 <= case < n:
            raise InputError(f"--case {case} is not one of the {n} flights")
        target = None if out is None else Path(out)
        meta, same = holds_sweep(target, spec) if target is not None else (None, False)
        if meta and meta.get("workflow") == "montecarlo":      # a sweep's folder: the case goes inside
            if not same:
                raise InputError(f"{out}: holds a sweep flown with other options or code (spec {meta.get('spec_hash')}, "
                                 f"these give {spec.hash()}); give the sweep's options to replay its flight")
            target = target / f"case-{case:06d}"
        if target is not None:
            check_output_dir(target, force)
        found = montecarlo_case(spec, case)
        echo(f"flight {case} of seed {seed}: {found.row['reason']}, " + ", ".join(
            f"{k} = {found.row[k]:.4g}" for k in ("rmse_m", "max_error_m", "settling_time_5pct_s", "m")))
        if target is not None:
            write_case(found, target, fmt=fmt, force=True)
            echo(f"wrote the flight to {target}")
        return found
    bar = None if quiet else ProgressBar(sys.stderr)
    try:
        res = montecarlo(mission, controller, population, n, seed, chunk_size=chunk_size, scheduler=scheduler,
                         workers=workers, out=out, resume=resume, force=force, fmt=fmt, progress=bar,
                         connect_timeout=connect_timeout, **options)
    finally:
        if bar is not None:
            bar.close()
    echo(res.summary_text())
    if worst:
        cols = ["vehicle", "seed", "reason", "rmse_m", "max_error_m", "settling_time_5pct_s", "stop_time_s", "m"]
        echo(f"worst {worst} (fly one alone again with --case VEHICLE):")
        echo(res.worst(worst)[cols].to_string(index=False, float_format=lambda v: f"{v:.4g}"))
    info = res.info
    echo(f"{info.get('flown', 0):,} flights flown ({info.get('resumed', 0):,} resumed) in {info.get('wall_s', 0):.1f} s "
         f"on {info.get('scheduler')}" + (f"; wrote {out}" if out is not None else ""))
    return res
