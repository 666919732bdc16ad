"""Gymnasium environments over the step-wise engine: N vehicles in one
:class:`~quadcruise.sim.stepper.Stepper`, so a step of all of them is one call of the
compiled kernel. See docs/gym.md for observations, actions, reward, termination and seeding.
"""

from __future__ import annotations

import math
from typing import Any, ClassVar

import gymnasium
import numpy as np
from gymnasium import spaces
from gymnasium.vector import AutoresetMode, VectorEnv

from quadcruise import checks
from quadcruise.control import as_controller
from quadcruise.control.setpoint import ACTION_CONTROLLERS, setpoint_gains
from quadcruise.errors import ArgumentTypeError, InputError
from quadcruise.gym.observe import OBS_SIZE, REF_SIZE, estimated_states, observe, references
from quadcruise.gym.rotor import rotor_episodes
from quadcruise.layout import F1, P_G, P_M, PSI, REF_PSI, REF_X, STATE_SIZE, X
from quadcruise.missions import Circle, Mission, mission_from_name, stack_params
from quadcruise.model.equivalent import paper_equivalent
from quadcruise.model.rotor_vehicle import RotorVehicle
from quadcruise.model.vehicle import Vehicle
from quadcruise.montecarlo.population import Population
from quadcruise.sim import plants
from quadcruise.sim.inputs import Limits, time_grid
from quadcruise.sim.rng import vehicle_states
from quadcruise.sim.status import ExitStatus
from quadcruise.sim.stepper import Stepper
from quadcruise.workflows.fly_inputs import check_can_hover
from quadcruise.workflows.rotor_fly import as_vehicle, designed_controller

EPISODE_STRIDE = 2**32
"""Episode e of vehicle i draws from the stream ``(seed, i * EPISODE_STRIDE + e)``: it depends on
(seed, i, e) only, never on the number of vehicles."""
RANDOM_MISSION_KEY = 2
"""spawn_key of a random reference's draws (the population's is 1, the engine's none)."""
RANDOM_DURATION = 20.0
"""[s]: the default episode of a random reference (from a lap of the slowest circle to 2.5 of the fastest)."""
DEFAULT_LIMITS = Limits(max_position=1.0e3, max_speed=50.0, max_rate=30.0, max_tilt=1.4)
"""The environments' divergence bounds: a vehicle past 80 degrees of tilt, 30 rad/s or 50 m/s
has crashed for any purpose of training."""


def random_circle(seed: int, episode_id: int) -> Circle:
    """A random circle reference: radius U[0.5, 3] m, lap U[8, 20] s, either direction, any start angle."""
    u = np.random.default_rng(np.random.SeedSequence([seed, episode_id], spawn_key=(RANDOM_MISSION_KEY,))).random(4)
    return Circle(
        radius=0.5 + 2.5 * u[0],
        period=8.0 + 12.0 * u[1],
        direction=1 if u[2] < 0.5 else -1,
        start_angle=2.0 * math.pi * u[3],
    )


def default_max_step(vehicle, dt: float) -> float:
    """The RK4 substep an environment flies by default: ``dt``; for a rotor-plant vehicle no
    longer than half its faster motor time constant.

    RK4 on the motor lag w' = (w_cmd - w) / tau is stable up to h = 2.78 tau, but a step of 2 tau
    (the Hummingbird's 5 ms motors at 100 Hz) misstates the lag; at h = tau / 2 its error per
    step is about (h / tau)^5 / 120 = 3e-4 of the step's change.

    Parameters
    ----------
    vehicle : Vehicle or RotorVehicle
        The nominal vehicle.
    dt : float
        The policy's period [s].

    Returns
    -------
    float
        [s].

    Examples
    --------
    >>> from quadcruise.model.rotor_vehicle import RotorVehicle
    >>> [default_max_step(RotorVehicle.preset(name), 0.01) for name in ("hummingbird", "crazyflie")]
    [0.0025, 0.01]
    """
    return plants.of(vehicle).longest_step(vehicle, dt)


class QuadVectorEnv(VectorEnv):
    """N quadrotors of one mission kind, stepped together (``gymnasium.vector.VectorEnv``).

    Parameters
    ----------
    num_envs : int
        Number of vehicles N.
    mission : Mission or str
        'hover', 'circle', 'square', 'waypoints', 'minsnap' (a name flies its defaults), a
        Mission object, or 'random' (a :func:`random_circle` per episode).
    action : {'rotors', 'rates', 'attitude', 'velocity'}
        The action mode (:mod:`quadcruise.control.setpoint`).
    controller : Controller or str, optional
        Fly this controller instead of the policy (a baseline: ``step`` then takes no actions).
    vehicle : Vehicle, RotorVehicle or str, optional
        The nominal vehicle (Table I by default), or a preset's name (``"crazyflie"``): a
        RotorVehicle flies the rotor-speed plant (:mod:`quadcruise.gym.rotor`).
    dt : float
        The policy's period [s] (100 Hz by default), one control period of the engine.
    max_step : float, optional
        Longest RK4 substep [s]; by default ``dt``, for a rotor-plant vehicle no longer than half
        its faster motor time constant (:func:`default_max_step`).
    duration : float, optional
        Episode length [s]; the mission's default duration by default (:data:`RANDOM_DURATION`
        for random references).
    population : Population, optional
        Domain randomisation: each episode's vehicle, initial offset, environment and sensors
        drawn from it (and ``model_error``: the action loops compute with the nominal vehicle).
    max_track_error : float
        A position error beyond this [m] terminates the episode with ``lost track``.
    limits : Limits, optional
        Divergence bounds; :data:`DEFAULT_LIMITS` by default.
    scales : dict, optional
        Action scales and loop gains (:data:`quadcruise.control.setpoint.DEFAULT_SCALES`).
    sensors : Sensors, optional
        The sensor models every vehicle carries (:class:`~quadcruise.estimation.Sensors`, each
        rate a divisor of ``1 / dt``); the population's by default.
    estimator : Ekf, optional
        The filter between them and the action loops (:class:`~quadcruise.estimation.Ekf`): a
        ``rates``, ``attitude`` or ``velocity`` action (or a baseline controller) is flown on its
        estimate; the population's by default.
    observe : {"truth", "estimate"}
        What the observation is computed from: the true state, or the filter's estimate
        (position, velocity, attitude, rates; the thrusts are the vehicle's own), with the
        truth's observation in ``info["true_obs"]``. The reward and the tracking check always
        read the truth. The estimate a step returns is the one the action loops flew that step
        on (the filter's at the step's start, one period old). The filter starts in the
        episode's first period: the observation a reset returns is the truth's
        (``info["estimated"]`` False until then).
    """

    metadata: ClassVar[dict] = {"autoreset_mode": AutoresetMode.NEXT_STEP, "render_modes": []}

    def __init__(
        self,
        num_envs: int = 1,
        *,
        mission: Mission | str = "hover",
        action: str = "attitude",
        controller: Any = None,
        vehicle: Vehicle | RotorVehicle | str | None = None,
        dt: float = 0.01,
        max_step: float | None = None,
        duration: float | None = None,
        population: Population | None = None,
        max_track_error: float = 2.0,
        limits: Limits | None = None,
        scales: dict | None = None,
        sensors: Any = None,
        estimator: Any = None,
        observe: str = "truth",
    ) -> None:
        w = "make()"  # gymnasium.make and make_vec hand their keywords here: each checked before any work
        checks.whole(w, "num_envs", num_envs, 1)
        checks.instance(w, "action", action, str, optional=False, want=f"one of {', '.join(ACTION_CONTROLLERS)}")
        checks.number(w, "dt", dt, "pos", unit="s")
        checks.number(w, "max_step", max_step, "pos", unit="s", optional=True)
        checks.number(w, "duration", duration, "pos", unit="s", optional=True)
        checks.instance(w, "limits", limits, Limits)
        checks.instance(w, "scales", scales, dict, want="a dict of action scales (control.setpoint.DEFAULT_SCALES)")
        if action not in ACTION_CONTROLLERS:
            raise InputError(f"unknown action mode {action!r}; valid: {', '.join(ACTION_CONTROLLERS)}")
        checks.instance(w, "population", population, Population)
        checks.instance(w, "mission", mission, (Mission, str), optional=False, want="a Mission or a mission's name")
        checks.instance(
            w, "vehicle", vehicle, (Vehicle, RotorVehicle, str), want="a Vehicle, a RotorVehicle or a preset's name"
        )
        checks.number(w, "max_track_error", max_track_error, "pos", unit="m", infinite=True)
        n = self.num_envs = int(num_envs)
        self.random_mission = isinstance(mission, str) and mission.strip().lower() == "random"
        self.mission = (
            random_circle(0, 0)
            if self.random_mission
            else (mission_from_name(mission) if isinstance(mission, str) else mission)
        )
        if not isinstance(self.mission, Mission):
            raise InputError(f"mission must be a Mission or a name, got {type(mission).__name__}")
        self.nominal = as_vehicle(vehicle) or Vehicle.paper()
        if not isinstance(self.nominal, (Vehicle, RotorVehicle)):
            raise InputError(
                f"vehicle must be a Vehicle, a RotorVehicle or a preset's name, got {checks.describe(vehicle)}"
            )
        self.plant = plants.of(self.nominal)
        # the paper vehicle the controllers believe: the rotor vehicle's "+" equivalent
        self.nominal_eq = paper_equivalent(self.nominal)
        if self.nominal_eq.batch_size is not None:
            raise InputError("the environment's vehicle must not be batched: use a population to vary it")
        check_can_hover(self.nominal_eq)
        # what every reset reads, computed once (a reset is on the hot path)
        self._nominal_row = self.nominal_eq.rows(1)
        self._start_ref, self._mission_row = self.mission.reference(0.0), stack_params(self.mission, n=1)
        self.population, self.action_mode, self.max_track_error = population, action, float(max_track_error)
        default = RANDOM_DURATION if self.random_mission else self.mission.duration
        self.duration = float(default if duration is None else duration)
        grid = time_grid(self.duration, float(dt))
        if self.plant.designs_gains and isinstance(controller, str):  # designed for the vehicle, as fly does
            controller = designed_controller(controller, self.plant.bandwidths((self.nominal,))[0])
        self.baseline = None if controller is None else as_controller(controller, w)
        try:
            gains = setpoint_gains(**(scales or {}))
        except ValueError as err:
            raise InputError(str(err)) from None
        draw = self._draw(0, np.arange(n) * EPISODE_STRIDE, n)
        # the drawn environment: a population's wind spread makes wind of still air
        self.plant.check_environment((self.nominal,), draw["environment"])
        self.sensors = None if population is None else population.noise
        observation = self._observation(w, sensors, estimator, observe, float(dt))
        if self.baseline is not None:
            function, gains, memory, width = (self.baseline.function, self.baseline.gains(), self.baseline.memory(), 0)
        else:
            function, memory, width = ACTION_CONTROLLERS[action], None, 4
        env_kw = {} if draw["environment"] is None else draw["environment"].kwargs(n)
        sens_kw = {} if self.sensors is None else self.sensors.kwargs(float(dt))
        self.stepper = Stepper(
            grid,
            draw["x0"],
            draw["vp"],
            function,
            gains,
            self.mission.function,
            draw["mp"],
            memory=memory,
            vp_ctrl=draw["vp_ctrl"],
            max_step=max_step or default_max_step(self.nominal, float(dt)),
            limits=limits or DEFAULT_LIMITS,
            setpoint_width=width,
            **env_kw,
            **sens_kw,
            **draw["own"],  # the plant's own rows (rotor plant: allocation, initial yaw) and arrays
            **draw["fixed"],
            **({} if observation is None else {"observation": observation}),
        )
        self.dt = float(dt)
        self.single_action_space = spaces.Box(-1.0, 1.0, (4,), dtype=np.float32)
        self.single_observation_space = spaces.Box(-np.inf, np.inf, (OBS_SIZE,), dtype=np.float32)
        self.action_space = spaces.Box(-1.0, 1.0, (n, 4), dtype=np.float32)
        self.observation_space = spaces.Box(-np.inf, np.inf, (n, OBS_SIZE), dtype=np.float32)
        self._ref = np.empty((n, REF_SIZE))
        self._obs = np.empty((n, OBS_SIZE), dtype=np.float32)
        self._reward = np.empty(n)
        self._lost = np.zeros(n, dtype=bool)
        self._true_obs = np.empty((n, OBS_SIZE), dtype=np.float32)
        self._estimated = np.zeros(n, dtype=bool)
        self._episode = np.zeros(n, dtype=np.int64)
        self._pending = np.zeros(n, dtype=bool)
        self._seed = 0
        self.returns = np.zeros(n)

    def _observation(self, w: str, sensors, estimator, observe: str, dt: float):
        """The vehicles' observation stage (None without sensor models), checked in one line."""
        from quadcruise.workflows.onboard import onboard_inputs

        if observe not in ("truth", "estimate"):
            raise InputError(f"{w} argument observe: expected 'truth' or 'estimate', got {checks.describe(observe)}")
        pop = self.population
        if pop is not None and (pop.imu_noise_spread > 0 or pop.gps_noise_spread > 0):
            raise InputError(
                f"{w}: the population's imu_noise_spread and gps_noise_spread are not drawn per episode in the "
                "environments; give them 0 (each vehicle's sensors differ through their own streams)"
            )
        sensors = sensors if sensors is not None else (None if pop is None else pop.sensors)
        estimator = estimator if estimator is not None else (None if pop is None else pop.estimator)
        if observe == "estimate" and estimator is None:
            raise InputError(
                f"{w} argument observe='estimate' needs an estimator: estimator=Ekf() and sensors=Sensors(...) "
                "with an imu and a gps"
            )
        if sensors is not None and self.sensors is not None:
            raise InputError(f"{w}: sensor models and the population's sensor noise: give one")
        from quadcruise.estimation.stage import Sensors

        if sensors is not None and not isinstance(sensors, Sensors):
            raise InputError(f"{w} argument sensors: expected a Sensors, got {checks.describe(sensors)}")
        n = self.num_envs
        ids = np.arange(n) * EPISODE_STRIDE
        g = float(self.nominal_eq.g)
        self.plant.refuse_sensors(f"{w} argument sensors", sensors)
        obs, _ = onboard_inputs(sensors, estimator, g=g, n=n, dt=dt, seed=0, first_vehicle=ids, where=w)
        self.observe_mode, self.observed = observe, obs is not None
        return obs

    def _draw(self, seed: int, ids: np.ndarray, k: int) -> dict:
        """The vehicle rows, initial states, mission rows and environment of k episodes."""
        pop = self.population
        if pop is None:
            vehicle, offsets, environment = self.nominal_eq, np.zeros((k, 3)), None
        else:  # a rotor vehicle's spreads are drawn on its equivalent (quadcruise.gym.rotor)
            d = pop.draw(seed, ids, k, self.nominal_eq, batch_vehicle=False)
            vehicle, offsets, environment = d.vehicle, d.offsets, d.environment
        if self.random_mission:
            missions = [random_circle(seed, int(i)) for i in ids]
            start, mp = np.concatenate([m.reference(0.0) for m in missions]), stack_params(missions, n=k)
        else:
            start, mp = self._start_ref, np.repeat(self._mission_row, k, axis=0)
        return {**EPISODES[self.plant.name](self, vehicle, start, offsets, mp, k), "environment": environment}

    def _paper_episodes(self, vehicle, start: np.ndarray, offsets: np.ndarray, mp: np.ndarray, k: int) -> dict:
        """The arrays of k episodes of a paper vehicle (``vehicle`` the drawn ones)."""
        pop = self.population
        vp = self._rows(vehicle, k)
        x0 = np.zeros((k, STATE_SIZE))  # level, still, rotors at the hover thrust
        x0[:, X : X + 3] = start[:, REF_X : REF_X + 3] + offsets  # on the reference, plus the drawn offset
        x0[:, PSI] = start[:, REF_PSI]
        x0[:, F1 : F1 + 4] = (vp[:, P_M] * vp[:, P_G] / 4.0)[:, None]
        vp_ctrl = self._rows(self.nominal, k) if pop is None or pop.model_error else vp
        return {"vp": vp, "vp_ctrl": vp_ctrl, "x0": x0, "mp": mp, "own": {}, "fixed": {}}

    def _rows(self, vehicle, k: int) -> np.ndarray:
        """``vehicle.rows(k)``, the nominal vehicle's from its row computed once."""
        return np.repeat(self._nominal_row, k, axis=0) if vehicle is self.nominal_eq else vehicle.rows(k)

    def _start(self, rows: np.ndarray) -> None:
        """Start new episodes of the vehicles ``rows``, each from its own (seed, vehicle, episode) stream."""
        k = rows.size
        if not k:
            return
        ids = rows * EPISODE_STRIDE + self._episode[rows]
        s = self.stepper
        draw = self._draw(self._seed, ids, k)
        s.vp[rows], s.vp_ctrl[rows], s.mp[rows] = draw["vp"], draw["vp_ctrl"], draw["mp"]
        for key, value in draw["own"].items():  # the plant's own rows (rotor plant: allocation, initial yaw)
            getattr(s, key)[rows] = value
        env = draw["environment"]
        if env is not None:
            s.disturbance_params[rows] = env.params(k)
        s.reset(
            self._mask(rows),
            x0=draw["x0"],
            rng=vehicle_states(self._seed, k, ids) if s.drawn else None,
            disturbance_memory=None if env is None else env.memory(k),
        )
        if self.observed:  # the episode's own sensor stream, (seed, vehicle, episode) as the rest
            from quadcruise.sim.observe import sensor_streams

            s.observation.rng[rows] = sensor_streams(self._seed, k, ids)
            s.log_obs[rows] = np.nan  # no estimate yet: the filter starts in the episode's first period
            self._estimated[rows] = False
        self._episode[rows] += 1
        self.returns[rows] = 0.0

    def _mask(self, rows: np.ndarray) -> np.ndarray:
        mask = np.zeros(self.num_envs, dtype=bool)
        mask[rows] = True
        return mask

    def _observe(self) -> None:
        s = self.stepper
        references(s.mission, s.time, s.mp, self._ref)
        observe(s.paper_state, self._ref, s.vp_ctrl, self.max_track_error, self._obs, self._reward, self._lost)
        if self.observe_mode == "estimate":  # the truth's kept for info; the policy sees the estimate's
            self._true_obs[:] = self._obs
            est, self._estimated[:] = estimated_states(s.paper_state, s.log_obs, self._estimated)
            observe(
                est,
                self._ref,
                s.vp_ctrl,
                self.max_track_error,
                self._obs,
                np.empty(self.num_envs),
                np.empty(self.num_envs, dtype=bool),
            )

    def reset(self, *, seed: int | None = None, options: dict | None = None):
        """Start every vehicle's episode again (``options={"reset_mask": mask}``: some of them).

        Parameters
        ----------
        seed : int, optional
            The seed of every draw from now on (episode counters restart at 0); a fresh one
            from the operating system when None on the first reset.
        options : dict, optional
            ``reset_mask``: (N,) bool, the vehicles to reset.

        Returns
        -------
        (numpy.ndarray, dict)
            The observations (N, OBS_SIZE) and infos.
        """
        seed = checks.whole("reset()", "seed", seed, optional=True)  # 1.5 was truncated, "abc" a ValueError
        mask = None if not options else options.get("reset_mask")
        if seed is not None or not hasattr(self, "_seeded"):
            self._seed = int(np.random.SeedSequence().entropy % (2**63)) if seed is None else seed
            self._seeded = True
            self._episode[:] = 0
        rows = np.arange(self.num_envs) if mask is None else np.flatnonzero(self.stepper.check_mask(mask))
        self._start(rows)
        self._pending[rows] = False
        self._observe()
        return self._obs.copy(), self._info()

    def _info(self) -> dict:
        s = self.stepper
        info = {"status": s.status.copy(), "t": s.time.copy(), "episode_return": self.returns.copy()}
        if self.observe_mode == "estimate":
            info.update(true_obs=self._true_obs.copy(), estimated=self._estimated.copy())
        return info

    def check_action(self, actions) -> np.ndarray:
        """The actions as a (N, 4) float64 array, or one InputError line naming what is wrong.

        Parameters
        ----------
        actions : array_like
            (N, 4) normalised actions in [-1, 1].

        Returns
        -------
        numpy.ndarray

        Raises
        ------
        InputError
            Wrong shape, not a number, not finite, or outside [-1, 1] (the vehicle and entry named).
        """
        try:
            a = np.asarray(actions, dtype=float)
        except (TypeError, ValueError):
            raise InputError(
                f"action: expected numbers of shape ({self.num_envs}, 4), got {type(actions).__name__}"
            ) from None
        if a.shape != (self.num_envs, 4):
            raise InputError(f"action: expected shape ({self.num_envs}, 4), got {a.shape}")
        bad = ~np.isfinite(a)
        if bad.any():
            i, j = np.argwhere(bad)[0]
            raise InputError(f"action: vehicle {i}, entry {j} is {a[i, j]} (must be finite, in [-1, 1])")
        out = np.abs(a) > 1.0
        if out.any():
            i, j = np.argwhere(out)[0]
            raise InputError(
                f"action: vehicle {i}, entry {j} is {a[i, j]:.6g}, outside the action space [-1, 1] "
                f"(mode '{self.action_mode}')"
            )
        return a

    def step(self, actions):
        """Fly every vehicle one period with its action; reset those whose episode ended at
        the previous step (their actions are ignored: gymnasium's NEXT_STEP autoreset).

        Parameters
        ----------
        actions : array_like or None
            (N, 4) normalised actions; None when the environment flies a baseline controller.

        Returns
        -------
        (obs, reward, terminated, truncated, info)
            Arrays over the N vehicles; ``info["status"]`` the engine's statuses.
        """
        s = self.stepper
        if self.baseline is None:
            a = self.check_action(actions)
            s.step(a)
        else:
            if actions is not None:
                raise InputError("action: this environment flies a baseline controller; step(None)")
            s.step()
        pending = np.flatnonzero(self._pending)  # done, so not flown: restarted now
        if pending.size:
            self._start(pending)
        self._observe()
        lost = self._lost & (s.status == int(ExitStatus.FINISHED))
        lost[pending] = False
        if lost.any():
            s.status[lost] = int(ExitStatus.LOST_TRACK)
            s.t_stop[lost] = s.time[lost]
        terminated = s.status != int(ExitStatus.FINISHED)
        truncated = ~terminated & (s.period >= s.t_grid.shape[0] - 1)
        reward = np.where(terminated, 0.0, self._reward)
        reward[pending] = 0.0
        terminated[pending] = truncated[pending] = False
        self.returns += reward
        info = self._info()
        self._pending = terminated | truncated
        return self._obs.copy(), reward, terminated, truncated, info


EPISODES = {"paper": QuadVectorEnv._paper_episodes, "rotor": rotor_episodes}
"""How an environment's episodes start, by the nominal vehicle's plant (:mod:`quadcruise.sim.plants`):
``episodes(env, vehicle, start, offsets, mp, k) -> dict`` of the Stepper's rows."""


class MakeArgumentTypeError(ArgumentTypeError):
    """An argument of the wrong type to ``gymnasium.make``: its one line kept whole.

    ``gymnasium.make`` raises a ``TypeError`` from an environment's constructor again as
    ``type(e)(f"{e} was raised from the environment creator ... with kwargs (...)")``, a line
    of every keyword's repr; this type keeps the first part, the line that names the argument.
    """

    def __init__(self, text: str) -> None:
        super().__init__(text.split(" was raised from the environment creator", 1)[0])


class QuadEnv(gymnasium.Env):
    """One quadrotor (``gymnasium.make``): a :class:`QuadVectorEnv` of one vehicle, without autoreset.

    Gymnasium's convention: once ``step`` has returned ``terminated`` or ``truncated``, the user
    calls ``reset``. A ``step`` before that raises ``gymnasium.error.ResetNeeded`` (as stepping
    before the first reset does), rather than fly past the mission's end and pay reward for it.

    Parameters
    ----------
    **kwargs : Any
        As :class:`QuadVectorEnv` (not ``num_envs``).
    """

    metadata: ClassVar[dict] = {"render_modes": []}

    def __init__(self, **kwargs: Any) -> None:
        try:
            self.vec = QuadVectorEnv(1, **kwargs)
        except ArgumentTypeError as exc:
            raise MakeArgumentTypeError(str(exc)) from None
        self.action_space = self.vec.single_action_space
        self.observation_space = self.vec.single_observation_space
        self._ended: str | None = "has not begun"  # why step needs a reset first, or None

    def reset(self, *, seed: int | None = None, options: dict | None = None):
        """Start an episode (see :meth:`QuadVectorEnv.reset`).

        Parameters
        ----------
        seed : int, optional
            The seed of every draw from now on.
        options : dict, optional
            Not used.

        Returns
        -------
        (numpy.ndarray, dict)
        """
        seed = checks.whole("reset()", "seed", seed, optional=True)  # before gymnasium's own seeding
        super().reset(seed=seed)
        obs, info = self.vec.reset(seed=seed)
        self._ended = None
        return obs[0], {k: v[0] for k, v in info.items()}

    def step(self, action):
        """One period (see :meth:`QuadVectorEnv.step`).

        Parameters
        ----------
        action : array_like
            (4,) normalised action.

        Returns
        -------
        (obs, reward, terminated, truncated, info)

        Raises
        ------
        gymnasium.error.ResetNeeded
            If the episode has ended (a step returned terminated or truncated) or not begun.
        """
        if self._ended is not None:
            raise gymnasium.error.ResetNeeded(
                f"step(): the episode {self._ended}; call reset() to start the next one"
            )  # fmt: skip
        a = None if action is None else np.asarray(action)
        if a is not None and a.shape != (4,):
            raise InputError(f"action: expected shape (4,), got {a.shape}")
        self.vec._pending[:] = False  # no autoreset: the user resets
        obs, r, term, trunc, info = self.vec.step(None if a is None else a[None, :])
        if term[0] or trunc[0]:
            self._ended = (
                "has ended ("
                + (
                    "terminated: " + ExitStatus(int(info["status"][0])).reason
                    if term[0]
                    else "truncated: the mission's end"
                )
                + ")"
            )
        return obs[0], float(r[0]), bool(term[0]), bool(trunc[0]), {k: v[0] for k, v in info.items()}


__all__ = ["DEFAULT_LIMITS", "EPISODE_STRIDE", "default_max_step", "QuadEnv", "QuadVectorEnv", "random_circle"]
