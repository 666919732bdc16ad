"""The sensor models' noise, against statistics computed here independently: sample variance
against density * sqrt(rate), the Allan deviation of white noise against density / sqrt(tau),
the spread of a random walk against density * sqrt(T), and the deterministic parts (scale,
misalignment, range, resolution, field geometry, timing) against numpy's own arithmetic."""

from __future__ import annotations

import math

import numpy as np
import pytest
from scipy.stats import chi2

from quadcruise.errors import InputError
from quadcruise.sensors import BMI088, ICM42688P, Baro, Gps, Imu, Magnetometer


def allan_deviation(y: np.ndarray, rate: float, tau: float) -> float:
    """Non-overlapping Allan deviation of the rate series y at cluster time tau (IEEE 952 Annex C)."""
    m = int(round(tau * rate))
    n = y.size // m
    means = y[: n * m].reshape(n, m).mean(axis=1)
    return float(np.sqrt(0.5 * np.mean(np.diff(means) ** 2)))


def variance_interval(n: int, p: float = 0.999) -> tuple[float, float]:
    """Where sample variance / true variance lies with probability p, for n normal samples."""
    return chi2.ppf((1 - p) / 2, n - 1) / (n - 1), chi2.ppf((1 + p) / 2, n - 1) / (n - 1)


def test_white_noise_variance_and_allan_deviation():
    imu = Imu(rate=400.0, gyro_noise=2e-4, accel_noise=2e-3)
    z = np.zeros((40000, 3))
    out, _ = imu.measure(z, z, seed=7)
    lo, hi = variance_interval(out.shape[0])
    for j, n in ((0, 2e-4), (3, 2e-3)):
        for col in out[:, j : j + 3].T:
            ratio = col.var() / (n * math.sqrt(400.0)) ** 2
            assert lo < ratio < hi, (j, ratio)
        # white noise: ADEV(tau) = n / sqrt(tau); 100 clusters of 1 s -> ~7 % spread
        adev = allan_deviation(out[:, j], 400.0, 1.0)
        assert abs(adev / n - 1.0) < 0.3, adev / n
    # the other direction: a density 4x smaller is told apart
    assert out[:, 0].var() / (0.5e-4 * 20.0) ** 2 > 10.0


def test_bias_random_walk_grows_as_density_sqrt_time():
    r, T, rate = 1e-3, 50.0, 100.0
    imu = Imu(rate=rate, gyro_bias_walk=r, accel_bias_walk=2 * r)
    z = np.zeros((int(T * rate), 3))
    biases = np.array([imu.measure(z, z, seed=3, vehicle=i)[1][:6] for i in range(150)])
    lo, hi = variance_interval(biases.shape[0] * 3)
    g = biases[:, :3].ravel()
    a = biases[:, 3:].ravel()
    assert lo < np.mean(g**2) / (r**2 * T) < hi
    assert lo < np.mean(a**2) / ((2 * r) ** 2 * T) < hi
    # without a walk the bias stays where it was switched on
    still = Imu(rate=rate, gyro_bias_init=0.01)
    out, st = still.measure(z, z, seed=3)
    assert np.allclose(out[:, :3], st[:3]) and np.any(st[:3] != 0)


def test_scale_misalignment_range_and_resolution():
    imu = Imu(rate=100.0, scale_error=0.02, misalignment=0.01)
    rng = np.random.default_rng(0)
    w, f = rng.normal(size=(50, 3)), rng.normal(size=(50, 3)) * 9.0
    out, st = imu.measure(w, f, seed=2)
    Mg, Ma = st[6:15].reshape(3, 3), st[15:24].reshape(3, 3)
    assert np.allclose(out[:, :3], w @ Mg.T) and np.allclose(out[:, 3:], f @ Ma.T)
    assert not np.allclose(Mg, np.eye(3)) and np.all(np.abs(np.diag(Mg) - 1) < 0.1)
    big = np.full((5, 3), 100.0)
    out, _ = BMI088.measure(big, big, seed=1)  # 100 rad/s is past 2000 deg/s, 100 m/s^2 within 24 g
    assert np.all(out[:, :3] == BMI088.gyro_range) and np.all(np.abs(out[:, 3:] - 100.0) < 1.0)
    sat = Imu(gyro_range=30.0, accel_range=50.0, gyro_lsb=0.01, accel_lsb=0.05)
    out, _ = sat.measure(big, -big * 10, seed=1)
    assert np.all(out[:, :3] == 30.0) and np.all(out[:, 3:] == -50.0)
    fine, _ = sat.measure(np.full((3, 3), 0.123456), np.full((3, 3), 1.23456), seed=1)
    assert np.allclose(fine[:, :3] / 0.01, np.round(fine[:, :3] / 0.01)) and np.allclose(fine[:, 0], 0.12)
    assert np.allclose(fine[:, 3], 1.25)


def test_seeded_streams():
    z = np.zeros((100, 3))
    a, _ = ICM42688P.measure(z, z, seed=5, vehicle=2)
    b, _ = ICM42688P.measure(z, z, seed=5, vehicle=2)
    c, _ = ICM42688P.measure(z, z, seed=5, vehicle=3)
    assert np.array_equal(a, b) and not np.array_equal(a, c)


def test_presets_carry_datasheet_densities():
    assert BMI088.gyro_noise == pytest.approx(math.radians(0.014))
    assert ICM42688P.accel_noise == pytest.approx(70e-6 * 9.80665)


def test_gps_timing_outage_and_noise():
    t = np.linspace(0.0, 400.0, 4001)
    pos = np.column_stack([t, 2 * t, 0 * t + 5])
    vel = np.tile([1.0, 2.0, 0.0], (t.size, 1))
    gps = Gps(rate=5.0, latency=0.2, horizontal_std=0.7, vertical_std=1.5, velocity_std=0.05,
              vertical_velocity_std=0.2, outage_start=100.0, outage_duration=50.0)  # fmt: skip
    ts, ta, z = gps.measure(t, pos, vel, seed=1)
    assert np.allclose(np.diff(ts[ts < 100]), 0.2) and np.allclose(ta - ts, 0.2)
    assert not np.any((ts >= 100.0) & (ts < 150.0)) and np.any(ts >= 150.0)
    err = z - np.column_stack([ts, 2 * ts, 0 * ts + 5, np.tile([1.0, 2.0, 0.0], (ts.size, 1))])
    lo, hi = variance_interval(ts.size)
    for j, s in enumerate((0.7, 0.7, 1.5, 0.05, 0.05, 0.2)):
        assert lo < err[:, j].var() / s**2 < hi, j


def test_baro_drift_and_noise():
    t = np.array([0.0, 100.0])
    b = Baro(rate=10.0, noise_std=0.3, bias_init=0.5, drift=0.05)
    finals, noise = [], []
    for i in range(200):
        ts, h, bias = b.measure(t, np.array([10.0, 10.0]), seed=4, vehicle=i)
        finals.append(bias[-1])
        noise.append(h - 10.0 - bias)
    lo, hi = variance_interval(200)
    assert lo < np.var(finals) / (0.5**2 + 0.05**2 * 100.0) < hi
    lo, hi = variance_interval(200 * ts.size)
    assert lo < np.var(noise) / 0.3**2 < hi


def test_magnetometer_field_geometry_and_noise():
    d, inc = math.radians(10.0), math.radians(60.0)
    m = Magnetometer(rate=10.0, strength=0.5, declination=d, inclination=inc, noise_std=0.0)
    B = m.world_field()
    assert math.degrees(math.atan2(B[0], B[1])) == pytest.approx(10.0)  # east of north
    assert math.degrees(math.atan2(-B[2], math.hypot(B[0], B[1]))) == pytest.approx(60.0)
    yaw = 0.7  # level, nose yawed 0.7 rad counter-clockwise from east
    q = np.array([[math.cos(yaw / 2), 0, 0, math.sin(yaw / 2)]] * 2)
    _, z, _ = m.measure(np.array([0.0, 1.0]), q, seed=1)
    c, s = math.cos(yaw), math.sin(yaw)
    Rz = np.array([[c, -s, 0], [s, c, 0], [0, 0, 1]])
    assert np.allclose(z, Rz.T @ B)
    noisy = Magnetometer(rate=50.0, noise_std=0.01, bias_std=0.05)
    _, z, bias = noisy.measure(np.array([0.0, 200.0]), np.array([[1.0, 0, 0, 0]] * 2), seed=1)
    e = z - noisy.world_field() - bias
    lo, hi = variance_interval(e.size)
    assert lo < e.var() / 0.01**2 < hi and np.any(bias != 0)


@pytest.mark.parametrize(
    ("make", "words"),
    [
        (lambda: Imu(gyro_noise=-1.0), "imu field 'gyro_noise'"),
        (lambda: Gps(rate=0.0), "gps field 'rate'"),
        (lambda: Baro(drift=float("nan")), "baro field 'drift'"),
        (lambda: Magnetometer(strength=-0.5), "mag field 'strength'"),
    ],
)
def test_bad_parameters_are_refused_by_name(make, words):
    with pytest.raises(InputError, match=words):
        make()


def test_step_functions_give_the_series_readings():
    from quadcruise.sensors.baro import baro_read
    from quadcruise.sensors.mag import mag_read
    from quadcruise.sim.rng import vehicle_states

    b = Baro(rate=10.0, noise_std=0.2, bias_init=0.0, drift=0.1)
    ts, h, bias = b.measure(np.array([0.0, 2.0]), np.array([3.0, 3.0]), seed=9)
    s, st, steps = vehicle_states(9, 1)[0, 0], np.zeros(1), []  # bias_init 0: no switch-on draw
    for _ in ts:
        r, s = baro_read(b.row(), st, 3.0, np.uint64(s))  # back in Python a state is an int
        steps.append(r)
    assert np.allclose(steps, h)
    out = np.empty(3)
    mag_read(
        Magnetometer(noise_std=0.0).row(), np.array([0.1, 0.0, -0.1]), 0.2, 0.3, 0.4, out, vehicle_states(1, 1)[0, 0]
    )
    assert np.allclose(out, [0.3, 0.3, 0.3])


def test_sensor_rate_must_divide_the_control_rate():
    from quadcruise.sensors.timing import periods_per_sample

    assert periods_per_sample("imu", 250.0, 0.001) == 4 and periods_per_sample("imu", 1000.0, 0.001) == 1
    for rate in (300.0, 2000.0):
        with pytest.raises(InputError, match=f"imu rate {rate:g} Hz does not divide the control rate 1000 Hz"):
            periods_per_sample("imu", rate, 0.001)
