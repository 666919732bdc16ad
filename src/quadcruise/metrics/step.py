"""Step and transient characteristics of one response: rise time, settling times, overshoot,
undershoot and peak (:func:`step_info`), the same for each row of a batch, and for a tracking
transient whose reference itself moves (:func:`transient_info`).

Times in seconds. Crossings are interpolated linearly between samples on a time grid that must
be strictly increasing but need not be uniform. The same for every vehicle of a batch at once,
vectorised: :mod:`quadcruise.metrics.batch`. Each definition and its reason: docs/metrics.md.

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
from quadcruise.metrics.signals import check_time, difference

__all__ = ["StepInfo", "step_info", "step_info_batch", "transient_info"]


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
    t = check_time(t)
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
    t = check_time(t)
    e = difference(reference, actual)
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
