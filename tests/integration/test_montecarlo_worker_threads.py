"""A Dask worker's numba threads: the worker process imported numba (through the ``quadcruise``
script a spawned worker imports first) before the nanny set ``NUMBA_NUM_THREADS=1``; its first
chunk must run, and a compile after it (a worker on an empty numba cache compiles the engine)
must not find numba's thread count changed under running threads.

Found on a fresh clone: the README's ``montecarlo ... --out`` ended in a ``RuntimeError: Cannot
set NUMBA_NUM_THREADS to a different value once the threads have been launched`` traceback.
"""

from __future__ import annotations

import os
import subprocess
import sys
import textwrap

WORKER = textwrap.dedent(
    """
    import os
    import numba  # imported as a spawned worker imports it: NUMBA_NUM_THREADS=2 in its environment
    from numba.np.ufunc import parallel
    from quadcruise.montecarlo.chunk import run_chunk
    from quadcruise.montecarlo.population import Population
    from quadcruise.montecarlo.spec import MonteCarloSpec

    os.environ["NUMBA_NUM_THREADS"] = "1"  # what the nanny sets after the spawn (sweep.py's env)
    spec = MonteCarloSpec("hover", population=Population(offset=0.2), seed=3, duration=0.2)
    chunk = run_chunk(spec, 0, 2, threads=1)
    assert parallel._is_initialized
    numba.njit(lambda x: x + 1)(1)  # a compile after the chunk re-reads numba's environment
    print(int(chunk["count"]), numba.config.NUMBA_NUM_THREADS, numba.get_num_threads())
    """
)


def run_worker(extra_env: dict) -> subprocess.CompletedProcess:
    env = {k: v for k, v in os.environ.items() if k != "NUMBA_NUM_THREADS"} | extra_env
    return subprocess.run([sys.executable, "-c", WORKER], env=env, capture_output=True, text=True, timeout=600)


def test_a_worker_that_imported_numba_before_its_environment_runs_on_one_thread():
    done = run_worker({"NUMBA_NUM_THREADS": "2"})
    assert done.returncode == 0, done.stderr[-2000:]
    assert "Cannot set NUMBA_NUM_THREADS" not in done.stderr
    assert done.stdout.split() == ["2", "1", "1"]


def test_numba_itself_refuses_the_change_under_running_threads():
    """The other direction, the cause: threads launched at the count numba read first, then a
    compile that reads a different NUMBA_NUM_THREADS, fails (numba's rule, which run_chunk avoids)."""
    code = textwrap.dedent(
        """
        import os, numba
        numba.set_num_threads(1)  # launches numba's threads at the count read at import: 2
        os.environ["NUMBA_NUM_THREADS"] = "1"
        numba.njit(lambda x: x + 1)(1)
        """
    )
    env = {k: v for k, v in os.environ.items() if k != "NUMBA_NUM_THREADS"} | {"NUMBA_NUM_THREADS": "2"}
    done = subprocess.run([sys.executable, "-c", code], env=env, capture_output=True, text=True, timeout=600)
    assert done.returncode != 0
    assert "Cannot set NUMBA_NUM_THREADS" in done.stderr
