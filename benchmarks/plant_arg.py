"""A/B of the kernel's plant: called inline vs passed in as a first-class function
(issue 31's choice): ``python benchmarks/plant_arg.py [--rounds 6] [--vehicles 200] [--steps 2000]``
and ``python benchmarks/plant_arg.py --cache`` (numba's cache across processes).

The prototype is the paper plant's RK4 step (:func:`quadcruise.sim.engine.rk4_step`, compiled
here once more with its signature, ``STEP_SIG``) flown by one small kernel, N vehicles x M
steps at h = 1 ms; each step first clips the vehicle's duties (not with ``--step-only``) to [0, 1] (``paper_clip``, the
plant's per-period command: a small function that numba inlines where it can), then takes the
RK4 step. Two forms differ only in how they reach the plant's two functions:

- ``inline``: the kernel calls them as global jit functions, as ``sim/engine.py``'s
  ``_kernel`` does today (the clip inlined, ``inline="always"``; the step linked into the
  kernel's module, where LLVM may inline it);
- ``passed``: the kernel takes them as arguments of numba's first-class function type
  ``types.FunctionType(STEP_SIG)``, as the kernels take the controller, the mission and the
  disturbance (an indirect call through an address, never inlined).

Both kernels are compiled eagerly with their signatures and ``cache=True``. The timed calls
alternate (A B B A A B ...) in one process; each figure is the process's CPU time
(``time.process_time``) per vehicle-step, best and median over the rounds, and the ratio
passed/inline (above 1: passing the plant costs).

``--cache`` runs two fresh processes with ``NUMBA_DEBUG_CACHE=1`` and a cache folder of their
own (``NUMBA_CACHE_DIR``), each calling both kernels, and prints what numba said of each
kernel: the first should save it, the second load it ("data loaded"). A kernel that takes a
function argument is compiled for that argument's *type*; a jit function handed to a
``FunctionType`` parameter keeps the type, so the cache index does not change with the
function handed in.
"""

from __future__ import annotations

import argparse
import os
import statistics
import subprocess
import sys
import tempfile
import time

import numpy as np
from numba import njit, types

from quadcruise import layout as L
from quadcruise.model.vehicle import Vehicle
from quadcruise.sim.engine import WORK_ROWS, rk4_step

_f8v, _f8m = types.float64[::1], types.float64[:, ::1]
STEP_SIG = types.void(_f8v, _f8v, _f8v, _f8v, types.boolean, types.float64, _f8m, types.boolean)
"""``step(x, u, vp, ext, full, h, work, fresh)``: :func:`~quadcruise.sim.engine.rk4_step`'s."""
StepType = types.FunctionType(STEP_SIG)

paper_step = njit(STEP_SIG, cache=True, error_model="numpy")(rk4_step.py_func)
"""The paper plant's RK4 step, compiled for ``STEP_SIG`` (both kernels call this one)."""

CLIP_SIG = types.int64(_f8v, _f8v)
"""``clip(cmd, u) -> clipped``: a plant's per-period command, here the duties clipped to [0, 1]."""
ClipType = types.FunctionType(CLIP_SIG)


@njit(CLIP_SIG, cache=True, inline="always")
def paper_clip(cmd, u):
    """The duties ``cmd`` clipped to [0, 1] into ``u``; how many were clipped."""
    clipped = 0
    for j in range(4):
        c = cmd[j]
        if c < 0.0 or c > 1.0:
            clipped += 1
        u[j] = min(max(c, 0.0), 1.0)
    return clipped


_KERNEL_TAIL = (_f8m, _f8m, _f8m, types.float64, types.int64, _f8m)


@njit(types.int64(*_KERNEL_TAIL), cache=True, nogil=True, error_model="numpy")
def kernel_inline(x, cmd, vp, h, steps, out):
    """N vehicles x ``steps`` periods (the command clipped, one RK4 step), the plant's two
    functions reached as global jit functions; how many duties were clipped."""
    work = np.zeros((WORK_ROWS, L.STATE_SIZE))
    ext = np.zeros(L.EXT_SIZE)
    ext[L.EXT_E1 :] = 1.0
    u = np.zeros(4)
    clipped = 0
    for i in range(x.shape[0]):
        xi = x[i].copy()
        for k in range(steps):
            clipped += paper_clip(cmd[i], u)
            paper_step(xi, u, vp[i], ext, False, h, work, k % 64 == 0)
        out[i] = xi
    return clipped


@njit(types.int64(ClipType, StepType, *_KERNEL_TAIL), cache=True, nogil=True, error_model="numpy")
def kernel_passed(clip, step, x, cmd, vp, h, steps, out):
    """The same, the plant's two functions passed in as first-class functions."""
    work = np.zeros((WORK_ROWS, L.STATE_SIZE))
    ext = np.zeros(L.EXT_SIZE)
    ext[L.EXT_E1 :] = 1.0
    u = np.zeros(4)
    clipped = 0
    for i in range(x.shape[0]):
        xi = x[i].copy()
        for k in range(steps):
            clipped += clip(cmd[i], u)
            step(xi, u, vp[i], ext, False, h, work, k % 64 == 0)
        out[i] = xi
    return clipped


def inputs(n: int) -> tuple[np.ndarray, ...]:
    """n paper vehicles (masses +/- 10 %) at a hover's thrusts, duties a little above it."""
    rng = np.random.default_rng(0)
    v = Vehicle.paper()
    vp = np.ascontiguousarray(np.broadcast_to(v.rows(1)[0], (n, L.PARAM_SIZE)).copy())
    vp[:, L.P_M] *= rng.uniform(0.9, 1.1, n)
    x = np.zeros((n, L.STATE_SIZE))
    x[:, L.Z] = 1.0
    x[:, L.F1 : L.F1 + 4] = (vp[:, L.P_M] * v.g / 4.0)[:, None]
    u = np.full((n, 4), 0.55)
    return x, u, vp


@njit(types.void(*_KERNEL_TAIL), cache=True, nogil=True, error_model="numpy")
def step_inline(x, u, vp, h, steps, out):
    """The step alone (``--step-only``), reached as a global jit function."""
    work = np.zeros((WORK_ROWS, L.STATE_SIZE))
    ext = np.zeros(L.EXT_SIZE)
    ext[L.EXT_E1 :] = 1.0
    for i in range(x.shape[0]):
        xi = x[i].copy()
        for k in range(steps):
            paper_step(xi, u[i], vp[i], ext, False, h, work, k % 64 == 0)
        out[i] = xi


@njit(types.void(StepType, *_KERNEL_TAIL), cache=True, nogil=True, error_model="numpy")
def step_passed(step, x, u, vp, h, steps, out):
    """The step alone (``--step-only``), passed in as a first-class function."""
    work = np.zeros((WORK_ROWS, L.STATE_SIZE))
    ext = np.zeros(L.EXT_SIZE)
    ext[L.EXT_E1 :] = 1.0
    for i in range(x.shape[0]):
        xi = x[i].copy()
        for k in range(steps):
            step(xi, u[i], vp[i], ext, False, h, work, k % 64 == 0)
        out[i] = xi


def run(which: str, x, u, vp, steps: int, step_only: bool = False) -> tuple[float, np.ndarray]:
    """CPU seconds of one call, and the final states."""
    out = np.empty_like(x)
    start = time.process_time()
    if step_only:
        if which == "inline":
            step_inline(x, u, vp, 1e-3, steps, out)
        else:
            step_passed(paper_step, x, u, vp, 1e-3, steps, out)
    elif which == "inline":
        kernel_inline(x, u, vp, 1e-3, steps, out)
    else:
        kernel_passed(paper_clip, paper_step, x, u, vp, 1e-3, steps, out)
    return time.process_time() - start, out


def ab(rounds: int, n: int, steps: int, step_only: bool = False) -> None:
    """Alternating rounds, one process: ns per vehicle-step by CPU time."""
    x, u, vp = inputs(n)
    a0, b0 = (run(which, x, u, vp, 10, step_only)[1] for which in ("inline", "passed"))  # load or compile, untimed
    same = np.array_equal(a0, b0)
    times: dict[str, list[float]] = {"inline": [], "passed": []}
    for r in range(rounds):
        for which in ("inline", "passed") if r % 2 == 0 else ("passed", "inline"):
            times[which].append(run(which, x, u, vp, steps, step_only)[0] / (n * steps) * 1e9)
    a, b = times["inline"], times["passed"]
    what = "the step alone" if step_only else "the duty clip, then the step"
    print(f"{what}: {n} vehicles x {steps} steps, {rounds} rounds alternating; CPU ns per vehicle-step (best / median)")
    print(f"  inline  {min(a):7.1f} / {statistics.median(a):7.1f}")
    print(f"  passed  {min(b):7.1f} / {statistics.median(b):7.1f}")
    print(f"  passed/inline: {min(b) / min(a):.3f} (best), {statistics.median(b) / statistics.median(a):.3f} (median)")
    print(f"  final states bit-identical: {same}")


def cache_check() -> None:
    """Two fresh processes, one cache folder: what numba says of each kernel."""
    here = os.path.dirname(os.path.abspath(__file__))
    code = (
        f"import sys; sys.path.insert(0, {here!r}); import plant_arg as p; "
        "x, u, vp = p.inputs(2); p.run('inline', x, u, vp, 5); p.run('passed', x, u, vp, 5)"
    )
    with tempfile.TemporaryDirectory() as folder:
        env = dict(os.environ, NUMBA_DEBUG_CACHE="1", NUMBA_CACHE_DIR=folder)
        for process in ("first", "second"):
            done = subprocess.run([sys.executable, "-c", code], env=env, capture_output=True, text=True, check=True)
            said = [
                line.strip()
                for line in done.stdout.splitlines()
                if "kernel_" in line and ("data saved" in line or "data loaded" in line or "index" in line)
            ]
            print(f"{process} process:")
            for line in said:
                print("  " + line)


def main(argv: list[str] | None = None) -> int:
    """Run the A/B or the cache check."""
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--rounds", type=int, default=6)
    parser.add_argument("--vehicles", type=int, default=200)
    parser.add_argument("--steps", type=int, default=2000)
    parser.add_argument("--step-only", action="store_true", help="the kernels that take the step alone, no clip")
    parser.add_argument("--cache", action="store_true", help="check numba's cache across two fresh processes")
    args = parser.parse_args(argv)
    if args.cache:
        cache_check()
    else:
        ab(args.rounds, args.vehicles, args.steps, args.step_only)
    return 0


if __name__ == "__main__":
    sys.exit(main())
