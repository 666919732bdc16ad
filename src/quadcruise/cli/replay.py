"""``quadcruise replay``: PWM duties replayed open loop, the states written to a CSV."""

from __future__ import annotations

import click

from quadcruise.cli.common import Bar, friendly, writable_with

__all__ = ["replay"]


@click.command("replay")
@click.argument("pwm_csv", metavar="PWM.csv")
@click.option("-o", "--out", "out", required=True, metavar="STATES.csv", callback=writable_with(".csv"),
              type=click.Path(dir_okay=False),
              help="Where to write the states (t,x,y,z,vx,vy,vz,phi,theta,psi,p,q,r,F1..F4).")
@click.option("--max-step", default=1e-3, show_default=True, type=float,
              help="Longest RK4 substep [s].")
@friendly
def replay(pwm_csv: str, out: str, max_step: float) -> None:
    """Replay PWM duties open loop (columns t,u1,u2,u3,u4) and write the states.

    Each row's duties hold until the next row's time. The vehicle (the paper's Table I)
    starts at rest at the origin with each rotor at the thrust of the first row.

    \f
    Parameters
    ----------
    pwm_csv : str
        ``PWM.csv``: path of the duty table, columns ``t`` [s] and ``u1`` .. ``u4`` (the four
        rotors' PWM duties).
    out : str
        ``-o``/``--out``: path of the states CSV to write (t, position [m], velocity [m/s],
        angles [rad], body rates [rad/s], rotor thrusts F1..F4 [N]).
    max_step : float
        ``--max-step``: longest RK4 substep [s].
    """
    import os

    from quadcruise.workflows.replay import read_duty_csv, write_states_csv
    from quadcruise.workflows.replay import replay as run_replay

    if os.path.exists(out) and os.path.exists(pwm_csv) and os.path.samefile(pwm_csv, out):
        raise click.BadParameter(f"{out} is the input file: write the states elsewhere", param_hint="'-o'")

    schedule = read_duty_csv(pwm_csv, progress=Bar(f"reading {pwm_csv}", unit="row"))
    result = run_replay(schedule, max_step=max_step, progress=Bar("flying", unit="row"))
    if not result.ok[0]:
        click.echo(f"warning: the flight stopped early: {result.status_text(0)}", err=True)
    write_states_csv(result, out, progress=Bar(f"writing {out}", unit="row"))
    click.echo(f"wrote {len(result.t)} states to {out} "
               f"(t = {result.t[0]:g} .. {result.t[-1]:g} s, final z = {result.final_state[0, 2]:.4f} m)")
