"""The Gymnasium environments on the rotor-speed plant: gymnasium's checker on every
environment and action mode for the Crazyflie and the Iris; `rotors` commands the real rotors
(checked on the plant's response against the kinematics); the vector env on every preset;
`crashed` terminates; a baseline controller in the environment flies what `fly` flies; domain
randomisation of the rotor vehicle from a Population, seeded per vehicle."""

import warnings

import gymnasium
import numpy as np
import pytest
from gymnasium.utils.env_checker import check_env

import quadcruise as qc
import quadcruise.gym  # noqa: F401 (registers the environments)
from quadcruise.disturbances import Environment, RotorLoss
from quadcruise.errors import InputError
from quadcruise.gym.env import QuadVectorEnv
from quadcruise.gym.evaluate import rollout
from quadcruise.layout import P_D, P_JXX, P_JYY, P_JZZ, P_K, P_M, P_OMEGA
from quadcruise.missions import Circle
from quadcruise.model.equivalent import paper_equivalent
from quadcruise.model.rotor_plant import ROTOR_P_JXX, ROTOR_P_KF, ROTOR_P_KM, ROTOR_P_M, ROTOR_P_TAU_UP
from quadcruise.model.rotor_vehicle import AERO_FIELDS, RotorVehicle
from quadcruise.montecarlo.population import Population
from quadcruise.sim.status import ExitStatus

MODES = ("rotors", "rates", "attitude", "velocity")
G = 9.81
pytestmark = pytest.mark.filterwarnings("ignore:.*Box observation space.*")


@pytest.mark.parametrize("vehicle", ["crazyflie", "iris"])
@pytest.mark.parametrize("env_id", ["quadcruise/Hover-v0", "quadcruise/Track-v0"])
@pytest.mark.parametrize("mode", MODES)
def test_gymnasium_checker_passes_on_rotor_vehicles(vehicle, env_id, mode):
    env = gymnasium.make(env_id, vehicle=vehicle, action=mode)
    check_env(env.unwrapped, skip_render_check=True)
    assert env.unwrapped.vec.stepper.rotor


@pytest.mark.parametrize("vehicle", ["crazyflie", "iris"])
def test_rotors_mode_commands_the_real_rotors(vehicle):
    v = RotorVehicle.preset(vehicle).replace(**dict.fromkeys(AERO_FIELDS, 0.0))  # no drag: the climb is kinematic
    env = gymnasium.make("quadcruise/Hover-v0", vehicle=v, action="rotors", population=None, dt=0.002)
    env.reset(seed=0)
    s = env.unwrapped.vec.stepper
    z0 = s.state[0, 2]
    for _ in range(500):  # 1 s with every rotor at 1.1 times its hover thrust: 0.1 g up, no turn
        env.step(np.full(4, 0.1, dtype=np.float32))
    w = s.state[0, 13:]
    np.testing.assert_allclose(v.kf * w**2, 1.1 * v.m * v.g / 4, rtol=1e-6)  # each rotor at its command
    lag = v.tau_up  # the rotors speed up: their first-order lag delays the climb by about tau_up
    assert s.state[0, 2] - z0 == pytest.approx(0.5 * 0.1 * v.g * (1.0 - lag) ** 2, abs=0.02 * 0.5 * 0.1 * v.g)
    assert np.abs(s.state[0, 10:13]).max() < 1e-9  # no body rate
    # rotor 1 alone faster: a moment about the axis its position sets (rotor 1 of the x layout)
    env.reset(seed=0)
    env.step(np.array([0.3, 0.0, 0.0, 0.0], dtype=np.float32))
    x1, y1 = v.rotors[0][0], v.rotors[0][1]
    p, q = s.state[0, 10], s.state[0, 11]
    assert np.sign(p) == np.sign(y1) and np.sign(q) == -np.sign(x1)  # M = r x F, F along body z


@pytest.mark.parametrize("vehicle", ["paper", "qball-x4", "crazyflie", "hummingbird", "iris"])
def test_the_vector_env_flies_any_preset_with_autoreset(vehicle):
    vec = gymnasium.make_vec(
        "quadcruise/Track-v0", num_envs=6, vectorization_mode="vector_entry_point", vehicle=vehicle, duration=0.5
    )
    vec.reset(seed=3)
    rng = np.random.default_rng(0)
    ended = np.zeros(6, dtype=int)
    for _ in range(80):
        obs, reward, term, trunc, info = vec.step(rng.uniform(-1, 1, (6, 4)).astype(np.float32))
        assert np.isfinite(obs).all() and np.isfinite(reward).all()
        ended += term | trunc
    assert ended.min() >= 1  # every vehicle's episode ended (50 periods) and restarted


def test_a_rotor_loss_over_the_ground_terminates_crashed():
    env = QuadVectorEnv(
        2,
        mission="hover",
        controller="se3",
        vehicle="iris",
        duration=5.0,
        dt=0.002,  # se3's gains for the Iris do not hold it at 100 Hz (fly crashes it too): docs/gym.md
        population=Population(environment=Environment(rotor_loss=RotorLoss(rotor=1, fraction=0.6, time=0.5))),
    )
    _, flights = rollout(env, seed=0)
    assert flights.status.tolist() == [int(ExitStatus.CRASHED)] * 2
    assert (0.5 < flights.t_stop).all() and (flights.t_stop < 5.0).all()
    healthy = QuadVectorEnv(2, mission="hover", controller="se3", vehicle="iris", duration=5.0, dt=0.002)
    _, ok = rollout(healthy, seed=0)
    assert ok.status.tolist() == [int(ExitStatus.FINISHED)] * 2


@pytest.mark.parametrize(("vehicle", "controller"), [("crazyflie", "se3"), ("iris", "cascade")])
def test_a_baseline_in_the_rotor_env_flies_what_fly_flies(vehicle, controller):
    circle = Circle(radius=1.0, period=6.0, center=(-1.0, 0.0))  # starts at x = y = 0, where fly starts
    env = QuadVectorEnv(2, mission=circle, controller=controller, vehicle=vehicle, dt=0.002, duration=2.0)
    returns, flights = rollout(env, seed=0)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        whole = qc.fly(circle, controller, vehicle=vehicle, n=2, dt=0.002, duration=2.0)
    assert whole.status.tolist() == [0, 0]
    np.testing.assert_allclose(flights.states, whole.states, rtol=0, atol=1e-12)
    np.testing.assert_allclose(flights.commands, whole.commands, rtol=0, atol=1e-12)
    err = np.linalg.norm(whole.states[:, 1:, :3] - whole.references[:, 1:, :3], axis=2)
    rate = np.linalg.norm(whole.states[:, 1:, 9:12], axis=2)
    np.testing.assert_allclose(returns, np.exp(-err / 0.5 - 0.05 * rate).sum(axis=1), rtol=1e-9)


def test_domain_randomisation_draws_rotor_vehicles_per_vehicle_seed():
    spreads = dict(mass_spread=0.1, inertia_spread=0.1, thrust_spread=0.05, bandwidth_spread=0.1, yaw_arm_spread=0.1)
    pop = Population(**spreads, model_error=False)  # each controller believes its drawn vehicle
    four = QuadVectorEnv(4, vehicle="crazyflie", population=pop)
    two = QuadVectorEnv(2, vehicle="crazyflie", population=pop)
    four.reset(seed=5)
    two.reset(seed=5)
    s4, s2 = four.stepper, two.stepper
    np.testing.assert_array_equal(s4.vp[:2], s2.vp)  # vehicle i's draw does not depend on N
    nominal = RotorVehicle.preset("crazyflie")
    rows = s4.vp
    assert len(set(rows[:, ROTOR_P_M])) == 4 and np.std(rows[:, ROTOR_P_M] / nominal.m) > 0.01
    for i in range(4):  # each drawn rotor vehicle's "+" equivalent is the drawn paper row its controller reads
        drawn = nominal.replace(
            m=rows[i, ROTOR_P_M],
            Jxx=rows[i, ROTOR_P_JXX],
            Jyy=rows[i, ROTOR_P_JXX + 1],
            Jzz=rows[i, ROTOR_P_JXX + 2],
            kf=rows[i, ROTOR_P_KF],
            km=rows[i, ROTOR_P_KM],
            tau_up=rows[i, ROTOR_P_TAU_UP],
            tau_down=rows[i, ROTOR_P_TAU_UP + 1],
        )
        eq = paper_equivalent(drawn)
        for name, col in (("m", P_M), ("Jxx", P_JXX), ("Jyy", P_JYY), ("Jzz", P_JZZ), ("K", P_K), ("d", P_D)):
            assert getattr(eq, name) == pytest.approx(s4.vp_ctrl[i, col], rel=1e-12)
        assert nominal.tau_up / rows[i, ROTOR_P_TAU_UP] == pytest.approx(s4.vp_ctrl[i, P_OMEGA] / four.nominal_eq.omega)
    rng = np.random.default_rng(1)
    for _ in range(30):
        a = rng.uniform(-0.2, 0.2, (4, 4)).astype(np.float32)
        four.step(a)
        two.step(a[:2])
    np.testing.assert_array_equal(s4.state[:2], s2.state)
    believing = QuadVectorEnv(2, vehicle="crazyflie", population=Population(**spreads, model_error=True))
    believing.reset(seed=5)  # the same draws flown, the controllers believing the nominal vehicle
    np.testing.assert_array_equal(believing.stepper.vp, s2.vp)
    np.testing.assert_array_equal(believing.stepper.vp_ctrl, np.tile(paper_equivalent(nominal).rows(1), (2, 1)))


def test_rotor_env_bad_input_is_one_line():
    hexa = RotorVehicle.preset("iris").replace(
        rotors=[[0.25 * np.cos(a), 0.25 * np.sin(a), 0.0, (-1) ** k] for k, a in enumerate(np.arange(6) * np.pi / 3)]
    )
    with pytest.raises(InputError, match="action 'rotors': the action has 4 entries and the vehicle 6 rotors"):
        QuadVectorEnv(2, vehicle=hexa, action="rotors")
    QuadVectorEnv(2, vehicle=hexa, action="attitude").reset(seed=0)  # the other modes fly any layout
    bare = RotorVehicle.preset("crazyflie").replace(**dict.fromkeys(AERO_FIELDS, 0.0))
    with pytest.raises(InputError, match="wind acts on a rotor-plant vehicle through its aerodynamics"):
        QuadVectorEnv(2, vehicle=bare, population=Population(wind_spread=2.0))
    QuadVectorEnv(2, vehicle="crazyflie", population=Population(wind_spread=2.0)).reset(seed=0)
    with pytest.raises(InputError, match="unknown vehicle preset|preset"):
        QuadVectorEnv(2, vehicle="no-such-drone")
