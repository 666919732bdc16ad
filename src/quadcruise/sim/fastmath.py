"""The speed tricks of the compiled hot path, in one place, each beside its plain formula.

A trick stays only while an alternating A/B run (``benchmarks/ab.py``) shows that it makes
the default path (the closed-loop circle of one vehicle and of 2,000, and the Monte Carlo
benchmark's sweep) at least 5 % faster; docs/performance.md gives each one's figures, and
those of the tricks that were taken out.
"""

from __future__ import annotations

__all__: list[str] = []
