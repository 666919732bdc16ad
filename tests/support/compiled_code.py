"""What a compiled function's machine-independent code (LLVM IR) contains, for tests."""

from __future__ import annotations

import re

from numba import njit


def reference_count_calls(py_func, signature) -> list[str]:
    """The functions, other than numba's Python-facing wrappers, that call NRT_incref or
    NRT_decref in a fresh, uncached compile of ``py_func`` with ``signature`` (the
    engine's error model): what the engine runs, whatever the cache holds."""
    fresh = njit(signature, error_model="numpy")(py_func)
    body, calls = "", []
    for line in "".join(fresh.inspect_llvm().values()).splitlines():
        start = re.match(r'define [^@]*@"?([^"(]+)', line)
        if start:
            body = start.group(1)
        elif (
            ("@NRT_incref" in line or "@NRT_decref" in line) and "call " in line and not body.startswith("_ZN7cpython")
        ):
            calls.append(body)
    return calls
