"""Geometric SE(3) control and the PX4-style cascade on the paper's plant: rotation helpers,
signs against eqs 5-7 and 11, loop stability with the rotor lag, flights, batches, compare()."""

from __future__ import annotations

import dataclasses
import json
import math
import re
import warnings

import control
import numpy as np
import pytest

import quadcruise as qc
from quadcruise.control import CONTROLLERS, controller_from_name
from quadcruise.control.cascade import (
    CASCADE_GAINS,
    Cascade,
    RateGains,
    cascade,
    constrain_xy,
    rate_loops,
    rate_pid_design,
)
from quadcruise.control.design import PDGains, PIDGains, cascade_state_space, loop_margins
from quadcruise.control.se3 import SE3, se3
from quadcruise.control.so3 import (
    attitude_lee,
    attitude_px4,
    error_lee,
    error_quaternion,
    euler_zyx,
    limit_tilt,
    rotation_zyx,
)
from quadcruise.layout import (
    CMD_FLAGS,
    CMD_PHI_D,
    CMD_PSI_D,
    CMD_SIZE,
    CMD_TAU_PHI,
    CMD_TAU_PSI,
    CMD_TAU_THETA,
    CMD_THETA_D,
    CMD_THRUST,
    F1,
    FLAG_THRUST_LIMIT,
    FLAG_TILT_LIMIT,
    P_G,
    P_JXX,
    P_JYY,
    P_JZZ,
    P_K1,
    P_K2,
    P_K3,
    P_K4,
    P_K5,
    P_K6,
    P_L,
    P_M,
    PSI,
    REF_PSI,
    REF_PSI_DOT,
    REF_SIZE,
    REF_X,
    REF_Y,
    REF_Z,
    STATE_SIZE,
    P,
    Q,
    R,
    Z,
)
from quadcruise.metrics import tracking_errors
from quadcruise.missions import Circle, Hover, Step
from quadcruise.missions.minsnap import MinimumSnap
from quadcruise.missions.waypoints import WaypointTable
from quadcruise.model.actuators import mix
from quadcruise.workflows.compare import Comparison, compare

V = qc.Vehicle.paper()
VP = V.rows(1)[0].copy()
MODERN = [SE3(), Cascade()]
IDS = ["se3", "cascade"]


def b3_of_eqs_5_to_7(phi, theta, psi):
    return np.array(
        [
            math.sin(phi) * math.sin(psi) + math.cos(phi) * math.sin(theta) * math.cos(psi),
            -math.sin(phi) * math.cos(psi) + math.cos(phi) * math.sin(theta) * math.sin(psi),
            math.cos(phi) * math.cos(theta),
        ]
    )


def command(ctrl, dx=0.0, dy=0.0, dz=0.0, dpsi=0.0, vp=VP, state=None):
    """One control period from level hover at (0, 0, 1), the reference offset by dx, dy, dz."""
    x = np.zeros(STATE_SIZE) if state is None else state.copy()
    if state is None:
        x[Z] = 1.0
        x[F1 : F1 + 4] = vp[P_M] * vp[P_G] / 4.0
    ref = np.zeros(REF_SIZE)
    ref[REF_X], ref[REF_Y], ref[REF_Z], ref[REF_PSI] = dx, dy, 1.0 + dz, dpsi
    cmd = np.zeros(CMD_SIZE)
    ctrl.function(0.0, 1e-3, x, ref, vp, ctrl.gains(), ctrl.memory(), cmd)
    return cmd


# --- rotations ---------------------------------------------------------------------------
def test_rotation_is_the_models_zyx_convention():
    rng = np.random.default_rng(3)
    for _ in range(100):
        phi, theta, psi = rng.uniform(-1.2, 1.2, 3)
        R = rotation_zyx(phi, theta, psi)
        Rm = np.array(R)
        np.testing.assert_allclose(Rm[:, 2], b3_of_eqs_5_to_7(phi, theta, psi), atol=1e-14)
        np.testing.assert_allclose(Rm.T @ Rm, np.eye(3), atol=1e-14)
        assert np.linalg.det(Rm) == pytest.approx(1.0)
        assert euler_zyx(R) == pytest.approx((phi, theta, psi), abs=1e-12)


@pytest.mark.parametrize("build", [attitude_lee, attitude_px4])
def test_desired_attitude_has_the_thrust_axis_and_the_heading(build):
    rng = np.random.default_rng(4)
    for _ in range(100):
        b3 = rng.normal(size=3)
        b3[2] = abs(b3[2]) + 0.5
        b3 /= np.linalg.norm(b3)
        psi = rng.uniform(-3, 3)
        Rd = np.array(build(*b3, psi))
        np.testing.assert_allclose(Rd[:, 2], b3, atol=1e-14)
        np.testing.assert_allclose(Rd.T @ Rd, np.eye(3), atol=1e-14)
        assert np.linalg.det(Rd) == pytest.approx(1.0)
        heading = math.atan2(Rd[1, 0], Rd[0, 0])
        if build is attitude_px4:  # PX4's construction keeps the ZYX yaw exactly
            assert math.remainder(heading - psi, 2 * math.pi) == pytest.approx(0.0, abs=1e-12)
        else:  # Lee's b1 is the projection of the heading on b3's plane
            c1 = np.array([math.cos(psi), math.sin(psi), 0.0])
            proj = c1 - (c1 @ b3) * b3
            np.testing.assert_allclose(Rd[:, 0], proj / np.linalg.norm(proj), atol=1e-12)


def test_attitude_errors_are_the_angle_differences_to_first_order():
    for axis in range(3):
        d = np.zeros(3)
        d[axis] = 1e-4
        Rm = rotation_zyx(*(0.02 + d))
        Rd = rotation_zyx(0.02, 0.02, 0.02)
        assert np.array(error_lee(Rm, Rd)) == pytest.approx(d, abs=2e-6)  # current - desired
        assert np.array(error_quaternion(Rm, Rd)) == pytest.approx(-d, abs=2e-6)  # desired - current
    # large errors: Lee's is sin(angle) on the axis, PX4's 2 sin(angle / 2), also near 180 deg
    for angle in (0.5, 2.0, math.pi - 1e-9):
        Rm = rotation_zyx(0.0, 0.0, angle)
        Rd = rotation_zyx(0.0, 0.0, 0.0)
        assert error_lee(Rm, Rd) == pytest.approx((0, 0, math.sin(angle)), abs=1e-12)
        assert error_quaternion(Rm, Rd) == pytest.approx((0, 0, -2 * math.sin(angle / 2)), abs=1e-7)


def test_tilt_limit_and_velocity_priority():
    hx, hy, lim = limit_tilt(10.0, 10.0, 1.0, math.radians(30))
    assert lim and math.atan2(math.hypot(hx, hy), 1.0) == pytest.approx(math.radians(30))
    assert hx == pytest.approx(hy)
    assert limit_tilt(0.1, 0.0, 9.81, 0.5) == (0.1, 0.0, False)
    assert limit_tilt(1.0, 1.0, -1.0, 0.5) == (0.0, 0.0, True)
    assert constrain_xy(1.0, 0.0, 1.0, 0.0, 5.0) == (2.0, 0.0)  # within the limit
    assert constrain_xy(6.0, 8.0, 1.0, 0.0, 5.0) == pytest.approx((3.0, 4.0))  # position term alone too big
    vx, vy = constrain_xy(3.0, 0.0, 0.0, 10.0, 5.0)  # feedforward trimmed
    assert (vx, vy) == pytest.approx((3.0, 4.0))


# --- signs from eqs 5-7 and 11 ---------------------------------------------------------------
@pytest.mark.parametrize("ctrl", MODERN, ids=IDS)
def test_signs_of_setpoints_and_torques(ctrl):
    c = command(ctrl)
    assert np.all(np.abs(c[CMD_TAU_PHI : CMD_TAU_PSI + 1]) < 1e-12) and c[CMD_FLAGS] == 0
    assert c[CMD_THRUST] == pytest.approx(V.m * V.g, rel=1e-12)  # hover: U1 = m g
    c = command(ctrl, dx=0.5)  # short of +x: pitch up (x'' ~ sin theta), pitch torque up
    assert c[CMD_THETA_D] > 0 and abs(c[CMD_PHI_D]) < 1e-12 and c[CMD_TAU_THETA] > 0
    assert c[0] > c[2]  # U3 = F1 - F3 > 0 (eq 3)
    c = command(ctrl, dy=0.5)  # short of +y: roll negative (y'' ~ -sin phi), roll torque down
    assert c[CMD_PHI_D] < 0 and abs(c[CMD_THETA_D]) < 1e-12 and c[CMD_TAU_PHI] < 0
    c = command(ctrl, dz=0.5)  # below: more thrust, level
    assert c[CMD_THRUST] > V.m * V.g and abs(c[CMD_THETA_D]) + abs(c[CMD_PHI_D]) < 1e-12
    c = command(ctrl, dpsi=0.3)  # yaw left: positive yaw torque (r' = k6 U4)
    assert c[CMD_PSI_D] == pytest.approx(0.3) and c[CMD_TAU_PSI] > 0
    # the duties realise the desired inputs through eqs (1)-(4)
    U = mix(*(c[:4] * V.K), V.d)
    assert U == pytest.approx(tuple(c[CMD_THRUST : CMD_TAU_PSI + 1]), rel=1e-12, abs=1e-12)


def test_se3_moments_cancel_the_gyroscopic_terms():
    """With R = R_d, eq (11) under the SE(3) moments gives w' = -kw w exactly (w x J w)."""
    vp = qc.Vehicle(Jxx=0.02, Jyy=0.035, Jzz=0.05).rows(1)[0]
    x = np.zeros(STATE_SIZE)
    x[Z] = 1.0
    x[P], x[Q], x[R] = 2.0, -3.0, 1.5
    ctrl = SE3()
    c = command(ctrl, vp=vp, state=x)
    U2, U3, U4 = c[CMD_TAU_PHI], c[CMD_TAU_THETA], c[CMD_TAU_PSI]
    kw = ctrl.attitude.kd
    assert vp[P_K1] * x[Q] * x[R] + vp[P_K2] * U2 == pytest.approx(-kw * x[P])
    assert vp[P_K3] * x[P] * x[R] + vp[P_K4] * U3 == pytest.approx(-kw * x[Q])
    assert vp[P_K5] * x[P] * x[Q] + vp[P_K6] * U4 == pytest.approx(-kw * x[R])


def rotorpy_se3(ctrl: SE3, vp=VP):
    """RotorPy 3.0's SE3Control with ctrl's gains and vp's mass and inertia (None without RotorPy)."""
    quadrotor_control = pytest.importorskip("rotorpy.controllers.quadrotor_control")
    from rotorpy.vehicles.crazyflie_params import quad_params

    params = dict(
        quad_params,
        mass=vp[P_M],
        Ixx=vp[P_JXX],
        Iyy=vp[P_JYY],
        Izz=vp[P_JZZ],
        kp_att=ctrl.attitude.kp,
        kd_att=ctrl.attitude.kd,
    )
    theirs = quadrotor_control.SE3Control(params)
    assert theirs.g == vp[P_G]  # RotorPy's g is fixed at 9.81, the paper's
    theirs.kp_pos = np.array([ctrl.position.kp, ctrl.position.kp, ctrl.altitude.kp])
    theirs.kd_pos = np.array([ctrl.position.kd, ctrl.position.kd, ctrl.altitude.kd])
    return theirs


def test_se3_equals_rotorpy_se3control_with_a_yaw_rate_reference():
    """Thrust, moments and R_d of se3 against RotorPy's SE3Control (an independent code path) at
    random tilted, rotating states and references that turn the yaw (psi_dot_d != 0)."""
    from scipy.spatial.transform import Rotation

    ctrl = SE3()
    theirs = rotorpy_se3(ctrl)
    rng = np.random.default_rng(21)
    for _ in range(50):
        x = np.zeros(STATE_SIZE)
        x[:3], x[3:6] = rng.uniform(-1, 1, 3), rng.uniform(-1, 1, 3)
        x[6:8], x[8] = rng.uniform(-0.3, 0.3, 2), rng.uniform(-math.pi, math.pi)  # roll, pitch, yaw
        x[P : R + 1] = rng.uniform(-2, 2, 3)
        ref = np.zeros(REF_SIZE)
        ref[:9] = x[:9] + rng.uniform(-0.3, 0.3, 9)  # position, velocity, acceleration
        ref[REF_PSI], ref[REF_PSI_DOT] = rng.uniform(-math.pi, math.pi), rng.uniform(-1.0, 1.0)
        cmd = np.zeros(CMD_SIZE)
        se3(0.0, 1e-3, x, ref, VP, ctrl.gains(), np.zeros(0), cmd)
        assert cmd[CMD_FLAGS] == 0  # neither limit acts: Lee's law alone
        state = {
            "x": x[:3],
            "v": x[3:6],
            "w": x[P : R + 1],
            "q": Rotation.from_euler("ZYX", [x[8], x[7], x[6]]).as_quat(),
        }
        flat = {"x": ref[:3], "x_dot": ref[3:6], "x_ddot": ref[6:9], "yaw": ref[REF_PSI], "yaw_dot": ref[REF_PSI_DOT]}
        out = theirs.update(0.0, state, flat)
        l = VP[P_L]
        np.testing.assert_allclose(cmd[CMD_THRUST], out["cmd_thrust"], rtol=1e-12)
        np.testing.assert_allclose(
            [cmd[CMD_TAU_PHI] * l, cmd[CMD_TAU_THETA] * l, cmd[CMD_TAU_PSI]], out["cmd_moment"], rtol=0, atol=1e-10
        )
        psi_d, theta_d, phi_d = Rotation.from_quat(out["cmd_q"]).as_euler("ZYX")
        np.testing.assert_allclose(
            [cmd[CMD_PHI_D], cmd[CMD_THETA_D], cmd[CMD_PSI_D]], [phi_d, theta_d, psi_d], rtol=0, atol=1e-10
        )


def yawing_minimum_snap() -> MinimumSnap:
    """A 2 m square flown as one minimum-snap path in 16 s, the heading turning a full lap
    (psi_dot_d up to 0.83 rad/s)."""
    return MinimumSnap(
        WaypointTable(
            [[0, 0, 1], [2, 0, 1], [2, 2, 1], [0, 2, 1], [0, 0, 1]],
            yaw=[0, math.pi / 2, math.pi, 1.5 * math.pi, 2 * math.pi],
            t=[0, 4, 8, 12, 16],
        )
    )


def yaw_error_deg(res) -> np.ndarray:
    """The yaw reference minus the flown yaw, wrapped to (-180, 180] [deg]."""
    e = res.references[0, :, REF_PSI] - res.states[0, :, PSI]
    return np.degrees(np.angle(np.exp(1j * e)))


@pytest.mark.slow
def test_se3_follows_the_yaw_rate_of_a_minimum_snap_path():
    """With w_d = (0, 0, psi_dot_d) se3 keeps the heading of a turning path within 0.6 deg;
    without it the rate term kw would hold it back by kw / kR psi_dot_d, more than 8 deg here."""
    mission = yawing_minimum_snap()
    ctrl = SE3()
    res = qc.fly(mission, ctrl)
    assert res.ok[0]
    rate = np.max(np.abs(res.references[0, :, REF_PSI_DOT]))
    assert math.degrees(ctrl.attitude.kd / ctrl.attitude.kp * rate) > 8.0  # the lag this path would show
    assert np.max(np.abs(yaw_error_deg(res))) < 0.6


@pytest.mark.slow
def test_cascade_feeds_the_yaw_rate_forward_on_a_minimum_snap_path():
    """The cascade adds psi_dot_d to its yaw rate setpoint: its yaw error stays a small part of
    the psi_dot_d / K_yaw a P attitude loop without feedforward would lag by (17 deg here)."""
    ctrl = Cascade()
    res = qc.fly(yawing_minimum_snap(), ctrl)
    assert res.ok[0]
    lag_without = math.degrees(np.max(np.abs(res.references[0, :, REF_PSI_DOT])) / ctrl.yaw_p)
    assert lag_without > 15.0
    assert np.max(np.abs(yaw_error_deg(res))) < 0.1 * lag_without


@pytest.mark.parametrize("ctrl", MODERN, ids=IDS)
def test_tilt_and_thrust_limits_are_applied_and_flagged(ctrl):
    c = command(ctrl, dx=100.0, dy=-100.0)
    tilt = math.acos(math.cos(c[CMD_PHI_D]) * math.cos(c[CMD_THETA_D]))
    assert tilt == pytest.approx(ctrl.max_tilt, abs=1e-9)
    assert int(c[CMD_FLAGS]) & FLAG_TILT_LIMIT
    weak = dataclasses.replace(ctrl, thrust_max=0.05) if isinstance(ctrl, Cascade) else ctrl
    c = command(weak, dz=100.0)
    assert int(c[CMD_FLAGS]) & FLAG_THRUST_LIMIT
    assert c[CMD_THRUST] == pytest.approx(0.05 * 4 * V.K if weak is not ctrl else 4 * V.K)
    c = command(ctrl, dz=-100.0)  # asked to fall faster than g: no negative thrust
    assert c[CMD_THRUST] >= 0.0 and (isinstance(ctrl, Cascade) or int(c[CMD_FLAGS]) & FLAG_THRUST_LIMIT)


# --- linear loops with the rotor lag (python-control) ------------------------------------------
@pytest.mark.parametrize("axis", ["roll", "yaw"])
def test_cascade_rate_and_attitude_loops_are_stable_with_the_rotor_lag(axis):
    loops = rate_loops(Cascade(), actuator_bandwidth=V.omega, axis=axis)
    for name in ("rate", "attitude"):
        gm, pm, _, _, wgc, _ = control.stability_margins(loops[name])
        assert pm > 40.0 and gm > 3.0
        assert np.all(control.feedback(loops[name], 1).poles().real < 0)
        if name == "rate":
            assert wgc < V.omega  # the rate loop is fast but below the 15 rad/s lag
    assert np.all(loops["closed"].poles().real < 0)
    assert float(loops["closed"].dcgain()) == pytest.approx(1.0)


def test_se3_attitude_loop_is_stable_with_the_rotor_lag():
    m = loop_margins(SE3().attitude, V.omega)
    assert m["stable"] and m["phase_margin"] > 20.0


def cascade_x_loop(c: Cascade, w=15.0, g=9.81):
    """The cascade's x loop linearised about hover (pitch axis, theta_d = a_x / g)."""
    names = ["x", "v", "th", "q", "al", "vi", "ri", "vdf", "adf"]
    n = len(names)
    i = {k: j for j, k in enumerate(names)}
    e = np.eye(n)
    A, B = np.zeros((n, n)), np.zeros((n, 1))
    fv, fa = 2 * math.pi * c.vel_d_cutoff, 2 * math.pi * c.rate_d_cutoff
    ev = (-c.xy_p * e[i["x"]] - e[i["v"]], c.xy_p)  # (state row, reference gain)
    acc = (c.xy_vel_p * ev[0] + e[i["vi"]] - c.xy_vel_d * e[i["vdf"]], c.xy_vel_p * ev[1])
    er = (c.roll_p * (acc[0] / g - e[i["th"]]) - e[i["q"]], c.roll_p * acc[1] / g)
    al = (c.rate.kp * er[0] + e[i["ri"]] - c.rate.kd * e[i["adf"]], c.rate.kp * er[1])
    A[i["x"]], A[i["v"]], A[i["th"]], A[i["q"]] = e[i["v"]], g * e[i["th"]], e[i["q"]], e[i["al"]]
    A[i["al"]], B[i["al"]] = w * (al[0] - e[i["al"]]), w * al[1]
    A[i["vi"]], B[i["vi"]] = c.xy_vel_i * ev[0], c.xy_vel_i * ev[1]
    A[i["ri"]], B[i["ri"]] = c.rate.ki * er[0], c.rate.ki * er[1]
    A[i["vdf"]] = fv * (g * e[i["th"]] - e[i["vdf"]])
    A[i["adf"]] = fa * (e[i["al"]] - e[i["adf"]])
    return control.ss(A, B, e[:1], 0.0)


@pytest.mark.parametrize("ctrl", MODERN, ids=IDS)
def test_small_step_follows_the_linearised_cascade(ctrl):
    """A 1 cm x step of the nonlinear closed loop follows python-control's linear model:
    for se3, design.cascade_state_space with the attitude PD as a PID without integral."""
    if isinstance(ctrl, SE3):
        full = cascade_state_space(ctrl.position, PIDGains(kp=ctrl.attitude.kp, ki=0.0, kd=ctrl.attitude.kd))
        assert np.all(full.A[:5, 5] == 0.0)  # with ki = 0 the last state, int(e), feeds nothing
        sys = control.ss(full.A[:5, :5], full.B[:5], full.C[:, :5], 0.0)
    else:
        sys = cascade_x_loop(ctrl)
    assert np.all(sys.poles().real < 0)
    res = qc.fly(Step(axis="x", size=0.01, time=1.0), ctrl, duration=13.0)
    k0 = int(np.searchsorted(res.t, 1.0))
    _, y = control.step_response(sys, T=res.t[k0:] - 1.0)
    assert np.max(np.abs(res.state("x")[0, k0:] / 0.01 - y)) < 2e-3


# --- flights -------------------------------------------------------------------------------
@pytest.mark.parametrize("ctrl", MODERN, ids=IDS)
def test_hover_is_an_equilibrium(ctrl):
    res = qc.fly(Hover(z=1.0), ctrl, duration=5.0)
    assert np.max(np.abs(res.states[0, :, :3] - [0, 0, 1])) < 1e-9
    assert np.max(np.abs(res.states[0, :, 6:12])) < 1e-9


@pytest.mark.parametrize("ctrl", MODERN, ids=IDS)
@pytest.mark.parametrize("axis,size", [("x", 1.0), ("y", 1.0), ("y", -1.0), ("z", 1.0), ("z", -0.5)])
def test_steps_are_reached_with_the_right_sign(ctrl, axis, size):
    res = qc.fly(Step(axis=axis, size=size), ctrl, duration=12.0)
    assert res.ok[0] and res.controller_limited_s[0] == 0.0
    j = "xyz".index(axis)
    base = np.array([0.0, 0.0, 1.0])
    goal = base.copy()
    goal[j] += size
    assert np.max(np.abs(res.final_state[0, :3] - goal)) < 0.02
    moved = res.state(axis)[0] - base[j]
    assert np.all(np.sign(moved[np.abs(moved) > 0.05]) == np.sign(size))  # never the wrong way
    for o in set("xyz") - {axis}:  # se3's U1 = F . b3 dips 2 cm while the tilt lags b3_d
        assert np.max(np.abs(res.state(o)[0] - base["xyz".index(o)])) < 0.03


@pytest.mark.parametrize("ctrl", MODERN, ids=IDS)
def test_x_and_y_steps_are_mirror_images(ctrl):
    rx = qc.fly(Step(axis="x", size=1.0), ctrl, duration=6.0)
    ry = qc.fly(Step(axis="y", size=1.0), ctrl, duration=6.0)
    np.testing.assert_allclose(rx.state("x")[0], ry.state("y")[0], atol=1e-9)
    np.testing.assert_allclose(rx.state("theta")[0], -ry.state("phi")[0], atol=1e-9)


@pytest.mark.parametrize("ctrl", MODERN, ids=IDS)
def test_yaw_step_is_followed_in_place(ctrl):
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")  # se3's yaw torque briefly asks for negative rotor thrust
        res = qc.fly(Step(axis="yaw", size=0.5), ctrl, duration=12.0)
    assert res.ok[0]
    assert res.final_state[0, PSI] == pytest.approx(0.5, abs=2e-3)
    assert np.max(np.abs(res.states[0, :, :2])) < 1e-6
    assert np.max(np.abs(res.state("z")[0] - 1.0)) < 0.02


@pytest.mark.parametrize("ctrl", MODERN, ids=IDS)
def test_circle_is_tracked_after_the_transient(ctrl):
    res = qc.fly("circle", ctrl, duration=40.0)
    assert res.ok[0]
    late = res.t > 15.0
    err = np.linalg.norm(res.states[0, late, :3] - res.references[0, late, :3], axis=1)
    assert err.max() < 0.1


@pytest.mark.parametrize("ctrl", MODERN, ids=IDS)
def test_batch_with_different_masses_equals_single_flights(ctrl):
    masses = np.array([3.0, 3.499, 4.0])
    batch = qc.fly(Circle(), ctrl, duration=5.0, vehicle=qc.Vehicle(m=masses))
    for i, m in enumerate(masses):
        single = qc.fly(Circle(), ctrl, duration=5.0, vehicle=qc.Vehicle(m=m))
        np.testing.assert_allclose(batch.states[i], single.states[0], rtol=0, atol=1e-12)
        np.testing.assert_allclose(batch.commands[i], single.commands[0], rtol=0, atol=1e-12)


# --- parameters ------------------------------------------------------------------------------
def test_registry_and_gains():
    assert CONTROLLERS["se3"] is SE3 and CONTROLLERS["cascade"] is Cascade
    assert controller_from_name("se3") == SE3() and controller_from_name("cascade") == Cascade()
    assert SE3().function is se3 and Cascade().function is cascade
    assert Cascade().gains().shape == (CASCADE_GAINS.size,) == (27,) and Cascade().memory().shape == (19,)
    assert SE3().memory_size == 0
    assert rate_pid_design(30.0).kp == 30.0  # scales with the rotor bandwidth
    assert json.dumps(Cascade().to_dict())


@pytest.mark.parametrize(
    "cls,kw,field",
    [
        (SE3, {"max_tilt": 2.0}, "max_tilt"),
        (SE3, {"max_tilt": float("nan")}, "max_tilt"),
        (SE3, {"attitude": (81.0, 14.4)}, "attitude"),
        (Cascade, {"xy_p": 0.0}, "xy_p"),
        (Cascade, {"xy_vel_i": -0.1}, "xy_vel_i"),
        (Cascade, {"max_tilt": 1.6}, "max_tilt"),
        (Cascade, {"thrust_max": 1.5}, "thrust_max"),
        (Cascade, {"thrust_min": -0.1}, "thrust_min"),
        (Cascade, {"rate": PDGains(kp=1.0, kd=0.1)}, "rate"),
        (Cascade, {"rate_d_cutoff": "30"}, "rate_d_cutoff"),
    ],
)
def test_bad_parameters_raise_input_error_naming_the_field(cls, kw, field):
    with pytest.raises(qc.InputError, match=f"'{field}'"):
        cls(**kw)


def test_bad_rate_gains_raise_input_error():
    with pytest.raises(qc.InputError, match="kd"):
        RateGains(kp=1.0, ki=0.0, kd=-1.0)


# --- comparison ------------------------------------------------------------------------------
def test_comparison_on_the_circle():
    """Every controller finishes the default circle and tracks it after the 2 m start
    transient; the table is printed for the record (pytest -s)."""
    cmp = compare("circle", duration=40.0)
    table = cmp.table()
    print("\n" + cmp.text())
    assert "did not settle" not in cmp.text()  # each converges onto its steady lag (docs/metrics.md)
    assert table.index.tolist() == ["nlpd", "gonzalez", "se3", "cascade"]
    assert table["status"].eq("finished").all()
    for label, res in cmp.results.items():
        rmse = float(tracking_errors(res.t, res.states[0, :, :3], res.references[0, :, :3], t_from=15.0)["rmse"])
        print(f"{label}: RMSE after 15 s = {rmse:.4f} m")
        assert rmse < 0.1
        # the steady error is the last half of the flight's, once converged
        half = tracking_errors(res.t, res.states[0, :, :3], res.references[0, :, :3], t_from=20.0)["rmse"]
        assert table.loc[label, "steady_rmse_m"] == pytest.approx(float(half), rel=1e-9)
    # se3 and cascade feed the circle's acceleration forward; nlpd (the paper's eq 16) does not
    assert table.loc["se3", "rmse_m"] < table.loc["nlpd", "rmse_m"] + 0.05


def test_compare_table_plot_dict_and_write(tmp_path):
    cmp = compare(Step(axis="y", size=1.0), ["nlpd", SE3(), "cascade", SE3(max_tilt=0.3)], duration=3.0, log_every=5)
    assert isinstance(cmp, Comparison)
    assert list(cmp.results) == ["nlpd", "se3", "cascade", "se3#2"]
    table = cmp.table()
    assert {"rmse_m", "rise_time_s", "settling_time_s", "overshoot_pct", "effort"} <= set(table.columns)
    assert table.loc["cascade", "axis"] == "y"
    fig = cmp.plot()
    top, ax_x, ax_y, ax_z, ax_error = fig.axes
    assert ax_z.get_ylabel() == "z [m]" and len(ax_z.get_lines()) == 1 + 4
    assert ax_error.get_ylabel() == "position error [m]"
    assert [ln.get_label() for ln in ax_error.get_lines()][:4] == list(cmp.results)
    d = cmp.to_dict()
    assert d["mission"]["axis"] == "y" and set(d["metrics"]) == set(cmp.results)
    assert d["controllers"]["se3#2"]["max_tilt"] == 0.3
    json.dumps(d, allow_nan=False)
    out = cmp.write(tmp_path / "cmp")
    assert sorted(p.name for p in out.iterdir()) == [
        "comparison.png",
        "metrics.csv",
        "quadcruise.json",
        "scenario.toml",
    ]
    by_label = compare("hover", {"paper": "nlpd", "px4": Cascade()}, duration=0.5)
    assert list(by_label.results) == ["paper", "px4"]
    batch = compare("hover", ("se3",), duration=0.5, vehicle=qc.Vehicle(m=np.array([3.0, 4.0])))
    assert batch.table().index.tolist() == [("se3", 0), ("se3", 1)]


def test_compare_rejects_bad_input():
    with pytest.raises(qc.InputError, match="unknown controller 'pid'"):
        compare("hover", ["pid"], duration=0.1)
    with pytest.raises(qc.InputError, match="at least one controller"):
        compare("hover", [], duration=0.1)
    with pytest.raises(qc.InputError, match="unknown mission"):
        compare("figure8", duration=0.1)
    with pytest.raises(qc.InputError, match="missions"):
        compare("hover", missions=[Hover()], duration=0.1)


@pytest.mark.parametrize("ctrl", MODERN, ids=IDS)
def test_circle_with_exact_euler_kinematics(ctrl):
    """The higher-fidelity plant (exact ZYX kinematics, where R' = R hat(w) holds) is flown too."""
    res = qc.fly("circle", ctrl, duration=40.0, full_dynamics=True)
    late = res.t > 15.0
    assert res.ok[0]
    assert np.linalg.norm(res.states[0, late, :3] - res.references[0, late, :3], axis=1).max() < 0.1


def test_cascade_integrators_remove_a_mass_error_that_se3_keeps():
    heavy, nominal = V.replace(m=1.2 * V.m), V
    pid = qc.fly("hover", Cascade(), duration=20.0, vehicle=heavy, controller_vehicle=nominal)
    pd = qc.fly("hover", SE3(), duration=20.0, vehicle=heavy, controller_vehicle=nominal)
    assert pid.final_state[0, Z] == pytest.approx(1.0, abs=0.01)
    # no integrator: m (g + kx e) = 1.2 m g, the offset e = 0.2 g / kx = 0.65 m
    assert pd.final_state[0, Z] == pytest.approx(1.0 - 0.2 * V.g / SE3().altitude.kp, abs=0.01)


def test_readme_states_the_tilt_flown_at_a_square_corner_as_measured():
    """README's flown-tilt figures at 45 deg max_tilt: each controller's largest tilt on the corners of
    a 4 m square at 2 m/s, and what it asked for, measured here (to the degree the README gives)."""
    from pathlib import Path

    from quadcruise.layout import CMD_PHI_D, CMD_THETA_D, PHI, THETA
    from quadcruise.missions import Square

    text = " ".join(Path(__file__).parents[2].joinpath("README.md").read_text().split())
    m = re.search(
        r"the largest tilt flown is (\d+)° for `nlpd`, (\d+)° for `gonzalez`, (\d+)° for `se3` and "
        r"(\d+)° for `cascade` \(asked: (\d+)°, (\d+)°, (\d+)°, (\d+)°\)",
        text,
    )
    assert m, "README lost its flown-tilt sentence"
    stated = [int(v) for v in m.groups()]
    flown, asked = [], []
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        for name in ("nlpd", "gonzalez", "se3", "cascade"):
            res = qc.fly(Square(side=4.0, speed=2.0), name, duration=12.0)
            s, c = res.states[0], res.commands[0]
            flown.append(math.degrees(np.arccos(np.min(np.cos(s[:, PHI]) * np.cos(s[:, THETA])))))
            asked.append(math.degrees(np.arccos(np.min(np.cos(c[:, CMD_PHI_D]) * np.cos(c[:, CMD_THETA_D])))))
    assert np.all(np.abs(np.array(flown + asked) - stated) < 0.6), (flown, asked)  # README's whole degrees
    assert flown[0] > 45.0 + 15.0 and asked[0] == pytest.approx(60.0, abs=0.1)  # per-axis limits: acos(cos^2 45)
    assert asked[2] == pytest.approx(45.0, abs=0.1)  # se3: the thrust axis's tilt
