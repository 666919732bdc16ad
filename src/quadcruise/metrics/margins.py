"""Stability margins of a discrete loop transfer, both gain margins in dB, and the floors below
which a margin is called short."""

from __future__ import annotations

import math
import warnings

import numpy as np

__all__ = ["MIN_GAIN_MARGIN_DB", "MIN_PHASE_MARGIN_DEG", "db", "low_margins", "margins"]

MIN_PHASE_MARGIN_DEG = 30.0
"""A phase margin below this [deg] is flagged: the usual floor for a loop that must tolerate
unmodelled lag (delay, a slower motor) without ringing."""
MIN_GAIN_MARGIN_DB = 6.0
"""A gain margin within this [dB] of 0 dB, up or down, is flagged: a loop gain error of a
factor 2 (thrust coefficient, inertia, battery sag) must not destabilise it."""


def db(factor: float) -> float:
    """A gain factor in decibels.

    Parameters
    ----------
    factor : float
        The factor [-], >= 0.

    Returns
    -------
    float
        20 log10(factor) [dB]; -inf for 0.
    """
    return -math.inf if factor == 0.0 else 20.0 * math.log10(factor)


def _omega(dt, n=2000):
    return np.logspace(-3, math.log10(0.999 * math.pi / dt), n)


def margins(L) -> dict:
    """Margins of a discrete loop transfer by ``control.stability_margins``.

    They are read from its frequency response up to the Nyquist frequency (the polynomial
    method is ill-conditioned for a 19-state loop with poles crowded near z = 1).

    Parameters
    ----------
    L : control.StateSpace
        The loop transfer, one input and one output, discrete (``L.dt`` > 0), signed for
        negative feedback (the closed loop is L / (1 + L)).

    Returns
    -------
    dict
        ``phase_margin`` [deg] at ``gain_crossover`` [rad/s]; ``gain_margin`` [-] (the one
        python-control picks, nearest 1) at ``phase_crossover`` [rad/s]; ``gain_increase``
        [-] (the smallest destabilising factor > 1, inf if none) at
        ``gain_increase_frequency`` [rad/s] and ``gain_decrease`` [-] (the largest < 1, 0 if
        none) at ``gain_decrease_frequency`` [rad/s], and both in decibels,
        ``gain_increase_db`` (> 0, inf if none) and ``gain_decrease_db`` (< 0, -inf if none);
        ``stability_margin`` (least distance of L to -1) and its frequency
        ``stability_margin_frequency`` [rad/s]; ``open_loop_unstable_poles`` (of L; when
        not 0 the margins alone do not tell stability). A loop with a ``gain_decrease`` is
        conditionally stable: it is stable at its own gain and goes unstable if the gain
        falls by that factor (a PID's integral on a double integrator makes the phase
        cross -180 deg below the gain crossover), as well as if it rises by
        ``gain_increase``.
    """
    import control

    w = _omega(L.dt)
    r = control.frequency_response(L, w).complex.ravel()
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        gms, pms, sms, wpcs, wgcs, wsms = (
            np.atleast_1d(a)
            for a in control.stability_margins((np.abs(r), np.degrees(np.unwrap(np.angle(r))), w), returnall=True)
        )
    with np.errstate(divide="ignore"):
        g = int(np.argmin(np.abs(np.log(gms)))) if gms.size and not np.isinf(gms).all() else None
    p, s = (int(np.argmin(np.abs(pms))) if pms.size else None), (int(np.argmin(sms)) if sms.size else None)
    up, down = np.flatnonzero(gms > 1), np.flatnonzero(gms < 1)
    up = up[np.argmin(gms[up])] if up.size else None
    down = down[np.argmax(gms[down])] if down.size else None
    increase, decrease = (math.inf if up is None else float(gms[up])), (0.0 if down is None else float(gms[down]))
    return {
        "phase_margin": math.inf if p is None else float(pms[p]),
        "gain_crossover": math.nan if p is None else float(wgcs[p]),
        "gain_margin": math.inf if g is None else float(gms[g]),
        "phase_crossover": math.nan if g is None else float(wpcs[g]),
        "gain_increase": increase,
        "gain_increase_frequency": math.nan if up is None else float(wpcs[up]),
        "gain_increase_db": db(increase),
        "gain_decrease": decrease,
        "gain_decrease_frequency": math.nan if down is None else float(wpcs[down]),
        "gain_decrease_db": db(decrease),
        "stability_margin": math.nan if s is None else float(sms[s]),
        "stability_margin_frequency": math.nan if s is None else float(wsms[s]),
        "open_loop_unstable_poles": int(np.sum(np.abs(np.linalg.eigvals(L.A)) > 1.0 + 1e-9)),
    }


def low_margins(m: dict) -> list[str]:
    """What is short in one loop's margins (:func:`margins`), in words.

    Flagged: a phase margin below :data:`MIN_PHASE_MARGIN_DEG`, a gain margin up or down
    within :data:`MIN_GAIN_MARGIN_DB` of 0 dB.

    Parameters
    ----------
    m : dict
        What :func:`margins` returns.

    Returns
    -------
    list of str
        One phrase per margin that is short (empty if none), e.g. ``"PM 18.1 deg < 30 deg"``.

    Examples
    --------
    >>> low_margins({"phase_margin": 18.1, "gain_increase_db": 38.2, "gain_decrease_db": -3.98})
    ['PM 18.1 deg < 30 deg', 'GM down -3.98 dB > -6 dB']
    """
    out = []
    if m["phase_margin"] < MIN_PHASE_MARGIN_DEG:
        out.append(f"PM {m['phase_margin']:.3g} deg < {MIN_PHASE_MARGIN_DEG:g} deg")
    if m["gain_increase_db"] < MIN_GAIN_MARGIN_DB:
        out.append(f"GM up {m['gain_increase_db']:+.3g} dB < {MIN_GAIN_MARGIN_DB:+g} dB")
    if m["gain_decrease_db"] > -MIN_GAIN_MARGIN_DB:
        out.append(f"GM down {m['gain_decrease_db']:+.3g} dB > {-MIN_GAIN_MARGIN_DB:+g} dB")
    return out
