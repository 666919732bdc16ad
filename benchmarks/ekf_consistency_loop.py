"""The EKF in the loop over a Monte Carlo (issue 35): 500 vehicles flying the circle on the
filter's estimate, the run-averaged NEES of position, velocity and attitude and each stream's NIS
at every logged instant against the chi-square 95 % bounds, the sweep's own verdict, and a figure.

    python benchmarks/ekf_consistency_loop.py                   # 500 flights of 10 s, about a minute
    python benchmarks/ekf_consistency_loop.py --runs 100 --figure nees_loop.png

Sensors, filter and flight: tests/integration/test_estimator_consistency.py's (imported from
there, so that the two cannot drift apart).
"""

from __future__ import annotations

import argparse
import sys
import time
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parents[1] / "tests" / "integration"))

from test_estimator_consistency import DOF, batch, run_averages, sweep  # noqa: E402

from quadcruise.estimation import average_bounds  # noqa: E402


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--runs", type=int, default=500)
    parser.add_argument("--figure", default="ekf_consistency_loop.png")
    args = parser.parse_args()
    start = time.perf_counter()
    result = batch(args.runs)
    took = time.perf_counter() - start
    avg = run_averages(result)
    print(f"{args.runs} flights of 10 s on the EKF, batched, in {took:.1f} s; finished: {int(result.ok.sum())}")
    print(f"{'quantity':12} {'dof':>3} {'mean':>7} {'95% bounds':>17} {'instants inside':>16}")
    for name, v in avg.items():
        lo, hi = average_bounds(DOF[name], args.runs)
        v = v[np.isfinite(v)]
        print(f"{name:12} {DOF[name]:3d} {v.mean():7.3f}   [{lo:6.3f}, {hi:6.3f}] {np.mean((v > lo) & (v < hi)):15.1%}")
    print(sweep(args.runs).summary_text().split("  filter consistency")[-1].join(["  filter consistency", ""]))
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    t = result.t[1:]
    fig, axes = plt.subplots(len(avg), 1, figsize=(8, 1.7 * len(avg)), sharex=True)
    for ax, (name, v) in zip(axes, avg.items(), strict=True):
        lo, hi = average_bounds(DOF[name], args.runs)
        ax.plot(t, v, lw=0.8)
        ax.axhline(lo, color="k", ls="--", lw=0.8)
        ax.axhline(hi, color="k", ls="--", lw=0.8)
        ax.set_ylabel(name)
    axes[-1].set_xlabel("t [s] (logged every 20 ms; a NIS: its stream's last update)")
    fig.suptitle(f"EKF in the loop: run-averaged NEES and NIS over {args.runs} flights, chi-square 95 % bounds")
    fig.tight_layout()
    fig.savefig(args.figure, dpi=110)
    print(f"wrote {args.figure}")


if __name__ == "__main__":
    main()
