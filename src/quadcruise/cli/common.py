"""What the commands share: their common options, the error handling that turns bad input
into one line ``error: ...`` with exit status 2, and the parsing of the options that name a
mission or a controller."""

from __future__ import annotations

import functools
import sys
import warnings
from typing import Callable

import click

from quadcruise.errors import InputError

__all__ = ["FORCE_OPTION", "FORMAT_OPTION", "REPORT_OPTION", "controller_from_options", "friendly",
           "mission_from_options"]

# options several commands share
FORMAT_OPTION = click.option("--format", "fmt", type=click.Choice(["csv", "parquet"]), default="csv",
                             show_default=True, help="Format of the traces.")
FORCE_OPTION = click.option("--force", is_flag=True, help="Replace a non-empty --out folder not written by quadcruise.")
def writable(ctx: click.Context, param: click.Parameter, value):
    """A click callback: refuse an output path that could not be written, before any work.

    Parameters
    ----------
    ctx : click.Context
    param : click.Parameter
    value : str or None
        The path given, or None.

    Returns
    -------
    str or None
        ``value``, checked.
    """
    if value is not None:
        from quadcruise.io.files import check_writable_place

        try:
            check_writable_place(value)
        except InputError as exc:
            raise click.BadParameter(str(exc), ctx=ctx, param=param) from None
    return value


REPORT_OPTION = click.option("--report", type=click.Path(dir_okay=False), metavar="PATH.html", callback=writable,
                             help="Also write a self-contained HTML report (tables, figures, interactive 3-D "
                                  "view, configuration).")


def friendly(func: Callable) -> Callable:
    """Wrap a command: InputError becomes one line on stderr, ``error: ...``, and exit status
    2; every warning raised meanwhile is shown plainly, ``warning: ...``.

    Parameters
    ----------
    func : callable
        The command's function.

    Returns
    -------
    callable
        The wrapped function (same name, docstring and signature, so click's help holds).
    """

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


def _poles(text: str | None, option: str):
    """Parse comma-separated poles, e.g. ``-0.7,-4.3`` or ``-1+2j,-1-2j``.

    Parameters
    ----------
    text : str or None
        The option's value; None when it was not given.
    option : str
        The option's name, for the error message.

    Returns
    -------
    list of complex or float, or None
        The poles (:func:`quadcruise.control.design.parse_pole` of each); None for None.

    Raises
    ------
    InputError
        A pole is not a number.
    """
    if text is None:
        return None
    from quadcruise.control.design import parse_pole

    try:
        return [parse_pole(p) for p in text.split(",")]
    except ValueError:
        raise InputError(f"{option} {text!r}: expected comma-separated poles, e.g. -0.7,-4.3") from None


def controller_params(params: tuple[str, ...], poles_text: str | None) -> dict:
    """The controller parameters that ``-c KEY=VALUE`` and ``--poles`` give.

    Parameters
    ----------
    params : tuple of str
        ``KEY=VALUE`` parameters.
    poles_text : str or None
        Closed-loop poles of the x/y loops; their PD gains become the ``position`` gains.

    Returns
    -------
    dict
    """
    from quadcruise.control.design import pd_from_poles
    from quadcruise.fields import parse_assignments

    out = parse_assignments(params, "--controller-param")
    poles = _poles(poles_text, "--poles")
    if poles is not None:
        out["position"] = pd_from_poles(poles)
    return out


def controller_from_options(name: str, params: tuple[str, ...], poles_text: str | None, base=None):
    """The controller that ``--controller``, ``-c KEY=VALUE`` and ``--poles`` describe.

    Parameters
    ----------
    name : str
        The controller's name (:func:`quadcruise.control.controller_from_name`); unused with ``base``.
    params : tuple of str
        ``KEY=VALUE`` parameters of the controller.
    poles_text : str or None
        Closed-loop poles of the x/y loops; their PD gains become the ``position`` gains.
    base : Controller, optional
        A controller (a scenario's) to change instead of a new one.

    Returns
    -------
    Controller
    """
    import dataclasses

    from quadcruise.control import controller_from_name

    given = controller_params(params, poles_text)
    if base is None:
        return controller_from_name(name, **given)
    known = [f.name for f in dataclasses.fields(base)]
    unknown = sorted(set(given) - set(known))
    if unknown:
        raise InputError(f"{base.name} has no parameter {unknown[0]!r}; its parameters: {', '.join(known)}")
    return dataclasses.replace(base, **given) if given else base


def mission_from_options(text: str, params: tuple[str, ...], smooth: bool):
    """A mission from a name or a waypoint CSV, with KEY=VALUE parameters.

    Parameters
    ----------
    text : str
        A mission name, or a path ending in ``.csv`` (a waypoint table).
    params : tuple of str
        ``KEY=VALUE`` parameters of the mission.
    smooth : bool
        Fly a waypoint table as a minimum-snap path instead of constant-speed legs.

    Returns
    -------
    Mission
    """
    from quadcruise.fields import parse_assignments
    from quadcruise.missions import mission_from_name

    mparams = parse_assignments(params, "--mission-param")
    if text.lower().endswith(".csv"):
        mparams["table"] = text
        text = "minsnap" if smooth else "waypoints"
    return mission_from_name(text, **mparams)
