"""Files written whole or not at all."""

from __future__ import annotations

import contextlib
import os
import shutil
import tempfile
from pathlib import Path


def _umask() -> int:
    mask = os.umask(0)
    os.umask(mask)
    return mask


@contextlib.contextmanager
def atomic_path(path: str | os.PathLike):
    """Yield a temporary path beside ``path``; move it into place only on success.

    A failure (or an interrupt) leaves no file at ``path`` and no temporary behind.
    """
    path = Path(path)
    path.parent.mkdir(parents=True, exist_ok=True)
    fd, tmp = tempfile.mkstemp(prefix=f".{path.name}.", suffix=".tmp", dir=path.parent)
    os.close(fd)
    os.chmod(tmp, 0o666 & ~_umask())     # mkstemp makes 0600; a result file is an ordinary file
    try:
        yield Path(tmp)
        os.replace(tmp, path)
    except BaseException:
        with contextlib.suppress(FileNotFoundError):
            os.unlink(tmp)
        raise


@contextlib.contextmanager
def atomic_dir(path: str | os.PathLike):
    """Yield a temporary folder beside ``path``; it becomes ``path`` only on success.

    An existing ``path`` is replaced only after the new one is complete.
    """
    path = Path(path)
    path.parent.mkdir(parents=True, exist_ok=True)
    tmp = Path(tempfile.mkdtemp(prefix=f".{path.name}.", suffix=".tmp", dir=path.parent))
    os.chmod(tmp, 0o777 & ~_umask())
    try:
        yield tmp
        if path.exists():
            old = path.with_name(f".{path.name}.old")
            shutil.rmtree(old, ignore_errors=True)
            os.replace(path, old)
            os.replace(tmp, path)
            shutil.rmtree(old, ignore_errors=True)
        else:
            os.replace(tmp, path)
    except BaseException:
        shutil.rmtree(tmp, ignore_errors=True)
        raise


MARKER = "quadcruise.json"
"""Every output folder quadcruise writes holds this file (the config, seed and version)."""


def check_output_dir(path: str | os.PathLike, force: bool = False) -> Path:
    """Refuse a non-empty folder that quadcruise did not write, unless ``force``."""
    from .errors import InputError

    path = Path(path)
    if path.exists() and not path.is_dir():
        raise InputError(f"{path}: exists and is not a folder")
    if path.is_dir() and any(path.iterdir()) and not (path / MARKER).is_file() and not force:
        raise InputError(f"{path}: folder is not empty and was not written by quadcruise "
                         "(use --force to replace it)")
    return path


def write_table(frame, path: Path, fmt: str) -> Path:
    """Write a numeric DataFrame as CSV or Parquet; returns the file written."""
    from .errors import InputError

    if fmt == "csv":
        import numpy as np

        out = path.with_suffix(".csv")
        # numpy formats numeric tables about twice as fast as pandas' to_csv
        np.savetxt(out, frame.to_numpy(dtype=float), delimiter=",", fmt="%.10g",
                   header=",".join(map(str, frame.columns)), comments="")
    elif fmt == "parquet":
        try:
            import pyarrow  # noqa: F401
        except ImportError:
            raise InputError("writing Parquet needs pyarrow: pip install 'quadcruise[parquet]'") from None
        out = path.with_suffix(".parquet")
        frame.to_parquet(out, index=False)
    else:
        raise InputError(f"unknown table format {fmt!r}; choose csv or parquet")
    return out
