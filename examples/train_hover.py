"""Train a hover policy in ``quadcruise/Hover-v0`` and set it beside nlpd.

    pip install 'quadcruise[train]'           # gymnasium and cma (CMA-ES), no deep-learning stack
    python examples/train_hover.py --out train-out

The policy is linear in the observation, squashed: ``action = tanh(W obs + b)`` (88
parameters), in the ``attitude`` action mode. CMA-ES (the ``cma`` library) searches W and b;
each generation is one batched episode of the vector environment: every candidate flies the same
``--repeats`` vehicles (the same draws: the seed is the generation's), all at once, so a
generation is one ``make_vec`` rollout of ``popsize x repeats`` vehicles. The fitness is the
mean reward per period (docs/gym.md). It stops at ``--target`` or after ``--generations``.

Written to ``--out``: ``learning_curve.png`` (mean reward of the generation's mean and best
candidate against env-steps), ``policy.npz`` (W, b), ``evaluation.csv`` (the trained policy and
nlpd on the same 16 unseen episodes: mean reward and the project's flight metrics).
"""

from __future__ import annotations

import argparse
import sys
import time
from pathlib import Path

import numpy as np


def linear_policy(params: np.ndarray, obs_size: int = 21) -> tuple[np.ndarray, np.ndarray]:
    """(W, b) of a flat parameter vector: W (4, obs_size), b (4,)."""
    return params[: 4 * obs_size].reshape(4, obs_size), params[4 * obs_size :]


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description="CMA-ES on a linear hover policy in quadcruise/Hover-v0")
    ap.add_argument("--out", type=Path, default=Path("train-out"))
    ap.add_argument("--generations", type=int, default=80)
    ap.add_argument("--popsize", type=int, default=24)
    ap.add_argument("--repeats", type=int, default=4, help="vehicles (episodes) per candidate and generation")
    ap.add_argument("--target", type=float, default=0.85, help="stop when the mean candidate reaches it")
    ap.add_argument("--seed", type=int, default=1)
    args = ap.parse_args(argv)
    try:
        import cma
        import gymnasium
    except ImportError as err:
        print(f"error: {err.name} is missing: pip install 'quadcruise[train]'", file=sys.stderr)
        return 2
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    import quadcruise.gym  # registers the environments
    from quadcruise.gym.evaluate import baselines, rollout

    args.out.mkdir(parents=True, exist_ok=True)
    n = args.popsize * args.repeats
    env = gymnasium.make_vec(
        "quadcruise/Hover-v0", num_envs=n, vectorization_mode="vector_entry_point", action="attitude"
    )
    periods = env.stepper.t_grid.shape[0] - 1
    obs_size = env.single_observation_space.shape[0]
    es = cma.CMAEvolutionStrategy(
        np.zeros(4 * obs_size + 4), 0.1, {"popsize": args.popsize, "seed": args.seed, "verbose": -9}
    )
    curve, steps, start = [], 0, time.perf_counter()
    for gen in range(args.generations):
        candidates = np.array(es.ask())
        W = np.repeat(np.stack([linear_policy(c, obs_size)[0] for c in candidates]), args.repeats, axis=0)
        b = np.repeat(np.stack([linear_policy(c, obs_size)[1] for c in candidates]), args.repeats, axis=0)

        def policy(obs, W=W, b=b):
            return np.tanh(np.einsum("nij,nj->ni", W, obs) + b).astype(np.float32)

        returns, _ = rollout(env, policy, seed=args.seed * 100_000 + gen)
        reward = returns.reshape(args.popsize, args.repeats).mean(axis=1) / periods
        es.tell(list(candidates), list(-reward))
        steps += n * periods
        curve.append((steps, float(reward.mean()), float(reward.max())))
        print(
            f"generation {gen + 1:3d}: {steps / 1e6:6.2f} M env-steps, mean reward {reward.mean():.3f}, "
            f"best {reward.max():.3f}, {time.perf_counter() - start:6.1f} s",
            flush=True,
        )
        if reward.mean() >= args.target:
            break
    W, b = linear_policy(np.asarray(es.result.xfavorite), obs_size)
    np.savez(args.out / "policy.npz", W=W, b=b)
    data = np.array(curve)
    fig, ax = plt.subplots(figsize=(6, 3.5))
    ax.plot(data[:, 0] / 1e6, data[:, 1], label="generation mean")
    ax.plot(data[:, 0] / 1e6, data[:, 2], label="best candidate")
    ax.set(xlabel="env-steps [M]", ylabel="mean reward per period", title="CMA-ES, linear policy, Hover-v0")
    ax.grid(True, alpha=0.3)
    ax.legend()
    fig.tight_layout()
    fig.savefig(args.out / "learning_curve.png", dpi=120)

    # the trained policy and nlpd on the same 16 unseen episodes
    test = quadcruise.gym.QuadVectorEnv(
        16, mission="hover", action="attitude", population=quadcruise.gym.HOVER_POPULATION
    )
    returns, flights = rollout(test, lambda obs: np.tanh(obs @ W.T + b).astype(np.float32), seed=999)
    table = flights.metrics().select_dtypes("number").drop(columns=["vehicle"], errors="ignore").mean()
    row = {"mean_reward": returns.mean() / periods, "finished": float(np.mean(flights.status == 0)), **table.to_dict()}
    import pandas as pd

    both = pd.concat(
        [
            pd.DataFrame([row], index=["linear policy (CMA-ES)"]),
            baselines(
                ("nlpd",), num_envs=16, seed=999, mission="hover", population=quadcruise.gym.HOVER_POPULATION
            ).drop(columns=["mean_return"]),
        ]
    )
    both.to_csv(args.out / "evaluation.csv")
    cols = [c for c in ("mean_reward", "finished", "rmse_m", "max_error_m", "steady_rmse_m") if c in both]
    print(both[cols].to_string(float_format=lambda v: f"{v:.4f}"))
    print(f"{steps / 1e6:.2f} M env-steps in {time.perf_counter() - start:.0f} s; written to {args.out}/")
    return 0


if __name__ == "__main__":
    sys.exit(main())
