"""The equations identified, as linear regressions: regressors and regressands from a flight log.

The paper's plant (:mod:`quadcruise.model.plant`) with any rotor positions (the log's
``CA_ROTOR*``): rotor i makes thrust ``K s(u_i)`` through a first-order lag of bandwidth
``omega``, with PX4's thrust-curve shape ``s(u) = (1 - f) u + f u^2`` (``THR_MDL_FAC``).
With ``F_i = lag_omega(s(u_i))`` (thrust in units of K), in the body frame (FLU)::

    a_z   = (K/m) sum_i F_i                                   specific force along body z
    p'    = k1 q r + (K/Jxx) sum_i  y_i F_i + c_x             roll,  k1 = (Jyy - Jzz)/Jxx
    q'    = k3 p r + (K/Jyy) sum_i -x_i F_i + c_y             pitch, k3 = (Jzz - Jxx)/Jyy
    r'    = k5 p q + (K d/Jzz) sum_i s_i F_i + c_z            yaw,   k5 = (Jxx - Jyy)/Jzz

with ``(x_i, y_i)`` rotor i's position [m] and ``s_i`` its yaw sign (+1 when its drag torque is
positive about body z up; eq (4): rotors 1 and 3). ``c_x, c_y, c_z`` are constant trim
accelerations (a centre of mass off the rotors' centre, unequal motors): left free so that a
trim does not bias the effectiveness. For a given ``omega`` (and ``f``) each line is linear in
its parameters.

Every signal, regressor and regressand alike, goes through the same filter: the angular
accelerations are the Savitzky-Golay first derivative (scipy.signal.savgol_coeffs) of the
logged rates, and every other signal is filtered by the same derivative filter applied to its
integral (:func:`kernels`), so the filter's delay and attenuation are exactly the same on both
sides of each equation and do not bias the fit.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from scipy.signal import lfilter, savgol_coeffs

CHANNELS = ("thrust", "roll", "pitch", "yaw")
"""The four regressions, in order."""
ROTATION_TERMS = {
    "roll": ("k1", "b_roll", "c_roll"),
    "pitch": ("k3", "b_pitch", "c_pitch"),
    "yaw": ("k5", "b_yaw", "c_yaw"),
}
"""Each rotational regression's coefficients: coupling, effectiveness, trim."""


@dataclass(frozen=True)
class Signals:
    """A log's samples, filtered and split into what the regressions need.

    Parameters
    ----------
    t : ndarray, shape (L,)
        Time [s].
    segment : ndarray, shape (L,)
        Segment index of each sample.
    u : ndarray, shape (L, n)
        Rotor commands in [0, 1].
    rates : ndarray, shape (L, 3)
        Body rates (FLU), filtered [rad/s].
    rate_dot : ndarray, shape (L, 3)
        Their derivative, by the same filter [rad/s^2].
    force_z : ndarray, shape (L,)
        Specific force along body z, filtered [m/s^2].
    products : ndarray, shape (L, 3)
        q r, p r, p q, each filtered after the product [rad^2/s^2].
    window : int
        The filter's window [samples].
    dt : float
        The grid's step [s].
    """

    t: np.ndarray
    segment: np.ndarray
    u: np.ndarray
    rates: np.ndarray
    rate_dot: np.ndarray
    force_z: np.ndarray
    products: np.ndarray
    window: int
    dt: float


def kernels(window: int, dt: float) -> tuple[np.ndarray, np.ndarray]:
    """The derivative filter and the smoothing filter matched to it.

    ``h`` is the Savitzky-Golay first-derivative filter (order 2). ``c`` is ``h`` applied to
    the integral of a signal (trapezoids between samples): ``h * p`` equals ``c * p'`` for any
    ``p'`` linear between samples, so a rate's filtered derivative and its filtered
    right-hand side see exactly the same filter, and the fit no bias from the filtering.

    Parameters
    ----------
    window : int
        Length [samples], odd, >= 5.
    dt : float
        Sample spacing [s].

    Returns
    -------
    h, c : ndarray, shape (window,)
        Convolution kernels (``numpy.convolve(x, k, "same")``); ``c`` sums to 1.

    Examples
    --------
    >>> h, c = kernels(7, 0.1)
    >>> round(float(c.sum()), 12), round(float(np.convolve(np.arange(20) * 0.1, h, "same")[10]), 12)
    (1.0, 1.0)
    """
    h = savgol_coeffs(window, 2, deriv=1, delta=dt, use="conv")
    g = np.cumsum(h)
    c = 0.5 * dt * (g + np.r_[0.0, g[:-1]])
    return h, c


def smooth(x: np.ndarray, segment: np.ndarray, window: int, deriv: int = 0, dt: float = 1.0) -> np.ndarray:
    """The matched filters of :func:`kernels` along axis 0, within each segment.

    Parameters
    ----------
    x : ndarray, shape (L,) or (L, k)
        The signal(s).
    segment : ndarray, shape (L,)
        Segment index of each sample: the filter does not reach across segments (the first
        and last half window of each segment are not valid: the fit leaves them out).
    window : int
        Window length [samples], odd, >= 5.
    deriv : int
        0 to smooth (``c``), 1 for the first derivative (``h``).
    dt : float
        Sample spacing [s].

    Returns
    -------
    ndarray
        Same shape as ``x``.

    Examples
    --------
    >>> t = np.arange(50) * 0.1
    >>> d = smooth(t ** 2, np.zeros(50, int), 5, deriv=1, dt=0.1)
    >>> bool(np.allclose(d[3:-3], 2 * t[3:-3]))
    True
    """
    h, c = kernels(window, dt)
    kernel = h if deriv else c
    x = np.asarray(x, dtype=np.float64)
    flat = x.reshape(len(x), -1)
    out = np.empty_like(flat)
    for k in np.unique(segment):
        rows = np.flatnonzero(segment == k)
        for j in range(flat.shape[1]):
            out[rows, j] = np.convolve(flat[rows, j], kernel, "same") if len(rows) >= len(kernel) else np.nan
    return out.reshape(x.shape)


def signals(t, segment, u, rates, force_z, window_s: float) -> Signals:
    """Filter a log's samples for the regressions.

    Parameters
    ----------
    t, segment : ndarray, shape (L,)
        Time [s] and segment index.
    u : ndarray, shape (L, n)
        Rotor commands [-].
    rates : ndarray, shape (L, 3)
        Body rates, FLU [rad/s].
    force_z : ndarray, shape (L,)
        Specific force along body z [m/s^2].
    window_s : float
        Filter window [s]; at least 5 samples, odd.

    Returns
    -------
    Signals
    """
    dt = float(np.median(np.diff(t))) if len(t) > 1 else 1.0
    window = max(5, round(window_s / dt) | 1)
    p, q, r = rates.T
    return Signals(
        t=t,
        segment=segment,
        u=np.clip(u, 0.0, 1.0),
        rates=smooth(rates, segment, window),
        rate_dot=smooth(rates, segment, window, deriv=1, dt=dt),
        force_z=smooth(force_z, segment, window),
        products=smooth(np.column_stack([q * r, p * r, p * q]), segment, window),
        window=window,
        dt=dt,
    )


def lagged(u: np.ndarray, segment: np.ndarray, omega: float, dt: float) -> np.ndarray:
    """First-order lag ``F' = omega (u - F)`` of each column, within each segment.

    The bilinear (trapezoidal) discretisation, exact for an input linear between samples (as
    the log's interpolation makes it), each segment starting in steady state.

    Parameters
    ----------
    u : ndarray, shape (L, n)
        Inputs.
    segment : ndarray, shape (L,)
        Segment index of each sample.
    omega : float
        Bandwidth [rad/s].
    dt : float
        Sample spacing [s].

    Returns
    -------
    ndarray, shape (L, n)

    Examples
    --------
    >>> y = lagged(np.r_[np.zeros(1), np.ones(999)][:, None], np.zeros(1000, int), 10.0, 1e-3)
    >>> round(float(y[101, 0]), 2)           # 1 - exp(-1) after 1/omega
    0.63
    """
    h = 0.5 * omega * dt
    a, b = (1.0 - h) / (1.0 + h), h / (1.0 + h)
    out = np.empty_like(u, dtype=np.float64)
    for k in np.unique(segment):
        rows = segment == k
        x = u[rows]
        zi = (x[0] * (1.0 - a) - b * x[0])[None, :]  # steady state: y[-1] = x[0]
        out[rows] = lfilter([b, b], [1.0, -a], x, axis=0, zi=zi)[0]
    return out


def regressions(
    sig: Signals, omega: float, shape_f: float | None, rotors: np.ndarray, fit_shape: bool = False
) -> dict[str, tuple[np.ndarray, np.ndarray, tuple[str, ...]]]:
    """The four regressions' data at a given rotor bandwidth.

    Parameters
    ----------
    sig : Signals
        The filtered log.
    omega : float
        Rotor bandwidth [rad/s].
    shape_f : float or None
        The thrust-curve factor f the moments' regressors are built with (0 for None).
    rotors : ndarray, shape (n, 3)
        x, y [m] (FLU) and yaw sign of each rotor.
    fit_shape : bool
        Fit f: the thrust regression gets two columns, ``sum u`` and ``sum u^2`` (lagged).

    Returns
    -------
    dict
        Channel name -> (y, X, parameter names); the names of the thrust regression are
        ``KL`` (K (1 - f) / m) and ``KQ`` (K f / m) when ``fit_shape``, else ``Km`` (K / m).
    """
    u = sig.u
    f = 0.0 if shape_f is None else shape_f
    if fit_shape:
        lin = smooth(lagged(u, sig.segment, omega, sig.dt), sig.segment, sig.window)
        quad = smooth(lagged(u * u, sig.segment, omega, sig.dt), sig.segment, sig.window)
        shape = (1.0 - f) * lin + f * quad
        thrust = (sig.force_z, np.column_stack([lin.sum(1), quad.sum(1)]), ("KL", "KQ"))
    else:
        shape = smooth(lagged((1.0 - f) * u + f * u * u, sig.segment, omega, sig.dt), sig.segment, sig.window)
        thrust = (sig.force_z, shape.sum(1)[:, None], ("Km",))
    ones = np.ones(len(u))
    out = {"thrust": thrust}
    arms = {"roll": shape @ rotors[:, 1], "pitch": shape @ -rotors[:, 0], "yaw": shape @ rotors[:, 2]}
    for axis, name in enumerate(("roll", "pitch", "yaw")):
        X = np.column_stack([sig.products[:, axis], arms[name], ones])
        out[name] = (sig.rate_dot[:, axis], X, ROTATION_TERMS[name])
    return out
