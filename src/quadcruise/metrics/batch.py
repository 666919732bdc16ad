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

from typing import Sequence

import numpy as np

from quadcruise.metrics.flight import TRANSIENT_MIN_ERROR, control_effort, tracking_errors

__all__ = ["first_crossing_batch", "settling_time_batch", "transient_batch", "flight_metrics_batch"]


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


def transient_batch(t: np.ndarray, pos: np.ndarray, ref: np.ndarray, mission: dict, bands: Sequence[float]):
    """The transient of each vehicle, measured as :func:`quadcruise.metrics.flight_metrics` does.

    On the stepped axis of a step mission, as a step response from the hover point the
    step leaves to the one it commands (from the step time on); otherwise on the axis
    with the largest initial tracking error, as the progress ``1 - e(t) / e(t[0])`` of
    that axis's error, if that error is at least
    :data:`~quadcruise.metrics.TRANSIENT_MIN_ERROR`.

    Parameters
    ----------
    t : ndarray, shape (L,)
        Sample times [s], at least 2.
    pos, ref : ndarray, shape (N, L, 3)
        Positions and references [m], finite.
    mission : dict
        The mission as its ``to_dict()`` records it (``kind``; for a step ``axis``,
        ``time``, ``size`` and the hover point); ``{}`` for none.
    bands : sequence of float
        Settling bands (0.02 for 2 %).

    Returns
    -------
    axis : ndarray of int64, shape (N,)
        The measured axis (0, 1, 2 for x, y, z), -1 where none is measured.
    rise : ndarray, shape (N,)
        10-90 % rise time [s].
    settling : list of ndarray, shape (N,)
        Settling time [s] from the start of the transient, one array per band.
    overshoot : ndarray, shape (N,)
        Overshoot [%] of the step (or of the initial error).

    Notes
    -----
    Every value of a vehicle without a measured transient is NaN, and so is every value
    of a step whose time lies outside ``[t[0], t[-1])``.
    """
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
    t_lo, t_hi = first_crossing_batch(ts, z, 0.1), first_crossing_batch(ts, z, 0.9)
    rise = t_hi - t_lo
    settle = [settling_time_batch(ts, z, b) for b in bands]
    over = np.maximum(0.0, 100.0 * (z.max(axis=1) - 1.0))
    if z.shape[0] == n:
        return axis, rise, settle, over
    sel = axis >= 0

    def put(v):
        full = np.full(n, np.nan)
        full[sel] = v
        return full
    return axis, put(rise), [put(s) for s in settle], put(over)


def flight_metrics_batch(t: np.ndarray, pos: np.ndarray, ref: np.ndarray, duties: np.ndarray, *,
                         mission: dict | None = None, bands: Sequence[float] = (0.02, 0.05),
                         transient_until: float | None = None) -> dict:
    """Tracking error, effort and transient of N vehicles that flew the whole record.

    The numbers of :func:`quadcruise.metrics.flight_metrics` for vehicles that did not
    stop early and have a finite reference (leave the others out: their metrics are NaN
    there), and the position error at the end.

    Parameters
    ----------
    t : ndarray, shape (L,)
        Sample times [s], strictly increasing.
    pos, ref : ndarray, shape (N, L, 3)
        Positions and references [m], finite.
    duties : ndarray, shape (N, L, 4)
        Rotor duties commanded [-].
    mission : dict, optional
        The mission's ``to_dict()``, which says how the transient is measured
        (:func:`transient_batch`).
    bands : sequence of float
        Settling bands (fractions).
    transient_until : float, optional
        End [s] of the window in which the transient is measured.

    Returns
    -------
    dict of ndarray, shape (N,)
        ``rmse_m`` and ``max_error_m`` (3-D position error over the record),
        ``final_error_m`` (at the last sample), ``effort`` (integral of the sum of squared
        duties [s]), ``transient_axis`` (-1: none), ``rise_time_s``, ``overshoot_pct``,
        and ``settling_s``: a list of one array per band. The transient is NaN (axis -1)
        when the window holds fewer than 2 samples.
    """
    n = pos.shape[0]
    err = tracking_errors(t, pos, ref)
    out = {"rmse_m": err["rmse"], "max_error_m": err["max_error"],
           "final_error_m": np.linalg.norm(pos[:, -1] - ref[:, -1], axis=1),
           "effort": control_effort(t, duties)["integral"],
           "transient_axis": np.full(n, -1, dtype=np.int64), "rise_time_s": np.full(n, np.nan),
           "settling_s": [np.full(n, np.nan) for _ in bands], "overshoot_pct": np.full(n, np.nan)}
    keep = slice(None) if transient_until is None else t <= transient_until
    tk = t[keep]
    if tk.size >= 2:
        axis, rise, settle, over = transient_batch(tk, pos[:, keep], ref[:, keep], mission or {}, bands)
        out.update(transient_axis=axis, rise_time_s=rise, settling_s=settle, overshoot_pct=over)
    return out
