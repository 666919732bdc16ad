"""Monte Carlo sweeps, tune and compare --population on rotor-plant vehicles (issue 23).

The independent path: each perturbed vehicle built here from the documented draws
(``SeedSequence([seed, i], spawn_key=(1,))``, 16 normal draws truncated at 3 sigma, the slots of
:data:`quadcruise.montecarlo.population.ROTOR_SLOTS`) and flown alone with :func:`quadcruise.fly`,
its metrics measured by :func:`quadcruise.metrics.flight_metrics`.
"""

from __future__ import annotations

import subprocess
import sys

import numpy as np
import pandas as pd
import pytest

import quadcruise as qc
from quadcruise.control import SE3
from quadcruise.disturbances import Environment, RotorLoss
from quadcruise.errors import InputError
from quadcruise.metrics import flight_metrics
from quadcruise.model.rotor_vehicle import RotorVehicle
from quadcruise.montecarlo import MonteCarloSpec, Population, montecarlo, montecarlo_case
from quadcruise.sim.status import ExitStatus


def unit_draws(seed: int, i: int) -> np.ndarray:
    g = np.random.default_rng(np.random.SeedSequence([seed, i], spawn_key=(1,)))
    z = g.standard_normal(16)
    for k in np.flatnonzero(np.abs(z) > 3.0):  # truncated: drawn again from the stream, in order
        while abs(v := g.standard_normal()) > 3.0:
            pass
        z[k] = v
    return z


def perturbed(nominal: RotorVehicle, seed: int, i: int, mass: float, inertia: float, thrust: float) -> RotorVehicle:
    z = unit_draws(seed, i)
    return nominal.replace(
        m=nominal.m * (1 + mass * z[0]),
        Jxx=nominal.Jxx * (1 + inertia * z[1]),
        Jyy=nominal.Jyy * (1 + inertia * z[2]),
        Jzz=nominal.Jzz * (1 + inertia * z[3]),
        kf=nominal.kf * (1 + thrust * z[4]),
    )


def test_a_sweep_flies_each_perturbed_crazyflie_as_fly_flies_it_alone():
    cf = RotorVehicle.preset("crazyflie")
    pop = Population(mass_spread=0.05, inertia_spread=0.1, thrust_spread=0.03)
    kw = dict(duration=8.0, vehicle=cf, scheduler="none")
    res = montecarlo("step", "se3", pop, 4, seed=5, chunk_size=3, **kw)
    table = res.table.set_index("vehicle")
    assert (
        res.spec.controller.attitude.kp
        == qc.fly("hover", "se3", vehicle=cf, duration=0.1).meta["controller"]["attitude"]["kp"]
    )  # the gains fly designs for the vehicle, not the paper's
    spreads = []
    for i in range(4):
        v = perturbed(cf, 5, i, 0.05, 0.1, 0.03)
        alone = qc.fly("step", "se3", vehicle=v, controller_vehicle=cf, duration=8.0, log_every=res.spec.log_every)
        m = flight_metrics(alone).iloc[0]
        np.testing.assert_array_equal(montecarlo_case(res.spec, i).result.rotor_states[0], alone.rotor_states[0])
        row = table.loc[i]
        assert row["m"] == pytest.approx(v.m, rel=1e-15) and row["Jyy"] == pytest.approx(v.Jyy, rel=1e-15)
        assert row["K"] == pytest.approx(v.kf * v.w_max**2, rel=1e-15)  # the "+" equivalent's K
        assert row["status"] == int(alone.status[0]) == 0 and row["reason"] == "ok"
        for metric in ("rmse_m", "max_error_m", "overshoot_pct", "rise_time_s", "settling_time_5pct_s"):
            assert np.isfinite(m[metric]) and row[metric] == pytest.approx(m[metric], rel=1e-9, abs=1e-12), metric
        spreads.append(row["rmse_m"])
    assert np.ptp(spreads) > 1e-4  # the vehicles do differ: the test could fail
    # the chunking does not matter
    again = montecarlo("step", "se3", pop, 4, seed=5, chunk_size=1, **kw)
    pd.testing.assert_frame_equal(res.table, again.table)


def test_model_error_off_each_controller_knows_its_own_vehicle():
    iris = RotorVehicle.preset("iris")
    pop = Population(mass_spread=0.1, model_error=False)
    res = montecarlo("hover", "se3", pop, 2, seed=1, duration=3.0, vehicle=iris, scheduler="none")
    with_error = montecarlo(
        "hover", "se3", Population(mass_spread=0.1), 2, seed=1, duration=3.0, vehicle=iris, scheduler="none"
    )
    for i in range(2):
        v = perturbed(iris, 1, i, 0.1, 0.0, 0.0)
        alone = qc.fly("hover", "se3", vehicle=v, duration=3.0, log_every=res.spec.log_every)
        assert res.table.loc[i, "final_error_m"] == pytest.approx(
            np.linalg.norm(alone.states[0, -1, :3] - alone.references[0, -1, :3]), rel=1e-9
        )
    # knowing its mass, se3 holds its altitude; believing the nominal one, it sags or climbs
    assert res.table["final_error_m"].max() < 0.01 < with_error.table["final_error_m"].min()


def test_a_rotor_fault_crashes_the_heavy_vehicles_and_the_sweep_says_so():
    iris = "iris"
    env = Environment(rotor_loss=RotorLoss(rotor=1, fraction=0.5, time=0.5))
    pop = Population(mass_spread=0.25)
    faulty = montecarlo(
        "hover",
        "se3",
        Population(mass_spread=0.25, environment=env),
        8,
        seed=2,
        duration=4.0,
        vehicle=iris,
        scheduler="none",
    )
    calm = montecarlo("hover", "se3", pop, 8, seed=2, duration=4.0, vehicle=iris, scheduler="none")
    crashed = faulty.table["status"] == int(ExitStatus.CRASHED)
    assert 0 < crashed.sum() < 8  # some, not all: the heavier ones
    assert (faulty.table.loc[crashed, "reason"] == "diverged").all()
    assert faulty.table.loc[crashed, "m"].min() > faulty.table.loc[~crashed, "m"].median()
    assert faulty.summary_data()["stopped"][ExitStatus.CRASHED.reason] == crashed.sum()
    assert "crashed: hit the ground" in faulty.summary_text()
    assert (faulty.table.loc[crashed, "stop_time_s"] < 4.0).all()
    # the other direction: without the fault none crashes, and the same draws fly
    assert (calm.table["status"] != int(ExitStatus.CRASHED)).all()
    np.testing.assert_array_equal(calm.table["m"], faulty.table["m"])
    # a crashed vehicle flown alone crashes too
    k = int(np.flatnonzero(crashed)[0])
    v = RotorVehicle.preset("iris").replace(m=float(faulty.table.loc[k, "m"]))
    with pytest.warns(Warning) as caught:
        alone = qc.fly(
            "hover", "se3", vehicle=v, controller_vehicle=RotorVehicle.preset("iris"), duration=4.0, environment=env
        )
    assert any("crashed" in str(w.message) for w in caught)
    assert alone.status_text(0).startswith("crashed") and alone.t_stop[0] == faulty.table.loc[k, "stop_time_s"]


def test_a_drawn_vehicle_that_cannot_lift_itself_flies_and_falls_instead_of_stopping_the_sweep():
    pop = Population(mass_spread=0.5, thrust_spread=0.55, distribution="uniform")
    res = montecarlo("hover", "se3", pop, 12, seed=0, duration=3.0, vehicle="crazyflie", scheduler="none")
    t = res.table
    lift = 4.0 * t["K"] / (t["m"] * 9.81)  # K = (n/4) kf w_max^2: all rotors at full speed over the weight
    weak = lift < 1.0
    assert weak.sum() >= 2 and (t.loc[weak, "status"] == int(ExitStatus.CRASHED)).all()
    assert (t.loc[lift > 1.1, "status"] != int(ExitStatus.CRASHED)).all()
    with pytest.raises(InputError, match="cannot lift itself"):  # a vehicle of one's own is still checked
        RotorVehicle.preset("crazyflie").replace(m=1.0)


def test_a_tune_on_a_rotor_vehicle_improves_its_flight():
    from quadcruise.tune import tune

    result = tune("step", "se3", vehicle="crazyflie", minimize="rmse_m", budget=4, popsize=8, duration=3.0, seed=2)
    start = qc.fly("step", result.start, vehicle="crazyflie", duration=3.0)
    tuned = qc.fly("step", result.controller, vehicle="crazyflie", duration=3.0, log_every=result.spec.log_every)
    assert result.start.attitude.kp == start.meta["controller"]["attitude"]["kp"] != SE3().attitude.kp
    before, after = flight_metrics(start)["rmse_m"].iloc[0], flight_metrics(tuned)["rmse_m"].iloc[0]
    assert after < 0.95 * before
    assert result.cost == pytest.approx(after, rel=1e-6)


def test_compare_names_get_the_gains_fly_gives_and_a_population_flies_them():
    from quadcruise.montecarlo.compare import compare_population

    cmp = qc.compare("hover", "se3", vehicle="iris", duration=0.5)
    assert (
        cmp.results["se3"].meta["controller"] == qc.fly("hover", "se3", vehicle="iris", duration=0.5).meta["controller"]
    )
    table = compare_population(
        "hover", "se3,nlpd", Population(mass_spread=0.05), 3, 4, duration=2.0, vehicle="iris", scheduler="none"
    )
    assert list(table.index) == ["se3", "nlpd"] and (table["flights"] == 3).all()


def quadcruise(*args, cwd):
    return subprocess.run(
        [sys.executable, "-m", "quadcruise", *map(str, args)], capture_output=True, text=True, cwd=cwd, timeout=600
    )


def test_the_command_line_sweeps_iris_on_dask_and_its_scenario_replays_it(tmp_path):
    common = ("--mission", "hover", "--controller", "nlpd", "--quiet")
    first = quadcruise(
        "montecarlo", "--vehicle", "iris", "-n", "4", "--duration", "2", "--mass-spread", "0.1",
        "--bandwidth-spread", "0.1", "--aero-spread", "0.2", "--scheduler", "local", "--workers", "1",
        "--out", "a", *common, cwd=tmp_path,
    )  # fmt: skip
    assert first.returncode == 0, first.stderr
    assert "4 flights of nlpd on hover" in first.stdout
    again = quadcruise("montecarlo", "--scenario", "a/scenario.toml", "--scheduler", "none", "--out", "b", cwd=tmp_path)
    assert again.returncode == 0, again.stderr
    a, b = (pd.read_csv(tmp_path / d / "flights.csv") for d in "ab")
    pd.testing.assert_frame_equal(a, b)
    assert len(a) == 4 and a["omega"].nunique() == 4  # the motors' bandwidths were drawn
    assert "rotor-speed plant" in (tmp_path / "a" / "report.md").read_text()


def test_the_command_line_compares_controllers_on_a_population_of_iris(tmp_path):
    proc = quadcruise(
        "compare", "hover", "--vehicle", "iris", "--controllers", "se3,cascade", "--population", "3",
        "--mass-spread", "0.05", "--duration", "2", cwd=tmp_path,
    )  # fmt: skip
    assert proc.returncode == 0, proc.stderr
    table = proc.stdout.split("the same 3 perturbed vehicles")[1].splitlines()
    assert [ln.split()[:2] for ln in table[2:4]] == [["se3", "3"], ["cascade", "3"]]


def test_every_command_gives_a_named_controller_the_gains_fly_designs_for_the_rotor_vehicle(tmp_path):
    designed = qc.fly("hover", "se3", vehicle="iris", duration=0.1).meta["controller"]["attitude"]
    assert designed["kp"] != SE3().attitude.kp  # not the paper's defaults
    proc = quadcruise("fly", "hover", "--vehicle", "iris", "--controller", "se3", "--duration", "0.1", "--out", "f",
                      cwd=tmp_path)  # fmt: skip
    assert proc.returncode == 0, proc.stderr
    text = (tmp_path / "f" / "scenario.toml").read_text()
    assert f"[controller.attitude]\nkp = {designed['kp']}\n" in text


@pytest.mark.parametrize(
    "args, words",
    [
        (["montecarlo", "--vehicle", "iris,K=2", "-n", "2"], "unknown key 'K'"),
        (["montecarlo", "--aero-spread", "0.1", "-n", "2"], "'aero_spread'"),
        (["tune", "step", "--vehicle", "iris,K=2", "--minimize", "rmse_m"], "unknown key 'K'"),
        (["compare", "hover", "--vehicle", "iris,omega=20", "--population", "3"], "unknown key 'omega'"),
    ],
)
def test_bad_input_on_a_rotor_sweep_is_one_line_exit_2(tmp_path, args, words):
    proc = quadcruise(*args, "--duration", "1", cwd=tmp_path)
    assert proc.returncode == 2, proc.stderr
    errors = [ln for ln in proc.stderr.splitlines() if ln.startswith("error: ")]
    assert len(errors) == 1 and words in errors[0] and "Traceback" not in proc.stderr, proc.stderr
    assert not proc.stdout.strip()


def test_the_library_refuses_what_a_rotor_sweep_cannot_fly_before_any_flight():
    with pytest.raises(InputError, match="'full_dynamics': not for a rotor-plant vehicle"):
        MonteCarloSpec("hover", "se3", Population(offset=0.1), vehicle="iris", full_dynamics=True)
    with pytest.raises(InputError, match="aerodynamics"):
        MonteCarloSpec("hover", "se3", Population(wind_spread=1.0), vehicle=RotorVehicle.preset("iris").without_aero())
    with pytest.raises(InputError, match="'aero_spread'"):
        MonteCarloSpec("hover", "se3", Population(aero_spread=0.1))
    with pytest.raises(InputError, match="of one plant"):
        MonteCarloSpec("hover", "se3", vehicle="iris", controller_vehicle=qc.Vehicle.paper())
