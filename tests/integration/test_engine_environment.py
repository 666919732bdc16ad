"""The engine's environment: sensor delay and noise, model error, wind through drag,
rotor damage, and the full-kinematics plant."""

import numpy as np
import pytest
from numba import njit
from scipy.integrate import solve_ivp
from scipy.spatial.transform import Rotation

import quadcruise as qc
from quadcruise.control.openloop import duty_schedule, pack_schedule
from quadcruise.layout import (
    CMD_PHI_D,
    CMD_THETA_D,
    CONTROLLER_SIG,
    DISTURBANCE_SIG,
    EXT_E1,
    EXT_SIZE,
    EXT_WX,
    F1,
    PHI,
    PSI,
    STATE_SIZE,
    VX,
    P,
    R,
    X,
    Z,
)
from quadcruise.missions import Hover
from quadcruise.workflows.replay import no_reference

V = qc.Vehicle.paper()


@njit(CONTROLLER_SIG)
def hover_probe(t, dt, x, ref, vp, gains, mem, cmd):
    """Hover duties; logs what it sees of x and z in two command columns."""
    h = vp[0] * vp[8] / (4.0 * vp[5])
    for j in range(4):
        cmd[j] = h
    cmd[CMD_PHI_D] = x[X]
    cmd[CMD_THETA_D] = x[Z]


@njit(DISTURBANCE_SIG)
def wind_and_damage(t, dt, x, dp, dmem, rng, ext):
    """dp = (wind x [m/s], effectiveness of rotor 1)."""
    for j in range(EXT_SIZE):
        ext[j] = 0.0
    for j in range(4):
        ext[EXT_E1 + j] = 1.0
    ext[EXT_WX] = dp[0]
    ext[EXT_E1] = dp[1]


def hover_x0(n=1):
    x0 = np.zeros((n, STATE_SIZE))
    x0[:, F1:] = V.m * V.g / 4
    return x0


def probe(n=1, **kw):
    grid = qc.time_grid(1.0, 0.01)
    x0 = hover_x0(n)
    x0[:, VX] = 1.0  # drift at 1 m/s so that delays show
    return qc.simulate(grid, x0, V.rows(n), hover_probe, np.zeros(0), no_reference, np.zeros(1), **kw)


def test_sensor_delay_shows_the_state_d_periods_late():
    res = probe(sensor_delay=3)
    seen, true = res.commands[0, :, CMD_PHI_D], res.states[0, :, X]
    np.testing.assert_allclose(seen[3:], true[:-3], atol=1e-12)
    np.testing.assert_allclose(seen[:3], true[0], atol=1e-12)  # before that: the start


def test_sensor_noise_has_its_std_and_depends_only_on_seed_and_vehicle():
    std = np.zeros(STATE_SIZE)
    std[X], std[Z] = 0.05, 0.01
    res = probe(n=4, sensor_std=std, seed=7)
    err_x = res.commands[:, :, CMD_PHI_D] - res.states[:, :, X]
    err_z = res.commands[:, :, CMD_THETA_D] - res.states[:, :, Z]
    assert err_x.std() == pytest.approx(0.05, rel=0.1) and err_z.std() == pytest.approx(0.01, rel=0.1)
    assert abs(err_x.mean()) < 0.01
    # the true flight is untouched (open-loop probe), and the noise is reproducible ...
    again = probe(n=4, sensor_std=std, seed=7)
    np.testing.assert_array_equal(again.commands, res.commands)
    # ... split-independent ...
    part = probe(n=2, sensor_std=std, seed=7, first_vehicle=2)
    np.testing.assert_array_equal(part.commands, res.commands[2:])
    # ... and different for another seed or another vehicle
    other = probe(n=4, sensor_std=std, seed=8)
    assert not np.allclose(other.commands[:, :, CMD_PHI_D], res.commands[:, :, CMD_PHI_D])
    assert not np.allclose(err_x[0], err_x[1])


def test_model_error_gives_the_predicted_altitude_sag():
    """The controller believes m = 3.499 kg, the vehicle weighs 10 % more: the PD altitude
    loop settles where Kp_z e = g (m_true / m_model - 1)."""
    heavy = V.replace(m=V.m * 1.1)
    res = qc.fly(Hover(z=1.0), "nlpd", vehicle=heavy, controller_vehicle=V, duration=20.0)
    kp_z = qc.control.NLPD().altitude.kp
    expected = V.g * 0.1 / kp_z
    assert 1.0 - res.final_state[0, Z] == pytest.approx(expected, rel=0.01)
    same = qc.fly(Hover(z=1.0), "nlpd", vehicle=heavy, duration=20.0)
    assert abs(same.final_state[0, Z] - 1.0) < 1e-6


def test_free_fall_with_drag_reaches_terminal_velocity():
    drag = V.replace(drag_linear=2.0)
    t = np.linspace(0.0, 20.0, 201)
    res = qc.replay(qc.DutySchedule(t=t, duties=np.zeros((t.size, 4))), vehicle=drag)
    assert res.state("vz")[0, -1] == pytest.approx(-V.m * V.g / 2.0, rel=1e-3)


def test_wind_acts_through_drag_and_damaged_rotor_loses_thrust():
    grid = qc.time_grid(10.0, 0.01)
    h = float(V.hover_duty)
    gains = pack_schedule(grid[[0, -1]], np.full((2, 4), h))
    vehicle = V.replace(drag_linear=1.5)
    res = qc.simulate(
        grid,
        hover_x0(),
        vehicle.rows(),
        duty_schedule,
        gains,
        no_reference,
        np.zeros(1),
        memory=np.zeros(1),
        disturbance=wind_and_damage,
        disturbance_params=[3.0, 1.0],
    )
    # open loop, level: vx' = c (w - vx) / m, so vx = w (1 - exp(-c t / m))
    expected = 3.0 * (1 - np.exp(-1.5 * grid / V.m))
    np.testing.assert_allclose(res.states[0, :, VX], expected, atol=1e-6)
    damaged = qc.simulate(
        grid,
        hover_x0(),
        V.rows(),
        duty_schedule,
        gains,
        no_reference,
        np.zeros(1),
        memory=np.zeros(1),
        disturbance=wind_and_damage,
        disturbance_params=[0.0, 0.6],
        limits=qc.Limits(max_tilt=np.inf),
    )  # open loop it tumbles: let it, to read the thrust
    assert damaged.final_state[0, F1] == pytest.approx(0.6 * V.K * h, rel=1e-6)
    assert damaged.final_state[0, F1 + 1] == pytest.approx(V.K * h, rel=1e-6)


def test_full_kinematics_agree_with_a_rotation_matrix_integration():
    """Torque-free tumbling with unequal inertias: the Euler angles of the full plant equal
    those of R' = R [w]x integrated independently with solve_ivp."""
    J = np.array([0.02, 0.03, 0.05])
    vehicle = qc.Vehicle(Jxx=J[0], Jyy=J[1], Jzz=J[2], g=0.0)
    w0 = np.array([0.3, -0.2, 0.4])
    att0 = np.array([0.1, -0.2, 0.3])  # phi, theta, psi
    t = np.linspace(0.0, 3.0, 31)
    x0 = np.zeros(STATE_SIZE)
    x0[PHI : PSI + 1] = att0
    x0[P : R + 1] = w0
    sched = pack_schedule(t[[0, -1]], np.zeros((2, 4)))
    res = qc.simulate(
        t,
        x0,
        vehicle.rows(),
        duty_schedule,
        sched,
        no_reference,
        np.zeros(1),
        memory=np.zeros(1),
        full_dynamics=True,
        max_step=1e-3,
    )

    def rhs(_t, s):
        Rm, w = s[:9].reshape(3, 3), s[9:]
        wx = np.array([[0, -w[2], w[1]], [w[2], 0, -w[0]], [-w[1], w[0], 0]])
        wdot = np.cross(J * w, w) / J
        return np.concatenate([(Rm @ wx).ravel(), wdot])

    R0 = Rotation.from_euler("ZYX", att0[::-1]).as_matrix()
    sol = solve_ivp(rhs, (0, 3), np.concatenate([R0.ravel(), w0]), t_eval=t, rtol=1e-11, atol=1e-12)
    angles = Rotation.from_matrix(sol.y[:9].T.reshape(-1, 3, 3)).as_euler("ZYX")[:, ::-1]
    np.testing.assert_allclose(res.states[0, :, PHI : PSI + 1], angles, atol=1e-7)
    np.testing.assert_allclose(res.states[0, :, P : R + 1], sol.y[9:].T, atol=1e-8)
    # the paper's kinematics (phi' = p, ...) do not: the simplification is visible here
    paper = qc.simulate(
        t, x0, vehicle.rows(), duty_schedule, sched, no_reference, np.zeros(1), memory=np.zeros(1), max_step=1e-3
    )
    assert np.max(np.abs(paper.states[0, :, PHI : PSI + 1] - angles)) > 1e-2


def test_bad_environment_options():
    with pytest.raises(qc.InputError, match="sensor noise"):
        probe(sensor_std=-np.ones(STATE_SIZE))
    with pytest.raises(qc.InputError, match="sensor delay"):
        probe(sensor_delay=-1)
