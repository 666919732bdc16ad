"""Alternating A/B timing of two versions of the package: ``python benchmarks/ab.py A B``.

A and B are each a git revision of this repository (exported with ``git archive`` into a
folder of its own under ``--trees``, once) or a folder holding ``src/quadcruise`` (another
worktree, or a copy with an edit). Every measurement is a fresh process of this
interpreter with ``PYTHONPATH=<side>/src``, which checks that it imported ``quadcruise``
from that folder; each side keeps its numba cache in its own ``__pycache__`` folders.

First each side runs once untimed (it compiles, or loads its cache). Then the rounds: A
then B in odd rounds, B then A in even ones (A B B A A B ...), so a drift of the host's
speed meets both sides alike. In each process every figure first flies 0.1 s untimed, then
makes its timed calls, the figures in turn. The report gives, per side and figure, the best and
the median rate over all timed calls, and the ratios B/A (above 1: B is faster), twice:
by the wall clock, and by the process's CPU time (all its threads), which other processes
on the host disturb much less (time spent waiting for a core is not counted). On two
threads the CPU-time rate is per core: it shows the cost of the work, not the speed-up.

Figures (``--figures``, comma-separated; the default: single,batch):

- ``single``: ``qc.fly("circle", "nlpd", duration=60)``, one vehicle at 1 kHz;
- ``batch``: the same circle, 2,000 vehicles (masses +/- 10 %) x 10 s, on numba's threads;
- ``mc``: the Monte Carlo benchmark's population (benchmarks/montecarlo.py), 136 flights of
  60 s swept in this process (chunks of 34 on numba's threads, metrics included);
- ``mc1``: one chunk of that population, 34 flights of 60 s on one thread: the task of
  one Dask worker;
- ``mcplain``: 272 flights of that population in one batched call on numba's threads,
  logging the start and the end only: the Monte Carlo benchmark's ``plain`` run;
- ``gym``: 200 steps of ``gymnasium.make_vec("quadcruise/Hover-v0", num_envs=1024,
  vectorization_mode="vector_entry_point", action="rotors")`` with random actions (seeded;
  autoreset included), as benchmarks/gym.py steps it: rates are env-steps per second;
- ``gym1``: 2,000 steps of one ``gymnasium.make("quadcruise/Hover-v0", action="rotors")``;
- ``rsingle``, ``rbatch``: the rotor-speed plant, ``qc.fly("circle", "se3", vehicle="iris")``, one
  vehicle x 60 s and 2,000 x 10 s; ``psingle``, ``pbatch``: the same calls on the paper's plant
  (``vehicle="paper"``), for the rotor plant's rate as a ratio of the paper plant's.

Rates are vehicle-steps per second. Before each process the script waits (up to
``--wait`` seconds) until the other processes of the host leave its cores idle: less than
``--busy`` of the machine's CPU time over 2 s. While the process runs it counts the CPU
time that other processes took (the machine's busy time less the child's own); a process
that met more than ``--busy`` is run again (at most ``--redo`` times), and the fraction is
printed with each process. On a shared host, repeat a comparison that looks borderline.
"""

from __future__ import annotations

import argparse
import json
import math
import os
import resource
import statistics
import subprocess
import sys
import tempfile
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
HZ = 1000.0
CLOCKS = {"wall": "wall clock", "cpu": "CPU time (all threads)"}
FIGURES = {  # name: (vehicles, flight seconds, timed calls per process)
    "single": (1, 60.0, 20),
    "batch": (2000, 10.0, 2),
    "mc": (136, 60.0, 2),
    "mc1": (34, 60.0, 3),
    "mcplain": (272, 60.0, 2),
    "gym": (1024, 0.2, 3),  # the gym figures' "seconds" x HZ are their steps
    "gym1": (1, 2.0, 3),
    "rsingle": (1, 60.0, 20),
    "rbatch": (2000, 10.0, 2),
    "psingle": (1, 60.0, 20),
    "pbatch": (2000, 10.0, 2),
}
PLANTS = {"rsingle": "iris", "rbatch": "iris", "psingle": "paper", "pbatch": "paper"}


# --- the child: one process of one side --------------------------------------------------
def figure_call(name: str, duration: float | None = None):
    """A zero-argument call that flies figure ``name`` once (for ``duration`` seconds
    instead of the figure's, if given)."""
    import numba
    import numpy as np

    import quadcruise as qc

    n, full, _ = FIGURES[name]
    duration = duration or full
    if name in ("gym", "gym1"):
        return gym_call(n, round(duration * HZ))
    if name in ("single", "batch"):  # Table I's mass, spread +/- 10 % over a batch
        vehicle = qc.Vehicle(m=3.499 * np.linspace(0.9, 1.1, n)) if n > 1 else None
        every = math.gcd(1000, round(duration * HZ))  # log_every must divide the periods (0.1 s warm-up: 100)
        return lambda: qc.fly("circle", "nlpd", vehicle=vehicle, duration=duration, dt=1.0 / HZ, log_every=every)
    if name in PLANTS:  # se3 on either plant: the same call
        every = math.gcd(1000, round(duration * HZ))
        return lambda: qc.fly(
            "circle", "se3", vehicle=PLANTS[name], n=n, duration=duration, dt=1.0 / HZ, log_every=every
        )
    # the Monte Carlo benchmark's population (benchmarks/, this script's folder, is on sys.path)
    from montecarlo import make_spec

    from quadcruise.montecarlo.sweep import fly_chunk, run_chunk, run_sweep

    spec = make_spec(duration)
    if name == "mc":
        return lambda: run_sweep(spec, n, scheduler="none")
    if name == "mcplain":
        return lambda: fly_chunk(spec, 0, n, log_every=spec.periods)
    threads = numba.get_num_threads()

    def one_task():
        try:
            return run_chunk(spec, 0, n, threads=1)
        finally:
            numba.set_num_threads(threads)

    return one_task


def gym_call(n: int, steps: int):
    """A zero-argument call that makes ``steps`` steps of random actions in ``n`` environments."""
    import gymnasium
    import numpy as np

    import quadcruise.gym  # noqa: F401 - registers the environments

    if n == 1:
        env = gymnasium.make("quadcruise/Hover-v0", action="rotors")
    else:
        env = gymnasium.make_vec(
            "quadcruise/Hover-v0", num_envs=n, vectorization_mode="vector_entry_point", action="rotors"
        )
    env.reset(seed=0)
    actions = np.random.default_rng(0).uniform(-1.0, 1.0, (steps, n, 4)).astype(np.float32)
    if n == 1:
        actions = actions[:, 0]

    def call():
        for k in range(steps):
            _, _, terminated, truncated, _ = env.step(actions[k])
            if n == 1 and (terminated or truncated):
                env.reset()

    return call


def child(names: list[str], tree: str, warm: bool) -> dict:
    import quadcruise

    where = Path(quadcruise.__file__).resolve()
    if Path(tree).resolve() / "src" not in where.parents:
        raise SystemExit(f"imported quadcruise from {where}, not from {tree}")
    for name in names:  # untimed, 0.1 s flights: the compiled code loads
        figure_call(name, 0.1)()
    out: dict = {"file": str(where), "wall": {}, "cpu": {}}
    if warm:
        return out
    calls = {name: figure_call(name) for name in names}
    for name, call in calls.items():
        out["wall"][name], out["cpu"][name] = [], []
        for _ in range(FIGURES[name][2]):
            t0, c0 = time.perf_counter(), time.process_time()
            call()
            out["cpu"][name].append(time.process_time() - c0)
            out["wall"][name].append(time.perf_counter() - t0)
    return out


# --- the parent ------------------------------------------------------------------------------
def side_tree(spec: str, trees: Path) -> Path:
    """The folder of a side: a folder with src/quadcruise as it is, or a git revision
    exported once into ``trees``."""
    path = Path(spec).expanduser()
    if (path / "src" / "quadcruise").is_dir():
        return path.resolve()
    sha = subprocess.run(
        ["git", "-C", str(ROOT), "rev-parse", "--verify", f"{spec}^{{commit}}"],
        capture_output=True,
        text=True,
        check=True,
    ).stdout.strip()
    tree = trees / sha[:12]
    if not (tree / "src" / "quadcruise").is_dir():
        tree.mkdir(parents=True, exist_ok=True)
        archive = subprocess.run(
            ["git", "-C", str(ROOT), "archive", sha, "src", "benchmarks"], capture_output=True, check=True
        ).stdout
        subprocess.run(["tar", "-x", "-C", str(tree)], input=archive, check=True)
    return tree


def run_side(tree: Path, names: list[str], warm: bool) -> dict:
    """One child process of a side: its output, with ``others``, the fraction of the
    machine's CPU time that other processes took while it ran."""
    env = os.environ | {"PYTHONPATH": str(tree / "src")}
    cmd = [sys.executable, str(Path(__file__).resolve()), "--child", ",".join(names), "--tree", str(tree)]
    if warm:
        cmd.append("--warm")
    ru0, (a0, b0) = resource.getrusage(resource.RUSAGE_CHILDREN), cpu_ticks()
    proc = subprocess.run(cmd, capture_output=True, text=True, env=env, cwd=tempfile.gettempdir())
    ru1, (a1, b1) = resource.getrusage(resource.RUSAGE_CHILDREN), cpu_ticks()
    if proc.returncode:
        raise SystemExit(f"{tree}: the child failed:\n{proc.stderr[-3000:]}")
    out = json.loads(proc.stdout.strip().splitlines()[-1])
    own = (ru1.ru_utime + ru1.ru_stime - ru0.ru_utime - ru0.ru_stime) * os.sysconf("SC_CLK_TCK")
    out["others"] = max(0.0, (b1 - b0 - own) / max(a1 - a0, 1))
    return out


def cpu_ticks() -> tuple[int, int]:
    """(all, busy) CPU time of the machine so far, in clock ticks (/proc/stat; zeros where
    it cannot be read)."""
    try:
        with open("/proc/stat") as f:
            v = [int(x) for x in f.readline().split()[1:9]]
    except OSError:
        return 0, 0
    return sum(v), sum(v) - v[3] - v[4]  # less idle and iowait


def busy_fraction(seconds: float = 2.0) -> float:
    """The fraction of the machine's CPU time spent busy over the next ``seconds``."""
    a0, b0 = cpu_ticks()
    time.sleep(seconds)
    a1, b1 = cpu_ticks()
    return (b1 - b0) / max(a1 - a0, 1)


def wait_for_idle(limit: float, wait_s: float) -> float:
    """Wait up to ``wait_s`` seconds for the host's busy fraction to fall below ``limit``;
    the last fraction seen."""
    end = time.monotonic() + wait_s
    busy = busy_fraction()
    while busy >= limit and time.monotonic() < end:
        busy = busy_fraction()
    return busy


def summary(times: list[float], work: int) -> dict:
    return {"best": work / min(times), "median": work / statistics.median(times), "calls": len(times)}


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("a", nargs="?", help="side A: a git revision or a folder with src/quadcruise")
    ap.add_argument("b", nargs="?", help="side B: the same")
    ap.add_argument("--rounds", type=int, default=5, help="processes per side (5)")
    ap.add_argument("--figures", default="single,batch", help=f"comma-separated, of {', '.join(FIGURES)}")
    ap.add_argument(
        "--trees",
        type=Path,
        default=Path(tempfile.gettempdir()) / "quadcruise-ab",
        help="where git revisions are exported",
    )
    ap.add_argument(
        "--busy",
        type=float,
        default=0.25,
        help="start a process when less than this fraction of the CPU time is busy (0.25)",
    )
    ap.add_argument("--wait", type=float, default=30.0, help="the longest wait for that, in seconds (30)")
    ap.add_argument("--redo", type=int, default=0, help="runs again of a process that met a busy host (0)")
    ap.add_argument("--json", type=Path, help="also write the times and the summary as JSON")
    ap.add_argument("--child", help=argparse.SUPPRESS)
    ap.add_argument("--tree", help=argparse.SUPPRESS)
    ap.add_argument("--warm", action="store_true", help=argparse.SUPPRESS)
    args = ap.parse_args(argv)
    if args.child:
        print(json.dumps(child(args.child.split(","), args.tree, args.warm)))
        return 0
    if not (args.a and args.b):
        ap.error("give two sides, A and B")
    names = [f.strip() for f in args.figures.split(",") if f.strip()]
    unknown = [f for f in names if f not in FIGURES]
    if unknown:
        ap.error(f"unknown figure(s) {', '.join(unknown)}; choose from {', '.join(FIGURES)}")
    sides = {"A": side_tree(args.a, args.trees), "B": side_tree(args.b, args.trees)}
    print(
        f"A = {args.a} ({sides['A']})\nB = {args.b} ({sides['B']})\n"
        f"{time.strftime('%Y-%m-%d %H:%M')}, {os.cpu_count()} cores, load {os.getloadavg()[0]:.2f}; "
        f"{args.rounds} rounds of {', '.join(f'{n} x{FIGURES[n][2]}' for n in names)}",
        flush=True,
    )
    for label, tree in sides.items():
        t0 = time.perf_counter()
        got = run_side(tree, names, warm=True)
        print(f"  warm {label}: {time.perf_counter() - t0:.1f} s, quadcruise from {got['file']}", flush=True)
    times: dict = {clock: {label: {n: [] for n in names} for label in sides} for clock in CLOCKS}
    others = []
    for r in range(args.rounds):
        for label in ("A", "B") if r % 2 == 0 else ("B", "A"):
            for attempt in range(args.redo + 1):
                before = wait_for_idle(args.busy, args.wait)
                got = run_side(sides[label], names, warm=False)
                print(
                    f"  round {r + 1} {label}: host busy {before:.2f} before, others {got['others']:.2f} "
                    "during: "
                    + ", ".join(f"{n} {min(got['wall'][n]) * 1e3:.0f} ms" for n in names)
                    + ("" if got["others"] < args.busy or attempt == args.redo else "  (again)"),
                    flush=True,
                )
                if got["others"] < args.busy:
                    break
            others.append(got["others"])
            for clock in CLOCKS:
                for n in names:
                    times[clock][label][n] += got[clock][n]
    print(
        f"\nM vehicle-steps per second, best and median of all calls (other processes took "
        f"{min(others):.2f}-{max(others):.2f} of the CPU time while the timed processes ran)"
    )
    result: dict = {
        "a": args.a,
        "b": args.b,
        "rounds": args.rounds,
        "date": time.strftime("%Y-%m-%d %H:%M"),
        "others": others,
        "figures": {},
    }
    for clock, label in CLOCKS.items():
        print(f"  {label:<30} {'A best':>7} {'A med':>7} {'B best':>7} {'B med':>7} {'B/A best':>9} {'B/A med':>8}")
        for n in names:
            work = FIGURES[n][0] * round(FIGURES[n][1] * HZ)
            a, b = summary(times[clock]["A"][n], work), summary(times[clock]["B"][n], work)
            ratio = {"best": b["best"] / a["best"], "median": b["median"] / a["median"]}
            result["figures"].setdefault(n, {})[clock] = {
                "A": a,
                "B": b,
                "ratio": ratio,
                "times": {k: times[clock][k][n] for k in sides},
            }
            print(
                f"    {n:<28} {a['best'] / 1e6:7.2f} {a['median'] / 1e6:7.2f} {b['best'] / 1e6:7.2f} "
                f"{b['median'] / 1e6:7.2f} {ratio['best']:9.3f} {ratio['median']:8.3f}"
            )
    if args.json:
        args.json.write_text(json.dumps(result, indent=1) + "\n")
    return 0


if __name__ == "__main__":
    sys.exit(main())
