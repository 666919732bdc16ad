"""Monte Carlo sweep throughput and the overhead of Dask: ``python benchmarks/montecarlo.py``.

The issue's target: 10,000 flights of 60 s at 1 kHz with turbulence, on a 2-core machine,
in under 3 minutes. Three runs of the same population (the circle flown by nlpd for 60 s,
3 laps; mass, inertia and thrust-gain spreads, 10 cm initial offsets, moderate Dryden
turbulence at 10 m, default drag), in this order:

- ``dask``: ``montecarlo(scheduler="local", workers=W)``: chunks of vehicles on a new
  ``distributed.LocalCluster`` of W processes, one numba thread each, metrics on a 10 ms
  log. Its time includes starting and stopping the cluster and each worker loading the
  compiled engine. It is the target's run, and it goes first, as a user's command starts
  on a machine that has not been busy for minutes;
- ``in process``: ``montecarlo(scheduler="none")``: the same chunks one after the other in
  this process (numba on all cores inside a chunk);
- ``plain``: every vehicle in ONE batched ``fly`` call logging only the start and the end:
  the engine alone, no chunks, no metrics.

The Dask overhead is reported against both, in wall time and in CPU time (this process
and its children: the Dask workers; less sensitive to other load on the machine). The
in-process and Dask tables are checked equal. Options: --quick (200 flights of 5 s, a smoke test), --n, --duration,
--workers,
--skip-plain, --json PATH. The load average is printed at the start and the end, and the
speed probe before each run: the host's speed moves (by up to 2x within minutes here), and
other processes on the machine slow every figure.
"""

from __future__ import annotations

import argparse
import json
import resource
import sys
import time
import warnings
from pathlib import Path

from machine import end_of_run, machine, probe

ROOT = Path(__file__).resolve().parents[1]
TARGET = dict(n=10_000, duration=60.0, seconds=180.0)


def make_spec(duration: float):
    from quadcruise.disturbances import Environment, Turbulence, with_drag
    from quadcruise.model.vehicle import Vehicle
    from quadcruise.montecarlo import MonteCarloSpec, Population

    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        vehicle = with_drag(Vehicle.paper())
    env = Environment(turbulence=Turbulence(intensity="moderate", altitude=10.0))
    population = Population(mass_spread=0.1, inertia_spread=0.1, thrust_spread=0.05, offset=0.1, environment=env)
    return MonteCarloSpec("circle", "nlpd", population, seed=1, duration=duration, dt=1e-3, vehicle=vehicle)


def cpu_seconds() -> float:
    """CPU time of this process and of its finished children (the Dask workers, once the
    cluster is closed)."""
    return sum(
        r.ru_utime + r.ru_stime
        for r in (resource.getrusage(resource.RUSAGE_SELF), resource.getrusage(resource.RUSAGE_CHILDREN))
    )


def timed(call):
    """(wall s, CPU s, value) of call()."""
    c0, t0 = cpu_seconds(), time.perf_counter()
    value = call()
    return time.perf_counter() - t0, cpu_seconds() - c0, value


def plain(spec, n: int):
    """All n vehicles in one batched fly call, logging the start and the end only."""
    from quadcruise.montecarlo.sweep import fly_chunk

    return fly_chunk(spec, 0, n, log_every=spec.periods)[0]


def sweep(spec, n: int, scheduler: str, workers: int | None):
    from quadcruise.montecarlo.sweep import run_sweep

    return run_sweep(spec, n, scheduler=scheduler, workers=workers)


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--quick", action="store_true", help="200 flights of 5 s: a smoke test")
    ap.add_argument("--n", type=int, help="number of flights (10,000)")
    ap.add_argument("--duration", type=float, help="flight time [s] (60)")
    ap.add_argument("--workers", type=int, default=2, help="Dask worker processes (2)")
    ap.add_argument("--skip-plain", action="store_true", help="leave out the single batched fly call")
    ap.add_argument("--json", type=Path, help="also write the figures as JSON")
    args = ap.parse_args(argv)
    n = args.n or (200 if args.quick else TARGET["n"])
    duration = args.duration or (5.0 if args.quick else TARGET["duration"])

    from quadcruise.montecarlo.sweep import run_chunk

    sources = {p: p.stat().st_mtime for p in (ROOT / "src" / "quadcruise").rglob("*.py")}
    import dask
    import distributed

    info = machine(dask=dask.__version__, distributed=distributed.__version__)
    print(
        f"machine: {info['cpu']}, {info['cores']} cores, numba {info['numba']} ({info['numba_threads']} threads), "
        f"dask {info['distributed']}; load average {', '.join(f'{v:.2f}' for v in info['load_avg_start'])}; "
        f"speed probe {info['probe_ns_start']:.0f} ns per plant RK4 step"
    )
    spec = make_spec(duration)
    work = n * spec.periods
    print(
        f"{n:,} flights of {duration:g} s at 1 kHz with moderate Dryden turbulence = {work / 1e6:,.0f} M vehicle-steps"
    )
    t0 = time.perf_counter()
    run_chunk(make_spec(0.01), 0, 2)  # load the compiled engine in this process
    results = {"warm_up_s": time.perf_counter() - t0}

    def run(name, call, extra=lambda value: ""):
        before = probe()
        wall, cpu, value = timed(call)
        rate = work / wall
        results[name] = {
            "wall_s": wall,
            "cpu_s": cpu,
            "vehicle_steps_per_s": rate,
            "flights_per_s": n / wall,
            "vehicle_steps_per_cpu_s": work / cpu,
            "probe_ns_before": before,
        }
        print(
            f"  {name:<11} {wall:8.1f} s  {rate / 1e6:6.2f} M vehicle-steps/s  {n / wall:8.1f} flights/s"
            f"  {cpu:8.1f} CPU s ({work / cpu / 1e6:.2f} M per CPU s)  probe {before:.0f} ns{extra(value)}",
            flush=True,
        )
        return value

    # the target's run first, as a user's command starts on a machine not already busy
    # for minutes; the host may slow under sustained load (see each run's probe)
    dist = run(
        "dask",
        lambda: sweep(spec, n, "local", args.workers),
        lambda r: f"  ({args.workers} workers, chunks of {r.info['chunk_size']})",
    )
    local = run("in process", lambda: sweep(spec, n, "none", None), lambda r: f"  (chunks of {r.info['chunk_size']})")
    if not args.skip_plain:
        run("plain", lambda: plain(spec, n))
    import pandas as pd

    changed = sorted(
        str(p.relative_to(ROOT))
        for p in (ROOT / "src" / "quadcruise").rglob("*.py")
        if sources.get(p) != p.stat().st_mtime
    )
    if changed:  # the workers import the package afresh: the runs flew different code
        print(f"  WARNING: source files changed during the run: {', '.join(changed)}")
    results["sources_changed"] = changed
    same = local.table.equals(dist.table)
    results["tables_identical"] = same
    print(f"  the in-process and Dask tables are {'identical' if same else 'DIFFERENT'}")
    if not same and not changed:
        pd.testing.assert_frame_equal(local.table, dist.table, check_exact=True)
    d = results["dask"]["wall_s"]
    results["dask_overhead_vs_in_process_pct"] = 100.0 * (d / results["in process"]["wall_s"] - 1.0)
    results["dask_cpu_overhead_vs_in_process_pct"] = 100.0 * (
        results["dask"]["cpu_s"] / results["in process"]["cpu_s"] - 1.0
    )
    print(
        f"Dask overhead (wall): {results['dask_overhead_vs_in_process_pct']:+.1f} % against the in-process sweep",
        end="",
    )
    if "plain" in results:
        results["dask_overhead_vs_plain_pct"] = 100.0 * (d / results["plain"]["wall_s"] - 1.0)
        results["in_process_overhead_vs_plain_pct"] = 100.0 * (
            results["in process"]["wall_s"] / results["plain"]["wall_s"] - 1.0
        )
        print(
            f", {results['dask_overhead_vs_plain_pct']:+.1f} % against the plain batched run "
            f"(in process: {results['in_process_overhead_vs_plain_pct']:+.1f} %)",
            end="",
        )
    print()
    print(
        f"Dask overhead (CPU): {results['dask_cpu_overhead_vs_in_process_pct']:+.1f} % against the in-process sweep"
        + (
            f", {100.0 * (results['dask']['cpu_s'] / results['plain']['cpu_s'] - 1.0):+.1f} % against the plain run"
            if "plain" in results
            else ""
        )
    )
    failures = local.summary()["failures"]
    print(
        f"outcome: {failures['count']:,} of {n:,} flights failed: "
        + ", ".join(f"{k} {v['count']:,}" for k, v in failures["by_reason"].items())
    )
    if n == TARGET["n"] and duration == TARGET["duration"]:
        ok = d < TARGET["seconds"]
        print(
            f"target (10,000 x 60 s under {TARGET['seconds']:.0f} s on Dask): {'met' if ok else 'NOT met'} ({d:.0f} s)"
        )
        results["target_met"] = ok
    print(end_of_run(info))
    if args.json:
        args.json.write_text(
            json.dumps(
                {
                    "machine": info,
                    "quick": args.quick,
                    "n": n,
                    "duration_s": duration,
                    "workers": args.workers,
                    "results": results,
                },
                indent=2,
            )
            + "\n"
        )
    return 0


if __name__ == "__main__":
    sys.exit(main())
