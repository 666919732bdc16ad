"""What a compiled function's machine-independent code (LLVM IR) contains, for tests."""

from __future__ import annotations

import functools
import re

from numba import njit


@functools.lru_cache(maxsize=8)
def fresh_llvm(py_func, signature) -> str:
    """The optimised LLVM IR of a fresh, uncached compile of ``py_func`` with ``signature`` (the
    engine's error model): what the engine runs, whatever the cache holds."""
    return "".join(njit(signature, error_model="numpy")(py_func).inspect_llvm().values())


def reference_count_calls(py_func, signature) -> list[str]:
    """The functions, other than numba's Python-facing wrappers, that call NRT_incref or
    NRT_decref in a fresh compile of ``py_func`` with ``signature`` (:func:`fresh_llvm`)."""
    body, calls = "", []
    for line in fresh_llvm(py_func, signature).splitlines():
        start = re.match(r'define [^@]*@"?([^"(]+)', line)
        if start:
            body = start.group(1)
        elif (
            ("@NRT_incref" in line or "@NRT_decref" in line) and "call " in line and not body.startswith("_ZN7cpython")
        ):
            calls.append(body)
    return calls


def row_offsets(py_func, signature, argument: str) -> tuple[set[int], int]:
    """How a fresh compile of ``py_func`` (:func:`fresh_llvm`) addresses the float64 array
    ``argument`` (its parameter's name): the entries it reaches at a constant offset (entry 0,
    the array's own address, needs none and is not listed), and how many addresses it
    computes from a run-time index. A row read through offsets that numba folded as
    constants has none of the latter."""
    constant, computed = set(), 0
    for line in fresh_llvm(py_func, signature).splitlines():
        gep = re.search(rf"getelementptr (?:inbounds )?(\w+), ptr %arg\.{argument}\.\d+, i64 (%?[\w.]+)", line)
        if gep:
            kind, index = gep.groups()
            if index.startswith("%"):
                computed += 1
            else:
                constant.add(int(index) // 8 if kind == "i8" else int(index))
    return constant, computed
