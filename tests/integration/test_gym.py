"""The Gymnasium environments: gymnasium's own checker on every environment and action mode;
each action mode does what docs/gym.md says (checked on the plant's response); autoreset per
vehicle; seeds that reproduce and do not depend on N; bad actions refused in one line; a
baseline controller in the environment flies what `fly` flies from the same start."""

import subprocess
import sys
import warnings
from pathlib import Path

import gymnasium
import numpy as np
import pytest
from gymnasium.utils.env_checker import check_env

import quadcruise as qc
import quadcruise.gym
from quadcruise.disturbances import Environment, SensorNoise, Turbulence, with_drag
from quadcruise.errors import InputError
from quadcruise.gym.env import QuadVectorEnv
from quadcruise.gym.evaluate import baselines, rollout
from quadcruise.layout import PHI, VX, P
from quadcruise.missions import MinimumSnap, Waypoints
from quadcruise.montecarlo.population import Population
from quadcruise.sim.status import ExitStatus

MODES = ("rotors", "rates", "attitude", "velocity")
pytestmark = pytest.mark.filterwarnings("ignore:.*Box observation space.*")


def test_import_quadcruise_does_not_import_gymnasium():
    code = "import sys, quadcruise; quadcruise.fly; print('gymnasium' in sys.modules)"
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, check=True)
    assert out.stdout.strip() == "False"


@pytest.mark.parametrize("env_id", ["quadcruise/Hover-v0", "quadcruise/Track-v0"])
@pytest.mark.parametrize("mode", MODES)
def test_gymnasium_checker_passes(env_id, mode):
    env = gymnasium.make(env_id, action=mode)
    check_env(env.unwrapped, skip_render_check=True)
    vec = gymnasium.make_vec(env_id, num_envs=3, vectorization_mode="vector_entry_point", action=mode)
    assert isinstance(vec, QuadVectorEnv)
    obs, _ = vec.reset(seed=0)
    assert obs.shape == (3, 21) and obs.dtype == np.float32 and vec.observation_space.contains(obs)


@pytest.mark.parametrize("mission", ["square", "waypoints", "minsnap", "random"])
def test_track_flies_every_mission_kind(mission):
    csv = str(Path(__file__).resolve().parents[2] / "examples" / "waypoints.csv")
    kind = {"waypoints": Waypoints(table=csv), "minsnap": MinimumSnap(table=csv)}.get(mission, mission)
    env = gymnasium.make_vec(
        "quadcruise/Track-v0", num_envs=2, vectorization_mode="vector_entry_point", mission=kind, controller="se3"
    )
    obs, _ = env.reset(seed=4)
    assert np.abs(obs[:, :3]).max() < 1e-9  # each episode starts on its reference
    for _ in range(100):
        obs, reward, terminated, _, _ = env.step(None)
    assert not terminated.any() and (reward > 0.5).all()
    if mission == "random":  # two vehicles, two different circles
        assert not np.array_equal(env.stepper.mp[0], env.stepper.mp[1])
        assert env.duration == 20.0


def _hold(mode, action, seconds, **kw):
    env = QuadVectorEnv(1, mission="hover", action=mode, duration=max(seconds, 1.0), max_track_error=1e3, **kw)
    env.reset(seed=0)
    for _ in range(round(seconds / env.dt)):
        env.step(np.array([action], dtype=np.float32))
    return env.stepper.state[0]


def test_each_action_mode_flies_its_setpoint():
    x = _hold("rotors", [0.0, 0.0, 0.0, 0.0], 2.0)  # hover duties: stays where it started
    assert np.abs(x[VX : VX + 3]).max() < 1e-9
    x = _hold("rotors", [0.2, 0.2, 0.2, 0.2], 0.5)  # 20 % more thrust on every rotor climbs
    assert x[VX + 2] > 0.3
    x = _hold("rates", [0.0, 0.1, 0.0, 0.0], 0.4)  # 0.1 of 3 rad/s of roll rate
    assert x[P] == pytest.approx(0.3, abs=0.01)
    x = _hold("attitude", [0.0, 0.4, 0.0, 0.0], 2.0)  # 0.4 of 0.5 rad of roll
    assert x[PHI] == pytest.approx(0.2, abs=0.005)
    x = _hold("velocity", [1 / 3, 0.0, 0.0, 0.0], 5.0)  # 1 m/s in x, level
    assert x[VX] == pytest.approx(1.0, abs=0.02) and abs(x[VX + 1]) < 0.02 and abs(x[VX + 2]) < 0.02


def test_autoreset_is_per_vehicle():
    env = QuadVectorEnv(3, mission="hover", action="rotors", duration=1.0)
    env.reset(seed=0)
    push = np.zeros((3, 4), dtype=np.float32)
    push[1] = 1.0  # vehicle 1 climbs away at twice the hover thrust
    for _ in range(100):
        obs, reward, terminated, truncated, info = env.step(push)
        if terminated[1]:
            break
    assert terminated.tolist() == [False, True, False] and not truncated.any()
    assert info["status"][1] == int(ExitStatus.LOST_TRACK) and reward[1] == 0.0
    assert info["episode_return"][1] > 0.0 and info["t"][1] > 0.0  # the ended episode's, at its last step
    t_before = env.stepper.time.copy()
    obs, reward, terminated, truncated, info = env.step(push)
    assert env.stepper.period[1] == 0 and reward[1] == 0.0 and not terminated[1]  # restarted
    assert info["status"][1] == int(ExitStatus.FINISHED) and info["t"][1] == 0.0  # the new episode's info
    assert info["episode_return"][1] == 0.0 and info["episode_return"][0] > 0.0
    assert np.linalg.norm(obs[1, :3]) < 2.0  # back near its reference
    assert np.allclose(env.stepper.time[[0, 2]], t_before[[0, 2]] + env.dt)  # the others flew on
    for _ in range(200):
        _, reward, terminated, truncated, info = env.step(np.zeros((3, 4), dtype=np.float32))
        if truncated[0]:
            break
    assert truncated[0] and truncated[2] and not terminated[0]  # the mission's end truncates


def test_seeds_reproduce_and_do_not_depend_on_n():
    pop = Population(
        offset=0.3,
        mass_spread=0.05,
        noise=SensorNoise(rate_std=0.01),
        environment=Environment(turbulence=Turbulence()),
        wind_spread=1.0,
    )
    runs = []
    for n in (2, 5, 5):
        env = QuadVectorEnv(
            n, mission="random", action="attitude", population=pop, duration=0.5, vehicle=with_drag(qc.Vehicle.paper())
        )
        obs, _ = env.reset(seed=11)
        actions = np.tile(np.array([0.05, 0.1, -0.1, 0.0], dtype=np.float32), (n, 1))
        for _ in range(80):  # past one episode: autoreset draws episode 1
            obs, *_ = env.step(actions)
        runs.append(obs)
    assert np.array_equal(runs[0], runs[1][:2]) and np.array_equal(runs[1], runs[2])
    assert not np.array_equal(runs[1][0], runs[1][1])  # vehicles do differ
    env = QuadVectorEnv(
        2, mission="random", action="attitude", population=pop, duration=0.5, vehicle=with_drag(qc.Vehicle.paper())
    )
    assert not np.array_equal(env.reset(seed=12)[0], runs[0])


@pytest.mark.parametrize(
    ("action", "message"),
    [
        (np.full((2, 4), np.nan), r"vehicle 0, entry 0 is nan \(must be finite"),
        (np.zeros((2, 3)), r"expected shape \(2, 4\), got \(2, 3\)"),
        (np.array([[0, 0, 0, 0], [0, 1.5, 0, 0]]), r"vehicle 1, entry 1 is 1.5, outside the action space"),
        ("up", r"expected numbers of shape \(2, 4\)"),
    ],
)
def test_bad_actions_are_one_clear_error(action, message):
    env = QuadVectorEnv(2, mission="hover", action="rates")
    env.reset(seed=0)
    with pytest.raises(InputError, match=message):
        env.step(action)
    with pytest.raises(InputError, match="unknown action mode 'thrust'"):
        QuadVectorEnv(2, action="thrust")


def test_a_rollout_keeps_each_flight_as_it_ended():
    env = QuadVectorEnv(3, mission="hover", action="rotors", duration=1.0)

    def climb_one(obs):
        a = np.zeros((3, 4), dtype=np.float32)
        a[1] = 1.0
        return a

    returns, flights = rollout(env, climb_one, seed=0)
    assert flights.status.tolist() == [0, int(ExitStatus.LOST_TRACK), 0]
    assert 0.0 < flights.t_stop[1] < 1.0 and flights.t_stop[0] == 1.0
    lost_at = round(float(flights.t_stop[1]) / env.dt)
    assert np.isfinite(flights.states[1, : lost_at + 1]).all() and np.isnan(flights.states[1, lost_at + 1 :]).all()
    assert np.linalg.norm(flights.final_state[1, :3] - flights.references[1, 0, :3]) > 2.0  # where it was lost
    assert returns[1] < returns[0]


def test_baselines_score_in_the_registered_environments_own_domain():
    """By default Hover-v0 as gymnasium.make_vec makes it (its 0.3 m start offsets), not a hover
    without offset, which scored every controller 500 a return and 0 m RMSE."""
    table = baselines(("nlpd", "se3"), num_envs=3, seed=2, duration=1.0)
    for name in ("nlpd", "se3"):
        vec = gymnasium.make_vec(
            "quadcruise/Hover-v0", num_envs=3, vectorization_mode="vector_entry_point", controller=name, duration=1.0
        )
        assert vec.population.offset == 0.3
        returns, flights = rollout(vec, seed=2)
        assert table.loc[name, "mean_return"] == returns.mean()
        assert table.loc[name, "rmse_m"] == pytest.approx(flights.metrics()["rmse_m"].mean(), rel=1e-12)
        assert np.linalg.norm(flights.states[:, 0, :3] - flights.references[:, 0, :3], axis=1).min() > 0.01
    assert (table["mean_reward"] < 0.95).all() and (table["rmse_m"] > 0.05).all()
    # the other direction: a hover with no offset (what the default was) is perfect for every controller
    still = baselines(("nlpd", "se3"), num_envs=3, seed=2, duration=1.0, population=None)
    assert (still["mean_reward"] == 1.0).all() and (still["rmse_m"] == 0.0).all()
    with pytest.raises(InputError, match="env_id 'Hover' is not a registered environment"):
        baselines(env_id="Hover")


@pytest.mark.parametrize("ending", ["truncated", "terminated"])
def test_a_single_env_must_be_reset_after_its_episode_ends(ending):
    """gymnasium's convention (Env.step: "If true, the user needs to call reset"): a step after the end
    raises ResetNeeded instead of flying on and paying reward (0.4435 a step before)."""
    kw = dict(duration=0.05) if ending == "truncated" else dict(max_track_error=0.05)  # Hover-v0: 0.3 m offsets
    env = gymnasium.make("quadcruise/Hover-v0", **kw)
    env.reset(seed=0)
    for _ in range(10):
        _, reward, terminated, truncated, info = env.step(np.zeros(4))
        if terminated or truncated:
            break
    assert (terminated, truncated) == (ending == "terminated", ending == "truncated")
    with pytest.raises(gymnasium.error.ResetNeeded, match=f"has ended \\({ending}"):
        env.step(np.zeros(4))
    env.reset(seed=1)  # and after a reset it flies again
    assert np.isfinite(env.step(np.zeros(4))[1])


def test_a_baseline_in_the_env_flies_what_fly_flies():
    env = QuadVectorEnv(2, mission="circle", controller="nlpd", dt=0.002, duration=2.0)
    returns, flights = rollout(env, seed=0)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        whole = qc.fly("circle", "nlpd", n=2, dt=0.002, duration=2.0, x0=flights.states[:, 0])
    np.testing.assert_allclose(flights.states, whole.states, rtol=0, atol=1e-12)
    np.testing.assert_allclose(flights.commands, whole.commands, rtol=0, atol=1e-12)
    # the same reward, computed independently from the logged flight
    err = np.linalg.norm(whole.states[:, 1:, :3] - whole.references[:, 1:, :3], axis=2)
    rate = np.linalg.norm(whole.states[:, 1:, 9:12], axis=2)
    np.testing.assert_allclose(returns, np.exp(-err / 0.5 - 0.05 * rate).sum(axis=1), rtol=1e-9)
    table = baselines(("nlpd", "cascade"), env_id="quadcruise/Track-v0", num_envs=2, dt=0.002, duration=2.0)
    assert table.loc["nlpd", "mean_return"] == pytest.approx(returns.mean())
    assert table.loc["nlpd", "rmse_m"] == pytest.approx(whole.metrics()["rmse_m"].mean(), rel=1e-9)
    assert (table["finished"] == 1.0).all()
