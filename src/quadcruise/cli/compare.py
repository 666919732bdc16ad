"""``quadcruise compare``: several controllers on one mission, and on request on the same Monte
Carlo population; one table, one figure."""

from __future__ import annotations

import sys

import click

from quadcruise.cli.common import (
    FORCE_OPTION,
    REPORT_OPTION,
    RISE_OPTION,
    SECONDS,
    SETTLE_BAND_OPTION,
    Bar,
    distinct_outputs,
    friendly,
    metric_options,
    needs_out,
    writable,
    writable_with,
)
from quadcruise.cli.compare_run import (
    compared_from_options,
    echo_population_comparison,
    population_from_options,
    population_record,
)
from quadcruise.cli.compare_ulog import comparison_ulog_paths, write_comparison_ulogs
from quadcruise.cli.objects import PARAMS_OPTION, with_px4_params
from quadcruise.cli.onboard import onboard_options
from quadcruise.cli.world import flight_world, note, world_options
from quadcruise.io.files import check_output_dir

__all__ = ["compare"]


@click.command("compare")
@click.argument("mission", metavar="MISSION")
@click.option(
    "--controllers",
    help="Comma-separated controller names (default: the scenario's, else those declared compared: "
    "nlpd,gonzalez,se3,cascade and any of yours, docs/extending.md).",
)
@PARAMS_OPTION
@click.option("--duration", type=SECONDS, help="Flight time [s] (default: the mission's).")
@click.option("--dt", type=SECONDS, help="Control period [s] (default 0.001, or the scenario's).")
@click.option(
    "-m",
    "--mission-param",
    "mission_params",
    multiple=True,
    metavar="KEY=VALUE",
    help="Mission parameter (repeatable).",
)
@click.option(
    "--out", type=click.Path(file_okay=False), callback=writable, help="Folder for metrics.csv and comparison.png."
)
@FORCE_OPTION
@click.option(
    "--population",
    type=int,
    metavar="N",
    help="Also fly every controller on the same Monte Carlo population of N vehicles.",
)
@click.option(
    "--seed",
    type=int,
    help="Seed of every random draw: the population's, and the turbulence and "
    "sensor noise of every flight (default 0, or the scenario's).",
)
@click.option("--mass-spread", type=float, help="Relative std of the population's mass (default 0.1).")
@world_options(
    wind_help="Wind of every flight (and of the population): constant:WX,WY,WZ | "
    "gust:AX,AY,AZ@START+DURATION | dryden:light|moderate|severe@ALTITUDE | loss:ROTOR,FRACTION@TIME "
    "(comma-separable; none: still air).",
    seed=False,
)
@REPORT_OPTION
@click.option(
    "--ulog",
    type=click.Path(dir_okay=False),
    metavar="PATH.ulg",
    callback=writable_with(".ulg"),
    help="Also write each controller's flight as a PX4 log: PATH-nlpd.ulg, PATH-se3.ulg, ...",
)
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
    help="The estimator every controller flies on: ekf (needs imu and gps), or none; the table says so.",
)
@RISE_OPTION
@SETTLE_BAND_OPTION
@friendly
def compare(
    mission,
    controllers,
    px4_params,
    duration,
    dt,
    mission_params,
    out,
    force,
    population,
    seed,
    mass_spread,
    vehicle,
    controller_vehicle,
    wind,
    turbulence,
    log_every,
    report,
    ulog,
    sensors_text,
    estimator_text,
    rise,
    settle_bands,
):
    """Fly MISSION (a name or a waypoint CSV) with several controllers; one table, one figure.

    \f
    Parameters
    ----------
    mission : str
        ``MISSION``: a mission name (:func:`quadcruise.missions.mission_from_name`) or the path
        of a waypoint CSV, flown as constant-speed legs.
    controllers : str
        ``--controllers``: comma-separated controller names.
    px4_params : str or None
        ``--params``: PX4's parameters (a log or a ``.params`` file) of the px4 controller
        (:func:`~quadcruise.cli.objects.with_px4_params`; px4 is added when not named).
    duration : float or None
        ``--duration``: flight time [s]; None: the mission's.
    dt : float
        ``--dt``: control period [s].
    mission_params : tuple of str
        ``-m``/``--mission-param``: the mission's parameters, each ``KEY=VALUE``.
    out : str or None
        ``--out``: folder to write ``metrics.csv`` and ``comparison.png`` to; None: print only.
    force : bool
        ``--force``: replace a non-empty ``out`` folder that quadcruise did not write.
    population : int or None
        ``--population``: also fly every controller on the same Monte Carlo population of this
        many perturbed vehicles; None: the scenario's ``[compare] population``, else the
        nominal vehicle only.
    seed : int or None
        ``--seed``: seed of the population and of every flight's turbulence and sensor noise;
        None: the scenario's, else 0.
    mass_spread : float or None
        ``--mass-spread``: relative standard deviation of the population's mass; None: the
        scenario's, else 0.1.
    vehicle, controller_vehicle : str or None
        ``--vehicle``, ``--controller-vehicle``: the flown (nominal) vehicle and the
        controllers' model of it (:func:`~quadcruise.cli.objects.vehicle_from_option`).
    wind, turbulence : str or None
        ``--wind``: the flights' (and the population's) disturbances, a
        :func:`~quadcruise.cli.wind.parse_wind` spec such as
        ``dryden:moderate@10``, replacing a scenario's; ``--turbulence``: Dryden turbulence added.
    log_every : int or None
        ``--log-every``: log every this many control periods.
    report : str or None
        ``--report``: path of a self-contained HTML report to write as well; None: no report.
    ulog : str or None
        ``--ulog``: each controller's flight as a PX4 log, the controller's label before the
        suffix (:func:`~quadcruise.cli.compare_ulog.write_comparison_ulogs`); None: none.
    sensors_text, estimator_text : str or None
        ``--sensors``, ``--estimator``: the sensor models and the estimator every controller
        flies on (:func:`~quadcruise.cli.onboard.onboard_options`); None: the scenario's, else none.
    rise : str
        ``--rise``: the rise-time convention, ``10-90`` or ``0-100`` (% of the step).
    settle_bands : tuple of float
        ``--settle-band``: the settling bands (fractions of the step), given once or twice.
    """
    import dataclasses

    from quadcruise.errors import whole_number
    from quadcruise.workflows.compare import compare as run_compare

    needs_out(out, force=force)
    distinct_outputs(out, report=report, ulog=ulog)
    conventions = metric_options(rise, settle_bands)
    if log_every is not None:
        whole_number(log_every, "--log-every", minimum=1)
    if out is not None:
        check_output_dir(out, force, inputs=(mission, vehicle, controller_vehicle, wind, turbulence))
    cmp_mission, chosen, kwargs, scenario = compared_from_options(mission, controllers, mission_params)
    world, notes = flight_world(
        vehicle=vehicle, controller_vehicle=controller_vehicle, wind=wind, turbulence=turbulence, scenario=scenario
    )
    chosen = with_px4_params(chosen, px4_params, world)
    kwargs = {
        **{k: v for k, v in kwargs.items() if k not in world},
        **{k: v for k, v in world.items() if v is not None},
    }
    kwargs.update({k: v for k, v in (("duration", duration), ("dt", dt), ("log_every", log_every)) if v is not None})
    kwargs = onboard_options(sensors_text, estimator_text, kwargs)
    count, pop_seed, pop = population_from_options(
        population,
        seed,
        mass_spread,
        scenario,
        kwargs.get("environment"),
        kwargs.get("sensors"),
        kwargs.get("estimator"),
    )
    if seed is not None or "seed" not in kwargs:  # the flights' seed: given, the scenario's, the population's
        kwargs["seed"] = pop_seed if seed is None else seed
    if count is not None:
        from quadcruise.montecarlo.sweep import check_sweep_size
        from quadcruise.workflows.fly_inputs import default_duration

        duration_s = kwargs.get("duration") or default_duration(cmp_mission)
        check_sweep_size(count, round(duration_s / kwargs.get("dt", 1e-3)))
    for line in notes:
        note(line)
    cmp = run_compare(cmp_mission, chosen, progress=Bar("flying", unit="controller"), **kwargs)
    click.echo(cmp.text(**conventions))
    if count is not None:
        table = echo_population_comparison(cmp_mission, cmp.controllers, count, pop_seed, pop, kwargs)
        cmp = dataclasses.replace(cmp, population=population_record(count, pop_seed, pop), population_table=table)
    if ulog is not None:
        for result in cmp.results.values():  # said in scenario.toml, as fly's is
            result.meta["ulog"] = {"path": str(ulog), "files": [str(p) for p in comparison_ulog_paths(cmp, ulog)]}
    if out is not None:  # first: the folder is replaced whole, so a file named inside it comes after
        cmp.write(out, force=force, **conventions)
        click.echo(f"wrote metrics.csv and comparison.png to {out}")
    if ulog is not None:
        written = write_comparison_ulogs(cmp, ulog)
        click.echo("wrote PX4 logs " + ", ".join(map(str, written)))
    if report is not None:
        from quadcruise.report.html import write_html_report
        from quadcruise.report.sections import comparison_report

        write_html_report(report, **comparison_report(cmp, **conventions))
        click.echo(f"wrote report {report}")
    if cmp.failed:
        sys.exit(1)  # a controller's flight did not finish: diverged, lost track, out of bounds
