"""Open-loop replay, the model-validation workflow: PWM duties in, states out.

Input: a schedule of rows ``t, u1, u2, u3, u4``; each row's duties hold from its t until
the next row's. The vehicle starts at rest at the origin, level, each rotor's thrust
already at K * u_i of the first row, in free flight (no ground). Output: one state per
input row, the first being the initial state; the last row only marks the end time.

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

from quadcruise._version import __version__
from quadcruise.control.openloop import duty_schedule, pack_schedule
from quadcruise.errors import InputError
from quadcruise.io.files import atomic_path, read_numeric_csv
from quadcruise.layout import F1, P_K, STATE_NAMES, STATE_SIZE
from quadcruise.model.vehicle import Vehicle
from quadcruise.sim.engine import Limits, simulate
from quadcruise.sim.result import SimResult

INPUT_COLUMNS = ("t", "u1", "u2", "u3", "u4")
OUTPUT_COLUMNS = ("t",) + STATE_NAMES


@njit(cache=True)     # compiled (as MISSION_SIG) on first use, not at import
def no_reference(t, mp, ref):
    """An open-loop flight has no reference: NaN throughout (a mission, ``MISSION_SIG``).

    Parameters
    ----------
    t : float
        Time [s] (unused).
    mp : ndarray
        Mission parameters (unused).
    ref : ndarray, shape (11,)
        Output: the reference, set to NaN.
    """
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
    with np.errstate(invalid="ignore"):      # the rows at fault, at array speed; the first one named below
        bad = ~np.isfinite(t) | np.r_[False, ~(t[1:] > t[:-1])] | ~np.all((u >= 0.0) & (u <= 1.0), axis=1)
    for k in range(int(np.argmax(bad)) if bad.any() else t.shape[0], t.shape[0]):
        where = f"{source}, line {lines[k]}" if lines else f"{source}, row {k + 1}"
        if not math.isfinite(t[k]):
            raise InputError(f"{where}, column 't': time is not finite ({t[k]!r})")
        if k and t[k] <= t[k - 1]:
            raise InputError(f"{where}, column 't': time {t[k]:g} is not after the previous row's {t[k - 1]:g}")
        for j in range(4):
            if not math.isfinite(u[k, j]):
                raise InputError(f"{where}, column 'u{j + 1}': duty is not finite ({u[k, j]!r})")
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
    _, _, data, lines = read_numeric_csv(path, INPUT_COLUMNS, progress=progress)
    if data.shape[0] < 2:
        raise InputError(f"{path}: needs at least two data rows (a start and an end time), found {data.shape[0]}")
    _validated(data[:, 0], data[:, 1:], str(path), lines)
    return DutySchedule(t=data[:, 0], duties=data[:, 1:], source=str(path))


MAX_SUBSTEPS = 2.0e10
"""The most RK4 substeps a replay may take (at about ten million a second, half an hour or more)."""


def replay(schedule: DutySchedule, vehicle: Vehicle | None = None, *, max_step: float = 1e-3,
           limits: Limits | None = None, full_dynamics: bool = False,
           progress: Callable[[int, int], None] | None = None) -> SimResult:
    """Fly the duty schedule open loop and log the state at every schedule row.

    Parameters
    ----------
    schedule : DutySchedule
        The duties and their times.
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
    vehicle = vehicle or Vehicle.paper()
    vp = vehicle.rows()
    x0 = np.zeros((vp.shape[0], STATE_SIZE))
    x0[:, F1:F1 + 4] = vp[:, [P_K]] * schedule.duties[0]   # thrust K * u of the first row
    meta = {
        "workflow": "replay",
        "source": schedule.source,
        "vehicle": vehicle.to_dict(),
        "max_step_s": max_step,
        "full_dynamics": bool(full_dynamics),
        "version": __version__,
    }
    rows = schedule.t.shape[0]
    if isinstance(max_step, (int, float)) and max_step > 0:     # (simulate refuses the others)
        substeps = float(np.sum(np.ceil(np.diff(schedule.t) / max_step - 1e-9)))
        if substeps > MAX_SUBSTEPS:
            raise InputError(f"{schedule.source}: {schedule.t[-1] - schedule.t[0]:g} s of duties at max_step "
                             f"{max_step:g} s is {substeps:.3g} RK4 substeps, hours of computing: a larger "
                             "--max-step or a shorter table")
    if progress is not None:
        progress(0, rows)
    result = simulate(schedule.t, x0, vp, duty_schedule, pack_schedule(schedule.t, schedule.duties),
                      no_reference, np.zeros(1), memory=np.zeros(1), max_step=max_step,
                      limits=Limits(max_tilt=math.inf) if limits is None else limits, meta=meta,
                      full_dynamics=full_dynamics)
    if progress is not None:
        progress(rows, rows)
    return result


def write_states_csv(result: SimResult, path: str | os.PathLike, vehicle: int = 0,
                     progress: Callable[[int, int], None] | None = None) -> None:
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
            np.savetxt(f, table[start:start + block], delimiter=",", fmt="%.15g", comments="",
                       header=",".join(OUTPUT_COLUMNS) if start == 0 else "")
        if progress is not None:
            progress(rows, rows)
