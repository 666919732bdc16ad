"""``quadcruise reproduce``: the paper's scenarios flown, its table printed, its folder written."""

from __future__ import annotations

import sys

import click

from quadcruise.cli.common import FORCE_OPTION, FORMAT_OPTION, REPORT_OPTION, Bar, distinct_outputs, friendly, writable
from quadcruise.io.files import check_output_dir

__all__ = ["reproduce"]


@click.command("reproduce")
@click.option(
    "--out",
    "out",
    default="quadcruise-out",
    show_default=True,
    type=click.Path(file_okay=False),
    callback=writable,
    help="Folder for metrics.json, figures, traces and report.md.",
)
@FORMAT_OPTION
@FORCE_OPTION
@REPORT_OPTION
@click.option(
    "--scenario",
    type=click.Path(dir_okay=False),
    metavar="FILE.toml",
    help="Reproduce with a scenario's vehicle and control period (e.g. the 1.4 kg Qball-X4).",
)
@friendly
def reproduce(out, fmt, force, report, scenario):
    """Reproduce the paper: both controllers on the circle, square and step, beside its numbers;
    and, labelled as fitted, the gains that reach the paper's reported transients.

    Writes OUT/metrics.json, one figure per paper figure, the traces and OUT/report.md,
    which explains every difference from the paper. Nothing is left half-written.

    \f
    Parameters
    ----------
    out : str
        ``--out``: folder to write ``metrics.json``, the figures, the traces and ``report.md`` to.
    fmt : {"csv", "parquet"}
        ``--format``: format of the traces.
    force : bool
        ``--force``: replace a non-empty ``out`` folder that quadcruise did not write.
    report : str or None
        ``--report``: path of a self-contained HTML report to write as well; None: no report.
    scenario : str or None
        ``--scenario``: path of a TOML scenario file whose vehicle and control period the
        flights use; None: the paper's vehicle and period.
    """
    import time

    from quadcruise.workflows.reproduce import fitted_table, results_table, write_reproduction, written_figures
    from quadcruise.workflows.reproduce import reproduce as run_reproduce

    start = time.perf_counter()
    distinct_outputs(out, report=report)
    check_output_dir(out, force, workflow="reproduce")
    settings = {}
    if scenario is not None:
        from quadcruise.workflows.scenario import load_scenario

        sc = load_scenario(scenario)
        settings = {"vehicle": sc.vehicle, "dt": sc.dt}
        unused = [
            name
            for name, part in (
                ("[mission]", sc.mission),
                ("[controller]", sc.controller),
                ("[disturbances]", sc.environment or sc.sensor_noise),
                ("[compare]", sc.compare),
                ("[montecarlo]", sc.montecarlo),
            )
            if part
        ] + [f"[simulation] {k}" for k in sc.simulation if k != "dt"]
        if unused:
            click.echo(
                f"warning: {scenario}: reproduce flies the paper's missions and controllers with the "
                f"scenario's vehicle and dt only; not used: {', '.join(unused)}",
                err=True,
            )
    with Bar("flying", unit="flight") as flown:
        rep = run_reproduce(progress=flown, **settings)
    click.echo(results_table(rep))
    click.echo("\nFitted to the paper's transients (not its gains; docs/paper.md explains):")
    click.echo(fitted_table(rep))
    with Bar("drawing", unit="figure") as drawn:
        write_reproduction(rep, out, force=force, fmt=fmt, progress=drawn)
    if report is not None:
        from quadcruise.report.html import write_html_report
        from quadcruise.report.sections import reproduction_report

        write_html_report(report, **reproduction_report(rep, written_figures(out)))
        click.echo(f"wrote report {report}")
    click.echo(f"wrote {out}/report.md, metrics.json, figures and traces in {time.perf_counter() - start:.1f} s")
    if rep.failed:  # each one's warning names it: "circle with nlpd: vehicle 0 lost track ..."
        sys.exit(1)  # a flight did not finish (e.g. a --scenario vehicle the paper's gains cannot fly)
