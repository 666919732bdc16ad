"""The ``quadcruise`` command: a thin layer that parses options and calls the library.

The group lives here, each command in its own module (:mod:`quadcruise.cli.fly`,
:mod:`~quadcruise.cli.replay`, :mod:`~quadcruise.cli.reproduce`,
:mod:`~quadcruise.cli.compare`, :mod:`~quadcruise.cli.analyze`,
:mod:`~quadcruise.cli.montecarlo`, :mod:`~quadcruise.cli.tune`,
:mod:`~quadcruise.cli.identify`), what they share in :mod:`quadcruise.cli.common`;
the larger commands keep what they run after parsing in a ``*_run`` module beside them
(:mod:`~quadcruise.cli.compare_run`, :mod:`~quadcruise.cli.montecarlo_run`, :mod:`~quadcruise.cli.tune_run`).
Bad input prints one line, ``error: ...``, and exits with status 2; a flight that did not
finish (``fly``, ``compare``, ``reproduce``) or a tune that missed its targets, status 1.
"""

from __future__ import annotations

import gc
import sys

import click

from quadcruise._version import __version__
from quadcruise.cli.analyze import analyze
from quadcruise.cli.compare import compare
from quadcruise.cli.fly import fly
from quadcruise.cli.identify import identify
from quadcruise.cli.montecarlo import montecarlo
from quadcruise.cli.replay import replay
from quadcruise.cli.reproduce import reproduce
from quadcruise.cli.tune import tune

__all__ = ["main", "run"]


@click.group(context_settings={"help_option_names": ["-h", "--help"]})
@click.version_option(__version__, prog_name="quadcruise")
def main() -> None:
    """Quadrotor cruise control: simulate, design and fly controllers, measure them."""


main.add_command(replay)
main.add_command(fly)
main.add_command(reproduce)
main.add_command(compare)
main.add_command(analyze)
main.add_command(montecarlo)
main.add_command(tune)
main.add_command(identify)


def run() -> None:
    """Entry point: click's own usage errors become one line with exit status 2 too.

    The process ends here, so what it made is first moved out of the garbage collector's
    sight (``gc.freeze``): the interpreter's last collection at exit would otherwise walk
    every object that numba, pandas and matplotlib left, about 0.2 s.

    Raises
    ------
    SystemExit
        Always: 0 on success, 2 for bad input, 130 when interrupted, else the command's status.
    """
    if len(sys.argv) <= 1:                  # bare `quadcruise`: the usage, as --help gives it
        with click.Context(main, info_name="quadcruise") as ctx:
            click.echo(main.get_help(ctx))
        sys.exit(0)
    try:
        code = main(standalone_mode=False)
    except click.exceptions.UsageError as exc:
        click.echo(f"error: {exc.format_message()}", err=True)
        sys.exit(2)
    except (click.exceptions.Abort, KeyboardInterrupt):
        click.echo("error: interrupted (a montecarlo sweep with --out resumes if run again)", err=True)
        sys.exit(130)
    finally:
        gc.freeze()
    sys.exit(code if isinstance(code, int) else 0)


if __name__ == "__main__":  # pragma: no cover
    run()
