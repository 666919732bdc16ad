"""``quadcruise montecarlo``: options to a population, the sweep or one case flown, the summary
printed. The library does the work (:func:`quadcruise.montecarlo.montecarlo`)."""

from __future__ import annotations

import sys
from typing import TYPE_CHECKING, Callable

import click

from quadcruise.cli.common import friendly
from quadcruise.errors import InputError

if TYPE_CHECKING:
    from quadcruise.montecarlo import Case, MonteCarloResult

__all__ = ["montecarlo", "montecarlo_command", "parse_noise"]


@click.command("montecarlo")
@click.option("--mission", default="circle", show_default=True, help="Mission name.")
@click.option("--controller", default="nlpd", show_default=True, help="Controller name.")
@click.option("-n", "--n", "n", type=int, show_default="1000", help="Number of flights.")
@click.option("--seed", type=int, show_default="0", help="Seed of every random draw.")
@click.option("--duration", type=float, help="Flight time [s] (default: the mission's).")
@click.option("--dt", type=float, help="Control period [s] (default 0.001, or the scenario's).")
@click.option("--wind", metavar="SPEC", help="Wind: constant:WX,WY,WZ | gust:AX,AY,AZ@START+DURATION | "
              "dryden:light|moderate|severe@ALTITUDE (comma-separable).")
@click.option("--wind-spread", type=float, show_default="0",
              help="Std of a random steady horizontal wind per flight [m/s].")
@click.option("--mass-spread", type=float, show_default="0", help="Relative std of the mass.")
@click.option("--inertia-spread", type=float, show_default="0", help="Relative std of each inertia.")
@click.option("--thrust-spread", type=float, show_default="0", help="Relative std of K.")
@click.option("--bandwidth-spread", type=float, show_default="0",
              help="Relative std of the actuator bandwidth.")
@click.option("--yaw-arm-spread", type=float, show_default="0", help="Relative std of d.")
@click.option("--distribution", type=click.Choice(["normal", "uniform"]), show_default="normal")
@click.option("--offset", type=float, show_default="0", help="Std of the start position [m].")
@click.option("--noise", metavar="position=STD,velocity=STD,angle=STD,rate=STD,delay=S",
              help="Sensor noise and delay.")
@click.option("--model-error/--no-model-error", default=None, show_default="model-error",
              help="The controller flies with the nominal model, not each vehicle's own.")
@click.option("--chunk-size", default="auto", show_default=True, help="Flights per task.")
@click.option("--scheduler", default="local", show_default=True,
              help="local (a Dask cluster of processes here), none (in this process) or a Dask address.")
@click.option("--workers", type=int, help="Workers of the local cluster.")
@click.option("--connect-timeout", type=float, default=10.0, show_default=True, help="[s] for --scheduler ADDRESS.")
@click.option("--out", type=click.Path(file_okay=False), help="Folder: chunks stream here, so a rerun resumes.")
@click.option("--force", is_flag=True, help="Replace a folder holding something else.")
@click.option("--resume/--no-resume", default=True, show_default=True)
@click.option("--format", "fmt", type=click.Choice(["csv", "parquet"]), default="csv", show_default=True)
@click.option("--require", "requirements", multiple=True, metavar="METRIC<=VALUE",
              help='Your own pass criterion, e.g. "steady_max_error_m<=0.2" (or <, >=, >; repeatable).')
@click.option("--max-track-error", "max_track_error_m", type=float, metavar="M",
              help="Error after the transient [m] beyond which a flight lost track (default: max(1, extent/4)).")
@click.option("--case", type=int, help="Fly flight I alone (replays a worst case exactly).")
@click.option("--worst", type=int, default=5, show_default=True, help="How many worst cases to list.")
@click.option("--quiet", is_flag=True, help="No progress bar.")
@click.option("--scenario", type=click.Path(dir_okay=False), metavar="FILE.toml",
              help="Mission, controller, vehicle, disturbances and a [montecarlo] table from a scenario file.")
@friendly
def montecarlo(**options):
    """Fly a population of perturbed vehicles and report the distribution of every metric.

    Runs on Dask (a local cluster of processes by default); results stream to --out as
    chunks finish, so an interrupted sweep resumes where it stopped. Every draw comes from
    --seed, whatever the chunking or the machine.
    """
    montecarlo_command(**options, echo=click.echo)


def parse_noise(text: str | None):
    """Parse a sensor noise spec, ``position=STD,velocity=STD,angle=STD,rate=STD,delay=S``.

    Parameters
    ----------
    text : str or None
        The spec; None, "" or "none" for no noise.

    Returns
    -------
    SensorNoise or None

    Raises
    ------
    InputError
        An unknown key, an item without ``=``, or a value that is not a number.

    Examples
    --------
    >>> parse_noise("position=0.01,delay=0.002").delay
    0.002
    """
    if text is None or str(text).strip().lower() in ("", "none"):
        return None
    from quadcruise.disturbances import SensorNoise

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
                       wind: str | None = None, wind_spread: float | None = None, offset: float | None = None,
                       mass_spread: float | None = None, inertia_spread: float | None = None, noise: str | None = None,
                       thrust_spread: float | None = None, bandwidth_spread: float | None = None,
                       yaw_arm_spread: float | None = None, distribution: str | None = None,
                       model_error: bool | None = None, chunk_size: str | int = "auto", scheduler: str = "local",
                       workers: int | None = None, connect_timeout: float = 10.0, out: str | None = None,
                       force: bool = False, resume: bool = True, fmt: str = "csv", case: int | None = None,
                       worst: int = 5, quiet: bool = False, scenario: str | None = None,
                       requirements: tuple[str, ...] = (), max_track_error_m: float | None = None,
                       echo: Callable[[str], None] = click.echo) -> MonteCarloResult | Case:
    """What ``quadcruise montecarlo`` runs: build the population, fly it (or one case), print
    the summary and the worst flights, write ``out``.

    Parameters
    ----------
    mission, controller, n, seed, duration, dt, scenario, requirements, max_track_error_m
        As :func:`quadcruise.montecarlo.scenario.sweep_spec`: None means "not given" (a
        ``scenario`` file's value, else the default).
    wind, noise : str, optional
        A :func:`~quadcruise.disturbances.parse_wind` spec and a :func:`parse_noise` one.
    mass_spread, inertia_spread, thrust_spread, bandwidth_spread, yaw_arm_spread, wind_spread, \
offset, distribution, model_error : optional
        :class:`~quadcruise.montecarlo.Population` fields.
    chunk_size : int or str
        Flights per task: a number (also as text) or "auto".
    scheduler, workers, connect_timeout, out, resume, force, fmt
        As :func:`quadcruise.montecarlo.montecarlo`.
    case : int, optional
        Fly flight ``case`` alone; with ``out``, write it there (into ``out/case-00000I`` beside its sweep).
    worst, quiet : int, bool
        How many worst flights to print; no progress bar.
    echo : callable
        Prints one text.

    Returns
    -------
    MonteCarloResult or Case
        The sweep, or the one flight.

    Raises
    ------
    InputError
        Bad input, before anything is written.
    """
    import numpy as np

    from quadcruise.disturbances import parse_wind
    from quadcruise.montecarlo import montecarlo_case
    from quadcruise.montecarlo.output import case_folder, case_text, write_case
    from quadcruise.montecarlo.progress import ProgressBar
    from quadcruise.montecarlo.scenario import sweep_spec
    from quadcruise.montecarlo.sweep import run_sweep

    if isinstance(chunk_size, str) and chunk_size != "auto":
        try:
            chunk_size = int(chunk_size)
        except ValueError:
            raise InputError(f"--chunk-size must be a whole number or auto, got {chunk_size!r}") from None
    spec, n = sweep_spec(mission=mission, controller=controller, n=n, seed=seed, duration=duration, dt=dt,
                         environment=parse_wind(wind) if wind is not None else None, noise=parse_noise(noise),
                         scenario=scenario, mass_spread=mass_spread, inertia_spread=inertia_spread,
                         thrust_spread=thrust_spread, bandwidth_spread=bandwidth_spread, offset=offset,
                         yaw_arm_spread=yaw_arm_spread, wind_spread=wind_spread, distribution=distribution,
                         model_error=model_error, requirements=requirements, max_track_error_m=max_track_error_m)
    if case is not None:
        if isinstance(case, bool) or not isinstance(case, (int, np.integer)) or not 0 <= case < n:
            raise InputError(f"--case {case} is not one of the {n} flights")
        target = case_folder(out, spec, case, force=force)
        found = montecarlo_case(spec, case)
        echo(case_text(found, spec.seed))
        if target is not None:
            write_case(found, target, fmt=fmt, force=True)
            echo(f"wrote the flight to {target}")
        return found
    bar = None if quiet else ProgressBar(sys.stderr)
    try:
        res = run_sweep(spec, n, chunk_size=chunk_size, scheduler=scheduler, workers=workers, out=out,
                        resume=resume, force=force, fmt=fmt, progress=bar, connect_timeout=connect_timeout)
    finally:
        if bar is not None:
            bar.close()
    echo(res.summary_text(worst=worst))
    info = res.info
    echo(f"{info.get('flown', 0):,} flights flown ({info.get('resumed', 0):,} resumed) in {info.get('wall_s', 0):.1f} s "
         f"on {info.get('scheduler')}" + (f"; wrote {out}" if out is not None else ""))
    return res
