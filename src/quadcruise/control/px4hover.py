"""PX4's hover-thrust estimator (``mc_hover_thrust_estimator``, release v1.15), compiled.

A one-state Kalman filter on the hover thrust ``h`` (``ZeroOrderHoverThrustEkf``, written from
``src/modules/mc_hover_thrust_estimator/zero_order_hover_thrust_ekf.{hpp,cpp}``): the state is
constant (its variance grows by ``Q dt^2``), the measurement is the vertical acceleration, up
positive, predicted from the collective thrust ``T`` (up positive, normalised) as

    a_z = g T / h - g,       H = d a_z / d h = -g T / h^2,

the innovation gated at ``HTE_ACC_GATE`` standard deviations (a rejected measurement leaves the
state; a run of rejections, seen as a low-passed signed test ratio over 0.2, bumps the state's
variance by ``1e3 Q dt^2``), the measurement noise ``R`` learnt from the residuals (time constant
2 s, within [1, 400] (m/s^2)^2) and scaled up while the vehicle moves fast (``HTE_VZ_THR``,
``HTE_VXY_THR``: ``MulticopterHoverThrustEstimator.cpp``), the state kept within
``MPC_THR_HOVER`` -+ ``HTE_THR_RANGE``. The module calls it valid once its variance is under
0.001 (and, the first time, its test ratio under 1) for 2 s.

The filter's state is a small array (:data:`HTE_STATE`), so that a controller keeps it in its
memory row.

Examples
--------
>>> import numpy as np
>>> s = hte_reset(0.5, 0.1)                     # MPC_THR_HOVER 0.5, HTE_HT_ERR_INIT 0.1
>>> for _ in range(200):                        # 4 s hovering at a true hover thrust of 0.6
...     hte_predict(s, 0.02, 0.0036 ** 2)
...     _ = hte_fuse(s, 0.0, 0.6, 3.0, 1.0, 0.1, 0.9, 0.0036 ** 2)
>>> round(float(s[HTE_HOVER]), 3)
0.6
"""

from __future__ import annotations

import math

import numpy as np
from numba import njit

from quadcruise import layout as L

__all__ = [
    "HTE_STATE",
    "HTE_HOVER",
    "HTE_VAR",
    "HTE_ACC_VAR",
    "HTE_RATIO",
    "hte_reset",
    "hte_predict",
    "hte_fuse",
    "hte_noise_scale",
]

ONE_G = 9.80665
"""PX4's ``CONSTANTS_ONE_G`` [m/s^2]."""
NOISE_TIME_CONSTANT = 2.0
"""``_noise_learning_time_constant`` [s]."""
LPF_TIME_CONSTANT = 1.0
"""``_lpf_time_constant`` [s] of the residual and signed test ratio low-passes."""
HTE_STATE = L.Row.of(
    "hover thrust estimator",
    "hover",
    "var",
    "acc_var",
    "residual_lpf",
    "ratio_lpf",
    "ratio",
    "innov",
    "dt",
    prefix="HTE_",
)
"""The filter's state: hover thrust [-], its variance, the acceleration noise variance
[(m/s^2)^2], the residual's and the signed test ratio's low-passes, the last test ratio and
innovation [m/s^2], the last period [s]."""
(HTE_HOVER, HTE_VAR, HTE_ACC_VAR, HTE_RESIDUAL_LPF, HTE_RATIO_LPF, HTE_RATIO, HTE_INNOV, HTE_DT) = HTE_STATE.offsets


def hte_reset(hover: float, err_init: float) -> np.ndarray:
    """A new filter's state (``MulticopterHoverThrustEstimator::reset``).

    Parameters
    ----------
    hover : float
        The initial hover thrust (``MPC_THR_HOVER``), kept within [0.1, 0.9].
    err_init : float
        Its 1-sigma uncertainty (``HTE_HT_ERR_INIT``).

    Returns
    -------
    numpy.ndarray
        :data:`HTE_STATE`'s row: acceleration noise variance 5 (``resetAccelNoise``), period 0.02 s.
    """
    s = np.zeros(HTE_STATE.size)
    hte_reset_into(s, hover, err_init)
    return s


@njit(cache=True, inline="always")
def hte_reset_into(s, hover, err_init):
    """:func:`hte_reset` into ``s`` (compiled)."""
    s[HTE_HOVER] = min(max(hover, 0.1), 0.9)
    s[HTE_VAR] = err_init * err_init
    s[HTE_ACC_VAR] = 5.0
    s[HTE_RESIDUAL_LPF] = 0.0
    s[HTE_RATIO_LPF] = 0.0
    s[HTE_RATIO] = 0.0
    s[HTE_INNOV] = 0.0
    s[HTE_DT] = 0.02


@njit(cache=True, inline="always")
def hte_predict(s, dt, process_var):
    """``predict``: the variance grows by ``process_var dt^2`` (``HTE_HT_NOISE^2``)."""
    s[HTE_VAR] += process_var * dt * dt
    s[HTE_DT] = dt


@njit(cache=True, inline="always")
def hte_noise_scale(vz, vxy, vz_thr, vxy_thr):
    """The measurement noise's scale while moving fast: ``max(|vz| - HTE_VZ_THR + 1,
    |vxy| - HTE_VXY_THR + 1, 1)`` (``MulticopterHoverThrustEstimator::Run``)."""
    return max(abs(vz) - vz_thr + 1.0, vxy - vxy_thr + 1.0, 1.0)


@njit(cache=True, error_model="numpy")
def hte_fuse(s, acc_z, thrust, gate, scale, h_min, h_max, process_var):
    """``fuseAccZ``: one measurement of the vertical acceleration.

    Parameters
    ----------
    s : numpy.ndarray
        :data:`HTE_STATE`'s row, updated in place.
    acc_z : float
        Vertical acceleration, up positive [m/s^2].
    thrust : float
        Collective thrust, up positive (normalised).
    gate : float
        Innovation gate [standard deviations] (``HTE_ACC_GATE``).
    scale : float
        Measurement noise scale (:func:`hte_noise_scale`; its square multiplies the variance).
    h_min, h_max : float
        The hover thrust's range.
    process_var : float
        The process noise variance (``HTE_HT_NOISE^2``), for the recovery's bump.

    Returns
    -------
    bool
        Whether the measurement passed the gate.
    """
    h = s[HTE_HOVER]
    p = s[HTE_VAR]
    r = s[HTE_ACC_VAR] * scale * scale
    big_h = -ONE_G * thrust / (h * h)
    innov_var = max(big_h * p * big_h + r, r)
    innov = acc_z - (ONE_G * thrust / h - ONE_G)
    k = p * big_h / innov_var
    ratio = innov * innov / (gate * gate * innov_var)
    residual = innov
    passed = ratio < 1.0
    if passed:
        s[HTE_HOVER] = min(max(h + k * innov, h_min), h_max)
        s[HTE_VAR] = min(max((1.0 - k * big_h) * p, 1e-10), 1.0)
        residual = acc_z - (ONE_G * thrust / s[HTE_HOVER] - ONE_G)
    elif abs(s[HTE_RATIO_LPF]) > 0.2:  # a run of rejections: the hover thrust changed, or the filter diverges
        s[HTE_VAR] += 1e3 * process_var * s[HTE_DT] * s[HTE_DT]
    dt = s[HTE_DT]
    alpha = dt / (LPF_TIME_CONSTANT + dt)
    signed = math.copysign(ratio, innov) if innov != 0.0 else 0.0
    s[HTE_RESIDUAL_LPF] = (1.0 - alpha) * s[HTE_RESIDUAL_LPF] + alpha * residual
    s[HTE_RATIO_LPF] = (1.0 - alpha) * s[HTE_RATIO_LPF] + alpha * min(max(signed, -1.0), 1.0)
    beta = dt / (NOISE_TIME_CONSTANT + dt)
    res = residual - s[HTE_RESIDUAL_LPF]
    p = s[HTE_VAR]
    s[HTE_ACC_VAR] = min(max((1.0 - beta) * s[HTE_ACC_VAR] + beta * (res * res + big_h * p * big_h), 1.0), 400.0)
    s[HTE_RATIO] = ratio
    s[HTE_INNOV] = innov
    return passed
