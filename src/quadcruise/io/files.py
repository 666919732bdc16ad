"""Files written whole or not at all."""

from __future__ import annotations

import contextlib
import os
import secrets
import shutil
import signal
import threading
from pathlib import Path

from quadcruise.errors import WriteError


def _temporary_names(path: Path):
    """Names for a temporary beside ``path``, ``.NAME.<random>.tmp``, one per try.

    The caller holds each name before it makes the file or folder (with a call that fails if
    it exists), so that an interrupt at any moment leaves it a name to remove: ``mkstemp``'s
    name is known only once the file exists, and Ctrl-C in between left an empty
    ``.NAME.*.tmp`` behind. 64 random bits make a clash with another's temporary negligible.
    """
    while True:
        yield path.with_name(f".{path.name}.{secrets.token_hex(8)}.tmp")


@contextlib.contextmanager
def _interrupts_deferred():
    """Hold Ctrl-C and SIGTERM back for a few system calls that must run together; a signal
    received meanwhile is raised as its handler raises it, once they are done (in the main
    thread only, where Python runs signal handlers; elsewhere nothing changes)."""
    if threading.current_thread() is not threading.main_thread():
        yield
        return
    held: list[int] = []
    kept = {}
    for sig in (signal.SIGINT, signal.SIGTERM):
        kept[sig] = signal.getsignal(sig)
        if callable(kept[sig]):
            signal.signal(sig, lambda signum, frame: held.append(signum))
    try:
        yield
    finally:
        for sig, handler in kept.items():
            if callable(handler):
                signal.signal(sig, handler)
        for signum in held[:1]:
            kept[signum](signum, None)


@contextlib.contextmanager
def atomic_path(path: str | os.PathLike):
    """Yield a temporary path beside ``path``; move it into place only on success.

    A failure (or an interrupt) leaves no file at ``path`` and no temporary behind. An
    ``OSError`` on the way (a full disk, a folder removed meanwhile) is raised as a
    :class:`~quadcruise.errors.WriteError` that names ``path``, not the temporary.

    Parameters
    ----------
    path : str or os.PathLike
        The file to write; its folder is created if missing.

    Yields
    ------
    pathlib.Path
        The temporary file (empty, already created) to write to.

    Raises
    ------
    WriteError
        If ``path`` could not be written.

    Examples
    --------
    >>> import tempfile
    >>> with tempfile.TemporaryDirectory() as folder:
    ...     with atomic_path(Path(folder) / "out.txt") as tmp:
    ...         _ = tmp.write_text("done")
    ...     sorted(p.name for p in Path(folder).iterdir())
    ['out.txt']
    """
    path = Path(path)
    tmp = None
    try:
        path.parent.mkdir(parents=True, exist_ok=True)
        for tmp in _temporary_names(path):  # noqa: B007 (tmp is the name made)
            try:
                os.close(os.open(tmp, os.O_WRONLY | os.O_CREAT | os.O_EXCL, 0o666))  # the umask applies
                break
            except FileExistsError:
                continue
        yield tmp
        os.replace(tmp, path)
    except BaseException as exc:
        if tmp is not None:
            with contextlib.suppress(OSError):
                os.unlink(tmp)
        if isinstance(exc, OSError):
            raise WriteError(path, exc) from None
        raise


def _remove(folder: Path) -> None:
    shutil.rmtree(folder, ignore_errors=True)


@contextlib.contextmanager
def atomic_dir(path: str | os.PathLike):
    """Yield a temporary folder beside ``path``; it becomes ``path`` only on success.

    An existing ``path`` is replaced only after the new one is complete. A failure (or an
    interrupt) leaves ``path`` as it was and removes the temporary folder. An ``OSError`` on
    the way (a full disk, a folder removed meanwhile) is raised as a
    :class:`~quadcruise.errors.WriteError` that names ``path``.

    Parameters
    ----------
    path : str or os.PathLike
        The folder to write; its parent is created if missing.

    Yields
    ------
    pathlib.Path
        The temporary folder (empty) to fill.

    Raises
    ------
    WriteError
        If ``path`` could not be written.
    """
    path = Path(path)
    tmp = None
    try:
        path.parent.mkdir(parents=True, exist_ok=True)
        for tmp in _temporary_names(path):  # noqa: B007 (tmp is the name made)
            try:
                os.mkdir(tmp, 0o777)  # the umask applies
                break
            except FileExistsError:
                continue
        yield tmp
        old, swapped = path.with_name(f".{path.name}.old"), False
        try:
            with _interrupts_deferred():  # Ctrl-C between the two moves would leave no folder at path
                if path.exists():
                    _remove(old)
                    os.replace(path, old)
                    try:
                        os.replace(tmp, path)
                    except BaseException:
                        os.replace(old, path)  # the old folder back where it was
                        raise
                    swapped = True
                else:
                    os.replace(tmp, path)
        finally:
            if swapped:
                _remove(old)
    except BaseException as exc:
        if tmp is not None:
            _remove(tmp)
        if isinstance(exc, OSError):
            raise WriteError(path, exc) from None
        raise


MARKER = "quadcruise.json"
"""Every output folder quadcruise writes holds this file (the config, seed and version)."""


def check_writable_place(path: str | os.PathLike) -> None:
    """Refuse a path that could not be written: its nearest existing folder must be a folder
    this process may write into (the missing ones between are created when writing).

    Parameters
    ----------
    path : str or os.PathLike
        A file or folder to be written.

    Raises
    ------
    InputError
        Naming the path and why (no such folder, not a folder, permission denied).

    Examples
    --------
    >>> check_writable_place("/proc/out")
    Traceback (most recent call last):
        ...
    quadcruise.errors.InputError: /proc/out: cannot write there (no such file or directory in /proc)
    """
    from quadcruise.errors import InputError

    if not str(path).strip():
        raise InputError("an output path is empty: name a file or folder to write")
    path = Path(path)
    if not path.resolve().name or path.name in ("", ".", ".."):
        what = "the root" if not path.resolve().name else "this folder or its parent"
        raise InputError(f"{path}: name a new file or folder to write, not {what}")
    parent = path.parent if str(path.parent) else Path(".")
    while not parent.exists() and parent != parent.parent:
        parent = parent.parent
    if not parent.is_dir():
        raise InputError(f"{path}: cannot write there ({parent} is not a folder)")
    try:  # the only sure test: make something there, and remove it
        probe = parent / f".quadcruise-probe.{secrets.token_hex(8)}"
        try:
            os.mkdir(probe)
        finally:
            with contextlib.suppress(OSError):
                os.rmdir(probe)
    except OSError as exc:
        raise InputError(f"{path}: cannot write there ({exc.strerror.lower()} in {parent})") from None


MARKER_LIMIT = 16 * 2**20
"""The largest :data:`MARKER` read [bytes]: a marker holds a configuration (a few kB, a
sweep's spec with its seeds some MB at most); a larger one is taken as damaged."""


class NotRegularFile(OSError):
    """A path that is not a regular file (a FIFO, a folder, a device), or one larger than asked:
    not to be read. Its message says which."""


def _kind(mode: int) -> str:
    import stat

    return "a FIFO" if stat.S_ISFIFO(mode) else "a folder" if stat.S_ISDIR(mode) else "a device or socket"


def not_a_file(path: str | os.PathLike) -> str:
    """Why ``path`` cannot be read as a file, for a message: no such file, or what it is instead.

    Examples
    --------
    >>> not_a_file("/no/such/file.csv"), not_a_file("/")
    ('no such file', 'a folder, not a regular file')
    """
    try:
        return f"{_kind(os.stat(path).st_mode)}, not a regular file"
    except OSError:
        return "no such file"


def open_regular(path: str | os.PathLike):
    """Open a regular file for reading in binary, without waiting on what is not one.

    The path is opened without blocking and checked on the open descriptor, so that a FIFO
    put where a file was expected (whose ``open`` would wait for a writer forever), a folder
    or a device is refused, not read.

    Parameters
    ----------
    path : str or os.PathLike
        The file.

    Returns
    -------
    io.BufferedReader
        The file, open for reading.

    Raises
    ------
    NotRegularFile
        If ``path`` is not a regular file (an ``OSError``, as a file that cannot be opened).
    """
    import stat

    fd = os.open(path, os.O_RDONLY | os.O_NONBLOCK | getattr(os, "O_NOCTTY", 0))
    try:
        mode = os.fstat(fd).st_mode
        if not stat.S_ISREG(mode):
            raise NotRegularFile(f"{_kind(mode)}, not a regular file")
        return os.fdopen(fd, "rb")
    except BaseException:
        os.close(fd)
        raise


def _small_file(path: Path, limit: int) -> bytes:
    """The bytes of ``path`` if it is a regular file (:func:`open_regular`) of at most ``limit`` bytes."""
    with open_regular(path) as f:
        size = os.fstat(f.fileno()).st_size
        if size > limit:
            raise NotRegularFile(f"{size} bytes, more than a marker's {limit}")
        data = f.read(limit + 1)
    if len(data) > limit:
        raise NotRegularFile(f"more than a marker's {limit} bytes")
    return data


def read_marker(folder: str | os.PathLike) -> dict | None:
    """The :data:`MARKER` of an output folder: what quadcruise wrote there.

    Parameters
    ----------
    folder : str or os.PathLike
        The folder; it need not exist.

    Returns
    -------
    dict or None
        The marker's JSON object, or None if the folder holds no marker.

    Raises
    ------
    InputError
        If the marker cannot be read or is not a JSON object (truncated, filled with NUL
        bytes, a list, nested too deeply), or is not a regular file of at most
        :data:`MARKER_LIMIT` bytes (a FIFO is not opened for reading: it would wait):
        what the folder holds (a Monte Carlo sweep's chunks, perhaps) is then unknown, so
        it is not to be replaced unless forced. The message says how.

    Examples
    --------
    >>> import tempfile
    >>> with tempfile.TemporaryDirectory() as folder:
    ...     _ = (Path(folder) / MARKER).write_text("[1, 2]")
    ...     read_marker(folder)  # doctest: +ELLIPSIS
    Traceback (most recent call last):
        ...
    quadcruise.errors.InputError: .../quadcruise.json: damaged (a JSON array, not an object), so what ... holds ...
    """
    import json

    from quadcruise.errors import InputError

    folder = Path(folder)
    path = folder / MARKER
    if not os.path.lexists(path):
        return None
    text = ""
    try:
        text = _small_file(path, MARKER_LIMIT).decode("utf-8")
        doc = json.loads(text)
        why = None if isinstance(doc, dict) else f"a JSON {type(doc).__name__.replace('list', 'array')}, not an object"
    except NotRegularFile as exc:
        why = str(exc)
    except OSError as exc:
        why = f"cannot be read: {(exc.strerror or str(exc)).lower()}"
    except UnicodeDecodeError:
        why = "not UTF-8 text"
    except RecursionError:
        why = "not JSON: nested too deeply"
    except json.JSONDecodeError as exc:
        why = (
            "empty"
            if not text.strip()
            else "NUL bytes"
            if "\0" in text
            else f"not JSON: {exc.msg.lower()} at line {exc.lineno}, column {exc.colno}"
        )
    if why is None:
        return doc
    raise InputError(
        f"{path}: damaged ({why}), so what {folder} holds (a Monte Carlo sweep's chunks, perhaps) "
        "is unknown: use --force to replace the folder, or delete it"
    )


def check_output_dir(path: str | os.PathLike, force: bool = False, *, workflow: str | None = None, inputs=()) -> Path:
    """Refuse a non-empty folder that quadcruise did not write, unless ``force``.

    Parameters
    ----------
    path : str or os.PathLike
        The output folder; it need not exist.
    force : bool
        Accept a non-empty folder without a :data:`MARKER` file (it will be replaced), one whose
        marker is damaged, or one that holds a Monte Carlo sweep when another workflow writes.
    workflow : str, optional
        What will write there; ``"montecarlo"`` may resume a sweep's folder (its own rules apply), any other
        writer must be forced to replace one; ``"reproduce"`` (a default name) replaces only a reproduction's.
    inputs : iterable of path, optional
        Files the run reads: a folder holding one is refused, ``force`` or not.

    Returns
    -------
    pathlib.Path
        ``path``.

    Raises
    ------
    InputError
        If ``path`` is a file or holds an input; or, unless ``force``, a non-empty folder without
        :data:`MARKER`, with a damaged one (:func:`read_marker`), or holding a sweep.
    """
    from quadcruise.errors import InputError
    from quadcruise.io.keep_inputs import check_keeps_inputs

    check_keeps_inputs(path := Path(path), inputs)  # whatever force says: the input would be lost
    if path.exists() and not path.is_dir():
        raise InputError(f"{path}: exists and is not a folder")
    check_writable_place(path)
    if force or not path.is_dir():
        return path
    held = read_marker(path)
    if held is None and any(path.iterdir()):
        raise InputError(f"{path}: folder is not empty and was not written by quadcruise (use --force to replace it)")
    if workflow != "montecarlo" and held is not None and held.get("workflow") == "montecarlo":
        raise InputError(
            f"{path}: holds a Monte Carlo sweep (hours of flights, resumable); use --force to "
            "replace it or choose another --out"
        )
    if workflow == "reproduce" and held is not None and held.get("workflow") != "reproduce":
        raise InputError(
            f"{path}: holds the output of quadcruise {held.get('workflow') or 'another command'}, not of "
            "reproduce; use --force to replace it or choose another --out"
        )
    return path


def check_table_format(fmt: str) -> None:
    """Refuse an unknown table format, or Parquet without pyarrow, before any work is done.

    Parameters
    ----------
    fmt : str
        ``"csv"`` or ``"parquet"``.

    Raises
    ------
    InputError
        For another format, or for ``"parquet"`` when pyarrow is not installed.

    Examples
    --------
    >>> check_table_format("csv")
    >>> check_table_format("xlsx")
    Traceback (most recent call last):
        ...
    quadcruise.errors.InputError: unknown table format 'xlsx'; choose csv or parquet
    """
    from quadcruise.errors import InputError

    if fmt not in ("csv", "parquet"):
        raise InputError(f"unknown table format {fmt!r}; choose csv or parquet")
    if fmt == "parquet":
        try:
            import pyarrow  # noqa: F401  (pandas needs it for Parquet)
        except ImportError:
            raise InputError("writing Parquet needs pyarrow: pip install 'quadcruise[parquet]'") from None


def write_table(frame, path: Path, fmt: str) -> Path:
    """Write a DataFrame as CSV or Parquet at ``path`` with the format's suffix, atomically.

    Numbers are written with 10 significant digits in a CSV, without the index.

    Parameters
    ----------
    frame : pandas.DataFrame
        The table.
    path : pathlib.Path
        Where to write; its suffix is replaced by the format's (``.csv``, ``.parquet``).
    fmt : str
        ``"csv"`` or ``"parquet"`` (see :func:`check_table_format`).

    Returns
    -------
    pathlib.Path
        The file written.
    """
    import pandas as pd

    check_table_format(fmt)
    out = Path(path).with_suffix("." + fmt)
    with atomic_path(out) as tmp:
        if fmt == "parquet":
            frame.to_parquet(tmp, index=False)
        elif all(pd.api.types.is_numeric_dtype(d) for d in frame.dtypes):
            import numpy as np

            # numpy's savetxt formats an all-numeric table faster than pandas' to_csv
            np.savetxt(
                tmp,
                frame.to_numpy(dtype=float),
                delimiter=",",
                fmt="%.10g",
                header=",".join(map(str, frame.columns)),
                comments="",
            )
        else:
            frame.to_csv(tmp, index=False, float_format="%.10g")
    return out


def _read_at_once(path: Path, required, optional, blank_ok):
    """:func:`read_numeric_csv`'s result by pandas' C reader, for a plain file (no quotes, no blank
    line, every row as wide as the header, every cell a number); None otherwise, and the reader
    that names each line and cell takes over."""
    import io

    import numpy as np
    import pandas as pd

    try:
        raw = path.read_bytes()
        raw = raw[3:] if raw.startswith(b"\xef\xbb\xbf") else raw
        text = raw.rstrip(b"\r\n")
        if b'"' in text:
            return None  # quoted cells: the csv module's
        header = [h.strip() for h in text.split(b"\n", 1)[0].decode().rstrip("\r").split(",")]
        rows = text.count(b"\n")
        if (
            len(set(header)) != len(header)
            or not set(required) <= set(header)
            or not set(header) <= set(required) | set(optional)
            or text.count(b",") != (rows + 1) * (len(header) - 1)
        ):
            return None
        if b"nan" in text.lower():
            return None  # a NaN cell: refused, by line
        used = [c for c in required + tuple(optional) if c in header]
        table = pd.read_csv(
            io.BytesIO(text),
            header=0,
            names=header,
            usecols=used,
            dtype=float,
            na_values=[""],
            keep_default_na=False,
            skipinitialspace=True,
            engine="c",
        )
        if len(table) != rows:
            return None  # a blank line (pandas skips it): lines to count
        columns = []
        for name in used:
            column = table[name].to_numpy(dtype=float)
            blank = np.flatnonzero(np.isnan(column))  # only a blank cell reads as NaN here
            if blank.size and (blank_ok is None or not all(blank_ok(name, int(k)) for k in blank)):
                return None
            columns.append(column)
    except (OSError, ValueError, UnicodeDecodeError, pd.errors.ParserError):
        return None
    data = np.column_stack(columns) if columns else np.empty((rows, 0))
    return 1, used, data, list(range(2, rows + 2))


def read_numeric_csv(
    path: str | os.PathLike, required: tuple[str, ...], optional: tuple[str, ...] = (), *, blank_ok=None, progress=None
):
    """Read a CSV of numbers with a header; any problem is one InputError naming the file,
    the line and the column.

    Blank lines are skipped but counted. Unknown columns are ignored with a warning.

    Parameters
    ----------
    path : str or os.PathLike
        The CSV file.
    required : tuple of str
        Columns the header must name.
    optional : tuple of str
        Columns the header may name.
    blank_ok : callable, optional
        ``blank_ok(column, row_index) -> bool``: whether a blank cell is allowed (it then
        reads as NaN); without it every blank cell is an error.
    progress : callable, optional
        ``progress(done, total)``: the data rows read into numbers, from 0 to the number of
        rows (about every hundredth of them when the file is read cell by cell).

    Returns
    -------
    header_line : int
        The file line of the header (1-based).
    columns : list of str
        The columns used: the required ones, then the optional ones present, in that order.
    data : ndarray, shape (rows, columns)
        The numbers, as floats.
    lines : list of int
        The file line of each row of ``data``.

    Examples
    --------
    >>> import tempfile
    >>> with tempfile.TemporaryDirectory() as folder:
    ...     path = Path(folder) / "duties.csv"
    ...     _ = path.write_text("t,u1\\n0,0.5\\n\\n1,0.6\\n")
    ...     head, columns, data, lines = read_numeric_csv(path, ("t",), ("u1", "u2"))
    >>> head, columns, data.tolist(), lines
    (1, ['t', 'u1'], [[0.0, 0.5], [1.0, 0.6]], [2, 4])
    """
    import csv
    import math
    import warnings

    import numpy as np

    from quadcruise.errors import InputError

    path = Path(path)
    if path.is_dir():
        raise InputError(f"{path}: is a folder, not a file")
    if not path.is_file():
        raise InputError(f"{path}: {not_a_file(path)}")  # a FIFO, too: it would not be opened
    fast = _read_at_once(path, required, optional, blank_ok)
    if fast is not None:
        if progress is not None:
            progress(0, fast[2].shape[0])
            progress(fast[2].shape[0], fast[2].shape[0])
        return fast
    try:
        with path.open(newline="", encoding="utf-8-sig") as f:  # a byte-order mark (Excel's) is dropped
            rows = [(n, r) for n, r in enumerate(csv.reader(f), start=1) if any(c.strip() for c in r)]
    except (OSError, UnicodeDecodeError, csv.Error) as exc:
        raise InputError(f"{path}: cannot be read ({exc.__class__.__name__}: {exc})") from None
    names = ",".join(required + tuple(f"[{c}]" for c in optional))
    if not rows:
        raise InputError(f"{path}: the file is empty (expected a header {names})")
    head, header = rows[0][0], [h.strip() for h in rows[0][1]]
    missing = [c for c in required if c not in header]
    if missing:
        raise InputError(
            f"{path}, line {head}, column(s) {', '.join(map(repr, missing))}: missing (the header must name {names})"
        )
    dupes = sorted({h for h in header if header.count(h) > 1})
    if dupes:
        raise InputError(f"{path}, line {head}, column(s) {', '.join(map(repr, dupes))}: appear more than once")
    extra = [h for h in header if h not in required + optional]
    if extra:
        warnings.warn(f"{path}: ignoring column(s) {', '.join(extra)}", stacklevel=3)
    used = [c for c in required + optional if c in header]
    position = [header.index(name) for name in used]
    data = np.empty((len(rows) - 1, len(used)))
    every = max(1, data.shape[0] // 100)
    for k, (line, row) in enumerate(rows[1:]):
        if progress is not None and k % every == 0:
            progress(k, data.shape[0])
        if len(row) != len(header):
            raise InputError(f"{path}, line {line}: has {len(row)} cells, the header has {len(header)}")
        for j, name in enumerate(used):
            cell = row[position[j]].strip()
            if not cell and blank_ok is not None and blank_ok(name, k):
                data[k, j] = math.nan
                continue
            try:
                value = float(cell)
            except ValueError:
                raise InputError(f"{path}, line {line}, column '{name}': {cell!r} is not a number") from None
            if math.isnan(value):
                raise InputError(f"{path}, line {line}, column '{name}': value is NaN")
            data[k, j] = value
    if progress is not None:
        progress(data.shape[0], data.shape[0])
    return head, used, data, [line for line, _ in rows[1:]]
