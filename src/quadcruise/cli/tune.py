"""``quadcruise tune``: the command, its options and its help. What it runs (options to a tune,
its progress and summary printed, its folder written) is in :mod:`quadcruise.cli.tune_run`;
the library does the work (:func:`quadcruise.tune.tune`)."""

from __future__ import annotations

import sys

import click

from quadcruise.cli.common import SECONDS, friendly, writable
from quadcruise.cli.objects import PARAMS_OPTION
from quadcruise.cli.tune_run import tune_command
from quadcruise.cli.world import world_options

__all__ = ["tune"]


@click.command("tune")
@click.argument("mission", metavar="MISSION")
@click.option(
    "-m",
    "--mission-param",
    "mission_params",
    multiple=True,
    metavar="KEY=VALUE",
    help="Mission parameter, e.g. -m size=2 (repeatable).",
)
@click.option("--controller", help="Controller name (default: the scenario's, else nlpd).")
@PARAMS_OPTION
@click.option(
    "-c",
    "--controller-param",
    "controller_params",
    multiple=True,
    metavar="KEY=VALUE",
    help="Controller parameter kept during the search, e.g. -c derivative=error (repeatable).",
)
@click.option(
    "--gains",
    metavar="NAMES",
    help="Gains to search, comma-separated: position.kp,position.kd "
    "(the default), or a PD pair by its poles: position.wn,position.zeta.",
)
@click.option(
    "--bounds",
    multiple=True,
    metavar="NAME=LOW:HIGH",
    help="Bounds of a gain (repeatable); default: a decade either side of its value.",
)
@click.option(
    "--target",
    "targets",
    multiple=True,
    metavar="METRIC=VALUE[+-TOL]",
    help="A value to reach, e.g. rise_time_s=1 or overshoot_pct=4+-1.5 (repeatable).",
)
@click.option(
    "--require",
    "require",
    multiple=True,
    metavar="METRIC<=VALUE",
    help="A bound every candidate must keep, e.g. 'overshoot_pct<=5' (<, >=, > too; repeatable).",
)
@click.option("--minimize", multiple=True, metavar="METRIC", help="A metric to make small (repeatable).")
@click.option(
    "--samples",
    type=int,
    default=1,
    show_default=True,
    help="Perturbed vehicles each candidate flies (a robust tune with the spreads below).",
)
@click.option(
    "--objective",
    default="worst",
    show_default=True,
    help="Over a candidate's vehicles: worst, median, or a quantile such as q90.",
)
@click.option("--mass-spread", type=float, default=0.0, show_default=True, help="Relative std of the mass.")
@click.option("--inertia-spread", type=float, default=0.0, show_default=True, help="Relative std of each inertia.")
@world_options(wind_help="Wind of every flight (as quadcruise montecarlo --wind), e.g. dryden:moderate@10.", seed=False)
@click.option(
    "--wind-spread",
    type=float,
    default=0.0,
    show_default=True,
    help="Std of a random steady horizontal wind per vehicle [m/s].",
)
@click.option("--noise", metavar="position=STD,...,delay=S", help="Sensor noise and delay.")
@click.option(
    "--sensors",
    metavar="NAME[=PRESET],...",
    help="Sensor models every vehicle carries: imu, gps, baro, mag (preset typical, or e.g. imu=bmi088).",
)
@click.option(
    "--estimator",
    metavar="NAME",
    help="The estimator the candidates fly on: ekf (needs imu and gps), or none (tunes with it in the loop).",
)
@click.option("--seed", type=int, default=0, show_default=True, help="Seed of the search and the population.")
@click.option("--budget", type=int, default=100, show_default=True, help="At most this many generations.")
@click.option("--popsize", type=int, help="Candidates per generation (default: 15 per gain).")
@click.option("--duration", type=SECONDS, help="Flight time [s] (default: the mission's).")
@click.option("--dt", type=SECONDS, help="Control period [s] (default 0.001).")
@click.option(
    "--out",
    type=click.Path(file_okay=False),
    callback=writable,
    help="Folder: scenario.toml with the tuned gains, tune.json, history, flights, figure.",
)
@click.option("--force", is_flag=True, help="Replace a non-empty --out folder not written by quadcruise.")
@click.option("--quiet", is_flag=True, help="No progress lines.")
@friendly
def tune(**options):
    """Tune a controller's gains on a MISSION towards targets on its metrics.

    MISSION is circle, square, step, hover, sysid, a waypoint CSV, or a TOML scenario file (its
    vehicle, controller, disturbances and simulation settings). Each generation of candidates
    is one batched flight; with --samples M each candidate flies the same M perturbed vehicles
    and its cost is the worst (or --objective quantile) of theirs. Bad input is refused
    before any flight.

    \f
    Parameters
    ----------
    **options
        The options by parameter name, passed on to
        :func:`quadcruise.cli.tune_run.tune_command`.

        mission : str
            ``MISSION``: a mission name, a waypoint CSV or a TOML scenario file.
        mission_params : tuple of str
            ``-m``: the mission's parameters, each ``KEY=VALUE`` (not with a scenario).
        controller : str
            ``--controller``: the controller's name (a scenario's controller unless given).
        controller_params : tuple of str
            ``-c``: the controller's parameters, each ``KEY=VALUE``, kept during the search.
        px4_params : str or None
            ``--params``: PX4's parameters (a log or a ``.params`` file) of the px4 controller;
            with px4, ``--out`` also writes ``tuned.params``.
        gains : str or None
            ``--gains``: the gains searched, comma-separated.
        bounds : tuple of str
            ``--bounds``: ``NAME=LOW:HIGH`` each.
        targets : tuple of str
            ``--target``: ``METRIC=VALUE`` or ``METRIC=VALUE+-TOL`` each.
        require : tuple of str
            ``--require``: ``METRIC<=VALUE`` (or ``<``, ``>=``, ``>``) each.
        minimize : tuple of str
            ``--minimize``: metrics to make small.
        samples : int
            ``--samples``: perturbed vehicles per candidate.
        objective : str
            ``--objective``: worst, median or a quantile (``q90``, ``0.9``).
        mass_spread, inertia_spread, wind_spread : float
            ``--mass-spread``, ``--inertia-spread``: relative standard deviations;
            ``--wind-spread``: standard deviation of a steady wind per vehicle [m/s].
        wind, noise : str or None
            ``--wind``: a :func:`~quadcruise.cli.wind.parse_wind` spec; ``--noise``: a
            :func:`~quadcruise.cli.montecarlo_run.parse_noise` spec.
        sensors, estimator : str or None
            ``--sensors``, ``--estimator``: the sensor models and the estimator every candidate
            flies on (:mod:`quadcruise.cli.onboard`); None: the scenario's, else none.
        turbulence : str or None
            ``--turbulence``: Dryden turbulence added.
        vehicle, controller_vehicle : str or None
            ``--vehicle``, ``--controller-vehicle``: the nominal vehicle and the controller's
            model of it (:func:`~quadcruise.cli.objects.vehicle_from_option`).
        log_every : int or None
            ``--log-every``: the metrics are measured on a log of every this many control
            periods (default: 10 ms).
        seed, budget : int
            ``--seed``: seed of everything random; ``--budget``: the most generations.
        popsize : int or None
            ``--popsize``: candidates per generation.
        duration, dt : float or None
            ``--duration``, ``--dt``: flight time and control period [s].
        out : str or None
            ``--out``: the folder to write.
        force, quiet : bool
            ``--force``: replace a folder quadcruise did not write; ``--quiet``: no progress.
    """
    if not tune_command(**options, echo=click.echo).met:
        sys.exit(1)  # the tuned gains miss a target or a requirement (the summary says which)
