"""Gymnasium throughput: ``python benchmarks/gym.py`` (``--quick``: a smoke test; ``--json PATH``).

Random actions at ``num_envs=1024`` through ``gymnasium.make_vec(..., vectorization_mode=
"vector_entry_point")`` (autoreset included: random actions crash vehicles, which restart), in
env-steps per second, against the batched ``fly`` of the same 1,024 vehicles at the same control
period (100 Hz, hover, nlpd) in vehicle-steps per second, measured in the same process in
alternating rounds. Targets (issue 25): >= 1e6 env-steps/s, and >= 0.15 x the fly rate.

The rotor-plant row: the Crazyflie (``vehicle="crazyflie"``, the rotor-speed plant) in the
``rotors`` mode with random actions, against the batched rotor-plant ``fly`` of the same vehicles
(hover, se3, 100 Hz), in the same rounds. Reported, no target (the issues set none for it).
"""

from __future__ import annotations

import argparse
import json
import os
import sys
import time

import numpy as np

TARGET_RATE = 1.0e6
TARGET_RATIO = 0.15


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--quick", action="store_true", help="small sizes: a smoke test, no targets checked")
    ap.add_argument("--json", help="also write the figures here")
    ap.add_argument("--num-envs", type=int, default=1024)
    ap.add_argument("--rounds", type=int, default=5)
    args = ap.parse_args(argv)
    import gymnasium

    import quadcruise as qc
    import quadcruise.gym  # registers the environments

    n = 64 if args.quick else args.num_envs
    steps = 20 if args.quick else 200
    rounds = 2 if args.quick else args.rounds
    rng = np.random.default_rng(0)
    out: dict = {"num_envs": n, "steps_per_call": steps, "rounds": rounds, "load_start": os.getloadavg(), "modes": {}}
    envs = {
        mode: gymnasium.make_vec(
            "quadcruise/Hover-v0", num_envs=n, vectorization_mode="vector_entry_point", action=mode
        )
        for mode in ("rotors", "rates", "attitude", "velocity")
    }
    rotor_env = gymnasium.make_vec(
        "quadcruise/Hover-v0", num_envs=n, vectorization_mode="vector_entry_point", action="rotors", vehicle="crazyflie"
    )
    for env in [*envs.values(), rotor_env]:
        env.reset(seed=0)
        env.step(env.action_space.sample())  # load the compiled code
    qc.fly("hover", "nlpd", n=n, dt=0.01, duration=0.1)
    qc.fly("hover", "se3", vehicle="crazyflie", n=n, dt=0.01, duration=0.1)
    fly_best, env_best = 0.0, dict.fromkeys(envs, 0.0)
    rotor_fly_best = rotor_env_best = 0.0
    for _ in range(rounds):
        t = time.perf_counter()
        qc.fly("hover", "nlpd", n=n, dt=0.01, duration=steps * 0.01)
        fly_best = max(fly_best, n * steps / (time.perf_counter() - t))
        for mode, env in envs.items():
            actions = rng.uniform(-1.0, 1.0, (steps, n, 4)).astype(np.float32)
            t = time.perf_counter()
            for k in range(steps):
                env.step(actions[k])
            env_best[mode] = max(env_best[mode], n * steps / (time.perf_counter() - t))
        t = time.perf_counter()
        qc.fly("hover", "se3", vehicle="crazyflie", n=n, dt=0.01, duration=steps * 0.01)
        rotor_fly_best = max(rotor_fly_best, n * steps / (time.perf_counter() - t))
        actions = rng.uniform(-1.0, 1.0, (steps, n, 4)).astype(np.float32)
        t = time.perf_counter()
        for k in range(steps):
            rotor_env.step(actions[k])
        rotor_env_best = max(rotor_env_best, n * steps / (time.perf_counter() - t))
    out["fly_rate"] = fly_best
    out["load_end"] = os.getloadavg()
    print(
        f"num_envs = {n}, {steps} steps a call, best of {rounds} rounds; load average "
        f"{out['load_start'][0]:.1f} at the start, {out['load_end'][0]:.1f} at the end"
    )
    print(f"batched fly (hover, nlpd, 100 Hz): {fly_best / 1e6:.3f} M vehicle-steps/s")
    ok = True
    for mode, rate in env_best.items():
        ratio = rate / fly_best
        out["modes"][mode] = {"rate": rate, "ratio_to_fly": ratio}
        verdict = "" if args.quick else (" ok" if rate >= TARGET_RATE and ratio >= TARGET_RATIO else " BELOW TARGET")
        ok = ok and (args.quick or (rate >= TARGET_RATE and ratio >= TARGET_RATIO))
        print(f"  {mode:9s} random actions: {rate / 1e6:.3f} M env-steps/s, {ratio:.2f} x fly{verdict}")
    out["rotor_plant"] = {
        "vehicle": "crazyflie",
        "mode": "rotors",
        "rate": rotor_env_best,
        "fly_rate": rotor_fly_best,
        "ratio_to_rotor_fly": rotor_env_best / rotor_fly_best,
        "ratio_to_paper_env": rotor_env_best / env_best["rotors"],
    }
    print(f"batched fly, rotor plant (crazyflie, hover, se3, 100 Hz): {rotor_fly_best / 1e6:.3f} M vehicle-steps/s")
    print(
        f"  crazyflie rotors random actions: {rotor_env_best / 1e6:.3f} M env-steps/s, "
        f"{rotor_env_best / rotor_fly_best:.2f} x its fly, "
        f"{rotor_env_best / env_best['rotors']:.2f} x the paper plant's"
    )
    if args.json:
        with open(args.json, "w") as f:
            json.dump(out, f, indent=2)
    return 0 if ok else 1


if __name__ == "__main__":
    sys.exit(main())
