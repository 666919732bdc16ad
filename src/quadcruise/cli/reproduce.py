"""``quadcruise reproduce``: the paper's scenarios flown, its table printed, its folder written."""

from __future__ import annotations

import click

from quadcruise.cli.common import FORCE_OPTION, FORMAT_OPTION, REPORT_OPTION, friendly, writable
from quadcruise.io.files import check_output_dir

__all__ = ["reproduce"]


@click.command("reproduce")
@click.option("--out", "out", default="quadcruise-out", show_default=True, type=click.Path(file_okay=False),
              callback=writable,
              help="Folder for metrics.json, figures, traces and report.md.")
@FORMAT_OPTION
@FORCE_OPTION
@REPORT_OPTION
@click.option("--scenario", type=click.Path(dir_okay=False), metavar="FILE.toml",
              help="Reproduce with a scenario's vehicle and control period (e.g. the 1.4 kg Qball-X4).")
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
    check_output_dir(out, force)
    settings = {}
    if scenario is not None:
        from quadcruise.workflows.scenario import load_scenario

        sc = load_scenario(scenario)
        settings = {"vehicle": sc.vehicle, "dt": sc.dt}
    rep = run_reproduce(progress=_flown, **settings)
    click.echo(results_table(rep))
    click.echo("\nFitted to the paper's transients (not its gains; docs/paper.md explains):")
    click.echo(fitted_table(rep))
    write_reproduction(rep, out, force=force, fmt=fmt, progress=_drawn)
    if report is not None:
        from quadcruise.report.html import reproduction_report, write_html_report

        write_html_report(report, **reproduction_report(rep, written_figures(out)))
        click.echo(f"wrote report {report}")
    click.echo(f"wrote {out}/report.md, metrics.json, figures and traces in {time.perf_counter() - start:.1f} s")


def _flown(done: int, total: int, label: str) -> None:
    """Say on stderr that a flight is done.

    Parameters
    ----------
    done, total : int
        Flights flown so far, and in all.
    label : str
        The flight just flown, e.g. "circle with nlpd".
    """
    click.echo(f"[{done}/{total}] flew {label}", err=True)


def _drawn(name: str) -> None:
    """Say on stderr that a figure is drawn.

    Parameters
    ----------
    name : str
        The figure's file name.
    """
    click.echo(f"drew {name}", err=True)
