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
        "circle",
        "nlpd",
        duration=4.0,
        dt=2e-3,
        log_every=4,
        seed=5,
        vehicle=with_drag(qc.Vehicle.paper().replace(m=3.8)),
        controller_vehicle=qc.Vehicle.paper(),
        environment=Environment(
            wind=ConstantWind((1.0, 0.5, 0.0)),
            gust=Gust((0.0, 2.0, 0.0), 1.0, 1.0),
            turbulence=Turbulence(intensity="moderate"),
            rotor_loss=RotorLoss(rotor=1, fraction=0.2, time=2.0),
            force=ExternalForce(force=(0.1, 0.0, 0.0)),
        ),
        sensors=SensorNoise(position_std=0.01, angle_std=0.002, delay=0.004),
    ),
    "waypoints": lambda: qc.fly(Waypoints(read_waypoints_csv(EXAMPLES / "waypoints.csv")), Cascade(), duration=4.0),
    "minsnap": lambda: qc.fly(MinimumSnap(read_waypoints_csv(EXAMPLES / "waypoints.csv")), "se3", duration=4.0),
    "batch": lambda: qc.fly(
        "step", "gonzalez", vehicle=qc.Vehicle(m=np.array([3.0, 3.5])), duration=3.0, max_track_error=5.0
    ),
    "start": lambda: qc.fly(
        "hover", "nlpd", duration=2.0, x0=np.r_[0.3, -0.2, 1.2, np.zeros(9), np.full(4, 3.499 * 9.81 / 4)]
    ),
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
    run = RUNNER.invoke(
        main,
        [
            "fly",
            str(EXAMPLES / "scenarios" / "circle_paper.toml"),
            "-m",
            "radius=3",
            "-c",
            "max_tilt=0.5",
            "--duration",
            "2",
            "--out",
            str(tmp_path / "a"),
        ],
    )
    assert run.exit_code == 0, run.output
    sc = load_scenario(tmp_path / "a" / "scenario.toml")
    assert sc.mission.radius == 3.0 and sc.controller.max_tilt == 0.5 and sc.duration == 2.0
    text = (tmp_path / "a" / "scenario.toml").read_text()
    assert "-m radius=3" in text and "-c max_tilt=0.5" in text
    bad = RUNNER.invoke(
        main, ["fly", str(EXAMPLES / "scenarios" / "circle_paper.toml"), "-m", "foo=2", "--out", str(tmp_path / "b")]
    )
    assert bad.exit_code == 2 and "foo" in bad.output and not (tmp_path / "b").exists()
    smooth = RUNNER.invoke(main, ["fly", "circle", "--smooth"])
    assert smooth.exit_code == 2 and "--smooth" in smooth.output


def test_loading_a_scenario_runs_no_code(tmp_path):
    marker = tmp_path / "ran"
    path = tmp_path / "evil.toml"
    path.write_text(f"[controller]\nname = \"__import__('pathlib').Path('{marker}').touch()\"\n")
    with pytest.raises(qc.InputError, match="unknown controller name"):
        load_scenario(path)
    path.write_text(f"[mission]\nkind = \"circle\"\nradius = \"__import__('pathlib').Path('{marker}').touch()\"\n")
    with pytest.raises(qc.InputError):
        load_scenario(path)
    assert not marker.exists()


def test_a_comparison_folder_replays_itself_and_compare_takes_a_scenario(tmp_path):
    a, b = tmp_path / "a", tmp_path / "b"
    one = RUNNER.invoke(
        main,
        [
            "compare",
            str(EXAMPLES / "scenarios" / "circle_turbulence.toml"),
            "--controllers",
            "nlpd,se3",
            "--duration",
            "3",
            "--out",
            str(a),
        ],
    )
    assert one.exit_code == 0, one.output
    sc = load_scenario(a / "scenario.toml")
    assert list(sc.compare) == ["nlpd", "se3"] and sc.environment is not None and sc.sensor_noise is not None
    two = RUNNER.invoke(main, ["compare", str(a / "scenario.toml"), "--out", str(b)])
    assert two.exit_code == 0, two.output
    assert (a / "metrics.csv").read_text() == (b / "metrics.csv").read_text()
    csv = RUNNER.invoke(main, ["compare", str(EXAMPLES / "waypoints.csv"), "--controllers", "nlpd", "--duration", "2"])
    assert csv.exit_code == 0, csv.output


def test_a_montecarlo_folder_replays_itself_and_takes_every_mission_source(tmp_path):
    a, b = tmp_path / "a", tmp_path / "b"
    common = ["--scheduler", "none", "--quiet"]
    one = RUNNER.invoke(
        main,
        [
            "montecarlo",
            "--mission",
            "step",
            "--n",
            "5",
            "--seed",
            "3",
            "--duration",
            "3",
            "--mass-spread",
            "0.1",
            "--wind",
            "dryden:light@10",
            "--noise",
            "position=0.01",
            "--require",
            "rmse_m<=1",
            "--out",
            str(a),
            *common,
        ],
    )
    assert one.exit_code == 0, one.output
    two = RUNNER.invoke(main, ["montecarlo", "--scenario", str(a / "scenario.toml"), "--out", str(b), *common])
    assert two.exit_code == 0, two.output
    assert (a / "flights.csv").read_text() == (b / "flights.csv").read_text()
    import json

    assert (
        json.loads((a / "quadcruise.json").read_text())["spec_hash"]
        == json.loads((b / "quadcruise.json").read_text())["spec_hash"]
    )
    as_mission = RUNNER.invoke(main, ["montecarlo", "--mission", str(a / "scenario.toml"), *common])
    assert as_mission.exit_code == 0 and "5 flights of nlpd on step" in as_mission.output
    csv = RUNNER.invoke(
        main,
        [
            "montecarlo",
            "--mission",
            str(EXAMPLES / "waypoints.csv"),
            "--n",
            "2",
            "--duration",
            "2",
            "--offset",
            "0.01",
            *common,
        ],
    )
    assert csv.exit_code == 0 and "on waypoints" in csv.output, csv.output


def test_a_reproduction_folder_holds_the_scenario_that_flies_it_again(tmp_path):
    from quadcruise.workflows.reproduce import reproduce, write_reproduction

    light = qc.Vehicle.paper().replace(m=1.4)
    first = quiet(reproduce, scenarios=("step",), vehicle=light, dt=2e-3)
    write_reproduction(first, tmp_path / "r")
    sc = load_scenario(tmp_path / "r" / "scenario.toml")
    again = quiet(reproduce, scenarios=("step",), vehicle=sc.vehicle, dt=sc.dt)
    assert again.runs == first.runs and sc.vehicle.m == 1.4


def test_the_vehicle_the_belief_the_world_and_the_seed_from_options_replay_from_the_folder(tmp_path):
    a, b, c = tmp_path / "a", tmp_path / "b", tmp_path / "c"
    options = [
        "--vehicle",
        "m=3.8,Jzz=0.05",
        "--controller-vehicle",
        "paper",
        "--wind",
        "constant:1,0.5,0",
        "--turbulence",
        "light",
        "--seed",
        "3",
        "--log-every",
        "5",
        "--duration",
        "3",
    ]
    one = RUNNER.invoke(main, ["fly", "circle", *options, "--out", str(a)])
    assert one.exit_code in (0, 1), one.output
    sc = load_scenario(a / "scenario.toml")
    assert sc.vehicle.m == 3.8 and sc.vehicle.Jzz == 0.05 and sc.vehicle.drag_linear == 0.3  # the default drag
    assert sc.controller_vehicle == qc.Vehicle.paper()
    assert sorted(sc.environment.parts) == ["turbulence", "wind"] and sc.environment.turbulence.intensity == "light"
    assert sc.simulation["seed"] == 3 and sc.simulation["log_every"] == 5
    assert len(pd.read_csv(a / "traces.csv")) == 3000 // 5 + 1
    two = RUNNER.invoke(main, ["fly", str(a / "scenario.toml"), "--out", str(b)])
    assert two.exit_code == one.exit_code, two.output
    assert (a / "traces.csv").read_text() == (b / "traces.csv").read_text()
    # beside the scenario an option changes it: another seed, another turbulence, other numbers
    three = RUNNER.invoke(main, ["fly", str(a / "scenario.toml"), "--seed", "4", "--out", str(c)])
    assert three.exit_code in (0, 1), three.output
    assert load_scenario(c / "scenario.toml").simulation["seed"] == 4
    assert (a / "traces.csv").read_text() != (c / "traces.csv").read_text()
    # and --vehicle KEY=VALUE changes the scenario's vehicle, keeping its other fields
    four = RUNNER.invoke(main, ["fly", str(a / "scenario.toml"), "--vehicle", "m=3.6", "--out", str(tmp_path / "d")])
    changed = load_scenario(tmp_path / "d" / "scenario.toml").vehicle
    assert four.exit_code in (0, 1) and changed.m == 3.6 and changed.Jzz == 0.05, four.output


def test_a_vehicle_from_a_file_or_a_preset(tmp_path):
    from quadcruise.cli.vehicle import vehicle_from_option

    (tmp_path / "light.toml").write_text("m = 1.4\nK = 48.0\n")
    assert vehicle_from_option(str(tmp_path / "light.toml"), "--vehicle") == qc.Vehicle.paper().replace(m=1.4, K=48.0)
    assert vehicle_from_option("paper", "--vehicle") == qc.Vehicle.paper()
    base = qc.Vehicle.paper().replace(K=100.0)
    assert vehicle_from_option("m=2", "--vehicle", base) == base.replace(m=2.0)  # fields change the base
    assert vehicle_from_option("paper,m=2", "--vehicle", base) == qc.Vehicle.paper().replace(m=2.0)  # a preset: not
    (tmp_path / "scenario.toml").write_text('[vehicle]\nm = 2.5\n[mission]\nkind = "hover"\n')
    assert vehicle_from_option(str(tmp_path / "scenario.toml"), "--vehicle").m == 2.5
    (tmp_path / "bad.toml").write_text("mass = 2.5\n")
    with pytest.raises(qc.InputError, match=r"--vehicle .*bad.toml: unknown key 'mass'"):
        vehicle_from_option(str(tmp_path / "bad.toml"), "--vehicle")


def test_the_controllers_belief_is_flown_the_sag_it_leaves_is_the_analytic_one(tmp_path):
    """A PD altitude loop whose controller believes the mass m_hat hovers, with the true mass m, at
    an error e = (m / m_hat - 1) g / kp below its reference (m g = m_hat (g + kp e)); told the
    truth, it holds the reference."""
    m, m_hat, kp, g = 4.55, 3.499, 3.01, 9.81
    for belief, expected in ((["--controller-vehicle", "paper"], (m / m_hat - 1) * g / kp), ([], 0.0)):
        out = tmp_path / f"f{len(belief)}"
        res = RUNNER.invoke(
            main,
            [
                "fly",
                "hover",
                "--vehicle",
                f"m={m}",
                *belief,
                "--duration",
                "15",
                "--log-every",
                "100",
                "--out",
                str(out),
            ],
        )
        assert res.exit_code in (0, 1), res.output
        assert ("note: the controller is told the flown vehicle (m=4.55)" in res.output) == (not belief)
        last = pd.read_csv(out / "traces.csv").iloc[-1]
        assert last["z_ref"] - last["z"] == pytest.approx(expected, abs=0.005)


def test_a_population_comparison_replays_itself(tmp_path):
    a, b = tmp_path / "a", tmp_path / "b"
    one = RUNNER.invoke(
        main,
        [
            "compare",
            "step",
            "--controllers",
            "nlpd,se3",
            "--duration",
            "3",
            "--population",
            "4",
            "--seed",
            "2",
            "--mass-spread",
            "0.05",
            "--wind",
            "constant:2,0,0",
            "--turbulence",
            "light",
            "--out",
            str(a),
        ],
    )
    assert one.exit_code == 0, one.output
    sc = load_scenario(a / "scenario.toml")
    assert sc.compare_population == {"n": 4, "seed": 2, "mass_spread": 0.05}
    assert sc.simulation["seed"] == 2 and sorted(sc.environment.parts) == ["turbulence", "wind"]
    # the drag the wind needs is said once, before the tables; no warning after them
    assert one.output.count("note: the vehicle has no drag, and wind acts only through drag") == 1
    assert "warning:" not in one.output and one.output.index("no drag") < one.output.index("rmse_m")
    two = RUNNER.invoke(main, ["compare", str(a / "scenario.toml"), "--out", str(b)])
    assert two.exit_code == 0, two.output
    for name in ("metrics.csv", "population.csv"):
        assert (a / name).read_text() == (b / name).read_text()
    table = pd.read_csv(a / "population.csv", index_col=0)
    assert list(table.index) == ["nlpd", "se3"] and (table["flights"] == 4).all()
    assert (table["rmse_m p95"] > table["rmse_m p50"]).all()  # the population was perturbed
    # another seed beside the scenario: other vehicles, other turbulence
    three = RUNNER.invoke(main, ["compare", str(a / "scenario.toml"), "--seed", "5", "--out", str(tmp_path / "c")])
    assert three.exit_code == 0 and load_scenario(tmp_path / "c" / "scenario.toml").compare_population["seed"] == 5
    assert (a / "population.csv").read_text() != (tmp_path / "c" / "population.csv").read_text()


def test_a_montecarlo_folder_replays_its_vehicle_and_belief(tmp_path):
    a, b = tmp_path / "a", tmp_path / "b"
    common = ["--scheduler", "none", "--quiet", "--worst", "0"]
    one = RUNNER.invoke(
        main,
        [
            "montecarlo",
            "--mission",
            "hover",
            "-n",
            "3",
            "--duration",
            "15",
            "--offset",
            "0.001",
            "--vehicle",
            "m=4",
            "--controller-vehicle",
            "paper",
            "--log-every",
            "20",
            "--out",
            str(a),
            *common,
        ],
    )
    assert one.exit_code == 0, one.output
    sc = load_scenario(a / "scenario.toml")
    assert sc.vehicle.m == 4.0 and sc.controller_vehicle == qc.Vehicle.paper()
    assert sc.montecarlo["log_dt"] == pytest.approx(0.02)
    flights = pd.read_csv(a / "flights.csv")
    sag = (4.0 / 3.499 - 1) * 9.81 / 3.01  # as in the single flight above
    assert flights["final_error_m"].to_numpy() == pytest.approx(np.full(3, sag), abs=0.01)
    two = RUNNER.invoke(main, ["montecarlo", "--scenario", str(a / "scenario.toml"), "--out", str(b), *common])
    assert two.exit_code == 0, two.output
    assert (a / "flights.csv").read_text() == (b / "flights.csv").read_text()
    told = RUNNER.invoke(
        main,
        [
            "montecarlo",
            "--mission",
            "hover",
            "-n",
            "3",
            "--duration",
            "15",
            "--offset",
            "0.001",
            "--vehicle",
            "m=4",
            *common,
        ],
    )
    assert "note: the controllers are told the nominal vehicle (m=4)" in told.output
