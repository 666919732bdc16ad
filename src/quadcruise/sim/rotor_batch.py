"""The inputs of a batch of rotor-plant flights checked and packed, and the batch flown and
gathered into a :class:`~quadcruise.sim.result.SimResult`, around the compiled kernel of
:mod:`quadcruise.sim.rotor_flight`."""

from __future__ import annotations

import numpy as np

from quadcruise.checks import describe
from quadcruise.errors import InputError
from quadcruise.layout import CMD_SIZE, REF_SIZE, STATE_SIZE
from quadcruise.model.rotor_plant import ROTOR_P_N_ROTORS, ROTOR_W1
from quadcruise.sim.engine import still_air
from quadcruise.sim.inputs import Limits, batch_inputs
from quadcruise.sim.kernel_args import RotorKernelArgs
from quadcruise.sim.observe import Observation
from quadcruise.sim.result import SimResult
from quadcruise.sim.rotor_flight import fly_rotor_pieces, rotor_carry_width
from quadcruise.sim.track_figures import track_arrays


def rotor_inputs(
    t_grid,
    x0,
    rp,
    alloc,
    vp_ctrl,
    gains,
    mp,
    *,
    psi0=0.0,
    memory=None,
    disturbance=None,
    disturbance_params=None,
    disturbance_memory=None,
    seed: int = 0,
    first_vehicle=0,
    sensor_std=None,
    sensor_delay: int = 0,
    max_step: float = 1e-3,
    log_every: int = 1,
    touchdown_speed=None,
) -> dict:
    """The rotor kernel's batch arrays, checked and broadcast to one row per vehicle (for
    :func:`fly_rotor_vehicles` and :class:`quadcruise.sim.stepper.Stepper`).

    Parameters
    ----------
    t_grid, x0, rp, alloc, vp_ctrl, gains, mp : array_like
        As in :func:`fly_rotor_vehicles`.
    psi0, memory, disturbance, disturbance_params, disturbance_memory, seed, first_vehicle : optional
        As in :func:`fly_rotor_vehicles`.
    sensor_std, sensor_delay, max_step, log_every, touchdown_speed : optional
        As in :func:`fly_rotor_vehicles`.

    Returns
    -------
    dict
        :func:`quadcruise.sim.inputs.batch_inputs`'s arrays for the rotor plant: ``vp`` the rotor
        rows ``rp``, ``vp_ctrl`` the controller's paper row, ``x0`` the rotor states; and ``alloc``,
        ``psi0``, ``touchdown`` (inf without a ground) as C-ordered rows, ``n_rotors``.

    Raises
    ------
    InputError
        Arrays whose shapes do not fit, a bad grid, step or touchdown speed.
    """
    rp = np.array(np.atleast_2d(np.asarray(rp, dtype=float)), order="C")
    n_vehicles = rp.shape[0]
    n = int(rp[0, ROTOR_P_N_ROTORS])
    if np.any(rp[:, ROTOR_P_N_ROTORS] != n):
        raise InputError("the vehicles of one flight must have the same number of rotors")
    x0 = np.array(np.broadcast_to(np.atleast_2d(np.asarray(x0, dtype=float)), (n_vehicles, ROTOR_W1 + n)), order="C")
    if not np.all(np.isfinite(x0)):
        raise InputError("the initial state must be finite")
    alloc = np.array(np.broadcast_to(np.atleast_2d(np.asarray(alloc, dtype=float)), (n_vehicles, 4 * n + 1)), order="C")
    psi0 = np.array(np.broadcast_to(np.asarray(psi0, dtype=float), (n_vehicles,)), order="C")
    seen0 = np.zeros((n_vehicles, STATE_SIZE))  # only its shape is checked
    inp = batch_inputs(
        t_grid,
        seen0,
        np.array(np.broadcast_to(np.atleast_2d(np.asarray(vp_ctrl, dtype=float)), (n_vehicles, np.shape(vp_ctrl)[-1]))),
        gains,
        mp,
        memory=memory,
        disturbance=disturbance,
        disturbance_params=disturbance_params,
        disturbance_memory=disturbance_memory,
        seed=seed,
        first_vehicle=first_vehicle,
        sensor_std=sensor_std,
        sensor_delay=sensor_delay,
        max_step=max_step,
        log_every=log_every,
    )
    touchdown = np.array(np.broadcast_to(np.inf if touchdown_speed is None else touchdown_speed, (n_vehicles,)), float)
    if touchdown_speed is not None and not np.all(touchdown > 0):
        raise InputError(f"touchdown speed must be > 0 m/s, got {describe(touchdown_speed)}")
    inp["vp_ctrl"], inp["vp"], inp["x0"] = inp["vp"], rp, x0  # the paper rows checked: the controller's
    inp.update(alloc=alloc, psi0=psi0, touchdown=touchdown, n_rotors=n)
    return inp


def fly_rotor_vehicles(
    t_grid,
    x0,
    rp,
    alloc,
    vp_ctrl,
    controller,
    gains,
    mission,
    mp,
    *,
    psi0=0.0,
    memory=None,
    disturbance=None,
    disturbance_params=None,
    disturbance_memory=None,
    seed: int = 0,
    first_vehicle=0,
    sensor_std=None,
    sensor_delay: int = 0,
    max_step: float = 1e-3,
    log_every: int = 1,
    limits: Limits | None = None,
    touchdown_speed=None,
    rotor_names: tuple[str, ...] = (),
    meta: dict | None = None,
    track: tuple | None = None,
    observation: Observation | None = None,
) -> SimResult:
    """Fly N rotor-plant vehicles closed loop and return a :class:`SimResult` in the paper layout.

    The array-level entry point that :func:`quadcruise.fly` builds on for a
    :class:`~quadcruise.model.rotor_vehicle.RotorVehicle`.

    Parameters
    ----------
    t_grid : (M+1,) array
        Strictly increasing control instants [s].
    x0 : (13 + n,) or (N, 13 + n) array
        Initial rotor states (:mod:`quadcruise.model.rotor_plant`), quaternions of unit length.
    rp : (P,) or (N, P) array
        The flown vehicles' parameter rows (:meth:`~quadcruise.model.rotor_vehicle.RotorVehicle.row`).
    alloc : (4 n + 1,) or (N, 4 n + 1) array
        The controller vehicle's duty-to-thrust matrix (:func:`quadcruise.model.equivalent.duty_to_thrust`)
        row by row, then its kf [N/(rad/s)^2].
    vp_ctrl : (PARAM_SIZE,) or (N, PARAM_SIZE) array
        The paper-layout row the controller reads (its equivalent vehicle's).
    controller : compiled function with ``CONTROLLER_SIG``
    gains : (G,) or (N, G) array
    mission : compiled function with ``MISSION_SIG``
    mp : (Mp,) or (N, Mp) array
    psi0 : float or (N,) array
        The yaw [rad] the initial quaternion's is read near (a mission's initial yaw may lie
        beyond pi).
    memory, disturbance, disturbance_params, disturbance_memory, seed, first_vehicle : optional
        As in :func:`quadcruise.simulate`.
    sensor_std, sensor_delay, max_step, log_every, limits : optional
        As in :func:`quadcruise.simulate` (``limits.max_tilt`` bounds the angle between body z
        and world z).
    touchdown_speed : float or (N,) array, optional
        With it, a ground at z = 0 (:func:`quadcruise.sim.rotor_engine.ground_contact`).
    rotor_names : tuple of str
        The rotor state's column names (:func:`quadcruise.model.rotor_plant.state_names`).
    meta : dict, optional
        Recorded in the result.
    track : tuple of numpy.ndarray, optional
        ``(rows, plan)``: the track checks' figures and plan, as in :func:`quadcruise.simulate`.
    observation : Observation, optional
        The vehicles' sensors and estimator, as :func:`quadcruise.simulate` takes them.

    Returns
    -------
    SimResult
        Paper-layout states, commands and references, with ``rotor_states`` and ``rotor_names``.

    Raises
    ------
    InputError
        Arrays whose shapes do not fit, a bad grid, step or touchdown speed.
    """
    inp = rotor_inputs(
        t_grid,
        x0,
        rp,
        alloc,
        vp_ctrl,
        gains,
        mp,
        psi0=psi0,
        memory=memory,
        disturbance=disturbance,
        disturbance_params=disturbance_params,
        disturbance_memory=disturbance_memory,
        seed=seed,
        first_vehicle=first_vehicle,
        sensor_std=sensor_std,
        sensor_delay=sensor_delay,
        max_step=max_step,
        log_every=log_every,
        touchdown_speed=touchdown_speed,
    )
    n_vehicles, n, t_grid = inp["vp"].shape[0], inp["n_rotors"], inp["t_grid"]
    limits = limits or Limits()
    n_periods = t_grid.shape[0] - 1
    n_log = n_periods // log_every + 1
    log_x = np.empty((n_vehicles, n_log, STATE_SIZE))
    log_rotor = np.empty((n_vehicles, n_log, ROTOR_W1 + n))
    log_cmd = np.empty((n_vehicles, n_log, CMD_SIZE))
    log_ref = np.empty((n_vehicles, n_log, REF_SIZE))
    x_final = np.empty((n_vehicles, ROTOR_W1 + n))
    seen_final = np.empty((n_vehicles, STATE_SIZE))
    status = np.zeros(n_vehicles, dtype=np.int64)
    t_stop = np.empty(n_vehicles)
    saturated = np.zeros((n_vehicles, 2))
    mem, dmem = inp["memory"], inp["disturbance_memory"]
    track_rows, track_plan = track_arrays(track, n_vehicles)
    obs = (observation or Observation.none(n_vehicles)).take(np.arange(n_vehicles))  # copies
    log_obs = obs.log(n_vehicles, n_log)
    fly_rotor_pieces(
        n_vehicles,
        RotorKernelArgs(
            t_grid=t_grid,
            x0=inp["x0"],
            psi0=inp["psi0"],
            rp=inp["vp"],
            alloc=inp["alloc"],
            vp_ctrl=inp["vp_ctrl"],
            controller=controller,
            gains=inp["gains"],
            mem=mem,
            mission=mission,
            mp=inp["mp"],
            disturbance=disturbance or still_air,
            disturbed=inp["disturbed"],
            dp=inp["disturbance_params"],
            dmem=dmem,
            rng=inp["rng"],
            sensor_std=inp["sensor_std"],
            sensor_delay=int(sensor_delay),
            observer=obs.function,
            observed=obs.active,
            op=obs.params,
            omem=obs.memory,
            orng=obs.rng,
            max_step=float(max_step),
            log_every=int(log_every),
            limits=limits.array(),
            ground=touchdown_speed is not None,
            touchdown=inp["touchdown"],
            n_step=n_periods,
            clock=np.zeros((n_vehicles, 2), dtype=np.int64),
            carry=np.empty((n_vehicles, rotor_carry_width(sensor_delay))),
            track=track_rows,
            track_plan=track_plan,
            log_x=log_x,
            log_rotor=log_rotor,
            log_cmd=log_cmd,
            log_ref=log_ref,
            log_obs=log_obs,
            x_final=x_final,
            seen_final=seen_final,
            status=status,
            t_stop=t_stop,
            saturated=saturated,
        ),
    )
    return SimResult(
        t=t_grid[::log_every][:n_log].copy(),
        states=log_x,
        commands=log_cmd,
        references=log_ref,
        final_state=seen_final,
        status=status,
        t_stop=t_stop,
        memory=mem,
        disturbance_memory=dmem,
        duty_clipped_s=saturated[:, 0].copy(),
        controller_limited_s=saturated[:, 1].copy(),
        meta=dict(meta or {}),
        rotor_states=log_rotor,
        rotor_final_state=x_final,
        rotor_names=tuple(rotor_names),
        observations=log_obs if obs.active else None,
    )


__all__ = ["fly_rotor_vehicles", "rotor_inputs"]
