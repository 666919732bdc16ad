"""A batch's default log against ``log_every=1000``: wall time, CPU time and peak memory.

``python benchmarks/batchlog.py`` flies ``qc.fly("circle", n=2000, duration=10.0)`` as it comes
(the log ``fly`` chooses; the track checks at every period, in the kernel, either way) and the same
call with ``log_every=1000``, each call in a fresh process, in
alternating order (A B B A ...), and reports per call the wall time, the CPU time of the process
during the call, its peak resident memory (``ru_maxrss``: the whole process, imports included)
and the load average; then each variant's best and median and the ratio default / 1000.
``--full`` adds ``log_every=1`` (the whole log: about 6.2 GB at the default size). ``--chunk
STEPS:PIECES`` (repeatable) adds the default call with other chunk sizes (``sim.chunked``'s
``CHUNK_VEHICLE_STEPS`` and ``PIECES_PER_THREAD``: they size only the heads flown again now).

Target (issue 26): the default costs at most 1.5 x the ``log_every=1000`` call, and its log
stays within 1 GiB.

    python benchmarks/batchlog.py                  # 3 rounds, about 2 minutes on 2 quiet cores
    python benchmarks/batchlog.py --rounds 5 --json out.json
    python benchmarks/batchlog.py --n 200 --rounds 1   # a smoke test
"""

from __future__ import annotations

import argparse
import json
import os
import statistics
import subprocess
import sys
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
VARIANTS = {"default": None, "every1000": 1000, "full": 1}


def child(variant: str, n: int, duration: float) -> dict:
    """Fly the variant once after a short warm-up; return its figures."""
    import resource
    import time
    import warnings

    import numpy as np

    import quadcruise as qc

    if variant.startswith("chunk"):
        import quadcruise.sim.chunked as chunked

        steps, pieces = variant[len("chunk") :].split(":")
        chunked.CHUNK_VEHICLE_STEPS, chunked.PIECES_PER_THREAD = int(steps), int(pieces)
    every = VARIANTS.get(variant)
    kwargs = {} if every is None else {"log_every": every}
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        qc.fly("circle", n=n, duration=1.0, **kwargs)  # untimed: loads the compiled code this variant runs
        caught.clear()
        cpu0, t0 = time.process_time(), time.perf_counter()
        res = qc.fly("circle", n=n, duration=duration, **kwargs)
        wall, cpu = time.perf_counter() - t0, time.process_time() - cpu0
    log_bytes = res.states.nbytes + res.commands.nbytes + res.references.nbytes
    return {
        "variant": variant,
        "wall_s": wall,
        "cpu_s": cpu,
        "peak_rss_gib": resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 2**20,
        "log_gib": log_bytes / 2**30,
        "log_every": res.meta["log_every"],
        "statuses": {str(k): int(v) for k, v in zip(*np.unique(res.status, return_counts=True), strict=True)},
        "warnings": [str(w.message) for w in caught],
        "load": os.getloadavg()[0],
    }


def run(variant: str, n: int, duration: float) -> dict:
    env = dict(os.environ, PYTHONPATH=str(ROOT / "src"))
    out = subprocess.run(
        [sys.executable, __file__, "--child", variant, "--n", str(n), "--duration", str(duration)],
        env=env,
        capture_output=True,
        text=True,
        check=True,
    )
    return json.loads(out.stdout.strip().splitlines()[-1])


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--rounds", type=int, default=3)
    ap.add_argument("--n", type=int, default=2000)
    ap.add_argument("--duration", type=float, default=10.0)
    ap.add_argument("--full", action="store_true", help="also log_every=1 (needs about 6.5 GB at the default size)")
    ap.add_argument("--chunk", action="append", default=[], metavar="STEPS:PIECES", help="also these chunk sizes")
    ap.add_argument("--json", help="write the calls and the summary here")
    ap.add_argument("--child", help=argparse.SUPPRESS)
    args = ap.parse_args(argv)
    if args.child:
        print(json.dumps(child(args.child, args.n, args.duration)))
        return 0
    names = ["default", "every1000"] + (["full"] if args.full else []) + [f"chunk{c}" for c in args.chunk]
    print(f"qc.fly('circle', n={args.n}, duration={args.duration}): {args.rounds} rounds, load {os.getloadavg()}")
    calls = []
    for r in range(args.rounds):
        for name in names if r % 2 == 0 else names[::-1]:
            got = run(name, args.n, args.duration)
            calls.append(got)
            print(
                f"  {name:10s} wall {got['wall_s']:6.2f} s  cpu {got['cpu_s']:6.2f} s  peak RSS "
                f"{got['peak_rss_gib']:5.2f} GiB  log {got['log_gib']:5.2f} GiB (log_every={got['log_every']})  "
                f"load {got['load']:.1f}  statuses {got['statuses']}",
                flush=True,
            )
    summary = {}
    for name in names:
        mine = [c for c in calls if c["variant"] == name]
        summary[name] = {
            key: {"best": min(c[key] for c in mine), "median": statistics.median(c[key] for c in mine)}
            for key in ("wall_s", "cpu_s", "peak_rss_gib")
        }
    print("best / median:")
    for name in names:
        s = summary[name]
        print(
            f"  {name:10s} wall {s['wall_s']['best']:.2f} / {s['wall_s']['median']:.2f} s, cpu "
            f"{s['cpu_s']['best']:.2f} / {s['cpu_s']['median']:.2f} s, peak RSS {s['peak_rss_gib']['best']:.2f} GiB"
        )
    a, b = summary["default"], summary["every1000"]
    ratio = {k: a[k]["median"] / b[k]["median"] for k in ("wall_s", "cpu_s")}
    print(f"default / every1000 (medians): wall {ratio['wall_s']:.2f}, cpu {ratio['cpu_s']:.2f} (target <= 1.5)")
    print(f"load at the end {os.getloadavg()}")
    if args.json:
        Path(args.json).write_text(json.dumps({"calls": calls, "summary": summary, "ratio": ratio}, indent=1))
    return 0


if __name__ == "__main__":
    sys.exit(main())
