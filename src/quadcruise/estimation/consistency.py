"""Consistency of a filter against the truth: normalised estimation error squared (NEES) per
block of the error state, and the chi-square bounds their averages over runs must lie in
(Bar-Shalom, Li and Kirubarajan, "Estimation with Applications to Tracking and Navigation",
2001, section 5.4).
"""

from __future__ import annotations

import numpy as np
from scipy.spatial.transform import Rotation
from scipy.stats import chi2

BLOCKS = {"position": slice(0, 3), "velocity": slice(3, 6), "attitude": slice(6, 9)}
"""The error state's blocks whose NEES is checked."""


def errors(x: np.ndarray, position: np.ndarray, velocity: np.ndarray, quaternion: np.ndarray) -> np.ndarray:
    """The true error state's first nine components, truth minus estimate.

    Parameters
    ----------
    x : numpy.ndarray
        (J, 16) estimates (p, v, q w first, ...).
    position, velocity : numpy.ndarray
        (J, 3) the truth, ENU.
    quaternion : numpy.ndarray
        (J, 4) the true attitude, w first.

    Returns
    -------
    numpy.ndarray
        (J, 9): dp [m], dv [m/s], dtheta [rad] with ``R_true = R_est Exp(dtheta)``.

    Examples
    --------
    >>> import numpy as np
    >>> x = np.r_[np.zeros(6), 1.0, np.zeros(9)][None]
    >>> errors(x, np.ones((1, 3)), np.zeros((1, 3)), np.array([[1.0, 0, 0, 0]]))[0, :3].tolist()
    [1.0, 1.0, 1.0]
    """
    est = Rotation.from_quat(x[:, [7, 8, 9, 6]])
    true = Rotation.from_quat(np.asarray(quaternion)[:, [1, 2, 3, 0]])
    dth = (est.inv() * true).as_rotvec()
    return np.column_stack([position - x[:, 0:3], velocity - x[:, 3:6], dth])


def nees(err: np.ndarray, cov: np.ndarray) -> dict:
    """Each block's NEES ``e^T P^-1 e`` per instant.

    Parameters
    ----------
    err : numpy.ndarray
        (J, 9) from :func:`errors`.
    cov : numpy.ndarray
        (J, 15, 15) the filter's covariances at the same instants.

    Returns
    -------
    dict
        Block name -> (J,) NEES (3 degrees of freedom each).

    Examples
    --------
    >>> import numpy as np
    >>> round(float(nees(np.ones((1, 9)), np.eye(15)[None] * 2.0)["velocity"][0]), 3)
    1.5
    """
    out = {}
    for name, s in BLOCKS.items():
        e, P = err[:, s], cov[:, s, s]
        out[name] = np.einsum("ji,ji->j", e, np.linalg.solve(P, e[..., None])[..., 0])
    return out


def average_bounds(dof: int, runs: int, probability: float = 0.95) -> tuple[float, float]:
    """The two-sided chi-square interval of an average of ``runs`` independent NEES (or NIS)
    values of ``dof`` degrees of freedom: ``chi2.ppf((1 -+ P) / 2, runs dof) / runs``.

    Parameters
    ----------
    dof : int
        Degrees of freedom of one value.
    runs : int
        How many are averaged.
    probability : float
        The interval's probability.

    Returns
    -------
    tuple of float
        (lower, upper).

    Examples
    --------
    >>> [round(b, 2) for b in average_bounds(3, 50)]
    [2.36, 3.72]
    """
    a = (1.0 - probability) / 2.0
    return float(chi2.ppf(a, dof * runs) / runs), float(chi2.ppf(1.0 - a, dof * runs) / runs)
