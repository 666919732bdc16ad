"""The scenario reader's building blocks: messages prefixed with the file and table, unknown keys
named with the nearest known one, numbers checked by kind. Private to the readers of
:mod:`quadcruise.workflows.scenario` and its tables' modules."""

from __future__ import annotations

import math

from quadcruise.errors import InputError


class Where:
    """Prefixes messages with the file and table: ``file: [table] ...``."""

    def __init__(self, source: str, table: str = "") -> None:
        self.source, self.table = source, table

    def at(self, table: str) -> Where:
        """The same file, at ``[table]``."""
        return Where(self.source, table)

    def error(self, message: str) -> InputError:
        """An InputError with the file and table in front of ``message``."""
        return InputError(f"{self.source}: [{self.table}] {message}" if self.table else f"{self.source}: {message}")

    def wrap(self, func, *args, **kwargs):
        """Call func; re-raise its InputError (or TypeError) with the file and table in front."""
        try:
            return func(*args, **kwargs)
        except (InputError, TypeError) as exc:
            raise self.error(str(exc)) from None


def check_keys(where: Where, prefix: str, table: dict, known: set) -> None:
    """Refuse a key of ``table`` not in ``known``, naming the nearest known one."""
    import difflib

    for key in table:
        if key not in known:
            close = difflib.get_close_matches(str(key), sorted(known), n=1)
            hint = f" (did you mean '{prefix}{close[0]}'?)" if close else ""
            raise where.error(f"unknown key '{prefix}{key}'{hint} (known: {', '.join(sorted(known))})")


def read_number(where: Where, key: str, value, kind=float):
    """``value`` as a finite number of ``kind`` (float, int or bool), or an error naming ``key``."""
    if kind is bool:
        if not isinstance(value, bool):
            raise where.error(f"'{key}' must be true or false, got {value!r}")
        return value
    if isinstance(value, bool) or not isinstance(value, (int, float)) or (kind is int and not isinstance(value, int)):
        raise where.error(f"'{key}' must be {'an integer' if kind is int else 'a number'}, got {value!r}")
    if not math.isfinite(value):
        raise where.error(f"'{key}' must be finite, got {value!r}")
    return kind(value)


def read_numbers(where: Where, key: str, value: list):
    """A list of numbers (one per vehicle, or a row of a table) as a float array."""
    import numpy as np

    if not isinstance(value, list) or not value:
        raise where.error(f"'{key}' must be a list of numbers, got {value!r}")
    rows = [read_numbers(where, key, v) if isinstance(v, list) else read_number(where, key, v) for v in value]
    if len({np.shape(r) for r in rows}) > 1:
        raise where.error(f"'{key}' must be a list of numbers or of equal lists of numbers (one per vehicle)")
    return np.array(rows)
