"""What the commands share: their common options, the error handling that turns bad input
into one line ``error: ...`` with exit status 2 (and a fault of the machine, Ctrl-C, into one
line too: :mod:`quadcruise.cli.faults`), and the parsing of the options that name a
mission or a controller."""

from __future__ import annotations

import functools
import math
import sys
import warnings
from collections.abc import Callable

import click

from quadcruise.cli.faults import EXIT_FAULT, fault_text, interrupt_text
from quadcruise.cli.feedback import Bar, close_bars, compile_notice
from quadcruise.cli.objects import controller_from_options, mission_from_options
from quadcruise.errors import InputError

__all__ = [
    "FORCE_OPTION",
    "FORMAT_OPTION",
    "REPORT_OPTION",
    "RISE_OPTION",
    "SETTLE_BAND_OPTION",
    "Bar",
    "friendly",
    "distinct_outputs",
    "needs_out",
    "writable_with",
    "metric_options",
    "writable",
    "controller_from_options",
    "mission_from_options",
]


# options several commands share
def _table_format(ctx: click.Context, param: click.Parameter, value: str) -> str:
    from quadcruise.io.files import check_table_format

    try:
        check_table_format(value)  # Parquet needs pyarrow: said before anything flies
    except InputError as exc:
        raise click.BadParameter(str(exc), ctx=ctx, param=param) from None
    return value


FORMAT_OPTION = click.option(
    "--format",
    "fmt",
    type=click.Choice(["csv", "parquet"]),
    default="csv",
    show_default=True,
    callback=_table_format,
    help="Format of the traces.",
)


class _Seconds(click.FloatRange):
    """A positive, finite number of seconds: ``FloatRange(min=0, min_open=True)`` let ``inf`` and
    ``nan`` through to the library, whose refusal named its Python argument (``fly() argument
    duration``), not the option."""

    name = "seconds"

    def convert(self, value, param, ctx):
        x = super().convert(value, param, ctx)
        if not math.isfinite(x):
            self.fail(f"{value!r} is not a finite number of seconds (give a positive number, e.g. 10)", param, ctx)
        return x


SECONDS = _Seconds(min=0.0, min_open=True)
"""A time option's type (--duration, --dt, --max-step): a positive finite number of seconds, said by the
option's name (``fly --duration inf``: "Invalid value for '--duration'")."""

FORCE_OPTION = click.option("--force", is_flag=True, help="Replace a non-empty --out folder not written by quadcruise.")


def writable(ctx: click.Context, param: click.Parameter, value):
    """A click callback: refuse an output path that could not be written, before any work."""
    if value is not None:
        from quadcruise.io.files import check_writable_place

        try:
            check_writable_place(value)
        except InputError as exc:
            raise click.BadParameter(str(exc), ctx=ctx, param=param) from None
    return value


def needs_out(out, **given) -> None:
    """Refuse options that only shape the ``--out`` folder when no ``--out`` is given."""
    if out is None:
        for name, was_given in given.items():
            if was_given:
                raise InputError(f"--{name} shapes the --out folder; without --out it would change nothing")


def distinct_outputs(out, **files) -> None:
    """Refuse, before any work, a file option that names the ``--out`` folder itself, or two
    that name one file: the folder or the other would be written over it after the work.

    A file named inside ``--out`` is kept: the folder is written first and the file after.

    Parameters
    ----------
    out : str or None
        The ``--out`` folder.
    **files : str or None
        Option name (``report``, ``ulog``, ``animate``) -> the path given, or None.

    Raises
    ------
    InputError
        Naming both options and the path.
    """
    from pathlib import Path

    given = [(f"--{name}", path) for name, path in files.items() if path is not None]
    given = ([("--out", out)] if out is not None else []) + given
    for i, (name, path) in enumerate(given):
        for other, seen in given[:i]:
            if Path(path).resolve() == Path(seen).resolve():
                raise InputError(f"{name} {path} and {other} {seen} name the same path: give each its own")


def writable_with(*suffixes: str):
    """A click callback: :func:`writable`, and the path must end in one of ``suffixes``."""

    def check(ctx: click.Context, param: click.Parameter, value):
        if value is not None and str(value).strip() and not str(value).lower().endswith(suffixes):
            raise click.BadParameter(
                f"{value}: the file is written as {' or '.join(suffixes)}; name it so", ctx=ctx, param=param
            )
        return writable(ctx, param, value)

    return check


REPORT_OPTION = click.option(
    "--report",
    type=click.Path(dir_okay=False),
    metavar="PATH.html",
    callback=writable_with(".html", ".htm"),
    help="Also write a self-contained HTML report (tables, figures, interactive 3-D view, configuration).",
)

RISE_OPTION = click.option(
    "--rise",
    type=click.Choice(["10-90", "0-100"]),
    default="10-90",
    show_default=True,
    help="Rise time between these percents of the step.",
)
SETTLE_BAND_OPTION = click.option(
    "--settle-band",
    "settle_bands",
    type=float,
    multiple=True,
    metavar="FRACTION",
    help="Settling band, a fraction of the step (default 0.02, then 0.05): the first "
    "gives settling_time_s, a second (0.05 if left out; 0.02 beside a first "
    "0.05) a column named after it.",
)


def metric_options(rise: str = "10-90", settle_bands: tuple[float, ...] = ()) -> dict:
    """``--rise`` and ``--settle-band`` as keywords of :func:`quadcruise.metrics.flight_metrics`, checked
    (:func:`~quadcruise.metrics.conventions.metric_conventions`) before anything flies."""
    from quadcruise.metrics.conventions import metric_conventions

    kw = {"rise": rise, "settle_bands": tuple(settle_bands) or (0.02, 0.05)}
    metric_conventions(**kw)
    return kw


def friendly(func: Callable) -> Callable:
    """Wrap a command: InputError becomes one line on stderr, ``error: ...``, and exit status
    2; a fault of the machine (an ``OSError``: a file it could not write), Ctrl-C and SIGTERM
    one line each too, with the statuses of :mod:`quadcruise.cli.faults`; every warning
    raised meanwhile is shown plainly, ``warning: ...``; a progress bar still open is closed
    first, and on a terminal numba's first compilation is announced
    (:mod:`quadcruise.cli.feedback`)."""

    @functools.wraps(func)
    def wrapper(*args, **kwargs):
        with warnings.catch_warnings(record=True) as caught, compile_notice():
            warnings.simplefilter("always")
            try:
                return func(*args, **kwargs)
            except InputError as exc:
                close_bars()
                click.echo(f"error: {exc}", err=True)
                sys.exit(2)
            except OSError as exc:
                close_bars()
                click.echo(f"error: {fault_text(exc)}", err=True)
                sys.exit(EXIT_FAULT)
            except KeyboardInterrupt as exc:
                close_bars()
                text, status = interrupt_text(exc, func.__name__)
                click.echo(("\n" if sys.stderr.isatty() else "") + f"error: {text}", err=True)  # after a ^C
                sys.exit(status)
            finally:
                close_bars()
                for w in caught:
                    click.echo(f"warning: {w.message}", err=True)

    return wrapper
