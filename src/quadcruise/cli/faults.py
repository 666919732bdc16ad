"""Faults of the machine on the command line, answered like bad input: one line on stderr and
an exit status of their own.

- A file or folder that cannot be written (a full disk, a folder removed or made read-only
  meanwhile): the library raises :class:`~quadcruise.errors.WriteError` (an ``OSError``)
  naming the path asked for; any other ``OSError`` that reaches a command is said the same
  way. Exit status :data:`EXIT_FAULT`.
- Standard output that cannot be written (``> /dev/full``, a disk that fills): the same, for
  ``standard output``. A reader that stops reading (``quadcruise fly circle | head -1``) is
  not a fault: the rest of the output is dropped quietly and the command finishes its work
  (its ``--out`` folder is written) with its own status, as a Unix filter's reader expects.
- Ctrl-C: :data:`EXIT_INTERRUPTED`; SIGTERM is made to stop the command the same way
  (:class:`Terminated`), so that a sweep's Dask workers are ended and no temporary file is
  left, with :data:`EXIT_TERMINATED`.

Exit status 74 is ``EX_IOERR`` of BSD's sysexits.h: distinct from 1 (a flight that did not
finish, a tune that missed its targets) and 2 (bad input), so that a script can tell a full
disk from a controller that failed.
"""

from __future__ import annotations

import errno
import os
import signal
import sys

from quadcruise.errors import WriteError

__all__ = [
    "EXIT_FAULT",
    "EXIT_INTERRUPTED",
    "EXIT_TERMINATED",
    "GuardedStdout",
    "Terminated",
    "fault_text",
    "guard_stdout",
    "interrupt_text",
    "stop_on_sigterm",
]

EXIT_FAULT = 74
"""Exit status when the machine failed the command: a file it could not write."""
EXIT_INTERRUPTED = 130
"""Exit status after Ctrl-C (128 + SIGINT, as a shell reports it)."""
EXIT_TERMINATED = 143
"""Exit status after SIGTERM (128 + SIGTERM)."""

_RESUMES = "a montecarlo sweep with --out resumes if run again"


class Terminated(KeyboardInterrupt):
    """SIGTERM, raised in the main thread as Ctrl-C is, so that the same clean-up runs."""


def _raise_terminated(signum, frame) -> None:
    raise Terminated


def stop_on_sigterm() -> None:
    """Make SIGTERM raise :class:`Terminated` in the main thread (call it from there)."""
    signal.signal(signal.SIGTERM, _raise_terminated)


def interrupt_text(exc: KeyboardInterrupt, command: str | None = "montecarlo") -> tuple[str, int]:
    """The line and the exit status for Ctrl-C or SIGTERM; the sweep's way on only for a sweep
    (``command``: the command interrupted; None: not known).

    Examples
    --------
    >>> interrupt_text(Terminated())
    ('terminated (a montecarlo sweep with --out resumes if run again)', 143)
    >>> interrupt_text(KeyboardInterrupt(), "identify")
    ('interrupted', 130)
    """
    hint = f" ({_RESUMES})" if command in ("montecarlo", None) else ""
    if isinstance(exc, Terminated):
        return f"terminated{hint}", EXIT_TERMINATED
    return f"interrupted{hint}", EXIT_INTERRUPTED


def fault_text(exc: OSError) -> str:
    """One line for an ``OSError`` that reached a command: the path, then the cause.

    Examples
    --------
    >>> fault_text(OSError(errno.EACCES, "Permission denied", "out/x.csv"))
    'out/x.csv: permission denied'
    """
    if isinstance(exc, WriteError) or not exc.strerror:
        return " ".join(str(exc).split()) or type(exc).__name__
    cause = exc.strerror[:1].lower() + exc.strerror[1:]
    return f"{exc.filename}: {cause}" if exc.filename else cause


def _stdout_to_devnull() -> None:
    """Point file descriptor 1 at /dev/null: what is still buffered for it, flushed at exit,
    then fails no more (Python would report it as an ignored exception)."""
    try:
        fd = os.open(os.devnull, os.O_WRONLY)
        os.dup2(fd, sys.__stdout__.fileno())
        os.close(fd)
    except (OSError, AttributeError, ValueError):
        pass


class GuardedStdout:
    """Standard output whose write failures are one :class:`~quadcruise.errors.WriteError`,
    and whose reader stopping (a broken pipe) drops the rest quietly."""

    def __init__(self, stream) -> None:
        self._stream = stream
        self.reader_gone = False
        self.fault: WriteError | None = None

    def __getattr__(self, name: str):
        return getattr(self._stream, name)

    def _failed(self, exc: OSError) -> None:
        _stdout_to_devnull()
        if exc.errno == errno.EPIPE:
            self.reader_gone = True
            return
        self.fault = WriteError("standard output", exc)  # said again by every later write
        raise self.fault from None

    def write(self, text: str) -> int:
        """Write ``text``, or drop it once the reader is gone."""
        if not isinstance(text, str):
            return self._stream.write(text)  # a TypeError, as from the stream itself
        if self.fault is not None:
            raise self.fault
        if text and not self.reader_gone:
            try:
                return self._stream.write(text)
            except OSError as exc:
                self._failed(exc)
        return len(text)

    def flush(self) -> None:
        """Flush, unless the reader is gone or a write failed (it said so)."""
        if self.fault is None and not self.reader_gone:
            try:
                self._stream.flush()
            except OSError as exc:
                self._failed(exc)


def guard_stdout() -> None:
    """Replace ``sys.stdout`` by a :class:`GuardedStdout` of it (once)."""
    if sys.stdout is not None and not isinstance(sys.stdout, GuardedStdout):
        sys.stdout = GuardedStdout(sys.stdout)
