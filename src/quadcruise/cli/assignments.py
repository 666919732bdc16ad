"""``KEY=VALUE`` options and comma-separated numbers, as the command line writes them
(``--mission-param radius=3,center=1,2``, ``--noise position=0.01``, ``--wind 2,0,0``): the one
reader of such text, which only the command line parses.

Examples
--------
>>> parse_assignments(["radius=3", "center=1,2", "axis=x"], "--mission-param")
{'radius': 3, 'center': (1, 2), 'axis': 'x'}
"""

from __future__ import annotations

import difflib
import re
from collections.abc import Iterable, Mapping
from typing import Any

from quadcruise.errors import InputError
from quadcruise.fields.checks import is_number

__all__ = ["parse_assignments", "parse_numbers"]

_INT = re.compile(r"[+-]?\d+")


def parse_numbers(text: str, what: str, count: int | None = None) -> list[float]:
    """Comma-separated numbers, e.g. ``"2,0,0"``.

    Parameters
    ----------
    text : str
        The numbers.
    what : str
        What they are, for messages (``"AX,AY,AZ"``).
    count : int, optional
        How many there must be.

    Returns
    -------
    list of float

    Examples
    --------
    >>> parse_numbers("2, 0,0", "AX,AY,AZ", 3)
    [2.0, 0.0, 0.0]
    >>> parse_numbers("2,0", "AX,AY,AZ", 3)
    Traceback (most recent call last):
        ...
    quadcruise.errors.InputError: needs 3 values AX,AY,AZ, got '2,0'
    """
    pieces = str(text).split(",")
    if count is not None and len(pieces) != count:
        raise InputError(f"needs {count} value{'s' * (count > 1)} {what}, got {text!r}")
    try:
        return [float(p) for p in pieces]
    except ValueError:
        raise InputError(f"{what} must be numbers, got {text!r}") from None


def _value(raw: str) -> Any:
    """A number (int if written as one), true/false, or the word itself."""
    word = raw.strip()
    if _INT.fullmatch(word):
        return int(word)
    if word.lower() in ("true", "false"):
        return word.lower() == "true"
    try:
        return float(word)
    except ValueError:
        return word


def parse_assignments(
    items: str | Iterable[str], what: str, keys: Iterable[str] | Mapping[str, str] | None = None, numbers: bool = False
) -> dict[str, Any]:
    """``KEY=VALUE`` options as a dict: the one parser of the command line's options.

    Items are separated by commas, or given as several strings; a comma-separated piece
    without ``=`` continues the value before it, so ``center=1,2`` is a pair. A value is an
    int (written as one), a float, true/false, a tuple of numbers (``1,2``) or else the
    text itself. Later items win.

    Parameters
    ----------
    items : str or iterable of str
        ``"position=0.01,delay=0.002"`` or ``("radius=3", "center=1,2")``.
    what : str
        The option, for messages (``"--mission-param"``, ``"noise spec"``).
    keys : iterable of str or mapping, optional
        The allowed keys (matched ignoring case); a mapping also renames them
        (``{"position": "position_std"}``). None: any key.
    numbers : bool
        Every value must be a number or numbers.

    Returns
    -------
    dict

    Raises
    ------
    InputError
        One line naming the option and the bad item: no ``=``, no key or value, an unknown
        key, or (with ``numbers``) a value that is not a number.

    Examples
    --------
    >>> parse_assignments("position=0.01,delay=2e-3", "noise spec", keys={"position": "position_std",
    ...                   "delay": "delay"}, numbers=True)
    {'position_std': 0.01, 'delay': 0.002}
    >>> parse_assignments(["accel_feedforward=true", "max_tilt=0.5"], "-c")
    {'accel_feedforward': True, 'max_tilt': 0.5}
    >>> parse_assignments("jitter=1", "noise spec", keys=["position", "delay"])
    Traceback (most recent call last):
        ...
    quadcruise.errors.InputError: noise spec 'jitter=1': unknown key 'jitter'; keys: position, delay
    """
    texts = [items] if isinstance(items, str) else list(items)
    rename = None if keys is None else (dict(keys) if isinstance(keys, Mapping) else {k: k for k in keys})
    lower = None if rename is None else {k.lower(): v for k, v in rename.items()}
    pairs: list[list] = []  # [key, [raw pieces], item as written]
    for text in texts:
        current = None  # the pair a piece without "=" continues
        for piece in str(text).split(","):
            key, sep, raw = piece.partition("=")
            if sep:
                current = [key.strip(), [raw], piece.strip()]
                pairs.append(current)
            elif current is not None:
                current[1].append(piece)
                current[2] += "," + piece.strip()
            else:
                raise InputError(f"{what} {piece.strip()!r}: expected KEY=VALUE")
    out: dict[str, Any] = {}
    for key, raws, item in pairs:
        if not key or not all(r.strip() for r in raws):
            raise InputError(f"{what} {item!r}: expected KEY=VALUE")
        if lower is not None:
            if key.lower() not in lower:
                close = difflib.get_close_matches(key.lower(), list(lower), n=1)
                hint = f" (did you mean '{close[0]}'?)" if close else ""
                raise InputError(f"{what} {item!r}: unknown key {key!r}{hint}; keys: {', '.join(rename)}")
            key = lower[key.lower()]
        if key in out:
            raise InputError(f"{what} {item!r}: {key!r} is given twice; give each key once")
        values = [_value(r) for r in raws]
        numeric = all(is_number(v) for v in values)
        if numbers and not numeric:
            raise InputError(f"{what} {item!r}: the value must be a number, got {','.join(r.strip() for r in raws)!r}")
        if len(values) == 1:
            out[key] = values[0]
        else:
            out[key] = tuple(values) if numeric else ",".join(r.strip() for r in raws)
    return out
