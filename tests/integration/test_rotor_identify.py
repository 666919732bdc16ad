"""A rotor-plant vehicle flown on ``sysid``, written as a PX4 log, identified: known truth back.

Each vehicle (the Crazyflie and Iris presets, and an Iris with changed inertia and motor time
constants) flies ``sysid`` under se3 with sensor noise; the flight is written as a PX4 log with
the system-identification profile (every 1 kHz command, the rotor speeds in ``esc_status``), and
``identify`` with the true mass and the preset as the base must give kf, km, Jxx, Jyy, Jzz within
5 % and tau_up, tau_down within 10 %, each identifiable and inside its 95 % interval. The truth
is the flown vehicle's fields. The 20-seed calibration is benchmarks/rotor_sysid_calibration.py
(numbers in docs/identify.md).
"""

from __future__ import annotations

import json
import math
import warnings

import numpy as np
import pytest
from click.testing import CliRunner
from pyulog import ULog

import quadcruise as qc
from quadcruise.cli.main import main
from quadcruise.disturbances import SensorNoise
from quadcruise.missions import Sysid

NOISE = SensorNoise(position_std=0.01, velocity_std=0.02, angle_std=0.005, rate_std=0.01)
WITHIN = {"kf": 0.05, "km": 0.05, "Jxx": 0.05, "Jyy": 0.05, "Jzz": 0.05, "tau_up": 0.10, "tau_down": 0.10}
VEHICLES = {
    "crazyflie": ("crazyflie", {}),
    "iris": ("iris", {}),
    "iris, changed inertia and motors": (
        "iris",
        {"Jxx": 0.035, "Jyy": 0.025, "Jzz": 0.06, "tau_up": 0.02, "tau_down": 0.03},
    ),
}


@pytest.fixture(scope="module")
def flights():
    """One 30 s sysid flight per vehicle (seed 11), shared by the tests below."""
    out = {}
    for name, (preset, changes) in VEHICLES.items():
        base = qc.Vehicle.preset(preset)
        vehicle = base.replace(**changes) if changes else base
        with warnings.catch_warnings():  # the Iris's yaw doublets hold some speed commands at 0: said, and fine
            warnings.simplefilter("ignore")
            flight = qc.fly(Sysid(repeats=1), "se3", vehicle=vehicle, sensors=NOISE, seed=11)
        assert flight.ok[0], flight.status_text(0)
        out[name] = (base, vehicle, flight)
    return out


@pytest.mark.slow
@pytest.mark.parametrize("name", list(VEHICLES))
def test_round_trip_recovers_the_rotor_plant(name, flights, tmp_path):
    base, vehicle, flight = flights[name]
    path = flight.to_ulog(tmp_path / "sysid.ulg")
    result = qc.identify(path, vehicle=base, mass=float(vehicle.m), commands="rad/s")
    for key, tol in WITHIN.items():
        p, truth = result.parameters[key], float(getattr(vehicle, key))
        assert p["identifiable"], (key, p)
        assert abs(p["value"] / truth - 1) < tol, (key, p["value"], truth)
        assert p["ci95"][0] <= truth <= p["ci95"][1], (key, p, truth)
    k_d = result.parameters["k_d"]
    assert k_d["identifiable"] and k_d["ci95"][0] <= vehicle.k_d <= k_d["ci95"][1], k_d
    hover = result.parameters["hover_speed"]
    assert hover["value"] == pytest.approx(vehicle.hover_speed, rel=0.01)
    # hover_duty: the hover's relative thrust (speed over full speed, squared), not the signal
    duty = result.parameters["hover_duty"]
    assert duty["value"] == pytest.approx((vehicle.hover_speed / vehicle.w_max) ** 2, rel=0.02)
    assert duty["ci95"][0] <= (vehicle.hover_speed / vehicle.w_max) ** 2 <= duty["ci95"][1], duty
    assert abs(duty["value"] - vehicle.hover_speed / vehicle.w_max) > 0.1
    for channel in ("p_dot", "q_dot", "r_dot"):
        assert result.validation[channel]["r2"] > 0.9, (channel, result.validation[channel])
    identified = result.vehicle()
    assert isinstance(identified, type(vehicle))
    assert np.allclose(np.array(identified.rotors), np.array(vehicle.rotors), atol=1e-6)


@pytest.mark.slow
def test_the_log_holds_the_rotor_plant_as_px4_logs_it(flights, tmp_path):
    """Read back with pyulog alone: esc_status holds the flown rotor speeds in rpm, actuator_motors
    each rotor's relative thrust (the commanded speed over w_max, squared: THR_MDL_FAC 1),
    actuator_outputs that speed ratio as PWM (PX4's FunctionMotors with THR_MDL_FAC 1: x =
    sqrt(rel)), CA_ROTOR* the vehicle's own rotors (FRD, KM positive CCW)."""
    _, vehicle, flight = flights["crazyflie"]
    log = ULog(str(flight.to_ulog(tmp_path / "cf.ulg")))
    esc = log.get_dataset("esc_status").data
    speeds = flight.rotor_states[0][:, 13:]
    for i in range(4):
        rpm = esc[f"esc[{i}].esc_rpm"].astype(float)
        assert np.max(np.abs(rpm - speeds[:, i] * 60 / (2 * math.pi))) <= 0.5 + 1e-6
    control = np.column_stack([log.get_dataset("actuator_motors").data[f"control[{i}]"] for i in range(4)])
    assert np.all((control >= 0) & (control <= 1)) and np.sqrt(np.median(control)) * vehicle.w_max == pytest.approx(
        vehicle.hover_speed, rel=0.05
    )
    outputs = log.get_dataset("actuator_outputs").data
    rows = np.searchsorted(log.get_dataset("actuator_motors").data["timestamp"], outputs["timestamp"])
    for i in range(4):
        assert np.allclose(outputs[f"output[{i}]"], 1000 + 1000 * np.sqrt(control[rows, i]), atol=2e-3)
    params = log.initial_parameters
    for i, (x, y, z, s) in enumerate(vehicle.rotors):
        assert params[f"CA_ROTOR{i}_PZ"] == pytest.approx(-z)
        assert params[f"CA_ROTOR{i}_PX"] == pytest.approx(x) and params[f"CA_ROTOR{i}_PY"] == pytest.approx(-y)
        assert params[f"CA_ROTOR{i}_KM"] == pytest.approx(-s * vehicle.km / vehicle.kf, rel=1e-6)
    assert params["THR_MDL_FAC"] == 1.0


@pytest.mark.slow
def test_sampled_commands_leave_the_time_constants_unidentified(flights, tmp_path):
    """PX4's default profile samples the 1 kHz commands at 250 Hz: when each changed is not in the
    log, so the motors' lag is reported not identifiable (never a tight interval on a guess)."""
    base, vehicle, flight = flights["iris"]
    path = flight.to_ulog(tmp_path / "default.ulg", profile="default")
    result = qc.identify(path, vehicle=base, mass=float(vehicle.m), commands="rad/s")
    for key in ("tau_up", "tau_down"):
        p = result.parameters[key]
        assert not p["identifiable"] and p["ci95"] == [None, None] and "sampled" in p["note"], p
    assert result.parameters["Jxx"]["identifiable"]


@pytest.mark.slow
def test_cli_identifies_and_the_vehicle_flies(flights, tmp_path):
    base, vehicle, flight = flights["iris"]
    path = flight.to_ulog(tmp_path / "iris.ulg")
    out = tmp_path / "ident"
    run = CliRunner().invoke
    res = run(
        main,
        ["identify", str(path), "--vehicle", "iris", "--commands", "rad/s", "--mass", "1.535", "--out", str(out)]
        + ["--report", str(tmp_path / "r.html")],
    )
    assert res.exit_code == 0, res.output
    assert (tmp_path / "r.html").stat().st_size > 0 and (out / "report.md").is_file()
    doc = json.loads((out / "identify.json").read_text())
    assert doc["parameters"]["Jxx"]["identifiable"] and doc["parameters"]["tau_down"]["identifiable"]
    toml = (out / "vehicle.toml").read_text()
    assert 'plant = "rotor"' in toml
    again = run(main, ["fly", "hover", "--vehicle", str(out / "vehicle.toml"), "--controller", "se3"])
    assert again.exit_code == 0, again.output


def test_rotor_speed_commands_need_a_rotor_plant(tmp_path):
    res = CliRunner().invoke(main, ["identify", str(tmp_path / "x.ulg"), "--commands", "rad/s", "--out", "o"])
    assert res.exit_code == 2 and len(res.output.strip().splitlines()) == 1 and "rotor plant" in res.output


@pytest.mark.slow
def test_csv_with_rotor_speeds(flights, tmp_path):
    """The same flight as a CSV in quadcruise's frames: commanded speeds u1..u4 [rad/s] and
    measured speeds w1..w4, the accelerometer from the velocity's derivative (no noise here)."""
    from scipy.spatial.transform import Rotation

    from quadcruise.sim.px4 import rotor_speed_commands

    base, vehicle, flight = flights["iris"]
    rs, t = flight.rotor_states[0], flight.t
    rows = {"t": t}
    commanded = rotor_speed_commands(flight.commands[0], flight.meta["vehicle"])
    for i in range(4):
        rows[f"u{i + 1}"], rows[f"w{i + 1}"] = commanded[:, i], rs[:, 13 + i]
    for j, key in enumerate(("x", "y", "z", "vx", "vy", "vz", "qw", "qx", "qy", "qz", "p", "q", "r")):
        rows[key] = rs[:, j]
    accel = np.gradient(rs[:, 3:6], t, axis=0, edge_order=2)
    rows["ax"], rows["ay"], rows["az"] = Rotation.from_quat(rs[:, [7, 8, 9, 6]]).inv().apply(accel + [0, 0, 9.81]).T
    path = tmp_path / "iris.csv"
    import pandas as pd

    pd.DataFrame(rows).to_csv(path, index=False)
    result = qc.identify(path, vehicle=base, mass=float(vehicle.m), commands="rad/s")
    for key, tol in WITHIN.items():
        p = result.parameters[key]
        assert p["identifiable"] and abs(p["value"] / getattr(vehicle, key) - 1) < tol, (key, p)
    assert not result.parameters["w_max"]["identifiable"] and "rad/s" in result.parameters["w_max"]["note"]
