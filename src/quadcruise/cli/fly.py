"""``quadcruise fly``: one mission flown by one controller; its metrics printed, its folder,
report and animation written on request."""

from __future__ import annotations

import sys

import click
import numpy as np

from quadcruise.cli.common import (
    FORCE_OPTION,
    FORMAT_OPTION,
    REPORT_OPTION,
    RISE_OPTION,
    SETTLE_BAND_OPTION,
    WORLD_OPTIONS,
    Bar,
    friendly,
    metric_options,
    needs_out,
    note,
    writable,
)
from quadcruise.cli.objects import flight_from_options, flight_world
from quadcruise.io.files import check_output_dir

__all__ = ["fly"]


@click.command("fly")
@click.argument("mission", metavar="MISSION")
@click.option("--controller", help="Controller name (default nlpd, or the scenario's).")
@click.option("--duration", type=float, help="Flight time [s] (default: one lap, or 10 s after a step).")
@click.option("--dt", type=float, help="Control period [s] (default 0.001).")
@click.option("--max-step", type=float, help="Longest RK4 substep [s] (default: dt).")
@click.option("-m", "--mission-param", "mission_params", multiple=True, metavar="KEY=VALUE",
              help="Mission parameter, e.g. -m radius=3 -m period=30 (repeatable).")
@click.option("-c", "--controller-param", "controller_params", multiple=True, metavar="KEY=VALUE",
              help="Controller parameter, e.g. -c max_tilt=0.5 (repeatable).")
@click.option("--poles", "position_poles", metavar="P1,P2",
              help="Closed-loop poles of the x/y loops [rad/s], e.g. -0.7,-4.3 (the paper's).")
@click.option("--out", "out", type=click.Path(file_okay=False), callback=writable, help="Folder for traces, figure and metrics.")
@FORMAT_OPTION
@FORCE_OPTION
@click.option("--smooth", is_flag=True, help="Fly a waypoint file as a minimum-snap path instead of legs.")
@REPORT_OPTION
@click.option("--animate", type=click.Path(dir_okay=False), metavar="PATH.gif", callback=writable,
              help="Also write an animation of the flight (.gif; .mp4 needs ffmpeg).")
@WORLD_OPTIONS
@RISE_OPTION
@SETTLE_BAND_OPTION
@friendly
def fly(mission, controller, duration, dt, max_step, mission_params, controller_params, position_poles,
        out, fmt, force, smooth, report, animate, vehicle, controller_vehicle, wind, turbulence, log_every, seed,
        rise, settle_bands):
    """Fly a MISSION with a controller on the paper's vehicle and print its metrics.

    MISSION is circle, square, step, hover, a waypoint CSV (columns x,y,z and optional yaw
    and t or speed), flown as constant-speed legs or, with --smooth, a minimum-snap path, or
    a TOML scenario file describing the whole run (options given here override it).
    With --out, also write the traces, a figure of the flight, the metrics and the
    configuration (quadcruise.json) to that folder, atomically.

    \f
    Parameters
    ----------
    mission : str
        ``MISSION``: a mission name (:func:`quadcruise.missions.mission_from_name`), the path of
        a waypoint CSV, or the path of a TOML scenario file (ending in ``.toml``).
    controller : str or None
        ``--controller``: the controller's name (:func:`quadcruise.control.controller_from_name`);
        None: the scenario's controller, else ``nlpd``. ``controller_params`` and
        ``position_poles`` change the scenario's controller when no name is given.
    duration : float or None
        ``--duration``: flight time [s]; None: the scenario's, else the mission's (one lap, or
        10 s after a step).
    dt : float or None
        ``--dt``: control period [s]; None: the scenario's, else 0.001 s.
    max_step : float or None
        ``--max-step``: longest RK4 substep [s]; None: the scenario's, else ``dt``.
    mission_params : tuple of str
        ``-m``/``--mission-param``: the mission's parameters, each ``KEY=VALUE`` (with a
        scenario, they change its mission).
    controller_params : tuple of str
        ``-c``/``--controller-param``: the controller's parameters, each ``KEY=VALUE``.
    position_poles : str or None
        ``--poles``: comma-separated closed-loop poles of the x/y loops [rad/s], e.g.
        ``-0.7,-4.3``; their PD gains replace the controller's position gains. None: not given.
    out : str or None
        ``--out``: folder to write the traces, the figure, the metrics and ``quadcruise.json``
        to; None: print only.
    fmt : {"csv", "parquet"}
        ``--format``: format of the traces.
    force : bool
        ``--force``: replace a non-empty ``out`` folder that quadcruise did not write.
    smooth : bool
        ``--smooth``: fly a waypoint CSV as a minimum-snap path instead of constant-speed legs.
    report : str or None
        ``--report``: path of a self-contained HTML report to write as well; None: no report.
    animate : str or None
        ``--animate``: path of an animation of the flight to write as well (``.gif``, or
        ``.mp4`` with ffmpeg); None: no animation.
    vehicle, controller_vehicle : str or None
        ``--vehicle``, ``--controller-vehicle``: the flown vehicle and the controller's model of
        it (:func:`~quadcruise.cli.objects.vehicle_from_option`); None: the scenario's, else
        Table I and the flown vehicle.
    wind, turbulence : str or None
        ``--wind``: a :func:`~quadcruise.disturbances.parse_wind` spec replacing the scenario's
        disturbances; ``--turbulence``: Dryden turbulence added
        (:func:`~quadcruise.cli.objects.environment_from_options`).
    log_every : int or None
        ``--log-every``: log every this many control periods; None: the scenario's, else 1.
    seed : int or None
        ``--seed``: seed of the turbulence and the sensor noise; None: the scenario's, else 0.
    rise : {"10-90", "0-100"}
        ``--rise``: the rise-time convention (% of the step).
    settle_bands : tuple of float
        ``--settle-band``: the settling bands (fractions of the step), given once or twice.
    """
    from quadcruise.errors import whole_number

    needs_out(out, force=force, format=fmt != "csv")
    conventions = metric_options(rise, settle_bands)
    if seed is not None:
        whole_number(seed, "--seed")
    if log_every is not None:
        whole_number(log_every, "--log-every", minimum=1)
    overrides = {k: v for k, v in (("duration", duration), ("dt", dt), ("max_step", max_step), ("seed", seed),
                                   ("log_every", log_every)) if v is not None}
    world = {"vehicle": vehicle, "controller_vehicle": controller_vehicle, "wind": wind, "turbulence": turbulence}
    given = [f"--{k.replace('_', '-')} {v}" for k, v in {**overrides, **world}.items() if v is not None] \
        + [f"-m {p}" for p in mission_params] + [f"-c {p}" for p in controller_params] \
        + ([f"--controller {controller}"] if controller else []) \
        + ([f"--poles {position_poles}"] if position_poles else [])
    the_mission, the_controller, kwargs, scenario = flight_from_options(
        mission, controller, mission_params, controller_params, position_poles, smooth)
    flown, notes = flight_world(**world, scenario=scenario)
    kwargs = {**{k: v for k, v in kwargs.items() if k not in flown}, **overrides,
              **{k: v for k, v in flown.items() if v is not None}}
    result = _fly_and_report(the_mission, the_controller, kwargs, out, fmt, force, report, animate, given, scenario,
                             conventions, notes)
    if not result.ok.all():
        sys.exit(1)             # a vehicle did not fly its mission: diverged, lost track, out of bounds


def _fly_and_report(mission, controller, kwargs: dict, out, fmt, force, report=None, animate=None, given=(),
                    scenario=None, conventions=None, notes=()):
    """Fly, print the metrics and each unfinished vehicle's reason, and write what was asked for.

    Parameters
    ----------
    mission : Mission
    controller : Controller
    kwargs : dict
        More keywords of :func:`quadcruise.workflows.fly.fly` (duration, dt, vehicle, ...).
    out : str or None
        Folder for the traces, figure, metrics and configuration.
    fmt : {"csv", "parquet"}
        Format of the traces.
    force : bool
        Replace a non-empty ``out`` that quadcruise did not write.
    report : str, optional
        Path of an HTML report.
    animate : str, optional
        Path of an animation (.gif, or .mp4 with ffmpeg).
    given : sequence of str
        The options given on the command line, recorded with the flight (``meta["command_line"]``).
    scenario : Scenario, optional
        The scenario file flown, recorded with the flight (source and title).
    conventions : dict, optional
        ``rise`` and ``settle_bands`` of the metrics (:func:`~quadcruise.cli.common.metric_options`).
    notes : sequence of str
        Lines printed on stderr (``note: ...``) once the options are checked, before flying.

    Returns
    -------
    SimResult
        The flight.
    """
    from quadcruise.metrics.tables import conventions_text, vehicle_metrics_text
    from quadcruise.workflows.fly import fly as run_fly
    from quadcruise.workflows.fly import write_flight

    if animate is not None:
        from quadcruise.plots.animate import check_animation_path

        check_animation_path(animate)       # suffix, and ffmpeg for .mp4: before anything flies
    if out is not None:
        check_output_dir(out, force)
    for line in notes:
        note(line)
    result = run_fly(mission, controller, **kwargs)
    result.meta["command_line"] = list(given)
    if scenario is not None:
        result.meta["scenario"] = {"source": scenario.source, "title": scenario.title}
    metrics = result.metrics(**(conventions or {}))
    click.echo(f"{controller.name} on {mission.name}: {result.t[-1]:g} s at dt = {result.meta['dt_s']:g} s")
    click.echo(vehicle_metrics_text(metrics))
    click.echo(conventions_text(metrics.attrs.get("conventions")))
    for i in np.flatnonzero(~result.ok):
        click.echo(f"vehicle {i} did not fly its mission: {result.status_text(int(i))}")
    if out is not None:
        write_flight(result, out, fmt, metrics=metrics)
        click.echo(f"wrote traces, figure and metrics to {out}")
    if report is not None:
        from quadcruise.report.html import flight_report, write_html_report

        write_html_report(report, **flight_report(result, metrics=metrics))
        click.echo(f"wrote report {report}")
    if animate is not None:
        from quadcruise.plots.animate import animate_flight

        animate_flight(result, animate, progress=Bar("drawing the animation", unit="frame"))
        click.echo(f"wrote animation {animate}")
    return result
