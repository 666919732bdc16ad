"""The command line's entry point (``quadcruise``, ``python -m quadcruise``) run in this
process, as a process would run it: the same function (:func:`quadcruise.cli.main.run`), its
exit status, standard output and standard error apart, in a folder of the test's choosing.

A process costs a second of interpreter start and imports; a test that asks only what the
entry point answers (its status, its one line, what it wrote) gets the same answer here in
milliseconds. What the entry point changes in the process (``sys.argv``, ``sys.stdout``,
the SIGTERM handler, the working folder, ``gc.freeze``) is put back afterwards. Warnings are
printed to standard error under a fresh interpreter's filters, as in a process of its own,
rather than collected by pytest: a stray warning is a second line of stderr here too. What
needs a process of its own (signals, a full disk, a closed pipe, numba's cold cache) is
tested with one.
"""

from __future__ import annotations

import contextlib
import gc
import io
import os
import signal
import subprocess
import sys
import traceback
import warnings
from pathlib import Path


def _fresh_filters() -> None:
    """The warning filters of ``python -m`` without -W options (CPython's defaults)."""
    warnings.resetwarnings()
    warnings.filterwarnings("ignore", category=ResourceWarning)
    warnings.filterwarnings("ignore", category=ImportWarning)
    warnings.filterwarnings("ignore", category=PendingDeprecationWarning)
    warnings.filterwarnings("ignore", category=DeprecationWarning)
    warnings.filterwarnings("default", category=DeprecationWarning, module="__main__")


def _print_warning(message, category, filename, lineno, file=None, line=None) -> None:
    sys.stderr.write(warnings.formatwarning(message, category, filename, lineno, line))


def run_entry(*args, cwd: str | os.PathLike | None = None) -> subprocess.CompletedProcess:
    """``quadcruise ARGS`` run in this process in folder ``cwd``.

    Returns
    -------
    subprocess.CompletedProcess
        ``returncode`` (the status it exits with), ``stdout`` and ``stderr`` (text), as
        ``subprocess.run(..., capture_output=True, text=True)`` gives them.
    """
    from quadcruise.cli.main import run

    argv = ["quadcruise", *map(str, args)]
    out, err = io.StringIO(), io.StringIO()
    saved = sys.argv, sys.stdout, sys.stderr, signal.getsignal(signal.SIGTERM), os.getcwd()
    code = 0
    try:
        if cwd is not None:
            os.chdir(Path(cwd))
        sys.argv, sys.stdout, sys.stderr = argv, out, err
        with warnings.catch_warnings():
            _fresh_filters()
            warnings.showwarning = _print_warning
            try:
                run()
            except SystemExit as stop:  # as the interpreter ends a process with it
                if stop.code is None or isinstance(stop.code, int):
                    code = stop.code or 0
                else:
                    err.write(f"{stop.code}\n")
                    code = 1
            except Exception:  # uncaught: a traceback and status 1, as from a process
                err.write(traceback.format_exc())
                code = 1
    finally:
        gc.unfreeze()
        sys.argv, sys.stdout, sys.stderr = saved[:3]
        signal.signal(signal.SIGTERM, saved[3])
        os.chdir(saved[4])
    with contextlib.suppress(ValueError):
        out.flush()
    return subprocess.CompletedProcess(argv, code, out.getvalue(), err.getvalue())
