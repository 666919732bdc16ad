"""The ``--wind`` spec of the command line: an :class:`~quadcruise.disturbances.Environment`
from text.

The library takes the parts as objects (``Environment(gust=Gust(...))``); only the command line
and the scenario reader turn text into them, so the spec's grammar lives here.

Examples
--------
>>> parse_wind("gust:2,0@5+2")
Traceback (most recent call last):
    ...
quadcruise.errors.InputError: wind spec 'gust:2,0@5+2': needs 3 values AX,AY,AZ, got '2,0'
"""

from __future__ import annotations

import re
from typing import Any

from quadcruise.cli.assignments import parse_numbers
from quadcruise.disturbances import INTENSITIES, ConstantWind, Environment, ExternalForce, Gust, RotorLoss, Turbulence
from quadcruise.disturbances.part import Part
from quadcruise.errors import InputError

PART_NAMES = {
    "constant": ConstantWind,
    "wind": ConstantWind,
    "gust": Gust,
    "dryden": Turbulence,
    "turbulence": Turbulence,
    "loss": RotorLoss,
    "rotor_loss": RotorLoss,
    "force": ExternalForce,
}
"""The parts by the names a spec gives them (in any case)."""


def wind_from_name(name: str, **kw: Any) -> Part:
    """A part by name (``constant``/``wind``, ``gust``, ``dryden``/``turbulence``,
    ``loss``/``rotor_loss``, ``force``) with its fields as keywords.

    Examples
    --------
    >>> wind_from_name("Gust", start=2.0).duration
    1.0
    """
    cls = PART_NAMES.get(str(name).lower())
    if cls is None:
        raise InputError(f"unknown disturbance {name!r}; choose one of {', '.join(PART_NAMES)}")
    try:
        return cls(**kw)
    except TypeError as e:
        raise InputError(f"{name}: {e}") from None


def _floats(text: str, k: int, what: str) -> list:
    return parse_numbers(text, what, k)


def _part(text: str) -> Part:
    name, _, body = text.partition(":")
    cls, body = PART_NAMES.get(name.strip().lower()), re.sub(r"\s+", "", body)
    first, at, rest = body.partition("@")
    if cls is None:
        raise InputError(f"unknown model {name.strip()!r}; choose one of {', '.join(PART_NAMES)}")
    if cls is ConstantWind:
        return ConstantWind(velocity=_floats(body, 3, "WX,WY,WZ"))
    if cls is Gust:
        start, plus, dur = rest.partition("+")
        if not plus:
            raise InputError("expected gust:AX,AY,AZ@START+DURATION")
        return Gust(_floats(first, 3, "AX,AY,AZ"), _floats(start, 1, "START")[0], _floats(dur, 1, "DURATION")[0])
    if cls is Turbulence:
        alt, _, speed = rest.partition("/")
        kw: dict = (
            {"intensity": first.lower()}
            if first.lower() in INTENSITIES
            else {"w20": _floats(first, 1, "LEVEL (light, moderate, severe or w20 m/s)")[0]}
        )
        return Turbulence(**kw, **{k: _floats(v, 1, k)[0] for k, v in (("altitude", alt), ("airspeed", speed)) if v})
    if cls is RotorLoss:
        if not at:
            raise InputError("expected loss:ROTOR,FRACTION@TIME")
        return RotorLoss(*_floats(first, 2, "ROTOR,FRACTION"), _floats(rest, 1, "TIME")[0])
    force, _, torque = body.partition("/")
    return ExternalForce(_floats(force, 3, "FX,FY,FZ"), _floats(torque, 3, "TX,TY,TZ") if torque else (0.0, 0.0, 0.0))


def parse_wind(text: str) -> Environment:
    """An :class:`Environment` from a command-line spec: parts separated by ``,`` ``;`` or spaces.

    Grammar (SI units; each kind at most once; ``none`` or ``calm``: still air)::

        constant:WX,WY,WZ                  steady wind [m/s]                   (or wind:)
        gust:AX,AY,AZ@START+DURATION       1 - cosine gust [m/s, s, s]
        dryden:LEVEL[@ALTITUDE[/AIRSPEED]] LEVEL light|moderate|severe or w20 [m/s];
                                           altitude [m] (10), airspeed [m/s] (1)  (or turbulence:)
        loss:ROTOR,FRACTION@TIME           rotor 1-4 loses FRACTION of its thrust at TIME [s]
        force:FX,FY,FZ[/TX,TY,TZ]          force [N] (earth frame), torque [N m] (body frame)

    e.g. ``constant:3,0,0,gust:2,0,0@5+2,dryden:moderate@10``. Bad input raises a one-line
    :class:`InputError` quoting the part.

    Parameters
    ----------
    text : str
        The spec, in the grammar above.

    Returns
    -------
    Environment
        The parts in their slots (empty for ``none``, ``calm`` or a blank spec).

    Raises
    ------
    InputError
        An unknown model, a malformed or out-of-range value, or a kind given twice.

    Examples
    --------
    >>> sorted(parse_wind("constant:3,0,0 gust:2,0,0@5+2").parts)
    ['gust', 'wind']
    >>> parse_wind("calm").parts
    {}
    """
    text = str(text).strip()
    if text.lower() in ("", "none", "calm"):
        return Environment()
    parts = []
    for piece in filter(None, re.split(r"[,;\s]+(?=[A-Za-z_]+\s*:)", text)):
        try:
            parts.append(_part(piece))
        except InputError as e:
            raise InputError(f"wind spec {piece!r}: {e}") from None
    return Environment.from_parts(*parts)
