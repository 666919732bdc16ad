"""Response metrics of a batch of flights, vectorised over the vehicles.

:mod:`quadcruise.metrics` measures one response at a time (:func:`~quadcruise.metrics.step_info`,
:func:`~quadcruise.metrics.transient_info`; :func:`~quadcruise.metrics.flight_metrics`
loops over the vehicles). The functions here take every vehicle at once, on the first
axis of (N, L) or (N, L, 3) arrays sampled on one time grid ``t`` (strictly increasing,
not necessarily uniform), and give the same numbers, to rounding, by the same rules:
crossings interpolated linearly between samples, integrals by the trapezoid rule. Each
vehicle's numbers depend on its own rows only. A Monte Carlo sweep's table is built from
them (:func:`quadcruise.montecarlo.sweep.sweep_metrics`).

Examples
--------
>>> t = np.linspace(0.0, 10.0, 1001)
>>> pos = np.zeros((2, t.size, 3))
>>> pos[:, :, 0] = np.outer([1.0, 2.0], np.exp(-t))     # x errors of 1 m and 2 m dying out
>>> out = flight_metrics_batch(t, pos, np.zeros_like(pos), np.zeros((2, t.size, 4)))
>>> out["transient_axis"], np.round(out["settling_s"][0], 3)   # 2 % settling: ln 50
(array([0, 0]), array([3.912, 3.912]))
"""

from __future__ import annotations

from collections.abc import Sequence

import numpy as np

from quadcruise.metrics.signals import control_effort, tracking_errors
from quadcruise.metrics.tracking import (
    STEADY_BAND,
    TRACKING_AXIS,
    TRANSIENT_MIN_ERROR,
    first_crossing_batch,
    moving_reference,
    tracking_transient_batch,
)

__all__ = [
    "first_crossing_batch",
    "settling_time_batch",
    "transient_batch",
    "window_errors_batch",
    "flight_metrics_batch",
]


def settling_time_batch(t: np.ndarray, z: np.ndarray, band: float) -> np.ndarray:
    """Time from ``t[0]`` after which each row of ``z`` stays within ``band`` of 1.

    Parameters
    ----------
    t : ndarray, shape (L,)
        Sample times [s], at least 2.
    z : ndarray, shape (N, L)
        One normalised response per row (1 is the value it should settle to).
    band : float
        Half-width of the band around 1 (0.02 for 2 %).

    Returns
    -------
    ndarray, shape (N,)
        ``t - t[0]`` [s] at the last exit from ``|z - 1| <= band``, interpolated on the
        band's edge; 0 for a row never outside; NaN for a row outside at the last sample
        (it did not settle).

    Examples
    --------
    >>> t = np.array([0.0, 1.0, 2.0, 3.0])
    >>> settling_time_batch(t, np.array([[0.0, 0.5, 1.0, 1.0], [0.0, 0.5, 0.9, 0.95]]), 0.02)
    array([1.96,  nan])
    """
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


def transient_batch(
    t: np.ndarray,
    pos: np.ndarray,
    ref: np.ndarray,
    mission: dict,
    bands: Sequence[float],
    rise: Sequence[float] = (0.1, 0.9),
    err: np.ndarray | None = None,
) -> dict:
    """The transient of each vehicle, measured as :func:`quadcruise.metrics.flight_metrics` does.

    Parameters
    ----------
    t : ndarray, shape (L,)
        Sample times [s], at least 2.
    pos, ref : ndarray, shape (N, L, 3)
        Positions and references [m], finite.
    mission : dict
        The mission's ``to_dict()`` (``{}`` for none).
    bands : sequence of float
        Settling bands (0.02 for 2 %).
    rise : (float, float)
        Rise-time levels, fractions of the step (0.1 and 0.9 for 10-90 %).
    err : ndarray, shape (N, L), optional
        The 3-D position errors [m], if already computed.

    Returns
    -------
    dict
        Arrays of shape (N,): ``axis`` (0, 1, 2 for x, y, z, :data:`TRACKING_AXIS` for a moving
        reference's error, -1 for none), ``t_step`` [s], ``rise_time_s``, ``settling_s`` (one
        array per band), ``overshoot_pct``, ``peak_time_s`` (from ``t_step`` [s]), ``settled_at``
        and ``steady_from`` (the end of the transient and the start of the steady window [s]).
        NaN where no transient is measured, for a step outside ``[t[0], t[-1])``, and (the last
        two) for one that did not settle.
    """
    n = pos.shape[0]
    bands = [float(b) for b in bands]
    out = {
        "axis": np.full(n, -1, dtype=np.int64),
        "t_step": np.full(n, np.nan),
        "rise_time_s": np.full(n, np.nan),
        "settling_s": [np.full(n, np.nan) for _ in bands],
        "overshoot_pct": np.full(n, np.nan),
        "peak_time_s": np.full(n, np.nan),
        "settled_at": np.full(n, np.nan),
        "steady_from": np.full(n, np.nan),
    }
    if moving_reference(t, ref, mission):
        if err is None:
            d = pos - ref
            err = np.sqrt((d * d).sum(axis=-1))
        got = tracking_transient_batch(t, err, bands, rise)
        sel = got["measured"]
        out["axis"][sel] = TRACKING_AXIS
        out["t_step"][sel] = t[0]
        for key in ("rise_time_s", "overshoot_pct", "peak_time_s", "settled_at", "steady_from"):
            out[key][sel] = got[key][sel]
        for full, got_band in zip(out["settling_s"], got["settling_s"], strict=False):
            full[sel] = got_band[sel]
        return out
    if mission.get("kind") == "step" and mission.get("axis") in ("x", "y", "z"):
        j = "xyz".index(mission["axis"])
        t_step = float(mission["time"])
        if not t[0] <= t_step < t[-1]:
            return out
        y0 = float(mission[mission["axis"]])
        step = float(mission["size"])
        after = t > t_step
        ts = np.concatenate(([t_step], t[after]))
        ys = np.empty((n, ts.size))
        ys[:, 1:] = pos[:, after, j]
        ys[:, 0] = [np.interp(t_step, t, pos[i, :, j]) for i in range(n)]
        z = (ys - y0) / step
        sel = np.arange(n)
        out["axis"][:] = j
    else:
        e0 = np.abs(ref[:, 0] - pos[:, 0])
        j = e0.argmax(axis=1)
        rows = np.arange(n)
        measured = e0[rows, j] >= TRANSIENT_MIN_ERROR
        out["axis"][measured] = j[measured]
        if not measured.any():
            return out
        sel = rows[measured]
        e = ref[sel, :, j[measured]] - pos[sel, :, j[measured]]
        z = 1.0 - e / e[:, :1]
        ts = t
    out["t_step"][sel] = ts[0]
    out["rise_time_s"][sel] = first_crossing_batch(ts, z, float(rise[1])) - first_crossing_batch(ts, z, float(rise[0]))
    for full, band in zip(out["settling_s"], bands, strict=False):
        full[sel] = settling_time_batch(ts, z, band)
    out["settled_at"][sel] = out["steady_from"][sel] = ts[0] + settling_time_batch(ts, z, STEADY_BAND)
    out["overshoot_pct"][sel] = np.maximum(0.0, 100.0 * (z.max(axis=1) - 1.0))
    out["peak_time_s"][sel] = ts[z.argmax(axis=1)] - ts[0]
    return out


def window_errors_batch(t: np.ndarray, pos: np.ndarray, ref: np.ndarray, t_from: np.ndarray) -> dict:
    """RMS and maximum 3-D position error of each vehicle from its own start time on.

    :func:`quadcruise.metrics.tracking_errors` with ``t_from``, one start per vehicle: the
    error interpolated linearly at ``t_from``, the window ``[t_from, t[-1]]`` integrated by
    trapezoids.

    Parameters
    ----------
    t : ndarray, shape (L,)
        Sample times [s], at least 2.
    pos, ref : ndarray, shape (N, L, 3)
        Positions and references [m].
    t_from : ndarray, shape (N,)
        Start of each vehicle's window [s], in ``[t[0], t[-1]]``; NaN for none.

    Returns
    -------
    dict of ndarray, shape (N,)
        ``rmse`` and ``max_error`` [m]; the error at the last sample where ``t_from`` is
        ``t[-1]``; NaN where ``t_from`` is NaN.

    Examples
    --------
    >>> t = np.array([0.0, 1.0, 2.0, 3.0])
    >>> pos = np.zeros((2, 4, 3))
    >>> pos[:, :, 0] = [10.0, 0.0, 0.0, 0.0]
    >>> window_errors_batch(t, pos, np.zeros_like(pos), np.array([0.5, np.nan]))["max_error"]
    array([ 5., nan])
    """
    n, length = pos.shape[:2]
    rows = np.arange(n)
    d = pos - ref
    e2 = (d**2).sum(axis=-1)  # (N, L)
    seg = 0.5 * (e2[:, 1:] + e2[:, :-1]) * np.diff(t)  # (N, L - 1)
    tail = np.zeros((n, length))
    tail[:, :-1] = np.cumsum(seg[:, ::-1], axis=1)[:, ::-1]  # integral from t[k] to the end
    peak = np.maximum.accumulate(np.sqrt(e2)[:, ::-1], axis=1)[:, ::-1]  # max from t[k] on
    start = np.where(np.isfinite(t_from), t_from, t[0])
    k = np.clip(np.searchsorted(t, start, side="right"), 1, length - 1)  # t[k - 1] <= start < t[k]
    w = ((start - t[k - 1]) / (t[k] - t[k - 1]))[:, None]
    d_from = d[rows, k - 1] + w * (d[rows, k] - d[rows, k - 1])
    e2_from = (d_from**2).sum(axis=-1)
    integral = 0.5 * (e2_from + e2[rows, k]) * (t[k] - start) + tail[rows, k]
    with np.errstate(divide="ignore", invalid="ignore"):
        rmse = np.sqrt(integral / (t[-1] - start))
    max_error = np.maximum(np.sqrt(e2_from), peak[rows, k])
    last = start >= t[-1]
    rmse[last] = max_error[last] = np.sqrt(e2[last, -1])
    rmse[~np.isfinite(t_from)] = max_error[~np.isfinite(t_from)] = np.nan
    return {"rmse": rmse, "max_error": max_error}


def flight_metrics_batch(
    t: np.ndarray,
    pos: np.ndarray,
    ref: np.ndarray,
    duties: np.ndarray,
    *,
    mission: dict | None = None,
    bands: Sequence[float] = (0.02, 0.05),
    transient_until: float | None = None,
    rise: Sequence[float] = (0.1, 0.9),
    hover_duty=None,
) -> dict:
    """Tracking error, effort and transient of N vehicles that flew the whole record.

    The numbers of :func:`quadcruise.metrics.flight_metrics` (for vehicles that did not stop early
    and have a finite reference), and the position error at the end.

    Parameters
    ----------
    t : ndarray, shape (L,)
        Sample times [s], strictly increasing.
    pos, ref : ndarray, shape (N, L, 3)
        Positions and references [m], finite.
    duties : ndarray, shape (N, L, 4)
        Rotor duties commanded [-].
    mission : dict, optional
        The mission's ``to_dict()``: how the transient is measured (:func:`transient_batch`).
    bands : sequence of float
        Settling bands (fractions).
    transient_until : float, optional
        End [s] of the window in which the transient is measured.
    rise : (float, float)
        Rise-time levels (fractions of the step).
    hover_duty : float or ndarray of shape (N,), optional
        Each vehicle's hover duty [-], about which the effort is measured; without it, NaN.

    Returns
    -------
    dict of ndarray, shape (N,)
        ``rmse_m``, ``max_error_m`` (over the record), ``steady_rmse_m``, ``steady_max_error_m``
        (over the steady window, :func:`transient_batch`'s ``steady_from``; the whole record
        without a transient; NaN if it never settles), ``final_error_m``, ``effort`` [s],
        ``transient_axis`` (-1: none; also when the window holds fewer than 2 samples),
        ``rise_time_s``, ``overshoot_pct``, ``peak_time_s``, and ``settling_s`` (one array per band).

    Examples
    --------
    >>> t = np.linspace(0.0, 10.0, 1001)
    >>> pos = np.zeros((1, t.size, 3))
    >>> pos[0, :, 0] = np.exp(-t)                          # 1 m of x error dying out
    >>> duties = np.full((1, t.size, 4), 0.25)
    >>> out = flight_metrics_batch(t, pos, np.zeros_like(pos), duties, hover_duty=0.25)
    >>> float(out["effort"][0]), round(float(out["steady_max_error_m"][0]), 6)   # 5 % of 1 m
    (0.0, 0.05)
    """
    n = pos.shape[0]
    bands = [float(b) for b in bands]
    err = tracking_errors(t, pos, ref)
    if hover_duty is None:
        effort = np.full(n, np.nan)
    else:
        trim = np.broadcast_to(np.asarray(hover_duty, dtype=float), (n,))
        effort = control_effort(t, duties - trim[:, None, None])["integral"]
    out = {
        "rmse_m": err["rmse"],
        "max_error_m": err["max_error"],
        "steady_rmse_m": err["rmse"].copy(),
        "steady_max_error_m": err["max_error"].copy(),
        "final_error_m": np.linalg.norm(pos[:, -1] - ref[:, -1], axis=1),
        "effort": effort,
        "transient_axis": np.full(n, -1, dtype=np.int64),
        "rise_time_s": np.full(n, np.nan),
        "settling_s": [np.full(n, np.nan) for _ in bands],
        "overshoot_pct": np.full(n, np.nan),
        "peak_time_s": np.full(n, np.nan),
        "settled_at": np.full(n, np.nan),
    }
    keep = slice(None) if transient_until is None else t <= transient_until
    tk = t[keep]
    if tk.size >= 2:
        got = transient_batch(tk, pos[:, keep], ref[:, keep], mission or {}, bands, rise)
        out.update(
            transient_axis=got["axis"],
            rise_time_s=got["rise_time_s"],
            settling_s=got["settling_s"],
            overshoot_pct=got["overshoot_pct"],
            peak_time_s=got["peak_time_s"],
            settled_at=got["settled_at"],
        )
        measured = np.flatnonzero(got["axis"] >= 0)
        if measured.size:
            steady = window_errors_batch(t, pos[measured], ref[measured], got["steady_from"][measured])
            out["steady_rmse_m"][measured] = steady["rmse"]
            out["steady_max_error_m"][measured] = steady["max_error"]
    return out
