"""Metrics of sampled signals over a flight: tracking error (RMS and maximum), control effort,
time in saturation.

Pure numpy. Every function reads signals on a time grid ``t`` that must be strictly increasing
but need not be uniform; integrals use the trapezoid rule, saturation is sample-and-hold.

Examples
--------
>>> import numpy as np
>>> t = np.linspace(0.0, 2.0, 201)
>>> float(tracking_errors(t, np.c_[t, t], np.zeros((201, 2)))["max_error"].round(9))   # |(2, 2)|
2.828427125
"""

from __future__ import annotations

import numpy as np

from quadcruise.errors import InputError

__all__ = ["tracking_errors", "control_effort", "time_in_saturation"]


def check_time(t) -> np.ndarray:
    """``t`` as a float array, checked: 1-D, at least 2 samples, finite, strictly increasing."""
    t = np.asarray(t, dtype=float)
    if t.ndim != 1 or t.size < 2:
        raise InputError(f"time vector must be 1-D with at least 2 samples, got shape {t.shape}")
    if not np.all(np.isfinite(t)):
        raise InputError("time vector contains NaN or inf")
    if not np.all(np.diff(t) > 0):
        raise InputError("time vector must be strictly increasing")
    return t


def _trapezoid(t: np.ndarray, f: np.ndarray) -> np.ndarray:
    """Integral of f over t along the last axis (trapezoid rule), vectorised."""
    return np.sum(0.5 * (f[..., 1:] + f[..., :-1]) * np.diff(t), axis=-1)


def difference(a, b) -> np.ndarray:
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
    t = check_time(t)
    d = difference(_time_major("actual", actual, t.size), _time_major("reference", reference, t.size))
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
    t = check_time(t)
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
    t = check_time(t)
    f = np.asarray(flags)
    if f.ndim < 1 or f.shape[-1] != t.size:
        raise InputError(f"flags must have time on the last axis with L = {t.size}, got {f.shape}")
    if f.dtype.kind == "f" and not np.all(np.isfinite(f)):
        raise InputError("flags contain NaN or inf")
    seconds = ((f[..., :-1] != 0) * np.diff(t)).sum(axis=-1)
    return {"seconds": seconds, "fraction": seconds / (t[-1] - t[0])}
