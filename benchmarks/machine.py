"""What every benchmark prints about the machine it ran on.

Shared virtual machines change speed from minute to minute. So besides the load average,
each benchmark prints a speed probe at its start and its end: the time of one RK4 step of
the plant (one vehicle, one thread, a compiled loop). Figures from runs whose probes differ
are not comparable; divide by the probe's ratio to compare them roughly.
"""

from __future__ import annotations

import functools
import os
import platform
from pathlib import Path

import numpy as np
from numba import njit


def machine(**versions: str) -> dict:
    """CPU, cores, numba threads, the versions of Python, numba, numpy and quadcruise (plus
    any ``versions`` given), and the load average at the start."""
    import numba

    import quadcruise

    lines = Path("/proc/cpuinfo").read_text().splitlines() if Path("/proc/cpuinfo").exists() else []
    cpu = next((ln.split(":", 1)[1].strip() for ln in lines if ln.startswith("model name")), platform.processor())
    return {
        "cpu": cpu,
        "cores": os.cpu_count(),
        "numba_threads": numba.get_num_threads(),
        "python": platform.python_version(),
        "numba": numba.__version__,
        "numpy": np.__version__,
        **versions,
        "quadcruise": quadcruise.__version__,
        "load_avg_start": list(os.getloadavg()),
        "probe_ns_start": probe(),
    }


def probe(steps: int = 200_000, repeats: int = 3) -> float:
    """Nanoseconds of one RK4 step of the Table I plant (hovering slightly tilted, one
    thread): best of ``repeats`` loops of ``steps``."""
    import time

    import quadcruise as qc
    from quadcruise.layout import EXT_E1, EXT_SIZE, F1, P_G, P_M, PHI, PSI, STATE_SIZE, THETA, Z

    vp = qc.Vehicle.paper().rows(1)[0]
    x = np.zeros(STATE_SIZE)
    x[Z], x[PHI], x[THETA], x[PSI] = 1.0, 0.02, -0.01, 0.3
    x[F1 : F1 + 4] = vp[P_M] * vp[P_G] / 4.0
    u = np.full(4, qc.Vehicle.paper().hover_duty)
    ext = np.zeros(EXT_SIZE)
    ext[EXT_E1 : EXT_E1 + 4] = 1.0
    loop = _rk4_loop()
    loop(x.copy(), u, vp, ext, 10)
    best = float("inf")
    for _ in range(repeats):
        t0 = time.perf_counter()
        loop(x.copy(), u, vp, ext, steps)
        best = min(best, time.perf_counter() - t0)
    return 1e9 * best / steps


def end_of_run(info: dict) -> str:
    """Record the load average and the speed probe at the end of a run in ``info``; the line
    that reports them."""
    info["load_avg_end"] = list(os.getloadavg())
    info["probe_ns_end"] = probe()
    return (
        f"load average at the end: {', '.join(f'{v:.2f}' for v in info['load_avg_end'])}; speed probe "
        f"{info['probe_ns_end']:.0f} ns (at the start {info['probe_ns_start']:.0f} ns)"
    )


@functools.cache
def _rk4_loop():
    """A compiled loop of RK4 steps of the plant, built on first use (after quadcruise is
    imported, so that importing this module does not import it)."""
    from quadcruise.layout import STATE_SIZE
    from quadcruise.sim.engine import WORK_ROWS, rk4_step
    from quadcruise.sim.fastmath import TRIG_REFRESH

    @njit(error_model="numpy")
    def loop(x, u, vp, ext, steps):
        work = np.empty((WORK_ROWS, STATE_SIZE))
        for i in range(steps):
            rk4_step(x, u, vp, ext, False, 1e-3, work, i % TRIG_REFRESH == 0)
        return x[0]

    return loop
