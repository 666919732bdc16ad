"""A step-wise engine: N vehicles advanced a few control periods per call, through the same
compiled kernel as a whole flight.

:class:`Stepper` holds everything a vehicle carries from one period to the next (its state,
its controller's and disturbance's memories, its random stream, the sensor-delay ring
buffer, its period on the time grid, its saturation times and status) and hands it to
:func:`quadcruise.sim.engine.fly_vehicles` for ``periods`` periods per :meth:`Stepper.step`.
The kernel reads all of it at the start of a call and writes it back at the end, so a flight
cut into steps is bit for bit the flight :func:`~quadcruise.sim.engine.simulate` flies in one
call. Each vehicle keeps its own period: after :meth:`Stepper.reset` of some of them, they
start their grid again while the others fly on.

The vehicles fly either plant: the paper's (:func:`~quadcruise.sim.engine.fly_vehicles`), or,
given the rotor plant's arrays (``alloc``, ``psi0``, ``touchdown_speed``, as
:func:`quadcruise.sim.rotor_batch.fly_rotor_vehicles` takes them), the rotor-speed plant
(:func:`~quadcruise.sim.rotor_flight.fly_rotor_pieces`), whose kernel keeps the same resume
contract. One API for both: :attr:`Stepper.state` is the plant's own state (16 entries, or the
13 + n of the rotor state), :attr:`Stepper.paper_state` the paper-layout state of either.

A policy reaches the plant through the controller too: a controller that reads its setpoint
from the first ``setpoint_width`` entries of its gains row (the action modes of
:mod:`quadcruise.gym`) is given that setpoint by ``step(commands)``.

Examples
--------
>>> import time

import numpy as np
>>> from quadcruise.workflows.stepwise import stepper
>>> s = stepper("hover", "nlpd", duration=0.01, n=2)
>>> s.step(); s.period.tolist(), s.status.tolist()
([1, 1], [0, 0])
"""

from __future__ import annotations

import time

import numpy as np

from quadcruise.checks import describe
from quadcruise.errors import InputError
from quadcruise.layout import CMD_SIZE, REF_SIZE, STATE_SIZE
from quadcruise.sim.engine import fly_vehicles, still_air
from quadcruise.sim.inputs import Limits, batch_inputs, fresh_carry
from quadcruise.sim.kernel_args import KernelArgs, RotorKernelArgs
from quadcruise.sim.observe import Observation, sensor_streams
from quadcruise.sim.rng import vehicle_states
from quadcruise.sim.rotor_batch import rotor_inputs
from quadcruise.sim.rotor_flight import fly_rotor_pieces, paper_states, rotor_carry_width
from quadcruise.sim.status import ExitStatus
from quadcruise.sim.threads import ThreadPlan

STEP_PIECES_PER_THREAD = 1
"""A step is short: one range of vehicles per thread, as each kernel call has a fixed cost."""


class Stepper:
    """N vehicles flown a few control periods per call (the arguments as in
    :func:`quadcruise.sim.engine.simulate`).

    Parameters
    ----------
    t_grid : (M+1,) array
        Control instants [s] shared by the vehicles; each vehicle has its own place on it.
    x0 : (16,) or (N, 16) array
        Initial states, restored by :meth:`reset` (rotor plant: (13 + n,) or (N, 13 + n) rotor states).
    vp : (N, PARAM_SIZE) array
        Vehicle parameter rows (rotor plant: the rotor vehicles' rows).
    controller : compiled function with ``CONTROLLER_SIG``
    gains : (G,) or (N, G) array
        The controller's parameters; :attr:`gains` may be written between steps.
    mission : compiled function with ``MISSION_SIG``
    mp : (Mp,) or (N, Mp) array
        The mission's parameters.
    memory, vp_ctrl, disturbance, disturbance_params, disturbance_memory : optional
        As in :func:`~quadcruise.sim.engine.simulate`; the memories are restored by :meth:`reset`.
    seed, first_vehicle : int
        Vehicle i's random stream is seeded from (seed, first_vehicle + i), as in a flight.
    sensor_std : (16,) or (N, 16) array, optional
    sensor_delay : int
        The controller sees the state this many control periods late.
    full_dynamics : bool
    max_step : float
        Longest RK4 substep [s].
    limits : Limits, optional
    periods : int
        Control periods flown per :meth:`step`.
    setpoint_width : int
        Number of leading gains entries that ``step(commands)`` writes (0: the controller
        flies alone, and ``step`` takes no commands).
    alloc : (4 n + 1,) or (N, 4 n + 1) array, optional
        Given, the vehicles fly the rotor plant: the controller vehicle's duty-to-thrust matrix
        and kf, as :func:`~quadcruise.sim.rotor_batch.fly_rotor_vehicles` takes it (``vp_ctrl``
        then required: the equivalent paper row the controller reads; ``full_dynamics`` not used).
    psi0 : float or (N,) array
        Rotor plant: the yaw [rad] the initial quaternion's is read near.
    touchdown_speed : float or (N,) array, optional
        Rotor plant: with it, a ground at z = 0.
    observation : Observation, optional
        The vehicles' sensors and estimator (:mod:`quadcruise.sim.observe`): the controller sees
        their estimate; their memories are restored by :meth:`reset`, their streams drawn again,
        and :attr:`log_obs` holds the step's observation rows.
    """

    def __init__(
        self,
        t_grid,
        x0,
        vp,
        controller,
        gains,
        mission,
        mp,
        *,
        memory=None,
        vp_ctrl=None,
        disturbance=None,
        disturbance_params=None,
        disturbance_memory=None,
        seed: int = 0,
        first_vehicle=0,
        sensor_std=None,
        sensor_delay: int = 0,
        full_dynamics: bool = False,
        max_step: float = 1e-3,
        limits: Limits | None = None,
        periods: int = 1,
        setpoint_width: int = 0,
        alloc=None,
        psi0=0.0,
        touchdown_speed=None,
        observation: Observation | None = None,
    ) -> None:
        if int(periods) != periods or periods < 1:
            raise InputError(f"periods must be a whole number >= 1, got {describe(periods)}")
        shared = dict(
            memory=memory,
            disturbance=disturbance,
            disturbance_params=disturbance_params,
            disturbance_memory=disturbance_memory,
            seed=seed,
            first_vehicle=first_vehicle,
            sensor_std=sensor_std,
            sensor_delay=sensor_delay,
            max_step=max_step,
        )
        self.rotor = alloc is not None  # the plant: the rotor-speed plant's arrays given, or the paper's
        if self.rotor:
            if vp_ctrl is None:
                raise InputError("Stepper: a rotor-plant flight needs vp_ctrl, the controller's equivalent paper row")
            if full_dynamics:
                raise InputError("Stepper: full_dynamics is the paper plant's option, not the rotor plant's")
            inp = rotor_inputs(
                t_grid, x0, vp, alloc, vp_ctrl, gains, mp, psi0=psi0, touchdown_speed=touchdown_speed, **shared
            )
            self.alloc, self.psi0, self.touchdown = inp["alloc"], inp["psi0"], inp["touchdown"]
            self.ground = touchdown_speed is not None
            self.carry = np.zeros((inp["n"], rotor_carry_width(int(sensor_delay))))
            self._paper_state = paper_states(inp["x0"], inp["vp"], self.psi0)  # then written by each step
            self.log_rotor = np.empty((inp["n"], int(periods) + 1, inp["x0"].shape[1]))
        else:
            inp = batch_inputs(t_grid, x0, vp, gains, mp, vp_ctrl=vp_ctrl, **shared)
            self.carry = fresh_carry(inp["x0"], int(sensor_delay))
        self.n = n = inp["n"]
        if not (0 <= int(setpoint_width) <= inp["gains"].shape[1]):
            raise InputError(
                f"setpoint_width must be in 0..{inp['gains'].shape[1]} (the gains' width), "
                f"got {describe(setpoint_width)}"
            )
        self.t_grid = inp["t_grid"]
        self.periods, self.setpoint_width = int(periods), int(setpoint_width)
        self.sensor_delay = int(sensor_delay)
        self.drawn = inp["drawn"]
        self.seed = int(seed)
        self.first_vehicle = (
            np.arange(n) + int(first_vehicle)
            if np.ndim(first_vehicle) == 0
            else np.asarray(first_vehicle, dtype=np.int64).ravel().copy()
        )
        self.vp, self.vp_ctrl, self.mp = inp["vp"], inp["vp_ctrl"], inp["mp"]
        self.gains = inp["gains"]
        self.disturbance_params = inp["disturbance_params"]
        self.sensor_std = inp["sensor_std"]
        self._x0, self._mem0, self._dmem0 = inp["x0"], inp["memory"], inp["disturbance_memory"]
        self.state = self._x0.copy()
        self.memory = self._mem0.copy()
        self.disturbance_memory = self._dmem0.copy()
        self.rng = inp["rng"]
        self.clock = np.zeros((n, 2), dtype=np.int64)
        self.saturated = np.zeros((n, 2))
        self.status = np.zeros(n, dtype=np.int64)
        self.t_stop = np.full(n, np.nan)
        rows = self.periods + 1
        self.log_x = np.empty((n, rows, STATE_SIZE))
        self.log_cmd = np.empty((n, rows, CMD_SIZE))
        self.log_ref = np.empty((n, rows, REF_SIZE))
        self.observation = (observation or Observation.none(n)).take(np.arange(n))  # its own copies
        if self.observation.params.shape[0] != n:
            raise InputError(f"Stepper: observation has {self.observation.params.shape[0]} rows, not {n}")
        self._omem0, self._orng0 = self.observation.memory.copy(), self.observation.rng.copy()
        self.log_obs = self.observation.log(n, rows)
        # the jit functions themselves: numba calls a jit function passed as an argument through
        # its own calling convention, which carries an exception raised in it to the caller
        # (not through its C wrapper, which would print the exception and carry on)
        self.controller, self.mission = controller, mission
        self.disturbance = disturbance or still_air
        self.disturbed = disturbance is not None
        self.full_dynamics, self.max_step = bool(full_dynamics), float(max_step)
        self.limits = (limits or Limits()).array()
        self._plan = ThreadPlan()  # one thread or all, for a step without a watcher

    @property
    def paper_state(self) -> np.ndarray:
        """(N, 16) the state in the paper layout (:data:`quadcruise.layout.STATE_NAMES`): the
        paper plant's state itself; for the rotor plant, position, velocity, the ZYX Euler angles
        of the quaternion, body rates and the thrusts of rotors 1..4
        (:func:`quadcruise.sim.rotor_flight.paper_state`), as of the last step."""
        return self._paper_state if self.rotor else self.state

    @property
    def period(self) -> np.ndarray:
        """(N,) each vehicle's control period index on the grid (0 at a reset)."""
        return self.clock[:, 0]

    @property
    def time(self) -> np.ndarray:
        """(N,) each vehicle's time on the grid [s]."""
        return self.t_grid[self.clock[:, 0]]

    @property
    def done(self) -> np.ndarray:
        """(N,) bool: the vehicle stopped (its status is not FINISHED) or flew its whole grid."""
        return (self.status != int(ExitStatus.FINISHED)) | (self.clock[:, 0] >= self.t_grid.shape[0] - 1)

    def reset(self, mask=None, *, x0=None, rng=None, seed: int | None = None, disturbance_memory=None) -> None:
        """Start some vehicles (or all) again at the grid's first instant.

        Parameters
        ----------
        mask : (N,) bool array, optional
            The vehicles to reset; all by default. The others are not touched.
        x0 : (16,) or (K, 16) array, optional
            Their new initial states (K the vehicles in ``mask``); the constructor's by default.
        rng : (K, 1) uint64 array, optional
            Their new random generator states (:mod:`quadcruise.sim.rng`).
        seed : int, optional
            Without ``rng``: draw their streams from (seed, first_vehicle + i) again; the
            constructor's seed by default.
        disturbance_memory : (K, D) array, optional
            Their disturbance's initial memory (kept for later resets); the constructor's by default.

        Raises
        ------
        InputError
            A mask or an array of the wrong shape, a non-finite x0.
        """
        rows = np.arange(self.n) if mask is None else np.flatnonzero(self.check_mask(mask))
        k = rows.size
        if not k:
            return
        width = self.state.shape[1]
        if x0 is None:
            start = self._x0[rows]
        else:
            start = np.asarray(x0, dtype=float)
            start = np.broadcast_to(start, (k, width)) if start.shape in ((width,), (1, width)) else start
            if start.shape != (k, width) or not np.isfinite(start).all():
                raise InputError(
                    f"reset: x0 must be finite and of shape ({width},) or ({k}, {width}), got {np.shape(x0)}"
                )
        if disturbance_memory is not None:
            dmem = np.asarray(disturbance_memory, dtype=float)
            if dmem.shape != (k, self._dmem0.shape[1]):
                raise InputError(
                    f"reset: disturbance_memory must have shape ({k}, {self._dmem0.shape[1]}), got {dmem.shape}"
                )
            self._dmem0[rows] = dmem
        self.state[rows] = start
        self.memory[rows] = self._mem0[rows]
        self.disturbance_memory[rows] = self._dmem0[rows]
        if rng is not None:
            rng = np.asarray(rng)
            if rng.shape != (k, 1) or rng.dtype != np.uint64:
                raise InputError(f"reset: rng must be a ({k}, 1) uint64 array, got {rng.shape} {rng.dtype}")
            self.rng[rows] = rng
        elif self.drawn:
            self.rng[rows] = vehicle_states(self.seed if seed is None else seed, k, self.first_vehicle[rows])
        self.observation.memory[rows] = self._omem0[rows]
        if self.observation.active:  # the sensors' streams drawn again, as the disturbance's are
            self.observation.rng[rows] = (
                self._orng0[rows] if seed is None else sensor_streams(seed, k, self.first_vehicle[rows])
            )
        self.clock[rows] = 0
        if self.rotor:  # the rotor kernel starts a vehicle at period 0 afresh, its carry unread
            self._paper_state[rows] = paper_states(np.ascontiguousarray(start), self.vp[rows], self.psi0[rows])
        else:
            self.carry[rows] = fresh_carry(np.ascontiguousarray(start), self.sensor_delay)
        self.saturated[rows] = 0.0
        self.status[rows] = int(ExitStatus.FINISHED)
        self.t_stop[rows] = np.nan

    def check_mask(self, mask) -> np.ndarray:
        """The mask as an (N,) bool array, or one InputError line.

        Parameters
        ----------
        mask : array_like
            (N,) bool.

        Returns
        -------
        numpy.ndarray

        Raises
        ------
        InputError
            Not an (N,) bool array.
        """
        mask = np.asarray(mask)
        if mask.shape != (self.n,) or mask.dtype != bool:
            raise InputError(f"reset: mask must be a ({self.n},) bool array, got {mask.shape} {mask.dtype}")
        return mask

    def step(self, commands=None, *, after_piece=None, pieces_per_thread: int = STEP_PIECES_PER_THREAD) -> None:
        """Fly every vehicle that is not :attr:`done` on for :attr:`periods` control periods.

        Parameters
        ----------
        commands : (N, setpoint_width) array, optional
            Written into the first ``setpoint_width`` entries of each vehicle's gains row
            before the step (the setpoint a policy gives its action-mode controller).
        after_piece : callable, optional
            ``after_piece(first, stop)``, on the thread that flew vehicles first..stop-1, right
            after it (:func:`~quadcruise.sim.engine.fly_vehicles`).
        pieces_per_thread : int
            Ranges of vehicles per thread.

        Raises
        ------
        InputError
            Commands of the wrong shape or not finite, or commands to a stepper without setpoints.

        Notes
        -----
        After the step, :attr:`log_x`, :attr:`log_cmd`, :attr:`log_ref` hold, from row 0, the
        state, command and reference at each instant flown (NaN in the rows not flown), and
        :attr:`state` the state reached.
        """
        if commands is not None:
            if not self.setpoint_width:
                raise InputError("step: this stepper's controller takes no commands (setpoint_width is 0)")
            c = np.asarray(commands, dtype=float)
            if c.shape != (self.n, self.setpoint_width):
                raise InputError(f"step: commands must have shape ({self.n}, {self.setpoint_width}), got {c.shape}")
            if not np.isfinite(c).all():
                raise InputError(
                    f"step: commands must be finite (row {int(np.flatnonzero(~np.isfinite(c).all(axis=1))[0])} is not)"
                )
            self.gains[:, : self.setpoint_width] = c
        if after_piece is not None:  # a chunk of a long flight: numba's threads
            self._fly(pieces_per_thread, after_piece, None)
            return
        threads = self._plan.threads()
        start = time.perf_counter()
        try:
            self._fly(pieces_per_thread, None, threads)
        finally:
            self._plan.record(threads, time.perf_counter() - start)

    def _fly(self, pieces_per_thread: int, after_piece, threads) -> None:
        """One step through the plant's kernel, on at most ``threads`` of numba's threads: its
        arguments by name, those of both plants first."""
        shared = dict(
            t_grid=self.t_grid,
            x0=self.state,
            vp_ctrl=self.vp_ctrl,
            controller=self.controller,
            gains=self.gains,
            mem=self.memory,
            mission=self.mission,
            mp=self.mp,
            disturbance=self.disturbance,
            disturbed=self.disturbed,
            dp=self.disturbance_params,
            dmem=self.disturbance_memory,
            rng=self.rng,
            sensor_std=self.sensor_std,
            sensor_delay=self.sensor_delay,
            observer=self.observation.function,
            observed=self.observation.active,
            op=self.observation.params,
            omem=self.observation.memory,
            orng=self.observation.rng,
            max_step=self.max_step,
            log_every=1,
            limits=self.limits,
            n_step=self.periods,
            clock=self.clock,
            carry=self.carry,
            log_x=self.log_x,
            log_cmd=self.log_cmd,
            log_ref=self.log_ref,
            log_obs=self.log_obs,
            x_final=self.state,
            status=self.status,
            t_stop=self.t_stop,
            saturated=self.saturated,
        )
        if self.rotor:
            fly, args = (
                fly_rotor_pieces,
                RotorKernelArgs(
                    **shared,
                    psi0=self.psi0,
                    rp=self.vp,
                    alloc=self.alloc,
                    ground=self.ground,
                    touchdown=self.touchdown,
                    log_rotor=self.log_rotor,
                    seen_final=self._paper_state,
                ),
            )
        else:
            fly, args = fly_vehicles, KernelArgs(**shared, vp=self.vp, full=self.full_dynamics)
        fly(self.n, args, pieces_per_thread, after_piece, threads)


__all__ = ["Stepper"]
