"""Open-loop replay, the model-validation workflow: commands in, states out.

Input: a command table (:mod:`quadcruise.workflows.commands`), rows ``t, u1 .. u4`` of PWM
duties or ``t, w1 .. wn`` of commanded rotor speeds [rad/s], as a CSV file, a pandas DataFrame
or a :class:`~quadcruise.workflows.commands.CommandSchedule`; each row's commands hold from its
t until the next row's. The vehicle chooses the plant: the paper's for a
:class:`~quadcruise.model.vehicle.Vehicle` (duties), the rotor-speed plant for a
:class:`~quadcruise.model.rotor_vehicle.RotorVehicle` (speeds, or duties turned into speeds by
its command-to-speed map). The vehicle starts at rest at the origin, level, each rotor already
at the first row's command (thrust K * u_i, or speed w_i), in free flight (no ground unless
asked). Output: one state per input row, the first being the initial state; the last row only
marks the end time.

Examples
--------
>>> import quadcruise as qc
>>> v = qc.Vehicle.paper()
>>> hover = [[float(v.hover_duty)] * 4] * 3
>>> res = qc.replay(qc.CommandSchedule(t=[0.0, 1.0, 2.0], duties=hover), vehicle=v)
>>> bool(abs(res.final_state[0, 2]) < 1e-9)    # hover stays put
True
"""

from __future__ import annotations

import math
import os
from collections.abc import Callable
from typing import Any

import numpy as np
from numba import njit

from quadcruise import checks
from quadcruise._version import __version__
from quadcruise.control.openloop import duty_schedule, pack_schedule
from quadcruise.errors import InputError
from quadcruise.io.files import atomic_path
from quadcruise.layout import F1, P_K, STATE_NAMES, STATE_SIZE
from quadcruise.model.rotor_plant import QW, ROTOR_W1, state_names
from quadcruise.model.rotor_vehicle import RotorVehicle
from quadcruise.model.vehicle import Vehicle
from quadcruise.sim.engine import simulate
from quadcruise.sim.inputs import Limits
from quadcruise.sim.result import SimResult
from quadcruise.sim.rotor_engine import replay_rotor_speeds
from quadcruise.sim.rotor_result import EULER_NAMES, RotorResult
from quadcruise.workflows.commands import (
    ROTOR_VEHICLES,
    CommandSchedule,
    DutySchedule,
    SpeedSchedule,
    deprecated,
    read_commands,
    read_duty_csv,
    read_rotor_csv,
    read_speed_csv,
    replay_plant,
)

__all__ = [
    "CommandSchedule",
    "DutySchedule",
    "SpeedSchedule",
    "read_commands",
    "read_duty_csv",
    "read_rotor_csv",
    "read_speed_csv",
    "replay",
    "replay_rotors",
    "write_rotor_states_csv",
    "write_states_csv",
]

INPUT_COLUMNS = ("t", "u1", "u2", "u3", "u4")
"""The paper's plant's command table."""

OUTPUT_COLUMNS = ("t",) + STATE_NAMES
"""The paper's plant's states, as :func:`write_states_csv` writes them."""


@njit(cache=True)  # compiled (as MISSION_SIG) on first use, not at import
def no_reference(t, mp, ref):
    """An open-loop flight's reference (a mission, ``MISSION_SIG``): NaN throughout."""
    for j in range(ref.shape[0]):
        ref[j] = math.nan


MAX_SUBSTEPS = 2.0e10
"""The most RK4 substeps a replay may take (at about ten million a second, half an hour or more)."""

ROTOR_MAX_STEP = 1e-4
"""Default longest RK4 substep [s] of a rotor-plant replay (why: docs/vehicles.md, "Step")."""

PAPER_MAX_STEP = 1e-3
"""Default longest RK4 substep [s] of a paper-plant replay."""


def replay(
    commands: Any,
    vehicle: Any = None,
    *,
    max_step: float | None = None,
    limits: Limits | None = None,
    full_dynamics: bool = False,
    wind=None,
    ground: bool = False,
    progress: Callable[[int, int], None] | None = None,
) -> SimResult | RotorResult:
    """Fly a command table open loop on the vehicle's plant and log the state at every row.

    Parameters
    ----------
    commands : CommandSchedule, str, os.PathLike or pandas.DataFrame
        The commands and their times: a schedule, or a CSV file or DataFrame read by its
        columns (:func:`~quadcruise.workflows.commands.read_commands`): ``t,u1,u2,u3,u4``
        (PWM duties in [0, 1]) or ``t,w1,..,wn`` (commanded rotor speeds [rad/s]).
    vehicle : Vehicle, RotorVehicle or str, optional
        The vehicle, or a preset's name or vehicle file (:meth:`quadcruise.Vehicle.load`);
        Table I by default. A :class:`~quadcruise.Vehicle` flies the paper's plant (duties
        only; a batched one replays the same table on each); a rotor-plant vehicle flies the
        rotor-speed plant (speeds within its [w_min, w_max], or duties u as speeds u w_max).
    max_step : float, optional
        Longest RK4 substep [s]; each row interval is split into equal substeps. Default:
        1e-3 s on the paper's plant, :data:`ROTOR_MAX_STEP` on the rotor plant.
    limits : Limits, optional
        Divergence bounds; by default on the paper's plant :class:`Limits` without the tilt
        bound: recorded duties may flip the vehicle on purpose, and a replay is a model's
        check, not a mission.
    full_dynamics : bool
        The paper's plant with the exact Euler-angle kinematics instead of the paper's (the
        rotor plant's quaternion kinematics are exact already).
    wind : sequence of 3 floats, optional
        A steady wind [m/s], world frame, acting through a rotor-plant vehicle's aerodynamics.
    ground : bool
        A ground at z = 0 (rotor plant): the vehicle starts on it, rests on it while its
        thrust is under its weight, and meeting it faster than the vehicle's
        ``touchdown_speed`` or upside down ends the flight ``CRASHED``
        (:func:`quadcruise.sim.rotor_engine.ground_contact`).
    progress : callable, optional
        ``progress(done, total)``: the table's rows flown, 0 before the flight and all of them
        after it (the engine flies them in one call).

    Returns
    -------
    SimResult or RotorResult
        One logged instant per row (the first is the initial state): a :class:`SimResult` on
        the paper's plant (references NaN), a :class:`RotorResult` on the rotor plant
        (columns ``x .. r, w1 .. wn``).

    Raises
    ------
    InputError
        A table whose columns fit no plant, a speed table for the paper's plant, a rotor
        count that is not the vehicle's, a speed outside its range (naming the row and
        column), an option its plant lacks, a bad wind or step.
    """
    return _replay(commands, vehicle, max_step, limits, full_dynamics, wind, ground, progress, "replay()")


def _replay(commands, vehicle, max_step, limits, full_dynamics, wind, ground, progress, w: str):
    """:func:`replay`, its messages naming ``w`` (the deprecated names' too)."""
    import pandas as pd

    checks.instance(  # every argument checked before any work
        w,
        "commands",
        commands,
        (CommandSchedule, str, os.PathLike, pd.DataFrame),
        optional=False,
        want="a CommandSchedule, a pandas DataFrame or the path of a t,u1..u4 or t,w1..wn CSV file",
    )
    if vehicle is None:
        vehicle = Vehicle.paper()
    elif isinstance(vehicle, (str, os.PathLike)):
        vehicle = Vehicle.load(vehicle)
    checks.instance(w, "vehicle", vehicle, (Vehicle, RotorVehicle), want="a Vehicle, a RotorVehicle or a preset's name")
    plant = replay_plant(vehicle)
    max_step = plant.max_step if max_step is None else checks.number(w, "max_step", max_step, "pos", unit="s")
    checks.instance(w, "limits", limits, Limits)
    full_dynamics = checks.flag(w, "full_dynamics", full_dynamics)
    ground = checks.flag(w, "ground", ground)
    checks.callback(w, "progress", progress)
    if wind is not None:
        wind = _wind(w, wind)
    if not plant.takes_speeds and ground:
        raise InputError(
            f"{w} argument ground: the paper's plant replays without a ground: give a rotor-plant "
            f"vehicle ({ROTOR_VEHICLES})"
        )
    if not plant.takes_speeds and wind is not None:
        raise InputError(
            f"{w} argument wind: the paper's plant replays in still air (its wind acts through a drag "
            "model: qc.fly with an Environment and disturbances.with_drag); a rotor-plant vehicle "
            f"replays in wind ({ROTOR_VEHICLES})"
        )
    if plant.takes_speeds and full_dynamics:
        raise InputError(
            f"{w} argument full_dynamics: the rotor plant's kinematics (quaternions) are exact already; "
            "full_dynamics applies to the paper's plant"
        )
    schedule = commands if isinstance(commands, CommandSchedule) else read_commands(commands, vehicle)
    if schedule.speeds is not None and not plant.takes_speeds:
        raise InputError(
            f"{schedule.source}: rotor speeds (columns t,w1..w{schedule.n_rotors}), which the paper's plant "
            f"does not fly: it replays PWM duties, columns t,u1,u2,u3,u4; for speeds give a rotor-plant "
            f"vehicle ({ROTOR_VEHICLES})"
        )
    if schedule.n_rotors != plant.n_rotors:
        raise InputError(
            f"{schedule.source}: {schedule.n_rotors} {schedule.kind} columns ({schedule.columns[1]}..), "
            f"but the vehicle has {plant.n_rotors} rotors (columns {','.join(_columns(schedule, plant.n_rotors))})"
        )
    substeps = float(np.sum(np.ceil(np.diff(schedule.t) / max_step - 1e-9)))
    if substeps > MAX_SUBSTEPS:
        raise InputError(
            f"{schedule.source}: {schedule.t[-1] - schedule.t[0]:g} s of {schedule.kind} at max_step "
            f"{max_step:g} s is {substeps:.3g} RK4 substeps, hours of computing: a larger "
            "--max-step or a shorter table"
        )
    fly = _rotor_replay if plant.takes_speeds else _paper_replay
    return fly(schedule, vehicle, max_step, limits, full_dynamics, wind, ground, progress)


def _columns(schedule: CommandSchedule, n: int) -> tuple:
    letter = schedule.columns[1][0]
    return ("t",) + tuple(f"{letter}{j + 1}" for j in range(n))


def _wind(w: str, wind) -> np.ndarray:
    """A steady wind checked: 3 finite numbers [m/s]."""
    if isinstance(wind, (str, bytes)) or not np.iterable(wind):
        checks.fail(w, "wind", wind, "3 finite numbers [m/s]")
    try:
        wind = np.asarray(wind, dtype=float)
    except (TypeError, ValueError):
        checks.fail(w, "wind", wind, "3 finite numbers [m/s]")
    if wind.shape != (3,) or not np.all(np.isfinite(wind)):
        raise InputError(f"wind must be 3 finite numbers [m/s], got {wind.tolist()!r}")
    return wind


def _paper_replay(schedule, vehicle, max_step, limits, full_dynamics, wind, ground, progress) -> SimResult:
    """The paper's plant: the duties through the engine, with an open-loop controller."""
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


def _rotor_replay(schedule, vehicle, max_step, limits, full_dynamics, wind, ground, progress) -> RotorResult:
    """The rotor-speed plant: the commanded speeds (duties u as u w_max) through its own engine."""
    speeds = schedule.speeds if schedule.speeds is not None else vehicle.command_speed(schedule.duties)
    outside = (speeds < vehicle.w_min) | (speeds > vehicle.w_max)
    if outside.any():
        k, j = (int(a[0]) for a in np.nonzero(outside))
        asked = "" if schedule.speeds is not None else f"duty {schedule.duties[k, j]:g} asks for "
        raise InputError(
            f"{schedule.where(k)}, column '{schedule.columns[j + 1]}': {asked}rotor speed {speeds[k, j]:g} rad/s "
            f"is outside the vehicle's [{vehicle.w_min:g}, {vehicle.w_max:g}]"
        )
    wind = np.zeros(3) if wind is None else wind
    n = vehicle.n_rotors
    x0 = np.zeros(ROTOR_W1 + n)
    x0[QW] = 1.0
    x0[ROTOR_W1:] = speeds[0]
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
        speeds,
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


def write_states_csv(
    result: SimResult | RotorResult,
    path: str | os.PathLike,
    vehicle: int = 0,
    progress: Callable[[int, int], None] | None = None,
) -> None:
    """Write one vehicle's states as a CSV (SI units, radians), atomically.

    The columns are ``t,x,y,z,vx,vy,vz,phi,theta,psi,p,q,r,F1..F4`` for the paper's plant,
    ``t,x,y,z,vx,vy,vz,qw,qx,qy,qz,p,q,r,w1..wn,phi,theta,psi`` for the rotor plant (the
    Euler angles ZYX beside the quaternion).

    Parameters
    ----------
    result : SimResult or RotorResult
        The flight (:func:`replay`'s).
    path : str or os.PathLike
        The CSV file to write.
    vehicle : int
        The vehicle's index.
    progress : callable, optional
        ``progress(done, total)``: the rows written, about every hundredth of them.

    Raises
    ------
    InputError
        A vehicle index the result does not hold.
    """
    vehicle = checks.whole("write_states_csv()", "vehicle", vehicle)
    if vehicle >= result.n:
        raise InputError(f"vehicle {vehicle} is not in this flight of {result.n} vehicles")
    if isinstance(result, RotorResult):  # the quaternion's state, and its Euler angles beside it
        header = ("t",) + tuple(result.names) + EULER_NAMES
        table = np.column_stack([result.t, result.states[vehicle], result.euler(vehicle)])
    else:
        header, table = OUTPUT_COLUMNS, np.column_stack([result.t, result.states[vehicle]])
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
                header=",".join(header) if start == 0 else "",
            )
        if progress is not None:
            progress(rows, rows)


# --- the names before one replay and one writer (deprecated for one release) ---------------------
def replay_rotors(
    schedule: Any,
    vehicle: RotorVehicle,
    *,
    max_step: float = ROTOR_MAX_STEP,
    limits: Limits | None = None,
    wind=(0.0, 0.0, 0.0),
    ground: bool = False,
    progress: Callable[[int, int], None] | None = None,
) -> RotorResult:
    """Deprecated: :func:`replay` with a rotor-plant vehicle.

    Parameters
    ----------
    schedule : CommandSchedule, str or os.PathLike
        Commanded speeds, or the path of a ``t,w1,..,wn`` CSV.
    vehicle : RotorVehicle
        The vehicle.
    max_step : float
        Longest RK4 substep [s].
    limits : Limits, optional
        Divergence bounds.
    wind : sequence of 3 floats
        A steady wind [m/s].
    ground : bool
        A ground at z = 0.
    progress : callable, optional
        ``progress(done, total)``.

    Returns
    -------
    RotorResult
    """
    deprecated("replay_rotors(schedule, vehicle)", "replay(commands, vehicle=...)")
    w = "replay_rotors()"
    checks.instance(
        w,
        "schedule",
        schedule,
        (CommandSchedule, str, os.PathLike),
        optional=False,
        want="a SpeedSchedule or the path of a t,w1,..,wn CSV file",
    )
    if not replay_plant(vehicle).takes_speeds:  # the one plant question, replay_plant's
        raise InputError(f"replay_rotors needs a rotor-plant vehicle (RotorVehicle), got {type(vehicle).__name__}")
    if max_step is None:
        checks.fail(w, "max_step", max_step, "a number > 0 [s]")
    return _replay(schedule, vehicle, max_step, limits, False, wind, ground, progress, w)


def write_rotor_states_csv(result: RotorResult, path: str | os.PathLike, vehicle: int = 0) -> None:
    """Deprecated: :func:`write_states_csv`.

    Parameters
    ----------
    result : RotorResult
        The flight.
    path : str or os.PathLike
        The CSV file to write.
    vehicle : int
        The vehicle's index.
    """
    deprecated("write_rotor_states_csv()", "write_states_csv()")
    write_states_csv(result, path, vehicle)
