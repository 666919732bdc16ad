"""The ``quadcruise`` command: a thin layer that parses options and calls the library.

The group lives here, each command in its own module (:mod:`quadcruise.cli.fly`,
:mod:`~quadcruise.cli.replay`, :mod:`~quadcruise.cli.reproduce`,
:mod:`~quadcruise.cli.compare`, :mod:`~quadcruise.cli.analyze`,
:mod:`~quadcruise.cli.montecarlo`, :mod:`~quadcruise.cli.tune`, :mod:`~quadcruise.cli.vehicles`,
:mod:`~quadcruise.cli.identify`, :mod:`~quadcruise.cli.px4_check`,
:mod:`~quadcruise.cli.estimate`), what they share in :mod:`quadcruise.cli.common`;
the larger commands keep what they run after parsing in a ``*_run`` module beside them
(:mod:`~quadcruise.cli.compare_run`, :mod:`~quadcruise.cli.montecarlo_run`, :mod:`~quadcruise.cli.tune_run`).
Bad input prints one line, ``error: ...``, and exits with status 2; a flight that did not
finish (``fly``, ``compare``, ``reproduce``) or a tune that missed its targets, status 1; a
file or standard output that could not be written, one line and status 74; Ctrl-C, 130;
SIGTERM, 143 (:mod:`quadcruise.cli.faults`).
"""

from __future__ import annotations

import gc
import signal
import sys
import warnings

import click

from quadcruise._version import __version__
from quadcruise.cli.analyze import analyze
from quadcruise.cli.compare import compare
from quadcruise.cli.estimate import estimate
from quadcruise.cli.faults import EXIT_FAULT, fault_text, guard_stdout, interrupt_text, stop_on_sigterm
from quadcruise.cli.fly import fly
from quadcruise.cli.identify import identify
from quadcruise.cli.montecarlo import montecarlo
from quadcruise.cli.px4_check import px4_check
from quadcruise.cli.replay import replay
from quadcruise.cli.reproduce import reproduce
from quadcruise.cli.tune import tune
from quadcruise.cli.vehicles import vehicles

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
main.add_command(vehicles)
main.add_command(identify)
main.add_command(px4_check)
main.add_command(estimate)


def run() -> None:
    """Entry point: click's own usage errors become one line with exit status 2 too.

    Standard output is guarded (:func:`~quadcruise.cli.faults.guard_stdout`): a write that
    fails is one line and status 74, a reader that stops reading drops the rest quietly.
    SIGTERM stops a command as Ctrl-C does (:func:`~quadcruise.cli.faults.stop_on_sigterm`).
    The process ends here, so what it made is first moved out of the garbage collector's
    sight (``gc.freeze``): the interpreter's last collection at exit would otherwise walk
    every object that numba, pandas and matplotlib left, about 0.2 s.

    Raises
    ------
    SystemExit
        Always: 0 on success, 2 for bad input, 74 for a file or standard output that could
        not be written, 130 when interrupted, 143 when terminated, else the command's status.
    """
    signal.signal(signal.SIGINT, signal.default_int_handler)  # the loading's handler (quadcruise/__init__) ends
    guard_stdout()
    stop_on_sigterm()
    try:
        if len(sys.argv) <= 1:  # bare `quadcruise`: the usage, as --help gives it
            with click.Context(main, info_name="quadcruise") as ctx:
                click.echo(main.get_help(ctx))
            code = 0
        else:
            code = main(standalone_mode=False)
        sys.stdout.flush()  # a fault of standard output is said here, not at exit
    except click.exceptions.UsageError as exc:
        click.echo(f"error: {exc.format_message()}", err=True)
        sys.exit(2)
    except OSError as exc:  # outside a command: --help, --version
        click.echo(f"error: {fault_text(exc)}", err=True)
        sys.exit(EXIT_FAULT)
    except (click.exceptions.Abort, KeyboardInterrupt) as exc:
        command = sys.argv[1] if len(sys.argv) > 1 else ""  # the sweep's way on is said for a sweep only
        text, status = interrupt_text(exc if isinstance(exc, KeyboardInterrupt) else KeyboardInterrupt(), command)
        click.echo(f"error: {text}", err=True)
        # a file an interrupted import had open is closed at exit: no news to a user, one line stays one
        warnings.filterwarnings("ignore", category=ResourceWarning)
        sys.exit(status)
    finally:
        gc.freeze()
    sys.exit(code if isinstance(code, int) else 0)


if __name__ == "__main__":  # pragma: no cover
    run()
