"""The px4 controller's batch speed against se3's: vehicle-steps/s of a 2,000-vehicle circle
on the Iris (rotor plant), after a warm-up flight compiles both.

Run: ``python benchmarks/px4_batch.py [N] [DURATION]`` (defaults 2000 and 10 s).
"""

from __future__ import annotations

import sys
import time
import warnings

import quadcruise as qc


def main(n: int = 2000, duration: float = 10.0) -> None:
    warnings.simplefilter("ignore")
    for name in ("se3", "px4"):
        qc.fly("circle", name, vehicle="iris", n=2, duration=0.5)  # compile
    rates = {}
    for name in ("se3", "px4", "se3", "px4"):
        t0 = time.perf_counter()
        res = qc.fly("circle", name, vehicle="iris", n=n, duration=duration)
        wall = time.perf_counter() - t0
        steps = n * round(duration / 0.001)
        rates.setdefault(name, []).append(steps / wall)
        print(f"{name}: {wall:.2f} s, {steps / wall:.3g} vehicle-steps/s, {res.status_text()[:40]}")
    best = {k: max(v) for k, v in rates.items()}
    print(f"px4 / se3 = {best['px4'] / best['se3']:.2f} (best of two each)")


if __name__ == "__main__":
    main(*(int(sys.argv[1]),) if len(sys.argv) > 1 else (), *(float(sys.argv[2]),) if len(sys.argv) > 2 else ())
