"""PX4's gyro filters (:mod:`quadcruise.control.px4filters`) against scipy's Butterworth design
and filtering, and the frame conversion at the PX4 loops' edge
(:mod:`quadcruise.control.px4math`) against scipy's rotations and the matrices the ULog
writer uses (:mod:`quadcruise.sim.px4`)."""

from __future__ import annotations

import numpy as np
import pytest
from scipy.signal import butter, lfilter
from scipy.spatial.transform import Rotation

from quadcruise.control.px4filters import alpha_apply, alpha_of, lpf2p_apply, lpf2p_coefficients, lpf2p_reset
from quadcruise.control.px4math import dcm_from_quat, enu_to_ned, flu_to_frd, quat_enu_flu_to_ned_frd
from quadcruise.sim.px4 import ENU_TO_NED, FLU_TO_FRD


@pytest.mark.parametrize("fs, fc", [(800.0, 40.0), (250.0, 30.0), (1000.0, 80.0), (400.0, 199.0)])
def test_the_gyro_low_pass_is_scipys_butterworth(fs, fc):
    b0, b1, b2, a1, a2 = lpf2p_coefficients(fs, fc)
    b, a = butter(2, fc / (fs / 2))
    assert np.allclose([b0, b1, b2], b, rtol=1e-12) and np.allclose([1.0, a1, a2], a, rtol=1e-12)
    x = np.random.default_rng(3).normal(size=400)
    coefficients, delay, out = (b0, b1, b2, a1, a2), (0.0, 0.0), []
    for sample in x:
        y, delay = lpf2p_apply(coefficients, delay, sample)
        out.append(y)
    assert np.allclose(out, lfilter(b, a, x), atol=1e-12)


def test_the_low_pass_resets_to_a_steady_value_and_refuses_bad_cutoffs():
    coefficients = lpf2p_coefficients(800.0, 40.0)
    delay = lpf2p_reset(coefficients, 2.5)
    for _ in range(5):
        y, delay = lpf2p_apply(coefficients, delay, 2.5)
        assert y == pytest.approx(2.5, rel=1e-12)
    for fc in (0.0, 400.0, 500.0):  # PX4 disables the filter: a pass-through
        assert lpf2p_coefficients(800.0, fc) == (1.0, 0.0, 0.0, 0.0, 0.0)
        assert lpf2p_apply(lpf2p_coefficients(800.0, fc), (0.0, 0.0), 1.7)[0] == 1.7


def test_the_d_term_filter_is_a_first_order_lag():
    alpha = alpha_of(800.0, 30.0)
    assert alpha == pytest.approx((1 / 800) / (1 / 800 + 1 / (2 * np.pi * 30)))
    x = np.random.default_rng(4).normal(size=300)
    state, out = 0.0, []
    for sample in x:
        state = alpha_apply(alpha, state, sample)
        out.append(state)
    assert np.allclose(out, lfilter([alpha], [1.0, alpha - 1.0], x), atol=1e-12)
    assert alpha_of(800.0, 0.0) == 1.0 and alpha_of(800.0, 400.0) == 1.0


def test_the_frames_are_the_ulog_writers():
    rng = np.random.default_rng(5)
    for _ in range(20):
        v = tuple(rng.normal(size=3))
        assert np.allclose(enu_to_ned(v), ENU_TO_NED @ v) and np.allclose(flu_to_frd(v), FLU_TO_FRD @ v)
        rot = Rotation.random(random_state=rng)
        q = tuple(rot.as_quat(scalar_first=True))
        q_ned = quat_enu_flu_to_ned_frd(q)
        assert np.allclose(np.array(dcm_from_quat(q_ned)), ENU_TO_NED @ rot.as_matrix() @ FLU_TO_FRD, atol=1e-12)
        assert np.allclose(np.array(dcm_from_quat(q)), rot.as_matrix(), atol=1e-12)
        back = quat_enu_flu_to_ned_frd(q_ned)
        assert np.allclose(np.array(dcm_from_quat(back)), rot.as_matrix(), atol=1e-12)  # its own inverse
    level_east = tuple(Rotation.from_euler("z", 0.0).as_quat(scalar_first=True))  # ENU: nose east
    assert np.allclose(np.array(dcm_from_quat(quat_enu_flu_to_ned_frd(level_east)))[:, 0], (0, 1, 0))  # NED: east
