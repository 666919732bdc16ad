"""Tuning speed: ``python benchmarks/tune.py``.

The issue's targets, on a 2-core machine, cold compile excluded (a tiny tune of each kind runs
first and is not timed):

- ``nominal``: the three-target nlpd tune of the README,
  ``quadcruise tune step --controller nlpd --target rise_time_s=1 --target settling_time_s=2
  --target overshoot_pct=4 --seed 1``: under 60 s;
- ``robust``: the same targets over 50 perturbed vehicles (mass and inertia spreads of 10 %,
  Dryden turbulence with a 1 m/s wind at 20 ft through the default drag, 5 mm position
  noise, 1 ms delay), the cost of a candidate the worst of its 50 flights; 20 candidates a
  generation, so a generation is 1,000 vehicles in one batch; a 1 m step at 0.5 s flown for
  6 s: under 5 minutes. (A steady wind leaves a PD loop a steady offset, and the "light"
  level, 7.7 m/s at 20 ft, moves a 1 m step by more than the 2 % band: with either, no gains
  settle every vehicle, and the worst case has no optimum to find.)

Each prints its wall time, the generations and flights, the vehicle-steps per second of the
whole search (flights, metrics and the optimiser), and the gains found. The machine, the load
average at the start and the end, and a speed probe come first and last (other processes on
the machine slow every figure). Options: --quick (a smoke test: small budgets), --json PATH.
"""

from __future__ import annotations

import argparse
import json
import sys
import time
import warnings
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parent))
from machine import end_of_run, machine  # noqa: E402

TARGETS = {"rise_time_s": 1.0, "settling_time_s": 2.0, "overshoot_pct": 4.0}
LIMITS = {"nominal": 60.0, "robust": 300.0}


def robust_population():
    from quadcruise.disturbances import Environment, SensorNoise, Turbulence
    from quadcruise.montecarlo import Population

    return Population(
        mass_spread=0.1,
        inertia_spread=0.1,
        environment=Environment(turbulence=Turbulence(w20=1.0, altitude=10.0)),
        noise=SensorNoise(position_std=0.005, delay=0.001),
    )


def cases(quick: bool) -> dict:
    from quadcruise.missions import Step

    budget = 3 if quick else 100
    return {
        "nominal": dict(mission="step", controller="nlpd", targets=TARGETS, seed=1, budget=budget),
        "robust": dict(
            mission=Step(size=1.0, time=0.5),
            controller="nlpd",
            targets=TARGETS,
            seed=1,
            population=robust_population(),
            samples=5 if quick else 50,
            objective="worst",
            popsize=20,
            duration=6.0,
            budget=budget,
        ),
    }


def warm_up() -> float:
    """A tiny tune of each kind, so that numba's compile (or cache load) is not timed."""
    from quadcruise.tune import tune

    start = time.perf_counter()
    for kw in cases(True).values():
        tune(**{**kw, "budget": 1, "popsize": 5, "duration": 1.0, "samples": min(kw.get("samples", 1), 2)})
    return time.perf_counter() - start


def run(name: str, kw: dict) -> dict:
    from quadcruise.tune import tune

    start = time.perf_counter()
    res = tune(**kw)
    wall = time.perf_counter() - start
    steps = res.info["flights"] * round(res.spec.duration / res.spec.dt)
    return {
        "wall_s": wall,
        "limit_s": LIMITS[name],
        "generations": res.generations,
        "flights": res.info["flights"],
        "vehicle_steps_per_s": steps / wall,
        "gains": res.gains,
        "cost": res.cost,
        "met": res.met,
        "reached": {t.metric: res.reached(t.metric) for t in res.targets},
    }


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--quick", action="store_true", help="small budgets: a smoke test")
    parser.add_argument("--json", type=Path, help="also write the figures here")
    args = parser.parse_args(argv)
    import scipy

    info = machine(scipy=scipy.__version__)
    print(
        f"{info['cpu']}, {info['cores']} cores, numba threads {info['numba_threads']}; "
        f"load average {', '.join(f'{v:.2f}' for v in info['load_avg_start'])}; "
        f"speed probe {info['probe_ns_start']:.0f} ns"
    )
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        info["warm_up_s"] = warm_up()
        results = {}
        for name, kw in cases(args.quick).items():
            r = results[name] = run(name, kw)
            gains = ", ".join(f"{k} {v:.4g}" for k, v in r["gains"].items())
            verdict = (
                ""
                if args.quick
                else f" (target < {r['limit_s']:.0f} s: {'met' if r['wall_s'] < r['limit_s'] else 'MISSED'})"
            )
            print(
                f"{name}: {r['wall_s']:.1f} s{verdict}; {r['generations']} generations, {r['flights']:,} flights, "
                f"{r['vehicle_steps_per_s'] / 1e6:.2f} M vehicle-steps/s; {gains}; cost {r['cost']:.3g}"
            )
    print(end_of_run(info))
    if args.json:
        args.json.write_text(json.dumps({"machine": info, "quick": args.quick, "results": results}, indent=2))
    return 0


if __name__ == "__main__":
    sys.exit(main())
