"""The full plant (exact Euler-angle kinematics) against an independent integration of the
attitude as a rotation matrix, and its stop before the Euler singularity at 90 degrees of pitch."""

from __future__ import annotations

import math
import warnings

import numpy as np
import pytest
from scipy.integrate import solve_ivp

import quadcruise as qc
from quadcruise.model.plant import EULER_PITCH_LIMIT
from quadcruise.sim.status import ExitStatus
from support.reference_model import euler_to_matrix, rotation_rhs

V = qc.Vehicle.paper()
HOVER = V.hover_duty


def pitch_kick(level: float, duration: float, kick_s: float = 0.1, dt: float = 0.01) -> qc.DutySchedule:
    """Rotor 1 at ``level`` and rotor 3 as far below hover for ``kick_s``, then rotor 4 strong
    for 0.2 s, the rest at about the hover duty: open loop, the vehicle tumbles in pitch, roll
    and yaw at once."""
    t = np.arange(0.0, duration + dt / 2, dt)
    duties = np.tile([HOVER, HOVER * 1.02, HOVER, HOVER], (t.size, 1))
    kick = t < kick_s
    duties[kick, 0], duties[kick, 2] = level, max(0.0, 2 * HOVER - level)
    duties[(t >= kick_s) & (t < kick_s + 0.2), 3] = HOVER * 1.3
    return qc.DutySchedule(t=t, duties=duties)


def rotation_reference(schedule: qc.DutySchedule, t_end: float) -> np.ndarray:
    """The rotation matrix at t_end, integrated row by row with scipy at tight tolerance."""
    y = np.zeros(22)
    y[6:15] = np.eye(3).ravel()
    y[18:22] = V.K * schedule.duties[0]
    for k in range(schedule.t.size - 1):
        t0, t1 = schedule.t[k], min(schedule.t[k + 1], t_end)
        if t1 <= t0:
            break
        sol = solve_ivp(lambda _, s: rotation_rhs(s, schedule.duties[k]), (t0, t1), y, rtol=1e-12, atol=1e-12)  # noqa: B023
        y = sol.y[:, -1]
    return y[6:15].reshape(3, 3)


def rotation_error(res, i_log: int, R_ref: np.ndarray) -> float:
    phi, theta, psi = res.states[0, i_log, 6:9]
    return float(np.linalg.norm(euler_to_matrix(phi, theta, psi) - R_ref))


def test_an_aggressive_manoeuvre_matches_a_rotation_matrix_integration_to_fourth_order():
    schedule = pitch_kick(0.08, 0.6)
    runs = {h: qc.replay(schedule, max_step=h, full_dynamics=True) for h in (2e-3, 1e-3)}
    res = runs[1e-3]
    angles = np.abs(res.states[0, :, 6:8]).max(axis=0)
    assert res.ok[0] and angles[0] > 1.4 and 0.8 < angles[1] < EULER_PITCH_LIMIT  # roll 80+, pitch 45+ degrees
    R_ref = rotation_reference(schedule, res.t[-1])
    coarse, fine = (rotation_error(runs[h], -1, R_ref) for h in (2e-3, 1e-3))
    assert fine < 1e-6
    assert 10.0 < coarse / fine < 22.0  # RK4: 16 per halving


def test_a_flip_through_90_degrees_stops_with_its_own_status_before_the_singularity():
    schedule = pitch_kick(0.12, 3.0)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        res = qc.replay(schedule, max_step=1e-3, full_dynamics=True)
    assert res.exit_status(0) is ExitStatus.PITCH_SINGULAR and res.stopped[0]
    assert "85 degrees" in res.status_text(0)
    theta = res.states[0, :, 7]
    last = int(np.flatnonzero(np.isfinite(theta))[-1])
    assert abs(theta[last]) > EULER_PITCH_LIMIT and np.all(np.abs(theta[:last]) <= EULER_PITCH_LIMIT)
    # up to the stop the attitude is still accurate
    i = last - 1
    assert rotation_error(res, i, rotation_reference(schedule, res.t[i])) < 1e-5
    # the paper's kinematics have no singularity: the same flight goes on (and is wrong there)
    paper = qc.replay(schedule, max_step=1e-3)
    assert paper.ok[0] and np.nanmax(np.abs(paper.states[0, :, 7])) > math.pi / 2


@pytest.mark.parametrize("pitch", [math.radians(80.0), math.radians(-80.0)])
def test_the_euler_and_matrix_attitudes_agree_at_a_steep_held_pitch(pitch):
    R = euler_to_matrix(0.3, pitch, -1.0)
    assert np.allclose(R @ R.T, np.eye(3)) and np.linalg.det(R) == pytest.approx(1.0)
