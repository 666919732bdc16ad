"""Engine throughput, scipy comparison and start-up time: ``python benchmarks/engine.py``.

--quick (small sizes, a smoke test), --json PATH, --skip-scipy, --cold (also time start-up
with an empty numba cache, private to that run). See benchmarks/README.md.
"""

from __future__ import annotations

import argparse
import contextlib
import json
import math
import os
import resource
import shutil
import subprocess
import sys
import tempfile
import time
from pathlib import Path

import numpy as np
from machine import end_of_run, machine

HZ = 1000.0  # control and integration rate of every benchmark [1/s]
ROW_HZ = 100.0  # open-loop schedule: duties held for 10 ms per row
FULL = dict(
    single_s=60.0,
    batch_n=2000,
    batch_s=10.0,
    repeats=5,
    min_s=3.0,
    rounds=5,
    warm_repeats=3,
    scipy_single_s=60.0,
    scipy_batch_n=2000,
    scipy_batch_s=10.0,
    scipy_budget_s=60.0,
)
QUICK = dict(
    single_s=2.0,
    batch_n=100,
    batch_s=1.0,
    repeats=2,
    min_s=0.0,
    rounds=2,
    warm_repeats=1,
    scipy_single_s=0.5,
    scipy_batch_n=50,
    scipy_batch_s=0.1,
    scipy_budget_s=5.0,
)
MAX_CALLS = 200  # a cap on the calls of one figure (a 60 s single flight takes ~20 ms)


@contextlib.contextmanager
def kernel_clock():
    """Time each run of the compiled kernel (over all its threads) inside simulate()/fly()
    (list of seconds)."""
    from quadcruise.sim import engine, stepper

    real, spent = engine.fly_vehicles, []

    def timed(*args, **kwargs):
        t0 = time.perf_counter()
        real(*args, **kwargs)
        spent.append(time.perf_counter() - t0)

    # the whole log's call, and the chunks of a flight whose checks see every period (the Stepper)
    engine.fly_vehicles = stepper.fly_vehicles = timed
    try:
        yield spent
    finally:
        engine.fly_vehicles = stepper.fly_vehicles = real


class Timing:
    """The calls of one figure: ``prepare(duration)`` gives a zero-argument call that flies
    n vehicles. A first call of 10 steps (compilation or cache loading, plus the fixed
    cost) is timed apart; then full calls, taken in rounds by :meth:`round`."""

    def __init__(self, prepare, n: int, duration: float):
        self.small, self.call = prepare(10 / HZ), prepare(duration)
        self.work = n * round(duration * HZ)
        self.first, self.walls, self.kernel, self.result = None, [], [], None

    def round(self, calls: int, seconds: float, cap: int) -> None:
        """At least ``calls`` full calls, and more until they have taken ``seconds`` (at
        most ``cap`` in this round)."""
        with kernel_clock() as kern:
            if self.first is None:
                t0 = time.perf_counter()
                self.small()
                self.first = time.perf_counter() - t0
                kern.clear()
            spent = done = 0
            while done < calls or (spent < seconds and done < cap):
                t0, before = time.perf_counter(), len(kern)
                self.result = self.call()
                self.walls.append(time.perf_counter() - t0)
                self.kernel.append(sum(kern[before:]))  # a chunked flight calls the kernel once a chunk
                spent, done = spent + self.walls[-1], done + 1

    def summary(self) -> dict:
        """The best call and the median, whole and compiled kernel alone (rates in
        vehicle-steps/s)."""
        res = self.result
        if res.stopped.any():  # a stop would shorten the work timed (a short circle is off track: fine)
            raise RuntimeError(f"a benchmark flight stopped early: {res.status_text(int(np.argmax(res.stopped)))}")
        best, kbest = min(self.walls), min(self.kernel)
        return {
            "vehicle_steps": self.work,
            "first_call_s": self.first,
            "best_s": best,
            "runs_s": self.walls,
            "calls": len(self.walls),
            "rate": self.work / best,
            "median_rate": self.work / float(np.median(self.walls)),
            "kernel_s": kbest,
            "kernel_rate": self.work / kbest,
        }


def measure(figures: dict, repeats: int, min_s: float = 0.0, rounds: int = 1) -> dict:
    """Time ``figures`` (name -> Timing) in ``rounds`` rounds, each figure in turn within a
    round: every figure makes at least ``repeats`` calls in all, and more until they have
    taken ``min_s`` seconds (at most MAX_CALLS). Rounds spread each figure's calls over the
    whole run, so that a slow spell of the host, which can last tens of seconds, meets
    every figure's calls alike instead of deciding one figure. Returns name -> summary."""
    calls, seconds, cap = -(-repeats // rounds), min_s / rounds, -(-MAX_CALLS // rounds)
    for _ in range(rounds):
        for fig in figures.values():
            fig.round(calls, seconds, cap)
    return {name: fig.summary() for name, fig in figures.items()}


def masses(n: int) -> np.ndarray:
    """Table I's mass, spread +/- 10 % over a batch."""
    return 3.499 * (np.linspace(0.9, 1.1, n) if n > 1 else np.ones(1))


def open_loop_setup(duration: float, m: np.ndarray):
    """Hover duty (Table I vehicle) +/- 5 % at 0.5 Hz on all rotors, one row per 10 ms; each
    vehicle starts slightly tilted and yawed (so the trigonometry sees non-zero angles),
    rotors at the first row's thrust."""
    import quadcruise as qc
    from quadcruise.layout import F1, P_K, PHI, PSI, THETA, Z

    vp = (qc.Vehicle(m=m) if m.size > 1 else qc.Vehicle(m=float(m[0]))).rows()
    t_rows = np.arange(round(duration * ROW_HZ) + 1) / ROW_HZ
    u = qc.Vehicle.paper().hover_duty * (1.0 + 0.05 * np.sin(np.pi * t_rows))[:, None] * np.ones(4)
    x0 = np.zeros((vp.shape[0], 16))
    x0[:, [Z, PHI, THETA, PSI]] = [1.0, 0.02, -0.01, 0.3]
    x0[:, F1 : F1 + 4] = vp[:, [P_K]] * u[0]
    return vp, x0, t_rows, u


def open_loop(n: int, duration: float) -> Timing:
    from quadcruise import simulate, time_grid
    from quadcruise.control.openloop import duty_schedule, pack_schedule
    from quadcruise.workflows.replay import no_reference

    def prepare(dur):
        vp, x0, t_rows, u = open_loop_setup(dur, masses(n))
        grid, gains = time_grid(dur, 1.0 / HZ), pack_schedule(t_rows, u)
        return lambda: simulate(
            grid,
            x0,
            vp,
            duty_schedule,
            gains,
            no_reference,
            np.zeros(1),
            memory=np.zeros(1),
            max_step=1.0 / HZ,
            log_every=1000,
        )

    return Timing(prepare, n, duration)


def closed_loop(n: int, duration: float) -> Timing:
    """The paper's controller on the default circle (R 2 m, 20 s a lap: 60 s is 3 laps)."""
    import quadcruise as qc

    vehicle = qc.Vehicle(m=masses(n)) if n > 1 else None
    # log every second, or the whole warm-up call's 10 periods (log_every must divide the periods)
    return Timing(
        lambda dur: (
            lambda: qc.fly(
                "circle", "nlpd", vehicle=vehicle, duration=dur, dt=1.0 / HZ, log_every=math.gcd(1000, round(dur * HZ))
            )
        ),
        n,
        duration,
    )


def rhs_batch(
    x: np.ndarray, u: np.ndarray, m: np.ndarray, Jxx=0.03, Jyy=0.03, Jzz=0.04, l=0.2, K=120.0, w=15.0, d=4 / 120, g=9.81
) -> np.ndarray:
    """The paper's plant (eqs 1-7, 11 and the rotor lag, Table I's vehicle) in numpy over x of
    shape (N, 16), one mass per vehicle: scipy's right-hand side, written from the equations
    (:func:`check_rhs` compares it with the compiled plant that quadcruise integrates)."""
    phi, th, psi, p, q, r = x[:, 6], x[:, 7], x[:, 8], x[:, 9], x[:, 10], x[:, 11]
    F = x[:, 12:16]
    U1 = F.sum(axis=1)
    a, cphi, sphi, cpsi, spsi = U1 / m, np.cos(phi), np.sin(phi), np.cos(psi), np.sin(psi)
    dx = np.empty_like(x)
    dx[:, 0:3] = x[:, 3:6]
    dx[:, 3] = (sphi * spsi + cphi * np.sin(th) * cpsi) * a
    dx[:, 4] = (-sphi * cpsi + cphi * np.sin(th) * spsi) * a
    dx[:, 5] = cphi * np.cos(th) * a - g
    dx[:, 6:9] = x[:, 9:12]
    dx[:, 9] = ((Jyy - Jzz) * q * r + l * (F[:, 1] - F[:, 3])) / Jxx
    dx[:, 10] = ((Jzz - Jxx) * p * r + l * (F[:, 0] - F[:, 2])) / Jyy
    dx[:, 11] = ((Jxx - Jyy) * p * q + d * (F[:, 0] + F[:, 2] - F[:, 1] - F[:, 3])) / Jzz
    dx[:, 12:16] = w * (K * u - F)
    return dx


def check_rhs(x: np.ndarray, u: np.ndarray, m: np.ndarray) -> None:
    """rhs_batch on the rows x equals quadcruise's compiled derivative (still air) for the
    vehicles of masses m, to rounding: both integrate the same equations."""
    import quadcruise as qc
    from quadcruise.layout import EXT_E1, EXT_SIZE
    from quadcruise.model.plant import derivative

    vp = (qc.Vehicle(m=m) if m.size > 1 else qc.Vehicle(m=float(m[0]))).rows()
    ext = np.zeros(EXT_SIZE)
    ext[EXT_E1 : EXT_E1 + 4] = 1.0
    ours = np.empty_like(x)
    for i in range(x.shape[0]):
        derivative(x[i], u, vp[i], ext, False, ours[i])
    np.testing.assert_allclose(rhs_batch(x, u, m), ours, rtol=1e-12, atol=1e-12)


def bench_scipy(duration: float, n: int, budget_s: float, max_step: float) -> dict:
    """solve_ivp RK45 (rtol 1e-6, atol 1e-9) row by row: each 10 ms row is one solve_ivp call
    from the previous row's end state, so the held duties are honoured exactly. N vehicles
    are one (N*16)-state vectorised system. If the first 10 % of the rows point to more
    than ``budget_s`` in all, the rest is extrapolated linearly; else the run is repeated
    (best kept) while the runs so far and one more fit in ``budget_s``."""
    from scipy.integrate import solve_ivp

    m = masses(n)
    _, x0, t_rows, u = open_loop_setup(duration, m)
    check_rhs(x0[-1:], u[0], m[-1:])
    rows, probe, runs, done = len(t_rows) - 1, max(1, (len(t_rows) - 1) // 10), [], 0
    while not runs or (sum(runs) + runs[-1] <= budget_s and done == rows and len(runs) < 5):
        y, nfev, done = x0.ravel(), 0, 0
        t0 = time.perf_counter()
        for k in range(rows):
            fun = lambda t, y, uk=u[k]: rhs_batch(y.reshape(n, 16), uk, m).ravel()  # noqa: E731
            sol = solve_ivp(fun, (t_rows[k], t_rows[k + 1]), y, method="RK45", rtol=1e-6, atol=1e-9, max_step=max_step)
            y, nfev, done = sol.y[:, -1], nfev + sol.nfev, k + 1
            if done == probe and (time.perf_counter() - t0) * rows / probe > budget_s:
                break
        runs.append((time.perf_counter() - t0) * rows / done)
    work = n * round(duration * HZ)
    return {
        "vehicle_steps": work,
        "simulated_s": duration * done / rows,
        "best_s": min(runs),
        "runs_s": runs,
        "rate": work / min(runs),
        "rhs_evals": nfev,
        "extrapolated": done < rows,
        "final_state": y.reshape(n, 16),
    }


def timed_subprocess(make_cmd, repeats: int, env: dict | None = None) -> tuple[float, float] | str:
    """(wall, CPU) seconds of the fastest of ``repeats`` runs of ``make_cmd(i)``, or its error.
    CPU time (user + system) hardly depends on what else the machine is running."""
    best = None
    for i in range(repeats):
        cpu0, t0 = resource.getrusage(resource.RUSAGE_CHILDREN), time.perf_counter()
        proc = subprocess.run(make_cmd(i), capture_output=True, text=True, cwd=tempfile.gettempdir(), env=env)
        wall, cpu1 = time.perf_counter() - t0, resource.getrusage(resource.RUSAGE_CHILDREN)
        if proc.returncode:
            return f"failed (rc {proc.returncode}): {(proc.stderr or proc.stdout).strip()[-200:]}"
        cpu = cpu1.ru_utime + cpu1.ru_stime - cpu0.ru_utime - cpu0.ru_stime
        best = (wall, cpu) if best is None or wall < best[0] else best
    return best


def bench_startup(cold: bool, repeats: int) -> dict:
    """Fresh interpreters: ``python -c`` flying the circle, and ``quadcruise fly circle``. A
    cold run gets an empty numba cache of its own (NUMBA_CACHE_DIR), so it compiles
    everything while the package's cache, which other processes share, stays as it is."""
    out: dict = {}
    exe = shutil.which("quadcruise", path=str(Path(sys.executable).parent))
    helptext = subprocess.run([exe, "--help"], capture_output=True, text=True).stdout if exe else ""
    has_fly = any(ln.split()[:1] == ["fly"] for ln in helptext.splitlines())
    with tempfile.TemporaryDirectory() as tmp:
        cmds = {
            "python": lambda i: [sys.executable, "-c", "import quadcruise; quadcruise.fly('circle')"],
            "cli": lambda i: [exe, "fly", "circle", "--out", str(Path(tmp) / f"{kind}{i}")],
        }
        for name, make in cmds.items():
            if name == "cli" and not has_fly:
                out["cli_skipped"] = "no 'fly' subcommand in `quadcruise --help`"
                continue
            for kind in ("cold", "warm") if cold else ("warm",):
                env = os.environ | {"NUMBA_CACHE_DIR": tempfile.mkdtemp(dir=tmp)} if kind == "cold" else None
                got = timed_subprocess(make, 1 if kind == "cold" else repeats, env)
                out[f"{name}_{kind}_s"], out[f"{name}_{kind}_cpu_s"] = got if isinstance(got, tuple) else (got, None)
    return out


def row(label: str, value, unit: str, target=None, quick=False, note="") -> str:
    """One line of the table; target > 0: at least that, target < 0: below -target."""
    if isinstance(value, str):
        return f"  {label:<44} {value}"
    shown = (
        f"{value:8.2f} s  " if unit == "s" else f"{value / 1e6:8.2f} M/s" if value >= 1e5 else f"{value / 1e3:8.1f} k/s"
    )
    verdict = ""
    if target is not None:
        ok = value >= target if target > 0 else value < -target
        want = f">= {target / 1e6:g} M/s" if target > 0 else f"< {-target:g} s"
        verdict = f"    target {want}: " + ("(quick)" if quick else "PASS" if ok else "MISS")
    return f"  {label:<44} {shown}{verdict}{note}"


def engine_section(size: dict, quick: bool, r: dict, final: dict) -> None:
    print(
        f"\nquadcruise, RK4 at {HZ:g} Hz: vehicle-steps/s, best whole call of at least {size['repeats']}, "
        f"repeated for {size['min_s']:g} s, in {size['rounds']} rounds taken in turn\n"
        f"  [compiled kernel alone] (median; calls); first call = 10 steps, compile or cache load included"
    )
    one, bn, bs = f"1 vehicle, {size['single_s']:g} s", f"{size['batch_n']} vehicles", f"{size['batch_s']:g} s"
    rows = (
        ("openloop_single", f"open loop, {one}", open_loop, 1, size["single_s"], 3e6),
        ("openloop_batch", f"open loop, {bn}, {bs}", open_loop, size["batch_n"], size["batch_s"], 5e6),
        ("closedloop_single", f"nlpd circle, {one}", closed_loop, 1, size["single_s"], 2.5e6),
        ("closedloop_batch", f"nlpd circle, {bn}, {bs}", closed_loop, size["batch_n"], size["batch_s"], 5e6),
    )
    figures = {key: make(n, dur) for key, _, make, n, dur, _ in rows}
    r |= measure(figures, size["repeats"], size["min_s"], size["rounds"])
    for key, label, *_, target in rows:
        d, final[key] = r[key], figures[key].result.final_state
        print(
            row(
                label,
                d["rate"],
                "/s",
                target,
                quick,
                f"  [{d['kernel_rate'] / 1e6:.2f} M]  ({d['median_rate'] / 1e6:.2f} M; {d['calls']})"
                f"  first {d['first_call_s'] * 1e3:.1f} ms",
            )
        )
    d = r["call_overhead"]
    print(
        f"  fixed cost of one call (1 vehicle, 10 steps): {d['best_s'] * 1e3:.2f} ms, "
        f"kernel {d['kernel_s'] * 1e3:.2f} ms"
    )


def scipy_section(size: dict, r: dict, final: dict) -> None:
    print(
        "\nscipy solve_ivp RK45, rtol 1e-6, atol 1e-9, one call per 10 ms duty row; "
        "max_step 1 ms (quadcruise's step) or none (adaptive)"
    )
    for key, n, dur, qc_key, max_step in (
        ("scipy_single", 1, size["scipy_single_s"], "openloop_single", 1e-3),
        ("scipy_single_adaptive", 1, size["scipy_single_s"], "openloop_single", math.inf),
        ("scipy_batch", size["scipy_batch_n"], size["scipy_batch_s"], "openloop_batch", 1e-3),
        ("scipy_batch_adaptive", size["scipy_batch_n"], size["scipy_batch_s"], "openloop_batch", math.inf),
    ):
        r[key] = d = bench_scipy(dur, n, size["scipy_budget_s"], max_step)
        d["speedup"] = r[qc_key]["rate"] / d["rate"]
        x_sp, x_qc = d.pop("final_state"), final[qc_key]
        same = (
            not d["extrapolated"]
            and x_sp.shape == x_qc.shape
            and dur == (size["single_s"] if n == 1 else size["batch_s"])
        )
        d["max_abs_diff_vs_quadcruise"] = float(np.abs(x_sp - x_qc).max()) if same else None
        how = (
            f"EXTRAPOLATED from {d['simulated_s']:g} s of {dur:g} s"
            if d["extrapolated"]
            else f"best of {len(d['runs_s'])}"
        )
        agree = f"; final states agree to {d['max_abs_diff_vs_quadcruise']:.1e}" if same else ""
        label = f"{n} vehicle{'s' * (n > 1)}, {dur:g} s, {'1 ms' if max_step < 1 else 'adaptive'}"
        print(
            row(
                f"{label}, {d['rhs_evals']} rhs evals",
                d["rate"],
                "/s",
                note=f"    quadcruise x{d['speedup']:.{0 if d['speedup'] >= 10 else 1}f} faster; {how}{agree}",
            )
        )


def startup_section(size: dict, quick: bool, cold: bool, r: dict) -> None:
    r["startup"] = s = bench_startup(cold, size["warm_repeats"])
    print(
        f"\nstart-up: wall time of a fresh process (warm: best of {size['warm_repeats']}; "
        f"cold: an empty numba cache, so everything compiles), (its CPU time)"
    )
    for name, label in (("python", "python -c \"...fly('circle')\""), ("cli", "quadcruise fly circle --out DIR")):
        if f"{name}_skipped" in s:
            print(row(label, f"skipped: {s[name + '_skipped']}", "s"))
            continue
        for kind, target in (("cold", -20.0), ("warm", -3.0)):
            cpu = s.get(f"{name}_{kind}_cpu_s")
            print(
                row(
                    f"{label}, {kind}",
                    s.get(f"{name}_{kind}_s", "not measured (give --cold)"),
                    "s",
                    target,
                    quick,
                    f"  (cpu {cpu:.2f} s)" if cpu else "",
                )
            )


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--quick", action="store_true", help="small sizes: a smoke test (< 20 s)")
    ap.add_argument("--json", metavar="PATH", help="also write the figures as JSON")
    ap.add_argument("--cold", action="store_true", help="also time start-up with an empty numba cache")
    ap.add_argument("--skip-scipy", action="store_true", help="leave out the scipy comparison")
    args = ap.parse_args(argv)
    size = QUICK if args.quick else FULL
    t0 = time.perf_counter()
    import quadcruise  # noqa: F401

    import_s = time.perf_counter() - t0
    import scipy

    info = machine(scipy=scipy.__version__) | {"import_s": import_s}
    r: dict = measure({"call_overhead": open_loop(1, 10 / HZ)}, 7)
    final: dict = {}
    print(
        f"quadcruise {info['quadcruise']} engine benchmark{' --quick' if args.quick else ''}\n"
        f"  {info['cpu']}, {info['cores']} cores, {info['numba_threads']} threads (numba's number); "
        f"python {info['python']}, numba {info['numba']}, "
        f"numpy {info['numpy']}, scipy {info['scipy']}\n"
        f"  load average {info['load_avg_start'][0]:.2f} at start; import quadcruise {info['import_s']:.2f} s; "
        f"speed probe {info['probe_ns_start']:.0f} ns per plant RK4 step"
    )
    engine_section(size, args.quick, r, final)
    if not args.skip_scipy:
        scipy_section(size, r, final)
    startup_section(size, args.quick, args.cold, r)
    print("\n" + end_of_run(info))
    if args.json:
        Path(args.json).write_text(
            json.dumps({"machine": info, "quick": args.quick, "sizes": size, "results": r}, indent=2)
        )
    return 0


if __name__ == "__main__":
    sys.exit(main())
