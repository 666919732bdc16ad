"""Physics invariants of the plant, through the engine (open-loop replay)."""

import numpy as np
import pytest

import quadcruise as qc
from quadcruise.layout import F1, P_K1, P_K3, P_K5, STATE_SIZE, P, Q, R
from quadcruise.model.actuators import mix, unmix
from quadcruise.model.plant import derivative
from support.reference_model import still_air_ext

V = qc.Vehicle.paper()


def sched(t, duties):
    return qc.DutySchedule(t=np.asarray(t, float), duties=np.asarray(duties, float))


def test_hover_equilibrium_stays_put():
    h = V.hover_duty
    res = qc.replay(sched(np.linspace(0, 10, 11), [[h] * 4] * 11))
    assert res.ok[0]
    assert np.max(np.abs(res.states[0, :, :12])) < 1e-9
    np.testing.assert_allclose(res.states[0, :, F1:], V.m * V.g / 4, rtol=1e-12)


def test_free_fall():
    t = np.linspace(0, 2, 21)
    res = qc.replay(sched(t, np.zeros((21, 4))))
    np.testing.assert_allclose(res.state("z")[0], -V.g * t**2 / 2, rtol=1e-12, atol=1e-12)
    np.testing.assert_allclose(res.state("vz")[0], -V.g * t, atol=1e-12)
    assert np.all(res.states[0, :, F1:] == 0.0)


def test_duty_step_reaches_63_percent_at_one_over_omega():
    tau = 1 / V.omega
    res = qc.replay(sched([0.0, 0.5, 0.5 + tau, 0.5 + 5 * tau], [[0] * 4, [0.5] * 4, [0.5] * 4, [0.5] * 4]))
    F_tau = res.states[0, 2, F1:]
    np.testing.assert_allclose(F_tau / (V.K * 0.5), 1 - np.exp(-1), rtol=1e-9)
    assert 0.632 < F_tau[0] / 60 < 0.633


def test_pure_roll_torque_follows_eq_11():
    # u = [h, h + e, h, h - e]: U2 = 2 K e, U3 = U4 = 0, so p' = k2 U2 and phi = k2 U2 t^2 / 2
    h, e = V.hover_duty, 0.01
    t = np.linspace(0, 0.5, 11)
    res = qc.replay(sched(t, [[h, h + e, h, h - e]] * 11))
    U2 = 2 * V.K * e
    k2 = V.l / V.Jxx
    np.testing.assert_allclose(res.state("phi")[0], k2 * U2 * t**2 / 2, rtol=1e-12, atol=1e-15)
    np.testing.assert_allclose(res.state("p")[0], k2 * U2 * t, rtol=1e-12, atol=1e-15)
    assert np.max(np.abs(res.state("theta")[0])) < 1e-12 and np.max(np.abs(res.state("psi")[0])) < 1e-12
    # roll to the right (phi > 0) pushes the vehicle towards -y, eq (6)
    assert res.state("y")[0, -1] < 0


def test_gyroscopic_terms_are_eulers_equations():
    """The k1..k6 form conserves rotational energy when no torque acts; the paper's printed
    eqs (8)-(10) would not (their inertia differences do not cancel)."""
    vp = qc.Vehicle(Jxx=0.02, Jyy=0.03, Jzz=0.05).rows()[0]
    x = np.zeros(STATE_SIZE)
    x[P], x[Q], x[R] = 1.0, -2.0, 3.0
    dx = np.empty(STATE_SIZE)
    derivative(x, np.zeros(4), vp, still_air_ext(), False, dx)
    assert dx[P] == pytest.approx(vp[P_K1] * -2.0 * 3.0)
    assert dx[Q] == pytest.approx(vp[P_K3] * 1.0 * 3.0)
    assert dx[R] == pytest.approx(vp[P_K5] * 1.0 * -2.0)
    J = np.array([0.02, 0.03, 0.05])
    assert np.dot(J * x[P : R + 1], dx[P : R + 1]) == pytest.approx(0.0, abs=1e-15)


def test_mixer_round_trip():
    F = np.array([3.0, 5.0, 7.0, 11.0])
    U = mix(*F, 0.05)
    assert U == pytest.approx((26.0, -6.0, -4.0, 0.05 * (10.0 - 16.0)))
    assert unmix(*U, 0.05) == pytest.approx(tuple(F))


def test_matches_independent_model_pointwise():
    from support.reference_model import rhs

    rng = np.random.default_rng(7)
    vp = V.rows()[0]
    for _ in range(20):
        x = rng.normal(size=STATE_SIZE)
        u = rng.uniform(0, 1, size=4)
        dx = np.empty(STATE_SIZE)
        derivative(x, u, vp, still_air_ext(), False, dx)
        np.testing.assert_allclose(dx, rhs(x, u), rtol=1e-13, atol=1e-13)


def test_the_compiled_derivative_reaches_its_rows_at_constant_offsets():
    """The plant reads the state, vehicle parameters and external inputs through quadcruise.layout's
    module-level ints (``x[L.VX]``), which numba folds: each row is addressed at constant offsets
    only, and the whole derivative is written."""
    from numba import types

    from quadcruise.layout import EXT_SIZE, PARAM_SIZE
    from support.compiled_code import row_offsets

    row = types.float64[::1]
    signature = types.void(row, row, row, row, types.boolean, row)
    for argument, size in (("x", STATE_SIZE), ("vp", PARAM_SIZE), ("ext", EXT_SIZE), ("dx", STATE_SIZE)):
        constant, computed = row_offsets(derivative.py_func, signature, argument)
        assert computed == 0 and constant and constant <= set(range(size)), (argument, constant, computed)
    assert row_offsets(derivative.py_func, signature, "dx")[0] == set(range(STATE_SIZE))
