"""Every flight's output folder holds scenario.toml, which the same command flies again to the
same numbers; options given with a scenario change it and are recorded; loading runs no code."""

from __future__ import annotations

import warnings
from pathlib import Path

import numpy as np
import pandas as pd
import pytest
from click.testing import CliRunner

import quadcruise as qc
from quadcruise.cli import main
from quadcruise.control.cascade import Cascade
from quadcruise.disturbances import (
    ConstantWind,
    Environment,
    ExternalForce,
    Gust,
    RotorLoss,
    SensorNoise,
    Turbulence,
    with_drag,
)
from quadcruise.missions import MinimumSnap, Waypoints, read_waypoints_csv
from quadcruise.workflows.scenario import load_scenario

EXAMPLES = Path(__file__).parents[2] / "examples"
RUNNER = CliRunner()


def quiet(func, *args, **kwargs):
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        return func(*args, **kwargs)


FLIGHTS = {
    "everything": lambda: qc.fly(
        "circle", "nlpd", duration=4.0, dt=2e-3, log_every=3, seed=5,
        vehicle=with_drag(qc.Vehicle.paper().replace(m=3.8)), controller_vehicle=qc.Vehicle.paper(),
        environment=Environment(wind=ConstantWind((1.0, 0.5, 0.0)), gust=Gust((0.0, 2.0, 0.0), 1.0, 1.0),
                                turbulence=Turbulence(intensity="moderate"),
                                rotor_loss=RotorLoss(rotor=1, fraction=0.2, time=2.0),
                                force=ExternalForce(force=(0.1, 0.0, 0.0))),
        sensors=SensorNoise(position_std=0.01, angle_std=0.002, delay=0.004)),
    "waypoints": lambda: qc.fly(Waypoints(read_waypoints_csv(EXAMPLES / "waypoints.csv")), Cascade(), duration=4.0),
    "minsnap": lambda: qc.fly(MinimumSnap(read_waypoints_csv(EXAMPLES / "waypoints.csv")), "se3", duration=4.0),
    "batch": lambda: qc.fly("step", "gonzalez", vehicle=qc.Vehicle(m=np.array([3.0, 3.5])), duration=3.0,
                            max_track_error=5.0),
    "start": lambda: qc.fly("hover", "nlpd", duration=2.0, x0=np.r_[0.3, -0.2, 1.2, np.zeros(9),
                                                                     np.full(4, 3.499 * 9.81 / 4)]),
}


@pytest.mark.parametrize("name", sorted(FLIGHTS))
def test_a_flight_written_as_a_scenario_flies_again_to_the_same_numbers(name, tmp_path):
    first = quiet(FLIGHTS[name])
    path = tmp_path / "scenario.toml"
    path.write_text(first.scenario_toml())
    again = quiet(load_scenario(path).fly)
    np.testing.assert_array_equal(first.states, again.states)
    np.testing.assert_array_equal(first.commands, again.commands)
    pd.testing.assert_frame_equal(first.metrics(), again.metrics())


@pytest.mark.parametrize("example", sorted(p.name for p in (EXAMPLES / "scenarios").glob("*.toml")))
def test_every_example_scenario_replays_from_its_output_folder(example, tmp_path):
    a, b = tmp_path / "a", tmp_path / "b"
    one = RUNNER.invoke(main, ["fly", str(EXAMPLES / "scenarios" / example), "--duration", "3", "--out", str(a)])
    assert one.exit_code in (0, 1), one.output
    assert (a / "scenario.toml").is_file()
    two = RUNNER.invoke(main, ["fly", str(a / "scenario.toml"), "--out", str(b)])
    assert two.exit_code == one.exit_code, two.output
    assert (a / "metrics.csv").read_text() == (b / "metrics.csv").read_text()
    assert (a / "traces.csv").read_text() == (b / "traces.csv").read_text()


def test_options_given_with_a_scenario_change_it_and_are_recorded(tmp_path):
    run = RUNNER.invoke(main, ["fly", str(EXAMPLES / "scenarios" / "circle_paper.toml"), "-m", "radius=3",
                               "-c", "max_tilt=0.5", "--duration", "2", "--out", str(tmp_path / "a")])
    assert run.exit_code == 0, run.output
    sc = load_scenario(tmp_path / "a" / "scenario.toml")
    assert sc.mission.radius == 3.0 and sc.controller.max_tilt == 0.5 and sc.duration == 2.0
    text = (tmp_path / "a" / "scenario.toml").read_text()
    assert "-m radius=3" in text and "-c max_tilt=0.5" in text
    bad = RUNNER.invoke(main, ["fly", str(EXAMPLES / "scenarios" / "circle_paper.toml"), "-m", "foo=2",
                               "--out", str(tmp_path / "b")])
    assert bad.exit_code == 2 and "foo" in bad.output and not (tmp_path / "b").exists()
    smooth = RUNNER.invoke(main, ["fly", "circle", "--smooth"])
    assert smooth.exit_code == 2 and "--smooth" in smooth.output


def test_loading_a_scenario_runs_no_code(tmp_path):
    marker = tmp_path / "ran"
    path = tmp_path / "evil.toml"
    path.write_text(f'[controller]\nname = "__import__(\'pathlib\').Path(\'{marker}\').touch()"\n')
    with pytest.raises(qc.InputError, match="unknown controller name"):
        load_scenario(path)
    path.write_text(f'[mission]\nkind = "circle"\nradius = "__import__(\'pathlib\').Path(\'{marker}\').touch()"\n')
    with pytest.raises(qc.InputError):
        load_scenario(path)
    assert not marker.exists()
