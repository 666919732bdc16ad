"""The one exception type for bad input, so the CLI can turn it into a one-line message."""

from __future__ import annotations


class InputError(ValueError):
    """Bad input from a user: a parameter, option or file that cannot be used.

    The message is one line and names what is wrong and where (file, row, field).
    The command line prints it as ``error: <message>`` and exits with status 2.
    """


class SimulationError(RuntimeError):
    """A simulation could not be carried out as asked (not bad input, not divergence)."""
