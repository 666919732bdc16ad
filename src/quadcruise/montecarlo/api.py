"""Monte Carlo sweeps: a population of perturbed vehicles flown through the batched engine,
with the distribution of every metric, the failure rate and its reasons, the worst cases
(each replayable alone), histograms and an envelope of the paths.

This module holds the entry points; the pieces, from the bottom up:

- :class:`~quadcruise.montecarlo.population.Population` (:mod:`quadcruise.montecarlo.population`): relative
  spreads of the vehicle's parameters, an initial position offset, a random steady wind,
  an :class:`~quadcruise.disturbances.Environment` and
  :class:`~quadcruise.disturbances.SensorNoise`; where each vehicle's randomness comes from;
- :class:`~quadcruise.montecarlo.spec.MonteCarloSpec` (:mod:`quadcruise.montecarlo.spec`): the population
  with the mission, controller, nominal vehicle, seed, flight time and step: everything
  that fixes the flights (it has a :meth:`~quadcruise.montecarlo.spec.MonteCarloSpec.hash`);
- :func:`quadcruise.montecarlo.sweep.run_chunk`: vehicles ``first .. first + count - 1`` flown as one batch, reduced to
  one row of metrics each (:mod:`quadcruise.metrics.batch`) plus a few decimated paths. It
  is a pure function of ``(spec, first, count)``, and vehicle i's flight depends on
  ``(seed, i)`` only, so any split into chunks gives the same table;
- :func:`montecarlo`: the whole population, in process or on Dask (:mod:`quadcruise.montecarlo.sweep`),
  streamed to disk and resumable (:mod:`quadcruise.montecarlo.store`), returning a
  :class:`~quadcruise.montecarlo.result.MonteCarloResult` (:mod:`quadcruise.montecarlo.result`;
  its figures: :mod:`quadcruise.plots.montecarlo`; its folder:
  :mod:`quadcruise.montecarlo.output`);
- :func:`montecarlo_case` / :func:`replay_case`: one vehicle flown alone again;
- ``quadcruise montecarlo`` runs :func:`quadcruise.cli.montecarlo.montecarlo_command`.

Examples
--------
>>> from quadcruise.montecarlo import Population, montecarlo
>>> res = montecarlo("hover", "nlpd", Population(mass_spread=0.05, offset=0.1), n=4, seed=1,
...                  duration=0.5, scheduler="none")
>>> len(res.table), res.table["vehicle"].tolist()
(4, [0, 1, 2, 3])
>>> s = res.summary()                           # 0.5 s is too short to settle: a metric, not a failure
>>> s["failures"]["count"], s["not_settled"]["count"]
(0, 4)
>>> from quadcruise.montecarlo import Requirement
>>> montecarlo("hover", "nlpd", Population(offset=0.1), n=4, seed=1, duration=0.5, scheduler="none",
...            requirements=[Requirement("steady_max_error_m", "<=", 0.05)]).summary()["requirements"][0]["failed"]
4
"""

from __future__ import annotations

import dataclasses
import os
from collections.abc import Callable
from pathlib import Path
from typing import Any

from quadcruise import checks
from quadcruise.control import Controller, as_controller
from quadcruise.disturbances import CustomDisturbance, Environment, SensorNoise
from quadcruise.errors import InputError, reject_unknown
from quadcruise.missions import Mission, as_mission
from quadcruise.model.vehicle import Vehicle
from quadcruise.montecarlo.chunk import Case, montecarlo_case, replay_case
from quadcruise.montecarlo.population import Population
from quadcruise.montecarlo.requirements import as_requirements
from quadcruise.montecarlo.result import MonteCarloResult
from quadcruise.montecarlo.spec import MonteCarloSpec
from quadcruise.montecarlo.sweep import run_sweep

__all__ = ["Case", "montecarlo", "montecarlo_case", "replay_case"]


# --- the whole population ---------------------------------------------------------------
def montecarlo(
    mission: Mission | str = "circle",
    controller: Controller | str = "nlpd",
    population: Population | None = None,
    n: int = 100,
    seed: int = 0,
    *,
    environment: Environment | None = None,
    sensors: SensorNoise | None = None,
    chunk_size: int | str = "auto",
    scheduler: str | None = None,
    workers: int | None = None,
    out: str | Path | None = None,
    resume: bool = True,
    force: bool = False,
    fmt: str = "csv",
    progress: Callable[[int, int], None] | None = None,
    connect_timeout: float = 10.0,
    **spec_options: Any,
) -> MonteCarloResult:
    """Fly a population of n vehicles and collect one row of metrics per flight.

    Parameters
    ----------
    mission : Mission or str
        The mission, or its name for the defaults.
    controller : Controller or str
        The controller, or its name for the defaults.
    population : Population
        The spreads; none (n identical vehicles) by default.
    n : int
        Number of flights (>= 1).
    seed : int
        Flight i depends on (seed, i) only.
    chunk_size : int or "auto"
        Vehicles per chunk (per task). "auto" keeps a chunk's log near 64 MB and gives each
        worker several chunks. The result does not depend on it.
    environment : Environment, optional
        The disturbances every vehicle meets (the population's ``environment``, if it has none).
    sensors : SensorNoise, optional
        Every vehicle's sensor noise and delay (the population's ``noise``, if it has none).
    scheduler : None, "none", "local" or an address
        None or "none" (default): in this process, numba using all cores, so a script needs
        no ``if __name__ == "__main__":`` guard; "local": a Dask LocalCluster of ``workers``
        processes (the machine's cores by default), one thread each — its worker processes
        are spawned, so a script using it needs that guard; "tcp://host:port": an existing
        Dask cluster (unreachable: InputError).
    workers : int, optional
        Worker processes of the "local" cluster; the machine's cores by default.
    out : str or pathlib.Path, optional
        Stream each chunk to ``out/chunks`` as it finishes and write the results at the end
        (see :mod:`quadcruise.montecarlo.store`). A folder holding part of the same sweep is resumed.
    resume : bool
        Load the chunks of this same sweep found in ``out`` instead of flying them again.
    force : bool
        Replace a folder holding something else (else InputError).
    fmt : {"csv", "parquet"}
        Format of the flights table.
    progress : callable, optional
        ``progress(done, total)`` after each chunk (flights done, resumed ones included);
        the command line's :class:`quadcruise.cli.feedback.Bar` draws it on a terminal.
    connect_timeout : float
        Time to wait for a scheduler given by address [s].
    **spec_options
        More :class:`MonteCarloSpec` fields: duration [s], dt [s], vehicle, log_dt [s],
        settle_band, ``requirements`` (your own pass criteria, e.g.
        ``[Requirement("steady_max_error_m", "<=", 0.2)]`` or
        ``{"steady_max_error_m": ("<=", 0.2)}``), ``max_track_error_m`` [m] (the "lost track"
        bound), ...

    Returns
    -------
    MonteCarloResult
        One table row per flight, the kept paths, the summary and how it ran.
    """
    spec_fields = [f.name for f in dataclasses.fields(MonteCarloSpec) if f.init]
    reject_unknown(
        "montecarlo()",
        {k: v for k, v in spec_options.items() if k not in spec_fields},
        [
            "chunk_size",
            "environment",
            "force",
            "fmt",
            "out",
            "progress",
            "resume",
            "scheduler",
            "sensors",
            "workers",
            "connect_timeout",
            *(f for f in spec_fields if f not in ("mission", "controller")),
        ],
    )
    check_montecarlo_arguments(
        mission,
        controller,
        population,
        n,
        seed,
        environment,
        sensors,
        chunk_size,
        scheduler,
        workers,
        out,
        resume,
        force,
        progress,
        connect_timeout,
        spec_options,
    )
    population = population or Population()
    if environment is not None or sensors is not None:
        if (environment is not None and population.environment is not None) or (
            sensors is not None and population.noise is not None
        ):
            raise InputError("give the environment and sensors either to montecarlo() or to the Population, not both")
        population = dataclasses.replace(
            population,
            environment=population.environment if environment is None else environment,
            noise=population.noise if sensors is None else sensors,
        )
    spec = MonteCarloSpec(mission=mission, controller=controller, population=population, seed=seed, **spec_options)
    return run_sweep(
        spec,
        n,
        chunk_size=chunk_size,
        scheduler=scheduler,
        workers=workers,
        out=out,
        resume=resume,
        force=force,
        fmt=fmt,
        progress=progress,
        connect_timeout=connect_timeout,
    )


def check_montecarlo_arguments(
    mission,
    controller,
    population,
    n,
    seed,
    environment,
    sensors,
    chunk_size,
    scheduler,
    workers,
    out,
    resume,
    force,
    progress,
    connect_timeout,
    spec_options: dict,
) -> None:
    """:func:`montecarlo`'s arguments checked, before any work, in the API's one message form
    (:mod:`quadcruise.checks`): a wrong type is an ArgumentTypeError, a bad value an InputError."""
    w = "montecarlo()"
    as_mission(mission, w)
    as_controller(controller, w)
    checks.instance(w, "population", population, Population)
    checks.whole(w, "n", n, 1)
    checks.whole(w, "seed", seed)
    checks.instance(w, "environment", environment, (Environment, CustomDisturbance))
    checks.instance(w, "sensors", sensors, SensorNoise)
    if not (isinstance(chunk_size, str) and chunk_size == "auto"):
        checks.whole(w, "chunk_size", chunk_size, 1)
    checks.instance(w, "scheduler", scheduler, str, want='"none", "local" or a scheduler address')
    checks.whole(w, "workers", workers, 1, optional=True)
    checks.instance(w, "out", out, (str, os.PathLike), want="a folder path")
    checks.flag(w, "resume", resume)
    checks.flag(w, "force", force)
    checks.callback(w, "progress", progress)
    checks.number(w, "connect_timeout", connect_timeout, "pos", unit="s")
    for name in ("duration", "dt", "log_dt", "trace_dt"):
        if name in spec_options:
            checks.number(w, name, spec_options[name], "pos", unit="s", optional=name == "duration")
    if "vehicle" in spec_options:
        checks.instance(w, "vehicle", spec_options["vehicle"], Vehicle, optional=False)
    if "requirements" in spec_options:
        as_requirements(spec_options["requirements"], w)


# --- command line -----------------------------------------------------------------------
