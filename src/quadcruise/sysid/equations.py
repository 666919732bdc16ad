"""The equations identified, as linear regressions: regressors and regressands from a flight log.

Rotor i makes thrust ``K s(u_i)``, ``s(u) = (1 - f) u + f u^2`` (PX4's ``THR_MDL_FAC``), through
a first-order lag of bandwidth ``omega``; with ``F_i`` that lagged thrust in units of K, body FLU::

    a_z   = (K/m) sum_i F_i
    p'    = k1 q r + (K/Jxx) sum_i  y_i F_i + c_x             k1 = (Jyy - Jzz)/Jxx
    q'    = k3 p r + (K/Jyy) sum_i -x_i F_i + c_y             k3 = (Jzz - Jxx)/Jyy
    r'    = k5 p q + (K d/Jzz) sum_i s_i F_i + c_z            k5 = (Jxx - Jyy)/Jzz

each linear in its parameters for a given ``omega``; both sides of each go through the same
filter (:func:`kernels`). The symbols and why: docs/identify.md.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from scipy.signal import lfilter, lfilter_zi, savgol_coeffs

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
    """A log's samples through the matched filters: ``t`` [s], ``segment``, commands ``u`` (L, n),
    body ``rates`` [rad/s] (FLU), ``rate_dot`` [rad/s^2], ``force_z`` [m/s^2], ``products`` (q r, p r,
    p q, filtered after the product), the filter's ``window`` [samples], the grid's ``dt`` [s],
    ``hold``, how the commands act between samples (:func:`lagged`), and ``lag_of``, what lags
    (``"thrust"``, the paper's plant; ``"speed"``, a rotor's speed, the thrust its square).
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
    hold: str = "linear"
    lag_of: str = "thrust"


def kernels(window: int, dt: float) -> tuple[np.ndarray, np.ndarray]:
    """The Savitzky-Golay derivative filter ``h`` (order 2) and ``c``, ``h`` applied to the integral.

    ``h * p`` equals ``c * p'`` for ``p'`` linear between samples, so a rate's filtered derivative
    and its filtered right-hand side see the same filter (no bias from the filtering).

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
    """:func:`kernels`' ``c`` (``deriv=0``) or ``h`` (``deriv=1``) along axis 0, within each segment.

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


def signals(t, segment, u, rates, force_z, window_s: float, hold: str = "linear", lag_of: str = "thrust") -> Signals:
    """Filter a log's samples for the regressions (a window of ``window_s``, at least 5 samples, odd;
    ``hold`` as :func:`lagged`; ``lag_of`` ``"thrust"``, the paper's lag of the thrust, or
    ``"speed"``, a rotor's lag of its speed, the thrust its square: :func:`regressions`)."""
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
        hold=hold,
        lag_of=lag_of,
    )


def lagged(u: np.ndarray, segment: np.ndarray, omega: float, dt: float, hold: str = "linear") -> np.ndarray:
    """The first-order lag ``F' = omega (u - F)`` of each column, each segment from steady state:
    bilinear for ``hold="linear"`` (commands a line between samples), exact for ``hold="zero"``
    (each command held until the next; why it matters: docs/identify.md, "Held commands").

    Examples
    --------
    >>> y = lagged(np.r_[np.zeros(1), np.ones(999)][:, None], np.zeros(1000, int), 10.0, 1e-3)
    >>> round(float(y[101, 0]), 2)           # 1 - exp(-1) after 1/omega
    0.63
    >>> held = lagged(np.r_[np.zeros(1), np.ones(999)][:, None], np.zeros(1000, int), 10.0, 1e-3, hold="zero")
    >>> float(held[1, 0]), round(float(held[101, 0]), 2)   # a sample late: 1 - exp(-1) at 101
    (0.0, 0.63)
    """
    if hold == "zero":
        a = float(np.exp(-omega * dt))
        num, den = [0.0, 1.0 - a], [1.0, -a]
    elif hold == "linear":
        h = 0.5 * omega * dt
        a, b = (1.0 - h) / (1.0 + h), h / (1.0 + h)
        num, den = [b, b], [1.0, -a]
    else:
        raise ValueError(f"hold must be 'linear' or 'zero', got {hold!r}")
    steady = lfilter_zi(num, den)
    out = np.empty_like(u, dtype=np.float64)
    for k in np.unique(segment):
        rows = segment == k
        x = u[rows]
        out[rows] = lfilter(num, den, x, axis=0, zi=steady[:, None] * x[0][None, :])[0]  # y[-1] = x[0]
    return out


def regressions(
    sig: Signals, omega: float, shape_f: float | None, rotors: np.ndarray, fit_shape: bool = False
) -> dict[str, tuple[np.ndarray, np.ndarray, tuple[str, ...]]]:
    """The four regressions' data at a given rotor bandwidth: channel -> (y, X, parameter names).

    The thrust regression's names are ``KL`` (K (1 - f) / m) and ``KQ`` (K f / m) when
    ``fit_shape``, else ``Km`` (K / m).
    """
    u = sig.u
    f = 0.0 if shape_f is None else shape_f
    if fit_shape:
        lin = smooth(lagged(u, sig.segment, omega, sig.dt, sig.hold), sig.segment, sig.window)
        quad = smooth(lagged(u * u, sig.segment, omega, sig.dt, sig.hold), sig.segment, sig.window)
        shape = (1.0 - f) * lin + f * quad
        thrust = (sig.force_z, np.column_stack([lin.sum(1), quad.sum(1)]), ("KL", "KQ"))
    elif sig.lag_of == "speed":  # u relative thrust: the speed sqrt(u) lags, the thrust is its square
        speed = lagged(np.sqrt((1.0 - f) * u + f * u * u), sig.segment, omega, sig.dt, sig.hold)
        shape = smooth(speed * speed, sig.segment, sig.window)
        thrust = (sig.force_z, shape.sum(1)[:, None], ("Km",))
    else:
        shape = smooth(lagged((1.0 - f) * u + f * u * u, sig.segment, omega, sig.dt, sig.hold), sig.segment, sig.window)
        thrust = (sig.force_z, shape.sum(1)[:, None], ("Km",))
    ones = np.ones(len(u))
    out = {"thrust": thrust}
    arms = {"roll": shape @ rotors[:, 1], "pitch": shape @ -rotors[:, 0], "yaw": shape @ rotors[:, 2]}
    for axis, name in enumerate(("roll", "pitch", "yaw")):
        X = np.column_stack([sig.products[:, axis], arms[name], ones])
        out[name] = (sig.rate_dot[:, axis], X, ROTATION_TERMS[name])
    return out
