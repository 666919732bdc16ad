"""Regression test: reference flights against values recorded before the package was split into
layers (``tests/support/reference_flights.npz``, recorded at commit ff599ce with the flat layout's
API). The move and the API of objects change no number: traces and metrics agree to rounding.

These are our own earlier numbers, so this test guards against *change*, not against error; the
physics is checked against independent paths (solve_ivp, python-control, closed forms) elsewhere.
"""

from __future__ import annotations

import warnings
from pathlib import Path

import numpy as np
import pytest

import quadcruise as qc
from quadcruise.control import NLPD
from quadcruise.disturbances import ConstantWind, Environment, Gust, RotorLoss, SensorNoise, Turbulence, with_drag
from quadcruise.montecarlo import Population, montecarlo
from quadcruise.sim.status import ExitStatus

REFERENCE = np.load(Path(__file__).parents[1] / "support" / "reference_flights.npz")
TOL = dict(rtol=1e-9, atol=1e-9)
# Columns whose meaning was changed on purpose since the recording (issue 16, "Metrics that show
# the tracking"): ``effort`` is now measured about the hover duty, not from zero duty, and a
# Monte Carlo flight whose transient did not settle is no longer a ``failure`` (failure codes
# are now diverged, lost track, saturated, failed a requirement). Every other column stays equal.
REDEFINED = {"effort", "failure"}
# Issue 21 ("metrics defined for what each mission is"): the transient and steady columns of a
# moving reference (circle, square) are now measured on the size of the 3-D tracking error
# against its own steady level, not on one axis's progress; those of a step are unchanged, and
# so is every trace.
MOVING = {"circle_nlpd", "square_gonzalez", "circle_env", "batch_mass", "mc"}
REDEFINED_MOVING = {
    "rise_time_s",
    "settling_time_s",
    "settling_time_5pct_s",
    "overshoot_pct",
    "peak_time_s",
    "steady_rmse_m",
    "steady_max_error_m",
    "not_settled",
    "transient_axis",
}


#: the paper's literal inversion, which the default nlpd was before the joint one (issue: the
#: controller at any yaw); the recorded flights used it
NLPD_SEQUENTIAL = NLPD(inversion="sequential")


def flights():
    env = Environment(
        wind=ConstantWind(velocity=(1.0, 0.5, 0.0)),
        turbulence=Turbulence(intensity="moderate"),
        rotor_loss=RotorLoss(rotor=1, fraction=0.2, time=4.0),
    )
    return {
        "circle_nlpd": lambda: qc.fly("circle", NLPD_SEQUENTIAL, log_every=10),
        "square_gonzalez": lambda: qc.fly("square", "gonzalez", duration=12.0, log_every=10),
        "step_se3": lambda: qc.fly("step", "se3", log_every=10),
        "step_cascade": lambda: qc.fly("step", "cascade", log_every=10),
        "step_full": lambda: qc.fly("step", NLPD_SEQUENTIAL, full_dynamics=True, log_every=10),
        "circle_env": lambda: qc.fly(
            "circle",
            NLPD_SEQUENTIAL,
            duration=8.0,
            vehicle=with_drag(qc.Vehicle.paper().replace(m=3.8)),
            controller_vehicle=qc.Vehicle.paper(),
            seed=7,
            log_every=10,
            environment=env,
            sensors=SensorNoise(position_std=0.01, angle_std=0.002, delay=0.004),
        ),
        "batch_mass": lambda: qc.fly(
            "circle", NLPD_SEQUENTIAL, vehicle=qc.Vehicle(m=np.linspace(2.5, 4.5, 6)), duration=5.0, log_every=50
        ),
        "gust_dt2": lambda: qc.fly(
            "step",
            NLPD_SEQUENTIAL,
            dt=2e-3,
            vehicle=with_drag(qc.Vehicle.paper()),
            duration=6.0,
            log_every=5,
            environment=Environment(gust=Gust(amplitude=(2.0, 0.0, 0.0), start=1.0, duration=1.0)),
        ),
    }


@pytest.mark.parametrize("name", sorted(flights()))
def test_flight_traces_and_metrics_are_unchanged(name):
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        res = flights()[name]()
    np.testing.assert_allclose(res.t, REFERENCE[f"{name}/t"], **TOL)
    np.testing.assert_allclose(res.states, REFERENCE[f"{name}/states"], **TOL)
    np.testing.assert_allclose(res.commands, REFERENCE[f"{name}/commands"], **TOL)
    metrics = res.metrics()
    for key in (k for k in REFERENCE.files if k.startswith(f"{name}/metric/")):
        column = key.rsplit("/", 1)[1]
        if column in REDEFINED or (name in MOVING and column in REDEFINED_MOVING):
            continue
        np.testing.assert_allclose(metrics[column].to_numpy(dtype=float), REFERENCE[key], err_msg=column, **TOL)


def test_replay_is_unchanged():
    states = qc.replay(qc.read_duty_csv(Path(__file__).parents[2] / "examples" / "pwm_step.csv"))
    np.testing.assert_allclose(states.states, REFERENCE["replay/states"], **TOL)


def test_montecarlo_table_is_unchanged():
    population = Population(mass_spread=0.1, environment=Environment(turbulence=Turbulence(intensity="light")))
    mc = montecarlo("circle", NLPD_SEQUENTIAL, population, n=16, seed=3, duration=4.0, scheduler="none")
    table = mc.to_pandas() if hasattr(mc, "to_pandas") else mc.table
    for key in (k for k in REFERENCE.files if k.startswith("mc/")):
        column = key.split("/", 1)[1]
        if column in REDEFINED | REDEFINED_MOVING:
            continue
        got = table[column].to_numpy(dtype=float)
        if column == "status":
            # Issue 33 ("one status for one flight"): a sweep's status is now fly's own, its track
            # verdict included; the flights are the same, so only a finished flight may have become
            # off or lost track, and the sweep then counts it as lost track
            verdict = np.isin(got, (int(ExitStatus.LOST_TRACK), int(ExitStatus.OFF_TRACK)))
            assert np.all(REFERENCE[key][verdict] == int(ExitStatus.FINISHED))
            assert np.all(table["reason"].to_numpy()[verdict] == "lost track")
            got = np.where(verdict, float(ExitStatus.FINISHED), got)
        np.testing.assert_allclose(got, REFERENCE[key], err_msg=column, **TOL)
