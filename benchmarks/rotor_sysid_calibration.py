"""The rotor plant identified from ``sysid`` flights over seeded runs: errors, interval coverage, time.

    python benchmarks/rotor_sysid_calibration.py --vehicle iris           # 20 seeds
    python benchmarks/rotor_sysid_calibration.py --vehicle crazyflie --seeds 5
    python benchmarks/rotor_sysid_calibration.py --vehicle iris-changed   # Jxx 0.035, Jyy 0.025, Jzz 0.06,
                                                                          # tau_up 0.02, tau_down 0.03

Each run flies ``sysid`` (58 s) under se3 with sensor noise (seed 100 + i), writes the PX4 log
(the system-identification profile: every 1 kHz command, the rotor speeds in ``esc_status``)
and identifies it with the true mass and the preset as the base vehicle. Printed per
parameter: how many runs hold the truth in their 95 % interval (the issue asks for 90 %), how
many were identifiable, the largest error; and the time of ``identify``.
"""

from __future__ import annotations

import argparse
import os
import statistics
import tempfile
import time
from pathlib import Path

import quadcruise as qc
from quadcruise.disturbances import SensorNoise
from quadcruise.missions import Sysid

TRUTH = ("kf", "km", "Jxx", "Jyy", "Jzz", "tau_up", "tau_down", "k_d")
VEHICLES = {
    "iris": ("iris", {}),
    "crazyflie": ("crazyflie", {}),
    "iris-changed": ("iris", {"Jxx": 0.035, "Jyy": 0.025, "Jzz": 0.06, "tau_up": 0.02, "tau_down": 0.03}),
}


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--seeds", type=int, default=20)
    parser.add_argument("--first-seed", type=int, default=100)
    parser.add_argument("--vehicle", choices=list(VEHICLES), default="iris")
    args = parser.parse_args()

    preset, changes = VEHICLES[args.vehicle]
    base = qc.Vehicle.preset(preset)
    vehicle = base.replace(**changes) if changes else base
    noise = SensorNoise(position_std=0.01, velocity_std=0.02, angle_std=0.005, rate_std=0.01)
    hits, worst, seen, times = dict.fromkeys(TRUTH, 0), dict.fromkeys(TRUTH, 0.0), dict.fromkeys(TRUTH, 0), []
    with tempfile.TemporaryDirectory() as folder:
        for i in range(args.seeds):
            seed = args.first_seed + i
            flight = qc.fly(Sysid(), "se3", vehicle=vehicle, sensors=noise, seed=seed)
            path = flight.to_ulog(Path(folder) / f"sysid-{i}.ulg")
            start = time.perf_counter()
            result = qc.identify(path, vehicle=base, mass=float(vehicle.m), commands="rad/s")
            times.append(time.perf_counter() - start)
            line = []
            for key in TRUTH:
                p, truth = result.parameters[key], float(getattr(vehicle, key))
                lo, hi = p["ci95"]
                inside = bool(lo is not None and lo <= truth <= hi)
                hits[key] += inside
                seen[key] += bool(p["identifiable"])
                worst[key] = max(worst[key], abs(p["value"] / truth - 1))
                line.append(f"{key} {100 * (p['value'] / truth - 1):+.2f}%{'' if inside else '!'}")
            print(f"seed {seed}: " + ", ".join(line), flush=True)
    print(f"{args.vehicle} on sysid under se3, {args.seeds} seeds, load average {os.getloadavg()[0]:.2f}")
    for key in TRUTH:
        print(
            f"{key:8s} truth inside the 95 % interval {hits[key]:2d}/{args.seeds}, "
            f"identifiable {seen[key]:2d}/{args.seeds}, largest error {100 * worst[key]:.2f} %"
        )
    print(f"identify: median {statistics.median(times):.1f} s, longest {max(times):.1f} s (a 58 s log at 1 kHz)")


if __name__ == "__main__":
    main()
