"""``quadcruise px4-check``: a PX4 log's own signals through the PX4 loops, compared with what
PX4 logged (a folder with ``check.json``)."""

from __future__ import annotations

import math
import shlex
import sys

import click

from quadcruise.cli.common import FORCE_OPTION, friendly, writable

__all__ = ["px4_check"]


@click.command("px4-check")
@click.argument("log", metavar="LOG.ulg")
@click.option(
    "--params",
    "params",
    default=None,
    metavar="LOG.ulg|FILE.params",
    help="Parameters to run the loops with (a PX4 log's or a QGroundControl file's); default: LOG's own.",
)
@click.option(
    "--out",
    "out",
    required=True,
    type=click.Path(file_okay=False),
    callback=writable,
    help="Folder for check.json (R2 and RMSE per loop and axis, the parameters, what limits the fit).",
)
@click.option(
    "--fly",
    "fly",
    is_flag=True,
    help="Also fly LOG's takeoff (its trajectory_setpoints, from the takeoff ramp) with the parameters, on the ground "
    "with PX4's takeoff, land detector and hover-thrust estimator, and compare height, roll, pitch, yaw with LOG "
    "(takeoff.png, vehicle.toml; exit 1 if the flight did not finish).",
)
@click.option(
    "--vehicle",
    "vehicle_text",
    default=None,
    metavar="NAME|FILE.toml|KEY=VALUE,...",
    help="With --fly: the vehicle flown (a rotor-plant vehicle); default jMAVSim's Iris (PX4 SITL airframe 10017), "
    "whose fields KEY=VALUE change (m=1.0).",
)
@click.option(
    "--thrust-curve",
    "thrust_curve",
    default=0.0,
    type=click.FloatRange(0.0, 1.0),
    show_default=True,
    help="With --fly: the vehicle's thrust per PX4 command u, (1 - a) u + a u^2 (0: linear, as jMAVSim and "
    "identify's thrust_curve_f of a PX4 log give).",
)
@click.option(
    "--fly-until",
    "until",
    default=None,
    type=float,
    metavar="SECONDS",
    help="With --fly: fly to this time of LOG [s from its start] instead of the takeoff's end (its return "
    "comes next in a SITL log).",
)
@click.option(
    "--no-hover-estimator",
    "no_hte",
    is_flag=True,
    help="With --fly: fly MPC_THR_HOVER as it is, without PX4's hover-thrust estimator.",
)
@FORCE_OPTION
@friendly
def px4_check(
    log: str,
    params: str | None,
    out: str,
    fly: bool,
    vehicle_text: str | None,
    thrust_curve: float,
    until: float | None,
    no_hte: bool,
    force: bool,
) -> None:
    """Feed LOG's attitude, rates and positions through PX4's loops (release v1.15, written from
    PX4's source) with LOG's parameters, and compare what they give with what PX4 logged.

    Prints R2 and RMSE per loop and axis, airborne samples only, and writes them to
    OUT/check.json. Parameters the loops do not use are counted here and listed there.

    \f
    Parameters
    ----------
    log : str
        ``LOG``: the PX4 log (``.ulg``).
    params : str or None
        ``--params``: a ``.ulg`` or ``.params`` file whose parameters to use instead.
    out : str
        ``--out``: the output folder.
    fly : bool
        ``--fly``: fly the log's takeoff too (:mod:`quadcruise.workflows.px4fly`).
    vehicle_text : str or None
        ``--vehicle``: the vehicle flown.
    thrust_curve : float
        ``--thrust-curve``: its thrust per command.
    until : float or None
        ``--fly-until``: the flight's end [s of the log].
    no_hte : bool
        ``--no-hover-estimator``.
    force : bool
        ``--force``: replace a folder quadcruise did not write.
    """
    from quadcruise.errors import InputError
    from quadcruise.io.files import check_output_dir
    from quadcruise.io.px4params import read_params
    from quadcruise.workflows.px4check import px4_check as run_check

    options = (("--vehicle", vehicle_text is not None), ("--thrust-curve", thrust_curve != 0.0),
               ("--fly-until", until is not None), ("--no-hover-estimator", no_hte))  # fmt: skip
    given = [name for name, on in options if on]
    if given and not fly:
        raise InputError(f"{given[0]} is for the flight: give --fly too")
    if not 0.0 <= thrust_curve <= 1.0:  # FloatRange lets nan through
        raise InputError(f"--thrust-curve {thrust_curve}: must be a number in [0, 1]")
    if until is not None and not math.isfinite(until):
        raise InputError(f"--fly-until {until}: must be a finite time in the log [s]")
    flight = None
    if fly:
        from quadcruise.cli.vehicle import vehicle_from_option
        from quadcruise.sim import plants
        from quadcruise.workflows.px4fly import jmavsim_iris

        vehicle = vehicle_from_option(vehicle_text, "--vehicle", base=jmavsim_iris()) or jmavsim_iris()
        if "ground" in plants.of(vehicle).refuses:  # --fly takes off from the ground
            raise InputError(f"--vehicle {vehicle_text!r}: --fly: {plants.of(vehicle).refuses['ground']}")
        flight = {"vehicle": vehicle, "thrust_curve": thrust_curve, "hover_estimator": not no_hte, "until_s": until}
    chosen = read_params(params) if params is not None else None
    check_output_dir(out, force, inputs=[log, params])
    words = ["quadcruise", "px4-check", log, "--out", out] + (["--params", params] if params else [])
    if fly:
        words += ["--fly"] + (["--vehicle", vehicle_text] if vehicle_text else [])
        words += (["--thrust-curve", repr(thrust_curve)] if thrust_curve else []) + (
            ["--no-hover-estimator"] if no_hte else []
        )
    result = run_check(log, chosen, command=shlex.join(words), fly=flight)
    click.echo(
        f"{result.log}: PX4 {result.px4_version}; loops of PX4 v1.15 with the parameters of {result.params.source}"
    )
    click.echo(result.table())
    for note in result.params.notes:  # another release's log: what flies at v1.15's defaults
        click.echo(f"note: {note}")
    unused = result.params.unused
    if 0 < len(unused) <= 12:
        click.echo(f"not used by the loops: {', '.join(unused)} (of {result.params.source})")
    elif unused:
        click.echo(
            f"{len(unused)} parameters of {result.params.source} are not used by the loops (listed in {out}/check.json)"
        )
    result.write(out, force=force)
    click.echo(f"wrote {out}/check.json" + (", takeoff.png and vehicle.toml" if fly else ""))
    if result.flight is not None and result.flight.status != "finished":
        click.echo(f"error: the takeoff flight did not finish: {result.flight.status}", err=True)
        sys.exit(1)
