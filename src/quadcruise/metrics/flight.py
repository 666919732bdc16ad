"""Response metrics: step and transient characteristics, tracking error, effort, saturation.

Pure numpy; times in seconds, positions in metres. Everything reads sampled signals on a
time grid ``t`` that must be strictly increasing but need not be uniform: crossings are
interpolated linearly between samples and integrals use the trapezoid rule. The same
metrics for every vehicle of a batch at once, vectorised: :mod:`quadcruise.metrics.batch`.

Examples
--------
>>> import numpy as np
>>> t = np.linspace(0.0, 10.0, 10001)
>>> info = step_info(t, 1.0 - np.exp(-t), y_final=1.0)   # first order, tau = 1 s
>>> round(info.rise_time, 4), round(float(np.log(9.0)), 4)    # 10-90 % rise is ln 9
(2.1972, 2.1972)
>>> round(info.settling_time, 4), round(float(np.log(50.0)), 4)  # 2 % settling: ln 50
(3.912, 3.912)
"""

from __future__ import annotations

import dataclasses
from dataclasses import dataclass

import numpy as np

from quadcruise.errors import InputError
from quadcruise.metrics.tracking import STEADY_BAND, TRANSIENT_MIN_ERROR, moving_reference, tracking_transient_batch

__all__ = [
    "StepInfo",
    "step_info",
    "step_info_batch",
    "transient_info",
    "tracking_errors",
    "control_effort",
    "time_in_saturation",
    "flight_metrics",
    "metric_conventions",
    "settling_column",
    "hover_duties",
    "STEADY_BAND",
    "EFFORT_DEFINITION",
    "RISE_CONVENTIONS",
]


@dataclass(frozen=True)
class StepInfo:
    """Step-response characteristics; times in seconds measured from the step.

    :func:`step_info` builds it. Percentages are of the step size ``|y_final - y_initial|``.

    Parameters
    ----------
    rise_time : float or None
        10-90 % rise time [s] (between the two ``rise`` levels of :func:`step_info`);
        None if the response never reaches the upper level.
    settling_time : float or None
        Settling time [s] into ``settle_bands[0]`` (2 % by default); None if the response
        is outside the band at the last sample ("did not settle").
    settling_time_5pct : float or None
        Settling time [s] into ``settle_bands[1]`` (5 % by default); None likewise.
    overshoot_pct : float
        Overshoot beyond ``y_final`` [%], 0 if none.
    undershoot_pct : float
        Excursion against the step direction [%], 0 if none.
    peak : float
        The response at its largest excursion in the step direction [unit of ``y``].
    peak_time : float
        First time of the peak [s], from the step.
    y_initial : float
        The value before the step [unit of ``y``].
    y_final : float
        The value the response should settle to [unit of ``y``].
    settled : bool
        True if ``settling_time`` exists (the response ends inside the first band).
    """

    rise_time: float | None
    settling_time: float | None
    settling_time_5pct: float | None
    overshoot_pct: float
    undershoot_pct: float
    peak: float
    peak_time: float
    y_initial: float
    y_final: float
    settled: bool

    def to_dict(self) -> dict:
        """The fields as a plain dict (None stays None).

        Returns
        -------
        dict
            Field name -> value.
        """
        return dataclasses.asdict(self)


def _check_time(t) -> np.ndarray:
    t = np.asarray(t, dtype=float)
    if t.ndim != 1 or t.size < 2:
        raise InputError(f"time vector must be 1-D with at least 2 samples, got shape {t.shape}")
    if not np.all(np.isfinite(t)):
        raise InputError("time vector contains NaN or inf")
    if not np.all(np.diff(t) > 0):
        raise InputError("time vector must be strictly increasing")
    return t


def _step_time(t: np.ndarray, signal: np.ndarray, t_step, what: str) -> float:
    """Check the signal is finite and t_step (default t[0]) lies in [t[0], t[-1])."""
    if not np.all(np.isfinite(signal)):
        raise InputError(f"{what} contains NaN or inf")
    t_step = float(t[0]) if t_step is None else float(t_step)
    if not t[0] <= t_step < t[-1]:
        raise InputError(f"t_step = {t_step:g} s is outside [{t[0]:g}, {t[-1]:g}) s")
    return t_step


def _first_crossing(t: np.ndarray, z: np.ndarray, level: float) -> float | None:
    """Time at which z first reaches ``level`` from below, interpolated (None if never)."""
    hits = np.flatnonzero(z >= level)
    if hits.size == 0:
        return None
    k = hits[0]
    if k == 0:
        return float(t[0])
    frac = (level - z[k - 1]) / (z[k] - z[k - 1])
    return float(t[k - 1] + frac * (t[k] - t[k - 1]))


def _settling_time(t: np.ndarray, z: np.ndarray, band: float) -> float | None:
    """Time (from t[0]) after which |z - 1| <= band for good, interpolated at the last exit."""
    outside = np.abs(z - 1.0) > band
    if outside[-1]:
        return None
    if not outside.any():
        return 0.0
    k = np.flatnonzero(outside)[-1]  # z[k] outside, z[k + 1] inside
    edge = 1.0 + band if z[k] > 1.0 else 1.0 - band
    frac = (edge - z[k]) / (z[k + 1] - z[k])
    return float(t[k] + frac * (t[k + 1] - t[k]) - t[0])


def step_info(
    t, y, *, y_initial=None, y_final=None, t_step=None, rise=(0.1, 0.9), settle_bands=(0.02, 0.05)
) -> StepInfo:
    """Rise time, settling times, overshoot, undershoot and peak of one step response.

    The response is normalised as ``z = (y - y_initial) / (y_final - y_initial)``: rise between the
    first crossings of the two ``rise`` levels, settling at the last exit from each band around 1
    (None if outside at the last sample), crossings interpolated between samples. How this differs
    from ``control.step_info``: docs/metrics.md.

    Parameters
    ----------
    t : array_like, shape (L,)
        Sample times [s], strictly increasing, not necessarily uniform.
    y : array_like, shape (L,)
        The response.
    y_initial : float, optional
        Value before the step; default: ``y`` at ``t_step`` (interpolated).
    y_final : float, optional
        Value the response should settle to; default: the last sample, inside every band by
        construction: pass the commanded value to detect a response that did not settle.
    t_step : float, optional
        Time of the step, ``t[0] <= t_step < t[-1]``; default ``t[0]``. Times are from it.
    rise : (float, float)
        Rise-time levels as fractions of the step (10 % and 90 %).
    settle_bands : (float, float)
        Settling bands as fractions of ``|step|`` (2 % and 5 %).

    Returns
    -------
    StepInfo
        Times [s] from ``t_step``, percentages of the step, peak in the unit of ``y``.

    Examples
    --------
    >>> t = np.linspace(0.0, 2.0, 5)
    >>> info = step_info(t, [4.0, 3.0, 2.0, 1.8, 2.0])     # downward step from 4 to 2
    >>> round(info.rise_time, 9), round(info.overshoot_pct, 9), info.peak, info.peak_time
    (0.8, 10.0, 1.8, 1.5)
    >>> step_info(t, [1.0, 1.0, 1.0, 1.0, 1.0])
    Traceback (most recent call last):
        ...
    quadcruise.errors.InputError: step size y_final - y_initial is zero (y_initial = y_final = 1)
    """
    t = _check_time(t)
    y = np.asarray(y, dtype=float)
    if y.shape != t.shape:
        raise InputError(f"response y has shape {y.shape}, time vector has {t.shape}")
    t_step = _step_time(t, y, t_step, "response y")
    levels = tuple(float(v) for v in rise)
    if len(levels) != 2 or not 0.0 <= levels[0] < levels[1] <= 1.0:
        raise InputError(f"rise levels must satisfy 0 <= low < high <= 1, got {rise}")
    lo, hi = levels
    bands = tuple(float(b) for b in settle_bands)
    if len(bands) != 2 or not all(0.0 < b < 1.0 for b in bands):
        raise InputError(f"settle_bands must be two fractions in (0, 1), got {settle_bands}")

    after = t > t_step  # the record from the step on
    ts = np.concatenate(([t_step], t[after]))
    ys = np.concatenate(([np.interp(t_step, t, y)], y[after]))
    y0 = float(ys[0]) if y_initial is None else float(y_initial)
    y1 = float(y[-1]) if y_final is None else float(y_final)
    if not (np.isfinite(y0) and np.isfinite(y1)):
        raise InputError(f"y_initial and y_final must be finite, got {y0}, {y1}")
    step = y1 - y0
    if abs(step) <= 16 * np.finfo(float).eps * max(abs(y0), abs(y1)) or step == 0.0:
        raise InputError(f"step size y_final - y_initial is zero (y_initial = y_final = {y0:g})")
    z = (ys - y0) / step

    t_lo, t_hi = _first_crossing(ts, z, lo), _first_crossing(ts, z, hi)
    settle = [_settling_time(ts, z, b) for b in bands]
    k_peak = int(np.argmax(z))
    return StepInfo(
        rise_time=None if t_hi is None else t_hi - t_lo,
        settling_time=settle[0],
        settling_time_5pct=settle[1],
        overshoot_pct=max(0.0, 100.0 * (float(z.max()) - 1.0)),
        undershoot_pct=max(0.0, -100.0 * float(z.min())),
        peak=float(ys[k_peak]),
        peak_time=float(ts[k_peak] - t_step),
        y_initial=y0,
        y_final=y1,
        settled=settle[0] is not None,
    )


def step_info_batch(t, y, *, y_initial=None, y_final=None, **kw) -> dict[str, np.ndarray]:
    """:func:`step_info` for each row of ``y``.

    Parameters
    ----------
    t : array_like, shape (L,)
        Sample times [s], strictly increasing.
    y : array_like, shape (N, L)
        One response per row.
    y_initial, y_final : float or array_like of shape (N,), optional
        As for :func:`step_info`, one for all rows or one per row.
    **kw
        Other keywords of :func:`step_info` (``t_step``, ``rise``, ``settle_bands``).

    Returns
    -------
    dict of ndarray, shape (N,)
        The fields of :class:`StepInfo`, one array each; a None (did not settle, never
        rose) becomes NaN, and ``settled`` is bool.

    Examples
    --------
    >>> t = np.linspace(0.0, 1.0, 3)
    >>> out = step_info_batch(t, [[0.0, 0.5, 1.0], [0.0, 0.2, 0.4]], y_final=1.0)
    >>> out["settling_time"], out["settled"]
    (array([0.98,  nan]), array([ True, False]))
    """
    y = np.asarray(y, dtype=float)
    if y.ndim != 2:
        raise InputError(f"batch response y must have shape (N, L), got {y.shape}")
    n = y.shape[0]
    y0 = [None] * n if y_initial is None else np.broadcast_to(np.asarray(y_initial, float), (n,))
    y1 = [None] * n if y_final is None else np.broadcast_to(np.asarray(y_final, float), (n,))
    rows = [step_info(t, y[i], y_initial=y0[i], y_final=y1[i], **kw).to_dict() for i in range(n)]
    out = {}
    for f in dataclasses.fields(StepInfo):
        vals = [r[f.name] for r in rows]
        out[f.name] = (
            np.array(vals, dtype=bool)
            if f.name == "settled"
            else np.array([np.nan if v is None else v for v in vals], dtype=float)
        )
    return out


def transient_info(t, actual, reference, *, t_step=None, rise=(0.1, 0.9), settle_bands=(0.02, 0.05)) -> StepInfo:
    """Step metrics of a tracking transient in which the reference itself moves.

    :func:`step_info` of the progress ``y = 1 - e(t) / e(t_step)``, ``e = reference - actual``, with
    ``y_initial=0, y_final=1``: for a constant reference, the ordinary step response. Over several
    axes ``e`` is the error's Euclidean norm, and the overshoot is then always 0.

    Parameters
    ----------
    t : array_like, shape (L,)
        Sample times [s], strictly increasing.
    actual, reference : array_like, shape (L,) or (L, n_axes)
        The response and what it tracks (one unit), broadcast against each other.
    t_step : float, optional
        Start of the transient [s]; default ``t[0]``. The error there must not be ~0.
    rise : (float, float)
        Rise-time levels as fractions of the initial error (10 % and 90 %).
    settle_bands : (float, float)
        Settling bands as fractions of the initial error (2 % and 5 %).

    Returns
    -------
    StepInfo
        Of the progress ``y``: times [s] from ``t_step``, percentages of the initial error.

    Examples
    --------
    >>> t = np.linspace(0.0, 10.0, 10001)
    >>> ref = np.c_[2.0 * np.cos(t), 2.0 * np.sin(t)]        # circle, starts 2 m away
    >>> act = ref * (1.0 - np.exp(-t))[:, None]                # error 2 exp(-t) m
    >>> round(transient_info(t, act, ref).settling_time, 4)    # ln 50
    3.912
    """
    t = _check_time(t)
    e = _difference(reference, actual)
    if e.ndim == 2:
        e = np.linalg.norm(e, axis=1)
    elif e.ndim != 1:
        raise InputError(f"actual and reference must be (L,) or (L, n_axes), got {e.shape}")
    if e.shape != t.shape:
        raise InputError(f"error signal has {e.shape[0]} samples, time vector has {t.size}")
    t_step = _step_time(t, e, t_step, "actual or reference")
    e0 = float(np.interp(t_step, t, e))
    scale = max(np.abs(actual).max(), np.abs(reference).max())
    if e0 == 0.0 or abs(e0) <= 1e-9 * scale:
        raise InputError(f"tracking error at t = {t_step:g} s is ~0: no transient to measure")
    return step_info(t, 1.0 - e / e0, y_initial=0.0, y_final=1.0, t_step=t_step, rise=rise, settle_bands=settle_bands)


def _trapezoid(t: np.ndarray, f: np.ndarray) -> np.ndarray:
    """Integral of f over t along the last axis (trapezoid rule), vectorised."""
    return np.sum(0.5 * (f[..., 1:] + f[..., :-1]) * np.diff(t), axis=-1)


def _difference(a, b) -> np.ndarray:
    """a - b as float arrays; shapes that do not broadcast are an InputError."""
    a, b = np.asarray(a, dtype=float), np.asarray(b, dtype=float)
    try:
        return a - b
    except ValueError:
        raise InputError(f"shapes {a.shape} and {b.shape} do not match") from None


def _time_major(name: str, a, n_t: int) -> np.ndarray:
    """(L,) -> (L, 1); (..., L, n) kept; checks the time axis (second-last) has n_t samples.

    A scalar is kept as it is (a constant, broadcast against the other operand)."""
    a = np.asarray(a, dtype=float)
    a = a[:, None] if a.ndim == 1 else a
    if a.ndim == 1 or (a.ndim >= 2 and a.shape[-2] != n_t):
        raise InputError(f"{name} must be (L,) or (..., L, n_axes) with L = {n_t}, got {a.shape}")
    if not np.all(np.isfinite(a)):
        raise InputError(f"{name} contains NaN or inf")
    return a


def tracking_errors(t, actual, reference, *, t_from=None) -> dict[str, np.ndarray]:
    """RMS and maximum tracking error over time, trapezoid-weighted in time.

    The error at each time is the Euclidean norm over the axes.

    Parameters
    ----------
    t : array_like, shape (L,)
        Sample times [s], strictly increasing, shared by every row.
    actual, reference : array_like, shape (L,) or (..., L, n_axes)
        The response and what it tracks [m, or any unit, the same for both], with time
        on the second-last axis, broadcast against each other (e.g. (N, L, 3) positions
        of N vehicles and one (L, 3) reference; a scalar reference is a constant).
    t_from : float, optional
        Start of the window [s], to skip the transient: the window is ``[t_from, t[-1]]``
        with the error interpolated at ``t_from``; default ``t[0]``.

    Returns
    -------
    dict of ndarray
        ``rmse`` = sqrt(integral |e|^2 dt / duration) and ``max_error``, of shape (...),
        and ``rmse_axes`` (per axis) of shape (..., n_axes), in the unit of the inputs.

    Examples
    --------
    >>> t = np.array([0.0, 1.0, 3.0])                 # non-uniform grid
    >>> out = tracking_errors(t, np.c_[[1.0, 1.0, 1.0], [0.0, 0.0, 0.0]], np.zeros((3, 2)))
    >>> float(out["rmse"]), float(out["max_error"]), out["rmse_axes"]
    (1.0, 1.0, array([1., 0.]))
    """
    t = _check_time(t)
    d = _difference(_time_major("actual", actual, t.size), _time_major("reference", reference, t.size))
    d = np.moveaxis(d, -2, -1)  # (..., n_axes, L)
    if t_from is not None:
        if not t[0] <= t_from < t[-1]:
            raise InputError(f"t_from = {t_from:g} s is outside [{t[0]:g}, {t[-1]:g}) s")
        k = int(np.searchsorted(t, t_from, side="right"))  # t[k - 1] <= t_from < t[k]
        w = (t_from - t[k - 1]) / (t[k] - t[k - 1])
        d_from = d[..., k - 1] + w * (d[..., k] - d[..., k - 1])
        d = np.concatenate((d_from[..., None], d[..., k:]), axis=-1)
        t = np.concatenate(([t_from], t[k:]))
    duration = t[-1] - t[0]
    ms_axes = _trapezoid(t, d**2) / duration
    return {
        "rmse": np.sqrt(ms_axes.sum(axis=-1)),
        "max_error": np.sqrt((d**2).sum(axis=-2)).max(axis=-1),
        "rmse_axes": np.sqrt(ms_axes),
    }


def control_effort(t, u) -> dict[str, np.ndarray]:
    """Integral over time of the sum of squared inputs (trapezoid) and its time mean.

    Parameters
    ----------
    t : array_like, shape (L,)
        Sample times [s], strictly increasing.
    u : array_like, shape (L,) or (..., L, m)
        The inputs (e.g. rotor duties [-]), with time on the second-last axis; subtract a
        trim (e.g. the hover duty) first to measure effort about it.

    Returns
    -------
    dict of ndarray, shape (...)
        ``integral`` [unit^2 s] and ``mean`` (the integral over the duration) [unit^2].

    Examples
    --------
    >>> out = control_effort([0.0, 1.0, 2.0], np.c_[[1.0, 1.0, 1.0], [0.0, 1.0, 0.0]])
    >>> float(out["integral"]), float(out["mean"])
    (3.0, 1.5)
    """
    t = _check_time(t)
    u = np.moveaxis(_time_major("u", u, t.size), -2, -1)
    integral = _trapezoid(t, (u**2).sum(axis=-2))
    return {"integral": integral, "mean": integral / (t[-1] - t[0])}


def time_in_saturation(t, flags) -> dict[str, np.ndarray]:
    """Seconds and fraction of the record during which ``flags`` is set (nonzero).

    Sample-and-hold: sample k holds from t[k] to t[k + 1], so the last sample adds no
    time.

    Parameters
    ----------
    t : array_like, shape (L,)
        Sample times [s], strictly increasing.
    flags : array_like, shape (L,) or (..., L)
        Saturation flags (any nonzero value is set), time on the last axis (e.g. (N, L)
        for a batch).

    Returns
    -------
    dict of ndarray, shape (...)
        ``seconds`` [s] and ``fraction`` (of ``t[-1] - t[0]``) [-].

    Examples
    --------
    >>> out = time_in_saturation([0.0, 1.0, 3.0, 4.0], [0, 1, 0, 1])
    >>> float(out["seconds"]), float(out["fraction"])
    (2.0, 0.5)
    """
    t = _check_time(t)
    f = np.asarray(flags)
    if f.ndim < 1 or f.shape[-1] != t.size:
        raise InputError(f"flags must have time on the last axis with L = {t.size}, got {f.shape}")
    if f.dtype.kind == "f" and not np.all(np.isfinite(f)):
        raise InputError("flags contain NaN or inf")
    seconds = ((f[..., :-1] != 0) * np.diff(t)).sum(axis=-1)
    return {"seconds": seconds, "fraction": seconds / (t[-1] - t[0])}


# --- a whole flight --------------------------------------------------------------------
_AXIS_NAMES = ("x", "y", "z")
FAILED_FLIGHT_METRICS = (
    "rise_time_s",
    "settling_time_s",
    "overshoot_pct",
    "peak_time_s",
    "steady_rmse_m",
    "steady_max_error_m",
)
"""The metrics (besides the second settling column) that are NaN for a flight that did not finish:
a vehicle that lost its track has no transient or steady state to measure."""
TRACKING_AXIS_NAME = "xyz"
"""The ``axis`` a moving reference's transient is measured on: the size of the 3-D error."""
EFFORT_DEFINITION = "integral of sum_i (u_i - u_hover)^2 dt over the four rotor duties, u_hover = m g / (4 K) [s]"
"""What the ``effort`` column measures, as the tables record it."""


def settling_column(band: float) -> str:
    """The name of the column of the settling time into ``band``, as a metrics table names its
    second band.

    Parameters
    ----------
    band : float
        The band, a fraction of the step (0.05 for 5 %).

    Returns
    -------
    str
        ``settling_time_<percent>pct_s``, the percent written with up to 6 significant digits
        and a ``p`` for the decimal point.

    Examples
    --------
    >>> settling_column(0.05), settling_column(0.03), settling_column(0.025)
    ('settling_time_5pct_s', 'settling_time_3pct_s', 'settling_time_2p5pct_s')
    """
    return f"settling_time_{format(100.0 * float(band), '.6g').replace('.', 'p')}pct_s"


RISE_CONVENTIONS = {"10-90": (0.1, 0.9), "0-100": (0.0, 1.0)}
"""The rise-time levels a name gives (``rise="0-100"``)."""


def metric_conventions(rise=(0.1, 0.9), settle_bands=(0.02, 0.05)) -> dict:
    """The conventions of a metrics table, checked: what its ``attrs["conventions"]`` records.

    Parameters
    ----------
    rise : (float, float) or {"10-90", "0-100"}
        Rise-time levels as fractions of the step: ``(0.1, 0.9)`` for 10-90 %, ``(0.0, 1.0)``
        for 0-100 %, or any ``0 <= low < high <= 1``; or one of :data:`RISE_CONVENTIONS`.
    settle_bands : float or sequence of one or two floats
        Settling bands as fractions of the step, each in (0, 1): the first is the
        ``settling_time_s`` column, the second (if only one is given: :data:`STEADY_BAND`,
        or 2 % when the first is that 5 %) the column :func:`settling_column` names; two
        equal bands are refused (they would print two identical columns).

    Returns
    -------
    dict
        ``rise`` and ``settle_bands`` (lists of two floats), ``settling_columns`` (column
        name -> band), ``steady_band`` (:data:`STEADY_BAND`) and ``effort``
        (:data:`EFFORT_DEFINITION`): plain values, ready for JSON.

    Raises
    ------
    InputError
        Levels or bands out of range, or not numbers.

    Examples
    --------
    >>> metric_conventions(rise="0-100", settle_bands=0.03)["settling_columns"]
    {'settling_time_s': 0.03, 'settling_time_5pct_s': 0.05}
    """
    if isinstance(rise, str):
        if rise not in RISE_CONVENTIONS:
            raise InputError(f"rise {rise!r}: choose one of {', '.join(RISE_CONVENTIONS)} or give two levels")
        rise = RISE_CONVENTIONS[rise]
    try:
        levels = tuple(float(v) for v in rise)
        bands = tuple(float(b) for b in np.atleast_1d(np.asarray(settle_bands, dtype=float)))
    except (TypeError, ValueError):
        raise InputError(f"rise levels and settle_bands must be numbers, got {rise!r}, {settle_bands!r}") from None
    if len(bands) == 1:  # the second column: 5 %, or 2 % beside a first 5 %
        bands = bands + ((0.02,) if bands[0] == STEADY_BAND else (STEADY_BAND,))
    if len(bands) == 2 and bands[0] == bands[1]:
        raise InputError(f"settle_bands: the two bands are the same ({bands[0]:g}): give two different bands, or one")
    if len(levels) != 2 or not 0.0 <= levels[0] < levels[1] <= 1.0:
        raise InputError(f"rise levels must satisfy 0 <= low < high <= 1, got {rise}")
    if len(bands) != 2 or not all(0.0 < b < 1.0 for b in bands):
        raise InputError(f"settle_bands must be one or two fractions in (0, 1), got {settle_bands}")
    return {
        "rise": list(levels),
        "settle_bands": list(bands),
        "settling_columns": {"settling_time_s": bands[0], settling_column(bands[1]): bands[1]},
        "steady_band": STEADY_BAND,
        "effort": EFFORT_DEFINITION,
    }


def hover_duties(meta, n: int) -> np.ndarray | None:
    """Each vehicle's hover duty m g / (4 K), from the vehicle a result records.

    Parameters
    ----------
    meta : dict
        A result's ``meta``: its ``vehicle`` entry (the flown vehicle's ``to_dict()``: ``m``
        [kg], ``g`` [m/s^2] and ``K`` [N], each a number or one per vehicle) is read; for a
        rotor-plant vehicle its ``paper_equivalent`` (the "+" vehicle whose duties were flown).
    n : int
        Number of vehicles.

    Returns
    -------
    ndarray, shape (n,), or None
        The duty per rotor [-] that holds each vehicle in hover; None if ``meta`` records no
        vehicle (a result built by :func:`quadcruise.simulate` without one).

    Examples
    --------
    >>> hover_duties({"vehicle": {"m": [3.0, 6.0], "g": 10.0, "K": 100.0}}, 2)
    array([0.075, 0.15 ])
    """
    vehicle = (meta.get("paper_equivalent") or meta.get("vehicle")) if isinstance(meta, dict) else None
    if not isinstance(vehicle, dict) or not all(k in vehicle for k in ("m", "g", "K")):
        return None
    try:
        m, g, k = (np.broadcast_to(np.asarray(vehicle[key], dtype=float), (n,)) for key in ("m", "g", "K"))
    except ValueError:
        raise InputError(f"the recorded vehicle does not describe {n} vehicle(s)") from None
    return m * g / (4.0 * k)


def flight_metrics(
    result,
    *,
    transient_axis: str | None = None,
    transient_until: float | None = None,
    rise=(0.1, 0.9),
    settle_bands=(0.02, 0.05),
):
    """Per-vehicle metrics of a :class:`~quadcruise.sim.result.SimResult`, as a DataFrame.

    The transient is measured on ``transient_axis`` if given; else, for a moving reference, on the
    size of the 3-D error against its own steady level (``axis`` ``xyz``); for a step mission, on
    its stepped axis as a step response; else on the axis of the largest initial error if it
    reaches :data:`TRANSIENT_MIN_ERROR`; otherwise not at all. The steady metrics cover the steady
    window of that definition (the whole flight without a transient). NaN: a settling time that
    does not exist, the steady metrics of a transient that never settles, every metric of a
    vehicle that stopped early, and the transient and steady metrics of one that did not finish
    (:data:`FAILED_FLIGHT_METRICS`). Each definition and its reason: docs/metrics.md.

    Parameters
    ----------
    result : SimResult
        The flight (duck-typed: ``t``, ``states``, ``references``, ``commands``, ``status``,
        ``meta`` and the saturation times; ``meta["vehicle"]`` gives the hover duty of the
        effort, :func:`hover_duties`).
    transient_axis : {"x", "y", "z"}, optional
        The axis whose transient is measured, instead of the one chosen as above.
    transient_until : float, optional
        End [s] of the window in which the transient is measured.
    rise : (float, float) or str
        Rise-time levels as fractions of the step: ``(0.1, 0.9)`` (default), ``(0.0, 1.0)``
        (also ``"0-100"``), or any ``0 <= low < high <= 1``.
    settle_bands : (float, float) or float
        Settling bands as fractions of the step: ``settling_time_s`` and the column
        :func:`settling_column` names (5 % if only one is given).

    Returns
    -------
    pandas.DataFrame
        One row per vehicle: ``vehicle``, ``status``, ``rmse_m``, ``max_error_m`` (3-D position
        error over the flight [m]), ``steady_rmse_m``, ``steady_max_error_m``, ``axis``,
        ``rise_time_s``, ``settling_time_s``, ``settling_time_<band>pct_s``, ``overshoot_pct``,
        ``peak_time_s``, ``effort`` (:data:`EFFORT_DEFINITION` [s]; NaN without a vehicle),
        ``duty_clipped_s``, ``controller_limited_s`` [s]; ``attrs["conventions"]`` records the
        conventions (:func:`metric_conventions`).

    Examples
    --------
    >>> import quadcruise as qc
    >>> res = qc.fly("step", duration=2.0)
    >>> flight_metrics(res)[["vehicle", "status", "axis"]]
       vehicle    status axis
    0        0  finished    x
    >>> flight_metrics(res, settle_bands=(0.02, 0.03)).attrs["conventions"]["settle_bands"]
    [0.02, 0.03]
    """
    import pandas as pd

    from quadcruise.layout import CMD_U1, REF_X, X

    conventions = metric_conventions(rise, settle_bands)
    levels, bands = tuple(conventions["rise"]), tuple(conventions["settle_bands"])
    second = settling_column(bands[1])
    t = result.t
    mission = result.meta.get("mission") if isinstance(result.meta.get("mission"), dict) else {}
    hover = hover_duties(result.meta, result.n)
    rows = []
    for i in range(result.n):
        row = {
            "vehicle": i,
            "status": result.status_text(i),
            "rmse_m": np.nan,
            "max_error_m": np.nan,
            "steady_rmse_m": np.nan,
            "steady_max_error_m": np.nan,
            "axis": None,
            "rise_time_s": np.nan,
            "settling_time_s": np.nan,
            second: np.nan,
            "overshoot_pct": np.nan,
            "peak_time_s": np.nan,
            "effort": np.nan,
            "duty_clipped_s": float(result.duty_clipped_s[i]),
            "controller_limited_s": float(result.controller_limited_s[i]),
        }
        rows.append(row)
        if result.stopped[i]:  # the engine stopped it: its later rows are NaN
            continue
        pos, ref = result.states[i, :, X : X + 3], result.references[i, :, REF_X : REF_X + 3]
        if np.all(np.isfinite(ref)):
            err = tracking_errors(t, pos, ref)
            row["rmse_m"], row["max_error_m"] = float(err["rmse"]), float(err["max_error"])
            keep = slice(None) if transient_until is None else t <= transient_until
            transient = _flight_transient(t[keep], pos[keep], ref[keep], mission, transient_axis, levels, bands)
            steady = (row["rmse_m"], row["max_error_m"])  # no transient: the whole flight
            if transient is not None:
                info, axis, t_step, settled = transient
                row.update(
                    axis=axis,
                    rise_time_s=_nan(info.rise_time),
                    settling_time_s=_nan(info.settling_time),
                    overshoot_pct=info.overshoot_pct,
                    peak_time_s=info.peak_time,
                )
                row[second] = _nan(info.settling_time_5pct)
                steady = (np.nan, np.nan) if settled is None else _steady_errors(t, pos, ref, t_step + settled)
            row["steady_rmse_m"], row["steady_max_error_m"] = steady
            if not result.ok[i]:  # lost or off track: no transient or steady state to speak of
                row.update({key: np.nan for key in FAILED_FLIGHT_METRICS + (second,)})
        if hover is not None:
            duties = result.commands[i, :, CMD_U1 : CMD_U1 + 4]
            row["effort"] = float(control_effort(t, duties - hover[i])["integral"])
    frame = pd.DataFrame(rows)
    frame.attrs["conventions"] = conventions
    return frame


def _steady_errors(t: np.ndarray, pos: np.ndarray, ref: np.ndarray, t_from: float) -> tuple[float, float]:
    """RMS and maximum 3-D error from ``t_from`` on; the error at the end if that is the last sample."""
    if t_from >= t[-1]:
        last = float(np.linalg.norm(pos[-1] - ref[-1]))
        return last, last
    err = tracking_errors(t, pos, ref, t_from=max(t_from, float(t[0])))
    return float(err["rmse"]), float(err["max_error"])


def _flight_transient(t, pos, ref, mission: dict, axis: str | None, rise: tuple, bands: tuple):
    """(StepInfo, axis name, start time [s], start of the steady window from the start time [s]
    or None if it did not settle), or None where no transient is measured."""
    if axis is None and moving_reference(t, ref[None], mission):
        got = tracking_transient_batch(t, np.linalg.norm(pos - ref, axis=1)[None], list(bands) + [STEADY_BAND], rise)
        if not got["measured"][0]:
            return None
        settle = [None if np.isnan(s[0]) else float(s[0]) for s in got["settling_s"]]
        info = StepInfo(
            rise_time=None if np.isnan(got["rise_time_s"][0]) else float(got["rise_time_s"][0]),
            settling_time=settle[0],
            settling_time_5pct=settle[1],
            overshoot_pct=float(got["overshoot_pct"][0]),
            undershoot_pct=np.nan,
            peak=np.nan,
            peak_time=float(got["peak_time_s"][0]),
            y_initial=0.0,
            y_final=1.0,
            settled=settle[0] is not None,
        )
        steady_from = float(got["steady_from"][0])
        return info, TRACKING_AXIS_NAME, float(t[0]), None if np.isnan(steady_from) else steady_from - float(t[0])
    if axis is None and mission.get("kind") == "step" and mission.get("axis") in _AXIS_NAMES:
        j = _AXIS_NAMES.index(mission["axis"])
        t_step = float(mission["time"])
        if not t[0] <= t_step < t[-1]:
            return None
        before = float(mission[mission["axis"]])  # the hover point the step leaves

        def measure(levels, settle):
            return step_info(
                t,
                pos[:, j],
                y_initial=before,
                y_final=before + float(mission["size"]),
                t_step=t_step,
                rise=levels,
                settle_bands=settle,
            )

        name = mission["axis"]
    else:
        e0 = np.abs(ref[0] - pos[0])
        j = _AXIS_NAMES.index(axis) if axis is not None else int(np.argmax(e0))
        if e0[j] < TRANSIENT_MIN_ERROR:
            return None
        t_step = float(t[0])

        def measure(levels, settle):
            return transient_info(t, pos[:, j], ref[:, j], rise=levels, settle_bands=settle)

        name = _AXIS_NAMES[j]
    info = measure(rise, bands)
    if bands[1] == STEADY_BAND:
        steady = info.settling_time_5pct
    elif bands[0] == STEADY_BAND:
        steady = info.settling_time
    else:
        steady = measure(rise, (STEADY_BAND, STEADY_BAND)).settling_time
    return info, name, t_step, steady


def _nan(value):
    return np.nan if value is None else float(value)
