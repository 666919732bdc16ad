"""The ``quadcruise`` command: a thin layer that parses options and calls the library.

Bad input prints one line, ``error: ...``, and exits with status 2.
"""

from __future__ import annotations

import functools
import sys
import warnings

import click

from . import __version__
from .errors import InputError


def _friendly(func):
    """Turn InputError into a one-line message with exit status 2; show warnings plainly."""

    @functools.wraps(func)
    def wrapper(*args, **kwargs):
        with warnings.catch_warnings(record=True) as caught:
            warnings.simplefilter("always")
            try:
                return func(*args, **kwargs)
            except InputError as exc:
                click.echo(f"error: {exc}", err=True)
                sys.exit(2)
            finally:
                for w in caught:
                    click.echo(f"warning: {w.message}", err=True)

    return wrapper


@click.group(context_settings={"help_option_names": ["-h", "--help"]})
@click.version_option(__version__, prog_name="quadcruise")
def main() -> None:
    """Quadrotor cruise control: simulate, design and fly controllers, measure them."""


@main.command()
@click.argument("pwm_csv", metavar="PWM.csv")
@click.option("-o", "--out", "out", required=True, metavar="STATES.csv",
              help="Where to write the states (t,x,y,z,vx,vy,vz,phi,theta,psi,p,q,r,F1..F4).")
@click.option("--max-step", default=1e-3, show_default=True, type=float,
              help="Longest RK4 substep [s].")
@_friendly
def replay(pwm_csv: str, out: str, max_step: float) -> None:
    """Replay PWM duties open loop (columns t,u1,u2,u3,u4) and write the states.

    Each row's duties hold until the next row's time. The vehicle (the paper's Table I)
    starts at rest at the origin with each rotor at the thrust of the first row.
    """
    from .replay import read_duty_csv, replay as run_replay, write_states_csv

    schedule = read_duty_csv(pwm_csv)
    result = run_replay(schedule, max_step=max_step)
    if not result.ok[0]:
        click.echo(f"warning: the flight stopped early: {result.status_text(0)}", err=True)
    write_states_csv(result, out)
    click.echo(f"wrote {len(result.t)} states to {out} "
               f"(t = {result.t[0]:g} .. {result.t[-1]:g} s, final z = {result.final_state[0, 2]:.4f} m)")


if __name__ == "__main__":  # pragma: no cover
    main()
