"""``quadcruise montecarlo``: options to a population, the sweep or one case flown, the summary
printed. The library does the work (:func:`quadcruise.montecarlo.montecarlo`)."""

from __future__ import annotations

import dataclasses
import sys
from pathlib import Path
from typing import Callable

import numpy as np

from quadcruise.disturbances import SensorNoise, parse_wind
from quadcruise.errors import InputError
from quadcruise.fields import parse_assignments
from quadcruise.io.files import check_output_dir
from quadcruise.montecarlo import Case, MonteCarloResult, MonteCarloSpec, Population, montecarlo, montecarlo_case
from quadcruise.montecarlo.output import write_case
from quadcruise.montecarlo.progress import ProgressBar
from quadcruise.montecarlo.store import holds_sweep
from quadcruise.workflows.scenario import load_scenario

__all__ = ["montecarlo_command", "parse_noise"]


def _from_scenario(path: str, given: dict):
    """The scenario, and the options ``given`` explicitly (Population fields, n, seed) with
    its [montecarlo] table (and [simulation] seed) filling the ones not given."""
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

    Parsed by :func:`quadcruise.fields.parse_assignments`; the values are checked by
    :class:`~quadcruise.disturbances.SensorNoise`.

    Parameters
    ----------
    text : str or None
        The spec: std of position [m], velocity [m/s], angles [rad], body rates [rad/s] and
        the delay [s]; any left out are 0. None, "" or "none": no sensor noise.

    Returns
    -------
    SensorNoise or None

    Examples
    --------
    >>> parse_noise("position=0.01,delay=0.002").delay
    0.002
    >>> parse_noise("jitter=1")
    Traceback (most recent call last):
        ...
    quadcruise.errors.InputError: noise spec 'jitter=1': unknown key 'jitter'; keys: position, velocity, angle, rate, delay
    """
    if text is None or str(text).strip().lower() in ("", "none"):
        return None
    names = {"position": "position_std", "velocity": "velocity_std", "angle": "angle_std",
             "rate": "rate_std", "delay": "delay"}
    return SensorNoise(**parse_assignments(text, "noise spec", keys=names, numbers=True))


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
