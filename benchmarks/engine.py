"""Engine throughput, scipy comparison and cold start: ``python benchmarks/engine.py``.

Options: --quick (smaller sizes, a smoke test), --json PATH, --skip-scipy, --cold (clears
numba's cache for the package first: every process's next run recompiles). See README.md.
"""

from __future__ import annotations

import argparse
import contextlib
import json
import os
import platform
import shutil
import subprocess
import sys
import tempfile
import time
from pathlib import Path

import numba
import numpy as np

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT / "tests"))
from reference_model import rhs as reference_rhs  # noqa: E402

HZ = 1000.0          # control and integration rate of every benchmark [1/s]
ROW_HZ = 100.0       # open-loop schedule: duties held for 10 ms per row
FULL = dict(single_s=60.0, batch_n=2000, batch_s=10.0, repeats=5, warm_repeats=3,
            scipy_single_s=60.0, scipy_batch_n=2000, scipy_batch_s=10.0, scipy_budget_s=60.0)
QUICK = dict(single_s=2.0, batch_n=100, batch_s=1.0, repeats=2, warm_repeats=1,
             scipy_single_s=0.5, scipy_batch_n=50, scipy_batch_s=0.1, scipy_budget_s=5.0)
TOL = dict(method="RK45", rtol=1e-6, atol=1e-9, max_step=1e-3)


def machine() -> dict:
    cpu = next((ln.split(":", 1)[1].strip() for ln in Path("/proc/cpuinfo").read_text().splitlines()
                if ln.startswith("model name")), platform.processor())
    import scipy
    import quadcruise
    return {"cpu": cpu, "cores": os.cpu_count(), "numba_threads": numba.get_num_threads(),
            "python": platform.python_version(), "numba": numba.__version__, "numpy": np.__version__,
            "scipy": scipy.__version__, "quadcruise": quadcruise.__version__,
            "load_avg_start": list(os.getloadavg())}


@contextlib.contextmanager
def kernel_clock():
    """Time each call of the compiled kernel inside simulate()/fly() (list of seconds)."""
    from quadcruise import engine
    real, spent = engine._kernel, []

    def timed(*args):
        t0 = time.perf_counter()
        real(*args)
        spent.append(time.perf_counter() - t0)
    engine._kernel = timed
    try:
        yield spent
    finally:
        engine._kernel = real


def measure(call, work: float, repeats: int) -> dict:
    """First call (JIT or cache load included), then best of ``repeats`` for the whole call
    and for the compiled kernel alone. ``work`` = vehicle-steps per call."""
    with kernel_clock() as kern:
        t0 = time.perf_counter()
        res = call()
        first = time.perf_counter() - t0
        if not res.ok.all():
            raise RuntimeError(f"benchmark flight stopped early: {res.status_text(int(np.argmin(res.ok)))}")
        walls = []
        for _ in range(repeats):
            t0 = time.perf_counter()
            call()
            walls.append(time.perf_counter() - t0)
    best, kbest = min(walls), min(kern[1:])
    return {"vehicle_steps": work, "first_call_s": first, "best_s": best, "runs_s": walls,
            "rate": work / best, "kernel_s": kbest, "kernel_rate": work / kbest}, res


def open_loop_setup(duration: float, masses: np.ndarray):
    """Hover duty (Table I vehicle) +/- 5 % at 0.5 Hz on all rotors, one row per 10 ms; each
    vehicle starts slightly tilted and yawed (so the trigonometry sees non-zero angles),
    rotors at the first row's thrust."""
    import quadcruise as qc
    from quadcruise.layout import F1, PHI, PSI, THETA, Z
    vehicle = qc.Vehicle(m=masses) if masses.size > 1 else qc.Vehicle(m=float(masses[0]))
    vp = vehicle.rows()
    t_rows = np.arange(round(duration * ROW_HZ) + 1) / ROW_HZ
    u = qc.Vehicle.paper().hover_duty * (1.0 + 0.05 * np.sin(np.pi * t_rows))[:, None] * np.ones(4)
    x0 = np.zeros((vp.shape[0], 16))
    x0[:, [Z, PHI, THETA, PSI]] = [1.0, 0.02, -0.01, 0.3]
    x0[:, F1:F1 + 4] = vp[:, [5]] * u[0]                      # column 5: K
    return vp, x0, t_rows, u


def bench_open_loop(duration: float, n: int, repeats: int):
    from quadcruise import simulate, time_grid
    from quadcruise.control.openloop import duty_schedule, pack_schedule
    from quadcruise.replay import no_reference
    masses = 3.499 * (np.linspace(0.9, 1.1, n) if n > 1 else np.ones(1))
    vp, x0, t_rows, u = open_loop_setup(duration, masses)
    grid, gains = time_grid(duration, 1.0 / HZ), pack_schedule(t_rows, u)
    call = lambda: simulate(grid, x0, vp, duty_schedule, gains, no_reference, np.zeros(1),  # noqa: E731
                            memory=np.zeros(1), max_step=1.0 / HZ, log_every=1000)
    out, res = measure(call, n * (len(grid) - 1), repeats)
    return out, res.final_state


def bench_call_overhead(repeats: int) -> dict:
    """Fixed cost of one simulate() call: 1 vehicle, 1 step (argument checks, allocation,
    dispatch and the parallel region's start and join)."""
    out = bench_open_loop(1.0 / ROW_HZ, 1, max(repeats, 5))[0]
    return {"first_call_s": out["first_call_s"], "best_s": out["best_s"], "kernel_s": out["kernel_s"]}


def bench_closed_loop(duration: float, n: int, repeats: int):
    import quadcruise as qc
    vehicle = qc.Vehicle(m=3.499 * np.linspace(0.9, 1.1, n)) if n > 1 else None
    call = lambda: qc.fly("circle", "nlpd", vehicle=vehicle, duration=duration,  # noqa: E731
                          dt=1.0 / HZ, log_every=1000)
    return measure(call, n * round(duration * HZ), repeats)[0]


def rhs_batch(x: np.ndarray, u: np.ndarray, m: np.ndarray, Jxx=0.03, Jyy=0.03, Jzz=0.04, l=0.2,
              K=120.0, w=15.0, d=4 / 120, g=9.81) -> np.ndarray:
    """tests/reference_model.rhs vectorised over x of shape (N, 16), one mass per vehicle."""
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


def bench_scipy(duration: float, n: int, budget_s: float) -> dict:
    """solve_ivp RK45 (rtol 1e-6, atol 1e-9, max_step 1 ms) row by row: each 10 ms row is one
    solve_ivp call from the previous row's end state, so the held duties are honoured exactly.
    N vehicles are one (N*16)-state vectorised system. If the first 10 % of the rows point
    to more than ``budget_s`` in all, the rest is extrapolated linearly."""
    from scipy.integrate import solve_ivp
    masses = 3.499 * (np.linspace(0.9, 1.1, n) if n > 1 else np.ones(1))
    _, x0, t_rows, u = open_loop_setup(duration, masses)
    assert np.allclose(rhs_batch(x0[-1:], u[0], masses[-1:])[0], reference_rhs(x0[-1], u[0], m=masses[-1]))
    probe = max(1, (len(t_rows) - 1) // 10)
    y, nfev, done = x0.ravel(), 0, 0
    t0 = time.perf_counter()
    for k in range(len(t_rows) - 1):
        fun = lambda t, y, uk=u[k]: rhs_batch(y.reshape(n, 16), uk, masses).ravel()  # noqa: E731
        sol = solve_ivp(fun, (t_rows[k], t_rows[k + 1]), y, **TOL)
        y, nfev, done = sol.y[:, -1], nfev + sol.nfev, k + 1
        if done == probe and (time.perf_counter() - t0) * (len(t_rows) - 1) / probe > budget_s:
            break
    elapsed = time.perf_counter() - t0
    scale = (len(t_rows) - 1) / done
    work = n * round(duration * HZ)
    return {"vehicle_steps": work, "simulated_s": duration * done / (len(t_rows) - 1),
            "best_s": elapsed * scale, "rate": work / (elapsed * scale), "rhs_evals": nfev,
            "extrapolated": done < len(t_rows) - 1, "final_state": y.reshape(n, 16)}


def timed_subprocess(cmd: list[str], repeats: int) -> float | str:
    """Best wall time of ``cmd``, or its error text."""
    best = None
    for _ in range(repeats):
        t0 = time.perf_counter()
        proc = subprocess.run(cmd, capture_output=True, text=True, cwd=tempfile.gettempdir())
        wall = time.perf_counter() - t0
        if proc.returncode:
            return f"failed (rc {proc.returncode}): {(proc.stderr or proc.stdout).strip()[-200:]}"
        best = wall if best is None else min(best, wall)
    return best


def clear_numba_cache() -> int:
    import quadcruise
    files = [p for pat in ("*.nbi", "*.nbc") for p in Path(quadcruise.__file__).parent.rglob(pat)]
    for p in files:
        p.unlink(missing_ok=True)
    return len(files)


def bench_startup(cold: bool, repeats: int) -> dict:
    out: dict = {}
    exe = shutil.which("quadcruise", path=str(Path(sys.executable).parent))
    py = [sys.executable, "-c", "import quadcruise; quadcruise.fly('circle')"]
    helptext = subprocess.run([exe, "--help"], capture_output=True, text=True).stdout if exe else ""
    has_fly = any(ln.split()[:1] == ["fly"] for ln in helptext.splitlines())
    with tempfile.TemporaryDirectory() as tmp:
        cli = [exe, "fly", "circle", "--out", tmp]
        for name, cmd in (("python", py), ("cli", cli if has_fly else None)):
            if cmd is None:
                out[f"{name}_skipped"] = "no 'fly' subcommand in `quadcruise --help`"
                continue
            if cold:
                out[f"{name}_cleared_files"] = clear_numba_cache()
                out[f"{name}_cold_s"] = timed_subprocess(cmd, 1)
            out[f"{name}_warm_s"] = timed_subprocess(cmd, repeats)
    return out


def row(label, value, unit, target=None, higher=True, quick=False, note=""):
    if isinstance(value, str):
        return f"  {label:<44} {value}"
    shown = f"{value / 1e6:9.2f} M" if unit.endswith("/s") else f"{value:9.2f}  "
    verdict = ""
    if target is not None:
        ok = value >= target if higher else value < target
        t = f"{target / 1e6:g} M" if unit.endswith("/s") else f"{target:g} s"
        verdict = f"  target {'>=' if higher else '<'} {t}: " + ("(quick)" if quick else "PASS" if ok else "MISS")
    return f"  {label:<44} {shown}{unit:<15}{verdict}{note}"


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--quick", action="store_true", help="small sizes: a smoke test (< 20 s)")
    ap.add_argument("--json", metavar="PATH", help="also write the figures as JSON")
    ap.add_argument("--cold", action="store_true", help="clear numba's cache for the package and time a cold start")
    ap.add_argument("--skip-scipy", action="store_true", help="leave out the scipy comparison")
    args = ap.parse_args(argv)
    size, q = (QUICK if args.quick else FULL), args.quick
    t_import = time.perf_counter()
    import quadcruise  # noqa: F401
    info = machine()
    info["import_s"] = time.perf_counter() - t_import
    r: dict = {"call_overhead": bench_call_overhead(size["repeats"])}
    info["threading_layer"] = numba.threading_layer()
    print(f"quadcruise {info['quadcruise']} engine benchmark{' (--quick)' if q else ''}")
    print(f"  {info['cpu']}, {info['cores']} cores, numba threads {info['numba_threads']} "
          f"({info['threading_layer']}); python "
          f"{info['python']}, numba {info['numba']}, numpy {info['numpy']}, scipy {info['scipy']}")
    print(f"  load average at start {info['load_avg_start'][0]:.2f}; import quadcruise {info['import_s']:.2f} s; "
          f"RK4 at {HZ:g} Hz, best of {size['repeats']} after a first call")
    r["openloop_single"], x_qc1 = bench_open_loop(size["single_s"], 1, size["repeats"])
    r["openloop_batch"], x_qcn = bench_open_loop(size["batch_s"], size["batch_n"], size["repeats"])
    r["closedloop_single"] = bench_closed_loop(size["single_s"], 1, size["repeats"])
    r["closedloop_batch"] = bench_closed_loop(size["batch_s"], size["batch_n"], size["repeats"])
    print(f"\nquadcruise (vehicle-steps/s, whole call; [compiled kernel alone]; first call)")
    for key, label, target in (("openloop_single", f"open loop, 1 vehicle, {size['single_s']:g} s", 3e6),
                               ("openloop_batch", f"open loop, {size['batch_n']} vehicles, {size['batch_s']:g} s", 5e6),
                               ("closedloop_single", f"nlpd circle, 1 vehicle, {size['single_s']:g} s", 2.5e6),
                               ("closedloop_batch", f"nlpd circle, {size['batch_n']} vehicles, {size['batch_s']:g} s", 5e6)):
        d = r[key]
        print(row(label, d["rate"], " steps/s", target, quick=q,
                  note=f"  [{d['kernel_rate'] / 1e6:.2f} M]  first {d['first_call_s']:.3f} s"))
    d = r["call_overhead"]
    print(f"  fixed cost of a call (1 vehicle, 10 steps): {d['best_s'] * 1e3:.2f} ms, "
          f"of which the kernel {d['kernel_s'] * 1e3:.2f} ms")
    if not args.skip_scipy:
        print(f"\nscipy solve_ivp RK45 rtol 1e-6 atol 1e-9 max_step 1 ms, one call per 10 ms duty row")
        for key, n, dur, qc_key, x_qc in (("scipy_single", 1, size["scipy_single_s"], "openloop_single", x_qc1),
                                          ("scipy_batch", size["scipy_batch_n"], size["scipy_batch_s"],
                                           "openloop_batch", x_qcn)):
            d = bench_scipy(dur, n, size["scipy_budget_s"])
            d["speedup"] = r[qc_key]["rate"] / d["rate"]
            x_sp = d.pop("final_state")
            same = dur == (size["single_s"] if n == 1 else size["batch_s"]) and not d["extrapolated"]
            d["max_abs_diff_vs_quadcruise"] = float(np.abs(x_sp - x_qc).max()) if same else None
            how = (f"EXTRAPOLATED from {d['simulated_s']:g} s of {dur:g} s" if d["extrapolated"] else "measured, 1 run")
            diff = d["max_abs_diff_vs_quadcruise"]
            print(row(f"{n} vehicle{'s' * (n > 1)}, {dur:g} s ({d['rhs_evals']} rhs evals)", d["rate"], " steps/s",
                      note=f"  quadcruise x{d['speedup']:.0f}; {how}"
                           + (f"; final state agrees to {diff:.1e}" if diff is not None else "")))
            r[key] = d
    r["startup"] = s = bench_startup(args.cold, size["warm_repeats"])
    print("\nstart-up (subprocess wall time, fresh interpreter; cold = numba cache cleared first)")
    for name, label in (("python", "python -c \"...fly('circle')\""), ("cli", "quadcruise fly circle --out DIR")):
        if f"{name}_skipped" in s:
            print(row(label, f"skipped: {s[name + '_skipped']}", ""))
            continue
        for kind, target in (("cold", 20.0), ("warm", 3.0)):
            v = s.get(f"{name}_{kind}_s", "not measured (give --cold)" if kind == "cold" else "?")
            print(row(f"{label}, {kind}", v, " s", target, higher=False, quick=q))
    info["load_avg_end"] = list(os.getloadavg())
    print(f"\nload average at end {info['load_avg_end'][0]:.2f}")
    if args.json:
        Path(args.json).write_text(json.dumps({"machine": info, "quick": q, "sizes": size, "results": r},
                                              indent=2, default=float))
    return 0


if __name__ == "__main__":
    sys.exit(main())
