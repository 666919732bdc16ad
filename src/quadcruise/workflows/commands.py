"""Command tables for an open-loop replay: one schedule type, one reader, the plant read from
the columns.

A table has a column ``t`` [s] and either ``u1 .. un``, normalised motor commands (PWM duties
in [0, 1]), or ``w1 .. wn``, commanded rotor speeds [rad/s]. Each row's commands hold from its
``t`` until the next row's. The paper's plant (:class:`~quadcruise.model.vehicle.Vehicle`)
flies duties, ``t,u1,u2,u3,u4``; a rotor-plant vehicle
(:class:`~quadcruise.model.rotor_vehicle.RotorVehicle`) flies speeds, or duties turned into
speeds by its command-to-speed map. :func:`read_commands` reads a CSV file or a pandas
DataFrame by its columns; :class:`CommandSchedule` holds either kind.

Examples
--------
>>> s = CommandSchedule(t=[0.0, 1.0], duties=[[0.5] * 4] * 2)
>>> s.kind, s.columns
('duties', ('t', 'u1', 'u2', 'u3', 'u4'))
>>> CommandSchedule(t=[0.0, 1.0], speeds=[[1800.0] * 4, [1800.0, 2e3, 1800.0, 1800.0]]).kind
'speeds'
"""

from __future__ import annotations

import csv
import math
import os
import warnings
from collections.abc import Callable
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np

from quadcruise import checks
from quadcruise.errors import InputError
from quadcruise.io.files import read_numeric_csv
from quadcruise.model.rotor_vehicle import RotorVehicle
from quadcruise.sim import plants

PAPER_ROTORS = 4
"""The paper's quadrotor's rotors: its duty table is ``t,u1,u2,u3,u4``."""

EXPECTED = "t,u1,u2,u3,u4 (PWM duties in [0, 1]) or t,w1,..,wn (commanded rotor speeds [rad/s])"
"""The columns a command table may have, as a message says them."""

ROTOR_VEHICLES = "crazyflie, hummingbird, iris or a vehicle file"
"""The rotor-plant vehicles a message may suggest."""


def deprecated(old: str, new: str) -> None:
    """Warn that ``old`` is a deprecated name of ``new`` (a ``DeprecationWarning`` at the caller's caller).

    Parameters
    ----------
    old : str
        The old call, e.g. ``"replay_rotors()"``.
    new : str
        The call that replaces it.
    """
    warnings.warn(
        f"{old} is deprecated and will be removed in the next release: use {new}", DeprecationWarning, stacklevel=3
    )


@dataclass(frozen=True)
class ReplayPlant:
    """What a vehicle's plant replays: its rotor count, whether it takes rotor speeds, its default step.

    Parameters
    ----------
    name : str
        ``"paper"`` or ``"rotor"``.
    n_rotors : int
        The number of rotors, n: the table's ``u1 .. un`` or ``w1 .. wn``.
    takes_speeds : bool
        Whether a table of rotor speeds applies (the rotor-speed plant), or duties only.
    max_step : float
        The default longest RK4 substep [s] (docs/vehicles.md, "Step").
    """

    name: str
    n_rotors: int
    takes_speeds: bool
    max_step: float


def replay_plant(vehicle: Any) -> ReplayPlant:
    """The plant a vehicle flies in a replay: the paper's for a :class:`~quadcruise.Vehicle`, the
    rotor-speed plant for a :class:`~quadcruise.model.rotor_vehicle.RotorVehicle`.

    Parameters
    ----------
    vehicle : Vehicle or RotorVehicle
        The vehicle.

    Returns
    -------
    ReplayPlant

    Examples
    --------
    >>> from quadcruise.model.vehicle import Vehicle
    >>> replay_plant(Vehicle.paper()).takes_speeds, replay_plant(Vehicle.preset("iris")).n_rotors
    (False, 4)
    """
    plant = plants.of(vehicle)
    return ReplayPlant(plant.name, plant.n_rotors(vehicle), plant.takes_speeds, plant.replay_step)


@dataclass(frozen=True, eq=False)
class CommandSchedule:
    """Piecewise-constant commands, duties or rotor speeds: row k holds from t[k] until t[k+1].

    Give exactly one of ``duties`` and ``speeds``.

    Parameters
    ----------
    t : array_like, shape (L,)
        Strictly increasing, finite times [s], L >= 2.
    duties : array_like, shape (L, n), optional
        Normalised motor commands (PWM duties) of rotors 1..n [-], each in [0, 1]: columns
        ``u1 .. un``.
    speeds : array_like, shape (L, n), optional
        Commanded speeds of rotors 1..n [rad/s], finite (the vehicle's range is checked by
        :func:`~quadcruise.workflows.replay.replay`): columns ``w1 .. wn``.
    source : str
        Where the rows came from (a file name), used in error messages.
    lines : tuple of int, optional
        The file line of each row, for error messages.

    Raises
    ------
    InputError
        A schedule that breaks these rules, naming ``source`` and the row (or line) and column.

    Examples
    --------
    >>> CommandSchedule(t=[0.0, 1.0], duties=[[0.5] * 4, [0.5, 1.5, 0.5, 0.5]])
    Traceback (most recent call last):
        ...
    quadcruise.errors.InputError: schedule, row 2, column 'u2': duty 1.5 is outside [0, 1]
    """

    t: np.ndarray
    duties: np.ndarray | None = None
    speeds: np.ndarray | None = None
    source: str = "schedule"
    lines: tuple = ()

    def __post_init__(self) -> None:
        if (self.duties is None) == (self.speeds is None):
            raise InputError(f"{self.source}: give duties (columns u1..un) or speeds (columns w1..wn), exactly one")
        kind = "duties" if self.speeds is None else "speeds"
        t = np.asarray(self.t, dtype=float)
        v = np.asarray(self.duties if self.speeds is None else self.speeds, dtype=float)
        if t.ndim != 1 or t.shape[0] < 2:
            raise InputError(f"{self.source}: needs at least two rows (a start and an end time)")
        if v.ndim != 2 or v.shape[0] != t.shape[0] or v.shape[1] < 1:
            raise InputError(f"{self.source}: {kind} have shape {v.shape}, expected ({t.shape[0]}, n)")
        with np.errstate(invalid="ignore"):  # the rows at fault, at array speed; the first one named below
            good = np.isfinite(v) & ((v >= 0.0) & (v <= 1.0) if kind == "duties" else True)
            bad = ~np.isfinite(t) | np.r_[False, ~(t[1:] > t[:-1])] | ~np.all(good, axis=1)
        if bad.any():
            k = int(np.argmax(bad))
            where = self.where(k)
            if not math.isfinite(t[k]):
                raise InputError(f"{where}, column 't': time is not finite ({checks.short_number(t[k])})")
            if k and not t[k] > t[k - 1]:
                raise InputError(f"{where}, column 't': time {t[k]:g} is not after the previous row's {t[k - 1]:g}")
            j = int(np.argmax(~good[k]))
            what, column = ("duty", f"u{j + 1}") if kind == "duties" else ("rotor speed", f"w{j + 1}")
            if not math.isfinite(v[k, j]):
                raise InputError(f"{where}, column '{column}': {what} is not finite ({checks.short_number(v[k, j])})")
            raise InputError(f"{where}, column '{column}': duty {v[k, j]:g} is outside [0, 1]")
        object.__setattr__(self, "t", t)
        object.__setattr__(self, kind, v)

    @property
    def kind(self) -> str:
        """``"duties"`` or ``"speeds"``."""
        return "duties" if self.speeds is None else "speeds"

    @property
    def values(self) -> np.ndarray:
        """The commands, shape (L, n): duties [-] or rotor speeds [rad/s]."""
        return self.duties if self.speeds is None else self.speeds

    @property
    def n_rotors(self) -> int:
        """The number of rotors commanded, n."""
        return self.values.shape[1]

    @property
    def columns(self) -> tuple:
        """The table's columns: ``t`` then ``u1 .. un`` or ``w1 .. wn``."""
        letter = "u" if self.speeds is None else "w"
        return ("t",) + tuple(f"{letter}{j + 1}" for j in range(self.n_rotors))

    def where(self, k: int) -> str:
        """How a message names row k: the source and its file line, or its row number.

        Parameters
        ----------
        k : int
            The row's index (from 0).

        Returns
        -------
        str
        """
        return f"{self.source}, line {self.lines[k]}" if self.lines else f"{self.source}, row {k + 1}"


def _header(path: Path) -> list[str] | None:
    """The first non-blank line's cells of a regular file, or None (missing, unreadable, empty):
    :func:`~quadcruise.io.files.read_numeric_csv` then says what is wrong."""
    if not path.is_file():
        return None  # a FIFO too: never opened here (it would wait)
    try:
        with path.open(newline="", encoding="utf-8-sig") as f:
            for line in f:
                if line.strip():
                    return [c.strip() for c in next(csv.reader([line]))]
    except (OSError, UnicodeDecodeError, csv.Error):
        return None
    return None


def _count(header, letter: str) -> int:
    """How many of ``<letter>1``, ``<letter>2``, ... the header names in a row."""
    n = 0
    while f"{letter}{n + 1}" in header:
        n += 1
    return n


def _frame_data(frame, columns: tuple, source: str) -> np.ndarray:
    """A DataFrame's command columns as floats; a missing column, a text cell or a NaN refused by name and row."""
    header = [str(c) for c in frame.columns]
    missing = [c for c in columns if c not in header]
    if missing:
        raise InputError(f"{source}, column(s) {', '.join(map(repr, missing))}: missing (columns {','.join(columns)})")
    others = [c for c in header if c not in columns]
    if others:
        warnings.warn(f"{source}: ignoring column(s) {', '.join(others)}", stacklevel=4)
    data = np.empty((len(frame), len(columns)))
    for j, name in enumerate(columns):
        column = frame[frame.columns[header.index(name)]]
        try:
            data[:, j] = column.to_numpy(dtype=float)
        except (TypeError, ValueError):
            k = next(k for k, c in enumerate(column) if not _is_number(c))
            raise InputError(f"{source}, row {k + 1}, column '{name}': {column.iloc[k]!r} is not a number") from None
        if np.isnan(data[:, j]).any():
            raise InputError(f"{source}, row {int(np.argmax(np.isnan(data[:, j]))) + 1}, column '{name}': value is NaN")
    return data


def _is_number(value) -> bool:
    try:
        float(value)
    except (TypeError, ValueError):
        return False
    return True


def _read(source, n_rotors: int | None, letter: str | None, plant: ReplayPlant | None, progress) -> CommandSchedule:
    """The reader behind :func:`read_commands` and the deprecated ones: ``letter`` forces the
    kind (``"u"`` or ``"w"``), ``n_rotors`` the count, ``plant`` refuses what it cannot fly."""
    import pandas as pd

    frame = source if isinstance(source, pd.DataFrame) else None
    name = "the commands (a DataFrame)" if frame is not None else str(source)
    header = [str(c) for c in frame.columns] if frame is not None else _header(Path(source))
    if letter is None and header is not None:
        letter = "w" if "w1" in header else "u" if "u1" in header else None
        if letter is None:
            found = ",".join(header) if header else "none"
            raise InputError(f"{name}: columns {found} fit no plant: expected {EXPECTED}")
    letter = letter or "u"  # a file that cannot be read: read_numeric_csv names what is wrong
    if plant is not None and letter == "w" and not plant.takes_speeds:
        raise InputError(
            f"{name}: columns t,w1..w{_count(header, 'w')} are rotor speeds [rad/s], which the paper's "
            f"plant does not fly: it replays PWM duties, columns t,u1,u2,u3,u4; for speeds give a "
            f"rotor-plant vehicle ({ROTOR_VEHICLES})"
        )
    n = n_rotors or (_count(header, letter) if header is not None else PAPER_ROTORS)
    columns = ("t",) + tuple(f"{letter}{i + 1}" for i in range(n))
    extra = f"{letter}{n + 1}"
    if header is not None and extra in header:  # a table for another vehicle: refused before it is read
        raise InputError(f"{name}: column '{extra}', but the vehicle has {n} rotors (columns {', '.join(columns)})")
    if frame is not None:
        data, lines = _frame_data(frame, columns, name), []
        if progress is not None:
            progress(len(frame), len(frame))
    else:
        _, _, data, lines = read_numeric_csv(source, columns, progress=progress)
    if data.shape[0] < 2:
        raise InputError(f"{name}: needs at least two data rows (a start and an end time), found {data.shape[0]}")
    kind = {"duties" if letter == "u" else "speeds": data[:, 1:]}
    return CommandSchedule(t=data[:, 0], source=name, lines=tuple(lines), **kind)


def read_commands(
    source: Any, vehicle: Any = None, *, progress: Callable[[int, int], None] | None = None
) -> CommandSchedule:
    """Read a command table, duties or rotor speeds by its columns; errors name the file, line and column.

    Parameters
    ----------
    source : str, os.PathLike or pandas.DataFrame
        A CSV file (a header, then at least two rows) or a DataFrame, with a column ``t`` [s]
        and either ``u1 .. un`` (PWM duties in [0, 1]) or ``w1 .. wn`` (commanded rotor speeds
        [rad/s]); other columns are ignored with a warning.
    vehicle : Vehicle or RotorVehicle, optional
        The vehicle the table is for: its rotor count (a column for a rotor it lacks is
        refused), and its plant (a speed table for the paper's plant is refused before the
        rows are read). Without it, n is the number of columns the header names.
    progress : callable, optional
        ``progress(done, total)``: the rows read (:func:`~quadcruise.io.files.read_numeric_csv`).

    Returns
    -------
    CommandSchedule
        With ``source`` the file name and the file line of each row.

    Raises
    ------
    InputError
        A table whose columns fit no plant, a speed table for the paper's plant, a missing or
        extra rotor column, a bad cell, or times that do not increase: one line naming the file.

    Examples
    --------
    >>> import pandas as pd
    >>> read_commands(pd.DataFrame({"t": [0.0, 1.0], "w1": [9.0, 9.0], "w2": [9.0, 8.0]})).speeds.shape
    (2, 2)
    """
    w = "read_commands()"
    checks.callback(w, "progress", progress)
    if not isinstance(source, (str, os.PathLike)):
        import pandas as pd

        checks.instance(w, "source", source, pd.DataFrame, optional=False, want="a path or a pandas DataFrame")
    plant = None if vehicle is None else replay_plant(vehicle)
    return _read(source, None if plant is None else plant.n_rotors, None, plant, progress)


# --- the names before one schedule type and one reader (deprecated for one release) ------------
class DutySchedule(CommandSchedule):
    """Deprecated: ``CommandSchedule(t, duties=...)``.

    Parameters
    ----------
    t : array_like, shape (L,)
        Times [s].
    duties : array_like, shape (L, n)
        Duties [-].
    source : str
        Where the rows came from.
    """

    def __init__(self, t, duties, source: str = "schedule") -> None:
        deprecated("DutySchedule(t, duties)", "CommandSchedule(t, duties=...)")
        super().__init__(t, duties=duties, source=source)


class SpeedSchedule(CommandSchedule):
    """Deprecated: ``CommandSchedule(t, speeds=...)``.

    Parameters
    ----------
    t : array_like, shape (L,)
        Times [s].
    speeds : array_like, shape (L, n)
        Commanded rotor speeds [rad/s].
    source : str
        Where the rows came from.
    lines : tuple of int, optional
        The file line of each row.
    """

    def __init__(self, t, speeds, source: str = "schedule", lines: tuple = ()) -> None:
        deprecated("SpeedSchedule(t, speeds)", "CommandSchedule(t, speeds=...)")
        super().__init__(t, speeds=speeds, source=source, lines=lines)


def read_duty_csv(path: str | os.PathLike, progress: Callable[[int, int], None] | None = None) -> CommandSchedule:
    """Deprecated: :func:`read_commands` (a ``t,u1,u2,u3,u4`` CSV of PWM duties).

    Parameters
    ----------
    path : str or os.PathLike
        The CSV file.
    progress : callable, optional
        ``progress(done, total)``: the rows read.

    Returns
    -------
    CommandSchedule
    """
    deprecated("read_duty_csv(path)", "read_commands(path)")
    checks.instance("read_duty_csv()", "path", path, (str, os.PathLike), optional=False, want="a path")
    checks.callback("read_duty_csv()", "progress", progress)
    return _read(path, PAPER_ROTORS, "u", None, progress)


def read_speed_csv(
    path: str | os.PathLike, n_rotors: int, progress: Callable[[int, int], None] | None = None
) -> CommandSchedule:
    """Deprecated: :func:`read_commands` (a ``t,w1,..,wn`` CSV of commanded rotor speeds).

    Parameters
    ----------
    path : str or os.PathLike
        The CSV file.
    n_rotors : int
        The vehicle's number of rotors, n.
    progress : callable, optional
        ``progress(done, total)``: the rows read.

    Returns
    -------
    CommandSchedule
    """
    deprecated("read_speed_csv(path, n_rotors)", "read_commands(path, vehicle)")
    w = "read_speed_csv()"
    checks.instance(w, "path", path, (str, os.PathLike), optional=False, want="a path")
    n_rotors = checks.whole(w, "n_rotors", n_rotors, 1)
    checks.callback(w, "progress", progress)
    return _read(path, n_rotors, "w", None, progress)


def read_rotor_csv(
    path: str | os.PathLike, vehicle: RotorVehicle, progress: Callable[[int, int], None] | None = None
) -> CommandSchedule:
    """Deprecated: :func:`read_commands` (duties then turned into speeds by the vehicle's map).

    Parameters
    ----------
    path : str or os.PathLike
        The CSV file.
    vehicle : RotorVehicle
        The vehicle.
    progress : callable, optional
        ``progress(done, total)``: the rows read.

    Returns
    -------
    CommandSchedule
        Rotor speeds [rad/s].
    """
    deprecated("read_rotor_csv(path, vehicle)", "read_commands(path, vehicle)")
    s = _read(path, vehicle.n_rotors, None, replay_plant(vehicle), progress)
    if s.speeds is not None:
        return s
    return CommandSchedule(t=s.t, speeds=vehicle.command_speed(s.duties), source=s.source, lines=s.lines)
