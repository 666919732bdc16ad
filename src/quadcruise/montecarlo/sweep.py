"""The machinery of a Monte Carlo sweep: chunks flown and reduced to metrics, in this
process or on Dask, streamed to disk (:mod:`quadcruise.montecarlo.store`), resumed.

**Chunks.** The population is cut into chunks of consecutive vehicles. A chunk is a pure
function of ``(spec, first, count)`` (:func:`run_chunk`): it draws its vehicles, flies
them as one batch and keeps one row of metrics per vehicle and a few decimated paths.
Since vehicle i depends on (seed, i) only, the table does not depend on the chunking, nor
on where a chunk ran.

**Dask.** ``scheduler="local"`` starts a ``distributed.LocalCluster`` of worker processes
with one thread each (numba runs one thread per task there) and without Dask's profiler
(:data:`LOCAL_CLUSTER_SETTINGS`); an address connects to an existing cluster. One task per chunk,
a bounded number in flight, gathered as they finish.
A worker that dies loses its tasks, the scheduler runs them again elsewhere, and since a
chunk is keyed by its first vehicle and written whole, every flight is counted once. Each
worker process loads the compiled engine from numba's cache once. Only the main process sees
Ctrl-C (:func:`_ctrl_c_for_this_process_only`) and closes the cluster, which ends the
workers; the cluster logs only what is CRITICAL: a chunk that fails raises here, and what
Dask would log besides (a worker restarted, the heartbeats lost while it closes after Ctrl-C)
is no news to a user.

**Memory.** One row per flight is kept; paths only for the first ``max_traces`` vehicles
and the first ``max_failure_traces`` failed ones; a chunk's log is held only while it is
reduced (about 64 MB with ``chunk_size="auto"``).
"""

from __future__ import annotations

import contextlib
import logging
import math
import os
import time
import uuid
import warnings
from collections.abc import Callable

import numpy as np

from quadcruise.checks import describe
from quadcruise.errors import InputError, SimulationError, WriteError, whole_number
from quadcruise.io.files import check_table_format
from quadcruise.montecarlo.chunk import fly_chunk, reduce_chunk, run_chunk, sweep_metrics
from quadcruise.montecarlo.output import write_outputs
from quadcruise.montecarlo.result import MonteCarloResult, Traces
from quadcruise.montecarlo.schema import COLUMNS, FAILURES
from quadcruise.montecarlo.spec import MonteCarloSpec
from quadcruise.montecarlo.store import SweepFolder

__all__ = [
    "run_chunk",
    "fly_chunk",
    "reduce_chunk",
    "sweep_metrics",
    "run_sweep",
    "check_sweep_size",
    "auto_chunk_size",
    "CHUNK_BUDGET",
]

CHUNK_BUDGET = 64 * 2**20
"""Bytes of engine log per chunk that ``chunk_size="auto"`` aims at."""

LOCAL_CLUSTER_SETTINGS = {
    "distributed.worker.profile.enabled": False,
    "distributed.admin.system-monitor.gil.enabled": False,
    "distributed.scheduler.work-stealing": False,
    "distributed.admin.tick.interval": "1s",
    "distributed.admin.system-monitor.interval": "5s",
    "distributed.worker.memory.monitor-interval": "1s",
}
"""Dask settings of the local cluster: no statistical profiler (it samples each task's stack
every 10 ms), GIL monitor or work stealing (the chunks are alike and few are in flight), and
the event-loop tick, system monitor and memory monitor at 1-5 s instead of 20-500 ms (what
that saves: docs/performance.md). A cluster of the user's (``scheduler=ADDRESS``) keeps its
own settings."""


# --- collecting chunks ------------------------------------------------------------------
class _Collector:
    """Rows of every flight, paths of a few; each vehicle at most once."""

    def __init__(self, spec: MonteCarloSpec, n: int) -> None:
        self.spec, self.n, self.hash = spec, n, spec.hash()
        self.parts: dict[int, dict] = {}
        self.covered: list[tuple[int, int]] = []
        self.trace_t: np.ndarray | None = None
        self.tr = {"vehicle": np.zeros(0, np.int64), "sample": np.zeros(0, bool), "pos": None, "ref": None}

    def add(self, chunk: dict) -> int:
        """Take a chunk (cut at n; a chunk overlapping one already taken is an error)."""
        first = int(chunk["first"])
        if str(chunk["hash"]) != self.hash:
            raise SimulationError(
                f"the chunk of vehicles from {first} was flown with other options or other "
                f"quadcruise code (spec {chunk['hash']}, this sweep's {self.hash}): "
                "every worker must run the same version"
            )
        count = min(int(chunk["count"]), self.n - first)
        if count <= 0:
            return 0
        if self.trace_t is not None and not np.array_equal(chunk["trace_t"], self.trace_t):
            raise SimulationError(f"the chunk of vehicles from {first} keeps its paths at other instants")
        for a, b in self.covered:
            if first < b and a < first + count:
                raise SimulationError(f"chunk of vehicles {first}..{first + count - 1} overlaps {a}..{b - 1}")
        self.covered.append((first, first + count))
        self.parts[first] = {k: chunk[k][:count] for k in COLUMNS}
        keep = chunk["trace_vehicle"] < first + count
        if self.trace_t is None:
            self.trace_t = chunk["trace_t"]
            shape = (0, chunk["trace_t"].size, 3)
            self.tr["pos"], self.tr["ref"] = np.zeros(shape), np.zeros(shape)
        for key, name in (
            ("vehicle", "trace_vehicle"),
            ("sample", "trace_sample"),
            ("pos", "trace_pos"),
            ("ref", "trace_ref"),
        ):
            self.tr[key] = np.concatenate([self.tr[key], chunk[name][keep]])
        extra = np.flatnonzero(~self.tr["sample"])
        if extra.size > self.spec.max_failure_traces:  # keep the first failures by index
            drop = extra[np.argsort(self.tr["vehicle"][extra], kind="stable")[self.spec.max_failure_traces :]]
            for key in self.tr:
                self.tr[key] = np.delete(self.tr[key], drop, axis=0)
        return count

    @property
    def done(self) -> int:
        return sum(b - a for a, b in self.covered)

    def missing(self, chunk_size: int) -> list[tuple[int, int]]:
        """(first, count) of the chunks still to fly: the gaps, cut into chunk_size pieces."""
        out, at = [], 0
        for a, b in sorted(self.covered) + [(self.n, self.n)]:
            for first in range(at, a, chunk_size):
                out.append((first, min(chunk_size, a - first)))
            at = max(at, b)
        return out

    def result(self, info: dict) -> MonteCarloResult:
        import pandas as pd

        order = sorted(self.parts)
        table = pd.DataFrame(
            {k: np.concatenate([self.parts[f][k] for f in order]).astype(t) for k, t in COLUMNS.items()}
        )
        if not np.array_equal(table["vehicle"].to_numpy(), np.arange(self.n)):
            raise SimulationError("the sweep's chunks do not cover every flight exactly once")
        table["reason"] = np.asarray(FAILURES, dtype=object)[table["failure"].to_numpy()]
        o = np.argsort(self.tr["vehicle"], kind="stable")
        traces = Traces(
            vehicle=self.tr["vehicle"][o],
            t=self.trace_t,
            pos=self.tr["pos"][o],
            ref=self.tr["ref"][o],
            sample=self.tr["sample"][o],
        )
        return MonteCarloResult(spec=self.spec, table=table, traces=traces, info=info)


# --- where chunks run -------------------------------------------------------------------
class _InProcess:
    """Chunks one after the other in this process; numba uses all cores within a chunk."""

    name = "this process"
    parallel = 1

    @property
    def threads(self) -> int:
        import numba

        return numba.get_num_threads()

    def run(self, spec, ranges):
        for first, count in ranges:
            yield reduce_chunk(spec, first, *fly_chunk(spec, first, count))

    def close(self) -> None:
        pass


class _Dask:
    """Chunks as tasks on a Dask cluster: a new LocalCluster, or one at an address."""

    def __init__(self, scheduler: str, workers: int | None, timeout: float) -> None:
        from distributed import Client, LocalCluster

        self.cluster = self.client = None
        if scheduler == "local":
            import dask

            n_workers = workers or os.cpu_count() or 1
            try:
                with dask.config.set(LOCAL_CLUSTER_SETTINGS), _ctrl_c_for_this_process_only():
                    self.cluster = LocalCluster(
                        n_workers=n_workers,
                        threads_per_worker=1,
                        processes=True,
                        dashboard_address=":0",
                        silence_logs=logging.CRITICAL,
                        env={"NUMBA_NUM_THREADS": "1"},
                    )
                    self.client = Client(self.cluster, set_as_default=False)
            except BaseException:  # Ctrl-C while the workers started (it arrives at the end)
                self.close()
                raise
            self.name = f"a local Dask cluster of {n_workers} processes"
        else:
            try:
                self.client = Client(scheduler, timeout=timeout, set_as_default=False)
            except Exception as exc:
                reason = " ".join(str(exc).split()) or type(exc).__name__
                raise InputError(f"cannot reach the Dask scheduler at {scheduler}: {reason}") from None
            self.name = f"the Dask cluster at {scheduler}"
        self.parallel = max(1, sum(self.client.nthreads().values()))
        self.threads = 1  # each task runs numba on one thread

    def run(self, spec, ranges):
        from distributed import as_completed

        todo = iter(ranges)
        key = f"{spec.hash()}-{uuid.uuid4().hex[:8]}"  # unique per run: no clash with a cancelled one
        pending = set()

        def submit():
            for first, count in todo:
                fut = self.client.submit(
                    run_chunk, spec, first, count, threads=1, key=f"quadcruise-chunk-{key}-{first}-{count}"
                )
                pending.add(fut)
                return fut
            return None

        queue = as_completed(loop=self.client.loop)
        try:
            for _ in range(2 * self.parallel + 2):
                fut = submit()
                if fut is None:
                    break
                queue.add(fut)
            for fut in queue:
                chunk = fut.result()
                pending.discard(fut)
                fut.release()
                nxt = submit()
                if nxt is not None:
                    queue.add(nxt)
                yield chunk
        finally:
            if pending:
                with contextlib.suppress(Exception):
                    self.client.cancel(list(pending))

    def close(self) -> None:
        if self.client is not None:
            with contextlib.suppress(Exception):
                self.client.close()
        if self.cluster is not None:
            with contextlib.suppress(Exception):
                self.cluster.close()


@contextlib.contextmanager
def _ctrl_c_for_this_process_only():
    """Processes and threads started inside never see Ctrl-C (SIGINT); this one still does."""
    # A terminal sends Ctrl-C to every process of the foreground group, local Dask workers
    # included, and each worker would print its own KeyboardInterrupt traceback. SIGINT is
    # blocked in this thread meanwhile: the threads started inside (Dask's event loop, which
    # starts the workers, and starts them again if one dies) and the processes they start keep
    # it blocked, and a Ctrl-C that came meanwhile is delivered here at the end. This process
    # then stops the sweep and closes the cluster, which ends its workers. multiprocessing's
    # resource tracker is started first: starting it unblocks SIGINT in the thread that does.
    import signal
    import threading

    if threading.current_thread() is not threading.main_thread() or not hasattr(signal, "pthread_sigmask"):
        yield
        return
    from multiprocessing import resource_tracker

    resource_tracker.ensure_running()
    before = signal.pthread_sigmask(signal.SIG_BLOCK, {signal.SIGINT})
    try:
        yield
    finally:
        signal.pthread_sigmask(signal.SIG_SETMASK, before)


def _scheduler(scheduler: str | None) -> str:
    text = "none" if scheduler is None else str(scheduler).strip()
    if text.lower() in ("local", "none", "process", ""):
        return text.lower() if text.lower() in ("local", "none") else "none"
    if "://" not in text and ":" not in text:
        raise InputError(f"scheduler must be local, none or an address such as tcp://host:8786, got {scheduler!r}")
    return text


def auto_chunk_size(spec: MonteCarloSpec, n: int, parallel: int = 1, threads: int = 1) -> int:
    """Vehicles per chunk: a log of about CHUNK_BUDGET bytes, at least 4 chunks per worker,
    and a multiple of the ``threads`` that share each chunk (when a chunk has that many), so
    that none of them waits for the others at the chunk's end.

    Examples
    --------
    >>> from quadcruise.montecarlo.spec import MonteCarloSpec
    >>> spec = MonteCarloSpec("hover", duration=1.0)
    >>> auto_chunk_size(spec, 100), auto_chunk_size(spec, 100, parallel=4, threads=2)
    (25, 6)
    """
    by_memory = max(1, CHUNK_BUDGET // spec.log_bytes())
    by_balance = max(1, math.ceil(n / (4 * max(1, parallel))))
    size = int(min(by_memory, by_balance, 1024))
    return size - size % threads if size >= threads > 1 else size


MAX_SWEEP_STEPS = 1.0e13
"""The most vehicle-steps a sweep may take (flights x control periods): days of computing on a
cluster of a hundred cores; beyond it the number of flights is surely a slip."""


def check_sweep_size(n: int, periods: int) -> None:
    """Refuse a sweep beyond :data:`MAX_SWEEP_STEPS` before anything flies."""
    if n * periods > MAX_SWEEP_STEPS:
        raise InputError(
            f"{n:,} flights x {periods:,} control periods is {n * periods:.2g} vehicle-steps, "
            "days of computing even on a cluster: fewer flights or a shorter duration"
        )


def run_sweep(
    spec: MonteCarloSpec,
    n: int,
    *,
    chunk_size: int | str = "auto",
    scheduler: str | None = None,
    workers: int | None = None,
    out=None,
    resume: bool = True,
    force: bool = False,
    fmt: str = "csv",
    progress: Callable[[int, int], None] | None = None,
    connect_timeout: float = 10.0,
) -> MonteCarloResult:
    """Fly vehicles 0 .. n-1 of ``spec``: see :func:`quadcruise.montecarlo.montecarlo`."""
    n = whole_number(n, "the number of flights", 1)
    check_sweep_size(n, spec.periods)
    if chunk_size != "auto" and (
        isinstance(chunk_size, bool) or not isinstance(chunk_size, (int, np.integer)) or chunk_size < 1
    ):
        raise InputError(f"chunk size must be a whole number >= 1 or 'auto', got {describe(chunk_size)}")
    workers = None if workers is None else whole_number(workers, "workers", 1)
    if not (isinstance(connect_timeout, (int, float)) and math.isfinite(connect_timeout) and connect_timeout > 0):
        raise InputError(f"connect_timeout must be a positive number of seconds, got {describe(connect_timeout)}")
    check_table_format(fmt)
    mode = _scheduler(scheduler)
    folder = SweepFolder(out, spec, force=force, resume=resume) if out is not None else None
    collector = _Collector(spec, n)
    start = time.perf_counter()
    runner = _InProcess() if mode == "none" else _Dask(mode, workers, connect_timeout)
    flown = 0
    try:
        size = auto_chunk_size(spec, n, runner.parallel, runner.threads) if chunk_size == "auto" else int(chunk_size)
        if folder is not None:
            folder.prepare(n, size)
            for chunk in folder.existing():
                try:
                    collector.add(chunk)
                except SimulationError as exc:
                    warnings.warn(f"{folder.path}: {exc}; skipped", stacklevel=2)
        resumed = collector.done
        todo = collector.missing(size)
        if progress:
            progress(collector.done, n)
        chunks = runner.run(spec, todo)
        try:
            for chunk in chunks:
                if folder is not None:
                    folder.write_chunk(chunk)
                flown += collector.add(chunk)
                if progress:
                    progress(collector.done, n)
        finally:
            chunks.close()  # cancels the tasks still out (an interruption)
    except WriteError as exc:
        raise _saying_what_is_kept(exc, folder, collector.done, n) from None
    finally:
        runner.close()
    wall = time.perf_counter() - start
    info = {
        "scheduler": runner.name,
        "parallel": runner.parallel,
        "chunk_size": size,
        "chunks_flown": len(todo),
        "flown": flown,
        "resumed": resumed,
        "wall_s": wall,
        "flights_per_s": flown / wall if wall > 0 else None,
        "vehicle_steps_per_s": flown * spec.periods / wall if wall > 0 else None,
        "out": None if out is None else str(out),
    }
    result = collector.result(info)
    if folder is not None:
        try:
            folder.reclaim(n, size)
            write_outputs(result, folder.path, fmt=fmt)
        except WriteError as exc:
            raise _saying_what_is_kept(exc, folder, n, n) from None
    return result


def _saying_what_is_kept(exc: WriteError, folder, done: int, n: int) -> WriteError:
    """``exc`` (a file of the sweep's folder that could not be written) saying which flights
    are safe on disk and that the same command goes on from them."""
    if folder is None or done == 0:
        return exc
    where = folder.path / "chunks"
    kept = (
        f"all {n:,} flights are kept in {where}: the same command writes the results without flying them again"
        if done == n
        else f"the {done:,} flights done are kept in {where}: the same command resumes from them"
    )
    return WriteError(exc.filename, exc, kept=kept)
