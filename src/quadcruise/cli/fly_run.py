"""What ``quadcruise fly`` runs once its options are parsed: the flight, its metrics printed, its
folder, report and animation written. The command, its options and its help are in
:mod:`quadcruise.cli.fly`."""

from __future__ import annotations

from pathlib import Path

import click
import numpy as np

from quadcruise.cli.feedback import Bar
from quadcruise.cli.world import note
from quadcruise.io.files import check_output_dir

__all__ = ["fly_and_report", "ulog_paths", "write_ulogs"]


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
    ulog=None,
    inputs=(),
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
    ulog : str, optional
        Path of a PX4 log of the flight (one file per vehicle for a batch: :func:`ulog_paths`).
    inputs : sequence of str
        The files the options name (scenario, vehicle, wind): an ``out`` that holds one is
        refused before flying (writing the folder would delete it).

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
        check_output_dir(out, force, inputs=[scenario.source if scenario is not None else None, *inputs])
    for line in notes:
        note(line)
    result = run_fly(mission, controller, **kwargs)
    result.meta["command_line"] = list(given)
    if ulog is not None:
        result.meta["ulog"] = {"path": str(ulog), "files": [str(p) for p in ulog_paths(ulog, result.n)]}
    if scenario is not None:
        result.meta["scenario"] = {"source": scenario.source, "title": scenario.title}
    metrics = result.metrics(**(conventions or {}))
    click.echo(f"{controller.name} on {mission.name}: {result.t[-1]:g} s at dt = {result.meta['dt_s']:g} s")
    click.echo(vehicle_metrics_text(metrics))
    click.echo(conventions_text(metrics.attrs.get("conventions")))
    for i in np.flatnonzero(~result.ok):
        click.echo(f"vehicle {i} did not fly its mission: {result.status_text(int(i))}")
    if out is not None:  # first: the folder is replaced whole, so a file named inside it comes after
        write_flight(result, out, fmt, metrics=metrics)
        click.echo(f"wrote traces, figure and metrics to {out}")
    if ulog is not None:
        written = write_ulogs(result, ulog)
        click.echo(f"wrote PX4 log{'s' if len(written) > 1 else ''} " + ", ".join(map(str, written)))
        if result.meta.get("px4_parameters_note"):  # the by-name px4 on a vehicle it was designed for
            note(f"{written[0]} {result.meta['px4_parameters_note']}")
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


def ulog_paths(path, n: int) -> list[Path]:
    """The PX4 logs ``--ulog PATH`` writes for a flight of ``n`` vehicles.

    A PX4 log holds one vehicle, so a batch is written one file per vehicle, its index (from 0,
    as :meth:`~quadcruise.SimResult.to_ulog` counts) before the suffix.

    Parameters
    ----------
    path : str or os.PathLike
        The path given (``.ulg``).
    n : int
        The number of vehicles flown.

    Returns
    -------
    list of pathlib.Path

    Examples
    --------
    >>> [p.name for p in ulog_paths("out/flight.ulg", 1)], [p.name for p in ulog_paths("flight.ulg", 2)]
    (['flight.ulg'], ['flight-0.ulg', 'flight-1.ulg'])
    """
    path = Path(path)
    if n == 1:
        return [path]
    return [path.with_name(f"{path.stem}-{i}{path.suffix}") for i in range(n)]


def write_ulogs(result, path) -> list[Path]:
    """Write each vehicle's PX4 log, all or none: a fault on one removes those already written.

    Parameters
    ----------
    result : SimResult
        The flight.
    path : str or os.PathLike
        The path given (``.ulg``); see :func:`ulog_paths`.

    Returns
    -------
    list of pathlib.Path
        The files written.

    Raises
    ------
    WriteError
        A file that could not be written (named); none of the files is left.
    """
    written: list[Path] = []
    try:
        for i, each in enumerate(ulog_paths(path, result.n)):
            written.append(result.to_ulog(each, vehicle=i))
    except BaseException:
        for done in written:
            done.unlink(missing_ok=True)
        raise
    return written
