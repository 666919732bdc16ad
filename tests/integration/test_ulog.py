"""Flights written as PX4 logs (ULog) and read back by pyulog alone, in PX4's conventions.

The checks do not go through quadcruise's conversion: the NED position, the heading and the
body axes are rebuilt here from the ZYX angles by their textbook formulas, the accelerometer
from the rotor thrusts (the paper's plant has no other force than thrust and gravity), and
the rotor geometry from the ``CA_ROTOR*`` parameters against eqs (1)-(4).
"""

from __future__ import annotations

import math

import numpy as np
import pytest
from pyulog import ULog

import quadcruise as qc
from quadcruise.disturbances import SensorNoise
from quadcruise.errors import InputError
from quadcruise.layout import F1, PHI, PSI, THETA, X, Y, Z
from quadcruise.missions import Circle, Step
from quadcruise.model.actuators import mix

TOPICS = {
    "vehicle_local_position",
    "vehicle_attitude",
    "vehicle_angular_velocity",
    "actuator_motors",
    "sensor_combined",
    "vehicle_status",
    "vehicle_land_detected",
}


def rotate(q, v):
    """v rotated by the unit quaternion q = (w, x, y, z): q v q*, written out."""
    w, x, y, z = q
    return np.array(
        [
            (1 - 2 * (y * y + z * z)) * v[0] + 2 * (x * y - w * z) * v[1] + 2 * (x * z + w * y) * v[2],
            2 * (x * y + w * z) * v[0] + (1 - 2 * (x * x + z * z)) * v[1] + 2 * (y * z - w * x) * v[2],
            2 * (x * z - w * y) * v[0] + 2 * (y * z + w * x) * v[1] + (1 - 2 * (x * x + y * y)) * v[2],
        ]
    )


def read(path):
    log = ULog(str(path))
    assert not log.file_corruption
    return log, {d.name: d.data for d in log.data_list}


@pytest.fixture(scope="module")
def yawed_circle(tmp_path_factory):
    """A circle flown at 60 deg of yaw with noisy rate sensors, and its log."""
    res = qc.fly(Circle(yaw=math.radians(60.0)), duration=6.0, sensors=SensorNoise(rate_std=0.02), seed=7)
    path = res.to_ulog(tmp_path_factory.mktemp("ulog") / "circle.ulg")
    return res, path


def test_every_topic_is_read_back_in_microseconds(yawed_circle):
    res, path = yawed_circle
    log, data = read(path)
    assert TOPICS <= set(data)
    for name, rate in (("vehicle_attitude", 250.0), ("vehicle_local_position", 50.0)):
        stamps = data[name]["timestamp"].astype(np.int64)
        assert stamps[0] == 0 and np.all(np.diff(stamps) == round(1e6 / rate))
        assert stamps[-1] == round(res.t[-1] * 1e6)
    assert log.msg_info_dict["sys_name"] == "quadcruise"
    assert data["vehicle_status"]["arming_state"][0] == 2  # armed
    assert not data["vehicle_land_detected"]["landed"].any()


def test_position_velocity_and_attitude_in_ned_frd(yawed_circle):
    res, path = yawed_circle
    _, data = read(path)
    lp, att = data["vehicle_local_position"], data["vehicle_attitude"]
    t_lp = lp["timestamp"] / 1e6
    rows = np.searchsorted(res.t, t_lp - 1e-9)
    s = res.states[0, rows]
    np.testing.assert_allclose(lp["x"], s[:, Y], atol=1e-5)  # north = ENU y
    np.testing.assert_allclose(lp["y"], s[:, X], atol=1e-5)  # east = ENU x
    np.testing.assert_allclose(lp["z"], -s[:, Z], atol=1e-5)  # down = -up
    heading = np.angle(np.exp(1j * (math.pi / 2 - s[:, PSI])))  # from north, clockwise
    np.testing.assert_allclose(np.angle(np.exp(1j * (lp["heading"] - heading))), 0.0, atol=1e-5)

    rows = np.searchsorted(res.t, att["timestamp"] / 1e6 - 1e-9)
    for k in range(0, len(rows), 97):
        phi, th, psi = res.states[0, rows[k], [PHI, THETA, PSI]]
        q = np.array([att[f"q[{i}]"][k] for i in range(4)], dtype=float)
        assert abs(np.linalg.norm(q) - 1.0) < 1e-6
        nose_enu = np.array([math.cos(psi) * math.cos(th), math.sin(psi) * math.cos(th), -math.sin(th)])
        up_enu = np.array(
            [
                math.cos(psi) * math.sin(th) * math.cos(phi) + math.sin(psi) * math.sin(phi),
                math.sin(psi) * math.sin(th) * math.cos(phi) - math.cos(psi) * math.sin(phi),
                math.cos(th) * math.cos(phi),
            ]
        )
        enu_to_ned = lambda v: np.array([v[1], v[0], -v[2]])  # noqa: E731
        np.testing.assert_allclose(rotate(q, [1, 0, 0]), enu_to_ned(nose_enu), atol=1e-6)  # FRD x: the nose
        np.testing.assert_allclose(rotate(q, [0, 0, -1]), enu_to_ned(up_enu), atol=1e-6)  # FRD -z: body up


def test_accelerometer_reads_thrust_over_mass(yawed_circle):
    res, path = yawed_circle
    _, data = read(path)
    sc = data["sensor_combined"]
    rows = np.searchsorted(res.t, sc["timestamp"] / 1e6 - 1e-9)[2:-2]
    acc = np.column_stack([sc[f"accelerometer_m_s2[{i}]"] for i in range(3)])[2:-2]
    thrust = res.states[0, rows, F1 : F1 + 4].sum(axis=1) / res.meta["vehicle"]["m"]
    np.testing.assert_allclose(acc[:, 2], -thrust, rtol=1e-4, atol=1e-4)  # along FRD z, upward
    np.testing.assert_allclose(acc[:, :2], 0.0, atol=1e-4)


def test_gyro_carries_the_flights_sensor_noise_reproducibly(yawed_circle, tmp_path):
    res, path = yawed_circle
    _, data = read(path)
    sc = data["sensor_combined"]
    rows = np.searchsorted(res.t, sc["timestamp"] / 1e6 - 1e-9)
    noise = sc["gyro_rad[0]"] - res.states[0, rows, 9]  # FRD x = FLU x
    assert 0.017 < noise.std() < 0.023 and abs(noise.mean()) < 0.003
    again = res.to_ulog(tmp_path / "again.ulg")
    assert again.read_bytes() == path.read_bytes()


def test_quiet_sensors_write_the_truth_and_at_rest_the_accelerometer_reads_minus_g(tmp_path):
    res = qc.fly("hover", duration=1.0)
    _, data = read(res.to_ulog(tmp_path / "hover.ulg"))
    sc = data["sensor_combined"]
    np.testing.assert_allclose(sc["accelerometer_m_s2[2]"], -9.81, atol=1e-6)
    np.testing.assert_allclose(sc["gyro_rad[1]"], 0.0, atol=1e-9)
    assert data["vehicle_attitude"]["q[0]"][0] > 0.0


def test_rotor_parameters_rebuild_eqs_1_to_4(tmp_path):
    res = qc.fly(Step(axis="y", size=1.0), duration=1.0)
    log, _ = read(res.to_ulog(tmp_path / "step.ulg"))
    p = log.initial_parameters
    assert p["CA_ROTOR_COUNT"] == 4 and p["MAV_TYPE"] == 2
    veh = res.meta["vehicle"]
    rng = np.random.default_rng(0)
    for F in rng.uniform(0.0, 30.0, (5, 4)):
        torque_frd = np.zeros(3)
        for i in range(4):
            r = np.array([p[f"CA_ROTOR{i}_PX"], p[f"CA_ROTOR{i}_PY"], p[f"CA_ROTOR{i}_PZ"]])
            torque_frd += np.cross(r, [0.0, 0.0, -F[i]])  # thrust along FRD -z
            torque_frd[2] += p[f"CA_ROTOR{i}_KM"] * F[i]  # PX4: KM > 0 counter-clockwise
        U1, U2, U3, U4 = mix(*F, veh["d"])
        torque_flu = torque_frd * np.array([1.0, -1.0, -1.0])
        np.testing.assert_allclose(torque_flu, [U2 * veh["l"], U3 * veh["l"], U4], rtol=1e-6, atol=1e-6)
        assert p["CA_ROTOR0_CT"] == pytest.approx(veh["K"])


def test_bad_arguments_are_one_line(tmp_path):
    res = qc.fly("hover", duration=0.2)
    with pytest.raises(InputError, match="vehicle must be an index"):
        res.to_ulog(tmp_path / "a.ulg", vehicle=3)
    with pytest.raises(InputError, match=r"ends in \.ulg"):
        res.to_ulog(tmp_path / "a.csv")
    assert not list(tmp_path.iterdir())
