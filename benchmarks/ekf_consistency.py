"""The EKF's consistency over many Monte Carlo runs (the slow test's, with more runs): the
run-averaged NEES of position, velocity and attitude and every update's NIS against the
chi-square 95 % bounds, and a figure of them over time.

    python benchmarks/ekf_consistency.py                 # 500 runs of 30 s, about 1-2 minutes
    python benchmarks/ekf_consistency.py --runs 100 --figure nees.png

The flight: ``quadcruise.estimation.tilted_circle``; sensors and filter settings: those of
tests/integration/test_ekf.py (imported from there, so that the two cannot drift apart).
"""

from __future__ import annotations

import argparse
import sys
import time
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parents[1] / "tests" / "integration"))

from test_ekf import DOF, matched, monte_carlo  # noqa: E402

from quadcruise.estimation import average_bounds  # noqa: E402


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--runs", type=int, default=500)
    parser.add_argument("--duration", type=float, default=30.0)
    parser.add_argument("--figure", default="ekf_consistency.png")
    args = parser.parse_args()
    start = time.perf_counter()
    avg = monte_carlo(matched(), args.runs, duration=args.duration)
    took = time.perf_counter() - start
    print(f"{args.runs} runs of {args.duration:g} s in {took:.1f} s")
    print(f"{'quantity':10} {'dof':>3} {'mean':>7} {'95% bounds':>17} {'instants inside':>16}")
    for name, v in avg.items():
        lo, hi = average_bounds(DOF[name], args.runs)
        inside = np.mean((v > lo) & (v < hi))
        print(f"{name:10} {DOF[name]:3d} {v.mean():7.3f}   [{lo:6.3f}, {hi:6.3f}] {inside:15.1%}")
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    fig, axes = plt.subplots(len(avg), 1, figsize=(8, 2 * len(avg)), sharex=False)
    for ax, (name, v) in zip(axes, avg.items(), strict=True):
        lo, hi = average_bounds(DOF[name], args.runs)
        ax.plot(v, lw=0.8)
        ax.axhline(lo, color="k", ls="--", lw=0.8)
        ax.axhline(hi, color="k", ls="--", lw=0.8)
        ax.set_ylabel(name)
    axes[-1].set_xlabel("sample (NEES: every 0.1 s; NIS: every update)")
    fig.suptitle(f"run-averaged NEES and NIS over {args.runs} runs, chi-square 95 % bounds")
    fig.tight_layout()
    fig.savefig(args.figure, dpi=110)
    print(f"wrote {args.figure}")


if __name__ == "__main__":
    main()
