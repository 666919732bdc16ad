"""Several controllers on the same Monte Carlo population (same seed: the same draws, gusts
and noise for each)."""

from __future__ import annotations

import functools
from collections.abc import Callable

from quadcruise.montecarlo.api import montecarlo
from quadcruise.workflows.compare import labelled, named_entries

__all__ = ["compare_population"]


def compare_population(
    mission,
    controllers,
    population,
    n: int,
    seed: int,
    *,
    progress: Callable[[int, int], None] | None = None,
    **montecarlo_kw,
):
    """The controllers on the *same* Monte Carlo population.

    Examples
    --------
    >>> from quadcruise.montecarlo import Population
    >>> t = compare_population("step", ["nlpd", "gonzalez"], Population(mass_spread=0.05), n=4, seed=1,
    ...                        duration=3.0, scheduler="none")
    >>> list(t.index), int(t.loc["nlpd", "flights"])
    (['nlpd', 'gonzalez'], 4)
    """
    import pandas as pd

    rows = {}
    chosen = labelled(controllers)
    named = named_entries(controllers)  # a name: the spec designs its gains for a rotor-plant vehicle
    for k, (label, ctrl) in enumerate(chosen.items()):
        part = None if progress is None else functools.partial(_overall, progress, k * n, len(chosen) * n)
        res = montecarlo(mission, ctrl.name if named[k] else ctrl, population, n, seed, progress=part, **montecarlo_kw)
        s = res.summary()
        row = {"flights": s["flights"], "failure_rate": s["failures"]["rate"]}
        for metric in ("rmse_m", "max_error_m", "steady_rmse_m", "steady_max_error_m", "settling_time_5pct_s"):
            row[f"{metric} p50"] = s["metrics"][metric]["p50"]
            row[f"{metric} p95"] = s["metrics"][metric]["p95"]
        if "estimate_position_rmse_m" in s["metrics"]:  # on the estimate: how far it was from the truth
            row["estimate_position_rmse_m p50"] = s["metrics"]["estimate_position_rmse_m"]["p50"]
        rows[label] = row
    return pd.DataFrame.from_dict(rows, orient="index")


def _overall(progress: Callable[[int, int], None], before: int, total: int, done: int, _: int) -> None:
    """One controller's ``done`` flights reported as flights of all of them."""
    progress(before + done, total)
