"""``quadcruise identify``: a flight log in, an identified vehicle out (a folder)."""

from __future__ import annotations

import shlex
import sys

import click

from quadcruise.cli.common import Bar, distinct_outputs, friendly, writable, writable_with
from quadcruise.errors import InputError
from quadcruise.io.files import not_a_file

__all__ = ["identify"]


def base_vehicle(text: str):
    """``--vehicle``: a preset (``paper``, Table I; ``iris``, ``crazyflie``, ...: the rotor plant) or a
    TOML file with a ``[vehicle]`` table."""
    from pathlib import Path

    from quadcruise.model.vehicle import Vehicle

    path = Path(text)
    if path.suffix.lower() != ".toml":
        try:
            return Vehicle.preset(text.strip().lower())
        except InputError:
            raise InputError(
                f"--vehicle: a preset (paper, iris, crazyflie, ...) or a TOML file with a [vehicle] table, got {text!r}"
            ) from None
    if not path.is_file():
        raise InputError(f"--vehicle: {text}: {not_a_file(path)}")
    from quadcruise.workflows.scenario import load_scenario

    return load_scenario(path).vehicle


def check_keeps_log(log: str, out: str) -> None:
    """Refuse an ``--out`` folder that holds ``LOG`` (writing the folder replaces it, ``--force`` or not).

    Examples
    --------
    >>> check_keeps_log("runs/a/flight.ulg", "runs/a")
    Traceback (most recent call last):
        ...
    quadcruise.errors.InputError: --out runs/a: holds the log being read (runs/a/flight.ulg), which writing ...
    """
    from quadcruise.io.keep_inputs import holds

    if holds(out, log):
        raise InputError(
            f"--out {out}: holds the log being read ({log}), which writing the folder would delete: "
            "choose another folder"
        )


@click.command("identify")
@click.argument("log", metavar="LOG")
@click.option(
    "--vehicle",
    "vehicle",
    default="paper",
    show_default=True,
    metavar="BASE",
    help="Base vehicle: a preset (paper; iris, crazyflie, ...: identify the rotor plant) or a TOML file with a "
    "[vehicle] table (geometry when the log has none, starting values, values for what the log cannot identify).",
)
@click.option(
    "--mass",
    type=float,
    default=None,
    metavar="KG",
    help="The vehicle's mass [kg]; without it K and the inertias are per unit mass.",
)
@click.option(
    "--frame",
    type=click.Choice(["enu", "ned"]),
    default=None,
    help="A CSV's frames (default enu: ENU world, FLU body); a ULog is always PX4's NED/FRD.",
)
@click.option(
    "--commands",
    default="duty",
    show_default=True,
    metavar="duty|rad/s|pwm:MIN:MAX",
    help="Rotor commands: normalised duties (ULog: actuator_motors, relative thrust), rotor speeds (rad/s; ULog: the "
    "signal x w_max, rotor plant), "
    "or PWM [us] with their range.",
)
@click.option(
    "--holdout",
    type=float,
    default=0.3,
    show_default=True,
    help="Fraction of the airborne time, at its end, kept out of the fit and predicted.",
)
@click.option(
    "--out",
    "out",
    required=True,
    type=click.Path(file_okay=False),
    callback=writable,
    help="Folder for identify.json, vehicle.toml, report.md and the figure.",
)
@click.option(
    "--report",
    type=click.Path(dir_okay=False),
    metavar="PATH.html",
    callback=writable_with(".html", ".htm"),
    help="Also write a self-contained HTML report (parameters, validation, figure, configuration).",
)
@click.option("--force", is_flag=True, help="Replace a non-empty --out folder that quadcruise did not write.")
@friendly
def identify(
    log: str,
    vehicle: str,
    mass: float | None,
    frame: str | None,
    commands: str,
    holdout: float,
    out: str,
    report: str | None,
    force: bool,
) -> None:
    """Identify the vehicle that flew LOG (a PX4 .ulg or a CSV) and check it on held-out data.

    Fits thrust, inertias, yaw moment and rotor lag by equation error, with 95 % intervals;
    what the log cannot identify is said so and taken from --vehicle. The first line is the
    verdict: exit 0 when the model fits the log, 1 when it does not (no intervals then), 2 for
    bad input.

    \f
    Parameters
    ----------
    log : str
        ``LOG``: the flight log, ``.ulg`` or ``.csv``.
    vehicle : str
        ``--vehicle``: the base vehicle (``paper`` or a TOML file).
    mass : float or None
        ``--mass``: the mass [kg].
    frame : str or None
        ``--frame``: a CSV's frames.
    commands : str
        ``--commands``: ``duty`` or ``pwm:MIN:MAX``.
    holdout : float
        ``--holdout``: fraction held out.
    out : str
        ``--out``: the output folder.
    report : str or None
        ``--report``: path of a self-contained HTML report to write as well.
    force : bool
        ``--force``: replace a folder quadcruise did not write.
    """
    import dataclasses

    from quadcruise.io.files import check_output_dir
    from quadcruise.io.flightlog import parse_commands
    from quadcruise.sysid.api import STAGES
    from quadcruise.sysid.api import identify as run_identify

    distinct_outputs(out, report=report)
    base = base_vehicle(vehicle)
    parse_commands(commands)
    check_keeps_log(log, out)
    check_output_dir(out, force)
    words = (
        [
            "quadcruise",
            "identify",
            log,
            "--vehicle",
            vehicle,
            "--commands",
            commands,
            "--holdout",
            f"{holdout:g}",
            "--out",
            out,
        ]
        + (["--mass", f"{mass:g}"] if mass is not None else [])
        + (["--frame", frame] if frame else [])
        + (["--report", report] if report else [])
    )
    bar = Bar("identifying", unit="stage")
    result = run_identify(
        log,
        base,
        mass=mass,
        frame=frame,
        commands=commands,
        holdout=holdout,
        progress=lambda done, total, stage="": bar(done, total, stage),
    )
    bar.close()
    result = dataclasses.replace(result, command=shlex.join(words))
    click.echo(str(result.summary()))
    result.write(out, force=force)
    click.echo(f"wrote identify.json, vehicle.toml, report.md and fit.png to {out} ({len(STAGES)} stages)")
    if report is not None:
        from quadcruise.report.html import write_html_report
        from quadcruise.report.identify import identification_report

        write_html_report(report, **identification_report(result))
        click.echo(f"wrote report {report}")
    if not result.fits:  # written, said, and the status says it: 1, the model does not fit the log
        sys.exit(1)
