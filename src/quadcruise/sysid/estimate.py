"""Equation-error least squares, ``omega`` by variable projection, intervals by a Newey-West sandwich.

The filtered residuals are autocorrelated over the filter window at least, so the ordinary
covariance would be several times too small; docs/identify.md gives the estimator and its reasons.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from scipy.optimize import minimize_scalar

from quadcruise.sysid.equations import CHANNELS, Signals, regressions


@dataclass(frozen=True)
class Fit:
    """The fitted coefficients (``names``, ``values``; ``omega`` last when ``omega_fitted``), their
    Newey-West covariance ``cov``, the ``omega`` [rad/s] and ``shape_f`` used, each channel's
    residual ``sigma``, the HAC ``bandwidth`` and the ``rows`` [samples] fitted.
    """

    names: tuple
    values: np.ndarray
    cov: np.ndarray
    omega: float
    omega_fitted: bool
    shape_f: float
    sigma: dict
    bandwidth: int
    rows: int

    def value(self, name: str) -> float:
        """One coefficient's value, by name."""
        return float(self.values[self.names.index(name)])

    def coefficients(self) -> dict[str, np.ndarray]:
        """Channel -> its coefficients, in the regression's column order."""
        out, k = {}, 0
        for c, width in self.widths:
            out[c] = self.values[k : k + width]
            k += width
        return out

    @property
    def widths(self) -> list[tuple[str, int]]:
        """(channel, number of coefficients) in order."""
        thrust = 2 if "KQ" in self.names else 1
        return [("thrust", thrust), ("roll", 3), ("pitch", 3), ("yaw", 3)]


def _solve(y: np.ndarray, X: np.ndarray) -> np.ndarray:
    beta, *_ = np.linalg.lstsq(X, y, rcond=None)
    return beta


def weighted_ssr(
    sig: Signals, rows: np.ndarray, omega: float, shape_f: float, rotors: np.ndarray, fit_shape: bool, sigma: dict
) -> float:
    """The profile objective at this omega: the sum over channels of SSR / sigma^2."""
    total = 0.0
    for c, (y, X, _) in regressions(sig, omega, shape_f, rotors, fit_shape).items():
        e = y[rows] - X[rows] @ _solve(y[rows], X[rows])
        total += float(e @ e) / sigma[c] ** 2
    return total


def fit(
    sig: Signals,
    rows: np.ndarray,
    rotors: np.ndarray,
    omega0: float,
    shape_f: float,
    *,
    fit_omega: bool,
    fit_shape: bool,
    omega_bounds: tuple[float, float],
) -> Fit:
    """Fit the four regressions (and ``omega``, the thrust curve's shape), with the Newey-West covariance."""

    def residual_sigma(omega, f):
        out = {}
        for c, (y, X, _) in regressions(sig, omega, f, rotors, fit_shape).items():
            e = y[rows] - X[rows] @ _solve(y[rows], X[rows])
            out[c] = max(float(np.std(e)), 1e-12)
        return out

    omega, f = float(omega0), float(shape_f)
    for _ in range(3 if fit_shape else 1):
        sigma = residual_sigma(omega, f)
        if fit_omega:
            lo, hi = np.log(omega_bounds[0]), np.log(omega_bounds[1])
            best = minimize_scalar(
                lambda lw, f=f, sigma=sigma: weighted_ssr(sig, rows, float(np.exp(lw)), f, rotors, fit_shape, sigma),
                bounds=(lo, hi),
                method="bounded",
                options={"xatol": 1e-4},
            )
            omega = float(np.exp(best.x))
        if fit_shape:
            y, X, _ = regressions(sig, omega, f, rotors, True)["thrust"]
            kl, kq = _solve(y[rows], X[rows])
            f = float(kq / (kl + kq)) if kl + kq != 0 else 0.0
    data = regressions(sig, omega, f, rotors, fit_shape)
    betas = {c: _solve(y[rows], X[rows]) for c, (y, X, _) in data.items()}
    resid = {c: data[c][0][rows] - data[c][1][rows] @ betas[c] for c in CHANNELS}
    sigma = {c: max(float(np.std(resid[c])), 1e-12) for c in CHANNELS}
    names = [n for c in CHANNELS for n in data[c][2]] + (["omega"] if fit_omega else [])
    values = np.concatenate([betas[c] for c in CHANNELS] + ([np.array([omega])] if fit_omega else []))
    n, p = int(rows.sum()), len(names)
    # Jacobians of each channel's prediction with respect to all coefficients, per sample
    jac = {c: np.zeros((n, p)) for c in CHANNELS}
    k = 0
    for c in CHANNELS:
        width = data[c][1].shape[1]
        jac[c][:, k : k + width] = data[c][1][rows]
        k += width
    if fit_omega:
        h = 1e-3 * omega
        up = regressions(sig, omega + h, f, rotors, fit_shape)
        down = regressions(sig, omega - h, f, rotors, fit_shape)
        # rounding is no dependence on omega (constant commands: the lag's output is the command at
        # every omega); left in, it is collinear with the gains' columns and takes their
        # identifiability with it. A lag's steady state is exact to about eps / (omega dt): its
        # recursion's pole is 1 - omega dt (at 2.3 rad/s and 4 ms, 110 eps)
        rounding = 64 * np.finfo(float).eps / min(1.0, omega * sig.dt)
        for c in CHANNELS:
            change = up[c][1][rows] - down[c][1][rows]
            change[np.abs(change) <= rounding * np.max(np.abs(data[c][1][rows]), initial=0.0)] = 0.0
            jac[c][:, -1] = change @ betas[c] / (2 * h)
    bread = sum(jac[c].T @ jac[c] / sigma[c] ** 2 for c in CHANNELS)
    score = sum(jac[c] * (resid[c] / sigma[c] ** 2)[:, None] for c in CHANNELS)
    seg = sig.segment[rows]
    lag = hac_bandwidth(resid, seg, sig.window)
    meat = score.T @ score
    for j in range(1, lag + 1):
        same = (seg[j:] == seg[:-j])[:, None]
        gamma = (score[j:] * same).T @ score[:-j]
        meat += (1.0 - j / (lag + 1.0)) * (gamma + gamma.T)
    cov = sandwich(bread, meat)
    return Fit(
        names=tuple(names),
        values=values,
        cov=cov,
        omega=omega,
        omega_fitted=fit_omega,
        shape_f=f,
        sigma=sigma,
        bandwidth=lag,
        rows=n,
    )


def sandwich(bread: np.ndarray, meat: np.ndarray, tol: float = 1e-10) -> np.ndarray:
    """``A^-1 S A^-1``, with infinite variance for a coefficient in a direction the data do not excite
    (an eigenvalue of the scaled ``A`` below ``tol`` times the largest): a pseudo-inverse would give
    it zero, a tight interval on nothing.

    Examples
    --------
    >>> cov = sandwich(np.diag([1.0, 0.0]), np.eye(2))
    >>> np.diag(cov).tolist()
    [1.0, inf]
    """
    scale = np.sqrt(np.clip(np.diag(bread), 1e-300, None))
    scaled = bread / np.outer(scale, scale)
    vals, vecs = np.linalg.eigh(scaled)
    good = vals > tol * max(vals.max(), 1e-300)
    inv = (vecs[:, good] / vals[good]) @ vecs[:, good].T / np.outer(scale, scale)
    cov = inv @ meat @ inv
    blind = np.any(np.abs(vecs[:, ~good]) > 1e-6, axis=1) | (np.diag(bread) <= 1e-300)
    cov[blind, :] = 0.0
    cov[:, blind] = 0.0
    cov[blind, blind] = np.inf
    return cov


def hac_bandwidth(resid: dict, segment: np.ndarray, window: int) -> int:
    """Newey-West bandwidth: max(2 window, the lag where every channel's residual autocorrelation is
    below 0.05), at most a fifth of the samples.

    Examples
    --------
    >>> rng = np.random.default_rng(0)
    >>> hac_bandwidth({"a": rng.standard_normal(1000)}, np.zeros(1000, int), 5)
    10
    """
    n = len(segment)
    cap = max(1, n // 5)
    longest = 2 * window
    for e in resid.values():
        e = e - e.mean()
        var = float(e @ e)
        if var <= 0:
            continue
        spectrum = np.fft.rfft(e, 2 * n)
        acf = np.fft.irfft(spectrum * np.conj(spectrum))[:n] / var
        below = np.flatnonzero(acf[1:] < 0.05)
        longest = max(longest, int(below[0]) + 1 if below.size else cap)
    return int(min(longest, cap))
