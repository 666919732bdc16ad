"""``quadcruise replay``: commands replayed open loop, the states written to a CSV: PWM duties
on the paper's plant, or commanded rotor speeds on a rotor-plant vehicle (``--vehicle``)."""

from __future__ import annotations

import click

from quadcruise.cli.common import SECONDS, Bar, friendly, writable_with

__all__ = ["replay"]


@click.command("replay")
@click.argument("pwm_csv", metavar="CMDS.csv")
@click.option(
    "-o",
    "--out",
    "out",
    required=True,
    metavar="STATES.csv",
    callback=writable_with(".csv"),
    type=click.Path(dir_okay=False),
    help="Where to write the states: t,x,y,z,vx,vy,vz,phi,theta,psi,p,q,r,F1..F4 for the paper's plant; "
    "t,x,y,z,vx,vy,vz,qw,qx,qy,qz,p,q,r,w1..wn,phi,theta,psi for a rotor-plant vehicle.",
)
@click.option(
    "--vehicle",
    "vehicle_name",
    default=None,
    metavar="NAME|FILE.toml",
    help="The vehicle: a preset (paper, qball-x4, crazyflie, hummingbird, iris) or a vehicle file "
    '([vehicle] preset = "iris" and the fields to change). Default: the paper\'s Table I.',
)
@click.option(
    "--ground",
    is_flag=True,
    help="A ground at z = 0 (rotor-plant vehicles): the vehicle starts and rests on it; meeting it faster "
    "than the vehicle's touchdown_speed, or upside down, ends the flight 'crashed'.",
)
@click.option(
    "--max-step",
    default=None,
    type=SECONDS,
    help="Longest RK4 substep [s]. Default: 1e-3 for the paper's plant, 1e-4 for a rotor-plant vehicle.",
)
@friendly
def replay(pwm_csv: str, out: str, vehicle_name: str | None, ground: bool, max_step: float | None) -> None:
    """Replay commands open loop and write the states.

    The table's columns say what it holds and the vehicle which plant flies it. For the
    paper's plant the columns are t,u1,u2,u3,u4 (PWM duties); for a rotor-plant vehicle,
    t,w1,..,wn (commanded rotor speeds, rad/s, in the vehicle's range) or t,u1,..,un
    (normalised commands in [0, 1], each rotor at u w_max: PX4's THR_MDL_FAC = 1). Each row's
    commands hold until the next row's time. The vehicle starts at rest at the origin, level,
    each rotor at the first row's command. The states are written even when the flight stops
    early (diverged, crashed); the exit status is then 1.

    \f
    Parameters
    ----------
    pwm_csv : str
        ``CMDS.csv``: path of the command table, columns ``t`` [s] and ``u1`` .. ``u4`` (PWM
        duties) or ``w1`` .. ``wn`` (rotor speeds [rad/s]).
    out : str
        ``-o``/``--out``: path of the states CSV to write (t, position [m], velocity [m/s],
        angles [rad] or the quaternion and the angles, body rates [rad/s], rotor thrusts
        F1..F4 [N] or rotor speeds [rad/s]).
    vehicle_name : str or None
        ``--vehicle``: a preset's name or a vehicle TOML file; None: the paper's Table I.
    ground : bool
        ``--ground``: a ground at z = 0 (rotor-plant vehicles only).
    max_step : float or None
        ``--max-step``: longest RK4 substep [s]; None: 1e-3 s (paper) or 1e-4 s (rotor plant).
    """
    import os
    import sys

    from quadcruise.errors import InputError
    from quadcruise.model.vehicle import Vehicle
    from quadcruise.workflows.commands import ROTOR_VEHICLES, read_commands, replay_plant
    from quadcruise.workflows.replay import replay as fly_open_loop
    from quadcruise.workflows.replay import write_states_csv

    if os.path.exists(out) and os.path.exists(pwm_csv) and os.path.samefile(pwm_csv, out):
        raise click.BadParameter(f"{out} is the input file: write the states elsewhere", param_hint="'-o'")
    vehicle = Vehicle.paper() if vehicle_name is None else Vehicle.load(vehicle_name)
    if getattr(vehicle, "batch_size", None) is not None:
        raise InputError(
            f"{vehicle_name}: replay flies one vehicle and writes its states: give one value per field, not a list"
        )
    if ground and not replay_plant(vehicle).takes_speeds:
        raise InputError(
            f"option '--ground': the paper's plant has no ground: give a rotor-plant --vehicle ({ROTOR_VEHICLES})"
        )
    schedule = read_commands(pwm_csv, vehicle, progress=Bar(f"reading {pwm_csv}", unit="row"))
    result = fly_open_loop(schedule, vehicle, max_step=max_step, ground=ground, progress=Bar("flying", unit="row"))
    write_states_csv(result, out, progress=Bar(f"writing {out}", unit="row"))
    click.echo(
        f"wrote {len(result.t)} states to {out} "
        f"(t = {result.t[0]:g} .. {result.t[-1]:g} s, final z = {result.final_state[0, 2]:.4f} m)"
    )
    if not result.ok[0]:
        click.echo(f"the flight stopped early: {result.status_text(0)}", err=True)
        sys.exit(1)  # diverged or crashed: the states up to then are written
