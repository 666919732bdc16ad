"""Waypoint tables and the waypoint legs: a table of points flown as straight legs.

A :class:`WaypointTable` holds the points and their timing (arrival times, or the speed of the
leg ending at each, or one cruise speed), read from a CSV by :func:`read_waypoints_csv`;
:class:`Waypoints` flies it as constant-speed legs. The same table flown as one minimum-snap
path: :mod:`quadcruise.missions.minsnap`. Their parameter layouts and continuity:
docs/missions.md.

Examples
--------
>>> from quadcruise.missions.waypoints import WaypointTable, Waypoints
>>> table = WaypointTable([[0, 0, 1], [2, 0, 1], [2, 1, 1]], speed=[0, 0.5, 0.25])
>>> table.times()
array([0., 4., 8.])
>>> legs = Waypoints(table)
>>> legs.reference([2.0, 6.0])[:, :5]            # x, y, z, vx, vy half-way along each leg
array([[1.  , 0.  , 1.  , 0.5 , 0.  ],
       [2.  , 0.5 , 1.  , 0.  , 0.25]])
>>> legs.duration
13.0
"""

from __future__ import annotations

import math
import os
from dataclasses import dataclass, field
from typing import Any, ClassVar

import numpy as np
from numba import njit

from quadcruise.checks import short_number
from quadcruise.errors import InputError
from quadcruise.fields import instance_of
from quadcruise.fields import unit_field as _f
from quadcruise.io.files import read_numeric_csv
from quadcruise.layout import REF_PSI, REF_PSI_DOT, REF_SIZE, REF_VX, REF_X
from quadcruise.missions.base import Mission

__all__ = [
    "WaypointTable",
    "read_waypoints_csv",
    "Waypoints",
    "SETTLE_S",
    "DEFAULT_SPEED",
]

COLUMNS = ("x", "y", "z", "yaw", "t", "speed")
DEFAULT_SPEED = 0.5  # m/s, the square mission's default speed, for tables that give no timing
SETTLE_S = 5.0  # s flown after the last point by default

# offsets into the packed parameter vector (mp) that the compiled reference reads
# Waypoints: [n, hold_yaw, (x, y, z, yaw, t) per point]
WP_N, WP_HOLD_YAW, WP_POINTS = 0, 1, 2  # count, yaw mode, first point
WP_STRIDE = 5  # entries per point: ...
PT_X, PT_YAW, PT_T = 0, 3, 4  # ... x, y, z from PT_X, then yaw, arrival time


# --- the table -----------------------------------------------------------------------------
@dataclass(frozen=True, eq=False)
class WaypointTable:
    """Waypoints and their timing, checked on construction.

    Parameters
    ----------
    points : array_like, shape (n, 3)
        Positions x, y, z [m], n >= 2, all finite. Without ``t``, no point may repeat the
        one before it (a zero-length leg).
    yaw : array_like, shape (n,), optional
        Yaw at each point [rad] (0 throughout if left out).
    t : array_like, shape (n,), optional
        Arrival times [s]: the first 0, then strictly increasing. A point repeated with a
        later time is a dwell.
    speed : array_like, shape (n,), optional
        Cruise speed on the leg ending at each point [m/s], > 0; the first entry is unused
        (NaN allowed, not negative). Not together with ``t``.
    source : str
        Name used in error messages (the file name).
    lines : sequence of int, optional
        The file line of each point, for error messages (rows are counted from 1 without it).

    Raises
    ------
    InputError
        One line naming the source, the row (or line) and column of the first bad value.

    Examples
    --------
    >>> WaypointTable([[0, 0, 1], [1, 0, 1]], t=[0.0, 0.0])
    Traceback (most recent call last):
        ...
    quadcruise.errors.InputError: waypoints, row 2, column 't': time 0 is not after the previous point's 0
    """

    points: Any
    yaw: Any = None
    t: Any = None
    speed: Any = None
    source: str = "waypoints"
    lines: Any = field(default=None, repr=False)  # file line of each point, for messages

    def __post_init__(self) -> None:
        src, lines = str(self.source), self.lines

        def where(k: int, col: str) -> str:
            return f"{src}, {'line ' + str(lines[k]) if lines else 'row ' + str(k + 1)}, column '{col}'"

        pts = _array(self.points, src, "points")
        if pts.ndim != 2 or pts.shape[1] != 3:
            raise InputError(f"{src}: points have shape {pts.shape}, expected (n, 3) (x, y, z)")
        n = pts.shape[0]
        if n < 2:
            raise InputError(f"{src}: needs at least two waypoints, found {n}")
        cols = {"yaw": self.yaw, "t": self.t, "speed": self.speed}
        if self.t is not None and self.speed is not None:
            raise InputError(f"{src}, columns 't' and 'speed': give arrival times or leg speeds, not both")
        for name, value in cols.items():
            if value is not None:
                cols[name] = _array(value, src, name)
                if cols[name].shape != (n,):
                    raise InputError(f"{src}: {name} has shape {cols[name].shape}, expected ({n},)")
        t, v = cols["t"], cols["speed"]
        named = [("x", pts[:, 0]), ("y", pts[:, 1]), ("z", pts[:, 2])]
        named += [(c, cols[c]) for c in ("yaw", "t") if cols[c] is not None]
        bad = np.argwhere(~np.isfinite(np.column_stack([c for _, c in named])))
        if bad.size:  # the first bad cell, row by row
            k, j = bad[0]
            raise InputError(f"{where(k, named[j][0])}: value is not finite ({short_number(named[j][1][k])})")
        if t is not None and t[0] != 0.0:
            raise InputError(f"{where(0, 't')}: the first arrival time must be 0, got {t[0]:g}")
        k = None if t is None else _after_first(np.diff(t) <= 0)
        if k is not None:
            raise InputError(f"{where(k, 't')}: time {t[k]:g} is not after the previous point's {t[k - 1]:g}")
        if v is not None and v[0] < 0:
            raise InputError(f"{where(0, 'speed')}: speed {v[0]:g} is negative (the first row's is unused)")
        k = None if v is None else _after_first(~(np.isfinite(v[1:]) & (v[1:] > 0)))
        if k is not None:
            raise InputError(f"{where(k, 'speed')}: the leg speed must be a positive number, got {v[k]:g}")
        k = None if t is not None else _after_first(np.all(pts[1:] == pts[:-1], axis=1))
        if k is not None:
            raise InputError(
                f"{where(k, 'x')} (and 'y', 'z'): the same point as the one before, "
                "a zero-length leg with no dwell time (give arrival times 't')"
            )
        for name, arr in (("points", pts), *cols.items()):
            if arr is not None:
                arr.setflags(write=False)
                object.__setattr__(self, name, arr)
        object.__setattr__(self, "source", src)

    def __len__(self) -> int:
        return self.points.shape[0]

    def __eq__(self, other: object) -> bool:
        if not isinstance(other, WaypointTable):
            return NotImplemented
        return all(_same(getattr(self, n), getattr(other, n)) for n in ("points", "yaw", "t", "speed"))

    def __hash__(self) -> int:
        return hash(tuple(None if a is None else a.tobytes() for a in (self.points, self.yaw, self.t, self.speed)))

    def times(self, speed: float = DEFAULT_SPEED) -> np.ndarray:
        """Arrival time at each point: ``t``, or cumulated leg length / leg speed.

        Parameters
        ----------
        speed : float
            Speed on every leg [m/s], used only when the table gives neither ``t`` nor
            ``speed``.

        Returns
        -------
        numpy.ndarray
            Shape (n,), arrival times [s], the first 0 (a copy).

        Examples
        --------
        >>> WaypointTable([[0, 0, 1], [3, 4, 1]]).times(speed=2.5)
        array([0., 2.])
        """
        if self.t is not None:
            return np.array(self.t)
        v = self.speed[1:] if self.speed is not None else np.full(len(self) - 1, float(speed))
        legs = np.linalg.norm(np.diff(self.points, axis=0), axis=1)
        return np.concatenate([[0.0], np.cumsum(legs / v)])

    def yaws(self) -> np.ndarray:
        """Yaw at each point, each leg turning the short way.

        A yaw is an angle: from 3.0 rad to -3.0 rad the vehicle turns 0.28 rad through
        +-pi, not 6 rad through 0. Each point's yaw is moved by whole turns (``numpy.unwrap``)
        so that no leg turns more than pi; a larger turn takes intermediate points.

        Returns
        -------
        numpy.ndarray
            Shape (n,), yaw [rad] (zeros if the table has none; a copy).

        Examples
        --------
        >>> WaypointTable([[0, 0, 1], [1, 0, 1], [2, 0, 1]], yaw=[3.0, -3.0, 3.0]).yaws().round(3)
        array([3.   , 3.283, 3.   ])
        """
        return np.zeros(len(self)) if self.yaw is None else np.unwrap(np.asarray(self.yaw, dtype=float))

    def to_dict(self) -> dict:
        """The table as plain lists, for JSON; :meth:`from_dict` reads it back.

        Returns
        -------
        dict
            ``x``, ``y``, ``z`` [m], ``yaw`` [rad], ``t`` [s], ``speed`` [m/s] as lists (None
            for an absent column; a non-finite entry, such as the unused first speed, as
            None) and ``source``. The file lines are not kept.
        """
        out: dict = {name: self.points[:, j].tolist() for j, name in enumerate("xyz")}
        for name in ("yaw", "t", "speed"):
            arr = getattr(self, name)
            out[name] = None if arr is None else [v if math.isfinite(v) else None for v in arr.tolist()]
        return {**out, "source": self.source}

    @classmethod
    def from_dict(cls, d: dict) -> WaypointTable:
        """Inverse of :meth:`to_dict`.

        Parameters
        ----------
        d : dict
            ``x``, ``y``, ``z`` [m] (lists of equal length), optionally ``yaw`` [rad],
            ``t`` [s], ``speed`` [m/s] (None entries read as NaN) and ``source``.

        Returns
        -------
        WaypointTable

        Raises
        ------
        InputError
            A missing coordinate or values that are not numbers, or a table
            :class:`WaypointTable` refuses.

        Examples
        --------
        >>> table = WaypointTable([[0, 0, 1], [1, 0, 1]], speed=[float("nan"), 0.5])
        >>> WaypointTable.from_dict(table.to_dict()) == table
        True
        """
        try:
            pts = np.column_stack([np.asarray(d[c], dtype=float) for c in "xyz"])
            opt = {
                c: None if d.get(c) is None else np.array([np.nan if v is None else v for v in d[c]], dtype=float)
                for c in ("yaw", "t", "speed")
            }
        except (KeyError, TypeError, ValueError) as exc:
            raise InputError(f"waypoint table: bad dict ({exc.__class__.__name__}: {exc})") from None
        return cls(pts, **opt, source=str(d.get("source", "waypoints")))


def _array(value: Any, src: str, name: str) -> np.ndarray:
    try:
        return np.array(value, dtype=float)
    except (TypeError, ValueError):
        raise InputError(f"{src}: {name} must be numbers, got {value!r}") from None


def _after_first(mask: np.ndarray) -> int | None:
    """1 + the index of the first True of a mask over legs (the row that ends that leg)."""
    idx = np.flatnonzero(mask)
    return int(idx[0]) + 1 if idx.size else None


def _same(a, b) -> bool:
    return (a is None) == (b is None) and (a is None or np.array_equal(a, b, equal_nan=True))


def read_waypoints_csv(path: str | os.PathLike) -> WaypointTable:
    """Read a waypoint CSV (header ``x,y,z`` and optionally ``yaw`` and ``t`` or ``speed``).

    Errors are one line naming the file, line and column; unknown columns are ignored with a
    warning. The first row's ``speed`` cell may be empty.

    Parameters
    ----------
    path : str or os.PathLike
        The CSV file: columns x, y, z [m], yaw [rad], t [s] (arrival times) or speed [m/s]
        (speed on the leg ending at each row).

    Returns
    -------
    WaypointTable
        With ``source`` the path and ``lines`` the file line of each point.

    Raises
    ------
    InputError
        No such file, a missing column, a cell that is not a number, both ``t`` and
        ``speed``, fewer than two waypoints, or a table :class:`WaypointTable` refuses.
    """
    head_line, used, data, lines = read_numeric_csv(
        path,
        ("x", "y", "z"),
        tuple(c for c in COLUMNS if c not in "xyz"),
        blank_ok=lambda name, k: name == "speed" and k == 0,
    )  # the first point ends no leg
    if "t" in used and "speed" in used:
        raise InputError(
            f"{path}, line {head_line}, columns 't' and 'speed': give arrival times or leg speeds, not both"
        )
    if data.shape[0] < 2:
        raise InputError(
            f"{path}, line {lines[-1] if lines else head_line}: needs at least two waypoints, found {data.shape[0]}"
        )
    col = {name: data[:, j] for j, name in enumerate(used)}
    return WaypointTable(
        np.column_stack([col["x"], col["y"], col["z"]]),
        yaw=col.get("yaw"),
        t=col.get("t"),
        speed=col.get("speed"),
        source=str(path),
        lines=tuple(lines),
    )


# --- the compiled reference of the legs ---------------------------------------------------
@njit(cache=True)
def last_start(t, mp, first, stride, count):
    """Largest k < count with mp[first + stride k] <= t (0 when t is before them all)."""
    lo, hi = 0, count - 1
    while lo < hi:
        mid = (lo + hi + 1) // 2
        if mp[first + stride * mid] <= t:
            lo = mid
        else:
            hi = mid - 1
    return lo


@njit(cache=True, error_model="numpy")
def waypoints_ref(t, mp, ref):
    """Waypoint reference: straight constant-speed legs, yaw linear or held.

    Before t = 0, the first point; after the last arrival, the last point, at rest.

    Parameters
    ----------
    t : float
        Time [s].
    mp : numpy.ndarray
        [n, hold_yaw, then per point x, y, z [m], yaw [rad], t [s]].
    ref : numpy.ndarray
        Output: the reference at ``t`` (``REF_SIZE`` entries, overwritten).
    """
    for i in range(REF_SIZE):
        ref[i] = 0.0
    n = int(mp[WP_N])
    last = WP_POINTS + WP_STRIDE * (n - 1)
    if t >= mp[last + PT_T] or t < 0.0:  # hold the last (first) point
        at = last if t >= 0.0 else WP_POINTS
        for j in range(3):
            ref[REF_X + j] = mp[at + PT_X + j]
        ref[REF_PSI] = mp[at + PT_YAW]
        return
    # leg [t_k, t_k+1): departure point a, arrival point b
    a = WP_POINTS + WP_STRIDE * last_start(t, mp, WP_POINTS + PT_T, WP_STRIDE, n - 1)
    b = a + WP_STRIDE
    dur = mp[b + PT_T] - mp[a + PT_T]
    s = (t - mp[a + PT_T]) / dur
    for j in range(3):  # REF_X.. and REF_VX.. are x, y, z in order
        ref[REF_X + j] = mp[a + PT_X + j] + s * (mp[b + PT_X + j] - mp[a + PT_X + j])
        ref[REF_VX + j] = (mp[b + PT_X + j] - mp[a + PT_X + j]) / dur
    if mp[WP_HOLD_YAW] != 0.0:
        ref[REF_PSI] = mp[a + PT_YAW]
    else:
        ref[REF_PSI] = mp[a + PT_YAW] + s * (mp[b + PT_YAW] - mp[a + PT_YAW])
        ref[REF_PSI_DOT] = (mp[b + PT_YAW] - mp[a + PT_YAW]) / dur


# --- the mission kinds -----------------------------------------------------------------------
def _as_table(value: Any) -> WaypointTable:
    if isinstance(value, WaypointTable):
        return value
    if isinstance(value, (str, os.PathLike)):
        return read_waypoints_csv(value)
    if isinstance(value, dict):
        return WaypointTable.from_dict(value)
    raise InputError(f"a waypoint table must be a WaypointTable, a CSV path or a dict, got {type(value).__name__}")


MAX_PATH_S = 1.0e7
"""The longest a waypoint path may take to fly [s] (about 116 days): beyond it a coordinate or a
speed is surely wrong, and the flight's size check would refuse it anyway."""


@dataclass(frozen=True)
class WaypointMission(Mission):
    """What the waypoint kinds (:class:`Waypoints`, :class:`~quadcruise.missions.minsnap.MinimumSnap`)
    share: the table (a WaypointTable, CSV path or dict), the default speed, ``times``,
    ``duration`` and ``to_dict``."""

    table: Any = _f(None, "-", "waypoint table or CSV path", instance_of(WaypointTable), optional=False)
    speed: float = _f(DEFAULT_SPEED, "m/s", "leg speed where the table gives no timing", "pos")

    def __post_init__(self) -> None:
        object.__setattr__(self, "table", _as_table(self.table))
        super().__post_init__()
        with np.errstate(over="ignore", invalid="ignore"):
            last = float(self.times[-1])
        if not (math.isfinite(last) and last <= MAX_PATH_S):
            raise InputError(
                f"{self.table.source}: flying the path takes {last:g} s at its speeds, more than "
                f"{MAX_PATH_S:g} s (a coordinate too large, or a speed too small?)"
            )

    @property
    def times(self) -> np.ndarray:
        """Arrival time at each point [s]."""
        return self.table.times(self.speed)

    @property
    def duration(self) -> float:
        """Default flight time: the last arrival + SETTLE_S, rounded up to a whole second."""
        return float(math.ceil(self.times[-1] + SETTLE_S - 1e-9))

    def to_dict(self) -> dict:
        """The mission as a dict, its table written out (:meth:`WaypointTable.to_dict`)."""
        d = super().to_dict()
        return {**d, "table": self.table.to_dict()}


@dataclass(frozen=True)
class Waypoints(WaypointMission):
    """Straight constant-speed legs between the points, explicit corners (C0), like the square.

    ``style`` is 'legs' (the smooth style is the kind :class:`MinimumSnap`); ``yaw_mode``
    'linear' turns at a constant rate over each leg, 'hold' keeps the departure point's yaw
    until the arrival. mp = [n, hold_yaw, (x, y, z, yaw, t) per point].

    Parameters
    ----------
    table : WaypointTable, str, os.PathLike or dict
        The points and their timing; a path is read by :func:`read_waypoints_csv`, a dict by
        :meth:`WaypointTable.from_dict`.
    speed : float
        Leg speed where the table gives no timing [m/s], > 0.
    style : str
        Path style: 'legs' (the only one; the smooth path is the kind 'minsnap').
    yaw_mode : str
        Yaw over a leg: 'linear' or 'hold'.

    Examples
    --------
    >>> Waypoints(WaypointTable([[0, 0, 1], [0, 0, 1]], t=[0, 2])).params()
    array([2., 0., 0., 0., 1., 0., 0., 0., 0., 1., 0., 2.])
    """

    style: str = _f("legs", "-", "path style; the smooth path is the mission 'minsnap'", "choice", ("legs",))
    yaw_mode: str = _f("linear", "-", "yaw over a leg", "choice", ("linear", "hold"))

    name: ClassVar[str] = "waypoints"
    columns: ClassVar[tuple] = ("n", "hold_yaw", "x[k]", "y[k]", "z[k]", "yaw[k]", "t[k]")
    function = staticmethod(waypoints_ref)

    def _row(self) -> np.ndarray:  # an array, not a tuple: 10^6 points stay quick
        per_point = np.column_stack([self.table.points, self.table.yaws(), self.times])
        return np.concatenate([[len(self.table), float(self.yaw_mode == "hold")], per_point.ravel()])
