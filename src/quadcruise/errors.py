"""The exception types the command line turns into one line: bad input (:class:`InputError`), a
file the machine could not write (:class:`WriteError`)."""

from __future__ import annotations

import numbers


class InputError(ValueError):
    """Bad input from a user: a parameter, option or file that cannot be used.

    The message is one line and names what is wrong and where (file, row, field).
    The command line prints it as ``error: <message>`` and exits with status 2.
    """


class WriteError(OSError):
    """A file or folder that could not be written: a fault of the machine (a full disk, a
    folder removed or made read-only meanwhile), not of the input.

    It is an ``OSError`` (``errno``, ``strerror`` and ``filename`` are the cause's, the
    filename being the path asked for, not a temporary one) whose message is one line:
    ``<path>: cannot write (<cause>)``, then what was kept. The command line prints it as
    ``error: <message>`` and exits with status 74 (``EX_IOERR`` of BSD's sysexits.h).

    Parameters
    ----------
    path : str or os.PathLike
        The file or folder that was being written.
    cause : OSError
        What the system said.
    kept : str, optional
        What was kept and how to go on, e.g. ``"the sweep resumes ..."``.

    Examples
    --------
    >>> import errno
    >>> print(WriteError("out/flights.csv", OSError(errno.ENOSPC, "No space left on device")))
    out/flights.csv: cannot write (no space left on device)
    """

    def __init__(self, path, cause: OSError, kept: str = "") -> None:
        text = cause.strerror or str(cause) or type(cause).__name__
        super().__init__(cause.errno, text, str(path))
        self.kept = kept

    def __str__(self) -> str:
        cause = self.strerror[:1].lower() + self.strerror[1:]
        return f"{self.filename}: cannot write ({cause})" + (f"; {self.kept}" if self.kept else "")


class ArgumentTypeError(InputError, TypeError):
    """Bad input of the wrong kind: a Python argument of another type than the one expected
    (a string for a number, a class for an object, a float for a seed).

    An :class:`InputError` (so the command line prints it in one line and exits 2) that is
    also a :class:`TypeError`, as a Python caller expects of a wrong type.
    """


class SimulationError(RuntimeError):
    """A simulation could not be carried out as asked (not bad input, not divergence)."""


class LogWarning(UserWarning):
    """A flight's log kept less than every period because the whole would not fit (``fly``
    with ``log_every`` left to it); the flight and its checks are the same."""


class ParameterWarning(UserWarning):
    """What a PX4 parameter file read by ``Px4.from_params`` holds that a caller should know
    once: parameters the loops do not use, values PX4 constrains, another release's names."""


class FlightWarning(UserWarning):
    """How a flight went, when it went wrong: a vehicle that did not finish, rotor duties
    clipped. Workflows that fly several (compare, reproduce) say whose flight it was."""


def _plain(value):
    """A numpy scalar as the Python number it holds, so that a message shows ``inf``, not
    ``np.float64(inf)`` (numpy 2's repr); anything else as it is."""
    item = getattr(value, "item", None)
    return item() if callable(item) and getattr(value, "shape", None) == () else value


def whole_number(value, what: str, minimum: int = 0) -> int:
    """``value`` as an int if it is a whole number >= ``minimum`` (not a bool, not a float).

    Parameters
    ----------
    value : Any
        The value to check.
    what : str
        How the error names it, e.g. ``"n"``.
    minimum : int
        The smallest value accepted.

    Returns
    -------
    int
        ``value``.

    Raises
    ------
    ArgumentTypeError
        "<what> must be a whole number >= <minimum>, got <value>", for a value that is not a
        whole number (a float, a bool, a string).
    InputError
        The same message, for a whole number below ``minimum``.

    Examples
    --------
    >>> whole_number(3, "n", 1)
    3
    >>> whole_number(2.0, "n", 1)
    Traceback (most recent call last):
        ...
    quadcruise.errors.ArgumentTypeError: n must be a whole number >= 1, got 2.0
    """
    wrong_type = isinstance(value, bool) or not isinstance(value, numbers.Integral)
    if wrong_type or value < minimum:
        raise (ArgumentTypeError if wrong_type else InputError)(
            f"{what} must be a whole number >= {minimum}, got {_plain(value)!r}"
        )
    return int(value)


def reject_unknown(where: str, given: dict, known) -> None:
    """InputError naming the first keyword of ``given`` (a ``**kwargs`` dict) and the choices.

    Parameters
    ----------
    where : str
        The function or table, e.g. ``"fly()"``.
    given : dict
        The keywords that no parameter took.
    known : iterable of str
        The keywords that are accepted.

    Raises
    ------
    InputError
        If ``given`` is not empty.

    Examples
    --------
    >>> reject_unknown("fly()", {"sede": 1}, ["seed", "dt"])
    Traceback (most recent call last):
        ...
    quadcruise.errors.InputError: fly() has no option 'sede' (did you mean 'seed'?); options: dt, seed
    """
    if not given:
        return
    import difflib

    name = sorted(given)[0]
    close = difflib.get_close_matches(name, list(known), n=1)
    hint = f" (did you mean '{close[0]}'?)" if close else ""
    raise InputError(f"{where} has no option '{name}'{hint}; options: {', '.join(sorted(known))}")
