"""Flight logs read into quadcruise's frames: a PX4 SITL log nobody here wrote, flights written as
PX4 logs and as CSV (frames checked against the flight's own states, by textbook formulas), and
every bad file refused with one line that names it.

The real logs of ``../shared/px4-logs`` are used where they are present (the SITL one is also
copied into tests/data/px4, with its BSD licence), and skipped cleanly where they are not.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pandas as pd
import pytest
from pyulog import ULog

import quadcruise as qc
from quadcruise.errors import InputError
from quadcruise.io.flightlog import read_flight_log
from quadcruise.layout import PHI, PSI, THETA, VX, P

DATA = Path(__file__).resolve().parents[1] / "data" / "px4"
SITL = DATA / "sample_px4_events.ulg"
SHARED = Path(__file__).resolve().parents[3] / "shared" / "px4-logs"
SHARED_ALT = Path("/work/shared/px4-logs")


def shared(name: str) -> Path:
    for folder in (SHARED, SHARED_ALT):
        if (folder / name).is_file():
            return folder / name
    pytest.skip(f"the real PX4 log {name} is not on this machine")


def euler_to_quat(phi, theta, psi):
    """(w, x, y, z) of Rz(psi) Ry(theta) Rx(phi), the half-angle formulas written out."""
    cr, sr, cp, sp, cy, sy = (
        np.cos(phi / 2),
        np.sin(phi / 2),
        np.cos(theta / 2),
        np.sin(theta / 2),
        np.cos(psi / 2),
        np.sin(psi / 2),
    )
    return np.column_stack(
        [
            cr * cp * cy + sr * sp * sy,
            sr * cp * cy - cr * sp * sy,
            cr * sp * cy + sr * cp * sy,
            cr * cp * sy - sr * sp * cy,
        ]
    )


@pytest.fixture(scope="module")
def flight():
    return qc.fly("step", "se3", duration=4.0, log_every=4)


@pytest.fixture(scope="module")
def flight_ulog(flight, tmp_path_factory):
    return flight.to_ulog(tmp_path_factory.mktemp("ulog") / "step.ulg")


def test_sitl_log_reads_its_airborne_stretch():
    log = read_flight_log(SITL)
    raw = ULog(str(SITL), message_name_filter_list=["vehicle_local_position"]).data_list[0].data
    assert log.n_rotors == 4 and log.commands.startswith("actuator_motors")
    assert 4.0 < log.duration < 9.0  # lifts off at ~19 s, touches down at ~26 s
    step = np.diff(log.t)
    assert np.allclose(step, 1 / 250, rtol=1e-6)  # the grid: sensor_combined's 250 Hz
    # the airborne samples are up: PX4's distance to the ground (raw, pyulog) above 0.3 m, the climb ~2 m
    t_raw = (raw["timestamp"] - ULog(str(SITL), message_name_filter_list=["vehicle_status"]).start_timestamp) * 1e-6
    assert np.interp(log.t, t_raw, raw["dist_bottom"]).min() >= 0.3
    up = -np.interp(log.t, t_raw, raw["z"]) + raw["z"][0]
    assert up.max() > 1.8
    assert np.allclose(log.position[:, 2] - log.position[0, 2], up - up[0], atol=1e-5)  # ENU z = -NED z
    # the accelerometer in FLU: +g along body z in hover
    assert 9.0 < np.median(log.specific_force[:, 2]) < 10.6
    assert np.allclose(np.linalg.norm(log.quaternion, axis=1), 1.0)
    # the x layout of CA_ROTOR*: rotor 0 front right (FLU: x > 0, y < 0), CCW rotors yaw sign -1
    assert log.rotors[0, 0] > 0 and log.rotors[0, 1] < 0 and log.rotors[0, 2] == -1.0
    assert log.hover_thrust is not None and 0.45 < np.median(log.hover_thrust[1]) < 0.52


def test_ulog_of_a_flight_comes_back_in_quadcruise_frames(flight, flight_ulog):
    log = read_flight_log(flight_ulog)
    states = flight.states[0]
    pick = np.searchsorted(flight.t, log.t - 1e-9)
    assert np.allclose(flight.t[pick], log.t, atol=1e-6)
    truth = states[pick]
    at_50hz = np.isclose(log.t * 50, np.round(log.t * 50))  # vehicle_local_position's own samples
    assert at_50hz.sum() >= 190
    assert np.allclose(log.velocity[at_50hz], truth[at_50hz, VX : VX + 3], atol=1e-5)
    assert np.allclose(log.velocity, truth[:, VX : VX + 3], atol=2e-3)  # linear in between
    assert np.allclose(log.rates, truth[:, P : P + 3], atol=1e-5)
    q = euler_to_quat(truth[:, PHI], truth[:, THETA], truth[:, PSI])
    assert np.allclose(np.abs(np.einsum("ij,ij->i", log.quaternion, q)), 1.0, atol=1e-6)
    assert np.allclose(log.u, np.clip(flight.commands[0][pick, 0:4], 0, 1), atol=1e-6)
    # the "+" rotors of eqs (1)-(4): 1 at -x, 2 at +y, 3 at +x, 4 at -y; 1 and 3 with positive yaw moment
    assert np.allclose(log.rotors, [[-0.2, 0, 1], [0, 0.2, -1], [0.2, 0, 1], [0, -0.2, -1]], atol=1e-6)


def csv_of(flight, frame="enu", landed=None):
    states = flight.states[0]
    q = euler_to_quat(states[:, PHI], states[:, THETA], states[:, PSI])
    v, w = states[:, VX : VX + 3], states[:, P : P + 3]
    if frame == "ned":
        v = v[:, [1, 0, 2]] * [1, 1, -1]
        w = w * [1, -1, -1]
        # R_ned_frd = A R B: quaternion product q_A * q * q_B, with q_A = (0, s, s, 0), q_B = (0, 1, 0, 0)
        s = np.sqrt(0.5)
        a = np.array([0.0, s, s, 0.0])

        def mul(x, y):
            w1, x1, y1, z1 = x.T
            w2, x2, y2, z2 = y.T
            return np.column_stack(
                [
                    w1 * w2 - x1 * x2 - y1 * y2 - z1 * z2,
                    w1 * x2 + x1 * w2 + y1 * z2 - z1 * y2,
                    w1 * y2 - x1 * z2 + y1 * w2 + z1 * x2,
                    w1 * z2 + x1 * y2 - y1 * x2 + z1 * w2,
                ]
            )

        q = mul(mul(np.tile(a, (len(q), 1)), q), np.tile([0.0, 1.0, 0.0, 0.0], (len(q), 1)))
    table = pd.DataFrame(
        {
            "t": flight.t,
            "vx": v[:, 0],
            "vy": v[:, 1],
            "vz": v[:, 2],
            "qw": q[:, 0],
            "qx": q[:, 1],
            "qy": q[:, 2],
            "qz": q[:, 3],
            "p": w[:, 0],
            "q": w[:, 1],
            "r": w[:, 2],
        }
    )
    for i in range(4):
        table[f"u{i + 1}"] = np.clip(flight.commands[0][:, i], 0, 1)
    if landed is not None:
        table["landed"] = landed
    return table


@pytest.mark.parametrize("frame", ["enu", "ned"])
def test_csv_in_either_frame_reads_the_same(flight, tmp_path, frame):
    path = tmp_path / "f.csv"
    csv_of(flight, frame).to_csv(path, index=False)
    log = read_flight_log(path, frame=frame)
    states = flight.states[0]
    assert np.allclose(log.velocity, states[:, VX : VX + 3], atol=1e-9)
    assert np.allclose(log.rates, states[:, P : P + 3], atol=1e-9)
    q = euler_to_quat(states[:, PHI], states[:, THETA], states[:, PSI])
    assert np.allclose(np.abs(np.einsum("ij,ij->i", log.quaternion, q)), 1.0, atol=1e-9)


def test_csv_landed_rows_are_left_out(flight, tmp_path):
    landed = (flight.t < 1.0).astype(int)
    path = tmp_path / "f.csv"
    csv_of(flight, landed=landed).to_csv(path, index=False)
    log = read_flight_log(path)
    assert log.t[0] >= 1.0 and log.t[-1] == pytest.approx(flight.t[-1])


# --- bad input: one line, naming the file and what is wrong ----------------------------------


def refused(path, match, **kw):
    with pytest.raises(InputError, match=match) as info:
        read_flight_log(path, **kw)
    message = str(info.value)
    assert "\n" not in message and str(path) in message
    return message


def test_real_log_never_armed():
    refused(shared("sample.ulg"), "never armed")


def test_real_vtol_log():
    refused(shared("sample_log_small.ulg"), "not a multicopter.*VTOL")


def test_not_a_ulog(tmp_path):
    path = tmp_path / "x.ulg"
    path.write_text("t,u1\n0,1\n")
    refused(path, "not a PX4 log")


def test_truncated_ulog(tmp_path):
    path = tmp_path / "cut.ulg"
    path.write_bytes(SITL.read_bytes()[:800_001])
    refused(path, "truncated PX4 log")


def test_ulog_without_needed_topics(flight, tmp_path):
    from quadcruise.io.ulog import write_ulog
    from quadcruise.sim.px4 import px4_topics

    states = flight.states[0]
    topics = px4_topics(flight.t, states, np.clip(flight.commands[0][:, :4], 0, 1), g=9.81)
    path = tmp_path / "partial.ulg"
    dropped = ("vehicle_attitude", "actuator_motors", "actuator_outputs")
    write_ulog(path, [tp for tp in topics if tp.name not in dropped])
    refused(path, "missing topic.*vehicle_attitude.*actuator_motors")


def test_ulog_armed_but_never_airborne(flight, tmp_path):
    from quadcruise.io.ulog import Topic, write_ulog
    from quadcruise.sim.px4 import px4_topics

    topics = px4_topics(flight.t, flight.states[0], np.clip(flight.commands[0][:, :4], 0, 1), g=9.81)
    grounded = []
    for tp in topics:
        if tp.name == "vehicle_land_detected":
            tp = Topic(tp.name, tp.fields, {**tp.values, "landed": np.ones(len(tp.values["timestamp"]), bool)})
        grounded.append(tp)
    path = tmp_path / "grounded.ulg"
    write_ulog(path, grounded, parameters={"MAV_TYPE": 2})
    refused(path, "armed but never airborne")


def test_ulog_of_a_fixed_wing(flight, tmp_path):
    from quadcruise.io.ulog import write_ulog
    from quadcruise.sim.px4 import px4_topics

    topics = px4_topics(flight.t, flight.states[0], np.clip(flight.commands[0][:, :4], 0, 1), g=9.81)
    path = tmp_path / "plane.ulg"
    write_ulog(path, topics, parameters={"MAV_TYPE": 1})
    refused(path, "not a multicopter.*MAV_TYPE 1")


@pytest.mark.parametrize(
    "change,match",
    [
        (lambda t: t.drop(columns=["qz"]), "missing column.*qz"),
        (lambda t: t.drop(columns=["u1", "u2", "u3", "u4"]), "missing column.*u1..un"),
        (lambda t: t.assign(t=t["t"].to_numpy()[::-1]), "row 3: time .* does not increase"),
        (lambda t: t.assign(landed=1), "nothing to identify"),
        (lambda t: t.assign(vx=["a"] + [0.0] * (len(t) - 1)), "row 2, column vx"),
    ],
)
def test_bad_csv(flight, tmp_path, change, match):
    path = tmp_path / "bad.csv"
    change(csv_of(flight)).to_csv(path, index=False)
    refused(path, match)


def test_bad_options(flight_ulog, tmp_path):
    refused(flight_ulog, "frame 'enu' is for CSV", frame="enu")
    with pytest.raises(InputError, match="commands must be"):
        read_flight_log(flight_ulog, commands="rpm")
    refused(tmp_path / "none.csv", "no such file")
