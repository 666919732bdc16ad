"""One vocabulary for results (docs/architecture.md): every result that holds flights answers
``metrics()`` with one row per flight, and ``to_pandas()`` is one row per logged sample for a
flight or a replay and one row per flight for a collection of flights."""

from __future__ import annotations

import numpy as np
import pandas as pd
import pytest

import quadcruise as qc
from quadcruise.metrics.flight import flight_metrics
from quadcruise.model.rotor_vehicle import RotorVehicle
from quadcruise.montecarlo import montecarlo
from quadcruise.montecarlo.schema import ESTIMATE_METRICS, METRICS
from quadcruise.tune import tune
from quadcruise.workflows.compare import compare
from quadcruise.workflows.replay import CommandSchedule, replay
from quadcruise.workflows.reproduce import reproduce

CF = RotorVehicle.preset("crazyflie")


def sim():
    res = qc.fly("step", n=2, duration=2.0, log_every=20)
    return res, {"flights": 2, "samples": 2 * len(res.t)}


def comparison():
    cmp = compare("step", ("nlpd", "se3"), duration=2.0, log_every=20)
    samples = sum(r.n * len(r.t) for r in cmp.results.values())
    return cmp, {"flights": 2, "samples": samples, "lead": ["controller", "vehicle", "t"]}


def sweep():
    return montecarlo("hover", n=3, seed=4, duration=1.0), {"flights": 3, "per_flight": True}


def reproduction():
    rep = reproduce(scenarios=("step",), controllers=("nlpd", "gonzalez"), dt=1e-2, fitted=False)
    return rep, {"flights": 2, "per_flight": True}


def tuned():
    res = tune("step", "nlpd", targets={"rise_time_s": 1.5}, gains="position.kp", bounds={"position.kp": (1.0, 10.0)},
               duration=3.0, budget=1, popsize=5, samples=3, seed=1)  # fmt: skip
    return res, {"flights": 3, "per_flight": True}


def rotor_replay():
    h = CF.hover_speed
    res = replay(CommandSchedule(t=[0.0, 0.5, 1.0], speeds=[[1.02 * h] * 4] * 3), vehicle=CF)
    return res, {"flights": None, "samples": len(res.t)}


@pytest.mark.parametrize("build", [sim, comparison, sweep, reproduction, tuned, rotor_replay])
def test_metrics_is_one_row_per_flight_and_to_pandas_per_sample_or_per_flight(build):
    result, want = build()
    frame = result.to_pandas()
    assert isinstance(frame, pd.DataFrame)
    if want["flights"] is None:  # an open-loop replay: no reference, so no metrics
        assert not hasattr(result, "metrics")
    else:
        table = result.metrics()
        assert isinstance(table, pd.DataFrame) and len(table) == want["flights"]
        assert {"rmse_m", "max_error_m"} <= set(table.columns)
        table["rmse_m"] = -1.0  # a copy: the result's own table is untouched
        assert (result.metrics()["rmse_m"] >= 0).all()
    if want.get("per_flight"):
        assert frame.equals(result.metrics())
    else:
        lead = want.get("lead", ["vehicle", "t"])
        assert len(frame) == want["samples"] and list(frame.columns[: len(lead)]) == lead


def test_sim_result_metrics_is_flight_metrics_and_to_pandas_its_traces():
    res, _ = sim()
    pd.testing.assert_frame_equal(res.metrics(), flight_metrics(res))
    frame = res.to_pandas()
    for i in range(res.n):
        np.testing.assert_array_equal(frame.loc[frame["vehicle"] == i, "x"], res.states[i, :, 0])


def test_comparison_metrics_rows_are_each_controller_flown_alone():
    cmp, _ = comparison()
    table = cmp.metrics()
    assert table.index.tolist() == ["nlpd", "se3"]
    for label in table.index:
        alone = qc.fly("step", controller=label, duration=2.0, log_every=20).metrics().iloc[0]
        assert table.loc[label, "rmse_m"] == pytest.approx(alone["rmse_m"], rel=1e-12)
    pd.testing.assert_frame_equal(cmp.table(), table)  # the old name


def test_montecarlo_metrics_rows_are_each_vehicle_flown_alone():
    mc, _ = sweep()
    table = mc.metrics()
    assert table["vehicle"].tolist() == [0, 1, 2]
    for i in range(3):
        alone = flight_metrics(mc.case(i, log_every=1).result).iloc[0]
        shared = [m for m in METRICS if m in alone.index]  # final_error_m is the sweep's own
        assert len(shared) == len([m for m in METRICS if m not in ESTIMATE_METRICS]) - 1  # flown on the truth
        for m in shared:
            assert table.loc[i, m] == pytest.approx(alone[m], rel=1e-6, abs=1e-12, nan_ok=True), (i, m)
    pd.testing.assert_frame_equal(mc.table, table)  # the old name


def test_rotor_replay_to_pandas_holds_the_log_and_one_vehicle():
    res, _ = rotor_replay()
    frame = res.to_pandas(0)
    assert list(frame.columns) == ["vehicle", "t", *res.names, "phi", "theta", "psi"]
    np.testing.assert_array_equal(frame[list(res.names)].to_numpy(), res.states[0])
    np.testing.assert_array_equal(frame[["phi", "theta", "psi"]].to_numpy(), res.euler(0))
    with pytest.raises(qc.InputError, match="vehicle 3 is not in this flight of 1"):
        res.to_pandas(3)
