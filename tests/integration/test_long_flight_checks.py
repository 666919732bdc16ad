"""Issue 31, items 2 and 3: a batch over the log budget keeps a fixed number of figures per
vehicle for its track checks (not a record of every period), on either plant, and still gives
the statuses and times of the whole log (``log_every=1``, judged by ``fly_failures``); the head
of a vehicle whose verdict those figures leave open is flown again, and flying every vehicle's
head again gives the same answer; ``x0`` and a sweep's ``--offset`` start a rotor-plant vehicle."""

from __future__ import annotations

import warnings

import numpy as np
import pytest

import quadcruise as qc
from quadcruise.disturbances import Environment, RotorLoss
from quadcruise.errors import InputError
from quadcruise.layout import PHI, PSI, THETA
from quadcruise.model.equivalent import paper_equivalent
from quadcruise.model.rotor_vehicle import RotorVehicle
from quadcruise.montecarlo import MonteCarloSpec, Population
from quadcruise.montecarlo.chunk import montecarlo_case
from quadcruise.sim.status import ExitStatus
from quadcruise.workflows import fly as fly_module
from quadcruise.workflows import fly_inputs, track_watch
from quadcruise.workflows.fly_inputs import hover_state

FIN, LOST, OFF = int(ExitStatus.FINISHED), int(ExitStatus.LOST_TRACK), int(ExitStatus.OFF_TRACK)


def quiet(*args, **kwargs):
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        return qc.fly(*args, **kwargs)


class Spy:
    """Counts the vehicles whose head ``fly`` flies again."""

    def __init__(self, monkeypatch):
        self.vehicles = 0
        real = fly_module.watch_again

        def spy(*args, vehicles, **kwargs):
            self.vehicles += int(np.count_nonzero(vehicles))
            return real(*args, vehicles=vehicles, **kwargs)

        monkeypatch.setattr(fly_module, "watch_again", spy)


def whole_and_watched(monkeypatch, *args, **kwargs):
    """The flight with its whole log (judged on it) and as a batch over a tiny log budget."""
    whole = quiet(*args, log_every=1, **kwargs)
    with monkeypatch.context() as m:
        m.setattr(fly_inputs, "LOG_BUDGET", 1)
        spy = Spy(m)
        watched = quiet(*args, **kwargs)
    every = watched.meta["log_every"]
    assert every > 1
    assert np.array_equal(whole.states[:, ::every], watched.states, equal_nan=True)
    return whole, watched, spy.vehicles


def same_verdict(a, b):
    assert a.status.tolist() == b.status.tolist()
    assert np.array_equal(a.t_stop, b.t_stop, equal_nan=True)


def every_head_again(monkeypatch):
    """Make every live vehicle's head be flown again (the kept figures decide nothing)."""
    monkeypatch.setattr(
        track_watch, "_moving_summary", lambda live, *rest: np.full(live.shape[0], track_watch.AMBIGUOUS)
    )


LOSSES = Environment(  # from 1 s to 11 s, ever smaller
    rotor_loss=RotorLoss(
        rotor=3, fraction=np.array([0.6, 0.7, 0.8, 0.5, 0.45, 0.4, 0.35, 0.3]), time=np.linspace(1, 11, 8)
    )
)


def test_a_long_circle_losing_track_at_many_times_judged_as_its_whole_log(monkeypatch):
    whole, watched, again = whole_and_watched(monkeypatch, "circle", environment=LOSSES, duration=14.0, n=8)
    same_verdict(whole, watched)
    status = whole.status.tolist()
    assert LOST in status and OFF in status and FIN in status, status  # both directions
    stops = whole.t_stop[np.asarray(status) != FIN]
    assert len(set(np.round(stops, 3))) >= 6  # at many different times
    with monkeypatch.context() as m:
        every_head_again(m)
        _, forced, _ = whole_and_watched(m, "circle", environment=LOSSES, duration=14.0, n=8)
    same_verdict(whole, forced)


def test_vehicles_that_fly_well_are_judged_from_the_kept_figures_alone(monkeypatch):
    masses = qc.Vehicle.paper().m * np.linspace(0.9, 1.3, 4)
    whole, watched, again = whole_and_watched(monkeypatch, "circle", vehicle=qc.Vehicle(m=masses), duration=12.0)
    same_verdict(whole, watched)
    assert whole.status.tolist() == [FIN] * 4 and again == 0


def test_steady_bounds_near_the_error_judged_from_the_head_flown_again(monkeypatch):
    # bounds about the circle's error where its transient ends (0.06-0.16 m from starts 0-2 m
    # away): beyond them now and then to the end, so the kept figures cannot place the
    # transient's end and the head is flown again
    x0 = hover_state(qc.Vehicle.paper(), 4, qc.missions.Circle())
    x0[:, 0], x0[:, 1] = [0.0, 0.5, 1.0, 1.9], [0.0, 0.5, -0.3, 0.0]
    flown_again, verdicts = 0, set()
    for bound in (0.04, 0.1, 0.12, 0.15):
        kw = dict(duration=10.0, max_steady_error=bound, x0=x0)
        whole, watched, again = whole_and_watched(monkeypatch, "circle", **kw)
        same_verdict(whole, watched)
        flown_again += again
        verdicts |= {(s, round(t, 3)) for s, t in zip(whole.status.tolist(), whole.t_stop.tolist(), strict=True)}
        with monkeypatch.context() as m:
            every_head_again(m)
            same_verdict(whole, whole_and_watched(m, "circle", **kw)[1])
    assert flown_again > 0
    assert (FIN, 10.0) in verdicts and len({t for s, t in verdicts if s == OFF}) >= 4  # off at 4 times


def test_a_rotor_batch_over_the_budget_flies_the_watched_path_with_the_whole_logs_verdicts(monkeypatch):
    env = Environment(
        rotor_loss=RotorLoss(rotor=1, fraction=np.array([0.9, 0.5, 0.0, 0.3]), time=np.array([1.0, 3.0, 1.0, 5.0]))
    )
    kw = dict(vehicle="iris", environment=env, duration=8.0, n=4)
    whole, watched, _ = whole_and_watched(monkeypatch, "circle", "se3", **kw)
    same_verdict(whole, watched)
    every = watched.meta["log_every"]
    assert np.array_equal(whole.rotor_states[:, ::every], watched.rotor_states, equal_nan=True)
    assert np.array_equal(whole.rotor_final_state, watched.rotor_final_state)
    assert np.array_equal(whole.final_state, watched.final_state)
    assert watched.rotor_names == whole.rotor_names and "paper_equivalent" in watched.meta
    status = whole.status.tolist()
    assert status[2] == FIN and len(set(status)) > 1, status
    with monkeypatch.context() as m:
        every_head_again(m)
        same_verdict(whole, whole_and_watched(m, "circle", "se3", **kw)[1])


def test_x0_starts_a_rotor_vehicle_where_it_says():
    iris = RotorVehicle.preset("iris")
    x0 = hover_state(paper_equivalent(iris), 3, qc.missions.Hover())
    default = quiet("hover", "se3", vehicle="iris", duration=0.5, n=3)
    same = quiet("hover", "se3", vehicle="iris", duration=0.5, x0=x0)
    assert np.array_equal(default.rotor_states, same.rotor_states)  # the hover thrusts: its hover, exactly
    x0[:, 0] = [0.0, 0.3, -0.5]
    x0[1, [PHI, THETA, PSI]] = [0.1, -0.2, 0.4]
    moved = quiet("hover", "se3", vehicle="iris", duration=0.5, x0=x0)
    start = moved.rotor_states[:, 0]
    assert start[:, 0].tolist() == [0.0, 0.3, -0.5]
    np.testing.assert_allclose(np.linalg.norm(start[:, 6:10], axis=1), 1.0, rtol=1e-15)
    # the kernel's own quaternion -> Euler (atan2/asin) reads back the angles given
    np.testing.assert_allclose(moved.states[1, 0, [PHI, THETA, PSI]], [0.1, -0.2, 0.4], atol=1e-14)
    assert moved.status_text(1) == "finished"  # it levels and holds
    fleet = [iris, iris.replace(m=iris.m * 1.2), iris]  # one vehicle each: each its own hover
    starts = np.concatenate([hover_state(paper_equivalent(v), 1, qc.missions.Hover()) for v in fleet])
    mixed = quiet("hover", "se3", vehicle=fleet, duration=0.1, x0=starts)
    assert [float(w) for w in mixed.rotor_states[:, 0, 13]] == [v.hover_speed for v in fleet]
    thrust = x0[2].copy()
    thrust[12:] = [2.0, 4.0, 4.0, 4.0]  # a four-rotor vehicle: each rotor's speed from its thrust
    spun = quiet("hover", "se3", vehicle="iris", duration=0.1, x0=thrust)
    np.testing.assert_allclose(spun.rotor_states[0, 0, 13:], np.sqrt(np.array([2.0, 4.0, 4.0, 4.0]) / iris.kf))


def test_x0_that_cannot_set_a_rotor_vehicle_is_one_line():
    a = np.radians(np.arange(6) * 60.0 + 30.0)
    hexa = RotorVehicle.preset("iris").replace(
        rotors=[[0.25 * np.cos(t), 0.25 * np.sin(t), 0.02, (-1) ** k] for k, t in enumerate(a)], m=2.0
    )
    x0 = hover_state(paper_equivalent(hexa), 1, qc.missions.Hover())[0]
    quiet("hover", "se3", vehicle=hexa, duration=0.1, x0=x0)  # its hover: fine
    x0[12] *= 1.1
    with pytest.raises(InputError, match=r"x0, row 0: .*6-rotor vehicle .*four rotors") as got:
        quiet("hover", "se3", vehicle=hexa, duration=0.1, x0=x0)
    assert "\n" not in str(got.value)
    x0 = hover_state(paper_equivalent(RotorVehicle.preset("iris")), 1, qc.missions.Hover())[0]
    x0[13] = -1.0
    with pytest.raises(InputError, match=r"x0, row 0: .*>= 0 N"):
        quiet("hover", "se3", vehicle="iris", duration=0.1, x0=x0)


def test_a_rotor_sweep_with_a_start_offset():
    spec = MonteCarloSpec("hover", "se3", population=Population(offset=0.2), vehicle="iris", seed=3, duration=0.5)
    case = montecarlo_case(spec, 7)
    assert case.row["dx0"] != 0.0 and case.row["dx0"] == float(case.result.rotor_states[0, 0, 0])
    assert case.row["dy0"] == float(case.result.states[0, 0, 1])
