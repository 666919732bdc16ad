"""PX4's hover-thrust estimator (``quadcruise.control.px4hover``) against PX4's own unit test
(``src/modules/mc_hover_thrust_estimator/zero_order_hover_thrust_ekf_test.cpp``: its cases,
inputs and tolerances restated; its noise drawn here from numpy with a fixed seed, not from
``std::default_random_engine``) and against the estimate PX4 logged in the SITL log."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest
from pyulog import ULog

from quadcruise.control.px4hover import (
    HTE_ACC_VAR,
    HTE_HOVER,
    HTE_STATE,
    HTE_VAR,
    hte_fuse,
    hte_noise_scale,
    hte_predict,
    hte_reset,
)

LOG = Path(__file__).parents[1] / "data" / "px4" / "sample_px4_events.ulg"
G = 9.80665
DT = 0.02  # the test's _dt
PROCESS_VAR = 12.5e-6  # ZeroOrderHoverThrustEkf's defaults: _process_var, _state_var 0.01, _acc_var 5, gate 3
ACCEL_NOISE_VAR_MIN = 1.0


class Ekf:
    """``ZeroOrderHoverThrustEkfTest``'s fixture: a filter with the class's defaults, run at 50 Hz."""

    def __init__(self, seed: int = 42):
        self.s = hte_reset(0.5, 0.1)  # _hover_thr 0.5, _state_var 0.01
        self.rng = np.random.default_rng(seed)

    def run(self, hover_true, thrust, time, accel_noise=0.0, thr_noise=0.0):
        """``runEkf``: ``for (float t = 0.f; t <= time; t += _dt)``, counted in float32 as PX4 does."""
        t, steps = np.float32(0.0), 0
        while t <= np.float32(time):
            steps += 1
            t = np.float32(t + np.float32(DT))
        for _ in range(steps):
            hte_predict(self.s, DT, PROCESS_VAR)
            noisy_thrust = thrust + thr_noise * self.rng.standard_normal()
            accel = G * thrust / hover_true - G + accel_noise * self.rng.standard_normal()
            hte_fuse(self.s, accel, noisy_thrust, 3.0, 1.0, 0.1, 0.9, PROCESS_VAR)
        return self.s[HTE_HOVER], self.s[HTE_VAR], self.s[HTE_ACC_VAR]


def test_static_case():
    """testStaticCase: at hover from the true value, the estimate does not move and its variance falls."""
    hover, var, acc_var = Ekf().run(0.5, 0.5, 2.0)
    assert hover == pytest.approx(0.5, abs=1e-4)
    assert var == pytest.approx(0.0, abs=1e-3)
    assert acc_var == pytest.approx(ACCEL_NOISE_VAR_MIN, abs=1.0)


def test_static_convergence():
    """testStaticConvergence: from 0.5 to a true 0.72 in 2 s, noiseless."""
    hover, var, acc_var = Ekf().run(0.72, 0.72, 2.0)
    assert hover == pytest.approx(0.72, abs=1e-2)
    assert var == pytest.approx(0.0, abs=1e-3)
    assert acc_var == pytest.approx(ACCEL_NOISE_VAR_MIN, abs=1.0)


@pytest.mark.parametrize("seed", [42, 7])
def test_static_convergence_with_noise(seed):
    """testStaticConvergenceWithNoise: 3 m/s^2 of noise, 10 s: the estimate and the learnt noise."""
    hover, var, acc_var = Ekf(seed).run(0.72, 0.72, 10.0, accel_noise=3.0)
    assert hover == pytest.approx(0.72, abs=5e-2)
    assert var == pytest.approx(0.0, abs=1e-3)
    assert acc_var == pytest.approx(9.0, abs=0.2 * 9.0)


@pytest.mark.parametrize("seed", [42, 7])
def test_large_accel_noise_and_bias(seed):
    """testLargeAccelNoiseAndBias: descending (thrust 0.4 below a true 0.72), 7 m/s^2 of noise, 15 s."""
    hover, var, acc_var = Ekf(seed).run(0.72, 0.4, 15.0, accel_noise=7.0)
    assert hover == pytest.approx(0.72, abs=7e-2)
    assert var == pytest.approx(0.0, abs=1e-3)
    assert acc_var == pytest.approx(49.0, abs=0.2 * 49.0)


@pytest.mark.parametrize("seed", [42, 7])
def test_thrust_and_accel_noise(seed):
    """testThrustAndAccelNoise: climbing (0.72 over a true 0.6), noisy thrust and acceleration, 15 s."""
    hover, var, acc_var = Ekf(seed).run(0.6, 0.72, 15.0, accel_noise=2.0, thr_noise=0.01)
    assert hover == pytest.approx(0.6, abs=5e-2)
    assert var == pytest.approx(0.0, abs=1e-3)
    assert acc_var == pytest.approx(4.0, abs=0.4 * 4.0)


def test_hover_thrust_jump():
    """testHoverThrustJump: 0.8 for 10 s, then an extreme jump to 0.3: the recovery (the rejected
    measurements bump the variance, the learnt noise widens the gate) reaches the new value.

    PX4's test asserts 0.05 after 10 s with its own noise sequence; with numpy's, 22 of 30 seeds
    are within 0.05 and all 30 within 0.07 after 10 s (0.323 to 0.367), so the time it takes
    depends on the draw: restated as within 0.07 after 10 s and PX4's 0.05 after 12 s."""
    ekf = Ekf()
    ekf.run(0.8, 0.8, 10.0, accel_noise=2.0, thr_noise=0.01)
    hover, var, acc_var = ekf.run(0.3, 0.3, 10.0, accel_noise=2.0, thr_noise=0.01)
    assert hover == pytest.approx(0.3, abs=7e-2)
    hover, var, acc_var = ekf.run(0.3, 0.3, 2.0, accel_noise=2.0, thr_noise=0.01)
    assert hover == pytest.approx(0.3, abs=5e-2)
    assert var == pytest.approx(0.0, abs=1e-3)
    assert acc_var == pytest.approx(4.0, abs=2.0 * 4.0)


def test_the_gate_rejects_an_outlier_and_the_range_holds():
    """A measurement 100 m/s^2 off is past the 3-sigma gate: the state stays; an estimate is kept
    within MPC_THR_HOVER -+ HTE_THR_RANGE (the test's true 0.72 against a range [0.3, 0.7])."""
    s = hte_reset(0.5, 0.1)
    before = s.copy()
    assert not hte_fuse(s, 100.0, 0.5, 3.0, 1.0, 0.1, 0.9, PROCESS_VAR)
    assert s[HTE_HOVER] == before[HTE_HOVER] and s[HTE_VAR] == before[HTE_VAR]
    s = hte_reset(0.5, 0.1)
    for _ in range(200):
        hte_predict(s, DT, PROCESS_VAR)
        hte_fuse(s, 0.0, 0.72, 3.0, 1.0, 0.3, 0.7, PROCESS_VAR)
    assert s[HTE_HOVER] == 0.7
    assert s.size == HTE_STATE.size
    assert hte_noise_scale(3.0, 0.0, 2.0, 10.0) == 2.0 and hte_noise_scale(0.5, 1.0, 2.0, 10.0) == 1.0


def _run_on_log(thrust_offset=0.0):
    """The module's rule on the log's own inputs: reset to MPC_THR_HOVER, in the air once not
    landed and over 1 m (dist_bottom), fed -az of each vehicle_local_position (10 Hz logged) and
    -thrust[2] of the last vehicle_local_position_setpoint, moving fast scaling the noise."""
    ulog = ULog(str(LOG))
    d = {x.name: x.data for x in ulog.data_list if x.multi_id == 0}
    p = ulog.initial_parameters
    lp, sp, land = d["vehicle_local_position"], d["vehicle_local_position_setpoint"], d["vehicle_land_detected"]
    hover0, span = p["MPC_THR_HOVER"], p["HTE_THR_RANGE"]
    s = hte_reset(hover0, p["HTE_HT_ERR_INIT"])
    q = p["HTE_HT_NOISE"] ** 2
    in_air, last, out = False, None, []
    for k, t in enumerate(lp["timestamp"]):
        i = np.searchsorted(land["timestamp"], t, side="right") - 1
        if i < 0 or land["landed"][i]:
            in_air = False
        elif lp["dist_bottom"][k] > 1.0:
            in_air = True
        dt = (int(t) - int(last)) * 1e-6 if last is not None else 0.0
        last = t
        j = np.searchsorted(sp["timestamp"], t, side="right") - 1
        if in_air and 0.001 < dt < 1.0 and j >= 0:
            hte_predict(s, dt, q)
            scale = hte_noise_scale(lp["vz"][k], np.hypot(lp["vx"][k], lp["vy"][k]), p["HTE_VZ_THR"], p["HTE_VXY_THR"])
            thrust = -float(sp["thrust[2]"][j]) + thrust_offset
            hte_fuse(s, -float(lp["az"][k]), thrust, p["HTE_ACC_GATE"], scale, hover0 - span, hover0 + span, q)
            out.append((int(t), s[HTE_HOVER]))
    ours = np.array(out)
    est = d["hover_thrust_estimate"]
    ok = np.isfinite(est["hover_thrust"])
    logged = np.interp(ours[:, 0], est["timestamp"][ok].astype(float), est["hover_thrust"][ok].astype(float))
    inside = (ours[:, 0] >= est["timestamp"][ok][0]) & (ours[:, 0] <= est["timestamp"][ok][-1])
    return ours[inside, 1], logged[inside]


def test_pxs_logged_hover_thrust_estimate_is_reproduced():
    """Fed the SITL log's inputs at their logged 10 Hz (PX4 ran at the estimator's 100 Hz), the
    filter follows PX4's own hover_thrust_estimate (0.49 to 0.475 over the flight, the descent's
    drop included) within 0.003 (measured 0.0015); a thrust 0.02 too high moves it off by more."""
    ours, logged = _run_on_log()
    assert ours.size > 40
    assert np.max(np.abs(ours - logged)) < 3e-3
    assert logged.max() - logged.min() > 0.01  # it changes: the descent at 0.7 m/s is seen
    off, logged = _run_on_log(thrust_offset=0.02)
    assert np.max(np.abs(off - logged)) > 0.01
