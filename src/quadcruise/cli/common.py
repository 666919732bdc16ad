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

__all__ = ["FORCE_OPTION", "FORMAT_OPTION", "REPORT_OPTION", "RISE_OPTION", "SETTLE_BAND_OPTION",
           "controller_from_options", "friendly", "metric_options", "mission_from_options"]

# options several commands share
FORMAT_OPTION = click.option("--format", "fmt", type=click.Choice(["csv", "parquet"]), default="csv",
                             show_default=True, help="Format of the traces.")
FORCE_OPTION = click.option("--force", is_flag=True, help="Replace a non-empty --out folder not written by quadcruise.")
REPORT_OPTION = click.option("--report", type=click.Path(dir_okay=False), metavar="PATH.html",
                             help="Also write a self-contained HTML report (tables, figures, interactive 3-D "
                                  "view, configuration).")

RISE_OPTION = click.option("--rise", type=click.Choice(["10-90", "0-100"]), default="10-90", show_default=True,
                           help="Rise time between these percents of the step.")
SETTLE_BAND_OPTION = click.option("--settle-band", "settle_bands", type=float, multiple=True, metavar="FRACTION",
                                  help="Settling band, a fraction of the step (default 0.02, then 0.05): the first "
                                       "gives settling_time_s, a second (0.05 if left out) a column named after it.")


def metric_options(rise: str = "10-90", settle_bands: tuple[float, ...] = ()) -> dict:
    """``--rise`` and ``--settle-band`` as keywords of :func:`quadcruise.metrics.flight_metrics`, checked
    (:func:`~quadcruise.metrics.flight.metric_conventions`) before anything flies.

    Parameters
    ----------
    rise : {"10-90", "0-100"}
        The rise-time levels in percent.
    settle_bands : tuple of float
        None (2 % and 5 %), one band (and 5 %) or two.

    Returns
    -------
    dict
        ``rise`` and ``settle_bands``.
    """
    from quadcruise.metrics.flight import metric_conventions

    kw = {"rise": rise, "settle_bands": tuple(settle_bands) or (0.02, 0.05)}
    metric_conventions(**kw)
    return kw


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


def _assignments(items: tuple[str, ...], option: str) -> dict:
    """Parse KEY=VALUE pairs: numbers, comma-separated pairs of numbers, or words.

    Parameters
    ----------
    items : tuple of str
        The values of a repeatable option, each ``KEY=VALUE``.
    option : str
        The option's name, for the error message.

    Returns
    -------
    dict
        Key -> a float, a tuple of floats (``1,2``) or the text as given.

    Raises
    ------
    InputError
        An item has no ``=`` or no key.
    """
    out = {}
    for item in items:
        key, sep, raw = item.partition("=")
        if not sep or not key.strip():
            raise InputError(f"{option} {item!r}: expected KEY=VALUE")
        parts = [p.strip() for p in raw.split(",")]
        try:
            values = [float(p) for p in parts]
            out[key.strip()] = values[0] if len(values) == 1 else tuple(values)
        except ValueError:
            out[key.strip()] = raw.strip()
    return out


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


def controller_from_options(name: str, params: tuple[str, ...], poles_text: str | None):
    """The controller that ``--controller``, ``-c KEY=VALUE`` and ``--poles`` describe.

    Parameters
    ----------
    name : str
        The controller's name (:func:`quadcruise.control.controller_from_name`).
    params : tuple of str
        ``KEY=VALUE`` parameters of the controller.
    poles_text : str or None
        Closed-loop poles of the x/y loops; their PD gains become the ``position`` gains.

    Returns
    -------
    Controller
    """
    from quadcruise.control import controller_from_name
    from quadcruise.control.design import pd_from_poles

    cparams = _assignments(params, "--controller-param")
    poles = _poles(poles_text, "--poles")
    if poles is not None:
        cparams["position"] = pd_from_poles(poles)
    return controller_from_name(name, **cparams)


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
    from quadcruise.missions import mission_from_name

    mparams = _assignments(params, "--mission-param")
    if text.lower().endswith(".csv"):
        mparams["table"] = text
        text = "minsnap" if smooth else "waypoints"
    return mission_from_name(text, **mparams)
