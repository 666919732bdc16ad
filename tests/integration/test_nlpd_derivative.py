"""nlpd's derivative: on the measurement (the default, unchanged) or on the whole error as eq (17)
writes it, through a filter N whose state starts at rest: a kick on a small step, absorbed by the
asin clip and the tilt limit on a large one."""

import math

import numpy as np
import pytest

import quadcruise as qc
from quadcruise.control import NLPD
from quadcruise.errors import InputError
from quadcruise.layout import CMD_FLAGS, CMD_THETA_D, FLAG_TILT_LIMIT
from quadcruise.missions import Step


def step_flight(size, **params):
    return qc.fly(Step(size=size, time=1.0), NLPD(**params), duration=8.0)


def pitch_at_step(result):
    k = int(np.searchsorted(result.t, 1.0))
    return result.commands[0, k, CMD_THETA_D], int(result.commands[0, k, CMD_FLAGS])


def test_the_default_is_the_measurement_form_and_ignores_the_filter():
    assert NLPD().derivative == "measurement"
    a, b = step_flight(0.5), step_flight(0.5, derivative_filter=3.0)
    np.testing.assert_array_equal(a.states, b.states)


def test_error_form_kicks_a_small_step_by_kd_n_per_metre():
    size, n = 0.001, 100.0
    c = NLPD(derivative="error", derivative_filter=n)
    theta, _ = pitch_at_step(step_flight(size, derivative="error", derivative_filter=n))
    g = qc.Vehicle.paper().g
    kick = c.position.kp * size + c.position.kd * n * size  # Kp E + Kd N E at the jump
    assert theta == pytest.approx(math.asin(kick / g), rel=1e-6)
    plain, _ = pitch_at_step(step_flight(size))
    assert plain == pytest.approx(math.asin(c.position.kp * size / g), rel=1e-6)
    assert theta > 100 * plain


def test_the_kick_decays_with_the_filter():
    fast, slow = (step_flight(0.001, derivative="error", derivative_filter=n) for n in (100.0, 10.0))
    k = int(np.searchsorted(fast.t, 1.0))
    # the kick is Kd N E: ten times smaller with N ten times smaller, and it lasts ten times longer
    ratio = fast.commands[0, k, CMD_THETA_D] / slow.commands[0, k, CMD_THETA_D]
    assert 8.0 < ratio < 10.5
    late = k + 100  # 0.1 s later: 10 / N = 0.1 s vs 1 s
    assert fast.commands[0, late, CMD_THETA_D] < slow.commands[0, late, CMD_THETA_D]


def test_on_a_large_step_the_limits_absorb_the_kick():
    plain, error = step_flight(1.0), step_flight(1.0, derivative="error")
    theta, flags = pitch_at_step(error)
    assert theta == pytest.approx(NLPD().max_tilt) and flags & FLAG_TILT_LIMIT
    assert 0.0 < error.controller_limited_s[0] < 0.1  # held at the limit a few hundredths of a second
    m, e = plain.metrics().iloc[0], error.metrics().iloc[0]
    assert e.overshoot_pct < 0.5 and m.overshoot_pct < 0.5
    assert e.rise_time_s == pytest.approx(m.rise_time_s, rel=0.1)  # 3.3 s against 3.1 s: the kick is gone


def test_unknown_derivative_form_is_refused():
    with pytest.raises(InputError, match="derivative"):
        NLPD(derivative="setpoint")
    with pytest.raises(InputError, match="derivative_filter"):
        NLPD(derivative="error", derivative_filter=0.0)
