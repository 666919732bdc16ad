"""The track checks made inside the kernels (issue 31, the watched path's speed): a flight with
any ``log_every`` flies the plain kernel path, whose running figures per vehicle
(``sim.track_figures``) give the statuses and times that ``fly_failures`` reads off the whole log
(``log_every=1``), on both plants, for flights that lose track or go off it and for flights that
do not, single and batched, at several ``log_every``; the figures are carried from one kernel
call to the next, so a flight cut into ``Stepper`` calls has the figures of one call, bit for bit;
and the checks change nothing of the flight itself."""

from __future__ import annotations

import warnings

import numpy as np
import pytest

import quadcruise as qc
from quadcruise.control import NLPD
from quadcruise.disturbances import Environment, RotorLoss
from quadcruise.errors import InputError
from quadcruise.missions import Circle, Step
from quadcruise.model.rotor_vehicle import RotorVehicle
from quadcruise.sim.chunked import watch_again
from quadcruise.sim.engine import simulate
from quadcruise.sim.inputs import Limits, time_grid
from quadcruise.sim.rotor_batch import fly_rotor_vehicles
from quadcruise.sim.status import ExitStatus
from quadcruise.sim.stepper import Stepper
from quadcruise.sim.track_figures import TRACK, fresh_track, no_track, track_plan
from quadcruise.workflows.fly_inputs import engine_inputs, hover_state
from quadcruise.workflows.rotor_fly import flight_setup, rotor_engine_inputs
from quadcruise.workflows.track_watch import TrackWatch

FIN, LOST, OFF = int(ExitStatus.FINISHED), int(ExitStatus.LOST_TRACK), int(ExitStatus.OFF_TRACK)


def quiet(*args, **kwargs):
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        return qc.fly(*args, **kwargs)


def same_verdict(whole, coarse, every):
    assert coarse.meta["log_every"] == every
    assert whole.status.tolist() == coarse.status.tolist(), every
    assert np.array_equal(whole.t_stop, coarse.t_stop), every


PAPER_LOSSES = Environment(  # rotor 3 loses ever less from 1 s to 11 s: lost, off, and fine
    rotor_loss=RotorLoss(
        rotor=3, fraction=np.array([0.6, 0.7, 0.8, 0.5, 0.45, 0.4, 0.35, 0.3]), time=np.linspace(1, 11, 8)
    )
)


@pytest.mark.parametrize("every", [2, 7, 1000, 14_000])
def test_a_paper_batch_judged_by_the_kernel_as_by_its_whole_log(every):
    kw = dict(environment=PAPER_LOSSES, duration=14.0, n=8)
    whole = quiet("circle", log_every=1, **kw)
    status = whole.status.tolist()
    assert LOST in status and OFF in status and FIN in status, status  # both directions
    same_verdict(whole, quiet("circle", log_every=every, **kw), every)


def test_single_paper_flights_at_several_log_every():
    seen = set()
    for fraction, time in ((0.6, 1.0), (0.3, 2.0), (0.0, 1.0)):
        env = Environment(rotor_loss=RotorLoss(rotor=3, fraction=fraction, time=time))
        kw = dict(environment=env, duration=6.0)
        whole = quiet("circle", log_every=1, **kw)
        seen.add(int(whole.status[0]))
        for every in (3, 40, 6000):
            same_verdict(whole, quiet("circle", log_every=every, **kw), every)
    assert FIN in seen and len(seen) > 1, seen


@pytest.mark.parametrize("every", [16, 1000])
def test_a_rotor_batch_and_its_single_flights_judged_as_their_whole_logs(every):
    env = Environment(
        rotor_loss=RotorLoss(rotor=1, fraction=np.array([0.9, 0.5, 0.0, 0.3]), time=np.array([1.0, 3.0, 1.0, 5.0]))
    )
    kw = dict(vehicle="iris", duration=8.0)
    whole = quiet("circle", "se3", environment=env, n=4, log_every=1, **kw)
    status = whole.status.tolist()
    assert FIN in status and len(set(status)) > 1, status
    same_verdict(whole, quiet("circle", "se3", environment=env, n=4, log_every=every, **kw), every)
    for i in (0, 2):  # one vehicle alone: a loss that ends it, and none
        alone = Environment(rotor_loss=RotorLoss(rotor=1, fraction=[0.9, 0.0][i // 2], time=1.0))
        single = quiet("circle", "se3", environment=alone, log_every=every, **kw)
        assert single.status.tolist() == [status[i]] and single.t_stop[0] == whole.t_stop[i]


def test_a_step_and_a_still_reference_judged_by_the_kernel():
    # a step (its response interpolated at the step's instant, on the grid or between two
    # instants) with a bound it settles within and one it does not, and a hover started away
    for step in (Step(size=1.0, time=0.5), Step(size=1.0, time=0.5003)):
        times = set()
        for bound in (None, 0.03):
            kw = dict(n=2, duration=12.0, max_steady_error=bound)
            whole = quiet(step, log_every=1, **kw)
            assert whole.status.tolist() == ([FIN, FIN] if bound is None else [OFF, OFF])
            times.add(float(whole.t_stop[0]))
            for every in (5, 500):
                same_verdict(whole, quiet(step, log_every=every, **kw), every)
        assert len(times) == 2 and min(times) > 0.5  # off from a time after the step, not its start
    x0 = hover_state(qc.Vehicle.paper(), 4, qc.missions.Hover())
    x0[:, 0] = [0.0, 0.5, 3.0, 8.0]
    for bound in (0.001, 0.05):
        kw = dict(x0=x0, duration=10.0, max_steady_error=bound)
        whole = quiet("hover", log_every=1, **kw)
        assert whole.status[0] == FIN and whole.status[-1] == OFF
        for every in (4, 100):
            same_verdict(whole, quiet("hover", log_every=every, **kw), every)


def flight(n=12):
    """Vehicles started ever closer to a tight position bound (stops at many periods), on a circle."""
    v, c, m = qc.Vehicle.paper(), NLPD(), Circle()
    t = time_grid(1.0, 1e-3)
    x0 = hover_state(v, n, m)
    x0[:, 0] = np.linspace(1.0, 2.49, n)
    x0[:, 3] = np.linspace(1.0, 6.0, n)  # moving outwards
    args = (t, x0, v.rows(n), c.function, c.gains(), m.function, m.params())
    return t, args, dict(memory=c.memory(), limits=Limits(max_position=2.5))


def test_the_figures_of_a_flight_cut_into_steps_are_those_of_one_call():
    n = 12
    t, args, opts = flight(n)
    bounds = np.linspace(0.3, 3.0, n)
    plan = track_plan(t)
    rows = fresh_track(n, bounds, 0.2, 0.1, plan)
    whole = simulate(*args, log_every=5, track=(rows, plan), **opts)
    plain = simulate(*args, log_every=5, **opts)  # the checks change nothing of the flight
    for name in ("states", "commands", "references", "final_state", "status", "t_stop", "memory"):
        assert np.array_equal(getattr(whole, name), getattr(plain, name), equal_nan=True), name
    assert len(set(whole.t_stop.round(6))) > 4  # stops at many instants
    assert (rows[:, 0] >= 0).any() and (rows[:, 0] < 0).any()  # lost track: some, not all
    for periods in (1, 7, 64):
        cut = fresh_track(n, bounds, 0.2, 0.1, plan)
        s = Stepper(*args, periods=periods, track=(cut, plan), **opts)
        while not s.done.all():
            s.step()
        assert np.array_equal(rows, s.track, equal_nan=True), periods
        assert s.status.tolist() == whole.status.tolist()
    s.reset()  # fresh figures again, and the same flight
    assert np.array_equal(s.track, fresh_track(n, bounds, 0.2, 0.1, plan), equal_nan=True)
    while not s.done.all():
        s.step()
    assert np.array_equal(rows, s.track, equal_nan=True)


def test_the_rotor_kernels_figures_cut_into_steps_are_those_of_one_call():
    n, iris = 4, RotorVehicle.preset("iris")
    c, m = flight_setup(iris, None, "se3")[1], Circle()
    t = time_grid(2.0, 1e-3)
    env = Environment(rotor_loss=RotorLoss(rotor=1, fraction=np.array([0.9, 0.0, 0.5, 0.0]), time=0.5))
    engine = engine_inputs(env, None, n, 1e-3)
    (grid, x0, rp, function, gains, mission, mp), plant = rotor_engine_inputs(
        t, iris, None, c.function, c.gains(), m, m.params(), n
    )
    names = plant.pop("rotor_names")
    plan = track_plan(t)
    lost_at = np.array([0.5, 10.0, 0.5, 10.0])  # from the start (2 m off the circle), never
    rows = fresh_track(n, lost_at, 0.2, 0.1, plan)
    whole = fly_rotor_vehicles(
        grid, x0, rp, plant.pop("alloc"), plant.pop("vp_ctrl"), function, gains, mission, mp,
        memory=c.memory(), rotor_names=names, track=(rows, plan), **plant, **engine,
    )  # fmt: skip
    assert (rows[:, 0] >= 0).any() and (rows[:, 0] < 0).any()  # lost track: some, not all
    (grid, x0, rp, function, gains, mission, mp), plant = rotor_engine_inputs(
        t, iris, None, c.function, c.gains(), m, m.params(), n
    )
    plant.pop("rotor_names")
    for periods in (1, 37):
        cut = fresh_track(n, lost_at, 0.2, 0.1, plan)
        s = Stepper(grid, x0, rp, function, gains, mission, mp, memory=c.memory(), periods=periods,
                    track=(cut, plan), **plant, **engine)  # fmt: skip
        while not s.done.all():
            s.step()
        assert np.array_equal(rows, cut, equal_nan=True), periods
        assert s.status.tolist() == whole.status.tolist()


def test_the_verdict_of_stepped_figures_is_the_whole_logs():
    # a circle batch whose figures come from a Stepper of 13 periods a call: TrackWatch's verdict
    # equals fly_failures' on the whole log (bounds near the error where the transient ends: the
    # head of some vehicles is flown again)
    x0 = hover_state(qc.Vehicle.paper(), 4, Circle())
    x0[:, 0], x0[:, 1] = [0.0, 0.5, 1.0, 1.9], [0.0, 0.5, -0.3, 0.0]
    kw = dict(duration=10.0, x0=x0, max_steady_error=0.12)
    whole = quiet("circle", log_every=1, **kw)
    v, c, m = qc.Vehicle.paper(), NLPD(), Circle()
    t = time_grid(10.0, 1e-3)
    watch = TrackWatch(
        t, m.to_dict(), whole.meta["max_track_error_m"], whole.meta["max_steady_error_m"],
        whole.meta["max_altitude_error_m"],
    )  # fmt: skip
    args = (t, x0, v.rows(4), c.function, c.gains(), m.function, m.params())
    s = Stepper(*args, memory=c.memory(), periods=13, track=watch.arrays)
    while not s.done.all():
        s.step()

    def again(vehicles, periods, feed):
        watch_again(*args, vehicles=vehicles, periods=periods, watch=feed, memory=c.memory())

    status, t_stop = watch.verdict(s.status, s.t_stop, again)
    assert status.tolist() == whole.status.tolist() and np.array_equal(t_stop, whole.t_stop)
    assert OFF in status.tolist() and FIN in status.tolist(), status


def test_track_arrays_of_the_wrong_shape_are_refused():
    t, args, opts = flight(3)
    plan = track_plan(t)
    with pytest.raises(InputError, match=r"track: \(rows, plan\) must be \(3, "):
        simulate(*args, track=(np.zeros((3, TRACK.size - 1)), plan), **opts)
    with pytest.raises(InputError, match="track"):
        Stepper(*args, track=(fresh_track(2, 1.0), plan), **opts)
    rows, off = no_track(3)  # checks off: rows of no width, untouched
    simulate(*args, track=(rows, off), **opts)
    assert rows.shape == (3, 0)


def test_checks_turned_off_leave_the_engines_statuses():
    # every bound infinite: no check, at any log_every (the kernel passes over them)
    env = Environment(rotor_loss=RotorLoss(rotor=3, fraction=0.6, time=1.0))
    kw = dict(environment=env, duration=6.0, max_track_error=np.inf, max_steady_error=np.inf)
    on = quiet("circle", log_every=1, environment=env, duration=6.0)
    assert on.status.tolist() != [FIN]  # with the checks, it does not finish well
    for every in (1, 3, 6000):
        off = quiet("circle", log_every=every, **kw)
        assert off.status.tolist() == [FIN] and off.t_stop.tolist() == [6.0]
    watch = TrackWatch(time_grid(1.0, 1e-3), {}, np.full(2, np.inf), np.full(2, np.inf), np.full(2, np.inf))
    assert watch.plan[0] == 0.0
