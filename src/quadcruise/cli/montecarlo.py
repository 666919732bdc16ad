"""``quadcruise montecarlo``: the command, its options and its help. What it runs (options to a
population, the sweep or one case flown, the summary printed) is in
:mod:`quadcruise.cli.montecarlo_run`, re-exported here; the library does the work
(:func:`quadcruise.montecarlo.montecarlo`)."""

from __future__ import annotations

import click

from quadcruise.cli.common import friendly
from quadcruise.cli.montecarlo_run import montecarlo_command, parse_noise

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
