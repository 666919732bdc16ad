"""Scoring a policy, or a built-in controller as a baseline policy, in the same environment:
by the environment's reward and by the project's own flight metrics.

Examples
--------
>>> import numpy as np
>>> from quadcruise.gym.env import QuadVectorEnv
>>> returns, flights = rollout(QuadVectorEnv(2, mission="hover", controller="nlpd", duration=1.0), seed=1)
>>> returns.shape, flights.states.shape, flights.ok.tolist()
((2,), (2, 101, 16), [True, True])
"""

from __future__ import annotations

from collections.abc import Callable

import numpy as np
import pandas as pd

from quadcruise.control.registry import baseline_names
from quadcruise.errors import InputError
from quadcruise.gym.env import QuadVectorEnv
from quadcruise.layout import CMD_SIZE, REF_SIZE, STATE_SIZE
from quadcruise.sim.result import SimResult

BASELINES = ("nlpd", "gonzalez", "se3", "cascade")
"""The built-in controllers flown as baseline policies (with any declared since with
``baseline=True``: :func:`quadcruise.control.registry.baseline_names`)."""


def rollout(env: QuadVectorEnv, policy: Callable | None = None, *, seed: int = 0) -> tuple[np.ndarray, SimResult]:
    """One episode of every vehicle of ``env``, from ``env.reset(seed=seed)`` to its end."""
    if not isinstance(env, QuadVectorEnv):
        env = getattr(env, "unwrapped", env)
    if (policy is None) != (env.baseline is not None):
        raise InputError("rollout: give a policy, or an environment made with controller=, not both or neither")
    obs, _ = env.reset(seed=seed)
    s, n = env.stepper, env.num_envs
    length = s.t_grid.shape[0]
    states = np.full((n, length, STATE_SIZE), np.nan)
    commands = np.full((n, length, CMD_SIZE), np.nan)
    refs = np.full((n, length, REF_SIZE), np.nan)
    states[:, 0] = s.paper_state
    returns = np.zeros(n)
    alive = np.ones(n, dtype=bool)
    status, t_stop, final = np.zeros(n, dtype=np.int64), np.full(n, s.t_grid[-1]), s.paper_state.copy()
    for k in range(length - 1):
        obs, reward, terminated, truncated, info = env.step(None if policy is None else policy(obs))
        returns[alive] += reward[alive]
        commands[alive, k] = s.log_cmd[alive, 0]
        refs[alive, k] = s.log_ref[alive, 0]
        states[alive, k + 1] = s.paper_state[alive]
        if k == length - 2:  # the last instant's reference and command
            commands[alive, k + 1] = s.log_cmd[alive, 1]
            refs[alive, k + 1] = s.log_ref[alive, 1]
        ended = alive & (terminated | truncated)  # as they ended: the next step restarts them
        status[ended], final[ended] = info["status"][ended], s.paper_state[ended]
        t_stop[ended & terminated] = s.t_stop[ended & terminated]
        alive &= ~ended
        if not alive.any():
            break
    meta = {
        "workflow": "gym",
        "mission": env.mission.to_dict(),
        "dt_s": env.dt,
        "seed": seed,
        "n": n,
        "controller": {"name": env.baseline.name} if env.baseline is not None else {"name": "policy"},
    }
    result = SimResult(
        t=s.t_grid.copy(),
        states=states,
        commands=commands,
        references=refs,
        final_state=final,
        status=status,
        t_stop=t_stop,
        memory=s.memory.copy(),
        duty_clipped_s=s.saturated[:, 0].copy(),
        controller_limited_s=s.saturated[:, 1].copy(),
        meta=meta,
        disturbance_memory=s.disturbance_memory.copy(),
    )
    return returns, result


def baselines(
    controllers=None, *, env_id: str = "quadcruise/Hover-v0", num_envs: int = 8, seed: int = 0, **env_kwargs
) -> pd.DataFrame:
    """Each built-in controller flown as a policy in the same environment, scored by the
    environment's return and by the project's flight metrics (their mean over the vehicles).

    The environment is the registered ``env_id``'s, its defaults included (Hover-v0's start
    offset of 0.3 m, Track-v0's circle), as ``gymnasium.make_vec(env_id, ...)`` makes it: the
    numbers a policy trained there is compared with.

    Parameters
    ----------
    controllers : sequence of str or Controller, optional
        The controllers; by default every one declared ``baseline=True``
        (:func:`quadcruise.control.registry.baseline_names`).
    env_id : str
        The registered environment (``"quadcruise/Hover-v0"`` or ``"quadcruise/Track-v0"``)
        whose keywords are the defaults.
    num_envs : int
        Vehicles per controller (the same episodes: the same seed).
    seed : int
        The episodes' seed.
    **env_kwargs
        Keywords of :class:`QuadVectorEnv` (mission, vehicle, dt, population, ...) that
        change the environment's (``population=None``: no domain randomisation).

    Returns
    -------
    pandas.DataFrame
        One row per controller: ``mean_return``, ``mean_reward`` (the return over the episode's
        periods: the same scale at any episode length or ``dt``), ``finished`` (the share of
        vehicles that flew the whole episode), and the mean of each numeric column of
        ``SimResult.metrics()``.
    """
    import gymnasium

    try:
        registered = dict(gymnasium.spec(env_id).kwargs) if isinstance(env_id, str) else None
    except gymnasium.error.Error:
        registered = None
    if registered is None:
        raise InputError(f"baselines(): env_id {env_id!r} is not a registered environment; quadcruise/Hover-v0 or "
                         "quadcruise/Track-v0")  # fmt: skip
    rows = []
    for controller in baseline_names() if controllers is None else controllers:
        env = QuadVectorEnv(num_envs, controller=controller, **{**registered, **env_kwargs})
        returns, flights = rollout(env, seed=seed)
        table = flights.metrics()
        periods = env.stepper.t_grid.shape[0] - 1
        row = {
            "controller": env.baseline.name,
            "mean_return": float(returns.mean()),
            "mean_reward": float(returns.mean() / periods),
            "finished": float(np.mean(flights.status == 0)),
        }
        row.update(table.select_dtypes("number").drop(columns=["vehicle"], errors="ignore").mean().to_dict())
        rows.append(row)
    return pd.DataFrame(rows).set_index("controller")


__all__ = ["BASELINES", "baselines", "rollout"]
