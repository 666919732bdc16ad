"""The issue's 500-flight check of the filter in the loop (issue 35): a Monte Carlo of vehicles
flying on the EKF's estimate, its run-averaged NEES of position, velocity and attitude and its
innovations' NIS against the chi-square 95 % bounds of a 500-run average (computed here with
scipy's chi2 through ``estimation.average_bounds``), at each logged instant; the sweep's own
summary says the same; a filter told a third of its sensors' noise is caught (both directions).
``benchmarks/ekf_consistency_loop.py`` runs it and draws the figure."""

from __future__ import annotations

import warnings

import numpy as np
import pytest

import quadcruise as qc
from quadcruise.estimation import Ekf, Sensors, average_bounds
from quadcruise.estimation.stage import PRESETS
from quadcruise.sensors import Gps

RUNS = 500
DOF = {"nees_pos": 3, "nees_vel": 3, "nees_att": 3, "nis_gps_pos": 3, "nis_gps_vel": 3, "nis_baro": 1, "nis_mag": 1}
SENSORS = Sensors(
    imu=PRESETS["imu"]["typical"], gps=Gps(rate=10.0, latency=0.0), baro=PRESETS["baro"]["typical"],
    mag=PRESETS["mag"]["typical"],
)  # fmt: skip
"""The typical sensors with the GPS on time (the filter does not compensate a latency)."""
FLIGHT = {"duration": 10.0, "seed": 11, "full_dynamics": True}


def batch(runs: int = RUNS, noise_scale: float = 1.0):
    """``runs`` vehicles flown as one batch on the filter's estimate, logged every 20 ms."""
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        return qc.fly(
            "circle", "nlpd", sensors=SENSORS, estimator=Ekf(noise_scale=noise_scale), n=runs, log_every=20, **FLIGHT
        )


def run_averages(result) -> dict:
    """Each quantity's average over the runs at each logged instant (a NIS: its last update's,
    refused or not), from the second logged instant on (the first is the filter's start)."""
    out = {}
    for name in DOF:
        v = np.abs(result.state(name)[:, 1:])
        out[name] = np.nanmean(v, axis=0) if np.isfinite(v).any() else v[0]
    return out


def sweep(runs: int = RUNS, noise_scale: float = 1.0):
    """The same vehicles as a Monte Carlo sweep (its table and summary)."""
    from quadcruise.montecarlo import Population, montecarlo

    pop = Population(sensors=SENSORS, estimator=Ekf(noise_scale=noise_scale))
    return montecarlo("circle", "nlpd", pop, runs, FLIGHT["seed"], duration=FLIGHT["duration"],
                      full_dynamics=True, scheduler="none")  # fmt: skip


@pytest.mark.slow
def test_500_flights_on_the_filter_are_consistent():
    r = batch()
    assert r.ok.all()
    for name, v in run_averages(r).items():
        lo, hi = average_bounds(DOF[name], RUNS)
        v = v[np.isfinite(v)]
        assert lo < v.mean() < hi, (name, v.mean(), lo, hi)
        assert np.mean((v > lo) & (v < hi)) > 0.8, (name, np.mean((v > lo) & (v < hi)))
    summary = sweep().summary_data()
    assert summary["failures"]["count"] == 0
    for name, c in summary["consistency"].items():  # the sweep's verdict on its per-flight means
        assert c["flights"] == RUNS and c["inside"], (name, c)


@pytest.mark.slow
def test_an_overconfident_filter_leaves_the_bounds():
    runs = 100
    r = batch(runs, noise_scale=1.0 / 3.0)
    for name in ("nees_pos", "nees_vel", "nees_att"):
        assert run_averages(r)[name].mean() > average_bounds(3, runs)[1], name
    swept = sweep(runs, noise_scale=1.0 / 3.0)
    assert not any(c["inside"] for c in swept.summary_data()["consistency"].values())
    assert "above (overconfident)" in swept.summary_text()
