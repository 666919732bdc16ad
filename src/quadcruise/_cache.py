"""Fingerprints of the package's sources: numba's on-disk cache kept in step with them,
and the code a Monte Carlo sweep was flown with (:func:`code_digest`).

numba keys each cached function on the file that defines it, not on the files of the
functions it calls and inlines: the engine's kernel inlines the plant's derivative, so an
edit to ``model/plant.py`` alone would leave a stale kernel in the cache (a checkout of
another commit, an edited source tree). When the first of the package's modules that may hold
compiled code is imported (any but ``errors``, ``_version``, this one and the command line: see
:func:`check_before_compiled_code`), before anything compiles, we stamp the package's compiled
sources (the contents of every ``.py`` file that uses numba) and, when the stamp differs from the
one stored beside the cache, remove the package's cached machine code (in the ``__pycache__``
folders, or under ``NUMBA_CACHE_DIR`` when it is set), which numba then compiles afresh. So
``import quadcruise`` alone imports no numba and deletes nothing. A read-only install is left
alone (numba caches such a package elsewhere, and an upgrade replaces every file there anyway).
"""

from __future__ import annotations

import contextlib
import functools
import hashlib
import importlib.abc
import os
import sys
import threading
from pathlib import Path

PACKAGE = Path(os.path.abspath(__file__)).parent  # as numba names the source files
STAMP = "quadcruise-sources.stamp"
WITHOUT_COMPILED_CODE = (
    "quadcruise.errors",
    "quadcruise._version",
    "quadcruise._cache",
    "quadcruise.__main__",
    "quadcruise.cli",
)
"""The package's modules (and packages) whose import leaves the stamp check for later: they hold
and load no compiled code of their own."""


def _digest(package: Path, compiled_only: bool) -> str:
    h = hashlib.sha256()
    for path in sorted(package.rglob("*.py")):
        text = path.read_bytes()
        if not compiled_only or b"numba" in text:
            h.update(path.relative_to(package).as_posix().encode() + b"\0" + text + b"\0")
    return h.hexdigest()


def sources_stamp(package: Path = PACKAGE) -> str:
    """A hash of the contents of every source file of the package that uses numba.

    Parameters
    ----------
    package : pathlib.Path
        The package's folder.

    Returns
    -------
    str
        The SHA-256 hex digest of the relative paths and contents of the ``.py`` files
        that mention ``numba``.
    """
    return _digest(package, True)


@functools.cache
def code_digest() -> str:
    """A hash of the contents of every source file of the package, as this process found
    them when first asked.

    A Monte Carlo spec's hash includes it, so a sweep resumes, or takes a worker's chunk,
    only from the same code (a version number alone does not change when a source tree is
    edited).

    Returns
    -------
    str
        The SHA-256 hex digest of the relative paths and contents of every ``.py`` file.
    """
    return _digest(PACKAGE, False)


def cache_dirs(package: Path = PACKAGE, numba_cache_dir: str | None = None) -> list[Path]:
    """Where numba keeps the package's compiled code.

    Parameters
    ----------
    package : pathlib.Path
        The package's folder.
    numba_cache_dir : str, optional
        numba's ``NUMBA_CACHE_DIR``; default: numba's configuration (the environment).

    Returns
    -------
    list of pathlib.Path
        One folder per source folder: its ``__pycache__``, or, when ``numba_cache_dir`` is
        set (not empty), its folder there (``<name>_<sha1 of the path>``, as numba's
        ``UserProvidedCacheLocator`` names it). The folders need not exist.
    """
    folders = sorted({path.parent for path in package.rglob("*.py")})
    if numba_cache_dir is None:
        from numba.core import config

        numba_cache_dir = config.CACHE_DIR
    if numba_cache_dir:
        return [Path(numba_cache_dir) / f"{d.name}_{hashlib.sha1(str(d).encode()).hexdigest()}" for d in folders]
    return [d / "__pycache__" for d in folders]


def drop_stale_cache(package: Path = PACKAGE, numba_cache_dir: str | None = None) -> bool:
    """Remove the package's numba cache files if the sources changed since the last stamp.

    The stamp is kept beside the cache files, in the first of :func:`cache_dirs`. Errors
    (a read-only tree, a file another process removed) are ignored.

    Parameters
    ----------
    package : pathlib.Path
        The package's folder.
    numba_cache_dir : str, optional
        numba's ``NUMBA_CACHE_DIR`` (see :func:`cache_dirs`).

    Returns
    -------
    bool
        True if it removed the cache (and wrote a new stamp); False if the stamp was
        current or the cache could not be written.
    """
    dirs = cache_dirs(package, numba_cache_dir)
    stamp_file = dirs[0] / STAMP
    stamp = sources_stamp(package)
    with contextlib.suppress(OSError):
        if stamp_file.read_text() == stamp:
            return False
    try:
        for folder in dirs:
            for pattern in ("*.nbi", "*.nbc"):
                for path in folder.glob(pattern):
                    with contextlib.suppress(FileNotFoundError):
                        path.unlink()
        stamp_file.parent.mkdir(parents=True, exist_ok=True)
        tmp = stamp_file.with_name(f"{stamp_file.name}.{os.getpid()}.tmp")
        tmp.write_text(stamp)
        tmp.replace(stamp_file)
    except OSError:
        return False
    return True


_lock = threading.Lock()
_checked = False


def check_stamp_once() -> None:
    """:func:`drop_stale_cache` for this package, once per process (later calls return at once)."""
    global _checked
    with _lock:
        if _checked:
            return
        _checked = True
        _remove_finder()
        drop_stale_cache()


class _BeforeCompiledCode(importlib.abc.MetaPathFinder):
    """Runs :func:`check_stamp_once` when a module of the package outside
    :data:`WITHOUT_COMPILED_CODE` is first imported; it finds no module itself."""

    def find_spec(self, fullname, path, target=None):
        if fullname.startswith("quadcruise.") and not any(
            fullname == light or fullname.startswith(light + ".") for light in WITHOUT_COMPILED_CODE
        ):
            check_stamp_once()
        return None  # the import goes on as usual


def _remove_finder() -> None:
    sys.meta_path[:] = [f for f in sys.meta_path if not isinstance(f, _BeforeCompiledCode)]


def check_before_compiled_code() -> None:
    """Make the first import of a module of the package that may hold compiled code (any outside
    :data:`WITHOUT_COMPILED_CODE`) run :func:`check_stamp_once` first: ``import quadcruise``
    calls it, and deletes nothing itself.

    Examples
    --------
    >>> import subprocess, sys
    >>> code = "import sys, quadcruise; print('numba' in sys.modules)"
    >>> subprocess.run([sys.executable, "-c", code], capture_output=True, text=True).stdout.strip()
    'False'
    """
    if not _checked and not any(isinstance(f, _BeforeCompiledCode) for f in sys.meta_path):
        sys.meta_path.insert(0, _BeforeCompiledCode())
