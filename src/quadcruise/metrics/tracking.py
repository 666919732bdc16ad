"""The entry transient of a moving reference (circle, square, waypoints, minimum snap),
measured on the size of the tracking error against its own steady level, vectorised over
vehicles; and the constants that say when a transient exists and when it has ended.
docs/metrics.md gives each definition with its reason, beside python-control's.
"""

from __future__ import annotations

from collections.abc import Sequence

import numpy as np

__all__ = [
    "STEADY_BAND",
    "TRANSIENT_MIN_ERROR",
    "TRACKING_AXIS",
    "FINAL_FRACTION",
    "first_crossing_batch",
    "moving_reference",
    "tracking_transient_batch",
]

TRANSIENT_MIN_ERROR = 0.01
"""An initial tracking error below this [m] is no transient to measure."""
STEADY_BAND = 0.05
"""A transient has ended when it settles into this band (fraction of the step, or of the way
from the initial error to its steady level): the off-track check starts there, and so does
the steady window of a step (``steady_rmse_m``, ``steady_max_error_m``), whatever
``settle_bands`` a table shows."""
TRACKING_AXIS = 3
"""The ``transient_axis`` code of a moving reference's transient: measured on the 3-D error's
size (named ``"xyz"`` in tables), not on one axis."""
FINAL_FRACTION = 0.25
"""A moving reference's error level is its largest value over this last fraction of the
flight; the error has converged when it stayed within the band above that level over
twice that (the last half): see docs/metrics.md."""


def moving_reference(t: np.ndarray, ref: np.ndarray, mission: dict) -> bool:
    """Whether the flight's reference moves: the transient is then measured on the tracking
    error (:func:`tracking_transient_batch`), not as a step.

    Parameters
    ----------
    t : ndarray, shape (L,)
        Sample times [s].
    ref : ndarray, shape (N, L, 3)
        Reference positions [m].
    mission : dict
        The mission's ``to_dict()`` (``{}`` for none): a step mission is a step.

    Returns
    -------
    bool
        True unless the mission is a step or the reference position stays within
        :data:`~quadcruise.metrics.TRANSIENT_MIN_ERROR` of where it starts.

    Examples
    --------
    >>> t = np.linspace(0.0, 1.0, 3)
    >>> moving_reference(t, np.zeros((1, 3, 3)), {}), moving_reference(t, np.ones((1, 3, 3)) * t[:, None], {})
    (False, True)
    """
    if mission.get("kind") == "step":
        return False
    for k in range(ref.shape[-1]):  # axis by axis: the log's strided rows, without copies of (N, L, 3)
        axis = ref[..., k]
        with np.errstate(invalid="ignore"):
            moved = np.fmax.reduce(np.abs(axis - axis[:, :1]), axis=None, initial=0.0)  # NaN (stopped) ignored
        if moved >= TRANSIENT_MIN_ERROR:
            return True
    return False


def tracking_transient_batch(
    t: np.ndarray, err: np.ndarray, bands: Sequence[float], rise: Sequence[float] = (0.1, 0.9)
) -> dict:
    """The entry transient of a moving reference, on the size of the tracking error ``e`` (3-D, [m]).

    The progress ``z = (e0 - e) / (e0 - E)``, ``E`` the steady level (the largest error over the last
    :data:`FINAL_FRACTION`), with python-control's conventions; settled only if the error stayed
    under the band over the last half of the flight. Each rule and its reason: docs/metrics.md.

    Parameters
    ----------
    t : ndarray, shape (L,)
        Sample times [s], at least 2.
    err : ndarray, shape (N, L)
        Tracking errors [m], finite.
    bands : sequence of float
        Settling bands (fractions of ``e0 - E``).
    rise : (float, float)
        Rise levels (fractions of ``e0 - E``).

    Returns
    -------
    dict
        Arrays of shape (N,), NaN where not measured or not converged: ``measured`` (bool),
        ``level`` (E [m]), ``rise_time_s``, ``settling_s`` (one array per band), ``overshoot_pct``,
        ``peak_time_s``, ``settled_at`` (``t[0]`` + the settling into
        :data:`~quadcruise.metrics.STEADY_BAND` [s]) and ``steady_from`` (start of the steady
        window, the last half of the flight [s]).

    Examples
    --------
    >>> t = np.linspace(0.0, 20.0, 2001)
    >>> e = np.vstack([0.1 + 1.9 * np.exp(-t), 2.0 * np.exp(-t / 10.0)])  # settles; still falling
    >>> out = tracking_transient_batch(t, e, [0.05])
    >>> np.round(out["settling_s"][0], 3), np.round(out["level"], 3)       # 5 %: ln 20
    (array([2.996,   nan]), array([0.1  , 0.446]))
    """
    n = err.shape[0]
    out = {
        "measured": np.zeros(n, dtype=bool),
        "level": np.full(n, np.nan),
        "rise_time_s": np.full(n, np.nan),
        "settling_s": [np.full(n, np.nan) for _ in bands],
        "overshoot_pct": np.full(n, np.nan),
        "peak_time_s": np.full(n, np.nan),
        "settled_at": np.full(n, np.nan),
        "steady_from": np.full(n, np.nan),
    }
    span = t[-1] - t[0]
    final = t >= t[-1] - FINAL_FRACTION * span
    if final.sum() < 2:
        final[-2:] = True
    level = err[:, final].max(axis=1)
    e0 = err[:, 0]
    measured = (e0 >= TRANSIENT_MIN_ERROR) & (level < e0)
    out["level"] = level
    out["measured"] = measured
    if not measured.any():
        return out
    sel = np.flatnonzero(measured)
    e, e0, level = err[sel], e0[sel], level[sel]
    scale = (e0 - level)[:, None]
    z = (e0[:, None] - e) / scale
    out["rise_time_s"][sel] = first_crossing_batch(t, z, float(rise[1])) - first_crossing_batch(t, z, float(rise[0]))
    held = t[-1] - 2.0 * FINAL_FRACTION * span  # converged: within the band from here on
    steady_k = None
    for full, band in zip(out["settling_s"] + [None], list(bands) + [STEADY_BAND], strict=False):
        above = z < 1.0 - band
        last = z.shape[1] - 1 - above[:, ::-1].argmax(axis=1)  # last sample above the line
        k = np.minimum(last, z.shape[1] - 2)
        rows = np.arange(sel.size)
        zk, zk1 = z[rows, k], z[rows, k + 1]
        with np.errstate(divide="ignore", invalid="ignore"):
            settle = t[k] + (1.0 - band - zk) / (zk1 - zk) * (t[k + 1] - t[k]) - t[0]
        settle[~above[rows, last]] = 0.0
        settle[settle > held - t[0] + 1e-12] = np.nan
        if full is None:
            steady_k = settle
        else:
            full[sel] = settle
    floor = err[sel][:, final].min(axis=1)
    entry_end = np.minimum(t[0] + 2.0 * steady_k, held)  # twice the settling time: the dip of
    entry = t[None, :] <= np.where(np.isnan(steady_k), -np.inf, entry_end)[:, None]  # an underdamped entry
    low = np.where(entry, e, np.inf)
    k_low = low.argmin(axis=1)
    dip = floor - low[np.arange(sel.size), k_low]
    over = np.where(np.isnan(steady_k), np.nan, np.maximum(0.0, 100.0 * dip / (e0 - level)))
    out["overshoot_pct"][sel] = over
    out["peak_time_s"][sel] = np.where(over > 0.0, t[k_low] - t[0], np.nan)  # NaN > 0 is False
    out["settled_at"][sel] = t[0] + steady_k
    out["steady_from"][sel] = np.where(np.isnan(steady_k), np.nan, held)
    return out


def first_crossing_batch(t: np.ndarray, z: np.ndarray, level: float) -> np.ndarray:
    """Time at which each row of ``z`` first reaches ``level``, interpolated.

    Parameters
    ----------
    t : ndarray, shape (L,)
        Sample times [s].
    z : ndarray, shape (N, L)
        One response per row (normalised: 0 at the start of a step, 1 at its end).
    level : float
        The level to reach, on the scale of ``z`` (0.1 and 0.9 for a 10-90 % rise).

    Returns
    -------
    ndarray, shape (N,)
        The time [s] on the scale of ``t``, interpolated linearly between the samples
        around the first one at or above ``level``; ``t[0]`` if the row starts there; NaN
        if it never gets there.

    Examples
    --------
    >>> first_crossing_batch(np.array([0.0, 1.0, 2.0]), np.array([[0.0, 0.5, 1.0], [0.0, 0.2, 0.4]]), 0.9)
    array([1.8, nan])
    """
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
