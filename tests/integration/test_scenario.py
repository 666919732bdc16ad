"""TOML scenario files: loading, validation messages, flying, the CLI."""

import warnings
from pathlib import Path

import numpy as np
import pytest
from click.testing import CliRunner

import quadcruise as qc
from quadcruise.cli import main
from quadcruise.workflows.scenario import load_scenario

EXAMPLES = Path(__file__).resolve().parents[2] / "examples"


def write(tmp_path, text, name="s.toml"):
    path = tmp_path / name
    path.write_text(text)
    return path


@pytest.mark.parametrize("name", sorted(p.name for p in (EXAMPLES / "scenarios").glob("*.toml")))
def test_shipped_scenarios_load_and_fly(name):
    sc = load_scenario(EXAMPLES / "scenarios" / name)
    assert sc.title
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")  # brief duty clipping is reported, not an error
        res = sc.fly()
    assert res.ok.all()
    assert res.meta["scenario"]["source"].endswith(name)


def test_paper_scenario_equals_the_default_flight():
    res = load_scenario(EXAMPLES / "scenarios" / "circle_paper.toml").fly()
    ref = qc.fly("circle")
    np.testing.assert_array_equal(res.states, ref.states)


def test_everything_a_scenario_sets_reaches_the_flight(tmp_path):
    path = write(
        tmp_path,
        """
title = "t"
[vehicle]
m = 2.0
[controller]
name = "gonzalez"
position_poles = [-1.0, -2.0]
altitude = { kp = 4.0, kd = 4.0 }
attitude_poles = [-8.0, -8.0, -1.0]
max_tilt = 0.5
[mission]
kind = "square"
side = 3.0
corner = [1.0, -1.0]
[simulation]
duration = 4.0
dt = 0.002
full_dynamics = true
""",
    )
    sc = load_scenario(path)
    assert sc.vehicle.m == 2.0
    c = sc.controller
    assert c.name == "gonzalez" and (c.position.kp, c.position.kd) == pytest.approx((2.0, 3.0))
    assert (c.altitude.kp, c.altitude.kd) == (4.0, 4.0) and c.max_tilt == 0.5
    assert (c.attitude.kp, c.attitude.ki, c.attitude.kd) == pytest.approx((80.0, 64.0, 17.0))
    assert sc.mission.corner == (1.0, -1.0)
    res = sc.fly()
    assert res.t[-1] == pytest.approx(4.0) and res.t[1] == pytest.approx(0.002)
    assert res.meta["full_dynamics"] is True and res.meta["vehicle"]["m"] == 2.0


def test_waypoint_table_is_relative_to_the_scenario(tmp_path):
    (tmp_path / "path.csv").write_text("x,y,z,speed\n0,0,1,\n1,0,1,0.5\n")
    sc = load_scenario(write(tmp_path, '[mission]\nkind = "waypoints"\ntable = "path.csv"\n'))
    assert sc.mission.name == "waypoints"
    assert sc.mission.reference([2.0])[0, 0] == pytest.approx(1.0)


def test_a_px4_params_file_is_relative_to_the_scenario(tmp_path, monkeypatch):
    """``[controller] params = "x.params"`` beside the scenario flies from any working folder; a
    missing one is one line naming the scenario file, the key and the file, exit 2."""
    folder = tmp_path / "sc"
    folder.mkdir()
    (folder / "x.params").write_text("1\t1\tMC_ROLL_P\t7.25\t9\n")
    text = '[mission]\nkind = "hover"\n[simulation]\nduration = 0.5\n[controller]\nname = "px4"\nparams = "{}"\n'
    (folder / "s.toml").write_text(text.format("x.params"))
    (folder / "m.toml").write_text(text.format("missing.params"))
    elsewhere = tmp_path / "elsewhere"
    elsewhere.mkdir()
    monkeypatch.chdir(elsewhere)  # not the scenario's folder: x.params is not here
    sc = load_scenario(Path("..") / "sc" / "s.toml")
    assert sc.controller.params["MC_ROLL_P"] == 7.25 and sc.controller.params.source == str(folder / "x.params")
    res = CliRunner().invoke(main, ["fly", str(Path("..") / "sc" / "s.toml")])
    assert res.exit_code == 0, res.output
    bad = CliRunner().invoke(main, ["fly", str(Path("..") / "sc" / "m.toml")])
    assert bad.exit_code == 2 and "Traceback" not in bad.output
    assert bad.output.strip() == (
        f"error: {Path('..') / 'sc' / 'm.toml'}: [controller] 'params' = 'missing.params': no such file "
        f"{folder / 'missing.params'} (relative to the scenario's folder)"
    )


BAD = [
    ("[mision]\nkind = 'circle'\n", "unknown key 'mision'"),
    ("[mission]\nkind = 'circle'\nradiu = 2\n", "[mission] unknown key 'radiu'"),
    ("[mission]\nkind = 'loop'\n", "[mission] 'kind' must be one of"),
    ("[mission]\nkind = 'circle'\nradius = 0.0\n", "[mission] circle field 'radius' (circle radius, m) must be > 0"),
    ("[simulation]\nduration = 'long'\n", "[simulation] 'duration' must be a number, got 'long'"),
    ("[simulation]\nduration = -1.0\n", "[simulation] 'duration' must be > 0"),
    ("[simulation]\nseed = 1.5\n", "[simulation] 'seed' must be an integer"),
    ("[simulation]\nfull_dynamics = 1\n", "'full_dynamics' must be true or false"),
    ("[vehicle]\nm = -3.0\n", "[vehicle] vehicle field 'm' (mass, kg) must be > 0"),
    ("[vehicle]\nmass = 3.0\n", "[vehicle] unknown key 'mass'"),
    ("[controller]\nname = 'pid'\n", "[controller] unknown controller name 'pid'"),
    (
        "[controller]\nposition_poles = [0.7, -4.3]\n",
        "[controller] pd_from_poles: pole 0.7 is not in the open left half plane",
    ),
    ("[controller]\nposition = { kp = 3.0, kx = 1.0 }\n", "[controller] unknown key 'position.kx'"),
    ("[controller]\ngain = 3.0\n", "[controller] unknown key 'gain'"),
    ("vehicle = 3\n", "[vehicle] must be a table"),
    ("[mission\nkind = 'circle'\n", "not valid TOML"),
]


@pytest.mark.parametrize("text, words", BAD)
def test_bad_scenarios_name_file_key_and_problem(tmp_path, text, words):
    path = write(tmp_path, text)
    with pytest.raises(qc.InputError) as info:
        load_scenario(path)
    message = str(info.value)
    assert message.startswith(str(path)) and words in message and "\n" not in message


def test_cli_flies_a_scenario_and_refuses_a_bad_one(tmp_path):
    runner = CliRunner()
    ok = runner.invoke(main, ["fly", str(EXAMPLES / "scenarios" / "circle_paper.toml"), "--duration", "2"])
    assert ok.exit_code == 0 and "nlpd on circle: 2 s" in ok.output
    bad = write(tmp_path, "[mission]\nkind = 'circle'\nradius = -1.0\n")
    res = runner.invoke(main, ["fly", str(bad)])
    assert res.exit_code == 2 and res.output.count("\n") == 1 and "radius" in res.output
    missing = runner.invoke(main, ["fly", str(tmp_path / "none.toml")])
    assert missing.exit_code == 2 and "no such file" in missing.output


def test_disturbances_reach_the_flight_and_the_seed_makes_it_repeatable(tmp_path):
    sc = load_scenario(EXAMPLES / "scenarios" / "circle_turbulence.toml")
    assert sc.environment.needs_drag and sc.sensor_noise is not None
    kw = sc.fly_kwargs()
    assert kw["sensors"].delay == 0.004 and kw["seed"] == 7 and kw["environment"] is sc.environment
    a, b = sc.fly(), sc.fly()
    np.testing.assert_array_equal(a.states, b.states)
    calm = load_scenario(EXAMPLES / "scenarios" / "circle_paper.toml").fly()
    assert a.ok[0] and np.abs(a.states[0, -1, :3] - calm.states[0, -1, :3]).max() > 0.01
    bad = write(tmp_path, "[disturbances]\nturbulence = { intensity = 'hurricane' }\n")
    with pytest.raises(qc.InputError, match=r"\[disturbances\].*intensity"):
        load_scenario(bad)
    bad = write(tmp_path, "[disturbances]\nstorm = 3\n", name="b.toml")
    with pytest.raises(qc.InputError, match=r"\[disturbances\] unknown key 'storm'"):
        load_scenario(bad)
