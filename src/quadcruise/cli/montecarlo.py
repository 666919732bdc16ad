"""``quadcruise montecarlo``: the command, its options and its help. What it runs (options to a
population, the sweep or one case flown, the summary printed) is in
:mod:`quadcruise.cli.montecarlo_run`, re-exported here; the library does the work
(:func:`quadcruise.montecarlo.montecarlo`)."""

from __future__ import annotations

import click

from quadcruise.cli.common import SECONDS, friendly, writable
from quadcruise.cli.montecarlo_run import montecarlo_command, parse_noise
from quadcruise.cli.objects import PARAMS_OPTION
from quadcruise.cli.world import world_options

__all__ = ["montecarlo", "montecarlo_command", "parse_noise"]


@click.command("montecarlo")
@click.option(
    "--mission",
    help="Mission: a name, a waypoint CSV or a scenario file (as --scenario); default: the scenario's, else circle.",
)
@click.option("--controller", help="Controller name (default: the scenario's, else nlpd).")
@PARAMS_OPTION
@click.option("-n", "--n", "n", type=int, show_default="1000", help="Number of flights.")
@click.option("--seed", type=int, show_default="0", help="Seed of every random draw.")
@click.option("--duration", type=SECONDS, help="Flight time [s] (default: the mission's).")
@click.option("--dt", type=SECONDS, help="Control period [s] (default 0.001, or the scenario's).")
@world_options(
    wind_help="Wind of every flight: constant:WX,WY,WZ | gust:AX,AY,AZ@START+DURATION | "
    "dryden:light|moderate|severe@ALTITUDE | loss:ROTOR,FRACTION@TIME (comma-separable).",
    seed=False,
)
@click.option(
    "--wind-spread", type=float, show_default="0", help="Std of a random steady horizontal wind per flight [m/s]."
)
@click.option("--mass-spread", type=float, show_default="0", help="Relative std of the mass.")
@click.option("--inertia-spread", type=float, show_default="0", help="Relative std of each inertia.")
@click.option("--thrust-spread", type=float, show_default="0", help="Relative std of K (kf on a rotor vehicle).")
@click.option("--bandwidth-spread", type=float, show_default="0", help="Relative std of the actuator bandwidth.")
@click.option("--yaw-arm-spread", type=float, show_default="0", help="Relative std of d (km on a rotor vehicle).")
@click.option(
    "--aero-spread", type=float, show_default="0", help="Relative std of a rotor vehicle's aerodynamic coefficients."
)
@click.option(
    "--population",
    "identification",
    type=click.Path(),
    metavar="DIR/identify.json",
    help="Draw the parameters identify found from their estimate and covariance (the vehicles the log is "
    "consistent with); the nominal vehicle is that folder's vehicle.toml unless --vehicle is given.",
)
@click.option("--distribution", type=click.Choice(["normal", "uniform"]), show_default="normal")
@click.option("--offset", type=float, show_default="0", help="Std of the start position [m].")
@click.option("--noise", metavar="position=STD,velocity=STD,angle=STD,rate=STD,delay=S", help="Sensor noise and delay.")
@click.option(
    "--sensors",
    "sensors_text",
    metavar="NAME[=PRESET],...",
    help="Sensor models every vehicle carries: imu, gps, baro, mag (preset typical, or e.g. imu=bmi088).",
)
@click.option(
    "--estimator",
    "estimator_text",
    metavar="NAME",
    help="The estimator the controller flies on: ekf (needs imu and gps), or none; "
    "the summary adds its error and NEES.",
)
@click.option("--imu-noise-spread", type=float, show_default="0", help="Relative std of each vehicle's IMU noise.")
@click.option("--gps-noise-spread", type=float, show_default="0", help="Relative std of each vehicle's GPS noise.")
@click.option(
    "--model-error/--no-model-error",
    default=None,
    show_default="model-error",
    help="The controller flies with the nominal model, not each vehicle's own.",
)
@click.option("--chunk-size", default="auto", show_default=True, help="Flights per task.")
@click.option(
    "--scheduler",
    default="local",
    show_default=True,
    help="local (a Dask cluster of processes here), none (in this process) or a Dask address.",
)
@click.option("--workers", type=int, help="Workers of the local cluster.")
@click.option("--connect-timeout", type=float, default=10.0, show_default=True, help="[s] for --scheduler ADDRESS.")
@click.option(
    "--out", type=click.Path(file_okay=False), callback=writable, help="Folder: chunks stream here, so a rerun resumes."
)
@click.option("--force", is_flag=True, help="Replace a folder holding something else.")
@click.option("--resume/--no-resume", default=True, show_default=True)
@click.option("--format", "fmt", type=click.Choice(["csv", "parquet"]), default="csv", show_default=True)
@click.option(
    "--require",
    "requirements",
    multiple=True,
    metavar="METRIC<=VALUE",
    help='Your own pass criterion, e.g. "steady_max_error_m<=0.2" (or <, >=, >; repeatable).',
)
@click.option(
    "--max-track-error",
    "max_track_error_m",
    type=float,
    metavar="M",
    help="Error after the transient [m] beyond which a flight lost track (default: max(1, extent/4)).",
)
@click.option("--case", type=int, help="Fly flight I alone (replays a worst case exactly).")
@click.option("--worst", type=int, default=5, show_default=True, help="How many worst cases to list.")
@click.option("--quiet", is_flag=True, help="No progress bar.")
@click.option(
    "--scenario",
    type=click.Path(dir_okay=False),
    metavar="FILE.toml",
    help="Mission, controller, vehicle, disturbances and a [montecarlo] table from a scenario file.",
)
@friendly
def montecarlo(**options):
    """Fly a population of perturbed vehicles and report the distribution of every metric.

    Runs on Dask (a local cluster of processes by default); results stream to --out as
    chunks finish, so an interrupted sweep resumes where it stopped. Every draw comes from
    --seed, whatever the chunking or the machine.

    \f
    Parameters
    ----------
    **options
        The options by parameter name, passed on to :func:`montecarlo_command`. An option
        without a default is None when not given: the ``scenario`` file's value, else the
        default that ``--help`` shows.

        mission, controller : str
            ``--mission``, ``--controller``: the mission's and the controller's names.
        px4_params : str or None
            ``--params``: PX4's parameters (a log or a ``.params`` file) flown by the px4 controller.
        n : int or None
            ``-n``/``--n``: number of flights.
        seed : int or None
            ``--seed``: seed of every random draw.
        duration : float or None
            ``--duration``: flight time [s]; None: the scenario's, else the mission's.
        dt : float or None
            ``--dt``: control period [s]; None: the scenario's, else 0.001 s.
        vehicle, controller_vehicle : str or None
            ``--vehicle``: the nominal vehicle (the population's centre);
            ``--controller-vehicle``: the vehicle every controller believes it flies (its model;
            default the nominal one). See :func:`~quadcruise.cli.objects.vehicle_from_option`.
        wind : str or None
            ``--wind``: wind, gust and turbulence of every flight, a
            :func:`~quadcruise.cli.wind.parse_wind` spec; None: the scenario's, else none.
        turbulence : str or None
            ``--turbulence``: Dryden turbulence added (its random stream differs by vehicle).
        log_every : int or None
            ``--log-every``: the metrics are measured on a log of every this many control
            periods (the spec's ``log_dt``; default 10 ms).
        wind_spread : float or None
            ``--wind-spread``: standard deviation of a random steady horizontal wind drawn per
            flight [m/s].
        mass_spread, inertia_spread, thrust_spread, bandwidth_spread, yaw_arm_spread, aero_spread : float or None
            ``--mass-spread`` .. ``--aero-spread``: relative standard deviations of the
            mass m, of each inertia, of the thrust gain K, of the actuator bandwidth, of the
            yaw moment arm d, and of a rotor-plant vehicle's aerodynamic coefficients (on a
            rotor-plant vehicle: kf, 1 / tau_up and 1 / tau_down, km; :mod:`quadcruise.montecarlo.population`).
        identification : str or None
            ``--population``: an ``identify.json`` (or its folder) whose identified parameters
            each vehicle draws from their estimated distribution
            (:meth:`~quadcruise.montecarlo.population.Population.from_identification`).
        distribution : {"normal", "uniform"} or None
            ``--distribution``: distribution of the random draws.
        offset : float or None
            ``--offset``: standard deviation of the start position on each axis [m].
        noise : str or None
            ``--noise``: sensor noise and delay, a :func:`parse_noise` spec; None: the
            scenario's, else none.
        sensors_text, estimator_text : str or None
            ``--sensors``, ``--estimator``: the sensor models and the estimator
            (:mod:`quadcruise.cli.onboard`); None: the scenario's, else none.
        imu_noise_spread, gps_noise_spread : float or None
            ``--imu-noise-spread``, ``--gps-noise-spread``: relative standard deviations of
            each vehicle's IMU and GPS noise (:mod:`quadcruise.montecarlo.sensor_spread`).
        model_error : bool or None
            ``--model-error``/``--no-model-error``: the controller computes with the nominal
            vehicle (True) or knows each vehicle's own parameters (False).
        chunk_size : str
            ``--chunk-size``: flights per task, a whole number or "auto".
        scheduler : str
            ``--scheduler``: "local" (a Dask cluster of processes here), "none" (in this
            process) or the address of a Dask scheduler.
        workers : int or None
            ``--workers``: worker processes of the local cluster; None: the machine's cores.
        connect_timeout : float
            ``--connect-timeout``: time to wait for a scheduler given by address [s].
        out : str or None
            ``--out``: folder that the chunks stream to as they finish and the results go to at
            the end; None: print only.
        force : bool
            ``--force``: replace an ``out`` folder holding something else.
        resume : bool
            ``--resume``/``--no-resume``: load the chunks of this same sweep found in ``out``
            instead of flying them again.
        fmt : {"csv", "parquet"}
            ``--format``: format of the flights table.
        case : int or None
            ``--case``: fly this flight (its number in the sweep) alone and, with ``out``,
            write it there; None: the whole sweep.
        worst : int
            ``--worst``: how many of the worst flights to list.
        quiet : bool
            ``--quiet``: no progress bar.
        scenario : str or None
            ``--scenario``: path of a TOML scenario file: mission, controller, vehicle,
            disturbances and a ``[montecarlo]`` table.
    """
    montecarlo_command(**options, echo=click.echo)
