"""The error-state EKF against a closed-form flight: its kinematics against scipy's rotations
and an exact trajectory, its heading Jacobian against finite differences, and its
consistency (NEES of position, velocity, attitude and the NIS of every update inside the
chi-square 95 % bounds over Monte Carlo runs; a filter told the wrong noise fails them)."""

from __future__ import annotations

import numpy as np
import pytest
from scipy.spatial.transform import Rotation

from quadcruise.estimation import EkfNoise, average_bounds, errors, nees, run_ekf, tilted_circle
from quadcruise.estimation.ekf import heading_innovation, quat_exp, quat_log, quat_mul, rotation
from quadcruise.sensors import Baro, Gps, Imu, Magnetometer

RATE = 200.0
IMU = Imu(rate=RATE, gyro_noise=2.4e-4, accel_noise=1.7e-3, gyro_bias_walk=2e-5, accel_bias_walk=3e-4,
          gyro_bias_init=0.005, accel_bias_init=0.05)  # fmt: skip
GPS, BARO = Gps(rate=10.0), Baro(rate=20.0, noise_std=0.2)
MAG = Magnetometer(rate=20.0, noise_std=0.003, declination=0.05)
SD0 = np.r_[[1.0] * 3, [0.2] * 3, [0.02] * 3, [IMU.gyro_bias_init] * 3, [IMU.accel_bias_init] * 3]


def matched(scale: float = 1.0) -> EkfNoise:
    """The filter told the sensors' own noise, every figure times ``scale``."""
    return EkfNoise(
        gyro_noise=IMU.gyro_noise * scale, accel_noise=IMU.accel_noise * scale,
        gyro_bias_walk=IMU.gyro_bias_walk, accel_bias_walk=IMU.accel_bias_walk,
        gps_horizontal_std=GPS.horizontal_std * scale, gps_vertical_std=GPS.vertical_std * scale,
        gps_velocity_std=GPS.velocity_std * scale, gps_vertical_velocity_std=GPS.vertical_velocity_std * scale,
        baro_std=BARO.noise_std * scale, heading_std=MAG.noise_std / np.hypot(*MAG.world_field()[:2]) * scale,
        gate=1.0,
    )  # fmt: skip


def monte_carlo(settings: EkfNoise, runs: int, duration: float = 30.0, stride: int = 20) -> dict:
    """Each block's NEES and each stream's NIS, averaged over runs at each instant."""
    t = np.arange(0.0, duration + 1e-9, 1.0 / RATE)
    truth, mid = tilted_circle(t), tilted_circle(t + 0.5 / RATE)  # a reading covers [t_k, t_k+1]
    rng = np.random.default_rng(1)
    sums: dict = {}
    for i in range(runs):
        z, st = IMU.measure(mid["rates"], mid["specific_force"], seed=11, vehicle=i)
        g = GPS.measure(t, truth["position"], truth["velocity"], seed=12, vehicle=i)
        b = BARO.measure(t, truth["position"][:, 2], seed=13, vehicle=i)
        m = MAG.measure(t, truth["quaternion"], seed=14, vehicle=i)
        e0 = rng.normal(size=15) * SD0  # the initial error drawn from P0
        q0 = Rotation.from_quat(truth["quaternion"][0, [1, 2, 3, 0]]) * Rotation.from_rotvec(-e0[6:9])
        x0 = np.r_[truth["position"][0] - e0[:3], truth["velocity"][0] - e0[3:6], q0.as_quat()[[3, 0, 1, 2]],
                   st[0:3] - e0[9:12], st[3:6] - e0[12:15]]  # fmt: skip
        run = run_ekf(t, z, x0, np.diag(SD0**2), settings, gps=(g[0], g[2]), baro=(b[0], b[1]),
                      mag=(m[0], m[1]), field=MAG.world_field(), stride=stride)  # fmt: skip
        k = slice(None, None, stride)
        values = nees(errors(run.x[k], truth["position"][k], truth["velocity"][k], truth["quaternion"][k]), run.cov)
        values.update(run.nis)
        for name, v in values.items():
            sums[name] = sums.get(name, 0.0) + v / runs
    return sums


DOF = {"position": 3, "velocity": 3, "attitude": 3, "gps_pos": 3, "gps_vel": 3, "baro": 1, "mag": 1}


def test_quaternion_helpers_match_scipy():
    r = np.array([0.3, -0.2, 0.5])
    q = quat_exp(*r)
    assert np.allclose(rotation(q), Rotation.from_rotvec(r).as_matrix())
    a, b = Rotation.from_rotvec([0.1, 0.2, 0.3]), Rotation.from_rotvec([-0.4, 0.1, 0.2])
    qa, qb = a.as_quat()[[3, 0, 1, 2]], b.as_quat()[[3, 0, 1, 2]]
    assert np.allclose(rotation(quat_mul(qa, qb)), (a * b).as_matrix())
    assert np.allclose(quat_log(q), r)


def test_noise_free_prediction_follows_the_closed_form_flight():
    t = np.arange(0.0, 20.0 + 1e-9, 1.0 / RATE)
    truth, mid = tilted_circle(t), tilted_circle(t + 0.5 / RATE)
    # the closed-form rates are those of the attitude history (scipy finite difference)
    rot = Rotation.from_quat(truth["quaternion"][:, [1, 2, 3, 0]])
    fd = (rot[:-1].inv() * rot[1:]).as_rotvec() * RATE
    assert np.abs(fd - mid["rates"][:-1]).max() < 1e-4
    x0 = np.r_[truth["position"][0], truth["velocity"][0], truth["quaternion"][0], np.zeros(6)]
    run = run_ekf(t, np.column_stack([mid["rates"], mid["specific_force"]]), x0, np.eye(15) * 1e-6, EkfNoise())
    err = errors(run.x, truth["position"], truth["velocity"], truth["quaternion"])
    assert np.abs(err[:, :3]).max() < 0.01 and np.abs(err[:, 6:]).max() < 1e-5
    # the other direction: a 1 mrad/s gyro offset left in drifts away
    bad = np.column_stack([mid["rates"] + 1e-3, mid["specific_force"]])
    err = errors(run_ekf(t, bad, x0, np.eye(15) * 1e-6, EkfNoise()).x, truth["position"], truth["velocity"],
                 truth["quaternion"])  # fmt: skip
    assert np.abs(err[:, :3]).max() > 0.1


def test_heading_jacobian_matches_finite_differences():
    field = MAG.world_field()
    q = Rotation.from_euler("ZYX", [0.7, 0.2, -0.3])
    x = np.r_[np.zeros(6), q.as_quat()[[3, 0, 1, 2]], np.zeros(6)]
    m = q.inv().apply(field)  # the reading of the true attitude
    H, scratch = np.zeros((1, 15)), np.zeros((1, 15))
    r0 = heading_innovation(x, *m, field, H)
    assert abs(r0) < 1e-12
    for i in range(3):
        d = np.zeros(3)
        d[i] = 1e-6  # the truth is the estimate turned by d (body frame): R_true = R Exp(d)
        m_d = (q * Rotation.from_rotvec(d)).inv().apply(field)
        r = heading_innovation(x, *m_d, field, scratch)
        assert r / 1e-6 == pytest.approx(H[0, 6 + i], abs=1e-4)


@pytest.mark.slow
def test_consistency_over_50_runs_and_wrong_noise_fails():
    runs = 50
    avg = monte_carlo(matched(), runs)
    for name, v in avg.items():
        lo, hi = average_bounds(DOF[name], runs)
        # the run-averaged NEES / NIS: its mean over time inside the 95 % interval, and at most
        # instants inside it too (95 % expected; neighbouring instants are correlated)
        assert lo < v.mean() < hi, (name, v.mean(), lo, hi)
        assert np.mean((v > lo) & (v < hi)) > 0.85, (name, np.mean((v > lo) & (v < hi)))
    for scale, side in ((0.4, "above"), (3.0, "below")):
        wrong = monte_carlo(matched(scale), 10)
        for name in ("position", "velocity", "attitude", "gps_pos", "baro", "mag"):
            lo, hi = average_bounds(DOF[name], 10)
            m = wrong[name].mean()
            assert (m > hi) if side == "above" else (m < lo), (scale, name, m, lo, hi)
