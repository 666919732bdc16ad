"""How long ``quadcruise.identify`` takes on a 60 s PX4 log (target: under 20 s).

    python benchmarks/identify.py              # 60 s of doublets, logged at 250 Hz, 3 rounds
    python benchmarks/identify.py --seconds 120 --rounds 5

The log: the paper's vehicle flying the doublet excitation (``quadcruise.sysid.excitation``)
with sensor noise, written by ``SimResult.to_ulog``. Timed: the whole ``identify`` call (reading
the ULog with pyulog, filtering, fitting, intervals, validation), best and median of the rounds;
the flight and the writing are not timed. The numba engine is warmed first.
"""

from __future__ import annotations

import argparse
import os
import statistics
import tempfile
import time
from pathlib import Path

import numpy as np

import quadcruise as qc
from quadcruise.disturbances import SensorNoise
from quadcruise.missions import Hover
from quadcruise.sysid.excitation import ScheduleController, doublets


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--seconds", type=float, default=60.0, help="log length [s]")
    parser.add_argument("--rounds", type=int, default=3)
    args = parser.parse_args()

    vehicle = qc.Vehicle.paper()
    t, u = doublets(vehicle, rate=0.6, spin=1.0, repeats=max(2, int(np.ceil(args.seconds / 17.0))))
    keep = t <= args.seconds
    t, u = t[keep], u[keep]
    noise = SensorNoise(position_std=0.01, velocity_std=0.02, angle_std=0.005, rate_std=0.01)
    flight = qc.fly(
        Hover(z=300.0),
        ScheduleController(t, u),
        vehicle=vehicle,
        duration=float(t[-1]),
        sensors=noise,
        seed=1,
        dt=0.004,  # commanded at 250 Hz, every command logged (a log of every 4th of 1 kHz does not fit)
        max_step=0.001,
        max_track_error=1e6,
        max_steady_error=1e6,
    )
    with tempfile.TemporaryDirectory() as folder:
        path = flight.to_ulog(Path(folder) / "sysid.ulg", profile="sysid")
        size = os.path.getsize(path)
        times = []
        for _ in range(args.rounds):
            start = time.perf_counter()
            result = qc.identify(path, mass=float(vehicle.m))
            times.append(time.perf_counter() - start)
    print(f"log: {flight.t[-1]:.1f} s at 250 Hz, {size / 1e6:.1f} MB; load average {os.getloadavg()[0]:.2f}")
    print(
        f"identify: best {min(times):.2f} s, median {statistics.median(times):.2f} s over {args.rounds} rounds "
        f"(target < 20 s)"
    )
    print(
        "K {K:.3f} N, Jxx {Jxx:.5f}, Jyy {Jyy:.5f}, Jzz {Jzz:.5f} kg m^2, d {d:.5f} m, omega {omega:.2f} rad/s".format(
            **{k: result.parameters[k]["value"] for k in ("K", "Jxx", "Jyy", "Jzz", "d", "omega")}
        )
    )


if __name__ == "__main__":
    main()
