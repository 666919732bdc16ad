"""The step-wise engine on the rotor-speed plant: a rotor-plant `fly` flown period by period
through `Stepper` is `fly` (to 1e-12; in fact bit for bit), with wind, gusts, turbulence, sensor
noise and a sensor delay; steps of several periods fly the same; a vehicle reset alone leaves
the others as they were; a vehicle that meets the ground too fast stops `crashed` while the
others fly on."""

import warnings

import numpy as np
import pytest

import quadcruise as qc
from quadcruise.disturbances import ConstantWind, Environment, Gust, RotorLoss, SensorNoise, Turbulence
from quadcruise.errors import InputError
from quadcruise.sim.status import ExitStatus
from quadcruise.workflows.stepwise import stepper

DUR = 0.4


def _kw(n=3, vehicle="crazyflie", **more):
    return dict(
        vehicle=vehicle,
        duration=DUR,
        dt=2e-3,
        max_step=1e-3,
        n=n,
        seed=7,
        environment=Environment(
            wind=ConstantWind((1.0, 0.5, 0.0)),
            gust=Gust(amplitude=(1.0, 0.0, 0.3), start=0.1, duration=0.2),
            turbulence=Turbulence(intensity="moderate"),
        ),
        sensors=SensorNoise(position_std=0.01, angle_std=0.01, rate_std=0.05, delay=0.006),
        **more,
    )


def _flown(s):
    paper, rotor, cmds = [s.paper_state.copy()], [s.state.copy()], []
    while not s.done.all():
        s.step()
        for r in range(s.periods + 1):
            if np.isfinite(s.log_cmd[:, r, 0]).any():
                cmds.append(s.log_cmd[:, r].copy())
        paper.append(s.paper_state.copy())
        rotor.append(s.state.copy())
    return np.stack(paper, axis=1), np.stack(rotor, axis=1), np.stack(cmds, axis=1)


@pytest.mark.parametrize(("vehicle", "controller"), [("crazyflie", "se3"), ("iris", "nlpd"), ("iris", "cascade")])
def test_rotor_fly_step_by_step_is_fly(vehicle, controller):
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        whole = qc.fly("circle", controller, **_kw(vehicle=vehicle))
    s = stepper("circle", controller, **_kw(vehicle=vehicle))
    assert s.rotor and s.state.shape == (3, 17)
    paper, rotor, cmds = _flown(s)
    assert rotor.shape == whole.rotor_states.shape
    np.testing.assert_allclose(rotor, whole.rotor_states, rtol=0, atol=1e-12)
    np.testing.assert_allclose(paper, whole.states, rtol=0, atol=1e-12)
    np.testing.assert_allclose(cmds, whole.commands, rtol=0, atol=1e-12)
    np.testing.assert_allclose(s.memory, whole.memory, rtol=0, atol=1e-12)
    np.testing.assert_allclose(s.disturbance_memory, whole.disturbance_memory, rtol=0, atol=1e-12)
    np.testing.assert_allclose(s.saturated, np.c_[whole.duty_clipped_s, whole.controller_limited_s], atol=1e-12)
    # the noise and turbulence did act: vehicles flown with other streams fly elsewhere
    assert np.abs(rotor[0, -1, :3] - rotor[1, -1, :3]).max() > 1e-6


def test_rotor_steps_of_several_periods_fly_the_same():
    one = stepper("circle", "se3", **_kw())
    many = stepper("circle", "se3", **_kw(periods=7))
    while not one.done.all():
        one.step()
    while not many.done.all():
        many.step()
    assert np.array_equal(one.state, many.state) and np.array_equal(one.carry, many.carry)
    assert many.period.tolist() == [round(DUR / 2e-3)] * 3


def test_a_rotor_vehicle_reset_alone_leaves_the_others():
    a, b = stepper("circle", "se3", **_kw()), stepper("circle", "se3", **_kw())
    first = []
    for _ in range(60):
        a.step()
        b.step()
        first.append(b.state[1].copy())
    a.reset(np.array([False, True, False]))
    assert a.period.tolist() == [60, 0, 60]
    np.testing.assert_array_equal(a.paper_state[1], stepper("circle", "se3", **_kw()).paper_state[1])
    for k in range(60):
        a.step()
        b.step()
        assert np.array_equal(a.state[1], first[k])  # vehicle 1 flies its start again
    assert np.array_equal(a.state[[0, 2]], b.state[[0, 2]])  # the others never noticed
    assert not np.array_equal(a.state[1], b.state[1])


def test_a_rotor_loss_ends_crashed_step_by_step_as_in_fly():
    # an iris losing 60 % of a rotor over the ground comes down crashed, mid-period, as in fly
    kw = dict(vehicle="iris", duration=4.0, dt=2e-3, n=1, environment=None)
    loss = Environment(rotor_loss=RotorLoss(rotor=1, fraction=0.6, time=0.1))
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        whole = qc.fly("hover", "se3", **{**kw, "environment": loss})
    s = stepper("hover", "se3", **{**kw, "environment": loss, "n": 2}, periods=50)
    while not s.done.all():
        s.step()
    assert whole.status[0] == int(ExitStatus.CRASHED)
    assert s.status.tolist() == [int(ExitStatus.CRASHED)] * 2
    assert s.t_stop[0] == pytest.approx(whole.t_stop[0], abs=1e-12)
    np.testing.assert_allclose(s.state[0], whole.rotor_final_state[0], rtol=0, atol=1e-12)


def test_bad_rotor_arguments_are_one_clear_error():
    s = stepper("hover", "se3", vehicle="crazyflie", duration=0.01, n=2)
    with pytest.raises(InputError, match=r"x0 must be finite and of shape \(17,\)"):
        s.reset(x0=np.zeros(16))
    with pytest.raises(InputError, match="full_dynamics"):
        stepper("hover", "se3", vehicle="crazyflie", duration=0.01, full_dynamics=True)


def test_after_piece_sees_every_rotor_vehicle_once_per_step():
    s = stepper("hover", "se3", vehicle="crazyflie", duration=0.02, n=5)
    seen = []
    s.step(after_piece=lambda first, stop: seen.extend(range(first, stop)), pieces_per_thread=2)
    assert sorted(seen) == list(range(5)) and s.period.tolist() == [1] * 5
