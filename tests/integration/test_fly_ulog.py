"""``quadcruise fly ... --ulog OUT.ulg``: the flight as a PX4 log, read back by pyulog alone.

Checked against the flight's own traces (``--out``), converted here to PX4's frames by the
textbook formulas (NED = (y, x, -z), FRD rates (p, -q, -r), heading pi/2 - psi, microsecond
timestamps); the hover command against m g / (4 K); the replay of the recorded
``scenario.toml`` must give the same bytes; a batch is one file per vehicle; a wrong name is
refused before flying and a write that fails leaves no file.
"""

from __future__ import annotations

import errno
import math
import os
import subprocess
import sys
from pathlib import Path

import numpy as np
import pandas as pd
import pytest
from click.testing import CliRunner
from pyulog import ULog

import quadcruise
from quadcruise.cli.main import main

SRC = str(Path(quadcruise.__file__).resolve().parents[1])  # this tree's code, in the subprocess


def run(*args):
    return CliRunner().invoke(main, [str(a) for a in args])


def data(path: Path) -> tuple[ULog, dict]:
    log = ULog(str(path))
    assert not log.file_corruption
    return log, {d.name: d.data for d in log.data_list}


@pytest.fixture(scope="module")
def step_flight(tmp_path_factory):
    """A yawed step flown with noise-free sensors, with its traces and its PX4 log."""
    folder = tmp_path_factory.mktemp("fly-ulog")
    result = run(
        "fly", "step", "--duration", "3", "-m", "yaw=0.7", "--seed", "3",
        "--ulog", folder / "step.ulg", "--out", folder / "out",
    )  # fmt: skip
    assert result.exit_code == 0, result.output
    assert f"wrote PX4 log {folder / 'step.ulg'}" in result.output
    return folder, pd.read_csv(folder / "out" / "traces.csv")


def test_the_log_reads_back_in_px4_conventions(step_flight):
    folder, traces = step_flight
    log, topics = data(folder / "step.ulg")
    t_us = np.round(traces["t"].to_numpy() * 1e6).astype(np.uint64)

    pos = topics["vehicle_local_position"]
    rows = np.searchsorted(t_us, pos["timestamp"])
    assert np.array_equal(t_us[rows], pos["timestamp"])  # microseconds of the flight's own instants
    assert np.median(np.diff(pos["timestamp"])) == pytest.approx(20_000)  # 50 Hz
    for ned, enu, sign in (("x", "y", 1), ("y", "x", 1), ("z", "z", -1)):
        assert np.allclose(pos[ned], sign * traces[enu].to_numpy()[rows], atol=1e-5), ned
    heading = math.pi / 2 - traces["psi"].to_numpy()[rows]
    assert np.allclose(np.angle(np.exp(1j * (pos["heading"] - heading))), 0.0, atol=1e-5)

    rates = topics["vehicle_angular_velocity"]
    rows = np.searchsorted(t_us, rates["timestamp"])
    assert np.median(np.diff(rates["timestamp"])) == pytest.approx(4_000)  # 250 Hz: the default profile
    for i, (name, sign) in enumerate((("p", 1), ("q", -1), ("r", -1))):
        assert np.allclose(rates[f"xyz[{i}]"], sign * traces[name].to_numpy()[rows], atol=1e-6), name

    motors = topics["actuator_motors"]
    rows = np.searchsorted(t_us, motors["timestamp"])
    for i in range(4):
        assert np.allclose(motors[f"control[{i}]"], traces[f"u{i + 1}"].to_numpy()[rows], atol=1e-7)

    q = np.column_stack([topics["vehicle_attitude"][f"q[{i}]"] for i in range(4)])
    assert np.allclose(np.linalg.norm(q, axis=1), 1.0, atol=1e-6)  # w first: unit quaternions
    assert q[0, 0] == pytest.approx(math.cos((math.pi / 2 - 0.7) / 2), abs=1e-6)  # level, heading 90 - 40 deg
    assert log.initial_parameters["SDLOG_PROFILE"] == 1
    assert log.initial_parameters["CA_ROTOR_COUNT"] == 4


def test_the_recorded_scenario_writes_the_same_bytes_again(step_flight, tmp_path):
    folder, _ = step_flight
    scenario = folder / "out" / "scenario.toml"
    assert f"--ulog {folder / 'step.ulg'}` writes the same bytes again" in scenario.read_text()
    result = run("fly", scenario, "--ulog", tmp_path / "again.ulg")
    assert result.exit_code == 0, result.output
    assert (tmp_path / "again.ulg").read_bytes() == (folder / "step.ulg").read_bytes()


def test_a_batch_is_one_log_per_vehicle(tmp_path):
    """Two vehicles of 1.0 and 1.5 kg hover: c-0.ulg and c-1.ulg, each at its own hover
    command m g / (4 K) (Table I's K = 120 N)."""
    (tmp_path / "batch.toml").write_text(
        '[mission]\nkind = "hover"\n[simulation]\nduration = 1.0\n[vehicle]\nm = [1.0, 1.5]\n'
    )
    result = run("fly", tmp_path / "batch.toml", "--ulog", tmp_path / "c.ulg")
    assert result.exit_code == 0, result.output
    assert sorted(p.name for p in tmp_path.glob("*.ulg")) == ["c-0.ulg", "c-1.ulg"]
    for i, mass in enumerate((1.0, 1.5)):
        _, topics = data(tmp_path / f"c-{i}.ulg")
        assert np.allclose(topics["actuator_motors"]["control[0]"], mass * 9.81 / (4 * 120.0), rtol=1e-6)


def test_a_sysid_flight_is_logged_at_the_rate_of_its_commands(tmp_path):
    """The sysid mission is written with PX4's system-identification profile: every command
    of a 1 kHz controller is in the log (the default profile would keep one in four)."""
    result = run("fly", "sysid", "--duration", "1", "--ulog", tmp_path / "s.ulg")
    assert result.exit_code == 0, result.output
    log, topics = data(tmp_path / "s.ulg")
    assert log.initial_parameters["SDLOG_PROFILE"] == 9  # default | system identification
    for name in ("actuator_motors", "vehicle_angular_velocity", "sensor_combined", "vehicle_attitude"):
        assert np.all(np.diff(topics[name]["timestamp"]) == 1_000), name
    assert np.median(np.diff(topics["vehicle_local_position"]["timestamp"])) == 20_000


@pytest.mark.parametrize("name", ["flight.csv", "flight"])
def test_a_wrong_name_is_refused_before_flying(tmp_path, name):
    env = {**os.environ, "PYTHONPATH": SRC, "QUADCRUISE_PROGRESS": "0"}
    proc = subprocess.run(
        [sys.executable, "-m", "quadcruise", "fly", "circle", "--ulog", str(tmp_path / name)],
        capture_output=True, text=True, env=env, cwd=tmp_path, timeout=300, check=False,
    )  # fmt: skip
    assert proc.returncode == 2
    assert proc.stdout == ""
    assert proc.stderr.splitlines() == [
        f"error: Invalid value for '--ulog': {tmp_path / name}: the file is written as .ulg; name it so"
    ]
    assert list(tmp_path.iterdir()) == []


def test_a_write_that_fails_is_one_line_exit_74_and_leaves_no_log(tmp_path, monkeypatch):
    """The second vehicle's log cannot be written: one line naming it, exit 74, and the first
    vehicle's log is removed too (all or none)."""
    (tmp_path / "batch.toml").write_text(
        '[mission]\nkind = "hover"\n[simulation]\nduration = 0.5\n[vehicle]\nm = [1.0, 1.5]\n'
    )
    write_bytes, calls = Path.write_bytes, []

    def second_fails(self, content):
        calls.append(self)
        if len(calls) == 2:
            write_bytes(self, content[:100])
            raise OSError(errno.ENOSPC, "No space left on device")
        return write_bytes(self, content)

    monkeypatch.setattr(Path, "write_bytes", second_fails)
    result = run("fly", tmp_path / "batch.toml", "--ulog", tmp_path / "c.ulg")
    assert result.exit_code == 74, result.output
    enospc = "cannot write (no space left on device)"
    assert result.stderr.strip().splitlines() == [f"error: {tmp_path / 'c-1.ulg'}: {enospc}"]
    assert sorted(p.name for p in tmp_path.iterdir()) == ["batch.toml"]


def test_compare_writes_one_log_per_controller(tmp_path):
    """``compare --ulog``: each controller's log, the same bytes as ``fly`` writes for that
    controller on the same mission, and the two controllers' logs differ."""
    result = run("compare", "step", "--controllers", "nlpd,se3", "--duration", "2", "--ulog", tmp_path / "c.ulg")
    assert result.exit_code == 0, result.output
    assert sorted(p.name for p in tmp_path.glob("*.ulg")) == ["c-nlpd.ulg", "c-se3.ulg"]
    flown = run("fly", "step", "--controller", "se3", "--duration", "2", "--ulog", tmp_path / "fly-se3.ulg")
    assert flown.exit_code == 0, flown.output
    assert (tmp_path / "c-se3.ulg").read_bytes() == (tmp_path / "fly-se3.ulg").read_bytes()
    assert (tmp_path / "c-nlpd.ulg").read_bytes() != (tmp_path / "c-se3.ulg").read_bytes()


def test_compare_records_its_logs_and_its_scenario_writes_them_again(tmp_path):
    """``compare --ulog --out``: scenario.toml names the logs; compare of it writes the same bytes."""
    args = ("compare", "step", "--controllers", "nlpd,se3", "--duration", "1")
    result = run(*args, "--ulog", tmp_path / "c.ulg", "--out", tmp_path / "out")
    assert result.exit_code == 0, result.output
    scenario = (tmp_path / "out" / "scenario.toml").read_text()
    assert f"--ulog {tmp_path / 'c.ulg'}` writes the same bytes again" in scenario
    assert str(tmp_path / "c-se3.ulg") in scenario
    again = run("compare", tmp_path / "out" / "scenario.toml", "--ulog", tmp_path / "again.ulg")
    assert again.exit_code == 0, again.output
    for label in ("nlpd", "se3"):
        assert (tmp_path / f"again-{label}.ulg").read_bytes() == (tmp_path / f"c-{label}.ulg").read_bytes()
    plain = run(*args, "--out", tmp_path / "plain")  # without --ulog, no word of a log
    assert plain.exit_code == 0 and "ulog" not in (tmp_path / "plain" / "scenario.toml").read_text()


SETPOINT_FIELDS = {
    "trajectory_setpoint": ["position[0]", "velocity[2]", "acceleration[1]", "jerk[2]", "yaw", "yawspeed"],
    "vehicle_local_position_setpoint": ["x", "y", "z", "vx", "vy", "vz", "acceleration[2]", "thrust[2]", "yaw"],
    "vehicle_attitude_setpoint": ["roll_body", "pitch_body", "yaw_body", "q_d[3]", "thrust_body[2]"],
    "vehicle_rates_setpoint": ["roll", "pitch", "yaw", "thrust_body[2]", "reset_integral"],
    "vehicle_thrust_setpoint": ["timestamp_sample", "xyz[0]", "xyz[2]"],
    "vehicle_torque_setpoint": ["timestamp_sample", "xyz[0]", "xyz[1]", "xyz[2]"],
    "actuator_outputs": ["noutputs", "output[0]", "output[15]"],
}


def test_the_setpoints_read_back_with_px4s_fields_and_meanings(step_flight):
    """The setpoints PX4's viewers overlay, read by pyulog, against the flight's own traces by
    hand-derived formulas for the paper's "+" quadrotor (rotors at -x, +y, +x, -y; thrust K u):
    PX4's allocator normalises the collective to -U1_d / (4 K) and, from pinv of the "+"
    effectiveness, the torques to (U2_d / (sqrt(2) K), -U3_d / (sqrt(2) K), -U4_d / (4 K d));
    the desired attitude in NED is (phi_d, -theta_d, pi/2 - psi_d); the reference in NED
    (y, x, -z), yaw pi/2 - psi_ref; the PWM output 1000 + 1000 u (THR_MDL_FAC 0)."""
    folder, traces = step_flight
    log, topics = data(folder / "step.ulg")
    vehicle = qc_vehicle(folder)
    K, d = vehicle["K"], vehicle["d"]
    t_us = np.round(traces["t"].to_numpy() * 1e6).astype(np.uint64)
    for name, fields in SETPOINT_FIELDS.items():
        assert name in topics, name
        assert all(f in topics[name] for f in fields), (name, sorted(topics[name]))
        rows = np.searchsorted(t_us, topics[name]["timestamp"])
        assert np.array_equal(t_us[rows], topics[name]["timestamp"]), name

    def at(name):
        return traces.iloc[np.searchsorted(t_us, topics[name]["timestamp"])]

    thrust, tr = topics["vehicle_thrust_setpoint"], at("vehicle_thrust_setpoint")
    assert np.allclose(thrust["xyz[2]"], -tr["U1_d"] / (4 * K), rtol=1e-5, atol=1e-7)
    assert np.all(thrust["xyz[0]"] == 0) and np.all(thrust["xyz[1]"] == 0)
    torque, tr = topics["vehicle_torque_setpoint"], at("vehicle_torque_setpoint")
    assert np.ptp(tr["U2_d"]) > 0 and np.ptp(tr["U4_d"]) > 0  # a yawed step moves them
    assert np.allclose(torque["xyz[0]"], tr["U2_d"] / (math.sqrt(2) * K), atol=1e-6)
    assert np.allclose(torque["xyz[1]"], -tr["U3_d"] / (math.sqrt(2) * K), atol=1e-6)
    assert np.allclose(torque["xyz[2]"], -tr["U4_d"] / (4 * K * d), atol=1e-6)

    att, tr = topics["vehicle_attitude_setpoint"], at("vehicle_attitude_setpoint")
    assert np.allclose(att["roll_body"], tr["phi_d"], atol=1e-6)
    assert np.allclose(att["pitch_body"], -tr["theta_d"], atol=1e-6)
    assert np.allclose(np.angle(np.exp(1j * (att["yaw_body"] - (math.pi / 2 - tr["psi_d"])))), 0.0, atol=1e-6)
    q_d = np.column_stack([att[f"q_d[{i}]"] for i in range(4)])
    assert np.allclose(np.linalg.norm(q_d, axis=1), 1.0, atol=1e-6)
    assert np.allclose(att["thrust_body[2]"], -tr["U1_d"] / (4 * K), rtol=1e-5, atol=1e-7)
    rates, tr = topics["vehicle_rates_setpoint"], at("vehicle_rates_setpoint")
    assert np.all(np.isnan(rates["roll"])) and np.allclose(rates["thrust_body[2]"], -tr["U1_d"] / (4 * K), rtol=1e-5)

    for name in ("trajectory_setpoint", "vehicle_local_position_setpoint"):
        sp, tr = topics[name], at(name)
        x = sp["position[0]"] if name == "trajectory_setpoint" else sp["x"]
        z = sp["position[2]"] if name == "trajectory_setpoint" else sp["z"]
        vz = sp["velocity[2]"] if name == "trajectory_setpoint" else sp["vz"]
        assert np.allclose(x, tr["y_ref"], atol=1e-6) and np.allclose(z, -tr["z_ref"], atol=1e-6), name
        assert np.allclose(vz, -tr["vz_ref"], atol=1e-6), name
        assert np.allclose(np.angle(np.exp(1j * (sp["yaw"] - (math.pi / 2 - tr["psi_ref"])))), 0.0, atol=1e-6)
    lps, tr = topics["vehicle_local_position_setpoint"], at("vehicle_local_position_setpoint")
    norm = np.linalg.norm(np.column_stack([lps[f"thrust[{i}]"] for i in range(3)]), axis=1)
    assert np.allclose(norm, tr["U1_d"] / (4 * K), rtol=1e-5) and np.all(lps["thrust[2]"] < 0)

    out, tr = topics["actuator_outputs"], at("actuator_outputs")
    for i in range(4):
        assert np.allclose(out[f"output[{i}]"], 1000 + 1000 * np.clip(tr[f"u{i + 1}"], 0, 1), atol=1e-3)
    assert np.all(out["output[4]"] == 900)  # no motor there: disarmed value
    params = log.initial_parameters
    assert params["THR_MDL_FAC"] == 0.0
    assert [params[f"PWM_MAIN_FUNC{i}"] for i in range(1, 5)] == [101, 102, 103, 104]
    assert (params["PWM_MAIN_MIN1"], params["PWM_MAIN_MAX4"]) == (1000, 2000)


def qc_vehicle(folder: Path) -> dict:
    import json

    return json.loads((folder / "out" / "quadcruise.json").read_text())["vehicle"]


def test_a_rotor_flight_logs_relative_thrust_and_its_signal(tmp_path):
    """``fly hover --vehicle iris --ulog``: actuator_motors is the relative thrust, m g / (4 kf w_max^2)
    at hover (the Iris preset's numbers), identical through ``read_flight_log``; actuator_outputs
    is PX4's signal of it through THR_MDL_FAC 1 (x = sqrt(rel)) as PWM; the thrust setpoint
    -m g / (4 CT) as well."""
    from quadcruise.io.flightlog import read_flight_log

    result = run(
        "fly", "hover", "--controller", "se3", "--vehicle", "iris", "--duration", "10", "--ulog", tmp_path / "h.ulg"
    )  # fmt: skip
    assert result.exit_code == 0, result.output
    log, topics = data(tmp_path / "h.ulg")
    m, kf, w_max, g = 1.535, 5.84e-06, 1100.0, 9.81  # the iris preset (PX4 SITL's iris.sdf)
    hover = m * g / (4 * kf * w_max**2)
    motors = topics["actuator_motors"]
    late = motors["timestamp"] > 5e6
    control = np.column_stack([motors[f"control[{i}]"][late] for i in range(4)])
    assert np.allclose(control, hover, rtol=1e-4), (control.mean(), hover)
    assert log.initial_parameters["THR_MDL_FAC"] == 1.0
    assert log.initial_parameters["CA_ROTOR0_CT"] == pytest.approx(kf * w_max**2, rel=1e-6)
    out = topics["actuator_outputs"]
    rows = np.searchsorted(motors["timestamp"], out["timestamp"])
    for i in range(4):  # FunctionMotors::updateValues with THR_MDL_FAC 1, then [min, max] PWM
        x = np.sqrt(motors[f"control[{i}]"][rows].astype(float))
        assert np.allclose(out[f"output[{i}]"], 1000 + 1000 * x, atol=2e-3)
    thrust = topics["vehicle_thrust_setpoint"]
    assert np.allclose(thrust["xyz[2]"][thrust["timestamp"] > 5e6], -hover, rtol=1e-4)
    flight = read_flight_log(tmp_path / "h.ulg")
    t_us = np.round(flight.t * 1e6).astype(np.uint64)
    same = np.isin(t_us, motors["timestamp"])
    rows = np.searchsorted(motors["timestamp"], t_us[same])
    assert np.array_equal(flight.u[same], np.column_stack([motors[f"control[{i}]"][rows] for i in range(4)]))
    assert flight.thrust_factor == 1.0 and "THR_MDL_FAC" not in flight.parameters
    # actuator_outputs read back through THR_MDL_FAC 1: the same relative thrust; rad/s: its signal
    pwm = read_flight_log(tmp_path / "h.ulg", commands="pwm:1000:2000")
    late = pwm.t > 5.0
    assert np.allclose(pwm.u[late], hover, rtol=1e-4)
    speeds = read_flight_log(tmp_path / "h.ulg", commands="rad/s")
    assert np.allclose(speeds.u[late] * w_max, math.sqrt(m * g / (4 * kf)), rtol=1e-4)  # the hover speed


def test_a_decimated_log_says_its_true_rate(tmp_path):
    """``--log-every 4`` on a 1 kHz sysid flight: the commands every 4 ms, the file says 250 Hz of
    1000 Hz in its info, and it does not claim the system-identification profile (every command)."""
    result = run("fly", "sysid", "--duration", "1", "--log-every", "4", "--ulog", tmp_path / "s.ulg")
    assert result.exit_code == 0, result.output
    log, topics = data(tmp_path / "s.ulg")
    assert np.all(np.diff(topics["actuator_motors"]["timestamp"]) == 4_000)
    assert log.msg_info_dict["quadcruise_log_rate_hz"] == pytest.approx(250.0)
    assert log.msg_info_dict["quadcruise_control_rate_hz"] == pytest.approx(1000.0)
    assert log.initial_parameters["SDLOG_PROFILE"] == 1
    full = run("fly", "sysid", "--duration", "1", "--ulog", tmp_path / "f.ulg")
    assert full.exit_code == 0, full.output
    log, _ = data(tmp_path / "f.ulg")
    assert log.msg_info_dict["quadcruise_log_rate_hz"] == pytest.approx(1000.0)
    assert log.initial_parameters["SDLOG_PROFILE"] == 9
