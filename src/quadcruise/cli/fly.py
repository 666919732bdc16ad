"""``quadcruise fly``: one mission flown by one controller; its metrics printed, its folder,
report and animation written on request."""

from __future__ import annotations

import click

from quadcruise.cli.common import (
    FORCE_OPTION,
    FORMAT_OPTION,
    REPORT_OPTION,
    RISE_OPTION,
    SETTLE_BAND_OPTION,
    controller_from_options,
    friendly,
    metric_options,
    mission_from_options,
)
from quadcruise.errors import InputError
from quadcruise.io.files import check_output_dir

__all__ = ["fly"]


@click.command("fly")
@click.argument("mission", metavar="MISSION")
@click.option("--controller", default="nlpd", show_default=True, help="Controller name.")
@click.option("--duration", type=float, help="Flight time [s] (default: one lap, or 10 s after a step).")
@click.option("--dt", type=float, help="Control period [s] (default 0.001).")
@click.option("--max-step", type=float, help="Longest RK4 substep [s] (default: dt).")
@click.option("-m", "--mission-param", "mission_params", multiple=True, metavar="KEY=VALUE",
              help="Mission parameter, e.g. -m radius=3 -m period=30 (repeatable).")
@click.option("-c", "--controller-param", "controller_params", multiple=True, metavar="KEY=VALUE",
              help="Controller parameter, e.g. -c max_tilt=0.5 (repeatable).")
@click.option("--poles", "position_poles", metavar="P1,P2",
              help="Closed-loop poles of the x/y loops [rad/s], e.g. -0.7,-4.3 (the paper's).")
@click.option("--out", "out", type=click.Path(file_okay=False), help="Folder for traces, figure and metrics.")
@FORMAT_OPTION
@FORCE_OPTION
@click.option("--smooth", is_flag=True, help="Fly a waypoint file as a minimum-snap path instead of legs.")
@REPORT_OPTION
@click.option("--animate", type=click.Path(dir_okay=False), metavar="PATH.gif",
              help="Also write an animation of the flight (.gif; .mp4 needs ffmpeg).")
@RISE_OPTION
@SETTLE_BAND_OPTION
@friendly
def fly(mission, controller, duration, dt, max_step, mission_params, controller_params, position_poles,
        out, fmt, force, smooth, report, animate, rise, settle_bands):
    """Fly a MISSION with a controller on the paper's vehicle and print its metrics.

    MISSION is circle, square, step, hover, a waypoint CSV (columns x,y,z and optional yaw
    and t or speed), flown as constant-speed legs or, with --smooth, a minimum-snap path, or
    a TOML scenario file describing the whole run (options given here override it).
    With --out, also write the traces, a figure of the flight, the metrics and the
    configuration (quadcruise.json) to that folder, atomically.
    """
    from quadcruise.missions import mission_from_name

    conventions = metric_options(rise, settle_bands)
    overrides = {k: v for k, v in (("duration", duration), ("dt", dt), ("max_step", max_step)) if v is not None}
    if mission.lower().endswith(".toml"):
        from quadcruise.workflows.scenario import load_scenario

        scenario = load_scenario(mission)
        the_mission, the_controller = scenario.mission or mission_from_name("circle"), scenario.controller
        if the_controller is None or controller_params or position_poles or controller != "nlpd":
            the_controller = controller_from_options(controller, controller_params, position_poles)
        kwargs = {**scenario.fly_kwargs(), **overrides}
    else:
        the_mission = mission_from_options(mission, mission_params, smooth)
        the_controller = controller_from_options(controller, controller_params, position_poles)
        kwargs = overrides
    _fly_and_report(the_mission, the_controller, kwargs, out, fmt, force, report, animate, conventions)


def _fly_and_report(mission, controller, kwargs: dict, out, fmt, force, report=None, animate=None,
                    conventions=None) -> None:
    """Fly, print the metrics, and write what was asked for.

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
    conventions : dict, optional
        ``rise`` and ``settle_bands`` of the metrics (:func:`~quadcruise.cli.common.metric_options`).
    """
    from quadcruise.metrics.tables import conventions_text, vehicle_metrics_text
    from quadcruise.workflows.fly import fly as run_fly
    from quadcruise.workflows.fly import write_flight

    if animate is not None and not animate.lower().endswith((".gif", ".mp4")):
        raise InputError(f"--animate {animate}: the animation must be a .gif (or .mp4, with ffmpeg)")
    if out is not None:
        check_output_dir(out, force)
    result = run_fly(mission, controller, **kwargs)
    metrics = result.metrics(**(conventions or {}))
    click.echo(f"{controller.name} on {mission.name}: {result.t[-1]:g} s at dt = {result.meta['dt_s']:g} s")
    click.echo(vehicle_metrics_text(metrics))
    click.echo(conventions_text(metrics.attrs.get("conventions")))
    if out is not None:
        write_flight(result, out, fmt, metrics=metrics)
        click.echo(f"wrote traces, figure and metrics to {out}")
    if report is not None:
        from quadcruise.report.html import flight_report, write_html_report

        write_html_report(report, **flight_report(result, metrics=metrics))
        click.echo(f"wrote report {report}")
    if animate is not None:
        from quadcruise.plots.animate import animate_flight

        animate_flight(result, animate)
        click.echo(f"wrote animation {animate}")
