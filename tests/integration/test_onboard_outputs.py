"""A flight on sensors and the EKF from the command line (issue 35): bad input refused in one line
before any work, the output folder's scenario.toml flies the same numbers again, and ``--ulog``
writes the sensors' and the estimator's topics as pyulog reads them, with PX4's meanings."""

from __future__ import annotations

import math

import numpy as np
import pandas as pd
import pytest
from click.testing import CliRunner
from pyulog import ULog

from quadcruise.cli import main


def run(*args):
    return CliRunner().invoke(main, [str(a) for a in args])


@pytest.mark.parametrize(
    ("args", "message"),
    [
        (["--sensors", "imu,lidar"], "--sensors: unknown sensor 'lidar'"),
        (["--sensors", "imu=foo"], "unknown imu preset 'foo'"),
        (["--estimator", "ekf"], "--estimator ekf needs the sensor 'imu'"),
        (["--sensors", "imu,baro,mag", "--estimator", "ekf"], "needs the sensor 'gps' (without it the horizontal"),
        (["--sensors", "imu,gps", "--estimator", "kalman"], "unknown estimator 'kalman'"),
        (["--sensors", "imu,gps", "--estimator", "ekf", "--dt", "0.003"], "imu rate 250 Hz does not divide"),
    ],
)
def test_bad_sensor_options_are_one_line_and_exit_2(tmp_path, args, message):
    out = tmp_path / "flight"
    res = run("fly", "hover", "--duration", "1", "--out", out, *args)
    assert res.exit_code == 2, res.output
    assert message in res.output and "Traceback" not in res.output
    assert len(res.output.strip().splitlines()) == 1
    assert not out.exists()  # before any work


@pytest.mark.parametrize(
    ("text", "message"),
    [
        ("[sensors.imu]\ngyro_noise = -1.0\n", "[sensors] imu field 'gyro_noise' (gyro noise density"),
        ('[sensors]\nimu = "typical"\nradar = "typical"\n', "[sensors] unknown key 'radar'"),
        ('[sensors]\nimu = { rate = 300.0 }\ngps = "typical"\n', "imu rate 300 Hz does not divide the control rate"),
        ('[sensors]\nimu = "typical"\ngps = { rate = 500.0 }\n', "gps rate 500 Hz is above the imu rate"),
        ('[sensors]\nimu = "typical"\n[estimator]\nkind = "ekf"\n', "needs the sensor 'gps'"),
        ('[estimator]\nkind = "ukf"\n', "[estimator] 'kind' must be one of ekf, none"),
        (
            '[sensors]\nimu = "typical"\n[disturbances]\nsensor_noise = { position_std = 0.1 }\n',
            "[sensors] and [disturbances] sensor_noise: give one",
        ),
    ],
)
def test_bad_sensor_tables_are_one_line_and_exit_2(tmp_path, text, message):
    path = tmp_path / "s.toml"
    path.write_text('[mission]\nkind = "hover"\n[simulation]\nduration = 1.0\n' + text)
    res = run("fly", path)
    assert res.exit_code == 2, res.output
    assert message in res.output and len(res.output.strip().splitlines()) == 1


def test_the_folder_flies_the_same_numbers_again_and_the_ulog_has_the_estimator(tmp_path):
    first, again, log = tmp_path / "a", tmp_path / "b", tmp_path / "f.ulg"
    res = run(
        "fly", "hover", "--duration", "3", "--sensors", "imu=bmi088,gps,baro,mag", "--estimator", "ekf",
        "--dt", "0.0025", "--out", first, "--ulog", log,
    )  # fmt: skip
    assert res.exit_code == 0, res.output
    assert "estimate_attitude_rmse_deg" in res.output and "nees_position" in res.output
    scenario = (first / "scenario.toml").read_text()
    assert "[sensors.imu]" in scenario and 'kind = "ekf"' in scenario and "rate = 400.0" in scenario
    res = run("fly", first / "scenario.toml", "--out", again)
    assert res.exit_code == 0, res.output
    a, b = pd.read_csv(first / "traces.csv"), pd.read_csv(again / "traces.csv")
    assert "x_est" in a.columns and "nees_att" in a.columns
    pd.testing.assert_frame_equal(a, b)  # the same numbers
    traces = a.set_index(np.round(a["t"] * 1e6).astype(np.uint64))

    ulog = ULog(str(log))
    data = {d.name: d.data for d in ulog.data_list}
    topics = ("sensor_combined", "vehicle_gps_position", "sensor_baro", "estimator_states", "estimator_innovations")
    assert set(topics) <= set(data)
    # sensor_combined: the IMU model's readings (400 Hz), FRD: at hover the accelerometer reads -g on z
    imu = data["sensor_combined"]
    assert np.all(np.diff(imu["timestamp"]) == 2500) and np.all(imu["gyro_integral_dt"] == 2500)
    assert abs(np.mean(imu["accelerometer_m_s2[2]"]) + 9.81) < 0.3  # the BMI088's switch-on bias: ~0.2
    np.testing.assert_allclose(imu["gyro_rad[1]"], -traces.loc[imu["timestamp"], "gyro_y"], rtol=1e-6, atol=1e-6)
    # vehicle_gps_position: geodetic about PX4 SITL's home, altitude above mean sea level
    gps = data["vehicle_gps_position"]
    north = np.radians(gps["latitude_deg"] - 47.397742) * 6378137.0
    east = np.radians(gps["longitude_deg"] - 8.545594) * 6378137.0 * math.cos(math.radians(47.397742))
    truth = traces.loc[gps["timestamp_sample"]]
    assert np.all(gps["timestamp"] - gps["timestamp_sample"] == 100_000)  # 0.1 s late
    assert np.all(np.abs(north - truth["y"].to_numpy()) < 4 * 0.5) and np.all(np.abs(east - truth["x"].to_numpy()) < 2)
    assert np.all(np.abs(gps["altitude_msl_m"] - 488.0 - truth["z"].to_numpy()) < 4 * 0.8)
    assert np.all(gps["fix_type"] == 3) and np.all(gps["eph"] == 0.5)
    # sensor_baro: PX4's own pressure-to-altitude formula gives the altitude back
    baro = data["sensor_baro"]
    t1, a_, r, g, p1 = 288.15, -6.5e-3, 287.05, 9.80665, 101325.0
    altitude = ((baro["pressure"] / p1) ** (-(a_ * r) / g) * t1 - t1) / a_
    z = traces.loc[baro["timestamp"], "z"].to_numpy()
    assert np.sqrt(np.mean((altitude - 488.0 - z) ** 2)) < 0.2  # the barometer's 0.1 m noise (float32 Pa: ~0.1 m)
    # estimator_states: EKF2's order, NED: pos[2] is minus the estimated altitude
    states = data["estimator_states"]
    est = traces.loc[states["timestamp"]]
    np.testing.assert_allclose(states["states[9]"], -est["z_est"], atol=1e-5)
    np.testing.assert_allclose(states["states[7]"], est["y_est"], atol=1e-5)
    np.testing.assert_allclose(states["covariances[8]"], est["sd_z"] ** 2, rtol=1e-5)
    assert np.all(states["n_states"] == 16)
    q = np.column_stack([states[f"states[{i}]"] for i in range(4)])
    np.testing.assert_allclose(np.linalg.norm(q, axis=1), 1.0, atol=1e-6)
    # estimator_innovations: EKF2's sign, predicted minus observed, NED
    innov = data["estimator_innovations"]
    est = traces.loc[innov["timestamp"]]
    np.testing.assert_allclose(innov["gps_hpos[0]"], -est["innov_gps_y"].fillna(0.0), atol=1e-5)
    np.testing.assert_allclose(innov["baro_vpos"], est["innov_baro"].fillna(0.0), atol=1e-5)
