"""Pole-placement gain design, checked against python-control (place, poles, margins, step_info)."""

from __future__ import annotations

import dataclasses

import control
import numpy as np
import pytest
import scipy.signal

from quadcruise.control.design import (
    PAPER_POSITION_POLES,
    PDGains,
    PIDGains,
    altitude_pd_design,
    attitude_pid_design,
    cascade_state_space,
    check_with_control,
    loop_margins,
    loop_transfer,
    pd_from_poles,
    pid_from_poles,
    position_pd_design,
)
from quadcruise.errors import InputError

A2 = [[0, 1], [0, 0]]
B2 = [[0], [1]]


def _same_poles(a, b, tol=1e-7):
    a, b = np.asarray(a, complex), np.asarray(b, complex)
    assert a.shape == b.shape
    d = np.abs(a[:, None] - b[None, :])
    assert max(d.min(0).max(), d.min(1).max()) <= tol * max(1.0, np.abs(b).max()), (a, b)


# --- the paper's numbers (eqs 17-18) -------------------------------------------------------


def test_paper_position_gains_eq18():
    g = pd_from_poles((-0.7, -4.3))
    assert g.kp == pytest.approx(3.01, abs=1e-12)
    assert g.kd == pytest.approx(5.0, abs=1e-12)
    assert g.tau_d == pytest.approx(5 / 3.01, rel=1e-12)
    assert round(g.tau_d, 2) == 1.66
    assert pd_from_poles((-4.3, -0.7)) == g == position_pd_design() == altitude_pd_design()
    assert PAPER_POSITION_POLES == (-0.7, -4.3)


def test_paper_closed_loop_is_eq17():
    g = position_pd_design()
    s = control.tf("s")
    eq17 = g.kp * (g.tau_d * s + 1) / (s**2 + g.kp * (g.tau_d * s + 1))
    cl = g.closed_loop()
    w = np.logspace(-2, 2, 50)
    np.testing.assert_allclose(cl(1j * w), eq17(1j * w), rtol=1e-12)
    _same_poles(cl.poles(), [-0.7, -4.3])
    assert control.dcgain(cl) == pytest.approx(1.0)
    # eq 17 is also the unity-feedback loop of C(s) = Kp (tau_d s + 1) on 1/s^2
    fb = control.feedback(g.controller() / s**2, 1)
    np.testing.assert_allclose(fb(1j * w), eq17(1j * w), rtol=1e-10)


def test_place_on_double_integrator_gives_kp_kd():
    g = position_pd_design()
    sys = control.ss(A2, B2, [[1, 0]], 0)
    K = control.place(sys.A, sys.B, [-0.7, -4.3])
    np.testing.assert_allclose(np.ravel(K), [3.01, 5.0], rtol=1e-10)
    np.testing.assert_allclose(np.ravel(K), [g.kp, g.kd], rtol=1e-10)
    _same_poles(np.linalg.eigvals(sys.A - sys.B @ K), PAPER_POSITION_POLES)


def test_check_with_control_paper():
    r = check_with_control(position_pd_design())
    np.testing.assert_allclose(r["place_gain"], [3.01, 5.0], rtol=1e-10)
    assert r["gain_error"] < 1e-10 and r["pole_error"] < 1e-10
    _same_poles(r["closed_loop_poles"], PAPER_POSITION_POLES)
    info = r["step_info"]
    # independent path: scipy's step response of (5 s + 3.01) / (s^2 + 5 s + 3.01)
    t, y = scipy.signal.step(([5.0, 3.01], [1.0, 5.0, 3.01]), T=np.linspace(0, 20, 20001))
    assert info["Overshoot"] == pytest.approx(100 * (y.max() - 1), abs=0.05)
    assert info["PeakTime"] == pytest.approx(t[y.argmax()], abs=0.05)
    assert info["SteadyStateValue"] == pytest.approx(1.0)


def test_natural_frequency_and_damping():
    wn, zeta = 3.0, 0.5
    wd = wn * np.sqrt(1 - zeta**2)
    g = pd_from_poles((-zeta * wn + 1j * wd, -zeta * wn - 1j * wd))
    assert g.natural_frequency == pytest.approx(wn)
    assert g.damping == pytest.approx(zeta)
    assert (g.kp, g.kd) == pytest.approx((wn**2, 2 * zeta * wn))
    _same_poles(g.poles, [-zeta * wn + 1j * wd, -zeta * wn - 1j * wd])


def test_gains_are_frozen():
    g = position_pd_design()
    with pytest.raises(dataclasses.FrozenInstanceError):
        g.kp = 1.0


# --- round trips poles -> gains -> poles ---------------------------------------------------


def _random_pole_sets(n, count, seed):
    rng = np.random.default_rng(seed)
    for i in range(count):
        if i % 2 and n >= 2:  # one complex pair (+ a real pole for n = 3)
            re, im = -rng.uniform(0.1, 20), rng.uniform(0.01, 20)
            yield [complex(re, im), complex(re, -im)] + list(-rng.uniform(0.1, 20, n - 2))
        else:
            yield list(-rng.uniform(0.1, 20, n))


@pytest.mark.parametrize("poles", list(_random_pole_sets(2, 40, seed=1)))
def test_pd_round_trip(poles):
    g = pd_from_poles(poles)
    _same_poles(g.poles, poles)
    _same_poles(g.closed_loop().poles(), poles)
    K = np.ravel(control.place(A2, B2, poles))
    np.testing.assert_allclose(K, [g.kp, g.kd], rtol=1e-8)
    r = check_with_control(g)
    assert r["gain_error"] < 1e-8 and r["pole_error"] < 1e-6


@pytest.mark.parametrize("poles", list(_random_pole_sets(3, 40, seed=2)))
def test_pid_round_trip(poles):
    g = pid_from_poles(poles)
    _same_poles(g.poles, poles, tol=1e-6)
    _same_poles(g.closed_loop().poles(), poles, tol=1e-6)
    A3 = np.eye(3, k=1)  # states (int y, y, y')
    K = np.ravel(control.place(A3, [[0], [0], [1]], poles))
    np.testing.assert_allclose(K, [g.ki, g.kp, g.kd], rtol=1e-7)
    assert check_with_control(g)["gain_error"] < 1e-7


def test_pid_char_poly():
    g = pid_from_poles((-1, -2, -3))
    assert (g.kp, g.ki, g.kd) == (11.0, 6.0, 6.0)
    np.testing.assert_allclose(g.controller()(2j), (6 * (2j) ** 2 + 11 * 2j + 6) / 2j)


# --- bad input -----------------------------------------------------------------------------


@pytest.mark.parametrize(
    "func, poles, match",
    [
        (pd_from_poles, (0.7, 4.3), r"pole 0\.7 is not in the open left half plane \(did you mean -0\.7\?\)"),
        (pd_from_poles, (-0.7, 4.3), r"pole 4\.3 .*did you mean -4\.3"),
        (pd_from_poles, (0.0, -1.0), r"pole 0 is not in the open left half plane$"),
        (pd_from_poles, (1j, -1j), r"pole \(0\+1j\) is not in the open left half plane"),
        (pd_from_poles, (0.5 + 1j, 0.5 - 1j), r"did you mean \(-0\.5\+1j\)"),
        (pd_from_poles, (-1 + 2j, -3.0), r"complex pole \(-1\+2j\) has no conjugate \(-1-2j\)"),
        (pd_from_poles, (-1 + 2j, -1 + 2j), r"no conjugate"),
        (pid_from_poles, (-1 + 2j, -1 - 2j, -1 + 2j), r"no conjugate"),
        (pd_from_poles, (-1.0,), r"pd_from_poles needs 2 poles, got 1"),
        (pd_from_poles, -1.0, r"needs 2 poles, got 1"),
        (pd_from_poles, (-1, -2, -3), r"needs 2 poles, got 3"),
        (pd_from_poles, [[-1, -2]], r"needs 2 poles"),
        (pd_from_poles, (), r"needs 2 poles, got 0"),
        (pid_from_poles, (-1, -2), r"pid_from_poles needs 3 poles, got 2"),
        (pd_from_poles, (float("nan"), -1), r"pole nan is not finite"),
        (pid_from_poles, (-1, -2, -np.inf), r"pole -inf is not finite"),
        (pd_from_poles, ("abc", -1), r"poles must be numbers"),
        (pd_from_poles, None, r"poles must be numbers"),
    ],
)
def test_bad_poles(func, poles, match):
    with pytest.raises(InputError, match=match) as exc:
        func(poles)
    assert "\n" not in str(exc.value)
    assert isinstance(exc.value, ValueError)


@pytest.mark.parametrize(
    "cls, kwargs, match",
    [
        (PDGains, dict(kp=0.0, kd=1.0), r"PD gain 'kp' \(proportional gain, 1/s\^2\) must be > 0, got 0.0"),
        (PDGains, dict(kp=-1.0, kd=1.0), r"'kp'"),
        (PDGains, dict(kp=1.0, kd=float("nan")), r"'kd' .* must be finite, got nan"),
        (PDGains, dict(kp="x", kd=1.0), r"gain 'kp' .* must be a number, got 'x'"),
        (PIDGains, dict(kp=1.0, ki=-1.0, kd=1.0), r"PID gain 'ki' \(integral gain, 1/s\^3\) must be >= 0, got -1.0"),
        (PIDGains, dict(kp=1.0, ki=1.0, kd=np.inf), r"'kd' .* must be finite, got inf"),
    ],
)
def test_bad_gains(cls, kwargs, match):
    with pytest.raises(InputError, match=match) as err:
        cls(**kwargs)
    assert "\n" not in str(err.value)


@pytest.mark.parametrize("w", [0.0, -15.0, float("nan"), np.inf, "fast", None])
def test_bad_actuator_bandwidth(w):
    with pytest.raises(InputError, match="actuator_bandwidth"):
        attitude_pid_design(w)


# --- attitude and altitude designs with the rotor lag -----------------------------------------


def test_attitude_design_poles_and_gains():
    g = attitude_pid_design()
    assert (g.kp, g.ki, g.kd) == pytest.approx((88.2, 40.5, 14.9))
    _same_poles(g.poles, [-7.2 + 5.4j, -7.2 - 5.4j, -0.5], tol=1e-6)  # wn 9, zeta 0.8
    r = check_with_control(g)
    assert r["gain_error"] < 1e-6
    # the dominant pair is faster than the position loop's fastest pole (4.3 rad/s)
    assert min(-p.real for p in np.atleast_1d(g.poles) if -p.real > 2) > 4.3


def test_attitude_margins_with_actuator_lag_independent():
    g = attitude_pid_design(15.0)
    s = control.tf("s")
    L = (g.kd * s**2 + g.kp * s + g.ki) / s * 15 / (s + 15) / s**2
    gm, pm, wg, wc = control.margin(L)
    assert pm > 20.0
    assert pm == pytest.approx(24.47, abs=0.01)
    assert wc == pytest.approx(12.49, abs=0.01)
    assert gm == pytest.approx(0.0509, abs=1e-4)  # gain may fall to 5 %, rise without limit
    assert np.all(control.feedback(L, 1).poles().real < 0)
    m = loop_margins(g, 15.0)
    assert m["stable"]
    assert (m["phase_margin"], m["gain_margin"], m["gain_crossover"], m["phase_crossover"]) == pytest.approx(
        (pm, gm, wc, wg)
    )
    # too slow a gain: conditionally stable loop goes unstable below the gain margin
    weak = PIDGains(kp=g.kp * 0.05, ki=g.ki * 0.05, kd=g.kd * 0.05)
    assert not loop_margins(weak, 15.0)["stable"]


def test_attitude_step_with_lag():
    L = loop_transfer(attitude_pid_design(), 15.0)
    cl = control.feedback(L, 1)
    _same_poles(cl.poles(), [-3.540 + 12.296j, -3.540 - 12.296j, -7.421, -0.500], tol=1e-3)
    info = control.step_info(cl)
    assert info["SteadyStateValue"] == pytest.approx(1.0)
    assert info["SettlingTime"] < 1.5


def test_cascade_with_paper_position_gains_is_well_damped():
    """The design rule's claim: the linearised x loop (position PD, attitude PID, rotor lag)
    is stable with every pole's damping ratio above 0.35, and the earlier rule (-7, -7, -1)
    is beaten on that measure."""
    sys = cascade_state_space(position_pd_design(), attitude_pid_design())
    ev = sys.poles()
    assert np.all(ev.real < 0)
    assert np.min(-ev.real / np.abs(ev)) > 0.35
    assert float(sys.dcgain()) == pytest.approx(1.0)
    old = cascade_state_space(position_pd_design(), pid_from_poles([-7, -7, -1])).poles()
    assert np.min(-old.real / np.abs(old)) < np.min(-ev.real / np.abs(ev))


def test_cascade_without_lag_tends_to_the_paper_loop():
    """With a very fast actuator and attitude loop the cascade is the paper's eq (17) loop
    with the derivative on the measurement: Kp / (s^2 + Kd s + Kp)."""
    sys = cascade_state_space(position_pd_design(), attitude_pid_design(1500.0), 1500.0)
    t = np.linspace(0, 10, 2001)
    _, y = control.step_response(sys, T=t)
    _, y0 = control.step_response(control.tf([3.01], [1, 5, 3.01]), T=t)
    assert np.max(np.abs(y - y0)) < 0.01


def test_attitude_margins_scale_with_bandwidth():
    m15 = loop_margins(attitude_pid_design(15.0), 15.0)
    m40 = loop_margins(attitude_pid_design(40.0), 40.0)
    assert m40["phase_margin"] == pytest.approx(m15["phase_margin"], abs=1e-6)
    assert m40["gain_crossover"] == pytest.approx(m15["gain_crossover"] * 40 / 15, rel=1e-6)


def test_altitude_pd_with_lag():
    g = altitude_pd_design()
    s = control.tf("s")
    gm, pm, _, wc = control.margin((g.kd * s + g.kp) * 15 / (s + 15) / s**2)
    assert pm > 60 and np.isinf(gm)
    assert loop_margins(g, 15.0)["phase_margin"] == pytest.approx(pm)
    assert loop_margins(g, None)["phase_margin"] == pytest.approx(83.18, abs=0.01)
    assert altitude_pd_design((-1, -2)) == PDGains(kp=2.0, kd=3.0)
