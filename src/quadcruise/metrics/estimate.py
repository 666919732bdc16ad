"""The estimation error of a flight on sensors and an estimator: how far what the controller saw
was from the truth, and how consistent the filter was (its NEES), per vehicle.

At each logged instant the estimate is the one the controller saw (held between IMU instants), the
truth the state flown. The attitude error is the angle of the rotation between the two attitudes,
``2 atan2(|v|, |w|)`` of ``q_est^* q_true``; the NEES is the filter's own, at its last IMU instant
(:mod:`quadcruise.estimation.onboard`).

Examples
--------
>>> import numpy as np
>>> from quadcruise import layout as L
>>> states = np.zeros((1, 2, L.STATE_SIZE)); obs = np.zeros((1, 2, L.OBSERVATION_SIZE))
>>> obs[0, :, L.O_QW] = 1.0; obs[0, :, L.O_X] = 0.3
>>> m = estimate_metrics(states, obs, 0)
>>> round(m["estimate_position_rmse_m"], 3), m["estimate_attitude_rmse_deg"]
(0.3, 0.0)
"""

from __future__ import annotations

import numpy as np

from quadcruise import layout as L

__all__ = ["ESTIMATE_METRICS", "estimate_metrics", "flew_an_estimator"]

ESTIMATE_METRICS = (
    "estimate_position_rmse_m",
    "estimate_attitude_rmse_deg",
    "nees_position",
    "nees_velocity",
    "nees_attitude",
)
"""The columns :func:`estimate_metrics` gives (declared in :mod:`quadcruise.metrics.declared`)."""


def flew_an_estimator(result) -> bool:
    """Whether a result's flight ran an estimator (an observation log with an estimate in it).

    Parameters
    ----------
    result : SimResult
        Duck-typed: ``observations`` (or none).

    Returns
    -------
    bool
    """
    obs = getattr(result, "observations", None)
    return obs is not None and bool(np.isfinite(obs[:, :, L.O_X]).any())


def _euler_quaternions(phi, theta, psi):
    a, b, c = 0.5 * phi, 0.5 * theta, 0.5 * psi
    ca, sa, cb, sb, cc, sc = np.cos(a), np.sin(a), np.cos(b), np.sin(b), np.cos(c), np.sin(c)
    return np.stack(
        [
            cc * cb * ca + sc * sb * sa,
            cc * cb * sa - sc * sb * ca,
            cc * sb * ca + sc * cb * sa,
            sc * cb * ca - cc * sb * sa,
        ],
        axis=-1,
    )


def estimate_metrics(states: np.ndarray, observations: np.ndarray, i: int) -> dict:
    """Vehicle i's estimation error over its logged instants (those flown: NaN rows are left out).

    Parameters
    ----------
    states : numpy.ndarray
        (N, L, STATE_SIZE) the truth, paper layout.
    observations : numpy.ndarray
        (N, L, OBSERVATION_SIZE) the observation log.
    i : int
        The vehicle.

    Returns
    -------
    dict
        :data:`ESTIMATE_METRICS`: position error RMS [m], attitude error RMS [deg], the mean NEES
        of position, velocity and attitude (3 for a consistent filter).
    """
    x, o = states[i], observations[i]
    flown = np.isfinite(x[:, L.X]) & np.isfinite(o[:, L.O_X])
    if not flown.any():
        return {name: np.nan for name in ESTIMATE_METRICS}
    x, o = x[flown], o[flown]
    dp = x[:, L.X : L.X + 3] - o[:, L.O_X : L.O_X + 3]
    qt = _euler_quaternions(x[:, L.PHI], x[:, L.THETA], x[:, L.PSI])
    qe = o[:, L.O_QW : L.O_QW + 4]
    w = np.abs(np.sum(qe * qt, axis=1))  # the scalar part of q_est^* q_true
    angle = 2.0 * np.arccos(np.clip(w / np.linalg.norm(qe, axis=1) / np.linalg.norm(qt, axis=1), -1.0, 1.0))
    nees = o[:, L.O_NEES : L.O_NEES + 3]
    return {
        "estimate_position_rmse_m": float(np.sqrt(np.mean(np.sum(dp**2, axis=1)))),
        "estimate_attitude_rmse_deg": float(np.degrees(np.sqrt(np.mean(angle**2)))),
        "nees_position": float(np.nanmean(nees[:, 0])),
        "nees_velocity": float(np.nanmean(nees[:, 1])),
        "nees_attitude": float(np.nanmean(nees[:, 2])),
    }
