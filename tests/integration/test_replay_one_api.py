"""One replay for both plants (issue 31): ``qc.replay(commands, vehicle=...)`` reads a duty or a
speed table by its columns (a CSV path, a DataFrame or a CommandSchedule) and flies the plant
of the vehicle; one reader, one writer, one schedule type; the old names warn and still work."""

from __future__ import annotations

import warnings
from pathlib import Path

import numpy as np
import pandas as pd
import pytest
from click.testing import CliRunner

import quadcruise as qc
from quadcruise.cli import main
from quadcruise.sim.result import SimResult
from quadcruise.sim.rotor_result import RotorResult
from quadcruise.workflows.replay import read_rotor_csv

EXAMPLES = Path(__file__).resolve().parents[2] / "examples"
PWM, FLIP = EXAMPLES / "pwm_step.csv", EXAMPLES / "crazyflie_flip.csv"


def new(call):
    """``call()``, failing on any DeprecationWarning: the new names raise none."""
    with warnings.catch_warnings():
        warnings.simplefilter("error", DeprecationWarning)
        return call()


def test_the_plant_comes_from_the_vehicle_and_the_kind_from_the_columns():
    paper = new(lambda: qc.replay(PWM))
    rotor = new(lambda: qc.replay(FLIP, vehicle="crazyflie"))
    assert isinstance(paper, SimResult) and isinstance(rotor, RotorResult)
    assert rotor.names[-4:] == ("w1", "w2", "w3", "w4") and rotor.meta["plant"] == "rotor"
    # the same flight whatever the table came as: a path, a schedule, a DataFrame; a vehicle or its name
    for table in (str(PWM), new(lambda: qc.read_commands(PWM)), pd.read_csv(PWM)):
        np.testing.assert_array_equal(new(lambda t=table: qc.replay(t, vehicle="paper")).states, paper.states)
    cf = qc.Vehicle.preset("crazyflie")
    for table in (FLIP, new(lambda: qc.read_commands(FLIP, cf)), pd.read_csv(FLIP)):
        np.testing.assert_array_equal(new(lambda t=table: qc.replay(t, vehicle=cf)).states, rotor.states)
    # rotor speeds held at hover keep the vehicle where it is; below hover it sinks
    hover = qc.CommandSchedule(t=[0.0, 1.0], speeds=[[cf.hover_speed] * 4] * 2)
    assert abs(new(lambda: qc.replay(hover, vehicle=cf)).final_state[0, 2]) < 1e-9
    low = qc.CommandSchedule(t=[0.0, 1.0], speeds=[[0.9 * cf.hover_speed] * 4] * 2)
    assert qc.replay(low, vehicle=cf).final_state[0, 2] < -0.1


def test_duties_on_a_rotor_vehicle_are_speeds_u_w_max():
    iris = qc.Vehicle.preset("iris")
    t = [0.0, 0.5, 1.0]
    u = np.array([[0.6] * 4, [0.62, 0.62, 0.6, 0.6], [0.6] * 4])
    by_duty = qc.replay(pd.DataFrame(np.c_[t, u], columns=["t", "u1", "u2", "u3", "u4"]), vehicle=iris)
    by_speed = qc.replay(qc.CommandSchedule(t=t, speeds=u * iris.w_max), vehicle=iris)
    np.testing.assert_array_equal(by_duty.states, by_speed.states)
    with pytest.raises(qc.InputError, match=r"row 2, column 'u1': duty 0\.01 asks for rotor speed 11 rad/s is outside"):
        qc.replay(
            qc.CommandSchedule(t=[0, 1], duties=[[0.6] * 4, [0.01, 0.6, 0.6, 0.6]]), vehicle=iris.replace(w_min=50.0)
        )


def test_one_writer_for_both_plants(tmp_path):
    paper, rotor = qc.replay(PWM), qc.replay(FLIP, vehicle="crazyflie")
    new(lambda: qc.write_states_csv(paper, tmp_path / "p.csv"))
    new(lambda: qc.write_states_csv(rotor, tmp_path / "r.csv"))
    p, r = pd.read_csv(tmp_path / "p.csv"), pd.read_csv(tmp_path / "r.csv")
    assert list(p.columns) == ["t", "x", "y", "z", "vx", "vy", "vz", "phi", "theta", "psi", "p", "q", "r"] + [
        f"F{i}" for i in range(1, 5)
    ]
    np.testing.assert_allclose(p.to_numpy()[:, 1:], paper.states[0], rtol=1e-14, atol=1e-15)
    expect = rotor.to_pandas(0).drop(columns="vehicle")
    assert list(r.columns) == list(expect.columns) and list(r.columns)[-3:] == ["phi", "theta", "psi"]
    np.testing.assert_allclose(r.to_numpy(), expect.to_numpy(), rtol=1e-14, atol=1e-15)
    with pytest.raises(qc.InputError, match="vehicle 1 is not in this flight of 1 vehicles"):
        qc.write_states_csv(rotor, tmp_path / "x.csv", vehicle=1)
    assert not (tmp_path / "x.csv").exists()


NEITHER = "t,u1,u2,u3,u4 (PWM duties in [0, 1]) or t,w1,..,wn (commanded rotor speeds [rad/s])"


@pytest.mark.parametrize(
    ("table", "vehicle", "words"),
    [
        ("t,a,b\n0,1,2\n1,1,2\n", None, f"columns t,a,b fit no plant: expected {NEITHER}"),
        ("t,a,b\n0,1,2\n1,1,2\n", "iris", f"columns t,a,b fit no plant: expected {NEITHER}"),
        ("t,w1,w2,w3,w4\n0,1,1,1,1\n1,1,1,1,1\n", None, "columns t,w1..w4 are rotor speeds [rad/s], which the paper's"),
        ("t,w1,w2,w3,w4\n0,1,1,1,1\n1,1,1,1,1\n", "paper", "it replays PWM duties, columns t,u1,u2,u3,u4"),
        ("t,u1,u2,u3,u4,u5,u6\n0,1,1,1,1,1,1\n1,1,1,1,1,1,1\n", None, "column 'u5', but the vehicle has 4 rotors"),
    ],
)
def test_a_table_that_fits_no_plant_is_one_line_naming_the_file_and_the_columns(tmp_path, table, vehicle, words):
    src = tmp_path / "cmds.csv"
    src.write_text(table)
    with pytest.raises(qc.InputError) as caught:
        qc.replay(src, vehicle=vehicle)
    assert str(caught.value).startswith(f"{src}: ") and words in str(caught.value)
    args = ["replay", str(src), "-o", str(tmp_path / "s.csv")] + (["--vehicle", vehicle] if vehicle else [])
    result = CliRunner().invoke(main, args)
    assert result.exit_code == 2, result.output
    assert result.output.strip() == f"error: {caught.value}"
    assert sorted(p.name for p in tmp_path.iterdir()) == ["cmds.csv"]


def test_what_a_plant_cannot_fly_is_refused_by_name():
    speeds = qc.CommandSchedule(t=[0.0, 1.0], speeds=[[1800.0] * 4] * 2, source="mine")
    with pytest.raises(qc.InputError, match=r"^mine: rotor speeds \(columns t,w1..w4\), which the paper's plant"):
        qc.replay(speeds)
    with pytest.raises(qc.InputError, match="the commands \\(a DataFrame\\): columns t,w1..w2 are rotor speeds"):
        qc.replay(pd.DataFrame({"t": [0.0, 1.0], "w1": [1.0, 1.0], "w2": [1.0, 1.0]}))
    six = qc.CommandSchedule(t=[0.0, 1.0], speeds=[[1800.0] * 6] * 2, source="six")
    with pytest.raises(qc.InputError, match=r"^six: 6 speeds columns \(w1..\), but the vehicle has 4 rotors"):
        qc.replay(six, vehicle="crazyflie")
    with pytest.raises(qc.InputError, match="argument ground: the paper's plant replays without a ground"):
        qc.replay(PWM, ground=True)
    with pytest.raises(qc.InputError, match="argument wind: the paper's plant replays in still air"):
        qc.replay(PWM, wind=(1.0, 0.0, 0.0))
    with pytest.raises(qc.InputError, match="argument full_dynamics: the rotor plant's kinematics"):
        qc.replay(FLIP, vehicle="crazyflie", full_dynamics=True)
    with pytest.raises(qc.InputError, match="give duties .* or speeds .*, exactly one"):
        qc.CommandSchedule(t=[0.0, 1.0])
    with pytest.raises(qc.InputError, match=r"row 2, column 'w3': rotor speed is not finite \(inf\)"):
        qc.CommandSchedule(t=[0.0, 1.0], speeds=[[1.0] * 4, [1.0, 1.0, np.inf, 1.0]])


def test_a_dataframe_names_its_row_and_column():
    frame = pd.DataFrame({"t": [0.0, 1.0, 2.0], "u1": [0.1] * 3, "u2": [0.1, "x", 0.1], "u3": [0.1] * 3})
    frame["u4"] = [0.1, 0.1, np.nan]
    with pytest.raises(qc.InputError, match=r"row 2, column 'u2': 'x' is not a number"):
        qc.read_commands(frame)
    frame["u2"] = 0.1
    with pytest.raises(qc.InputError, match=r"row 3, column 'u4': value is NaN"):
        qc.read_commands(frame)
    frame["u4"] = 0.1
    frame["note"] = "a"
    with pytest.warns(UserWarning, match="ignoring column\\(s\\) note"):
        assert qc.read_commands(frame).duties.shape == (3, 4)


# --- the old names: deprecated aliases for one release, each warning with the new call -------------
def test_the_old_names_still_work_and_warn_naming_the_new_call(tmp_path):
    cf = qc.Vehicle.preset("crazyflie")
    with pytest.warns(DeprecationWarning, match=r"use CommandSchedule\(t, duties=...\)"):
        duty = qc.DutySchedule(t=[0.0, 1.0], duties=[[0.5] * 4] * 2)
    with pytest.warns(DeprecationWarning, match=r"use CommandSchedule\(t, speeds=...\)"):
        speed = qc.SpeedSchedule(t=[0.0, 1.0], speeds=[[1800.0] * 4] * 2)
    assert isinstance(duty, qc.CommandSchedule) and duty.kind == "duties" and speed.kind == "speeds"
    with pytest.warns(DeprecationWarning, match=r"read_duty_csv\(path\) is deprecated .*use read_commands\(path\)"):
        old = qc.read_duty_csv(PWM)
    np.testing.assert_array_equal(old.duties, qc.read_commands(PWM).duties)
    with pytest.warns(DeprecationWarning, match=r"use read_commands\(path, vehicle\)"):
        old = qc.read_speed_csv(FLIP, 4)
    np.testing.assert_array_equal(old.speeds, qc.read_commands(FLIP, cf).speeds)
    with pytest.warns(DeprecationWarning, match=r"use read_commands\(path, vehicle\)"):
        assert read_rotor_csv(FLIP, cf).kind == "speeds"
    with pytest.warns(DeprecationWarning, match=r"use replay\(commands, vehicle=...\)"):
        old = qc.replay_rotors(FLIP, cf)
    np.testing.assert_array_equal(old.states, qc.replay(FLIP, vehicle=cf).states)
    with pytest.warns(DeprecationWarning, match=r"use write_states_csv\(\)"):
        qc.write_rotor_states_csv(old, tmp_path / "old.csv")
    qc.write_states_csv(old, tmp_path / "new.csv")
    assert (tmp_path / "old.csv").read_bytes() == (tmp_path / "new.csv").read_bytes()
    with pytest.warns(DeprecationWarning), pytest.raises(qc.InputError, match="replay_rotors needs a rotor-plant"):
        qc.replay_rotors(FLIP, qc.Vehicle.paper())
