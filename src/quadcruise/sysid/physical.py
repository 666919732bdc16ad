"""From regression coefficients to the vehicle's parameters, with 95 % intervals (delta method).

With the mass m given: ``K = m Km`` (or ``m (KL + KQ)``, ``f = KQ / (KL + KQ)``),
``Jxx = K / b_roll``, ``Jyy = K / b_pitch``, ``Jzz`` from roll's and pitch's gyroscopic terms
(inverse-variance weights), ``d = b_yaw Jzz / K``; without it, the same per unit mass
(``_per_m``). A parameter is identifiable when its 95 % interval is finite and within
:data:`RELATIVE_HALF_WIDTH` of its value (f: :data:`SHAPE_HALF_WIDTH`); otherwise it is reported
with the base vehicle's value and no interval. docs/identify.md explains.
"""

from __future__ import annotations

import numpy as np

from quadcruise.sysid.estimate import Fit

RELATIVE_HALF_WIDTH = 0.25
"""The largest 95 % half-width, relative to the value, of an identifiable parameter."""
SHAPE_HALF_WIDTH = 0.1
"""The largest 95 % half-width of an identifiable thrust-curve factor f (a number in [0, 1],
whose true value may be 0: an absolute bound)."""
CONSISTENCY_SIGMAS = 3.0
"""How many standard errors apart the two estimates of Jzz (from roll's and pitch's gyroscopic
terms) may be before Jzz and d are reported not identifiable."""
Z95 = 1.959963984540054
"""The two-sided 95 % normal quantile."""


def hover_command(km: float, kq: float, n: int, g: float) -> float:
    """The per-rotor command ``u`` of level hover, ``n (km u + kq u^2) = g`` (NaN when no positive root).

    Examples
    --------
    >>> round(hover_command(10.0, 0.0, 4, 9.81), 6)
    0.24525
    """
    c = g / n
    if abs(kq) < 1e-12 * max(abs(km), 1e-300):
        return c / km if km > 0 else float("nan")
    disc = km * km + 4.0 * kq * c
    return float((-km + np.sqrt(disc)) / (2.0 * kq)) if disc >= 0 else float("nan")


def mapping(fit: Fit, mass: float | None, n_rotors: int, g: float, jzz_weights: tuple[float, float]):
    """The function ``values -> {parameter: value}`` from the coefficient vector."""
    idx = {name: i for i, name in enumerate(fit.names)}
    scale = 1.0 if mass is None else float(mass)
    suffix = "_per_m" if mass is None else ""
    w1, w2 = jzz_weights

    def phys(v: np.ndarray) -> dict:
        if "KQ" in idx:
            kl, kq = v[idx["KL"]], v[idx["KQ"]]
        else:  # f fixed: the regressor is the relative thrust s(u), and so is the hover command
            kl, kq = v[idx["Km"]], 0.0
        km = kl + kq
        jxx, jyy = km / v[idx["b_roll"]], km / v[idx["b_pitch"]]
        jzz = w1 * (jyy - v[idx["k1"]] * jxx) + w2 * (jxx + v[idx["k3"]] * jyy)
        out = {
            f"K{suffix}": km * scale,
            f"Jxx{suffix}": jxx * scale,
            f"Jyy{suffix}": jyy * scale,
            f"Jzz{suffix}": jzz * scale,
            "d": v[idx["b_yaw"]] * jzz / km,
            "hover_duty": hover_command(kl, kq, n_rotors, g),
        }
        if "KQ" in idx:
            out["thrust_curve_f"] = kq / km
        if "omega" in idx:
            out["omega"] = v[idx["omega"]]
        return out

    return phys


def jacobian(func, v: np.ndarray) -> tuple[list[str], np.ndarray, np.ndarray]:
    """``(names, values, jac)`` of a dict-valued function at ``v``, by central differences."""
    with np.errstate(all="ignore"):
        return _jacobian(func, v)


def _jacobian(func, v):
    base = func(v)
    names = list(base)
    jac = np.zeros((len(names), len(v)))
    for j in range(len(v)):
        h = 1e-6 * max(abs(v[j]), 1e-8)
        up, down = v.copy(), v.copy()
        up[j] += h
        down[j] -= h
        fu, fd = func(up), func(down)
        jac[:, j] = [(fu[n] - fd[n]) / (2 * h) for n in names]
    return names, np.array([base[n] for n in names]), jac


def parameters(
    fit: Fit,
    mass: float | None,
    n_rotors: int,
    g: float,
    systematic: dict[str, float] | None = None,
    coupling: tuple[bool, bool] = (True, True),
    covariance: dict | None = None,
) -> dict[str, dict]:
    """The physical parameters: name -> ``{"value", "se", "ci95": [lo, hi], "identifiable"}``.

    ``systematic`` adds a uniform error's variance (half-range^2 / 3) per name; ``coupling`` says
    whether roll's and pitch's gyroscopic terms may give Jzz (one whose regressor is mostly sensor
    noise is biased toward zero and must not). ``covariance``, a dict, is filled with the
    identifiable parameters' joint covariance, ``{"names": [...], "matrix": [[...]]}``: the delta
    method's, plus each systematic term's variance on the diagonal (its diagonal is each interval's
    standard error squared).
    """
    # Jzz's two estimates, weighted by their inverse variances
    est, jzz, rows = [], [], []
    finite = np.where(np.isfinite(fit.cov), fit.cov, 0.0)
    blind = ~np.isfinite(np.diag(fit.cov))
    for w in ((1.0, 0.0), (0.0, 1.0)):
        names, values, jac = jacobian(mapping(fit, mass, n_rotors, g, w), fit.values)
        k = next(i for i, n in enumerate(names) if n.startswith("Jzz"))
        row = jac[k]
        seen = np.all(np.isfinite(row)) and not np.any(row[blind] != 0)
        est.append(float(np.nan_to_num(row) @ finite @ np.nan_to_num(row)) if seen else np.inf)
        jzz.append(float(values[k]))
        rows.append(np.nan_to_num(row))
    # the two estimates of Jzz must agree: if not, the gyroscopic terms do not fit the model (a
    # test of the over-determined part of the model, with their covariance)
    diff_var = float((rows[0] - rows[1]) @ finite @ (rows[0] - rows[1]))
    consistent = not (
        all(np.isfinite(est))
        and all(coupling)
        and diff_var > 0
        and abs(jzz[0] - jzz[1]) > CONSISTENCY_SIGMAS * np.sqrt(diff_var)
    )
    inv = [1.0 / v if v > 0 and np.isfinite(v) and ok else 0.0 for v, ok in zip(est, coupling, strict=False)]
    weights = (0.5, 0.5) if sum(inv) == 0 else (inv[0] / sum(inv), inv[1] / sum(inv))
    names, values, jac = jacobian(mapping(fit, mass, n_rotors, g, weights), fit.values)
    blind = ~np.isfinite(np.diag(fit.cov))
    finite = np.where(np.isfinite(fit.cov), fit.cov, 0.0)
    cov = np.nan_to_num(jac) @ finite @ np.nan_to_num(jac).T
    unseen = ~np.all(np.isfinite(jac), axis=1) | np.any(np.abs(np.nan_to_num(jac[:, blind], nan=1.0)) > 0, axis=1)
    cov[unseen, unseen] = np.inf
    if not consistent:
        for i, name in enumerate(names):
            if name.startswith("Jzz") or name == "d":
                cov[i, i] = np.inf
    out = {}
    for i, name in enumerate(names):
        extra = (systematic or {}).get(name, 0.0)
        se = float(np.sqrt(max(cov[i, i], 0.0) + extra * extra / 3.0))
        value = float(values[i])
        bound = SHAPE_HALF_WIDTH if name == "thrust_curve_f" else RELATIVE_HALF_WIDTH * abs(value)
        ok = bool(
            np.isfinite(value) and np.isfinite(se) and (value != 0.0 or name == "thrust_curve_f") and Z95 * se <= bound
        )
        out[name] = {"value": value, "se": se, "ci95": [value - Z95 * se, value + Z95 * se], "identifiable": ok}
        if not consistent and (name.startswith("Jzz") or name == "d"):
            out[name]["inconsistent"] = (
                f"roll's and pitch's gyroscopic terms give Jzz {jzz[0]:.4g} and {jzz[1]:.4g} "
                f"(more than {CONSISTENCY_SIGMAS:g} standard errors apart): the log does not "
                "fit the model there (commands changing faster than logged, a missing term)"
            )
    if covariance is not None:
        keep = [i for i, name in enumerate(names) if out[name]["identifiable"]]
        matrix = cov[np.ix_(keep, keep)].copy()
        for j, i in enumerate(keep):
            matrix[j, j] = out[names[i]]["se"] ** 2
        covariance.update(names=[names[i] for i in keep], matrix=matrix.tolist())
    return out
