"""`benchmarks/engine.py --quick` runs and writes its figures; speed is not checked here
(the targets live in the benchmark itself)."""

import json
import math
import subprocess
import sys
from pathlib import Path

SCRIPT = Path(__file__).resolve().parents[2] / "benchmarks" / "engine.py"
TIMINGS = ("vehicle_steps", "first_call_s", "best_s", "rate", "kernel_s", "kernel_rate")


def positive(value) -> bool:
    return isinstance(value, (int, float)) and not isinstance(value, bool) and math.isfinite(value) and value > 0


def test_quick_benchmark_writes_positive_figures(tmp_path):
    out = tmp_path / "bench.json"
    proc = subprocess.run(
        [sys.executable, str(SCRIPT), "--quick", "--skip-scipy", "--json", str(out)],
        capture_output=True,
        text=True,
        timeout=600,
    )
    assert proc.returncode == 0, proc.stderr[-2000:]
    assert "open loop, 1 vehicle" in proc.stdout
    data = json.loads(out.read_text())

    assert data["quick"] is True
    for key in ("cpu", "cores", "numba_threads", "numba", "numpy", "scipy", "quadcruise"):
        assert key in data["machine"], key
    assert positive(data["machine"]["cores"]) and positive(data["machine"]["import_s"])

    results = data["results"]
    for bench in ("call_overhead", "openloop_single", "openloop_batch", "closedloop_single", "closedloop_batch"):
        for key in TIMINGS:
            assert positive(results[bench][key]), (bench, key, results[bench].get(key))
        assert all(positive(t) for t in results[bench]["runs_s"])
    assert results["openloop_batch"]["vehicle_steps"] > results["openloop_single"]["vehicle_steps"]
    assert not any(key.startswith("scipy") for key in results)  # --skip-scipy

    startup = results["startup"]
    assert positive(startup["python_warm_s"]), startup
    assert "python_cold_s" not in startup  # no --cold: warm only
    assert positive(startup["cli_warm_s"]) or "cli_skipped" in startup, startup


def test_quick_gym_benchmark_writes_positive_figures(tmp_path):
    out = tmp_path / "gym.json"
    script = SCRIPT.parent / "gym.py"
    proc = subprocess.run(
        [sys.executable, str(script), "--quick", "--json", str(out)],
        check=False,
        capture_output=True,
        text=True,
        timeout=600,
    )
    assert proc.returncode == 0, proc.stderr[-2000:]
    data = json.loads(out.read_text())
    assert positive(data["fly_rate"])
    assert set(data["modes"]) == {"rotors", "rates", "attitude", "velocity"}
    assert all(positive(m["rate"]) and positive(m["ratio_to_fly"]) for m in data["modes"].values())


def test_quick_rotor_benchmark_flies_both_plants(tmp_path):
    out = tmp_path / "rotor.json"
    script = SCRIPT.with_name("rotor.py")
    proc = subprocess.run(
        [sys.executable, str(script), "--quick", "--json", str(out)], capture_output=True, text=True, timeout=600
    )
    assert proc.returncode == 0, proc.stderr[-2000:]
    data = json.loads(out.read_text())
    for side in ("paper", "iris"):
        assert positive(data["results"][side]["rate"]) and len(data["results"][side]["runs_s"]) == 3
    assert positive(data["ratio"]) and "rotor plant / paper plant" in proc.stdout
