"""An x-quad without ESC telemetry identified from its commands alone, over seeded closed-loop runs.

    python benchmarks/sysid_no_esc.py                       # 100 and 250 Hz, THR_MDL_FAC 0, 0.5, 1, 20 seeds
    python benchmarks/sysid_no_esc.py --rates 250 --factors 0.5 --seeds 5
    python benchmarks/sysid_no_esc.py --motors iris         # the Iris's unequal time constants (12.5/25 ms)

Each run flies ``sysid`` (one repeat, 30 s) under se3 at the control rate (``dt`` 1/rate: every
command computed is in the log) on an x-quad (the Iris's rotors, mass and kf; no rotor inertia or
rotor drag; Jxx 0.035, Jyy 0.045; motor time constants 20 ms both ways), with sensor noise on the
rates (0.01 rad/s) and the velocity (0.02 m/s), seed 100 + i. The log is what a PX4 vehicle
without ESC telemetry gives: its ``actuator_outputs`` signal ``x`` (the relative thrust
``(w_cmd / w_max)^2`` through the inverse of ``THR_MDL_FAC`` f: ``f x^2 + (1 - f) x``), with f in
its parameters, the x geometry of ``CA_ROTOR*``, no rotor speeds. Identified with the Iris as the
base and the true mass. Printed per configuration: the verdict's count, and for Jxx, Jyy, Jzz,
kf w_max^2 (``K``) and tau: how many runs hold the truth in the 95 % interval, identifiable, the
largest error; and identify's median time.
"""

from __future__ import annotations

import argparse
import statistics
import time
import warnings

import numpy as np

import quadcruise as qc
from quadcruise.io.flightlog import FlightLog
from quadcruise.missions import Sysid
from quadcruise.sim.px4 import rotor_speed_commands

RATE_STD, VELOCITY_STD = 0.01, 0.02


def x_quad(motors: str):
    """The x-quad flown: the Iris's rotors, mass and kf, no rotor inertia or drag."""
    tau = {"equal": (0.02, 0.02), "iris": (0.0125, 0.025)}[motors]
    return qc.Vehicle.preset("iris").replace(
        J_rotor=0.0, k_d=0.0, k_z=0.0, Jxx=0.035, Jyy=0.045, tau_up=tau[0], tau_down=tau[1]
    )


def signal_of(rel: np.ndarray, f: float) -> np.ndarray:
    """PX4's output signal x of a relative thrust: the root in [0, 1] of ``f x^2 + (1 - f) x = rel``."""
    rel = np.clip(rel, 0.0, 1.0)
    if f < 1e-12:
        return rel
    return (-(1.0 - f) + np.sqrt((1.0 - f) ** 2 + 4.0 * f * rel)) / (2.0 * f)


def log_without_esc(flight, vehicle, f: float, rate: float, seed: int) -> FlightLog:
    """The flight as a PX4 log without ESC telemetry would read (see the module)."""
    rs, t = flight.rotor_states[0], flight.t
    rng = np.random.default_rng([seed, 7])
    w = rotor_speed_commands(flight.commands[0], flight.meta["vehicle"], flight.meta.get("controller_vehicle"))
    accel = np.gradient(rs[:, 3:6], t, axis=0, edge_order=2)
    from scipy.spatial.transform import Rotation

    body = Rotation.from_quat(rs[:, [7, 8, 9, 6]]).inv().apply(accel + [0.0, 0.0, vehicle.g])
    rotors = np.array([[x, y, s] for x, y, _, s in vehicle.rotors])
    return FlightLog(
        source=f"x-quad-{rate:g}Hz-f{f:g}-seed{seed}.ulg",
        t=t,
        segment=np.zeros(len(t), int),
        u=signal_of((w / vehicle.w_max) ** 2, f),
        velocity=rs[:, 3:6] + rng.normal(0.0, VELOCITY_STD, (len(t), 3)),
        quaternion=rs[:, 6:10],
        rates=rs[:, 10:13] + rng.normal(0.0, RATE_STD, (len(t), 3)),
        specific_force=body,
        position=rs[:, 0:3],
        rotors=rotors,
        parameters={"THR_MDL_FAC": f, "SDLOG_PROFILE": 9},  # the system-identification profile: every command
        rates_hz={"actuator_outputs": rate, "vehicle_angular_velocity": rate},
        commands="actuator_outputs PWM mapped with the log's PWM_MAIN_MIN/MAX",
        resampling="the flight's own samples",
    )


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--seeds", type=int, default=20)
    parser.add_argument("--first-seed", type=int, default=100)
    parser.add_argument("--rates", type=float, nargs="+", default=[100.0, 250.0])
    parser.add_argument("--factors", type=float, nargs="+", default=[0.0, 0.5, 1.0])
    parser.add_argument("--motors", choices=["equal", "iris"], default="equal")
    args = parser.parse_args()
    vehicle = x_quad(args.motors)
    base = qc.Vehicle.preset("iris")
    truth = {
        "Jxx": vehicle.Jxx,
        "Jyy": vehicle.Jyy,
        "Jzz": vehicle.Jzz,
        "K": vehicle.kf * vehicle.w_max**2,
        "tau_up": vehicle.tau_up,
    }
    for rate in args.rates:
        flights = {}
        for i in range(args.seeds):
            seed = args.first_seed + i
            with warnings.catch_warnings():
                warnings.simplefilter("ignore")
                flights[seed] = qc.fly(Sysid(repeats=1), "se3", vehicle=vehicle, dt=1.0 / rate, seed=seed)
        for f in args.factors:
            inside = dict.fromkeys(truth, 0)
            known = dict.fromkeys(truth, 0)
            worst = dict.fromkeys(truth, 0.0)
            fits, times = 0, []
            for seed, flight in flights.items():
                log = log_without_esc(flight, vehicle, f, rate, seed)
                start = time.perf_counter()
                result = qc.identify(log, base, mass=float(vehicle.m))
                times.append(time.perf_counter() - start)
                fits += result.fits
                for key, value in truth.items():
                    p = result.parameters[key]
                    estimate = p.get("estimate", p["value"]) if not p["identifiable"] else p["value"]
                    worst[key] = max(worst[key], abs(estimate / value - 1.0))
                    if p["identifiable"]:
                        known[key] += 1
                        inside[key] += p["ci95"][0] <= value <= p["ci95"][1]
            print(
                f"{rate:g} Hz, THR_MDL_FAC {f:g}, motors {args.motors}: verdict fits {fits}/{args.seeds}; "
                + "; ".join(
                    f"{k} inside {inside[k]}/{args.seeds} (identifiable {known[k]}), worst {100 * worst[k]:.2f} %"
                    for k in truth
                )
                + f"; identify median {statistics.median(times):.1f} s",
                flush=True,
            )


if __name__ == "__main__":
    main()
