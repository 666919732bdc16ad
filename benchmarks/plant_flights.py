"""Flights of both plants on every path issue 31's plant descriptions touched, saved to an npz, to
compare two trees bit for bit: ``PYTHONPATH=<tree>/src python benchmarks/plant_flights.py OUT.npz``
(a tree: ``git archive REV src | tar -x -C <tree>``), then
``python benchmarks/plant_flights.py --compare A.npz B.npz``.

Cases: a paper batch with sensor noise and delay, the watched (chunked) path, a given x0, full
dynamics; the rotor plant alone, a tuple of vehicles, watched, with a controller vehicle; a
Stepper of each plant; Monte Carlo chunks of each plant with and without offsets; 50 gym steps of
each plant with seeded random actions.
"""

from __future__ import annotations

import sys
import warnings

import numpy as np

FIELDS = ("states", "commands", "references", "final_state", "status", "t_stop", "duty_clipped_s", "rotor_states")


def flights() -> dict[str, np.ndarray]:
    """Every case's arrays, by ``case.field``."""
    import gymnasium

    import quadcruise as qc
    import quadcruise.gym  # noqa: F401  (registers the environments)
    from quadcruise.disturbances import SensorNoise
    from quadcruise.montecarlo.chunk import fly_chunk
    from quadcruise.montecarlo.population import Population
    from quadcruise.montecarlo.spec import MonteCarloSpec
    from quadcruise.workflows.stepwise import stepper

    print(qc.__file__)
    out: dict[str, np.ndarray] = {}

    def keep(name, result):
        for key in FIELDS:
            value = getattr(result, key, None)
            if value is not None:
                out[f"{name}.{key}"] = np.asarray(value)

    iris = qc.Vehicle.preset("iris")
    hover = np.r_[0.1, 0.0, 1.0, np.zeros(9), np.full(4, 3.499 * 9.81 / 4)]
    keep(
        "paper_batch",
        qc.fly(
            "circle",
            "nlpd",
            vehicle=qc.Vehicle.paper().replace(m=[3.2, 3.5, 3.8]),
            duration=2.0,
            sensors=SensorNoise(position_std=0.01, delay=0.002),
            seed=4,
        ),
    )
    keep("paper_watched", qc.fly("circle", "nlpd", n=4, duration=2.0, log_every=10))
    keep("paper_x0", qc.fly("hover", "gonzalez", duration=1.0, x0=hover))
    keep("paper_full", qc.fly("circle", "se3", duration=1.0, full_dynamics=True))
    keep("rotor_single", qc.fly("circle", "se3", vehicle="iris", duration=2.0))
    keep("rotor_tuple", qc.fly("circle", "se3", vehicle=[iris, iris.replace(m=1.6)], duration=2.0))
    keep("rotor_watched", qc.fly("circle", "nlpd", vehicle="crazyflie", n=3, duration=2.0, log_every=10))
    keep("rotor_cv", qc.fly("hover", "se3", vehicle="iris", controller_vehicle=iris.replace(m=1.4), duration=1.0))
    for name, vehicle, controller in (("rotor_stepper", "iris", "se3"), ("paper_stepper", None, "nlpd")):
        s = stepper("circle", controller, vehicle=vehicle, duration=0.5, n=2)
        for _ in range(100):
            s.step()
        out[f"{name}.state"], out[f"{name}.paper"] = s.state.copy(), s.paper_state.copy()
    for name, vehicle, controller, population in (
        ("mc_paper", "paper", "nlpd", Population(mass_spread=0.1, wind_spread=1.0)),
        ("mc_paper_off", "paper", "nlpd", Population(offset=0.2)),
        ("mc_rotor", "iris", "se3", Population(mass_spread=0.1, offset=0.2)),
        ("mc_rotor0", "crazyflie", "se3", Population(inertia_spread=0.1)),
    ):
        spec = MonteCarloSpec("circle", controller, population, vehicle=vehicle, duration=1.0, seed=3)
        keep(name, fly_chunk(spec, 0, 5)[0])
    for vehicle in ("paper", "iris"):
        env = gymnasium.make_vec(
            "quadcruise/Hover-v0", num_envs=4, vectorization_mode="vector_entry_point", action="rotors", vehicle=vehicle
        )
        obs, _ = env.reset(seed=2)
        rng = np.random.default_rng(0)
        seen = [obs]
        for _ in range(50):
            obs, reward, *_ = env.step(rng.uniform(-0.2, 0.2, (4, 4)).astype(np.float32))
            seen += [obs, reward[:, None].astype(np.float32)]
        out[f"gym_{vehicle}"] = np.concatenate(seen, axis=1)
    return out


def compare(a_path: str, b_path: str) -> int:
    """Print the arrays that differ (shape or any value, NaN equal to NaN); 1 if any."""
    a, b = np.load(a_path), np.load(b_path)
    if set(a.files) != set(b.files):
        print("cases differ:", sorted(set(a.files) ^ set(b.files)))
        return 1
    bad = [k for k in a.files if not (a[k].shape == b[k].shape and np.array_equal(a[k], b[k], equal_nan=True))]
    print(f"{len(a.files)} arrays of {len({k.split('.')[0] for k in a.files})} cases; differ: {bad or 'none'}")
    return 1 if bad else 0


def main(argv: list[str]) -> int:
    """``OUT.npz``, or ``--compare A.npz B.npz``."""
    if argv[:1] == ["--compare"] and len(argv) == 3:
        return compare(argv[1], argv[2])
    if len(argv) != 1:
        print(__doc__)
        return 2
    warnings.simplefilter("ignore")
    out = flights()
    np.savez(argv[0], **out)
    print(len(out), "arrays")
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
