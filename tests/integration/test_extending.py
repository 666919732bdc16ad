"""One declaration per controller: docs/extending.md's example, declared once, flies by name in
fly, compare (paper and rotor-plant vehicles), the command line, the gym's baselines and a
scenario file; an installed package's entry point declares one for a fresh process."""

import json
import os
import re
import runpy
import subprocess
import sys
import textwrap
from pathlib import Path

import numpy as np
import pytest
from click.testing import CliRunner

import quadcruise as qc
from quadcruise.cli import main
from quadcruise.control import NLPD, controller_from_name
from quadcruise.control.design import attitude_pid_design, pd_from_poles
from quadcruise.control.registry import (
    baseline_names,
    compared_names,
    controller_names,
    register_controller,
    unregister_controller,
)
from quadcruise.errors import InputError
from quadcruise.model.equivalent import paper_equivalent
from quadcruise.model.rotor_vehicle import RotorVehicle

ROOT = Path(__file__).resolve().parents[2]
EXAMPLE = ROOT / "examples" / "own_controller.py"


@pytest.fixture
def gentle():
    """The docs' example declared, and taken back after the test (the registry is per process)."""
    names = runpy.run_path(str(EXAMPLE))
    yield names["Gentle"]
    unregister_controller("gentle")


def test_the_docs_show_the_example_file_verbatim():
    text = (ROOT / "docs" / "extending.md").read_text()
    blocks = re.findall(r"```python\n(.*?)```", text, flags=re.S)
    assert EXAMPLE.read_text() in blocks


def test_fly_by_name_equals_the_object(gentle):
    by_name = qc.fly("step", "gentle", duration=3)
    by_object = qc.fly("step", gentle(), duration=3)
    nlpd = qc.fly("step", "nlpd", duration=3)
    assert by_name.meta["controller"]["name"] == "gentle"
    assert by_name.meta["controller"]["position"] == {"kp": 1.0, "kd": 2.5}  # (s + 0.5)(s + 2)
    assert np.array_equal(by_name.states, by_object.states)
    assert not np.allclose(by_name.states, nlpd.states)  # its own gains, not nlpd's
    assert list(by_name.status) == [0]


def test_compare_on_paper_and_rotor_vehicles(gentle):
    assert "gentle" in controller_names() and "gentle" not in compared_names()
    cmp = qc.compare("step", ["nlpd", "gentle"], duration=2)
    assert list(cmp.controllers) == ["nlpd", "gentle"] and isinstance(cmp.controllers["gentle"], gentle)
    rotor = RotorVehicle.preset("crazyflie")
    cmp = qc.compare("step", ["gentle"], vehicle=rotor, duration=2)
    flown = cmp.controllers["gentle"]
    w = paper_equivalent(rotor).omega
    assert isinstance(flown, gentle) and w != 15.0
    assert flown.attitude == attitude_pid_design(w) and flown.yaw == attitude_pid_design(w)
    assert flown.position == pd_from_poles((-0.5, -2.0))  # the rest as declared
    assert (cmp.metrics()["status"] == "finished").all()


def test_tune_starts_from_its_gains(gentle):
    from quadcruise.tune import tune

    res = tune("step", "gentle", gains="position.kp", targets={"rise_time_s": 2.0}, duration=6.0, budget=4, popsize=6)
    assert res.start_gains == {"position.kp": 1.0}  # gentle's, not nlpd's 3.01
    assert isinstance(res.controller, gentle) and res.controller.name == "gentle"
    assert res.controller.position.kd == 2.5 and res.controller.position.kp == res.gains["position.kp"]


def test_montecarlo_by_name(gentle):
    from quadcruise.montecarlo import Population, montecarlo

    by_name = montecarlo("step", "gentle", Population(mass_spread=0.1), n=4, seed=1, duration=2, scheduler="none")
    by_object = montecarlo("step", gentle(), Population(mass_spread=0.1), n=4, seed=1, duration=2, scheduler="none")
    assert by_name.spec.controller.name == "gentle"
    assert by_name.table["rmse_m"].tolist() == by_object.table["rmse_m"].tolist()


def test_command_line_and_scenario_file(gentle, tmp_path):
    out = tmp_path / "flight"
    res = CliRunner().invoke(main, ["fly", "step", "--controller", "gentle", "--duration", "2", "--out", str(out)])
    assert res.exit_code == 0, res.output
    assert "gentle on step" in res.output
    assert json.loads((out / "quadcruise.json").read_text())["controller"]["position"] == {"kp": 1.0, "kd": 2.5}
    again = CliRunner().invoke(main, ["fly", str(out / "scenario.toml"), "--out", str(tmp_path / "again")])
    assert again.exit_code == 0, again.output
    first, second = (np.loadtxt(p / "traces.csv", delimiter=",", skiprows=1) for p in (out, tmp_path / "again"))
    assert np.array_equal(first, second)
    both = CliRunner().invoke(main, ["compare", "step", "--controllers", "nlpd,gentle", "--duration", "2"])
    assert both.exit_code == 0, both.output
    assert "gentle" in both.output and "nlpd" in both.output


def test_gym_baselines_include_it(gentle):
    pytest.importorskip("gymnasium")
    from quadcruise.gym.evaluate import baselines

    assert baseline_names()[-1] == "gentle"
    table = baselines(num_envs=2, mission="hover", duration=0.5)
    assert list(table.index) == list(baseline_names())
    assert table.loc["gentle", "finished"] == 1.0
    from quadcruise.gym.env import QuadVectorEnv

    rotor = RotorVehicle.preset("crazyflie")
    env = QuadVectorEnv(2, controller="gentle", vehicle=rotor, mission="hover", duration=0.5)
    assert isinstance(env.baseline, gentle) and env.baseline.attitude == attitude_pid_design(
        paper_equivalent(rotor).omega
    )


def test_without_rotor_design_one_line_on_a_rotor_vehicle(gentle):
    class PaperOnly(gentle):
        name = "paper_only"

    register_controller("paper_only", PaperOnly)
    try:
        assert list(qc.fly("hover", "paper_only", duration=0.5).status) == [0]
        with pytest.raises(InputError, match="'paper_only' has no design for a rotor-plant vehicle"):
            qc.fly("hover", "paper_only", vehicle="crazyflie", duration=0.5)
        assert list(qc.fly("hover", PaperOnly(), vehicle="crazyflie", duration=0.5).status) == [0]
    finally:
        unregister_controller("paper_only")
    with pytest.raises(InputError, match="unknown controller 'paper_only'"):
        controller_from_name("paper_only")


def test_declarations_refused():
    with pytest.raises(InputError, match="already declared"):
        register_controller("nlpd", NLPD)
    with pytest.raises(InputError, match="NLPD.name is 'nlpd'; give the class `name = 'mine'`"):
        register_controller("mine", NLPD)  # it would be flown and reported as nlpd
    with pytest.raises(InputError, match="must be letters"):
        register_controller("my controller", NLPD)
    with pytest.raises(InputError, match="rotor_design must be callable"):
        register_controller("nlpd", NLPD, rotor_design=3.0, replace=True)
    assert controller_names()[:4] == ("nlpd", "gonzalez", "se3", "cascade")
    entry = unregister_controller("cascade")
    try:
        assert "cascade" not in controller_names() and "cascade" not in compared_names()
        with pytest.raises(InputError, match="unknown controller 'cascade'"):
            qc.fly("hover", "cascade", duration=0.5)
    finally:
        register_controller(**entry._asdict())  # declared again as it was
    assert {"nlpd", "gonzalez", "se3", "cascade"} <= set(controller_names()) and "cascade" in compared_names()


def test_an_installed_entry_point_declares_it_in_a_fresh_process(tmp_path):
    (tmp_path / "gentle_plugin.py").write_text(EXAMPLE.read_text())
    info = tmp_path / "gentle_plugin-1.0.dist-info"
    info.mkdir()
    (info / "METADATA").write_text("Metadata-Version: 2.1\nName: gentle-plugin\nVersion: 1.0\n")
    (info / "entry_points.txt").write_text("[quadcruise.controllers]\ngentle = gentle_plugin\n")
    code = textwrap.dedent(
        """
        from quadcruise.control import CONTROLLERS, controller_from_name
        print(list(CONTROLLERS), controller_from_name("gentle").position.kp)
        """
    )
    env = {**os.environ, "PYTHONPATH": os.pathsep.join([str(tmp_path), os.environ.get("PYTHONPATH", "")])}
    got = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, env=env, check=False)
    assert got.returncode == 0, got.stderr
    assert got.stdout.strip() == "['nlpd', 'gonzalez', 'se3', 'cascade', 'px4', 'gentle'] 1.0"
