"""The paper's controller: inverse model (eqs 16, 19), decoupling (eq 13), closed loop."""

import math
import warnings

import control
import numpy as np
import pytest

import quadcruise as qc
from quadcruise.control import NLPD, controller_from_name
from quadcruise.control.attitude import ATT_MEMORY, decoupled_attitude
from quadcruise.control.design import PIDGains, attitude_pid_design, cascade_state_space, pd_from_poles
from quadcruise.control.inversion import phi_from_eq6, theta_from_eq5
from quadcruise.control.position import nlpd
from quadcruise.layout import (
    CMD_FLAGS,
    CMD_PHI_D,
    CMD_SIZE,
    CMD_THETA_D,
    CMD_THRUST,
    FLAG_TILT_LIMIT,
    PHI,
    PSI,
    REF_SIZE,
    REF_X,
    REF_Y,
    STATE_SIZE,
    THETA,
    P,
    Q,
    R,
)
from quadcruise.missions import Circle, Hover, Step
from quadcruise.model.plant import derivative
from support.reference_model import still_air_ext

V = qc.Vehicle.paper()


def eq5(theta, phi, psi, a):
    return (math.sin(phi) * math.sin(psi) + math.cos(phi) * math.sin(theta) * math.cos(psi)) * a


def eq6(phi, theta, psi, a):
    return (-math.sin(phi) * math.cos(psi) + math.cos(phi) * math.sin(theta) * math.sin(psi)) * a


def test_inverse_model_solves_eqs_5_and_6_exactly():
    rng = np.random.default_rng(1)
    for _ in range(200):
        phi, psi = rng.uniform(-0.4, 0.4), rng.uniform(-0.8, 0.8)
        a = rng.uniform(8, 15)
        ux, uy = rng.uniform(-2, 2, size=2)
        theta_d, c1 = theta_from_eq5(ux, phi, psi, a)
        phi_d, c2 = phi_from_eq6(uy, theta_d, psi, a)
        assert not (c1 or c2)
        assert eq5(theta_d, phi, psi, a) == pytest.approx(ux, abs=1e-10)
        assert eq6(phi_d, theta_d, psi, a) == pytest.approx(uy, abs=1e-10)
        assert abs(phi_d) < math.pi / 2


def test_eq19_root_is_the_one_nearest_level_at_any_yaw():
    """Beyond |psi| = pi/2 (cos psi <= 0) the roll still solves eq (6) exactly, and of the
    two roots in (-pi, pi] it is the one with the smaller |phi| (checked by bisection)."""
    rng = np.random.default_rng(7)
    for psi in list(rng.uniform(-3.1, 3.1, 300)) + [math.pi / 2, -math.pi / 2, math.pi]:
        theta, a, uy = rng.uniform(-0.6, 0.6), rng.uniform(8, 15), rng.uniform(-3, 3)
        phi_d, clipped = phi_from_eq6(uy, theta, psi, a)
        if clipped:
            continue
        assert eq6(phi_d, theta, psi, a) == pytest.approx(uy, abs=1e-9)
        grid = np.linspace(-math.pi, math.pi, 20001)
        f = np.array([eq6(p, theta, psi, a) - uy for p in grid])
        roots = grid[:-1][np.sign(f[:-1]) != np.sign(f[1:])]
        assert abs(phi_d) <= np.min(np.abs(roots)) + 1e-3, (psi, phi_d, roots)


def test_roll_of_a_tilt_limited_pitch_uses_the_limited_pitch():
    """When the pitch setpoint is limited, eq (19) is solved with the limited pitch's sine."""
    c = NLPD(max_tilt=math.radians(20), inversion="sequential")
    x = np.zeros(STATE_SIZE)
    x[12:] = V.m * V.g / 4
    x[PSI] = 0.4
    ref = np.zeros(REF_SIZE)
    ref[REF_X], ref[REF_Y] = 100.0, 0.5
    cmd = np.zeros(CMD_SIZE)
    nlpd(0.0, 1e-3, x, ref, V.rows()[0], c.gains(), c.memory(), cmd)
    assert cmd[CMD_THETA_D] == pytest.approx(math.radians(20)) and int(cmd[CMD_FLAGS]) & FLAG_TILT_LIMIT
    uy = c.position.kp * 0.5
    a = cmd[CMD_THRUST] / V.m
    phi_d, _ = phi_from_eq6(uy, cmd[CMD_THETA_D], 0.4, a)
    assert cmd[CMD_PHI_D] == pytest.approx(phi_d, abs=1e-14)
    assert eq6(cmd[CMD_PHI_D], cmd[CMD_THETA_D], 0.4, a) == pytest.approx(uy, abs=1e-12)


def test_eq19_keeps_the_sign_the_paper_squares_away():
    # at psi = 0 the paper's eq (19) gives sin(phi) = +sqrt(...) whatever the sign of u_y
    a = 9.81
    for uy in (-2.0, 2.0):
        phi_d, _ = phi_from_eq6(uy, 0.1, 0.0, a)
        assert phi_d == pytest.approx(-math.asin(uy / a))
        assert math.copysign(1, phi_d) == -math.copysign(1, uy)


def test_eq16_error_sign_is_negative_feedback():
    """Short of the x reference, the controller pitches forward (theta > 0 accelerates +x)."""
    x = np.zeros(STATE_SIZE)
    x[12:] = V.m * V.g / 4
    ref = np.zeros(REF_SIZE)
    ref[REF_X] = 1.0
    cmd = np.zeros(CMD_SIZE)
    nlpd(0.0, 1e-3, x, ref, V.rows()[0], NLPD().gains(), NLPD().memory(), cmd)
    assert cmd[CMD_THETA_D] > 0 and abs(cmd[CMD_PHI_D]) < 1e-15


def test_asin_argument_and_tilt_are_limited_and_flagged():
    assert theta_from_eq5(50.0, 0.0, 0.0, 9.81) == (pytest.approx(math.pi / 2), True)
    x = np.zeros(STATE_SIZE)
    ref = np.zeros(REF_SIZE)
    ref[REF_X] = 100.0
    cmd = np.zeros(CMD_SIZE)
    c = NLPD(max_tilt=math.radians(20))
    nlpd(0.0, 1e-3, x, ref, V.rows()[0], c.gains(), c.memory(), cmd)
    assert cmd[CMD_THETA_D] == pytest.approx(math.radians(20))
    assert int(cmd[CMD_FLAGS]) & FLAG_TILT_LIMIT


def test_decoupling_cancels_gyroscopic_terms():
    """With eq (13) the plant's p', q', r' equal the PID outputs U* whatever p, q, r are."""
    vp = qc.Vehicle(Jxx=0.02, Jyy=0.035, Jzz=0.05).rows()[0]
    x = np.zeros(STATE_SIZE)
    x[P], x[Q], x[R] = 2.0, -3.0, 1.5
    x[PHI], x[THETA], x[PSI] = 0.1, -0.05, 0.2
    gains = np.array([10.0, 0.0, 0.0, 4.0, 0.0, 0.0, 1.0])  # P only: U* = Kp e
    U2, U3, U4, _ = decoupled_attitude(x, 0.3, 0.1, -0.1, vp, gains, np.zeros(ATT_MEMORY), 1e-3)
    from quadcruise.model.actuators import unmix

    x[12:] = unmix(30.0, U2, U3, U4, vp[7])  # thrusts that realise (U1, U2, U3, U4)
    dx = np.empty(STATE_SIZE)
    derivative(x, x[12:] / vp[5], vp, still_air_ext(), False, dx)
    assert dx[P] == pytest.approx(10.0 * (0.3 - 0.1))
    assert dx[Q] == pytest.approx(10.0 * (0.1 + 0.05))
    assert dx[R] == pytest.approx(4.0 * (-0.1 - 0.2))


def test_hover_is_an_equilibrium_of_the_closed_loop():
    res = qc.fly(Hover(z=1.0), duration=5.0)
    assert np.max(np.abs(res.states[0, :, :3] - [0, 0, 1])) < 1e-9
    assert np.max(np.abs(res.states[0, :, 6:12])) < 1e-9


def test_small_step_agrees_with_python_control_linear_cascade():
    """The nonlinear closed loop, linearised by a 1 cm step, follows the python-control model
    of position PD + attitude PID + 15 rad/s rotor lag (design.cascade_state_space)."""
    res = qc.fly(Step(axis="x", size=0.01, time=1.0), duration=11.0)
    k0 = int(np.searchsorted(res.t, 1.0))
    _, y = control.step_response(cascade_state_space(NLPD().position, NLPD().attitude), T=res.t[k0:] - 1.0)
    assert np.max(np.abs(res.state("x")[0, k0:] / 0.01 - y)) < 2e-3
    m = res.metrics().iloc[0]
    info = control.step_info(cascade_state_space(NLPD().position, NLPD().attitude))
    assert m.rise_time_s == pytest.approx(info["RiseTime"], abs=0.02)
    assert m.settling_time_s == pytest.approx(info["SettlingTime"], abs=0.05)


@pytest.mark.parametrize("axis", ["x", "y", "z"])
def test_unit_step_is_reached_on_every_axis(axis):
    res = qc.fly(Step(axis=axis, size=-1.0 if axis == "y" else 1.0, time=0.5), duration=12.0)
    m = res.metrics().iloc[0]
    assert res.ok[0]
    assert m.settling_time_s < 8.0 and m.overshoot_pct < 15.0
    others = [a for a in "xyz" if a != axis]
    for o in others:
        base = 1.0 if o == "z" else 0.0
        assert np.max(np.abs(res.state(o)[0] - base)) < 0.01


def test_x_and_y_steps_are_mirror_images():
    """Jxx = Jyy: a +x step and a +y step give the same response (signs of eqs 16, 19)."""
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        rx = qc.fly(Step(axis="x", size=1.0), duration=6.0)
        ry = qc.fly(Step(axis="y", size=1.0), duration=6.0)
    np.testing.assert_allclose(rx.state("x")[0], ry.state("y")[0], atol=1e-9)
    np.testing.assert_allclose(rx.state("theta")[0], -ry.state("phi")[0], atol=1e-9)


def test_circle_is_tracked_after_the_transient():
    res = qc.fly(Circle(), duration=40.0)
    assert res.ok[0]
    pos, ref = res.states[0, :, :3], res.references[0, :, :3]
    late = res.t > 15.0
    err = np.linalg.norm(pos[late] - ref[late], axis=1)
    assert err.max() < 0.1
    ff = qc.fly(Circle(), NLPD(accel_feedforward=True), duration=40.0)
    err_ff = np.linalg.norm(ff.states[0, late, :3] - ref[late], axis=1)
    assert err_ff.max() < err.max() / 3  # feedforward removes most of the steady lag


def test_batch_with_per_vehicle_parameters_equals_single_flights():
    masses = np.array([3.0, 3.499, 4.0])
    batch = qc.fly(Circle(), duration=5.0, vehicle=qc.Vehicle(m=masses))
    for i, m in enumerate(masses):
        single = qc.fly(Circle(), duration=5.0, vehicle=qc.Vehicle(m=m))
        np.testing.assert_allclose(batch.states[i], single.states[0], rtol=0, atol=1e-12)


def test_per_vehicle_missions():
    ms = [Circle(radius=r) for r in (1.0, 2.0, 3.0)]
    res = qc.fly(missions=ms, duration=2.0)
    assert res.n == 3
    np.testing.assert_allclose(res.references[:, 0, REF_X], [1.0, 2.0, 3.0])


def test_controller_registry_and_bad_parameters():
    assert controller_from_name("nlpd") == NLPD()
    with pytest.raises(qc.InputError, match="unknown controller 'pid'"):
        controller_from_name("pid")
    with pytest.raises(qc.InputError, match="max_tilt"):
        NLPD(max_tilt=2.0)
    with pytest.raises(qc.InputError, match="open left half plane"):
        NLPD(position=pd_from_poles([0.7, -4.3]))


def test_diverging_flight_warns_and_stops():
    """Attitude gains 200 times too weak (below the loop's gain margin) make the cascade
    unstable: the vehicle runs away, and the flight stops with a reason and a warning."""
    g = attitude_pid_design()
    weak = NLPD(attitude=PIDGains(kp=g.kp / 200, ki=g.ki / 200, kd=g.kd / 200))
    with pytest.warns(UserWarning, match="diverged: position left the bound at t = "):
        res = qc.fly(Step(axis="x", size=1.0, time=0.1), weak, duration=20.0, limits=qc.Limits(max_position=100.0))
    assert not res.ok[0] and res.t_stop[0] < 20.0
    assert res.metrics().iloc[0].status.startswith("diverged")


@pytest.mark.parametrize("name", ["nlpd", "gonzalez", "se3"])
def test_compiled_controller_makes_no_reference_count_calls(name):
    """The engine runs vehicles in parallel threads that share the batch arrays; each
    NRT_incref/decref on them is an atomic write to one shared counter. These controllers
    read their arrays into scalars first and write last, so their compiled body
    has none (only numba's Python-facing wrapper does). A fresh, uncached compile of the same
    Python function shows what the engine runs."""
    from quadcruise.layout import CONTROLLER_SIG
    from support.compiled_code import reference_count_calls

    calls = reference_count_calls(controller_from_name(name).function.py_func, CONTROLLER_SIG)
    assert calls == []


@pytest.mark.parametrize(
    "name, gains, memory",
    [("nlpd", "gains", 5), ("gonzalez", "gains", 3), ("se3", "gains", 0), ("cascade", "G", 19)],
)
def test_compiled_controller_reads_its_rows_at_constant_offsets(name, gains, memory):
    """The offsets unpacked from each controller's declared rows (quadcruise.layout.Row) are
    module-level ints, which numba folds: every entry of the gains and memory rows is reached
    at a constant offset in the compiled body, none through an index computed at run time
    (which a row read through a tuple or an object's attribute could need)."""
    from quadcruise.layout import CONTROLLER_SIG
    from support.compiled_code import row_offsets

    function = controller_from_name(name).function.py_func
    size = controller_from_name(name).gains().size
    assert row_offsets(function, CONTROLLER_SIG, gains) == (set(range(size)), 0)
    assert row_offsets(function, CONTROLLER_SIG, "mem") == (set(range(memory)), 0)


@pytest.mark.parametrize("name", ["nlpd", "gonzalez", "se3", "cascade"])
def test_compiled_controller_reads_the_engine_vectors_at_constant_offsets(name):
    """The controllers read the state, reference and vehicle parameters and write the command
    through quadcruise.layout's module-level ints (imported as the module: ``x[L.PHI]``), which
    numba folds like imported names: every entry is reached at a constant offset, none through
    an index computed at run time."""
    from quadcruise.layout import CMD_SIZE, CONTROLLER_SIG, PARAM_SIZE, REF_SIZE, STATE_SIZE
    from support.compiled_code import row_offsets

    function = controller_from_name(name).function.py_func
    for argument, size in (("x", STATE_SIZE), ("ref", REF_SIZE), ("vp", PARAM_SIZE), ("cmd", CMD_SIZE)):
        constant, computed = row_offsets(function, CONTROLLER_SIG, argument)
        assert computed == 0 and constant and constant <= set(range(size)), (argument, constant, computed)
    assert row_offsets(function, CONTROLLER_SIG, "cmd")[0] == set(range(CMD_SIZE))  # the whole command
