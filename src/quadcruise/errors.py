"""The one exception type for bad input, so the CLI can turn it into a one-line message."""

from __future__ import annotations

import numbers


class InputError(ValueError):
    """Bad input from a user: a parameter, option or file that cannot be used.

    The message is one line and names what is wrong and where (file, row, field).
    The command line prints it as ``error: <message>`` and exits with status 2.
    """


class SimulationError(RuntimeError):
    """A simulation could not be carried out as asked (not bad input, not divergence)."""


def whole_number(value, what: str, minimum: int = 0) -> int:
    """``value`` as an int if it is a whole number >= ``minimum`` (not a bool, not a float);
    else InputError "<what> must be a whole number >= <minimum>, got <value>"."""
    if isinstance(value, bool) or not isinstance(value, numbers.Integral) or value < minimum:
        raise InputError(f"{what} must be a whole number >= {minimum}, got {value!r}")
    return int(value)
