"""Whether the filter a sweep flew on was consistent: the mean NEES over its flights against the
chi-square 95 % bounds (Bar-Shalom, Li and Kirubarajan, *Estimation with Applications to Tracking
and Navigation*, 2001, sec. 5.4.2).

Each flight's ``nees_position`` (and velocity, attitude) is the mean of its filter's NEES over its
logged instants (:func:`quadcruise.metrics.estimate.estimate_metrics`, 3 dof). Over N flights the
average of N independent chi-square(3) values lies, for a consistent filter, within
``chi2.ppf([0.025, 0.975], 3 N) / N`` with 95 % probability. A flight's time-mean varies less than
one instant's NEES, so these bounds are wide for it: a value outside them is inconsistent all the
more; the per-instant check is ``benchmarks/ekf_consistency_loop.py``'s.

Examples
--------
>>> import numpy as np, pandas as pd
>>> tab = pd.DataFrame({k: np.full(100, 3.0) for k in ("nees_position", "nees_velocity", "nees_attitude")})
>>> c = nees_consistency(tab, np.ones(100, dtype=bool))
>>> c["nees_position"]["inside"], [round(b, 2) for b in c["nees_position"]["bounds"]]
(True, [2.54, 3.5])
"""

from __future__ import annotations

import numpy as np

__all__ = ["NEES_COLUMNS", "chi2_bounds", "consistency_text", "nees_consistency"]

NEES_COLUMNS = {"nees_position": 3, "nees_velocity": 3, "nees_attitude": 3}
"""The table's NEES columns and their degrees of freedom."""


def chi2_bounds(dof: int, runs: int, p: float = 0.95) -> tuple[float, float]:
    """The two-sided ``p`` bounds of the average of ``runs`` chi-square(``dof``) values.

    Parameters
    ----------
    dof : int
        Degrees of freedom of one value.
    runs : int
        How many are averaged, >= 1.
    p : float
        Probability inside.

    Returns
    -------
    (float, float)
        ``chi2.ppf((1 -+ p) / 2, dof runs) / runs``.

    Examples
    --------
    >>> [round(b, 3) for b in chi2_bounds(3, 500)]
    [2.789, 3.218]
    """
    from quadcruise.estimation import average_bounds

    lo, hi = average_bounds(dof, runs, p)
    return float(lo), float(hi)


def nees_consistency(table, kept) -> dict:
    """The mean NEES of the flights that kept track, and its 95 % bounds.

    Parameters
    ----------
    table : pandas.DataFrame
        A sweep's table (its ``nees_*`` columns).
    kept : numpy.ndarray
        (N,) bool: the flights counted.

    Returns
    -------
    dict
        For each of :data:`NEES_COLUMNS`: ``mean``, ``flights``, ``bounds`` (lower, upper) and
        ``inside`` (None without a flight).
    """
    out = {}
    for name, dof in NEES_COLUMNS.items():
        v = table[name].to_numpy(dtype=float)[np.asarray(kept, dtype=bool)]
        v = v[np.isfinite(v)]
        if not v.size:
            out[name] = {"mean": None, "flights": 0, "bounds": None, "inside": None}
            continue
        lo, hi = chi2_bounds(dof, v.size)
        mean = float(v.mean())
        out[name] = {"mean": mean, "flights": int(v.size), "bounds": [lo, hi], "inside": bool(lo <= mean <= hi)}
    return out


def consistency_text(consistency: dict) -> str:
    """One line a quantity: the mean NEES, its bounds and the verdict.

    Parameters
    ----------
    consistency : dict
        :func:`nees_consistency`'s.

    Returns
    -------
    str

    Examples
    --------
    >>> print(consistency_text({"nees_position": {"mean": 4.1, "flights": 10, "bounds": [2.0, 4.0], "inside": False}}))
      filter consistency (mean NEES over the flights, 3 for a consistent filter; 95 % bounds):
        nees_position    4.1 in [2, 4] over 10 flights: above (overconfident)
    """
    lines = ["  filter consistency (mean NEES over the flights, 3 for a consistent filter; 95 % bounds):"]
    for name, c in consistency.items():
        if c["mean"] is None:
            lines.append(f"    {name:<16} not measured")
            continue
        lo, hi = c["bounds"]
        verdict = "inside" if c["inside"] else ("above (overconfident)" if c["mean"] > hi else "below (too cautious)")
        lines.append(f"    {name:<16} {c['mean']:.4g} in [{lo:.4g}, {hi:.4g}] over {c['flights']:,} flights: {verdict}")
    return "\n".join(lines)
