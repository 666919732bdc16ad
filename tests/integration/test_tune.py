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
from quadcruise.tune import Bounds, GainSpace, Requirement, Target, TuneResult, tune
from quadcruise.tune.objective import FAILURE_COST, REQUIREMENT_COST, Objective
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
        targets=[Target("rise_time_s", 1.2)],
        require=[Requirement("overshoot_pct", "<=", 20)],
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
    targets = {
        "rise_time_s": info["RiseTime"],
        "settling_time_s": info["SettlingTime"],
        "overshoot_pct": info["Overshoot"],
    }
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
    again = tune(  # the same targets and requirement as mappings: the same tune
        Step(size=1.0, time=0.5),
        "nlpd",
        gains=["position.kp"],
        targets={"rise_time_s": 1.2},
        require={"overshoot_pct": ("<=", 20)},
        seed=2,
        **SMALL,
    )
    assert again.gains == small.gains and again.history.equals(small.history)


def test_result_speaks_like_every_result(small, tmp_path):
    assert isinstance(small, TuneResult)
    hist = small.history
    assert small.to_pandas().equals(small.flights) and small.metrics().equals(small.flights)
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


@pytest.mark.parametrize("controller, vehicle", [("nlpd", None), ("se3", "iris")], ids=["paper plant", "rotor plant"])
def test_a_tuned_folder_flies_its_own_numbers(controller, vehicle, tmp_path):
    """`fly DIR/scenario.toml` gives the tuned row: the same flight, logged as the search measured
    it (its 10 ms log, not every period: 0.2003 against 0.1993 m before) and judged by its bounds."""
    from quadcruise.montecarlo.schema import METRICS

    kw = {} if vehicle is None else {"vehicle": qc.Vehicle.preset(vehicle)}
    res = tune("step", controller, minimize=["rmse_m"], seed=1, duration=4.0, budget=1, popsize=5, **kw)
    out = res.write(tmp_path / "t")
    flown = load_scenario(out / "scenario.toml").fly()
    row, again = res.flights.iloc[0], flown.metrics().iloc[0]
    assert flown.meta["log_every"] == res.spec.log_every == 10 and res.response.meta["log_every"] == 10
    assert (flown.rotor_states is not None) == (vehicle is not None)
    assert again["status"] == "finished" and row["status"] == 0
    shared = [m for m in METRICS if m in again.index]
    assert {"rmse_m", "steady_max_error_m", "rise_time_s", "overshoot_pct", "effort"} <= set(shared)
    for m in shared:  # NaN (a 2 % band never reached) equal to NaN
        np.testing.assert_allclose(float(again[m]), row[m], rtol=1e-12, atol=0, err_msg=m)
    assert float(again["rmse_m"]) == pytest.approx(res.reached("rmse_m"), rel=1e-12)
    # the other direction: the same gains logged every period measure another RMSE
    fine = qc.fly("step", res.controller, duration=4.0, seed=1, **kw)
    assert abs(float(fine.metrics().iloc[0]["rmse_m"]) - row["rmse_m"]) > 1e-6


def test_robust_tune_flies_each_candidate_on_the_same_perturbed_vehicles():
    pop = Population(mass_spread=0.05, inertia_spread=0.1)  # none sags off its altitude: every sample flies
    res = tune(
        Step(size=1.0, time=0.5),
        "nlpd",
        gains="position.kp",
        targets={"settling_time_s": 3},
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
        targets={"settling_time_s": 3},
        population=pop,
        samples=5,
        objective="median",
        seed=1,
        **SMALL,
    )
    assert median.cost == np.quantile(median.flights["cost"], 0.5, method="higher")


def test_requirements_rank_before_targets_and_failures_last(small):
    obj = Objective(None, None, (Target("rise_time_s", 1),), (Requirement("overshoot_pct", "<=", 5),))
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
    assert small.history["cost"].min() < REQUIREMENT_COST


def test_gains_by_pole_pair_and_derived_saturation_levels():
    space = GainSpace.build(NLPD(), ["position.wn", "position.zeta"], [Bounds("position.zeta", 0.3, 1.2)])
    c = space.controllers([[2.0, 0.5]])[0]
    assert (c.position.kp, c.position.kd) == pytest.approx((4.0, 2.0))
    assert space.gains[1].log is False and space.gains[0].log is True
    base = GainSpace.build(Gonzalez(), "position.kp").controllers([[0.5]])[0]  # the literal tanh form follows k_p
    assert base.accel_p == pytest.approx(0.5)
    fixed = GainSpace.build(Gonzalez(accel_p=3.85), "position.kp").controllers([[0.5]])[0]
    assert fixed.accel_p == 3.85


def test_targets_requirements_and_bounds_are_objects_and_the_cli_texts_read_into_the_same():
    from quadcruise.cli.criteria import parse_bounds, parse_minimize, parse_objective, parse_targets
    from quadcruise.montecarlo.scenario import parse_requirements
    from quadcruise.tune.criteria import as_minimize, as_requirements, as_targets
    from quadcruise.tune.space import as_bounds

    targets = (Target("overshoot_pct", 4, 1.5), Target("rise_time_s", 1.0))
    assert targets[1].tolerance == pytest.approx(0.1) and Target("overshoot_pct", 0).tolerance == 1.0
    assert as_targets({"overshoot_pct": (4, 1.5), "rise_time_s": 1}, "tune()") == targets
    assert parse_targets(["overshoot_pct=4+-1.5", "rise_time_s = 1"]) == targets
    required = (Requirement("overshoot_pct", "<=", 5), Requirement("rmse_m", ">", 0.25))
    assert as_requirements({"overshoot_pct": ("<=", 5), "rmse_m": (">", 0.25)}, "tune()") == required
    assert parse_requirements(["overshoot_pct<=5", "rmse_m > 0.25"]) == required
    assert [r.text for r in required] == ["overshoot_pct<=5", "rmse_m>0.25"]
    bounds = {"position.kp": Bounds("position.kp", 0.5, 10), "position.kd": Bounds("position.kd", 1, 8)}
    assert as_bounds({"position.kp": (0.5, 10), "position.kd": [1, 8]}, "tune()") == bounds
    assert as_bounds(parse_bounds(["position.kp=0.5:10,position.kd=1:8"]), "tune()") == bounds
    assert as_minimize("rmse_m", "tune()") == parse_minimize(["rmse_m"]) == ("rmse_m",)
    assert parse_objective("q90") == 0.9 and parse_objective("max") == "worst"
    # numbers of any numeric type pass, as everywhere in the API
    assert as_targets({"rise_time_s": np.float32(1.0)}, "tune()") == (Target("rise_time_s", 1.0, 0.1),)
    assert Requirement("rmse_m", "<=", np.int64(1)) == Requirement("rmse_m", "<=", 1.0)
    assert as_bounds({"position.kp": np.array([0.5, 10.0])}, "tune()") == {"position.kp": bounds["position.kp"]}
    with pytest.raises(AttributeError):  # frozen: a target is a value
        targets[0].value = 3.0


def no_flight(*args, **kwargs):
    raise AssertionError("flew before refusing bad input")


@pytest.mark.parametrize(
    "kwargs, error, words",
    [
        (dict(targets=["rise_time_s=1"]), TypeError, ["tune() argument targets[0] must be a Target", "str 'rise_"]),
        (dict(targets="rise_time_s=1"), TypeError, ["tune() argument targets must be Target objects or a mapping"]),
        (dict(targets={"rise_time": 1}), ValueError, ["tune() argument targets key", "did you mean 'rise_time_s'?"]),
        (dict(targets={"overshoot_pct": -4}), ValueError, ["targets['overshoot_pct'] must be a number >= 0"]),
        (dict(targets={"overshoot_pct": "4"}), TypeError, ["targets['overshoot_pct'] must be", "str '4'"]),
        (dict(targets={"overshoot_pct": (4, 0)}), ValueError, ["targets['overshoot_pct'][1] must be a positive"]),
        (dict(targets={"overshoot_pct": (4, 1, 2)}), TypeError, ["targets['overshoot_pct'] must be a value or a pair"]),
        (dict(targets=[Target("rmse_m", 1), Target("rmse_m", 2)]), ValueError, ["targets gives rmse_m twice"]),
        (dict(require=["overshoot_pct<=5"]), TypeError, ["tune() argument require[0] must be a Requirement"]),
        (dict(require={"overshoot_pct": ("=<", 5)}), ValueError, ["require['overshoot_pct'][0] must be one of"]),
        (dict(require={"overshoot_pct": 5}), TypeError, ["require['overshoot_pct'] must be a pair (op, value)"]),
        (dict(require={"overshoot_pct": (["<="], 5)}), TypeError, ["require['overshoot_pct'][0] must be one of"]),
        (dict(bounds={"position.kp": "1:10"}), TypeError, ["bounds['position.kp'] must be a pair", "str '1:10'"]),
        (dict(bounds="position.kp=0.5:10"), TypeError, ["tune() argument bounds must be Bounds objects or a mapping"]),
        (dict(bounds={"position.kp": (10, 1)}), ValueError, ["bounds['position.kp'] must be a pair", "reversed"]),
        (dict(bounds={"position.kp": (1, "10")}), TypeError, ["tune() argument bounds['position.kp'][1]", "str '10'"]),
        (dict(bounds={"max_tilt": (0.1, 0.5)}), ValueError, ["bounds of 'max_tilt', which is not searched"]),
        (dict(gains="position.kp,position.kd"), ValueError, ["several gains are a list", "['position.kp', 'position"]),
        (dict(gains=3), TypeError, ["tune() argument gains must be a gain's name or a list"]),
        (dict(minimize="rmse_m,effort"), ValueError, ["tune() argument minimize must be a metric of the flights"]),
        (dict(minimize=["rmse"]), ValueError, ["minimize[0]", "did you mean 'rmse_m'?"]),
        (dict(objective="q90"), ValueError, ["tune() argument objective must be 'worst', 'median' or a quantile"]),
        (dict(objective=True), TypeError, ["tune() argument objective"]),
    ],
)
def test_bad_criteria_in_python_are_one_line_naming_the_argument_before_any_flight(monkeypatch, kwargs, error, words):
    monkeypatch.setattr("quadcruise.tune.objective.fly_chunk", no_flight)
    with pytest.raises(error) as caught:
        tune("step", **{"targets": {"rise_time_s": 1}, **kwargs})
    assert isinstance(caught.value, InputError)  # the command line would say it in one line, exit 2
    text = str(caught.value)
    assert "\n" not in text and all(w in text for w in words), text


@pytest.mark.parametrize(
    "make, error, words",
    [
        (lambda: Target("rise_time", 1), ValueError, ["Target() argument metric", "did you mean 'rise_time_s'?"]),
        (lambda: Target(3, 1), TypeError, ["Target() argument metric must be a metric's name (str), got int 3"]),
        (lambda: Target("overshoot_pct", float("nan")), ValueError, ["Target() argument value", "nan"]),
        (lambda: Target("overshoot_pct", 4, -1), ValueError, ["Target() argument tolerance must be a positive"]),
        (lambda: Requirement("rmse_m", "=<", 1), ValueError, ["Requirement() argument op must be one of"]),
        (lambda: Requirement("rmse_m", "<=", "1"), TypeError, ["Requirement() argument value", "str '1'"]),
        (lambda: Requirement("rmse_m", "<=", float("inf")), ValueError, ["Requirement() argument value", "inf"]),
        (lambda: Bounds("position.kp", 10, 1), ValueError, ["Bounds() argument high must be above low = 10"]),
        (lambda: Bounds("position.kp", "1", 10), TypeError, ["Bounds() argument low", "str '1'"]),
        (lambda: Bounds("", 1, 10), TypeError, ["Bounds() argument gain"]),
    ],
)
def test_the_objects_check_their_fields_on_construction(make, error, words):
    with pytest.raises(error) as caught:
        make()
    assert isinstance(caught.value, InputError) and all(w in str(caught.value) for w in words), str(caught.value)


RISE = ["--target", "rise_time_s=1"]


@pytest.mark.parametrize(
    "args, message",
    [
        (["--target", "rise=1"], "unknown metric 'rise' (did you mean 'rise_time_s'?)"),
        (["--target", "settling=2"], "unknown metric 'settling' (did you mean 'settling_time_s'?)"),
        (["--target", "overshoot=4"], "unknown metric 'overshoot' (did you mean 'overshoot_pct'?)"),
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
        (["--target", "overshoot_pct=4+-0"], "target 'overshoot_pct=4+-0': the tolerance must be > 0"),
        ([*RISE, "--target", "rise_time_s=2"], "target: rise_time_s is given twice"),
        (["--bounds", "position.kp=a:3", *RISE], "bounds 'position.kp=a:3': 'a' is not a finite number"),
        (
            ["--gains", ",", *RISE],
            "gains ',': expected gain names, e.g. position.kp,position.kd; gains of nlpd: position.kp",
        ),
        ([], "nothing to tune for"),
    ],
)
def test_bad_input_is_one_line_exit_2_before_any_flight(tmp_path, monkeypatch, args, message):
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
        tune("step", targets={"rise_time_s": 1}, sede=1)
