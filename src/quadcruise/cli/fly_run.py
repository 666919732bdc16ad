"""What ``quadcruise fly`` runs once its options are parsed: the flight, its metrics printed, its
folder, report and animation written. The command, its options and its help are in
:mod:`quadcruise.cli.fly`."""

from __future__ import annotations

import click
import numpy as np

from quadcruise.cli.feedback import Bar
from quadcruise.cli.world import note
from quadcruise.io.files import check_output_dir

__all__ = ["fly_and_report"]


def fly_and_report(
    mission,
    controller,
    kwargs: dict,
    out,
    fmt,
    force,
    report=None,
    animate=None,
    given=(),
    scenario=None,
    conventions=None,
    notes=(),
):
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

        check_animation_path(animate)  # suffix, and ffmpeg for .mp4: before anything flies
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
        from quadcruise.report.html import write_html_report
        from quadcruise.report.sections import flight_report

        write_html_report(report, **flight_report(result, metrics=metrics))
        click.echo(f"wrote report {report}")
    if animate is not None:
        from quadcruise.plots.animate import animate_flight

        animate_flight(result, animate, progress=Bar("drawing the animation", unit="frame"))
        click.echo(f"wrote animation {animate}")
    return result
