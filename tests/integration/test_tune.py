"""quadcruise.tune and ``quadcruise tune``: a known optimum reached, reproducible, robust over a
population, its result object and folder, and bad input refused before any flight."""

import json
import shlex

import numpy as np
import pytest
from click.testing import CliRunner

import quadcruise as qc
from quadcruise.cli import main
from quadcruise.control import NLPD, Gonzalez
from quadcruise.control.design import attitude_pid_design
from quadcruise.errors import InputError
from quadcruise.missions import Step
from quadcruise.montecarlo import Population
from quadcruise.tune import GainSpace, TuneResult, tune
from quadcruise.tune.objective import FAILURE_COST, REQUIREMENT_COST, Objective
from quadcruise.tune.spec import parse_requirements, parse_targets
from quadcruise.workflows.scenario import load_scenario

SMALL = dict(duration=6.0, budget=4, popsize=6)


def run(*args):
    return CliRunner().invoke(main, [str(a) for a in args])


@pytest.fixture(scope="module")
def small():
    """A small tune: one gain, few generations."""
    return tune(
        Step(size=1.0, time=0.5),
        "nlpd",
        gains="position.kp",
        targets=["rise_time_s=1.2"],
        require=["overshoot_pct<=20"],
        seed=2,
        **SMALL,
    )


def test_reaches_the_gains_of_a_designed_linear_response():
    """A linear-like loop (fast rotors and attitude, a 1 cm step: nothing saturates) behaves as
    Kp / (s^2 + Kd s + Kp); the targets are python-control's step_info of a designed pole pair,
    and the tuner finds that pair's gains from the paper's."""
    ctrl = pytest.importorskip("control")
    kp, kd = 4.0, 2.4  # wn 2 rad/s, zeta 0.6
    info = ctrl.step_info(ctrl.tf([kp], [1.0, kd, kp]))
    targets = [
        f"rise_time_s={info['RiseTime']}",
        f"settling_time_s={info['SettlingTime']}",
        f"overshoot_pct={info['Overshoot']}",
    ]
    fast = attitude_pid_design(300.0)
    res = tune(
        Step(size=0.01, time=0.5),
        NLPD(attitude=fast, yaw=fast),
        targets=targets,
        seed=3,
        duration=8.0,
        vehicle=qc.Vehicle.paper().replace(omega=300.0),
    )
    assert res.met and res.start_gains == {"position.kp": 3.01, "position.kd": 5.0}
    assert res.gains["position.kp"] == pytest.approx(kp, rel=0.05)
    assert res.gains["position.kd"] == pytest.approx(kd, rel=0.05)


def test_the_same_seed_gives_the_same_gains(small):
    again = tune(
        Step(size=1.0, time=0.5),
        "nlpd",
        gains="position.kp",
        targets=["rise_time_s=1.2"],
        require=["overshoot_pct<=20"],
        seed=2,
        **SMALL,
    )
    assert again.gains == small.gains and again.to_pandas().equals(small.to_pandas())


def test_result_speaks_like_every_result(small, tmp_path):
    assert isinstance(small, TuneResult)
    hist = small.to_pandas()
    assert list(hist.columns) == ["generation", "candidate", "position.kp", "cost"]
    assert len(hist) == 6 * (small.generations + 1) and small.cost == hist["cost"].min()
    summary = small.summary()
    assert summary["gains"]["position.kp"]["tuned"] == small.gains["position.kp"]
    assert [c["metric"] for c in summary["checks"]] == ["rise_time_s", "overshoot_pct"]
    assert "position.kp" in str(summary) and "rise_time_s" in str(summary)
    assert len(small.plot().axes) == 2
    out = small.write(tmp_path / "t")
    assert sorted(p.name for p in out.iterdir()) == [
        "flights.csv",
        "history.csv",
        "quadcruise.json",
        "scenario.toml",
        "tune.json",
        "tune.png",
    ]
    assert json.loads((out / "tune.json").read_text())["gains"]["position.kp"]["tuned"] == small.gains["position.kp"]
    sc = load_scenario(out / "scenario.toml")  # flies the tuned gains
    assert sc.controller.position.kp == small.gains["position.kp"]
    assert sc.fly().metrics().iloc[0]["rise_time_s"] == pytest.approx(small.reached("rise_time_s"), abs=0.02)


def test_robust_tune_flies_each_candidate_on_the_same_perturbed_vehicles():
    pop = Population(mass_spread=0.05, inertia_spread=0.1)  # none sags off its altitude: every sample flies
    res = tune(
        Step(size=1.0, time=0.5),
        "nlpd",
        gains="position.kp",
        targets=["settling_time_s=3"],
        population=pop,
        samples=5,
        objective="worst",
        seed=1,
        **SMALL,
    )
    assert len(res.flights) == 5 and res.info["flights"] == 5 * 6 * (res.generations + 1)
    assert res.reached("settling_time_s") == res.flights["settling_time_s"].max()
    assert res.flights["settling_time_s"].nunique() == 5  # five different vehicles
    assert "[montecarlo]" in res.scenario_toml() and "mass_spread = 0.05" in res.scenario_toml()
    median = tune(
        Step(size=1.0, time=0.5),
        "nlpd",
        gains="position.kp",
        targets=["settling_time_s=3"],
        population=pop,
        samples=5,
        objective="median",
        seed=1,
        **SMALL,
    )
    assert median.cost == np.quantile(median.flights["cost"], 0.5, method="higher")


def test_requirements_rank_before_targets_and_failures_last(small):
    obj = Objective(None, None, parse_targets(["rise_time_s=1"]), parse_requirements(["overshoot_pct<=5"]))
    metrics = {
        "status": np.array([[0, 0, 0, 0, 3]]),
        "rise_time_s": np.array([[1.0, 1.5, 1.0, np.nan, 1.0]]),
        "overshoot_pct": np.array([[0.0, 5.0, 6.0, 0.0, 0.0]]),
        "rmse_m": np.array([[0.1, 0.1, 0.1, 0.5, np.nan]]),
    }
    cost = obj.flight_cost(metrics)[0]
    assert cost[0] == 0.0 and cost[1] == pytest.approx(25.0)  # (0.5 s / 0.1 s)^2
    assert cost[2] == pytest.approx(REQUIREMENT_COST * (1 + 1 / 5))  # 1 point over a bound of 5
    assert cost[3] == FAILURE_COST * 1.5 and cost[4] == 10 * FAILURE_COST  # no rise time; did not finish
    assert obj.reduce(cost[None, :4]) == FAILURE_COST * 1.5
    assert small.to_pandas()["cost"].min() < REQUIREMENT_COST


def test_gains_by_pole_pair_and_derived_saturation_levels():
    space = GainSpace.build(NLPD(), "position.wn,position.zeta", {"position.zeta": (0.3, 1.2)})
    c = space.controllers([[2.0, 0.5]])[0]
    assert (c.position.kp, c.position.kd) == pytest.approx((4.0, 2.0))
    assert space.gains[1].log is False and space.gains[0].log is True
    base = GainSpace.build(Gonzalez(), "position.kp").controllers([[0.5]])[0]  # the literal tanh form follows k_p
    assert base.accel_p == pytest.approx(0.5)
    fixed = GainSpace.build(Gonzalez(accel_p=3.85), "position.kp").controllers([[0.5]])[0]
    assert fixed.accel_p == 3.85


RISE = ["--target", "rise_time_s=1"]


@pytest.mark.parametrize(
    "args, message",
    [
        (["--target", "rise=1"], "unknown metric 'rise'"),
        (["--target", "overshoot_pct=-4"], "no metric is negative"),
        (["--minimize", "rmse"], "unknown metric 'rmse' (did you mean 'rmse_m'?)"),
        (["--gains", "position.kx", *RISE], "unknown gain 'position.kx' of nlpd (did you mean 'position.kp'?)"),
        (["--bounds", "position.kp=10:1", *RISE], "reversed or empty"),
        (["--bounds", "position.kp=1:1", *RISE], "reversed or empty"),
        (["--bounds", "position.kp=-1:3", *RISE], "must be > 0"),
        (["--bounds", "max_tilt=0.1:0.5", *RISE], "not searched"),
        (["--budget", "0", *RISE], "budget (generations) must be a whole number >= 1"),
        (["--require", "overshoot_pct=<5", *RISE], "expected METRIC<=VALUE"),
        (["--objective", "best", *RISE], "expected worst, median or a quantile"),
        ([], "nothing to tune for"),
    ],
)
def test_bad_input_is_one_line_exit_2_before_any_flight(tmp_path, monkeypatch, args, message):
    def no_flight(*a, **k):
        raise AssertionError("flew before refusing bad input")

    monkeypatch.setattr("quadcruise.tune.objective.fly_chunk", no_flight)
    out = tmp_path / "out"
    res = run("tune", "step", *args, "--out", out)
    assert res.exit_code == 2, res.output
    lines = res.output.strip().splitlines()
    assert len(lines) == 1 and lines[0].startswith("error: ") and message in lines[0], res.output
    assert not out.exists()


def test_cli_prints_progress_and_summary_and_writes_the_folder(tmp_path, monkeypatch):
    monkeypatch.setenv("QUADCRUISE_PROGRESS", "1")  # the bar, as on a terminal
    out = tmp_path / "tuned"
    res = run(
        "tune",
        "step",
        "-m",
        "time=0.5",
        "--gains",
        "position.kp",
        "--target",
        "rise_time_s=1.2+-0.2",
        "--budget",
        "2",
        "--popsize",
        "5",
        "--duration",
        "6",
        "--seed",
        "4",
        "--out",
        out,
    )
    assert res.exit_code == 0, res.output
    assert "every target and requirement met" in res.output
    assert "tuning" in res.output and "best cost" in res.output and "tuned nlpd on step" in res.output
    text = (out / "scenario.toml").read_text()
    command = next(line for line in text.splitlines() if line.startswith("# regenerate: "))[len("# regenerate: ") :]
    assert shlex.split(command)[:3] == ["quadcruise", "tune", "step"] and "--seed 4" in command
    flown = run("fly", out / "scenario.toml")
    assert flown.exit_code == 0, flown.output


def test_cli_exits_1_when_the_tuned_gains_miss_a_target_and_still_writes_them(tmp_path):
    out = tmp_path / "missed"  # two generations cannot bring the rise within 10 % of 1.2 s
    res = run(
        "tune",
        "step",
        "-m",
        "time=0.5",
        "--gains",
        "position.kp",
        "--target",
        "rise_time_s=1.2",
        "--budget",
        "2",
        "--popsize",
        "5",
        "--duration",
        "6",
        "--seed",
        "4",
        "--out",
        out,
    )
    assert res.exit_code == 1, res.output
    assert "rise_time_s                1.2 +- 0.12" in res.output and "NO" in res.output
    assert "not every target or requirement met" in res.output
    assert json.loads((out / "tune.json").read_text())["met"] is False
    assert (out / "scenario.toml").exists()  # the best gains found, to look at or fly


def test_qc_tune_is_the_package():
    assert qc.tune.tune is tune and qc.tune.TuneResult is TuneResult


def test_library_refuses_unknown_options():
    with pytest.raises(InputError, match="tune\\(\\) has no option 'sede'"):
        tune("step", targets=["rise_time_s=1"], sede=1)
