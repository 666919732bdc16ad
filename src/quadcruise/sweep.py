"""The machinery of a Monte Carlo sweep: chunks flown and reduced to metrics, in this
process or on Dask, streamed to disk, resumed; the figures and the report.

**Chunks.** The population is cut into chunks of consecutive vehicles. A chunk is a pure
function of ``(spec, first, count)`` (:func:`run_chunk`): it draws its vehicles, flies
them as one batch and keeps one row of metrics per vehicle and a few decimated paths.
Since vehicle i depends on (seed, i) only, the table does not depend on the chunking, nor
on where a chunk ran.

**Dask.** ``scheduler="local"`` starts a ``distributed.LocalCluster`` of worker processes
with one thread each (numba runs one thread per task there); an address connects to an
existing cluster. One task per chunk, a bounded number in flight, gathered as they finish.
A worker that dies loses its tasks, the scheduler runs them again elsewhere, and since a
chunk is keyed by its first vehicle and written whole, every flight is counted once. Each
worker process loads the compiled engine from numba's cache once.

**On disk** (``out``)::

    quadcruise.json            the spec, its hash, n, and whether the sweep is complete
    chunks/chunk-000000120.npz one per chunk (vehicles 120 ..), written whole or not at all
    flights.csv                one row per flight (or flights.parquet)
    summary.json, worst.csv    quantiles, failure rate by reason, the worst flights
    histograms.png, envelope.png, report.md

quadcruise.json is written before the first chunk and chunks as they finish, so an
interrupted sweep leaves a folder that the same command resumes: chunks already there
(of the same spec hash) are loaded, not flown. A folder holding another sweep, or
anything else, is refused unless ``force``. The results are written at the end.

**Memory.** One row per flight is kept; paths only for the first ``max_traces`` vehicles
and the first ``max_failure_traces`` failed ones; a chunk's log is held only while it is
reduced (about 64 MB with ``chunk_size="auto"``).
"""

from __future__ import annotations

import contextlib
import json
import logging
import math
import os
import shutil
import sys
import time
import uuid
import warnings
from pathlib import Path
from typing import Any, Callable, Iterator

import numpy as np

from . import __version__
from .errors import InputError, SimulationError
from .io import MARKER, atomic_path, check_output_dir, check_table_format, write_table
from .layout import CMD_U1, REF_X, X
from .metrics import control_effort, tracking_errors
from .montecarlo import COLUMNS, FAILURES, METRICS, Draw, MonteCarloResult, MonteCarloSpec, Traces, _plain

__all__ = ["run_chunk", "fly_chunk", "reduce_chunk", "sweep_metrics", "run_sweep", "auto_chunk_size",
           "ProgressBar", "plot_histograms", "plot_envelope", "write_outputs", "CHUNK_BUDGET"]

CHUNK_BUDGET = 64 * 2**20
"""Bytes of engine log per chunk that ``chunk_size="auto"`` aims at."""
CHUNKS = "chunks"


# --- one chunk --------------------------------------------------------------------------
def fly_chunk(spec: MonteCarloSpec, first: int, count: int, log_every: int | None = None):
    """Fly vehicles first .. first + count - 1 of the population as one batch:
    ``(SimResult, Draw)``. Divergence and clipping are not warned about (they are in the
    table)."""
    from .flight import fly, hover_state

    draw = spec.population.draw(spec.seed, first, count, spec.vehicle, spec.dt)
    x0 = hover_state(draw.vehicle, count, spec.mission)
    x0[:, X:X + 3] += draw.offsets
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        res = fly(spec.mission, spec.controller, vehicle=draw.vehicle,
                  controller_vehicle=spec.vehicle if spec.population.model_error else None,
                  duration=spec.duration, dt=spec.dt, max_step=spec.max_step, x0=x0,
                  log_every=spec.log_every if log_every is None else log_every,
                  full_dynamics=spec.full_dynamics, seed=spec.seed, first_vehicle=first,
                  **draw.environment)
    return res, draw


def run_chunk(spec: MonteCarloSpec, first: int, count: int, threads: int | None = None) -> dict:
    """Vehicles first .. first + count - 1, flown and reduced to a chunk (dict of arrays).

    Keys: ``first``, ``count``, ``hash``, one array per column of :data:`COLUMNS`, and the
    kept paths: ``trace_vehicle`` (k,), ``trace_t`` (L,), ``trace_pos`` and ``trace_ref``
    (k, L, 3), ``trace_sample`` (k,) (True: one of the first ``max_traces`` vehicles; else
    kept as one of the first ``max_failure_traces`` failures). A pure function of its
    arguments: this is the Dask task. ``threads`` sets numba's threads for this call (1 on a
    Dask worker).
    """
    if threads is not None:
        import numba

        numba.set_num_threads(max(1, min(int(threads), numba.config.NUMBA_NUM_THREADS)))
    res, draw = fly_chunk(spec, first, count)
    return reduce_chunk(spec, first, res, draw)


def reduce_chunk(spec: MonteCarloSpec, first: int, res, draw: Draw) -> dict:
    """The chunk of :func:`run_chunk` from a flown batch and its draw."""
    count = res.n
    cols = sweep_metrics(res, spec)
    cols["vehicle"] = np.arange(first, first + count, dtype=np.int64)
    cols.update({k: np.asarray(v, dtype=float) for k, v in draw.columns.items()})
    out = {"first": np.int64(first), "count": np.int64(count), "hash": np.str_(spec.hash())}
    out.update({k: np.asarray(cols[k], dtype=t) for k, t in COLUMNS.items()})
    # paths: the random sample (the first max_traces vehicles) and the chunk's first failures
    sample = cols["vehicle"] < spec.max_traces
    failed = np.flatnonzero((cols["failure"] != 0) & ~sample)[:spec.max_failure_traces]
    keep = np.union1d(np.flatnonzero(sample), failed).astype(np.int64)
    step = spec.trace_every
    out["trace_vehicle"] = cols["vehicle"][keep]
    out["trace_sample"] = sample[keep]
    out["trace_t"] = res.t[::step].copy()
    out["trace_pos"] = np.ascontiguousarray(res.states[keep, ::step, X:X + 3])
    out["trace_ref"] = np.ascontiguousarray(res.references[keep, ::step, REF_X:REF_X + 3])
    return out


# --- vectorised metrics -----------------------------------------------------------------
def _first_crossing(t, z, level):
    """Per row of z (N, L): time z first reaches level, interpolated (NaN if never)."""
    rows = np.arange(z.shape[0])
    hit = z >= level
    k = hit.argmax(axis=1)
    km = np.maximum(k - 1, 0)
    with np.errstate(divide="ignore", invalid="ignore"):
        frac = (level - z[rows, km]) / (z[rows, k] - z[rows, km])
        out = t[km] + frac * (t[k] - t[km])
    out[k == 0] = t[0]
    out[~hit[rows, k]] = np.nan
    return out


def _settling(t, z, band):
    """Per row: time from t[0] after which |z - 1| <= band for good (NaN: outside at the end)."""
    rows = np.arange(z.shape[0])
    outside = np.abs(z - 1.0) > band
    last = z.shape[1] - 1 - outside[:, ::-1].argmax(axis=1)
    any_out = outside[rows, last]
    k = np.minimum(last, z.shape[1] - 2)
    zk, zk1 = z[rows, k], z[rows, k + 1]
    edge = np.where(zk > 1.0, 1.0 + band, 1.0 - band)
    with np.errstate(divide="ignore", invalid="ignore"):
        out = t[k] + (edge - zk) / (zk1 - zk) * (t[k + 1] - t[k]) - t[0]
    out[~any_out] = 0.0
    out[outside[:, -1]] = np.nan
    return out


def _transients(t, pos, ref, mission: dict, bands):
    """Transient of each vehicle as :func:`quadcruise.metrics.flight_metrics` measures it:
    (axis (N,), rise, settling per band..., overshoot), on pos/ref (N, L, 3)."""
    from .metrics import TRANSIENT_MIN_ERROR

    n = pos.shape[0]
    axis = np.full(n, -1, dtype=np.int64)
    nan = np.full(n, np.nan)
    if mission.get("kind") == "step" and mission.get("axis") in ("x", "y", "z"):
        j = "xyz".index(mission["axis"])
        t_step = float(mission["time"])
        if not t[0] <= t_step < t[-1]:
            return axis, nan, [nan] * len(bands), nan
        y0 = float(mission[mission["axis"]])
        step = float(mission["size"])
        after = t > t_step
        ts = np.concatenate(([t_step], t[after]))
        ys = np.empty((n, ts.size))
        ys[:, 1:] = pos[:, after, j]
        ys[:, 0] = [np.interp(t_step, t, pos[i, :, j]) for i in range(n)]
        z = (ys - y0) / step
        axis[:] = j
    else:
        e0 = np.abs(ref[:, 0] - pos[:, 0])
        j = e0.argmax(axis=1)
        rows = np.arange(n)
        measured = e0[rows, j] >= TRANSIENT_MIN_ERROR
        axis[measured] = j[measured]
        if not measured.any():
            return axis, nan, [nan] * len(bands), nan
        rows = rows[measured]
        e = ref[rows, :, j[measured]] - pos[rows, :, j[measured]]
        z = 1.0 - e / e[:, :1]
        ts = t
    t_lo, t_hi = _first_crossing(ts, z, 0.1), _first_crossing(ts, z, 0.9)
    rise = t_hi - t_lo
    settle = [_settling(ts, z, b) for b in bands]
    over = np.maximum(0.0, 100.0 * (z.max(axis=1) - 1.0))
    if z.shape[0] == n:
        return axis, rise, settle, over
    sel = axis >= 0

    def put(v):
        full = np.full(n, np.nan)
        full[sel] = v
        return full
    return axis, put(rise), [put(s) for s in settle], put(over)


def sweep_metrics(result, spec: MonteCarloSpec) -> dict[str, np.ndarray]:
    """Per-vehicle metrics of a batch, vectorised: the columns of :data:`COLUMNS` but the
    vehicle index and the drawn values.

    ``rmse_m``, ``max_error_m``, ``rise_time_s``, ``settling_time_s`` (2 %),
    ``settling_time_5pct_s``, ``overshoot_pct``, ``effort``, ``duty_clipped_s`` and
    ``controller_limited_s`` equal :func:`quadcruise.metrics.flight_metrics` on the same
    result (to rounding; the transient is measured on the same axis with the same rules);
    ``final_error_m`` is the position error at the end. Every metric of a vehicle that
    stopped early is NaN. Each vehicle's numbers depend on its own rows only, so they do
    not change with the batch a vehicle is flown in.
    """
    t = result.t
    n = result.n
    status = np.asarray(result.status, dtype=np.int64)
    out: dict[str, Any] = {m: np.full(n, np.nan) for m in METRICS}
    out["duty_clipped_s"] = np.asarray(result.duty_clipped_s, dtype=float).copy()
    out["controller_limited_s"] = np.asarray(result.controller_limited_s, dtype=float).copy()
    out["transient_axis"] = np.full(n, -1, dtype=np.int64)
    out["status"] = status
    out["stop_time_s"] = np.asarray(result.t_stop, dtype=float).copy()
    refs = result.references[:, :, REF_X:REF_X + 3]
    live = np.flatnonzero((status == 0) & np.isfinite(refs).all(axis=(1, 2)))
    not_settled = np.zeros(n, dtype=bool)
    if live.size:
        pos = result.states[live, :, X:X + 3]
        ref = refs[live]
        err = tracking_errors(t, pos, ref)                              # batched over vehicles
        out["rmse_m"][live] = err["rmse"]
        out["max_error_m"][live] = err["max_error"]
        out["final_error_m"][live] = np.linalg.norm(pos[:, -1] - ref[:, -1], axis=1)
        out["effort"][live] = control_effort(t, result.commands[live, :, CMD_U1:CMD_U1 + 4])["integral"]
        keep = slice(None) if spec.transient_until is None else t <= spec.transient_until
        mission = result.meta.get("mission") if isinstance(result.meta.get("mission"), dict) else {}
        tk = t[keep]
        if tk.size >= 2:
            bands = (0.02, 0.05, spec.settle_band)
            axis, rise, settle, over = _transients(tk, pos[:, keep], ref[:, keep], mission, bands)
            out["transient_axis"][live] = axis
            out["rise_time_s"][live] = rise
            out["settling_time_s"][live] = settle[0]
            out["settling_time_5pct_s"][live] = settle[1]
            out["overshoot_pct"][live] = over
            not_settled[live] = (axis >= 0) & np.isnan(settle[2])
    diverged = status != 0
    saturated = out["duty_clipped_s"] > spec.max_clipped_s
    out.update(diverged=diverged, saturated=saturated, not_settled=not_settled)
    out["failure"] = np.select([diverged, saturated, not_settled], [1, 2, 3], 0).astype(np.int64)
    return out


# --- progress ---------------------------------------------------------------------------
class ProgressBar:
    """``progress(done, total)`` that prints flights done, the rate and the time left.

    On a terminal it rewrites one line; otherwise it prints a line at most every
    ``log_interval`` seconds (and the last one). The rate counts the flights flown since
    the first call (flights resumed from disk are done but not flown).

    >>> import io
    >>> buf = io.StringIO()
    >>> bar = ProgressBar(buf)
    >>> bar(0, 10); bar(10, 10); bar.close()
    >>> buf.getvalue().splitlines()[-1].split(",")[0]
    '10/10 flights (100.0 %)'
    """

    def __init__(self, stream=None, *, label: str = "flights", min_interval: float = 0.25,
                 log_interval: float = 10.0) -> None:
        self.stream = sys.stderr if stream is None else stream
        self.label = label
        self.tty = bool(getattr(self.stream, "isatty", lambda: False)())
        self.interval = min_interval if self.tty else log_interval
        self.t0: float | None = None
        self.done0 = 0
        self.last = -math.inf
        self.width = 0

    def __call__(self, done: int, total: int) -> None:
        now = time.monotonic()
        if self.t0 is None:
            self.t0, self.done0 = now, done
        final = done >= total
        if not final and now - self.last < self.interval:
            return
        self.last = now
        elapsed = now - self.t0
        rate = (done - self.done0) / elapsed if elapsed > 0 and done > self.done0 else 0.0
        eta = "-" if not rate else _clock((total - done) / rate)
        text = (f"{done:,}/{total:,} {self.label} ({100.0 * done / max(total, 1):.1f} %), "
                f"{rate:,.0f} {self.label}/s, ETA {eta}")
        if self.tty:
            self.stream.write("\r" + text.ljust(self.width))
            self.width = len(text)
        else:
            self.stream.write(text + "\n")
        self.stream.flush()

    def close(self) -> None:
        """End the line (on a terminal)."""
        if self.tty and self.width:
            self.stream.write("\n")
            self.stream.flush()
            self.width = 0


def _clock(seconds: float) -> str:
    seconds = int(round(seconds))
    h, rest = divmod(seconds, 3600)
    return f"{h}:{rest // 60:02d}:{rest % 60:02d}" if h else f"{rest // 60}:{rest % 60:02d}"


# --- chunks on disk ---------------------------------------------------------------------
def _chunk_path(folder: Path, first: int) -> Path:
    return folder / CHUNKS / f"chunk-{first:09d}.npz"


def _write_chunk(folder: Path, chunk: dict) -> None:
    with atomic_path(_chunk_path(folder, int(chunk["first"]))) as tmp:
        with open(tmp, "wb") as f:
            np.savez(f, **chunk)


def _read_chunks(folder: Path, spec_hash: str) -> Iterator[dict]:
    """The complete chunks of this spec in ``folder``; others are skipped with a warning."""
    for path in sorted((folder / CHUNKS).glob("chunk-*.npz")):
        try:
            with np.load(path, allow_pickle=False) as data:
                chunk = {k: data[k] for k in data.files}
        except Exception as exc:              # a foreign or damaged file: fly it again
            warnings.warn(f"{path}: unreadable ({exc}); its flights are flown again", stacklevel=3)
            continue
        if str(chunk.get("hash")) != spec_hash or int(chunk["first"]) != int(path.stem.split("-")[1]):
            warnings.warn(f"{path}: belongs to another sweep; its flights are flown again", stacklevel=3)
            continue
        yield chunk


def _marker(path: Path) -> dict | None:
    try:
        return json.loads((path / MARKER).read_text())
    except (OSError, ValueError):
        return None


class _Folder:
    """The output folder of a sweep: checked at construction (nothing is written), then
    :meth:`prepare` (marker), :meth:`write_chunk`."""

    def __init__(self, out, spec: MonteCarloSpec, *, force: bool, resume: bool) -> None:
        self.path = check_output_dir(out, force)
        self.hash = spec.hash()
        self.spec = spec
        meta = _marker(self.path) if self.path.is_dir() else None
        same = bool(meta) and meta.get("workflow") == "montecarlo" and meta.get("spec_hash") == self.hash
        if meta is not None and not same and not force:
            what = (f"a different sweep (spec {meta.get('spec_hash')})" if meta.get("workflow") == "montecarlo"
                    else f"a quadcruise {meta.get('workflow', 'result')} result")
            raise InputError(f"{self.path}: holds {what}; use --force to replace it or choose another --out")
        self.resume = same and resume
        self.clear = self.path.is_dir() and any(self.path.iterdir()) and not self.resume

    def existing(self) -> Iterator[dict]:
        return _read_chunks(self.path, self.hash) if self.resume else iter(())

    def prepare(self, n: int, chunk_size: int) -> None:
        if self.clear:
            shutil.rmtree(self.path)
        (self.path / CHUNKS).mkdir(parents=True, exist_ok=True)
        write_marker(self.path, self.spec, n, chunk_size=chunk_size, complete=False)

    def write_chunk(self, chunk: dict) -> None:
        _write_chunk(self.path, chunk)


def write_marker(path: Path, spec: MonteCarloSpec, n: int, **extra: Any) -> None:
    """quadcruise.json of a sweep folder, whole or not at all."""
    doc = {"workflow": "montecarlo", "version": __version__, "spec_hash": spec.hash(), "n": n,
           "seed": spec.seed, **extra, "spec": spec.to_dict()}
    with atomic_path(path / MARKER) as tmp:
        tmp.write_text(json.dumps(doc, indent=2, default=_plain) + "\n")


# --- collecting chunks ------------------------------------------------------------------
class _Collector:
    """Rows of every flight, paths of a few; each vehicle at most once."""

    def __init__(self, spec: MonteCarloSpec, n: int) -> None:
        self.spec, self.n = spec, n
        self.parts: dict[int, dict] = {}
        self.covered: list[tuple[int, int]] = []
        self.trace_t: np.ndarray | None = None
        self.tr = {"vehicle": np.zeros(0, np.int64), "sample": np.zeros(0, bool),
                   "pos": None, "ref": None}

    def add(self, chunk: dict) -> int:
        """Take a chunk (cut at n; a chunk overlapping one already taken is an error)."""
        first = int(chunk["first"])
        count = min(int(chunk["count"]), self.n - first)
        if count <= 0:
            return 0
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
        for key, name in (("vehicle", "trace_vehicle"), ("sample", "trace_sample"),
                          ("pos", "trace_pos"), ("ref", "trace_ref")):
            self.tr[key] = np.concatenate([self.tr[key], chunk[name][keep]])
        extra = np.flatnonzero(~self.tr["sample"])
        if extra.size > self.spec.max_failure_traces:      # keep the first failures by index
            drop = extra[np.argsort(self.tr["vehicle"][extra], kind="stable")[self.spec.max_failure_traces:]]
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
        table = pd.DataFrame({k: np.concatenate([self.parts[f][k] for f in order]).astype(t)
                              for k, t in COLUMNS.items()})
        if not np.array_equal(table["vehicle"].to_numpy(), np.arange(self.n)):
            raise SimulationError("the sweep's chunks do not cover every flight exactly once")
        table["reason"] = np.asarray(FAILURES, dtype=object)[table["failure"].to_numpy()]
        o = np.argsort(self.tr["vehicle"], kind="stable")
        traces = Traces(vehicle=self.tr["vehicle"][o], t=self.trace_t, pos=self.tr["pos"][o],
                        ref=self.tr["ref"][o], sample=self.tr["sample"][o])
        return MonteCarloResult(spec=self.spec, table=table, traces=traces, info=info)


# --- where chunks run -------------------------------------------------------------------
class _InProcess:
    """Chunks one after the other in this process; numba uses all cores within a chunk."""

    name = "this process"
    parallel = 1

    def run(self, spec, ranges):
        for first, count in ranges:
            yield run_chunk(spec, first, count)

    def close(self) -> None:
        pass


class _Dask:
    """Chunks as tasks on a Dask cluster: a new LocalCluster, or one at an address."""

    def __init__(self, scheduler: str, workers: int | None, timeout: float) -> None:
        from distributed import Client, LocalCluster

        self.cluster = None
        if scheduler == "local":
            n_workers = workers or os.cpu_count() or 1
            self.cluster = LocalCluster(n_workers=n_workers, threads_per_worker=1, processes=True,
                                        dashboard_address=":0", silence_logs=logging.ERROR,
                                        env={"NUMBA_NUM_THREADS": "1"})
            self.client = Client(self.cluster, set_as_default=False)
            self.name = f"a local Dask cluster of {n_workers} processes"
        else:
            try:
                self.client = Client(scheduler, timeout=timeout, set_as_default=False)
            except Exception as exc:
                reason = " ".join(str(exc).split()) or type(exc).__name__
                raise InputError(f"cannot reach the Dask scheduler at {scheduler}: {reason}") from None
            self.name = f"the Dask cluster at {scheduler}"
        self.parallel = max(1, sum(self.client.nthreads().values()))

    def run(self, spec, ranges):
        from distributed import as_completed

        todo = iter(ranges)
        key = f"{spec.hash()}-{uuid.uuid4().hex[:8]}"     # unique per run: no clash with a cancelled one
        pending = set()

        def submit():
            for first, count in todo:
                fut = self.client.submit(run_chunk, spec, first, count, threads=1,
                                         key=f"quadcruise-chunk-{key}-{first}-{count}")
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
        with contextlib.suppress(Exception):
            self.client.close()
        if self.cluster is not None:
            with contextlib.suppress(Exception):
                self.cluster.close()


def _scheduler(scheduler: str | None) -> str:
    text = "local" if scheduler is None else str(scheduler).strip()
    if text.lower() in ("local", "none", "process", ""):
        return text.lower() if text.lower() in ("local", "none") else "none"
    if "://" not in text and ":" not in text:
        raise InputError(f"scheduler must be local, none or an address such as tcp://host:8786, got {scheduler!r}")
    return text


def auto_chunk_size(spec: MonteCarloSpec, n: int, parallel: int = 1) -> int:
    """Vehicles per chunk: a log of about CHUNK_BUDGET bytes, at least 4 chunks per worker."""
    by_memory = max(1, CHUNK_BUDGET // spec.log_bytes())
    by_balance = max(1, math.ceil(n / (4 * max(1, parallel))))
    return int(min(by_memory, by_balance, 1024))


def run_sweep(spec: MonteCarloSpec, n: int, *, chunk_size: int | str = "auto", scheduler: str | None = "local",
              workers: int | None = None, out=None, resume: bool = True, force: bool = False, fmt: str = "csv",
              progress: Callable[[int, int], None] | None = None, connect_timeout: float = 10.0) -> MonteCarloResult:
    """Fly vehicles 0 .. n-1 of ``spec``: see :func:`quadcruise.montecarlo.montecarlo`.

    Every input is checked (and a scheduler address reached) before anything is written.
    ``progress(done, total)`` is called at the start (done: flights found on disk) and
    after each chunk; an exception from it (or Ctrl-C) stops the sweep, leaving the chunks
    already written for a resume.
    """
    if isinstance(n, bool) or not isinstance(n, (int, np.integer)) or n < 1:
        raise InputError(f"the number of flights must be a whole number >= 1, got {n!r}")
    n = int(n)
    if chunk_size != "auto" and (isinstance(chunk_size, bool) or not isinstance(chunk_size, (int, np.integer))
                                 or chunk_size < 1):
        raise InputError(f"chunk size must be a whole number >= 1 or 'auto', got {chunk_size!r}")
    if workers is not None and (isinstance(workers, bool) or not isinstance(workers, (int, np.integer)) or workers < 1):
        raise InputError(f"workers must be a whole number >= 1, got {workers!r}")
    check_table_format(fmt)
    mode = _scheduler(scheduler)
    folder = _Folder(out, spec, force=force, resume=resume) if out is not None else None
    collector = _Collector(spec, n)
    start = time.perf_counter()
    runner = _InProcess() if mode == "none" else _Dask(mode, workers, connect_timeout)
    flown = 0
    try:
        size = auto_chunk_size(spec, n, runner.parallel) if chunk_size == "auto" else int(chunk_size)
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
            chunks.close()                  # cancels the tasks still out (an interruption)
    finally:
        runner.close()
    wall = time.perf_counter() - start
    info = {"scheduler": runner.name, "parallel": runner.parallel, "chunk_size": size, "chunks_flown": len(todo),
            "flown": flown, "resumed": resumed, "wall_s": wall, "flights_per_s": flown / wall if wall > 0 else None,
            "vehicle_steps_per_s": flown * spec.periods / wall if wall > 0 else None,
            "out": None if out is None else str(out)}
    result = collector.result(info)
    if folder is not None:
        write_outputs(result, folder.path, fmt=fmt)
    return result


# --- results on disk --------------------------------------------------------------------
def write_outputs(result: MonteCarloResult, out, *, fmt: str = "csv", force: bool = False) -> Path:
    """The results of a sweep into ``out`` (see the module), each file whole or not at all;
    quadcruise.json last, marked complete."""
    from .plots import save_figure

    path = Path(out)
    meta = _marker(path) if path.is_dir() else None
    ours = bool(meta) and meta.get("workflow") == "montecarlo" and meta.get("spec_hash") == result.spec.hash()
    if not ours:
        check_output_dir(path, force)
        if meta is not None and not force:
            raise InputError(f"{path}: holds another quadcruise result; use --force to replace it")
        if path.is_dir() and any(path.iterdir()):
            shutil.rmtree(path)
    path.mkdir(parents=True, exist_ok=True)
    name = write_table(result.table, path / "flights", fmt).name
    summary = result.summary()
    with atomic_path(path / "summary.json") as tmp:
        tmp.write_text(json.dumps({**summary, "info": result.info}, indent=2, default=_plain) + "\n")
    worst = result.worst(20)
    with atomic_path(path / "worst.csv") as tmp:
        worst.to_csv(tmp, index=False, float_format="%.10g")
    figures = {"histograms.png": result.plot_histograms(), "envelope.png": result.plot_envelope()}
    for fig_name, fig in figures.items():
        save_figure(fig, path / fig_name)
    with atomic_path(path / "report.md") as tmp:
        tmp.write_text(report_markdown(result, summary, worst, name))
    write_marker(path, result.spec, result.n, complete=True, table=name,
                 chunk_size=result.info.get("chunk_size"))
    return path


def write_case(case, out, *, fmt: str = "csv", force: bool = False) -> Path:
    """One re-flown vehicle into ``out``, whole or not at all: its traces, its row
    (case.json), a figure of the flight and quadcruise.json."""
    from .io import atomic_dir, write_table
    from .plots import plot_flight, save_figure

    path = check_output_dir(out, force)
    with atomic_dir(path) as tmp:
        tmp = Path(tmp)
        write_table(case.result.to_pandas(), tmp / "traces", fmt)
        (tmp / "case.json").write_text(json.dumps(case.row, indent=2, default=_plain) + "\n")
        save_figure(plot_flight(case.result), tmp / "flight.png")
        (tmp / MARKER).write_text(json.dumps({"workflow": "montecarlo-case", "vehicle": case.vehicle,
                                              **case.result.meta}, indent=2, default=_plain) + "\n")
    return path


def report_markdown(result: MonteCarloResult, summary: dict, worst, table_name: str) -> str:
    """report.md: what was flown, the failures, the quantiles, the worst flights, figures."""
    spec = result.spec
    pop = {k: v for k, v in spec.population.to_dict().items() if v not in (0.0, None)}
    f = summary["failures"]
    lines = [f"# Monte Carlo: {spec.controller.name} on {spec.mission.name}, {summary['flights']:,} flights\n",
             f"quadcruise {__version__}, seed {spec.seed}, {spec.duration:g} s at dt = {spec.dt:g} s, "
             f"metrics on a {spec.dt * spec.log_every:g} s log; spec hash `{spec.hash()}`.\n",
             "Population: " + (", ".join(f"{k} = {v}" for k, v in pop.items()) or "nominal") + ".\n",
             f"## Failures: {f['count']:,} of {summary['flights']:,} ({100 * f['rate']:.2f} %)\n",
             "Each flight counts once, under the first that applies: diverged (the engine stopped it), "
             f"saturated (rotor duties clipped for more than {spec.max_clipped_s:g} s), did not settle "
             f"(the transient still outside the {100 * spec.settle_band:g} % band at the end).\n",
             "| reason | flights | rate |", "|---|---|---|"]
    for reason, v in f["by_reason"].items():
        lines.append(f"| {reason} | {v['count']:,} | {100 * v['rate']:.2f} % |")
    if summary["stopped"]:
        lines.append("\nWhy the engine stopped flights: " + "; ".join(f"{k}: {v:,}" for k, v in summary["stopped"].items()) + ".")
    lines += ["\n## Metrics\n", "| metric | flights | p5 | p50 | p95 | max |", "|---|---|---|---|---|---|"]
    for name, m in summary["metrics"].items():
        cells = " | ".join("-" if m[k] is None else f"{m[k]:.4g}" for k in ("p5", "p50", "p95", "max"))
        lines.append(f"| {name} | {m['count']:,} | {cells} |")
    lines += ["\n## Worst flights\n",
              "Fly one alone again: `quadcruise montecarlo <the same options> --case VEHICLE`, or in Python "
              "`quadcruise.montecarlo.montecarlo_case(spec, VEHICLE)`; it gives the same row.\n",
              "| vehicle | reason | rmse [m] | max error [m] | settling 5 % [s] | stop [s] | m [kg] |",
              "|---|---|---|---|---|---|---|"]
    for _, r in worst.head(10).iterrows():
        cells = " | ".join("-" if not np.isfinite(r[k]) else f"{r[k]:.4g}"
                           for k in ("rmse_m", "max_error_m", "settling_time_5pct_s", "stop_time_s", "m"))
        lines.append(f"| {int(r['vehicle'])} | {r['reason']} | {cells} |")
    info = result.info
    lines += ["\n## Figures\n", "![histograms](histograms.png)\n", "![envelope](envelope.png)\n",
              "\n## How it ran\n",
              f"{info.get('flown', 0):,} flights flown and {info.get('resumed', 0):,} resumed from disk on "
              f"{info.get('scheduler')}, chunks of {info.get('chunk_size')} vehicles, "
              f"{info.get('wall_s', 0):.1f} s. One row per flight: `{table_name}`; the chunks: `chunks/`.\n"]
    return "\n".join(lines)


# --- figures ----------------------------------------------------------------------------
def plot_histograms(result, metrics=("rmse_m", "max_error_m", "final_error_m", "rise_time_s",
                                   "settling_time_5pct_s", "overshoot_pct", "effort", "duty_clipped_s")):
    """Figure of :meth:`MonteCarloResult.plot_histograms`."""
    from matplotlib.figure import Figure

    panels = list(metrics) + ["failures"]
    cols = 3
    rows = math.ceil(len(panels) / cols)
    fig = Figure(figsize=(4.3 * cols, 3.2 * rows), layout="constrained")
    axes = fig.subplots(rows, cols, squeeze=False).ravel()
    for ax, name in zip(axes, panels):
        if name == "failures":
            counts = [int(np.count_nonzero(result.table["failure"] == c)) for c in range(4)]
            ax.bar(range(4), counts, color=["tab:green", "tab:red", "tab:orange", "tab:purple"])
            ax.set_xticks(range(4), FAILURES, fontsize="small")
            for x, c in enumerate(counts):
                ax.annotate(f"{c:,}", (x, c), ha="center", va="bottom", fontsize="small")
            ax.set_title(f"outcome of {result.n:,} flights", fontsize="medium")
            ax.set_ylabel("flights")
            continue
        v = result.table[name].to_numpy(dtype=float)
        v = v[np.isfinite(v)]
        if v.size:
            ax.hist(v, bins=40, color="tab:blue", alpha=0.8)
            for q, style in zip(np.percentile(v, [5, 50, 95]), (":", "-", ":")):
                ax.axvline(q, color="k", ls=style, lw=1.0)
        else:
            ax.text(0.5, 0.5, "not measured", ha="center", va="center", transform=ax.transAxes, color="0.4")
        missing = result.n - v.size
        ax.set_title(f"{name}  (n = {v.size:,}" + (f", {missing:,} n/a)" if missing else ")"), fontsize="medium")
        ax.grid(True, alpha=0.3)
    for ax in axes[len(panels):]:
        ax.set_visible(False)
    fig.suptitle(f"{result.spec.controller.name} on {result.spec.mission.name}: {result.n:,} flights, seed "
                 f"{result.spec.seed} (lines: 5 %, median, 95 %)")
    return fig

def plot_envelope(result):
    """Top view of the kept paths (the first vehicles; failures in orange, diverged in
    red) and the median and 5-95 % band of the position error of the sampled flights."""
    from matplotlib.figure import Figure

    tr = result.traces
    fig = Figure(figsize=(13, 5.5), layout="constrained")
    top, ax_e = fig.subplots(1, 2, width_ratios=(1, 1.4))
    lookup = result.table.set_index("vehicle")["failure"]
    fail = lookup.reindex(tr.vehicle).to_numpy() if len(tr.vehicle) else np.zeros(0, int)
    n_sample = int(np.count_nonzero(tr.sample))
    alpha = float(np.clip(6.0 / max(n_sample, 1), 0.08, 0.8))
    for k in range(len(tr.vehicle)):
        x, y = tr.pos[k, :, 0], tr.pos[k, :, 1]
        color = {0: "tab:blue", 1: "tab:red"}.get(int(fail[k]), "tab:orange")
        top.plot(x, y, color=color, lw=0.7 if fail[k] == 0 else 0.9, alpha=alpha if fail[k] == 0 else 0.7)
        live = np.flatnonzero(np.isfinite(x) & np.isfinite(y))
        if fail[k] == 1 and live.size:
            top.plot(x[live[-1]], y[live[-1]], "x", color="tab:red", ms=6)
    total = result.table["failure"].value_counts()
    for code, color, what in ((0, "tab:blue", "ok"), (1, "tab:red", "diverged"), (2, "tab:orange", "failed otherwise")):
        drawn = int(np.count_nonzero(fail == code)) if code < 2 else int(np.count_nonzero(fail >= 2))
        all_ = int(total.get(code, 0)) if code < 2 else int(total.get(2, 0) + total.get(3, 0))
        if all_:
            top.plot([], [], color=color, lw=1, label=f"{what} ({drawn:,} drawn of {all_:,})")
    ref = next((tr.ref[k] for k in range(len(tr.vehicle)) if np.all(np.isfinite(tr.ref[k, :, :2]))), None)
    if ref is not None:
        top.plot(ref[:, 0], ref[:, 1], color="k", ls="--", lw=1.0, label="reference")
    top.set_aspect("equal", adjustable="datalim")
    top.set(xlabel="x [m]", ylabel="y [m]", title="top view")
    top.legend(fontsize="small", loc="upper center", bbox_to_anchor=(0.5, -0.12), ncols=2)
    err = np.linalg.norm(tr.pos[tr.sample] - tr.ref[tr.sample], axis=2)
    if err.size and np.any(np.isfinite(err)):
        with warnings.catch_warnings():
            warnings.simplefilter("ignore", RuntimeWarning)
            p5, p50, p95 = np.nanpercentile(err, [5, 50, 95], axis=0)
        ax_e.fill_between(tr.t, p5, p95, color="tab:blue", alpha=0.25, lw=0, label="5-95 %")
        ax_e.plot(tr.t, p50, color="tab:blue", lw=1.5, label="median")
        ax_e.set_ylim(bottom=0)
        ax_e.legend(fontsize="small", loc="best")
    ax_e.set(xlabel="time [s]", ylabel="position error |p - p_ref| [m]",
             title=f"position error of the first {n_sample:,} flights")
    if tr.t.size > 1:
        ax_e.set_xlim(tr.t[0], tr.t[-1])
    for ax in (top, ax_e):
        ax.grid(True, alpha=0.3)
    fig.suptitle(f"{result.spec.controller.name} on {result.spec.mission.name}: {result.n:,} flights, seed {result.spec.seed}")
    return fig

