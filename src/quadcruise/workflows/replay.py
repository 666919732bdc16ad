"""Open-loop replay, the model-validation workflow: commands in, states out.

Input: a schedule of rows ``t, u1, u2, u3, u4`` (PWM duties, the paper's plant) or
``t, w1, ..., wn`` (commanded rotor speeds [rad/s], a rotor-plant vehicle:
:class:`~quadcruise.model.rotor_vehicle.RotorVehicle`); each row's commands hold from its t
until the next row's. The vehicle starts at rest at the origin, level, each rotor already at
the first row's command (thrust K * u_i, or speed w_i), in free flight (no ground). Output:
one state per input row, the first being the initial state; the last row only marks the end
time.

Examples
--------
>>> import quadcruise as qc
>>> v = qc.Vehicle.paper()
>>> hover = [[float(v.hover_duty)] * 4] * 3
>>> res = qc.replay(qc.DutySchedule(t=[0.0, 1.0, 2.0], duties=hover), vehicle=v)
>>> bool(abs(res.final_state[0, 2]) < 1e-9)    # hover stays put
True
"""

from __future__ import annotations

import math
import os
from collections.abc import Callable
from dataclasses import dataclass

import numpy as np
from numba import njit

from quadcruise import checks
from quadcruise._version import __version__
from quadcruise.control.openloop import duty_schedule, pack_schedule
from quadcruise.errors import InputError
from quadcruise.io.files import atomic_path, read_numeric_csv
from quadcruise.layout import F1, P_K, STATE_NAMES, STATE_SIZE
from quadcruise.model.rotor_plant import QW, ROTOR_W1, state_names
from quadcruise.model.rotor_vehicle import RotorVehicle
from quadcruise.model.vehicle import Vehicle
from quadcruise.sim.engine import simulate
from quadcruise.sim.inputs import Limits
from quadcruise.sim.result import SimResult
from quadcruise.sim.rotor_engine import replay_rotor_speeds
from quadcruise.sim.rotor_result import RotorResult

INPUT_COLUMNS = ("t", "u1", "u2", "u3", "u4")
OUTPUT_COLUMNS = ("t",) + STATE_NAMES


@njit(cache=True)  # compiled (as MISSION_SIG) on first use, not at import
def no_reference(t, mp, ref):
    """An open-loop flight's reference (a mission, ``MISSION_SIG``): NaN throughout."""
    for j in range(ref.shape[0]):
        ref[j] = math.nan


@dataclass(frozen=True, eq=False)
class DutySchedule:
    """Piecewise-constant PWM duties: row k holds from t[k] until t[k+1].

    Parameters
    ----------
    t : array_like, shape (n,)
        Strictly increasing times [s], n >= 2.
    duties : array_like, shape (n, 4)
        Duties of rotors 1..4 [-], each in [0, 1].
    source : str
        Where the rows came from (a file name), used in error messages.

    Raises
    ------
    InputError
        For a schedule that breaks these rules, naming ``source`` and the row.
    """

    t: np.ndarray
    duties: np.ndarray
    source: str = "schedule"

    def __post_init__(self) -> None:
        t, u = _validated(self.t, self.duties, self.source)
        object.__setattr__(self, "t", t)
        object.__setattr__(self, "duties", u)


def _validated(t, duties, source: str, lines: list[int] | None = None):
    """Check a schedule; errors name ``source`` and the row (or the file line)."""
    t = np.asarray(t, dtype=float)
    u = np.asarray(duties, dtype=float)
    if t.ndim != 1 or t.shape[0] < 2:
        raise InputError(f"{source}: needs at least two rows (a start and an end time)")
    if u.shape != (t.shape[0], 4):
        raise InputError(f"{source}: duties have shape {u.shape}, expected ({t.shape[0]}, 4)")
    with np.errstate(invalid="ignore"):  # the rows at fault, at array speed; the first one named below
        bad = ~np.isfinite(t) | np.r_[False, ~(t[1:] > t[:-1])] | ~np.all((u >= 0.0) & (u <= 1.0), axis=1)
    for k in range(int(np.argmax(bad)) if bad.any() else t.shape[0], t.shape[0]):
        where = f"{source}, line {lines[k]}" if lines else f"{source}, row {k + 1}"
        if not math.isfinite(t[k]):
            raise InputError(f"{where}, column 't': time is not finite ({checks.short_number(t[k])})")
        if k and t[k] <= t[k - 1]:
            raise InputError(f"{where}, column 't': time {t[k]:g} is not after the previous row's {t[k - 1]:g}")
        for j in range(4):
            if not math.isfinite(u[k, j]):
                raise InputError(f"{where}, column 'u{j + 1}': duty is not finite ({checks.short_number(u[k, j])})")
            if not 0.0 <= u[k, j] <= 1.0:
                raise InputError(f"{where}, column 'u{j + 1}': duty {u[k, j]:g} is outside [0, 1]")
    return t, u


def read_duty_csv(path: str | os.PathLike, progress: Callable[[int, int], None] | None = None) -> DutySchedule:
    """Read a ``t,u1,u2,u3,u4`` CSV; errors name the file, line and column.

    Parameters
    ----------
    path : str or os.PathLike
        The CSV file: a header naming at least ``t, u1, u2, u3, u4`` (others are ignored
        with a warning), then at least two rows of times [s] and duties [-].
    progress : callable, optional
        ``progress(done, total)``: the rows read (:func:`~quadcruise.io.files.read_numeric_csv`).

    Returns
    -------
    DutySchedule
        With ``source`` the file name.
    """
    checks.instance("read_duty_csv()", "path", path, (str, os.PathLike), optional=False, want="a path")
    checks.callback("read_duty_csv()", "progress", progress)
    _, _, data, lines = read_numeric_csv(path, INPUT_COLUMNS, progress=progress)
    if data.shape[0] < 2:
        raise InputError(f"{path}: needs at least two data rows (a start and an end time), found {data.shape[0]}")
    _validated(data[:, 0], data[:, 1:], str(path), lines)
    return DutySchedule(t=data[:, 0], duties=data[:, 1:], source=str(path))


MAX_SUBSTEPS = 2.0e10
"""The most RK4 substeps a replay may take (at about ten million a second, half an hour or more)."""


def replay(
    schedule: DutySchedule | str | os.PathLike,
    vehicle: Vehicle | None = None,
    *,
    max_step: float = 1e-3,
    limits: Limits | None = None,
    full_dynamics: bool = False,
    progress: Callable[[int, int], None] | None = None,
) -> SimResult:
    """Fly the duty schedule open loop and log the state at every schedule row.

    Parameters
    ----------
    schedule : DutySchedule or str or os.PathLike
        The duties and their times, or the path of a ``t,u1,u2,u3,u4`` CSV file
        (read by :func:`read_duty_csv`).
    vehicle : Vehicle, optional
        Table I by default. A batched vehicle replays the same schedule on each.
    max_step : float
        Longest RK4 substep [s]; each row interval is split into equal substeps.
    limits : Limits, optional
        Divergence bounds; by default :class:`Limits` without the tilt bound: recorded duties
        may flip the vehicle on purpose, and a replay is a model's check, not a mission.
    full_dynamics : bool
        Fly the plant with the exact Euler-angle kinematics instead of the paper's.
    progress : callable, optional
        ``progress(done, total)``: the schedule's rows flown, 0 before the flight and all
        of them after it (the engine flies them in one call).

    Returns
    -------
    SimResult
        One logged instant per schedule row (the first is the initial state); the
        references are NaN.
    """
    w = "replay()"  # every argument checked before any work
    checks.instance(
        w,
        "schedule",
        schedule,
        (DutySchedule, str, os.PathLike),
        optional=False,
        want="a DutySchedule or the path of a t,u1,u2,u3,u4 CSV file",
    )
    vehicle = checks.instance(w, "vehicle", vehicle, Vehicle) or Vehicle.paper()
    max_step = checks.number(w, "max_step", max_step, "pos", unit="s")
    checks.instance(w, "limits", limits, Limits)
    full_dynamics = checks.flag(w, "full_dynamics", full_dynamics)
    checks.callback(w, "progress", progress)
    if not isinstance(schedule, DutySchedule):
        schedule = read_duty_csv(schedule)
    vp = vehicle.rows()
    x0 = np.zeros((vp.shape[0], STATE_SIZE))
    x0[:, F1 : F1 + 4] = vp[:, [P_K]] * schedule.duties[0]  # thrust K * u of the first row
    meta = {
        "workflow": "replay",
        "source": schedule.source,
        "vehicle": vehicle.to_dict(),
        "max_step_s": max_step,
        "full_dynamics": bool(full_dynamics),
        "version": __version__,
    }
    rows = schedule.t.shape[0]
    substeps = float(np.sum(np.ceil(np.diff(schedule.t) / max_step - 1e-9)))
    if substeps > MAX_SUBSTEPS:
        raise InputError(
            f"{schedule.source}: {schedule.t[-1] - schedule.t[0]:g} s of duties at max_step "
            f"{max_step:g} s is {substeps:.3g} RK4 substeps, hours of computing: a larger "
            "--max-step or a shorter table"
        )
    if progress is not None:
        progress(0, rows)
    result = simulate(
        schedule.t,
        x0,
        vp,
        duty_schedule,
        pack_schedule(schedule.t, schedule.duties),
        no_reference,
        np.zeros(1),
        memory=np.zeros(1),
        max_step=max_step,
        limits=Limits(max_tilt=math.inf) if limits is None else limits,
        meta=meta,
        full_dynamics=full_dynamics,
    )
    if progress is not None:
        progress(rows, rows)
    return result


def write_states_csv(
    result: SimResult, path: str | os.PathLike, vehicle: int = 0, progress: Callable[[int, int], None] | None = None
) -> None:
    """Write one vehicle's states as ``t,x,...,F4`` (SI units, radians), atomically.

    Parameters
    ----------
    result : SimResult
        The flight.
    path : str or os.PathLike
        The CSV file to write.
    vehicle : int
        The vehicle's index.
    progress : callable, optional
        ``progress(done, total)``: the rows written, about every hundredth of them.
    """
    table = np.column_stack([result.t, result.states[vehicle]])
    rows = table.shape[0]
    block = max(1000, -(-rows // 100))
    with atomic_path(path) as tmp, open(tmp, "wb") as f:
        for start in range(0, rows, block):
            if progress is not None:
                progress(start, rows)
            np.savetxt(
                f,
                table[start : start + block],
                delimiter=",",
                fmt="%.15g",
                comments="",
                header=",".join(OUTPUT_COLUMNS) if start == 0 else "",
            )
        if progress is not None:
            progress(rows, rows)


# --- rotor-plant vehicles: commanded rotor speeds ---------------------------------------------
@dataclass(frozen=True, eq=False)
class SpeedSchedule:
    """Piecewise-constant commanded rotor speeds: row k holds from t[k] until t[k+1].

    Parameters
    ----------
    t : array_like, shape (L,)
        Strictly increasing, finite times [s], L >= 2.
    speeds : array_like, shape (L, n)
        Commanded speeds of rotors 1..n [rad/s], finite (the vehicle's range is checked by
        :func:`replay_rotors`).
    source : str
        Where the rows came from (a file name), used in error messages.
    lines : tuple of int, optional
        The file line of each row, for error messages.

    Raises
    ------
    InputError
        A schedule that breaks these rules, naming ``source`` and the row (or line) and column.
    """

    t: np.ndarray
    speeds: np.ndarray
    source: str = "schedule"
    lines: tuple = ()

    def __post_init__(self) -> None:
        t = np.asarray(self.t, dtype=float)
        w = np.asarray(self.speeds, dtype=float)
        if t.ndim != 1 or t.shape[0] < 2:
            raise InputError(f"{self.source}: needs at least two rows (a start and an end time)")
        if w.ndim != 2 or w.shape[0] != t.shape[0]:
            raise InputError(f"{self.source}: rotor speeds have shape {w.shape}, expected ({t.shape[0]}, n)")
        with np.errstate(invalid="ignore"):
            bad = ~np.isfinite(t) | np.r_[False, ~(t[1:] > t[:-1])] | ~np.all(np.isfinite(w), axis=1)
        if bad.any():
            k = int(np.argmax(bad))
            where = self.where(k)
            if not math.isfinite(t[k]):
                raise InputError(f"{where}, column 't': time is not finite ({checks.short_number(t[k])})")
            if k and not t[k] > t[k - 1]:
                raise InputError(f"{where}, column 't': time {t[k]:g} is not after the previous row's {t[k - 1]:g}")
            j = int(np.argmax(~np.isfinite(w[k])))
            raise InputError(f"{where}, column 'w{j + 1}': rotor speed is not finite ({checks.short_number(w[k, j])})")
        object.__setattr__(self, "t", t)
        object.__setattr__(self, "speeds", w)

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


def read_speed_csv(
    path: str | os.PathLike, n_rotors: int, progress: Callable[[int, int], None] | None = None
) -> SpeedSchedule:
    """Read a ``t,w1,..,wn`` CSV of commanded rotor speeds; errors name the file, line and column.

    Parameters
    ----------
    path : str or os.PathLike
        The CSV file: a header naming ``t`` and ``w1`` .. ``wn`` (other columns are ignored
        with a warning, but a column ``w<n+1>`` is refused: the file is for another vehicle),
        then at least two rows of times [s] and speeds [rad/s].
    n_rotors : int
        The vehicle's number of rotors, n.
    progress : callable, optional
        ``progress(done, total)``: the rows read.

    Returns
    -------
    SpeedSchedule
        With ``source`` the file name and the file line of each row.
    """
    w = "read_speed_csv()"
    checks.instance(w, "path", path, (str, os.PathLike), optional=False, want="a path")
    n_rotors = checks.whole(w, "n_rotors", n_rotors, 1)
    checks.callback(w, "progress", progress)
    data, lines = _rotor_table(path, n_rotors, "w", progress)
    return SpeedSchedule(t=data[:, 0], speeds=data[:, 1:], source=str(path), lines=tuple(lines))


def _rotor_table(path, n_rotors: int, letter: str, progress) -> tuple[np.ndarray, list]:
    """The rows of a ``t,<letter>1..<letter>n`` CSV and their file lines; a column for a rotor the
    vehicle lacks, or fewer than two rows, refused naming the file."""
    columns = ("t",) + tuple(f"{letter}{i + 1}" for i in range(n_rotors))
    _, used, data, lines = read_numeric_csv(path, columns, (f"{letter}{n_rotors + 1}",), progress=progress)
    if len(used) > len(columns):
        raise InputError(
            f"{path}: column '{used[len(columns)]}', but the vehicle has {n_rotors} rotors "
            f"(columns {', '.join(columns)})"
        )
    if data.shape[0] < 2:
        raise InputError(f"{path}: needs at least two data rows (a start and an end time), found {data.shape[0]}")
    return data, lines


def read_rotor_csv(
    path: str | os.PathLike, vehicle: RotorVehicle, progress: Callable[[int, int], None] | None = None
) -> SpeedSchedule:
    """Read a rotor-plant vehicle's commands: ``t,w1,..,wn`` rotor speeds [rad/s], or ``t,u1,..,un``
    normalised commands (duties in [0, 1]) turned into speeds by the vehicle's command-to-speed map
    (:meth:`~quadcruise.model.rotor_vehicle.RotorVehicle.command_speed`).

    Parameters
    ----------
    path : str or os.PathLike
        The CSV file (a header, then at least two rows).
    vehicle : RotorVehicle
        The vehicle: its rotor count and command-to-speed map.
    progress : callable, optional
        ``progress(done, total)``: the rows read.

    Returns
    -------
    SpeedSchedule
        The commanded speeds, with ``source`` the file name and each row's file line.

    Raises
    ------
    InputError
        A missing or extra column, a duty outside [0, 1] or not finite (naming the line and
        column), or times that do not increase.
    """
    n = vehicle.n_rotors
    try:
        with open(path, newline="", encoding="utf-8-sig") as f:
            header = [c.strip() for c in f.readline().split(",")]
    except (OSError, UnicodeDecodeError):  # read_speed_csv names what is wrong with the file
        header = []
    if "w1" in header or "u1" not in header:
        return read_speed_csv(path, n, progress)
    data, lines = _rotor_table(path, n, "u", progress)
    u = data[:, 1:]
    bad = ~(np.isfinite(u) & (u >= 0.0) & (u <= 1.0))
    if bad.any():
        k, j = (int(i) for i in np.argwhere(bad)[0])
        raise InputError(f"{path}, line {lines[k]}, column 'u{j + 1}': duty {float(u[k, j])!r} is not in [0, 1]")
    return SpeedSchedule(t=data[:, 0], speeds=vehicle.command_speed(u), source=str(path), lines=tuple(lines))


ROTOR_MAX_STEP = 1e-4
"""Default longest RK4 substep [s] of a rotor-plant replay (why: docs/vehicles.md, "Step")."""


def replay_rotors(
    schedule: SpeedSchedule | str | os.PathLike,
    vehicle: RotorVehicle,
    *,
    max_step: float = ROTOR_MAX_STEP,
    limits: Limits | None = None,
    wind=(0.0, 0.0, 0.0),
    ground: bool = False,
    progress: Callable[[int, int], None] | None = None,
) -> RotorResult:
    """Fly the commanded rotor speeds open loop on the rotor-speed plant and log every row.

    The vehicle starts at rest at the origin, level (the identity quaternion), each rotor at
    its first commanded speed.

    Parameters
    ----------
    schedule : SpeedSchedule, str or os.PathLike
        The commanded speeds [rad/s] and their times [s]; every speed within the vehicle's
        [w_min, w_max]; or the path of a ``t,w1,..,wn`` CSV of them (:func:`read_speed_csv`).
    vehicle : RotorVehicle
        The vehicle (:meth:`quadcruise.Vehicle.preset`); its rotor count must be the
        schedule's.
    max_step : float
        Longest RK4 substep [s] (:data:`ROTOR_MAX_STEP` by default); each row interval is
        split into equal substeps.
    limits : Limits, optional
        Divergence bounds (position, speed, body rate).
    wind : sequence of 3 floats
        A steady wind [m/s], world frame; it acts through the vehicle's aerodynamics.
    ground : bool
        A ground at z = 0: the vehicle starts on it, rests on it while its thrust is under
        its weight, and meeting it faster than the vehicle's ``touchdown_speed`` or upside
        down ends the flight ``CRASHED`` (:func:`quadcruise.sim.rotor_engine.ground_contact`).
    progress : callable, optional
        ``progress(done, total)``: the schedule's rows flown (0, then all of them).

    Returns
    -------
    RotorResult
        One logged state per schedule row, columns ``x .. r, w1 .. wn``.

    Raises
    ------
    InputError
        A rotor count that does not match, a speed outside the vehicle's range (naming the
        row and column), a bad wind or step.
    """
    w = "replay_rotors()"  # every argument checked before any work
    checks.instance(
        w,
        "schedule",
        schedule,
        (SpeedSchedule, str, os.PathLike),
        optional=False,
        want="a SpeedSchedule or the path of a t,w1,..,wn CSV file",
    )
    if not isinstance(vehicle, RotorVehicle):
        raise InputError(f"replay_rotors needs a rotor-plant vehicle (RotorVehicle), got {type(vehicle).__name__}")
    max_step = checks.number(w, "max_step", max_step, "pos", unit="s")
    checks.instance(w, "limits", limits, Limits)
    ground = checks.flag(w, "ground", ground)
    checks.callback(w, "progress", progress)
    if isinstance(wind, (str, bytes)) or not np.iterable(wind):
        checks.fail(w, "wind", wind, "3 finite numbers [m/s]")
    try:
        wind = np.asarray(wind, dtype=float)
    except (TypeError, ValueError):
        checks.fail(w, "wind", wind, "3 finite numbers [m/s]")
    if wind.shape != (3,) or not np.all(np.isfinite(wind)):
        raise InputError(f"wind must be 3 finite numbers [m/s], got {wind.tolist()!r}")
    if not isinstance(schedule, SpeedSchedule):
        schedule = read_speed_csv(schedule, vehicle.n_rotors)
    n = vehicle.n_rotors
    if schedule.speeds.shape[1] != n:
        raise InputError(
            f"{schedule.source}: {schedule.speeds.shape[1]} rotor speed columns, but the vehicle has {n} rotors"
        )
    outside = (schedule.speeds < vehicle.w_min) | (schedule.speeds > vehicle.w_max)
    if outside.any():
        k, j = (int(a[0]) for a in np.nonzero(outside))
        raise InputError(
            f"{schedule.where(k)}, column 'w{j + 1}': rotor speed {schedule.speeds[k, j]:g} rad/s is "
            f"outside the vehicle's [{vehicle.w_min:g}, {vehicle.w_max:g}]"
        )
    substeps = float(np.sum(np.ceil(np.diff(schedule.t) / max_step - 1e-9)))
    if substeps > MAX_SUBSTEPS:
        raise InputError(
            f"{schedule.source}: {schedule.t[-1] - schedule.t[0]:g} s of rotor speeds at max_step "
            f"{max_step:g} s is {substeps:.3g} RK4 substeps, hours of computing: a larger "
            "--max-step or a shorter table"
        )
    x0 = np.zeros(ROTOR_W1 + n)
    x0[QW] = 1.0
    x0[ROTOR_W1:] = schedule.speeds[0]
    ext = np.r_[np.zeros(6), wind, np.ones(n)]
    meta = {
        "workflow": "replay",
        "plant": "rotor",
        "source": schedule.source,
        "vehicle": vehicle.to_dict(),
        "max_step_s": max_step,
        "wind": wind.tolist(),
        "ground": bool(ground),
        "version": __version__,
    }
    rows = schedule.t.shape[0]
    if progress is not None:
        progress(0, rows)
    result = replay_rotor_speeds(
        schedule.t,
        schedule.speeds,
        x0,
        vehicle.row(),
        ext=ext,
        max_step=max_step,
        limits=limits,
        touchdown_speed=vehicle.touchdown_speed if ground else None,
        names=state_names(n),
        meta=meta,
    )
    if progress is not None:
        progress(rows, rows)
    return result


def write_rotor_states_csv(result: RotorResult, path: str | os.PathLike, vehicle: int = 0) -> None:
    """Write one vehicle's states as ``t,x,y,z,vx,vy,vz,qw,qx,qy,qz,p,q,r,w1..wn,phi,theta,psi``
    (SI units, radians; the Euler angles ZYX), atomically.

    Parameters
    ----------
    result : RotorResult
        The flight.
    path : str or os.PathLike
        The CSV file to write.
    vehicle : int
        The vehicle's index.
    """
    frame = result.to_pandas(vehicle).drop(columns="vehicle")
    with atomic_path(path) as tmp, open(tmp, "wb") as f:
        np.savetxt(f, frame.to_numpy(), delimiter=",", fmt="%.15g", comments="", header=",".join(frame.columns))
