"""``compare --ulog``: each compared flight as its own PX4 log, ``PATH-LABEL.ulg``."""

from __future__ import annotations

import re
from pathlib import Path

__all__ = ["comparison_ulog_paths", "write_comparison_ulogs"]


def _labelled(path, label) -> Path:
    """``PATH.ulg`` as ``PATH-LABEL.ulg``, the label's odd characters made ``_``."""
    path = Path(path)
    return path.with_name(f"{path.stem}-{re.sub(r'[^A-Za-z0-9._-]', '_', str(label))}{path.suffix}")


def comparison_ulog_paths(cmp, path) -> list[Path]:
    """The files :func:`write_comparison_ulogs` writes, in its order (said before writing them).

    Parameters
    ----------
    cmp : Comparison
        The flights.
    path : str or os.PathLike
        The path given (``.ulg``).

    Returns
    -------
    list of pathlib.Path
    """
    from quadcruise.cli.fly_run import ulog_paths

    return [p for label, result in cmp.results.items() for p in ulog_paths(_labelled(path, label), result.n)]


def write_comparison_ulogs(cmp, path) -> list[Path]:
    """Write each controller's flight as a PX4 log, all or none.

    ``PATH.ulg`` becomes ``PATH-LABEL.ulg`` for each controller's label (characters other than
    letters, digits, ``.``, ``_`` and ``-`` made ``_``); a flight of several vehicles is one file
    per vehicle after that (:func:`~quadcruise.cli.fly_run.ulog_paths`).

    Parameters
    ----------
    cmp : Comparison
        The flights.
    path : str or os.PathLike
        The path given (``.ulg``).

    Returns
    -------
    list of pathlib.Path
        The files written.

    Raises
    ------
    WriteError
        A file that could not be written (named); none of the files is left.
    """
    from quadcruise.cli.fly_run import write_ulogs

    written = []
    try:
        for label, result in cmp.results.items():
            written += write_ulogs(result, _labelled(path, label))
    except BaseException:
        for done in written:
            done.unlink(missing_ok=True)
        raise
    return written
