"""Never write a folder over the files a run reads: every output folder is replaced whole
(:func:`quadcruise.io.files.atomic_dir`), so one holding an input would delete it."""

from __future__ import annotations

import os
from pathlib import Path

__all__ = ["check_keeps_inputs", "holds"]


def check_keeps_inputs(folder: str | os.PathLike, inputs=()) -> None:
    """Refuse a folder to be written that is, or holds, a file the run read: writing a folder
    replaces it whole (:func:`atomic_dir`), so the input would be deleted, ``force`` or not.

    Parameters
    ----------
    folder : str or os.PathLike
        The output folder.
    inputs : iterable of str or os.PathLike or None
        The files read (a log, a scenario, a vehicle file); None and paths that do not exist are
        skipped (nothing there to lose).

    Raises
    ------
    InputError
        Naming the folder and the input, in one line.

    Examples
    --------
    >>> import tempfile
    >>> with tempfile.TemporaryDirectory() as d:
    ...     _ = (Path(d) / "flight.ulg").write_bytes(b"x")
    ...     try:
    ...         check_keeps_inputs(d, [Path(d) / "flight.ulg"])
    ...     except Exception as exc:
    ...         print(type(exc).__name__, "would delete it" in str(exc))
    InputError True
    """
    from quadcruise.errors import InputError

    target = Path(folder)
    for given in inputs:
        if given is None or not str(given).strip():
            continue
        if Path(given).exists() and holds(target, given):
            raise InputError(
                f"{folder}: holds {given}, which this run reads; writing the folder would delete it: "
                "choose another folder"
            )


def holds(folder: str | os.PathLike, path: str | os.PathLike) -> bool:
    """Whether ``folder`` is ``path`` or holds it (at any depth), after links and ``..``.

    Examples
    --------
    >>> holds("runs/a", "runs/a/flight.ulg"), holds("runs/a", "runs/ab/flight.ulg"), holds("runs/a", "runs/a")
    (True, False, True)
    """
    folder, path = Path(folder).resolve(), Path(path).resolve()
    return path == folder or folder in path.parents
