"""`quadcruise replay --vehicle`: rotor speeds replayed on a rotor-plant vehicle; good and bad input."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest
from click.testing import CliRunner

from quadcruise import Vehicle
from quadcruise.cli import main
from quadcruise.workflows.replay import read_commands, replay

FLIP = Path(__file__).resolve().parents[2] / "examples" / "crazyflie_flip.csv"
HEADER = "t,x,y,z,vx,vy,vz,qw,qx,qy,qz,p,q,r,w1,w2,w3,w4,phi,theta,psi"


def run(*args):
    return CliRunner().invoke(main, list(args))


def test_the_flip_example_replays_through_inverted_and_writes_states(tmp_path):
    out = tmp_path / "states.csv"
    result = run("replay", str(FLIP), "--vehicle", "crazyflie", "-o", str(out))
    assert result.exit_code == 0, result.output
    assert out.read_text().splitlines()[0] == HEADER
    data = np.loadtxt(out, delimiter=",", skiprows=1)
    vehicle = Vehicle.preset("crazyflie")
    res = replay(read_commands(FLIP, vehicle), vehicle)
    np.testing.assert_allclose(data[:, 1:18], res.states[0], rtol=1e-14, atol=1e-14)  # written to 15 digits
    # the first row is the start: at rest, level, at the origin, rotors at the first command
    np.testing.assert_array_equal(data[0, 1:14], [0, 0, 0, 0, 0, 0, 1, 0, 0, 0, 0, 0, 0])
    np.testing.assert_array_equal(data[0, 14:18], [1788.55] * 4)
    # the Euler angles beside the quaternion: phi = atan2(2 (qw qx + qy qz), 1 - 2 (qx^2 + qy^2))
    qw, qx, qy, qz = data[:, 7:11].T
    np.testing.assert_allclose(data[:, 18], np.arctan2(2 * (qw * qx + qy * qz), 1 - 2 * (qx**2 + qy**2)), atol=1e-12)
    assert (1 - 2 * (qx**2 + qy**2)).min() < -0.8  # upside down at t = 0.47 s
    assert list(tmp_path.iterdir()) == [out]


def test_paper_vehicle_by_name_is_the_default_replay(tmp_path):
    pwm = Path(__file__).resolve().parents[2] / "examples" / "pwm_step.csv"
    a, b = tmp_path / "a.csv", tmp_path / "b.csv"
    assert run("replay", str(pwm), "-o", str(a)).exit_code == 0
    assert run("replay", str(pwm), "--vehicle", "paper", "-o", str(b)).exit_code == 0
    assert a.read_bytes() == b.read_bytes()


def test_a_vehicle_file_with_a_preset_and_overrides(tmp_path):
    mine = tmp_path / "heavy.toml"
    mine.write_text('[vehicle]\npreset = "crazyflie"\nm = 0.04\n')
    out = tmp_path / "s.csv"
    result = run("replay", str(FLIP), "--vehicle", str(mine), "-o", str(out))
    assert result.exit_code == 0, result.output
    heavy = np.loadtxt(out, delimiter=",", skiprows=1)
    # 10 g heavier at the same speeds: it sinks at (4 kf w^2 - m g) / m, less a little induced-inflow drag
    v = Vehicle.preset("crazyflie")
    sink = (4 * v.kf * 1788.55**2 - 0.04 * v.g) / 0.04 * 0.2**2 / 2
    assert heavy[1, 3] == pytest.approx(sink, rel=0.02) and heavy[1, 3] > sink


BAD = {
    "speed_above_max": (
        "t,w1,w2,w3,w4\n0,1800,1800,1800,1800\n1,1800,2600,1800,1800\n",
        "line 3, column 'w2': rotor speed 2600 rad/s is outside the vehicle's [0, 2500]",
    ),
    "speed_negative": (
        "t,w1,w2,w3,w4\n0,1800,1800,1800,-5\n1,1800,1800,1800,1800\n",
        "line 2, column 'w4': rotor speed -5 rad/s is outside",
    ),
    "nan": ("t,w1,w2,w3,w4\n0,1800,1800,1800,1800\n1,1800,nan,1800,1800\n", "line 3, column 'w2': value is NaN"),
    "missing_rotor": ("t,w1,w2,w3\n0,1800,1800,1800\n1,1800,1800,1800\n", "column(s) 'w4': missing"),
    "a_fifth_rotor": ("t,w1,w2,w3,w4,w5\n0,1,1,1,1,1\n1,1,1,1,1,1\n", "column 'w5', but the vehicle has 4 rotors"),
    "time_back": (
        "t,w1,w2,w3,w4\n0,1800,1800,1800,1800\n0,1800,1800,1800,1800\n",
        "line 3, column 't': time 0 is not after the previous row's 0",
    ),
    "duty_above_one": (
        "t,u1,u2,u3,u4\n0,0.1,0.1,0.1,0.1\n1,0.1,0.1,1.5,0.1\n",
        "line 3, column 'u3': duty 1.5 is outside [0, 1]",
    ),
    "duties_missing_rotor": ("t,u1,u2,u3\n0,0.1,0.1,0.1\n1,0.1,0.1,0.1\n", "column(s) 'u4': missing"),
    "a_fifth_duty": ("t,u1,u2,u3,u4,u5\n0,1,1,1,1,1\n1,1,1,1,1,1\n", "column 'u5', but the vehicle has 4 rotors"),
}


@pytest.mark.parametrize("case", sorted(BAD))
def test_bad_input_is_one_line_exit_two_no_output(tmp_path, case):
    text, words = BAD[case]
    src = tmp_path / "cmds.csv"
    src.write_text(text)
    out = tmp_path / "states.csv"
    result = run("replay", str(src), "--vehicle", "crazyflie", "-o", str(out))
    assert result.exit_code == 2, result.output
    lines = result.output.strip().splitlines()
    assert len(lines) == 1 and lines[0].startswith("error: "), result.output
    assert words in lines[0] and str(src) in lines[0], lines[0]
    assert sorted(p.name for p in tmp_path.iterdir()) == ["cmds.csv"]


@pytest.mark.parametrize(
    ("vehicle", "words"),
    [
        ("crazyfly", "unknown vehicle preset 'crazyfly' (did you mean 'crazyflie'?)"),
        ("absent.toml", "absent.toml: no such file"),
    ],
)
def test_bad_vehicle_is_one_line_exit_two(tmp_path, vehicle, words):
    out = tmp_path / "states.csv"
    result = run("replay", str(FLIP), "--vehicle", vehicle, "-o", str(out))
    assert result.exit_code == 2
    assert result.output.strip() == f"error: {words}" or words in result.output.strip()
    assert len(result.output.strip().splitlines()) == 1
    assert not out.exists()


def test_a_vehicle_that_cannot_lift_itself_is_refused_before_any_work(tmp_path):
    mine = tmp_path / "lead.toml"
    mine.write_text('[vehicle]\npreset = "crazyflie"\nm = 1.0\n')
    out = tmp_path / "states.csv"
    result = run("replay", str(FLIP), "--vehicle", str(mine), "-o", str(out))
    assert result.exit_code == 2
    assert result.output.strip().startswith(f"error: {mine}: [vehicle] vehicle cannot lift itself")
    assert not out.exists()


def test_a_crash_on_the_ground_writes_the_states_says_so_and_exits_one(tmp_path):
    src = tmp_path / "drop.csv"
    src.write_text("t,w1,w2,w3,w4\n0,2300,2300,2300,2300\n0.5,0,0,0,0\n3,0,0,0,0\n")
    out = tmp_path / "states.csv"
    result = run("replay", str(src), "--vehicle", "crazyflie", "--ground", "-o", str(out))
    assert result.exit_code == 1, result.output
    assert "the flight stopped early: crashed: hit the ground faster" in result.output
    data = np.loadtxt(out, delimiter=",", skiprows=1)
    assert np.isfinite(data[1]).all() and np.isnan(data[2, 1:]).all()  # states until the crash, then NaN
    free = run("replay", str(src), "--vehicle", "crazyflie", "-o", str(tmp_path / "free.csv"))
    assert free.exit_code == 0  # no ground: it falls on


def test_ground_needs_a_rotor_vehicle(tmp_path):
    pwm = Path(__file__).resolve().parents[2] / "examples" / "pwm_step.csv"
    result = run("replay", str(pwm), "--ground", "-o", str(tmp_path / "s.csv"))
    assert result.exit_code == 2 and "'--ground'" in result.output and "paper's plant has no ground" in result.output
    assert len(result.output.strip().splitlines()) == 1


def test_vehicles_lists_every_preset_with_its_source_and_file():
    from quadcruise.model.vehicle_files import PRESETS, preset_source

    result = run("vehicles")
    assert result.exit_code == 0, result.output
    for name, path in PRESETS.items():
        assert preset_source(name) in result.output and f"file: {path}" in result.output
        assert path.is_file()
    assert "iris         rotor    1.535 kg  4 rotors" in result.output


def test_a_batched_vehicle_file_is_refused_not_cut_to_its_first(tmp_path):
    pwm = Path(__file__).resolve().parents[2] / "examples" / "pwm_step.csv"
    mine = tmp_path / "two.toml"
    mine.write_text('[vehicle]\npreset = "paper"\nm = [1.0, 2.0]\n')
    out = tmp_path / "s.csv"
    result = run("replay", str(pwm), "--vehicle", str(mine), "-o", str(out))
    assert result.exit_code == 2 and "replay flies one vehicle" in result.output and not out.exists()


def test_duties_replay_as_the_speeds_of_the_command_to_speed_map(tmp_path):
    """t,u1..u4 on a rotor vehicle: each rotor at u w_max (PX4's THR_MDL_FAC = 1), the same states as
    the speeds given directly; a duty outside [0, 1] is one line naming the line and column."""
    import pandas as pd

    iris = Vehicle.preset("iris")
    t = np.array([0.0, 0.5, 1.0, 1.5])
    u = np.array([[0.6] * 4, [0.62, 0.62, 0.6, 0.6], [0.6] * 4, [0.6] * 4])  # rotors 1, 2 spin one way
    duties, speeds = tmp_path / "u.csv", tmp_path / "w.csv"
    pd.DataFrame(np.c_[t, u], columns=["t", "u1", "u2", "u3", "u4"]).to_csv(duties, index=False)
    pd.DataFrame(np.c_[t, u * iris.w_max], columns=["t", "w1", "w2", "w3", "w4"]).to_csv(speeds, index=False)
    for src, out in ((duties, tmp_path / "su.csv"), (speeds, tmp_path / "sw.csv")):
        res = run("replay", str(src), "--vehicle", "iris", "-o", str(out))
        assert res.exit_code == 0, res.output
    a, b = pd.read_csv(tmp_path / "su.csv"), pd.read_csv(tmp_path / "sw.csv")
    assert a.shape == b.shape and np.array_equal(a.to_numpy(), b.to_numpy())
    assert a["w1"].iloc[0] == pytest.approx(0.6 * iris.w_max)
    assert not np.allclose(a["r"].iloc[-1], 0.0)  # the yaw doublet turned it: the duties were read
    bad = tmp_path / "bad.csv"
    bad.write_text("t,u1,u2,u3,u4\n0,0.6,0.6,0.6,0.6\n1,0.6,1.2,0.6,0.6\n")
    res = run("replay", str(bad), "--vehicle", "iris", "-o", str(tmp_path / "x.csv"))
    assert res.exit_code == 2 and "line 3, column 'u2': duty 1.2 is outside [0, 1]" in res.output
    assert not (tmp_path / "x.csv").exists()
