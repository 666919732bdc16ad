"""The paper's controller at any yaw: the joint inversion of eqs (5) and (6), and the measured
limit of the paper's literal sequential form (eq 16 with the current roll, then eq 19)."""

from __future__ import annotations

import math
import warnings

import numpy as np
import pytest

import quadcruise as qc
from quadcruise.control import NLPD
from quadcruise.control.inversion import phi_from_eq6, theta_from_eq5, tilt_joint
from quadcruise.missions import Circle, MinimumSnap, Step, WaypointTable


def fly(*args, **kwargs):
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        return qc.fly(*args, **kwargs)


def eq5_eq6(phi, theta, psi, a):
    """The horizontal accelerations of eqs (5) and (6) [m/s^2]."""
    sf, cf, st, sp, cp = math.sin(phi), math.cos(phi), math.sin(theta), math.sin(psi), math.cos(psi)
    return (sf * sp + cf * st * cp) * a, (-sf * cp + cf * st * sp) * a


def test_the_joint_pair_satisfies_eqs_5_and_6_together_at_random_yaw_tilt_and_thrust():
    rng = np.random.default_rng(7)
    for _ in range(2000):
        psi = rng.uniform(-math.pi, math.pi)
        a = rng.uniform(2.0, 40.0)
        phi, theta = rng.uniform(-1.2, 1.2, 2)  # any attitude up to 69 degrees
        ux, uy = eq5_eq6(phi, theta, psi, a)  # a feasible wish
        phi_d, theta_d, flags = tilt_joint(ux, uy, math.sin(psi), math.cos(psi), a, 1.5, 0)
        assert flags == 0
        np.testing.assert_allclose(eq5_eq6(phi_d, theta_d, psi, a), (ux, uy), atol=1e-9 * a)
        np.testing.assert_allclose((phi_d, theta_d), (phi, theta), atol=1e-9)  # and it is the unique one


def test_the_sequential_pair_does_not_satisfy_eq_5_with_its_own_roll():
    """Eq (16) solves eq (5) with the *current* roll: with the roll it then sets, eq (5) misses."""
    psi, a, ux, uy = math.radians(45.0), 9.81, 1.0, 0.0
    theta_d, _ = theta_from_eq5(ux, 0.0, psi, a)  # level now
    phi_d, _ = phi_from_eq6(uy, theta_d, psi, a)
    x_acc, y_acc = eq5_eq6(phi_d, theta_d, psi, a)
    assert abs(y_acc - uy) < 1e-9 and abs(x_acc - ux) > 0.2  # eq (6) holds, eq (5) does not


STEP_YAWS = [-80.0, -60.0, -45.0, -20.0, 0.0, 30.0, 45.0, 60.0, 80.0]


@pytest.fixture(scope="module")
def level_step():
    return fly(Step(), "nlpd", duration=12.0).metrics().iloc[0]


@pytest.mark.parametrize("axis", ["x", "y"])
@pytest.mark.parametrize("yaw", STEP_YAWS)
def test_nlpd_steps_alike_at_any_held_yaw(axis, yaw, level_step):
    m = fly(Step(axis=axis, yaw=math.radians(yaw)), "nlpd", duration=12.0).metrics().iloc[0]
    assert m["status"] == "finished"
    assert m["rise_time_s"] == pytest.approx(level_step["rise_time_s"], rel=1e-3)
    assert m["settling_time_s"] == pytest.approx(level_step["settling_time_s"], rel=1e-3)
    assert m["overshoot_pct"] < 0.1


@pytest.mark.slow
@pytest.mark.parametrize("yaw, grows", [(38.0, False), (40.0, True)])
def test_the_paper_literal_inversion_loses_its_damping_beyond_39_degrees(yaw, grows):
    """A 1 mm x-step under a held yaw: the sequential form's oscillation dies out at 38
    degrees and grows at 40 (the tan^2(psi) roll feedback through attitude loop and rotor lag)."""
    res = fly(Step(size=0.001, yaw=math.radians(yaw)), NLPD(inversion="sequential"), duration=60.0, log_every=10)
    err = np.abs(res.states[0, :, 0] - res.references[0, :, 0])
    early, late = err[(res.t > 10) & (res.t < 20)].max(), err[res.t > 50].max()
    assert (late > 2 * early) if grows else (late < 0.5 * early)
    joint = fly(Step(size=0.001, yaw=math.radians(yaw)), "nlpd", duration=60.0, log_every=10)
    assert np.abs(joint.states[0, joint.t > 50, 0] - 0.001).max() < 1e-6


def test_a_circle_flown_at_yaw_60_degrees_is_tracked():
    joint = fly(Circle(yaw=math.radians(60.0)), "nlpd", duration=40.0)
    literal = fly(Circle(yaw=math.radians(60.0)), NLPD(inversion="sequential"), duration=40.0)

    def late_error(res):
        return np.linalg.norm(res.states[0, :, :3] - res.references[0, :, :3], axis=1)[res.t > 20].max()

    level = fly(Circle(), "nlpd", duration=40.0)
    assert late_error(joint) == pytest.approx(late_error(level), rel=0.02)  # as good as at yaw 0
    assert late_error(literal) > 0.5  # the literal form lags


def test_a_minimum_snap_path_that_yaws_from_0_to_90_degrees_ends_on_its_last_point():
    table = WaypointTable(
        [[0, 0, 1], [2, 1, 1], [4, 0, 1.5], [5, 2, 1]], yaw=[0.0, 0.5, 1.0, math.pi / 2], t=[0, 4, 8, 12]
    )
    res = fly(MinimumSnap(table), "nlpd")
    assert res.ok[0]
    assert np.linalg.norm(res.final_state[0, :3] - [5.0, 2.0, 1.0]) < 0.05
    literal = fly(MinimumSnap(table), NLPD(inversion="sequential"))
    assert not literal.ok[0] or np.linalg.norm(literal.final_state[0, :3] - [5.0, 2.0, 1.0]) > 0.5


@pytest.mark.parametrize("yaw", [-80.0, 45.0, 80.0])
def test_the_gonzalez_reconstruction_works_in_the_yaw_frame(yaw):
    m = fly(Step(yaw=math.radians(yaw)), "gonzalez", duration=14.0).metrics().iloc[0]
    assert m["status"] == "finished" and m["overshoot_pct"] < 0.5 and m["settling_time_s"] < 7.0
