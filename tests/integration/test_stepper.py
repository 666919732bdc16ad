"""The step-wise engine against a whole flight: `fly` flown period by period through
`Stepper` is `fly` (to 1e-12; in fact bit for bit), with turbulence, gusts, sensor noise and
a sensor delay; a vehicle reset alone leaves the others as they were; seeds reproduce and do
not depend on the number of vehicles."""

import warnings

import numpy as np
import pytest

import quadcruise as qc
from quadcruise.disturbances import Environment, Gust, SensorNoise, Turbulence, with_drag
from quadcruise.errors import InputError
from quadcruise.model.vehicle import Vehicle
from quadcruise.sim.status import ExitStatus
from quadcruise.workflows.stepwise import stepper

DUR = 0.4
pytestmark = pytest.mark.filterwarnings("ignore:the vehicle has no drag")


def _kw(n=3, **more):
    return dict(
        vehicle=with_drag(Vehicle.paper()),
        duration=DUR,
        dt=2e-3,
        max_step=1e-3,
        n=n,
        seed=7,
        environment=Environment(
            gust=Gust(amplitude=(2.0, 0.0, 0.5), start=0.1, duration=0.2), turbulence=Turbulence(intensity="severe")
        ),
        sensors=SensorNoise(position_std=0.02, angle_std=0.01, rate_std=0.05, delay=0.006),
        **more,
    )


def _flown(s):
    states, cmds, refs = [s.state.copy()], [], []
    while not s.done.all():
        s.step()
        rows = s.periods + 1
        for r in range(rows):
            if np.isfinite(s.log_cmd[:, r, 0]).any():
                cmds.append(s.log_cmd[:, r].copy())
                refs.append(s.log_ref[:, r].copy())
        states.append(s.state.copy())
    return np.stack(states, axis=1), np.stack(cmds, axis=1), np.stack(refs, axis=1)


@pytest.mark.parametrize("controller", ["nlpd", "cascade"])
def test_fly_step_by_step_is_fly(controller):
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        whole = qc.fly("circle", controller, **_kw())
    s = stepper("circle", controller, **_kw())
    states, cmds, refs = _flown(s)
    assert states.shape == whole.states.shape
    np.testing.assert_allclose(states, whole.states, rtol=0, atol=1e-12)
    np.testing.assert_allclose(cmds, whole.commands, rtol=0, atol=1e-12)
    np.testing.assert_allclose(refs, whole.references, rtol=0, atol=1e-12)
    np.testing.assert_allclose(s.memory, whole.memory, rtol=0, atol=1e-12)
    np.testing.assert_allclose(s.disturbance_memory, whole.disturbance_memory, rtol=0, atol=1e-12)
    np.testing.assert_allclose(s.saturated[:, 0], whole.duty_clipped_s, rtol=0, atol=1e-12)
    # the noise and turbulence did act: vehicles flown with other streams fly elsewhere
    assert np.abs(states[0, -1, :3] - states[1, -1, :3]).max() > 1e-6


def test_steps_of_several_periods_fly_the_same():
    one = stepper("circle", "nlpd", **_kw())
    many = stepper("circle", "nlpd", **_kw(periods=7))  # 200 periods: 28 steps of 7, then 4
    while not one.done.all():
        one.step()
    while not many.done.all():
        many.step()
    assert np.array_equal(one.state, many.state) and np.array_equal(one.memory, many.memory)
    assert many.period.tolist() == [round(DUR / 2e-3)] * 3


def test_a_vehicle_reset_alone_leaves_the_others():
    a, b = stepper("circle", "nlpd", **_kw()), stepper("circle", "nlpd", **_kw())
    first = []
    for _ in range(60):
        a.step()
        b.step()
        first.append(b.state[1].copy())
    a.reset(np.array([False, True, False]))
    assert a.period.tolist() == [60, 0, 60]
    for k in range(60):
        a.step()
        b.step()
        assert np.array_equal(a.state[1], first[k])  # vehicle 1 flies its start again
    assert np.array_equal(a.state[[0, 2]], b.state[[0, 2]])  # the others never noticed
    assert not np.array_equal(a.state[1], b.state[1])


def test_seeds_reproduce_and_do_not_depend_on_n():
    four = stepper("circle", "nlpd", **_kw(n=4))
    two = stepper("circle", "nlpd", **_kw(n=2, first_vehicle=2))
    for _ in range(50):
        four.step()
        two.step()
    assert np.array_equal(four.state[2:], two.state)
    four.reset()
    again = stepper("circle", "nlpd", **_kw(n=4))
    other = stepper("circle", "nlpd", **_kw(n=4))
    other.reset(seed=8)
    for _ in range(50):
        four.step()
        again.step()
        other.step()
    assert np.array_equal(four.state, again.state)
    assert not np.array_equal(four.state, other.state)


def test_a_diverged_vehicle_stops_with_its_status_and_the_rest_fly_on():
    s = stepper("hover", "nlpd", duration=0.2, dt=2e-3, n=2, limits=qc.Limits(max_rate=4.0))
    x0 = s.state.copy()
    x0[0, 9] = 4.5  # vehicle 0 starts rolling faster than the bound
    s.reset(x0=x0)
    s.step()
    assert s.status.tolist() == [int(ExitStatus.RATE_BOUND), int(ExitStatus.FINISHED)]
    assert s.period.tolist() == [1, 1] and s.t_stop[0] == s.t_grid[1]
    stopped = s.state[0].copy()
    while not s.done.all():
        s.step()
    assert np.array_equal(s.state[0], stopped) and s.period.tolist() == [1, 100]
    assert s.status.tolist() == [int(ExitStatus.RATE_BOUND), int(ExitStatus.FINISHED)]
    assert np.isnan(s.log_x[0]).all()  # a stopped vehicle logs nothing


def test_bad_arguments_are_one_clear_error():
    s = stepper("hover", "nlpd", duration=0.01, n=2)
    with pytest.raises(InputError, match="takes no commands"):
        s.step(np.zeros((2, 4)))
    with pytest.raises(InputError, match=r"mask must be a \(2,\) bool"):
        s.reset(np.array([1, 0]))
    with pytest.raises(InputError, match="x0 must be finite"):
        s.reset(x0=np.full(16, np.nan))
