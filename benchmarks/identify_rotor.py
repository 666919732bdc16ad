"""How long ``quadcruise.identify`` takes on a 60 s log of a rotor-plant vehicle (target: under 20 s).

    python benchmarks/identify_rotor.py                    # the Iris on sysid (58 s), 1 kHz log, 3 rounds
    python benchmarks/identify_rotor.py --vehicle crazyflie --rounds 5

The log: the preset flying ``sysid`` under se3 with sensor noise, written by ``SimResult.to_ulog``
(the system-identification profile: every 1 kHz command, the rotor speeds in ``esc_status``).
Timed: the whole ``identify`` call (reading the ULog with pyulog, filtering, the rigid-body and
motor fits, the refits of the systematic terms, intervals, validation), best and median of the
rounds; the flight and the writing are not timed.
"""

from __future__ import annotations

import argparse
import os
import statistics
import tempfile
import time
import warnings
from pathlib import Path

import quadcruise as qc
from quadcruise.disturbances import SensorNoise
from quadcruise.missions import Sysid


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--vehicle", default="iris")
    parser.add_argument("--rounds", type=int, default=3)
    args = parser.parse_args()

    vehicle = qc.Vehicle.preset(args.vehicle)
    noise = SensorNoise(position_std=0.01, velocity_std=0.02, angle_std=0.005, rate_std=0.01)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        flight = qc.fly(Sysid(), "se3", vehicle=vehicle, sensors=noise, seed=1)
    with tempfile.TemporaryDirectory() as folder:
        path = flight.to_ulog(Path(folder) / "sysid.ulg")
        size = os.path.getsize(path)
        times = []
        for _ in range(args.rounds):
            start = time.perf_counter()
            result = qc.identify(path, vehicle=args.vehicle, mass=float(vehicle.m), commands="rad/s")
            times.append(time.perf_counter() - start)
    print(f"log: {flight.t[-1]:.1f} s at 1 kHz, {size / 1e6:.1f} MB; load average {os.getloadavg()[0]:.2f}")
    print(
        f"identify: best {min(times):.2f} s, median {statistics.median(times):.2f} s over {args.rounds} rounds "
        "(target < 20 s)"
    )
    print(", ".join(f"{k} {result.parameters[k]['value']:.5g}" for k in ("kf", "km", "Jxx", "Jzz", "tau_up")))


if __name__ == "__main__":
    main()
