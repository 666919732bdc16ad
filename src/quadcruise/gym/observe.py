"""The compiled per-step work of the environments: references, observations, rewards and
the tracking check of N vehicles in one call (no Python loop over vehicles).

The observation (:data:`OBS_NAMES`, float32: errors, attitude and rates in the body frame, the
rotor thrusts about hover) and the reward ``exp(-|p - p_ref| / 0.5 m - 0.05 |omega| / (1 rad/s))``
are tabled, with their reasons, in docs/gym.md.
"""

from __future__ import annotations

import math

import numpy as np
from numba import njit

from quadcruise.control.so3 import rotation_zyx
from quadcruise.layout import (
    F1,
    O_P,
    O_PHI,
    O_VX,
    O_X,
    P_G,
    P_M,
    PHI,
    PSI,
    REF_AX,
    REF_PSI,
    REF_SIZE,
    REF_VX,
    REF_X,
    THETA,
    VX,
    P,
    X,
)

OBS_NAMES = (
    "ex_b",
    "ey_b",
    "ez_b",
    "evx_b",
    "evy_b",
    "evz_b",
    "up_x",
    "up_y",
    "up_z",
    "sin_epsi",
    "cos_epsi",
    "p",
    "q",
    "r",
    "ax_ref_b",
    "ay_ref_b",
    "az_ref_b",
    "f1_rel",
    "f2_rel",
    "f3_rel",
    "f4_rel",
)
OBS_SIZE = len(OBS_NAMES)
REWARD_DISTANCE = 0.5
"""[m]: the reward falls by 1/e per this distance from the reference."""
REWARD_RATE = 0.05
"""[1/(rad/s)]: and by exp(-0.05) per rad/s of body rate."""


@njit(cache=True)
def references(mission, t, mp, ref):
    """The mission's reference of every vehicle at its own time."""
    for i in range(t.shape[0]):
        mission(t[i], mp[i], ref[i])


@njit(cache=True)
def observe(x, ref, vp, bound, obs, reward, lost):
    """Observations, rewards and the tracking check of N vehicles (the module docstring's layout)."""
    for i in range(x.shape[0]):
        Rm = rotation_zyx(x[i, PHI], x[i, THETA], x[i, PSI])
        ex, ey, ez = x[i, X] - ref[i, REF_X], x[i, X + 1] - ref[i, REF_X + 1], x[i, X + 2] - ref[i, REF_X + 2]
        ux, uy, uz = (x[i, VX] - ref[i, REF_VX], x[i, VX + 1] - ref[i, REF_VX + 1], x[i, VX + 2] - ref[i, REF_VX + 2])
        ax, ay, az = ref[i, REF_AX], ref[i, REF_AX + 1], ref[i, REF_AX + 2]
        for j in range(3):
            obs[i, j] = Rm[0][j] * ex + Rm[1][j] * ey + Rm[2][j] * ez
            obs[i, 3 + j] = Rm[0][j] * ux + Rm[1][j] * uy + Rm[2][j] * uz
            obs[i, 6 + j] = Rm[2][j]
            obs[i, 14 + j] = Rm[0][j] * ax + Rm[1][j] * ay + Rm[2][j] * az
            obs[i, 11 + j] = x[i, P + j]
        e_psi = x[i, PSI] - ref[i, REF_PSI]
        obs[i, 9], obs[i, 10] = math.sin(e_psi), math.cos(e_psi)
        hover = vp[i, P_M] * vp[i, P_G] / 4.0
        for j in range(4):
            obs[i, 17 + j] = x[i, F1 + j] / hover - 1.0
        dist = math.sqrt(ex * ex + ey * ey + ez * ez)
        rate = math.sqrt(x[i, P] ** 2 + x[i, P + 1] ** 2 + x[i, P + 2] ** 2)
        reward[i] = math.exp(-dist / REWARD_DISTANCE - REWARD_RATE * rate) if math.isfinite(dist + rate) else 0.0
        lost[i] = not dist <= bound


def estimated_states(truth: np.ndarray, log_obs: np.ndarray, had: np.ndarray):
    """The states a policy observes on the estimate: the truth with position, velocity, Euler
    angles and body rates replaced by the filter's latest (the last logged row that holds one).

    Parameters
    ----------
    truth : numpy.ndarray
        (N, 16) the true states, paper layout.
    log_obs : numpy.ndarray
        (N, R, OBSERVATION_SIZE) the step's observation log (:attr:`quadcruise.sim.stepper.Stepper.log_obs`).
    had : numpy.ndarray
        (N,) bool: whether each vehicle had an estimate before (kept where this step logged none).

    Returns
    -------
    (numpy.ndarray, numpy.ndarray)
        The (N, 16) states and (N,) whether each holds an estimate (else the truth's).
    """
    est = truth.copy()
    if log_obs.shape[1] == 0:
        return est, had
    finite = np.isfinite(log_obs[:, :, O_X])
    found = finite.any(axis=1)
    last = log_obs.shape[1] - 1 - np.argmax(finite[:, ::-1], axis=1)
    rows = np.flatnonzero(found)
    pick = log_obs[rows, last[rows]]
    for at, width, col in ((O_X, 3, X), (O_VX, 3, VX), (O_PHI, 3, PHI), (O_P, 3, P)):
        est[rows, col : col + width] = pick[:, at : at + width]
    return est, had | found


__all__ = [
    "OBS_NAMES",
    "estimated_states",
    "OBS_SIZE",
    "REF_SIZE",
    "REWARD_DISTANCE",
    "REWARD_RATE",
    "observe",
    "references",
]
