"""Does the identified model fit the log? The verdict that comes before any interval.

An interval is only as good as the model it is computed in: a wrong structure (a rotor plant read
as the paper's, a missing term) or commands the log did not see (a log that samples them) give
tight intervals around a wrong value. Five checks, each able to fail on its own
(docs/identify.md, "The verdict"):

- **every command seen**: the commands are logged at the rate the controller computed them
  (PX4's ``IMU_GYRO_RATEMAX``, the rate loop's rate, or the rate the writer recorded), or do not
  change between samples (:data:`STILL_SHARE`: an open-loop schedule of steps); a log that samples
  changing commands leaves the commands between samples unknown, not held;
- **held out**: each equation's residual on the held-out tail, against its residual in the fit:
  mean square at most :data:`MAX_HELD_RATIO` times the fitted one (a model that holds predicts
  data it was not fitted on as well as the data it was);
- **white residuals**: the residuals' autocorrelation, past the filter's own reach
  (:data:`WHITE_LAG_WINDOWS` filter windows), under :data:`MAX_LATE_ACF` (what the filter and
  sensor noise leave is short; an unmodelled dynamic leaves a long tail);
- **segments agree**: the parameters fitted on the first and second half of the fitted time apart
  by at most :data:`MAX_SEGMENT_Z` standard errors of their difference;
- **structure**: the other lag structure (a rotor's speed lagging and its thrust the square, or
  the paper's thrust lagging) fitted to the same rows leaves no equation's residual variance
  :data:`BETTER_STRUCTURE` lower (the paper's plant on a rotor vehicle's log, or the reverse).
"""

from __future__ import annotations

import dataclasses

import numpy as np

from quadcruise.sysid.logprep import SYSID_PROFILE_BIT

MAX_HELD_RATIO = 2.0
"""The largest ratio of an equation's held-out mean square residual to its fitted one."""
NEGLIGIBLE = 1e-4
"""A residual mean square under this share of its regressand's variance (R^2 over 0.9999) is
negligible: the held-out and whiteness checks judge noise and missing dynamics, not dust."""
DUST_RMS = 1e-6
"""A residual whose root mean square is under this [m/s^2, rad/s^2] is negligible whatever its
regressand: a thousandth of the derivative noise of the best gyroscope (1e-3 rad/s at 1 kHz gives
about 5e-3 rad/s^2 through the 0.08 s filter), so only a noise-free simulated log has one. A
hover without noise has residuals of 1e-13 rad/s^2 (floating-point dust) whose regressand is dust
too: relative to it (:data:`NEGLIGIBLE`) they looked like a model that does not fit."""
WHITE_LAG_WINDOWS = 4
"""Filter windows past which the residuals' autocorrelation is judged."""
MAX_LATE_ACF = 0.5
"""The largest autocorrelation allowed past :data:`WHITE_LAG_WINDOWS` filter windows."""
MAX_SEGMENT_Z = 5.0
"""Standard errors of their difference by which two halves' estimates may differ."""
BETTER_STRUCTURE = 0.3
"""How much lower (a share) the other lag structure's residual variance must be to fail the model."""
STILL_SHARE = 0.95
"""The least share of unchanged consecutive commands for sampled commands to count as all seen."""
HELD_SHARE = 2.0 / 3.0
"""On a log that does not say its control rate, the least share of unchanged consecutive commands
(each command repeated exactly, held 3 samples on average) for the log to count as holding every
command: commands that change at (nearly) every logged sample were sampled, as far as the log
shows (a 1 kHz controller's commands kept every 100th gave K +1 % with an interval excluding the
truth)."""
LEVEL_SPREAD = 0.05
"""Each rotor's commands' standard deviation over their mean under which a log whose changes
identify nothing (no inertia, ``d`` nor lag identifiable: a hover) is judged on its commands'
level alone: sampled commands then lose nothing the fit uses (the sampled mean is the mean), and
any thrust curve's curvature moves the mean thrust by about the spread squared (< 0.3 %)."""
SAMPLED_SHARE = 0.9
"""Commands logged below this share of the controller's rate are sampled, not all seen."""
FITS = "fits"
"""The verdict's word when every check passes."""
NOT_FIT = "does not fit"
"""The verdict's word when any check fails."""


def control_rate(parameters: dict, info: dict | None = None) -> float | None:
    """The rate [Hz] the controller computed commands at, when the log says it; else None.

    PX4 runs the rate controller on each ``vehicle_angular_velocity``, published at
    ``IMU_GYRO_RATEMAX``; a quadcruise log records its control rate in the log's information
    (``quadcruise_control_rate_hz``).

    Examples
    --------
    >>> control_rate({"IMU_GYRO_RATEMAX": 800}), control_rate({})
    (800.0, None)
    """
    for source, key in ((info or {}, "quadcruise_control_rate_hz"), (parameters, "IMU_GYRO_RATEMAX")):
        value = source.get(key)
        try:
            value = float(value)
        except (TypeError, ValueError):
            continue
        if np.isfinite(value) and value > 0:
            return value
    return None


def late_autocorrelation(e: np.ndarray, segment: np.ndarray, lag: int) -> float:
    """The residual's autocorrelation at ``lag`` samples, within segments.

    Examples
    --------
    >>> rng = np.random.default_rng(0)
    >>> abs(late_autocorrelation(rng.standard_normal(5000), np.zeros(5000, int), 10)) < 0.05
    True
    """
    e = e - e.mean()
    var = float(e @ e) / len(e)
    if var <= 0 or lag >= len(e):
        return 0.0
    same = segment[lag:] == segment[:-lag]
    if not np.any(same):
        return 0.0
    return float(np.mean((e[lag:] * e[:-lag])[same]) / var)


def negligible_residual(mean_square: float, y_var: float = 0.0) -> bool:
    """Whether a residual of this mean square is dust: under :data:`NEGLIGIBLE` of its regressand's
    variance, or under :data:`DUST_RMS` squared (a noise-free hover, whose regressand is dust too).

    Examples
    --------
    >>> negligible_residual(4e-27), negligible_residual(1e-6, 1.0), negligible_residual(1e-3, 1.0)
    (True, True, False)
    """
    return mean_square <= NEGLIGIBLE * y_var or mean_square <= DUST_RMS**2


def judge(checks: dict) -> dict:
    """The verdict from the checks' results: ``{"verdict", "fits", "reasons", "checks"}``.

    ``checks``: name -> ``{"ok": bool, "why": str, ...}``; the verdict fits when every one is ok.
    A check that passed keeps no ``why`` (``""``): its sentence says how it would have failed.

    Examples
    --------
    >>> judge({"held_out": {"ok": True, "why": ""}})["verdict"]
    'fits'
    >>> judge({"held_out": {"ok": False, "why": "yaw residual 3x"}})["reasons"]
    ['yaw residual 3x']
    >>> judge({"commands": {"ok": True, "why": "the commands between samples are unknown"}})["checks"]
    {'commands': {'ok': True, 'why': ''}}
    """
    checks = {name: c if not c["ok"] else {**c, "why": ""} for name, c in checks.items()}
    reasons = [c["why"] for c in checks.values() if not c["ok"]]
    return {"verdict": NOT_FIT if reasons else FITS, "fits": not reasons, "reasons": reasons, "checks": checks}


def residual_checks(
    resid_fit: dict, resid_held: dict, seg_fit: np.ndarray, window: int, y_fit: dict | None = None, y_held=None
) -> dict:
    """The held-out and whiteness checks on each equation's residuals (fitted rows and held-out rows).

    Parameters
    ----------
    resid_fit, resid_held : dict
        Equation -> its residuals on the fitted and on the held-out rows.
    seg_fit : numpy.ndarray
        The fitted rows' segment indices.
    window : int
        The filter window [samples].
    y_fit, y_held : dict, optional
        Equation -> its regressand on the same rows: a residual under :data:`NEGLIGIBLE` of its
        variance fails neither check (a noise-free log's residual is numerical and modelling dust).

    Returns
    -------
    dict
        ``held_out`` and ``white``, each ``{"ok", "why", per equation's figure}``.
    """
    ratios, late = {}, {}
    lag = WHITE_LAG_WINDOWS * window
    for c, e in resid_fit.items():
        fitted = float(np.mean(e**2))
        held = resid_held.get(c)
        if held is not None and held.size and fitted > 0:
            ratios[c] = float(np.mean(held**2) / fitted)
        late[c] = late_autocorrelation(e, seg_fit, lag)

    def negligible(c, e, y):
        return negligible_residual(float(np.mean(e**2)), float(np.var(y[c])) if y is not None and c in y else 0.0)

    bad_held = {c: r for c, r in ratios.items() if not r <= MAX_HELD_RATIO and not negligible(c, resid_held[c], y_held)}
    bad_white = {c: a for c, a in late.items() if not abs(a) <= MAX_LATE_ACF and not negligible(c, resid_fit[c], y_fit)}
    return {
        "held_out": {
            "ok": not bad_held,
            "ratio": ratios,
            "why": "held-out residuals "
            + ", ".join(f"{c} {r:.2g}x" for c, r in bad_held.items())
            + f" the fitted ones' mean square (at most {MAX_HELD_RATIO:g}x): the model does not predict "
            "what it was not fitted on",
        },
        "white": {
            "ok": not bad_white,
            "autocorrelation": late,
            "lag_samples": lag,
            "why": "residuals correlated "
            + ", ".join(f"{c} {a:.2f}" for c, a in bad_white.items())
            + f" at {lag} samples ({WHITE_LAG_WINDOWS} filter windows; at most {MAX_LATE_ACF:g}): a dynamic "
            "the model lacks",
        },
    }


def segment_check(first: dict, second: dict) -> dict:
    """Whether the parameters fitted on two halves of the log agree.

    Parameters
    ----------
    first, second : dict
        Name -> ``{"value", "se"}`` from each half (a parameter with a non-finite standard error
        in either half is not compared; standard errors are floored at 1e-6 of the value).

    Returns
    -------
    dict
        ``{"ok", "why", "z": name -> |a - b| / sqrt(se_a^2 + se_b^2)}``.

    Examples
    --------
    >>> segment_check({"K": {"value": 1.0, "se": 0.01}}, {"K": {"value": 1.1, "se": 0.01}})["ok"]
    False
    """
    z = {}
    for name, a in first.items():
        b = second.get(name)
        if b is None:
            continue
        # a floor of 1e-6 of the value: a noise-free log's standard errors are numerical dust
        floor = 1e-6 * max(abs(a["value"]), abs(b["value"]))
        scale = float(np.sqrt(a["se"] ** 2 + b["se"] ** 2 + floor**2))
        if np.isfinite(scale) and scale > 0 and np.isfinite(a["value"]) and np.isfinite(b["value"]):
            z[name] = abs(a["value"] - b["value"]) / scale
    bad = {k: v for k, v in z.items() if v > MAX_SEGMENT_Z}
    return {
        "ok": not bad,
        "z": z,
        "why": "the two halves of the log give different "
        + ", ".join(f"{k} ({v:.1f} standard errors apart)" for k, v in bad.items())
        + f" (at most {MAX_SEGMENT_Z:g}): the parameters are not constant in this model",
    }


def command_check(
    cmd_hz: float, control_hz: float | None, still: float = 0.0, level: float | None = None, every: bool = False
) -> dict:
    """Whether the log holds every command its controller computed, or commands that did not change
    between its samples.

    ``still`` is the share of consecutive logged commands that did not change at all (an open-loop
    schedule of steps: what was not logged equals what was, but at its steps); at least
    :data:`STILL_SHARE` passes however slowly they are logged. ``level``, when given, is the largest
    spread of a rotor's commands over their mean on a log whose command changes identify nothing
    (a hover: no inertia, ``d`` nor lag identifiable); under :data:`LEVEL_SPREAD` it passes too (what
    is fitted comes from the commands' level, which sampling keeps). ``every``: the log says it holds
    every command (PX4's system-identification logging profile, its commands at the body rates'
    rate). A log that says neither its control rate (``control_hz`` None) nor ``every`` passes only
    when its commands are held, repeating exactly (``still`` at least :data:`HELD_SHARE`): commands
    changing at (nearly) every sample were sampled.

    Examples
    --------
    >>> command_check(100.0, 1000.0)["ok"], command_check(1000.0, 1000.0)["ok"], command_check(250.0, None)["ok"]
    (False, True, False)
    >>> command_check(250.0, None, still=0.75)["ok"], command_check(250.0, None, every=True)["ok"]
    (True, True)
    >>> command_check(250.0, 1000.0, still=0.99)["ok"]
    True
    >>> command_check(250.0, 1000.0, level=0.02)["ok"], command_check(250.0, 1000.0, level=0.3)["ok"]
    (True, False)
    """
    level_only = level is not None and level < LEVEL_SPREAD
    if control_hz is None and not every:
        ok = still >= HELD_SHARE or level_only
        why = (
            f"the log does not say its control rate and its commands (logged at {cmd_hz:g} Hz) change at "
            f"{100 * (1 - still):.0f} % of its samples: sampled, not held, so the commands between samples "
            "are unknown (log every command, PX4: SDLOG_PROFILE with bit 3, or state the controller's rate: "
            "the log's IMU_GYRO_RATEMAX)"
        )
    else:
        ok = every or control_hz is None or cmd_hz >= SAMPLED_SHARE * control_hz or still >= STILL_SHARE or level_only
        why = (
            f"the commands are logged at {cmd_hz:g} Hz and the controller computed them at "
            f"{control_hz or 0:g} Hz, changing between samples ({100 * (1 - still):.0f} % of them): the commands "
            "between samples are unknown (log every command: PX4's system-identification profile)"
        )
    return {
        "ok": bool(ok),
        "command_hz": cmd_hz,
        "control_hz": control_hz,
        "unchanged_share": still,
        "level_spread": level,
        "every_logged": bool(every),
        "why": why,
    }


def unchanged_share(u: np.ndarray, segment: np.ndarray) -> float:
    """The share of consecutive samples (within segments) whose commands did not change at all.

    Examples
    --------
    >>> unchanged_share(np.array([[0.5], [0.5], [0.6], [0.6]]), np.zeros(4, int))
    0.6666666666666666
    """
    if len(u) < 2:
        return 0.0
    same = np.all(u[1:] == u[:-1], axis=1) & (segment[1:] == segment[:-1])
    pairs = int(np.sum(segment[1:] == segment[:-1]))
    return float(np.sum(same)) / pairs if pairs else 0.0


def structure_check(sigma: dict, other_sigma: dict, lag_of: str, other: str, y_var: dict | None = None) -> dict:
    """Whether the other lag structure (a rotor's speed lagging, its thrust the square; or the
    paper's thrust lagging) fits the log better: each equation's residual variance against the
    model's; better by more than :data:`BETTER_STRUCTURE` on any equation fails.

    Examples
    --------
    >>> structure_check({"thrust": 1.0}, {"thrust": 0.5}, "thrust", "speed")["ok"]
    False
    """
    ratio = {c: (other_sigma[c] / sigma[c]) ** 2 for c in sigma if sigma[c] > 0}
    dust = {c for c in ratio if negligible_residual(sigma[c] ** 2, (y_var or {}).get(c, 0.0))}
    bad = {c: r for c, r in ratio.items() if r < 1.0 - BETTER_STRUCTURE and c not in dust}
    what = {
        "speed": "the rotors' speed lagging (a rotor-plant vehicle: --vehicle iris, a file)",
        "thrust": "the thrust lagging (the paper's plant: --vehicle paper)",
    }
    return {
        "ok": not bad,
        "variance_ratio": ratio,
        "other": other,
        "why": f"the log fits {what[other]} better than this model's {lag_of} lag: residual variance "
        + ", ".join(f"{c} {100 * (1 - r):.0f} % lower" for c, r in bad.items())
        + " (or neither is the vehicle's: unequal motor time constants, a missing term)",
    }


def withhold(table: dict, verdict: dict) -> dict:
    """The table of a model that does not fit: each value the best fit's, no interval, not identifiable.

    Parameters
    ----------
    table : dict
        Name -> row (:func:`_table`).
    verdict : dict
        :func:`quadcruise.sysid.verdict.judge`'s.

    Returns
    -------
    dict
    """
    out = {}
    for name, row in table.items():
        row = dict(row)
        if row["identifiable"]:
            row.update(
                identifiable=False,
                ci95=[None, None],
                source="log (best fit of a model that does not fit)",
                note="no interval: the model does not fit this log (the verdict says why)",
                estimate=row["value"],
            )
        out[name] = row
    return out


def paper_verdict(flight, sig, fit_rows, held, rotors, result, mass, g, cmd_hz, rates, level=None) -> dict:
    """The checks of this module on the paper plant's fit (:func:`quadcruise.sysid.api.identify`'s
    signals, rows, rotors, :class:`~quadcruise.sysid.estimate.Fit`, mass, gravity, command rate and
    :func:`~quadcruise.sysid.logprep.log_rates`; ``level``: :func:`command_check`'s): :func:`judge`'s
    verdict."""
    from quadcruise.sysid.equations import regressions
    from quadcruise.sysid.estimate import fit
    from quadcruise.sysid.physical import parameters

    shape = "KQ" in result.names
    data = regressions(sig, result.omega, result.shape_f, rotors, shape)
    beta = result.coefficients()
    resid = {c: data[c][0] - data[c][1] @ beta[c] for c in data}
    checks = residual_checks(
        {c: e[fit_rows] for c, e in resid.items()},
        {c: e[held] for c, e in resid.items()},
        sig.segment[fit_rows],
        sig.window,
        {c: data[c][0][fit_rows] for c in data},
        {c: data[c][0][held] for c in data},
    )
    idx = np.flatnonzero(fit_rows)
    halves = []
    for part in (idx[: len(idx) // 2], idx[len(idx) // 2 :]):
        rows = np.zeros_like(fit_rows)
        rows[part] = True
        try:
            again = fit(
                sig,
                rows,
                rotors,
                result.omega,
                result.shape_f,
                fit_omega=False,
                fit_shape=False,
                omega_bounds=(result.omega, result.omega),
            )
            found = parameters(again, mass, flight.n_rotors, g)
        except (np.linalg.LinAlgError, ValueError):
            found = {}
        halves.append({k: v for k, v in found.items() if v["identifiable"]})
    checks["segments"] = segment_check(*halves)
    profile = int(flight.parameters.get("SDLOG_PROFILE", 0) or 0)
    checks["commands"] = command_check(
        cmd_hz,
        control_rate(rates, rates),
        unchanged_share(flight.u, flight.segment),
        level,
        # PX4's system-identification profile logs every command: at the grid's (the body rates') rate
        every=bool(profile & SYSID_PROFILE_BIT) and cmd_hz >= SAMPLED_SHARE / sig.dt,
    )
    other = "speed" if sig.lag_of == "thrust" else "thrust"
    alt = fit(
        dataclasses.replace(sig, lag_of=other),
        fit_rows,
        rotors,
        result.omega,
        result.shape_f,
        fit_omega=result.omega_fitted,
        fit_shape=False,
        omega_bounds=(0.5, min(500.0, 0.5 / sig.dt)),
    )
    y_var = {c: float(np.var(data[c][0][fit_rows])) for c in data}
    checks["structure"] = structure_check(result.sigma, alt.sigma, sig.lag_of, other, y_var)
    return judge(checks)


def rotor_verdict(data, betas, fit_rows, held, segment, window, refit_half) -> dict:
    """The held-out, whiteness and segment checks on the rotor plant's rigid-body fit.

    Parameters
    ----------
    data : dict
        :func:`quadcruise.sysid.rotor.regressions`' output (a channel may stack two equations).
    betas : dict
        Each channel's coefficients.
    fit_rows, held : numpy.ndarray
        The samples fitted and held out (bool).
    segment : numpy.ndarray
        Each sample's segment.
    window : int
        The filter window [samples].
    refit_half : callable
        ``refit_half(rows)`` -> name -> ``{"value", "se", "identifiable"}`` fitted on ``rows`` alone.

    Returns
    -------
    dict
        :func:`judge`'s verdict.
    """
    n = len(segment)
    fitted, out_of_fit, seg_fit, ys = {}, {}, {}, {}
    for c, (y, X, _) in data.items():
        stacked = len(y) > n
        rows_f = np.r_[fit_rows, fit_rows] if stacked else fit_rows
        rows_h = np.r_[held, held] if stacked else held
        seg = np.r_[segment, segment + int(segment.max()) + 1] if stacked else segment
        e = y - X @ betas[c]
        ok = np.isfinite(e)
        fitted[c], out_of_fit[c], seg_fit[c] = e[rows_f & ok], e[rows_h & ok], seg[rows_f & ok]
        ys[c] = (y[rows_f & ok], y[rows_h & ok])
    checks = {}
    for c in data:
        one = residual_checks({c: fitted[c]}, {c: out_of_fit[c]}, seg_fit[c], window, {c: ys[c][0]}, {c: ys[c][1]})
        for name, check in one.items():
            merged = checks.setdefault(name, {"ok": True, "why": "", "channels": {}})
            merged["channels"][c] = {k: v for k, v in check.items() if k not in ("ok", "why")}
            if not check["ok"]:
                merged["ok"] = False
                merged["why"] = (merged["why"] + "; " if merged["why"] else "") + check["why"]
    idx = np.flatnonzero(fit_rows)
    halves = []
    for part in (idx[: len(idx) // 2], idx[len(idx) // 2 :]):
        rows = np.zeros_like(fit_rows)
        rows[part] = True
        try:
            found = refit_half(rows)
        except (np.linalg.LinAlgError, ValueError):
            found = {}
        halves.append({k: v for k, v in found.items() if v["identifiable"]})
    checks["segments"] = segment_check(*halves)
    return judge(checks)
