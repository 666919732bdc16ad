"""The folder of a Monte Carlo sweep (``out``): its marker, the chunks as they finish,
and the resume of an interrupted sweep.

On disk::

    quadcruise.json            the spec, its hash (of the options, version and code), n,
                               and whether the sweep is complete
    chunks/chunk-000000120.npz one per chunk (vehicles 120 ..), written whole or not at all
    flights.csv                one row per flight (or flights.parquet)
    summary.json, worst.csv    quantiles, failure rate by reason, the worst flights
    histograms.png, envelope.png, report.md

quadcruise.json is written before the first chunk and chunks as they finish, so an
interrupted sweep leaves a folder that the same command resumes: chunks already there
(of the same spec hash) are loaded, not flown. A folder holding another sweep, or
anything else, is refused unless ``force``. The results are written at the end
(:mod:`quadcruise.montecarlo.output`).
"""

from __future__ import annotations

import shutil
import warnings
from collections.abc import Iterator
from pathlib import Path
from typing import Any

import numpy as np

from quadcruise._cache import code_digest
from quadcruise._version import __version__
from quadcruise.errors import InputError, WriteError
from quadcruise.io.files import MARKER, atomic_path, check_output_dir, open_regular, read_marker
from quadcruise.io.plainjson import dumps
from quadcruise.montecarlo.schema import COLUMNS
from quadcruise.montecarlo.spec import MonteCarloSpec

__all__ = ["CHUNKS", "write_marker", "holds_sweep"]

CHUNKS = "chunks"


def _chunk_path(folder: Path, first: int) -> Path:
    return folder / CHUNKS / f"chunk-{first:09d}.npz"


def _write_chunk(folder: Path, chunk: dict) -> None:
    with atomic_path(_chunk_path(folder, int(chunk["first"]))) as tmp:
        with open(tmp, "wb") as f:
            np.savez(f, **chunk)


TRACES = ("trace_vehicle", "trace_sample", "trace_t", "trace_pos", "trace_ref")
"""The arrays of a chunk file besides ``first``, ``count``, ``hash`` and the table's columns."""


def _load_chunk(path: Path) -> dict:
    """The arrays of one chunk file; ValueError or OSError if it is not a whole .npz archive."""
    with open_regular(path) as f:  # closed whatever np.load makes of it; a FIFO is refused, not waited on
        if f.read(4) not in (b"PK\x03\x04", b"PK\x05\x06"):
            raise ValueError("not an .npz archive")
        f.seek(0)
        with np.load(f, allow_pickle=False) as data:
            return {k: data[k] for k in data.files}


def _chunk_problem(chunk: dict, first: int) -> str | None:
    """What makes a loaded chunk unusable (missing arrays, lengths that do not agree), or None."""
    missing = [k for k in ("first", "count", "hash", *COLUMNS, *TRACES) if k not in chunk]
    if missing:
        return f"it lacks {', '.join(missing[:3])}{' ...' if len(missing) > 3 else ''}"
    if chunk["first"].shape != () or chunk["count"].shape != () or int(chunk["first"]) != first:
        return "its first vehicle is not the one its name says"
    count = int(chunk["count"])
    if count < 1 or any(chunk[k].shape != (count,) for k in COLUMNS):
        return "its columns do not hold one value per flight"
    if not np.array_equal(chunk["vehicle"], np.arange(first, first + count)):
        return "its vehicles are not numbered in order"
    kept, samples = chunk["trace_vehicle"].shape, chunk["trace_t"].shape
    if (
        len(kept) != 1
        or chunk["trace_sample"].shape != kept
        or len(samples) != 1
        or any(chunk[k].shape != (*kept, *samples, 3) for k in ("trace_pos", "trace_ref"))
    ):
        return "its paths do not fit together"
    return None


def _read_chunks(folder: Path, spec_hash: str) -> Iterator[dict]:
    """The complete chunks of this spec in ``folder``; others are skipped with a warning."""
    for path in sorted((folder / CHUNKS).glob("chunk-*.npz")):
        try:
            first = int(path.stem.split("-")[1])
            chunk = _load_chunk(path)
        except Exception as exc:  # a foreign or damaged file: fly it again
            warnings.warn(
                f"{path}: damaged or unreadable ({' '.join(str(exc).split()) or type(exc).__name__}); "
                "its flights are flown again",
                stacklevel=3,
            )
            continue
        if str(chunk.get("hash")) != spec_hash:
            warnings.warn(f"{path}: belongs to another sweep; its flights are flown again", stacklevel=3)
            continue
        problem = _chunk_problem(chunk, first)
        if problem is not None:
            warnings.warn(f"{path}: damaged ({problem}); its flights are flown again", stacklevel=3)
            continue
        yield chunk


def _marker(path: Path, force: bool = False) -> dict | None:
    """The folder's marker; a damaged one is refused (InputError) unless ``force``, then None."""
    try:
        return read_marker(path)
    except InputError:
        if force:
            return None
        raise


def holds_sweep(path: Path, spec: MonteCarloSpec, *, force: bool = False) -> tuple[dict | None, bool]:
    """What folder ``path`` holds, and whether it is this very sweep."""
    meta = _marker(path, force) if path.is_dir() else None
    return meta, bool(meta) and meta.get("workflow") == "montecarlo" and meta.get("spec_hash") == spec.hash()


class SweepFolder:
    """The output folder of a sweep: checked at construction (nothing is written), then
    :meth:`prepare` (marker), :meth:`write_chunk`."""

    def __init__(self, out, spec: MonteCarloSpec, *, force: bool, resume: bool) -> None:
        self.path = check_output_dir(out, force, workflow="montecarlo")
        self.hash = spec.hash()
        self.spec = spec
        meta, same = holds_sweep(self.path, spec, force=force)
        if meta is not None and not same and not force:
            what = (
                f"a different sweep (spec {meta.get('spec_hash')})"
                if meta.get("workflow") == "montecarlo"
                else f"a quadcruise {meta.get('workflow', 'result')} result"
            )
            raise InputError(f"{self.path}: holds {what}; use --force to replace it or choose another --out")
        self.resume = same and resume
        self.clear = self.path.is_dir() and any(self.path.iterdir()) and not self.resume

    def existing(self) -> Iterator[dict]:
        """The chunks of this sweep already in the folder (none unless resuming)."""
        return _read_chunks(self.path, self.hash) if self.resume else iter(())

    def prepare(self, n: int, chunk_size: int) -> None:
        """Clear a folder that is not resumed, and write the marker (not complete)."""
        # the marker before the chunks' folder: a fault leaves a folder this sweep resumes, or none of its own
        try:
            if self.clear:
                shutil.rmtree(self.path)
            write_marker(self.path, self.spec, n, chunk_size=chunk_size, complete=False)
            (self.path / CHUNKS).mkdir(exist_ok=True)
        except WriteError:
            raise
        except OSError as exc:
            raise WriteError(self.path, exc) from None

    def reclaim(self, n: int, chunk_size: int) -> None:
        """Write the marker again if it is gone or damaged since :meth:`prepare` (the folder
        removed or changed while the sweep ran), so that the results go where they were asked
        for instead of being refused as another's."""
        try:
            held = read_marker(self.path)
        except InputError:
            held = None
        if not held or held.get("spec_hash") != self.hash:
            write_marker(self.path, self.spec, n, chunk_size=chunk_size, complete=False)

    def write_chunk(self, chunk: dict) -> None:
        """Write one chunk as ``chunks/chunk-<first>.npz``, whole or not at all."""
        _write_chunk(self.path, chunk)


def write_marker(path: Path, spec: MonteCarloSpec, n: int, **extra: Any) -> None:
    """quadcruise.json of a sweep folder, whole or not at all."""
    doc = {
        "workflow": "montecarlo",
        "version": __version__,
        "code": code_digest()[:16],
        "spec_hash": spec.hash(),
        "n": n,
        "seed": spec.seed,
        **extra,
        "spec": spec.to_dict(),
    }
    with atomic_path(path / MARKER) as tmp:
        tmp.write_text(dumps(doc, indent=2) + "\n")
