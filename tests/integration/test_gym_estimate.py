"""The gym on the estimate (issue 35): ``observe="estimate"`` gives the policy the observation of
the EKF's estimate and keeps the truth's in ``info["true_obs"]``, which is exactly what the same
environment observing the truth returns (the flight itself does not change: the action loops fly
on the estimate either way); gymnasium's checker passes; bad options are one line."""

from __future__ import annotations

import dataclasses

import gymnasium
import numpy as np
import pytest
from gymnasium.utils.env_checker import check_env

import quadcruise.gym  # noqa: F401  (registers the environments)
from quadcruise.errors import InputError
from quadcruise.estimation import Ekf, Sensors
from quadcruise.gym.env import QuadVectorEnv
from quadcruise.montecarlo import Population

pytestmark = pytest.mark.filterwarnings("ignore:.*Box observation space.*")
SENSORS = Sensors.typical()  # IMU at 250 Hz: a policy period of 4 ms samples it every period
KW = dict(mission="hover", dt=0.004, duration=1.0, sensors=SENSORS, estimator=Ekf())


def rollout(observe, steps=100, seed=5):
    env = QuadVectorEnv(2, controller="nlpd", observe=observe, **KW)
    obs, info = env.reset(seed=seed)
    out = [(obs, info)]
    for _ in range(steps):
        obs, _, _, _, info = env.step(None)
        out.append((obs, info))
    return out


def test_the_estimate_is_observed_and_the_truth_kept_in_info():
    est, truth = rollout("estimate"), rollout("truth")
    obs0, info0 = est[0]
    assert not info0["estimated"].any()  # before the filter's first period: the truth's
    np.testing.assert_array_equal(obs0, info0["true_obs"])
    for (_, i_est), (o_truth, i_truth) in zip(est[1:], truth[1:], strict=True):
        assert i_est["estimated"].all() and "true_obs" not in i_truth
        np.testing.assert_array_equal(i_est["true_obs"], o_truth)  # the same flight, observed two ways
    o, i = est[-1]
    err = np.abs(o[:, :3] - i["true_obs"][:, :3])  # position error, body frame [m]
    assert (err > 1e-4).any() and (err < 0.5).all()  # the filter's error: there, and small


def test_gymnasium_checker_passes_on_the_estimate():
    check_env(gymnasium.make("quadcruise/Hover-v0", action="attitude", observe="estimate", **{
        k: v for k, v in KW.items() if k != "mission"}).unwrapped, skip_render_check=True)  # fmt: skip


@pytest.mark.parametrize(
    ("kw", "message"),
    [
        ({"observe": "belief"}, "argument observe: expected 'truth' or 'estimate'"),
        ({"observe": "estimate", "estimator": None, "sensors": None}, "observe='estimate' needs an estimator"),
        ({"sensors": Sensors.typical(("imu",))}, "ekf needs the sensor 'gps'"),
        ({"dt": 0.01}, "imu rate 250 Hz does not divide the control rate 100 Hz"),
        ({"sensors": "imu,gps"}, "argument sensors: expected a Sensors"),
        (
            {"population": Population(sensors=SENSORS, imu_noise_spread=0.1)},
            "imu_noise_spread and gps_noise_spread are not drawn per episode",
        ),
    ],
)
def test_bad_options_are_one_line(kw, message):
    with pytest.raises(InputError) as err:
        QuadVectorEnv(1, **{**KW, "observe": "estimate", **kw})
    assert message in str(err.value) and "\n" not in str(err.value)


def test_make_refuses_a_bad_observe_in_one_line():
    with pytest.raises(InputError, match="argument observe: expected 'truth' or 'estimate', got"):
        gymnasium.make("quadcruise/Hover-v0", observe="noisy")


def test_a_population_gives_its_sensors_and_each_episode_its_own_stream():
    pop = Population(offset=0.1, sensors=dataclasses.replace(SENSORS), estimator=Ekf())
    env = QuadVectorEnv(1, mission="hover", dt=0.004, duration=0.2, population=pop, observe="estimate")
    firsts = []
    for _ in range(2):  # two episodes: different sensor draws
        env.reset(seed=None if firsts else 3)
        obs, *_ = env.step(np.zeros((1, 4)))
        firsts.append(obs.copy())
    assert not np.array_equal(firsts[0], firsts[1])
    env.reset(seed=3)
    again, *_ = env.step(np.zeros((1, 4)))
    np.testing.assert_array_equal(again, firsts[0])  # the same seed: the same episode
