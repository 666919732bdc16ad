"""What flying on sensors and the EKF costs: ``python benchmarks/estimator_cost.py``.

A batched flight (``qc.fly("circle", "nlpd", n=N)``, masses alike, at 1 kHz, the log every 100
periods as a sweep keeps it) flown on the true state (A) and on the estimate of an IMU, a GPS, a
barometer and a magnetometer through the EKF (B: ``sensors=Sensors.typical(), estimator=Ekf()``),
alternating A B B A A B ... in one process after one untimed flight of each (numba compiles or
loads its cache), so a drift of the shared host's speed meets both alike. Rates are
vehicle-steps per second, by the wall clock and by the process's CPU time (all its threads,
which other processes disturb less); the ratio B/A is the estimator flight's speed as a fraction
of the true-state flight's (issue 35 asks at least 0.3). ``--plant iris`` flies the rotor plant
(``--imu bmi088_1khz``: its designed controller has no margin for a 250 Hz IMU, docs/sensors.md).
"""

from __future__ import annotations

import argparse
import statistics
import sys
import time
import warnings


def main(argv=None) -> int:
    """Run the alternating A/B and print the rates and the ratio.

    Parameters
    ----------
    argv : list of str, optional
        The command line (``sys.argv[1:]`` by default).

    Returns
    -------
    int
        0.
    """
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--n", type=int, default=200, help="vehicles (default 200)")
    parser.add_argument("--duration", type=float, default=10.0, help="flight time [s] (default 10)")
    parser.add_argument("--rounds", type=int, default=6, help="timed flights per side (default 6)")
    parser.add_argument("--plant", choices=("paper", "iris"), default="paper", help="the vehicle (default paper)")
    parser.add_argument("--imu", default="typical", help="the IMU preset (default typical: 250 Hz)")
    args = parser.parse_args(argv)

    import quadcruise as qc
    from quadcruise.estimation import Ekf, Sensors
    from quadcruise.estimation.stage import PRESETS

    vehicle = None if args.plant == "paper" else "iris"
    common = dict(vehicle=vehicle, n=args.n, duration=args.duration, log_every=100, seed=1)
    sensors = Sensors(imu=PRESETS["imu"][args.imu], **{k: PRESETS[k]["typical"] for k in ("gps", "baro", "mag")})
    sides = {"A true state": {}, "B imu,gps,baro,mag + ekf": dict(sensors=sensors, estimator=Ekf())}
    steps = args.n * round(args.duration / 1e-3)

    def flight(extra):
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")
            wall, cpu = time.perf_counter(), time.process_time()
            result = qc.fly("circle", "nlpd", **common, **extra)
            return time.perf_counter() - wall, time.process_time() - cpu, result

    for name, extra in sides.items():  # compile, or load the cache
        result = flight(extra)[2]
        print(f"{name}: {int(result.ok.sum())} of {args.n} finished", flush=True)
    times = {name: {"wall": [], "cpu": []} for name in sides}
    order = list(sides)
    for r in range(args.rounds):
        for name in order if r % 2 == 0 else order[::-1]:
            wall, cpu, _ = flight(sides[name])
            times[name]["wall"].append(wall)
            times[name]["cpu"].append(cpu)
    print(f"{args.plant}, imu {args.imu}, {args.n} vehicles x {args.duration:g} s at 1 kHz, {args.rounds} rounds")
    for clock in ("wall", "cpu"):
        rates = {name: [steps / s for s in times[name][clock]] for name in sides}
        for name in sides:
            print(
                f"  {clock:4s} {name:26s} best {max(rates[name]) / 1e6:7.3f}  "
                f"median {statistics.median(rates[name]) / 1e6:7.3f} M vehicle-steps/s"
            )
        a, b = (rates[name] for name in sides)
        best, median = max(b) / max(a), statistics.median(b) / statistics.median(a)
        print(f"  {clock:4s} ratio B/A: best {best:.3f}, median {median:.3f}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
