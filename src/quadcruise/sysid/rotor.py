"""The rotor-speed plant identified from a log with measured rotor speeds (PX4 ``esc_status``).

Two estimators, each the least squares of the equation it fits (why: docs/identify.md, "A
rotor-plant vehicle"):

**Rigid body, equation error with the logged speeds as regressors** (body FLU, still air; each
side through the matched Savitzky-Golay filters of :mod:`quadcruise.sysid.equations`)::

    a_z      = (kf/m) sum w_i^2 - (k_z/m) sum w_i v_iz                   accelerometer z
    a_x, a_y = -(k_d/m) sum w_i v_ix (v_iy) + trims                      accelerometer x, y
    p'  = k1 q r + (kf/Jxx) sum  y_i w_i^2 + a_x M_x + g_x q sum s_i w_i + c_x
    q'  = k3 p r + (kf/Jyy) sum -x_i w_i^2 + a_y M_y - g_y p sum s_i w_i + c_y
    r'  = k5 p q + (km/Jzz) sum  s_i w_i^2 + a_z M_z + g_z d/dt sum s_i w_i + c_z

with ``v_i = R^T v + Omega x r_i`` each hub's airspeed, ``M`` the aerodynamic moment of
:mod:`quadcruise.model.rotor_plant` at the identified ``k_d``, ``k_z`` (free scale ``a``: ~1/J),
``g = J_rotor / J`` the rotors' gyroscopic and reaction torques (columns only where the base
vehicle has a rotor inertia). Jzz from the gyroscopic terms ``k1 = (Jyy - Jzz)/Jxx``,
``k3 = (Jzz - Jxx)/Jyy`` (inverse-variance weighted), then ``km``.

**Motors, one-step prediction of the logged speeds from the logged commands** (each command
held for a sample, the exact discretisation of ``w' = (c - w)/tau``)::

    w[k+1] = c[k] + (w[k] - c[k]) exp(-dt / tau),   tau = tau_up if c[k] > w[k] else tau_down

``c = s_w u_hat``: a normalised command ``u`` is a speed through PX4's thrust model
(``u_hat = sqrt((1 - f) u + f u^2)``, ``f`` the log's ``THR_MDL_FAC``) with the scale ``s_w``
(``w_max``) fitted too; commands in rad/s are the speeds.
"""

from __future__ import annotations

import math

import numpy as np
from scipy.optimize import least_squares

from quadcruise.sysid.equations import smooth
from quadcruise.sysid.estimate import hac_bandwidth, sandwich
from quadcruise.sysid.physical import CONSISTENCY_SIGMAS, RELATIVE_HALF_WIDTH, Z95

ROTOR_UNITS = {
    "kf": "N/(rad/s)^2",
    "km": "N m/(rad/s)^2",
    "Jxx": "kg m^2",
    "Jyy": "kg m^2",
    "Jzz": "kg m^2",
    "k_d": "N/(rad/s m/s)",
    "k_z": "N/(rad/s m/s)",
    "J_rotor": "kg m^2",
    "tau_up": "s",
    "tau_down": "s",
    "w_max": "rad/s",
    "hover_speed": "rad/s",
    "hover_duty": "-",
}
"""Each identified rotor-plant parameter's unit (``_per_m``: the same over kg)."""
VELOCITY_SAMPLES = 15
"""The velocity's own samples (PX4 logs ``vehicle_local_position`` at 50 Hz) its smoothing spans
before it becomes a drag regressor (errors in variables: docs/identify.md)."""
MIN_GAP_SAMPLES = 200
"""The least number of samples, per direction, whose command differs from the speed by more than
1 % of the hover speed, for that direction's time constant to be fitted."""


def body_airspeed(flight, velocity: np.ndarray | None = None) -> np.ndarray:
    """The body-frame velocity ``R^T v`` (still air) [m/s] of every sample.

    Parameters
    ----------
    flight : FlightLog
        The log (its attitudes and velocities).
    velocity : numpy.ndarray, optional
        (L, 3) world velocities [m/s] to use instead of the log's.

    Returns
    -------
    numpy.ndarray
        (L, 3) body-frame velocities [m/s].
    """
    return flight.rotation().inv().apply(flight.velocity if velocity is None else velocity)


def hub_airspeeds(v_body: np.ndarray, rates: np.ndarray, hubs: np.ndarray) -> np.ndarray:
    """Each hub's airspeed ``v_b + Omega x r_i`` [m/s].

    Parameters
    ----------
    v_body : numpy.ndarray
        (L, 3) body-frame velocities [m/s].
    rates : numpy.ndarray
        (L, 3) body rates [rad/s].
    hubs : numpy.ndarray
        (n, 3) hub positions [m] (FLU).

    Returns
    -------
    numpy.ndarray
        (L, n, 3) airspeeds [m/s].
    """
    return v_body[:, None, :] + np.cross(rates[:, None, :], hubs[None, :, :])


def aero_moment(speeds, v_hub, hubs, k_d: float, k_z: float, k_h: float, k_flap: float) -> np.ndarray:
    """The rotors' aerodynamic moment [N m] as :mod:`quadcruise.model.rotor_plant` computes it.

    Parameters
    ----------
    speeds : numpy.ndarray
        (L, n) rotor speeds [rad/s].
    v_hub : numpy.ndarray
        (L, n, 3) hub airspeeds [m/s].
    hubs : numpy.ndarray
        (n, 3) hub positions [m].
    k_d, k_z, k_h, k_flap : float
        Rotor drag, induced inflow, translational lift and flapping coefficients.

    Returns
    -------
    numpy.ndarray
        (L, 3) body moments [N m].
    """
    h = -speeds[:, :, None] * np.array([k_d, k_d, k_z]) * v_hub
    h[:, :, 2] += k_h * (v_hub[:, :, 0] ** 2 + v_hub[:, :, 1] ** 2)
    moment = np.cross(hubs[None, :, :], h).sum(1)
    flap = np.cross(v_hub, np.array([0.0, 0.0, 1.0]))
    moment -= k_flap * (speeds[:, :, None] * flap).sum(1)
    return moment


def denoised(x: np.ndarray, segment: np.ndarray, window: int) -> np.ndarray:
    """``x`` through a Savitzky-Golay smoothing filter (order 2, zero phase) within each segment.

    The gyroscopic products ``q r``, ``p r``, ``q sum s_i w_i`` and the drag's ``w_i v_i`` are
    regressors: sensor noise in them biases their coefficients toward zero (errors in variables;
    0.02 m/s of velocity noise biased the Iris's k_d by -0.3 %, twice its interval). Smoothed
    first, their noise variance is some thirty times smaller, and an order-2 filter leaves the
    doublets' shape (docs/identify.md).
    """
    from scipy.signal import savgol_filter

    out = np.array(x, dtype=np.float64)
    for k in np.unique(segment):
        rows = segment == k
        if rows.sum() > window:
            out[rows] = savgol_filter(out[rows], window, 2, axis=0, mode="interp")
    return out


def regressions(flight, speeds, hubs, window, dt, aero, gyro: bool):
    """The rigid-body regressions (the module's equations) at a filter window.

    Parameters
    ----------
    flight : FlightLog
        The log: rates, attitudes, velocities, accelerometer.
    speeds : numpy.ndarray
        (L, n) measured rotor speeds [rad/s].
    hubs : numpy.ndarray
        (n, 4) rotor x, y, z [m] and direction s.
    window : int
        The Savitzky-Golay window [samples].
    dt : float
        The grid's step [s].
    aero : tuple
        (k_d, k_z, k_h, k_flap, c_D (3,), m): the aerodynamic terms taken as known.
    gyro : bool
        Include the rotors' gyroscopic and reaction columns.

    Returns
    -------
    dict
        Channel (``thrust``, ``drag``, ``roll``, ``pitch``, ``yaw``) -> (y, X, coefficient names);
        ``drag`` stacks the x and y equations.
    """
    seg = flight.segment
    rates = denoised(flight.rates, seg, window)
    force = flight.specific_force
    k_d, k_z, k_h, k_flap, c_d, m = aero
    v_hz = float(flight.rates_hz.get("vehicle_local_position", flight.rates_hz.get("csv", 1.0 / dt)))
    v_window = max(window, round(VELOCITY_SAMPLES / (v_hz * dt)) | 1)  # velocity logged slower than the rates
    v_b = body_airspeed(flight, denoised(flight.velocity, seg, v_window))
    pos = hubs[:, :3]
    v_hub = hub_airspeeds(v_b, rates, pos)
    w2 = speeds**2
    x, y, s = hubs[:, 0], hubs[:, 1], hubs[:, 3]
    # known parts of the force (translational lift, parasitic drag), per unit mass
    lift = k_h * (v_hub[:, :, 0] ** 2 + v_hub[:, :, 1] ** 2).sum(1) / m
    parasitic = -np.linalg.norm(v_b, axis=1)[:, None] * c_d * v_b / m

    def f(z):
        return smooth(z, seg, window)

    def d(z):
        return smooth(z, seg, window, deriv=1, dt=dt)

    out = {}
    out["thrust"] = (
        f(force[:, 2] - lift - parasitic[:, 2]),
        np.column_stack([f(w2.sum(1)), f((speeds * v_hub[:, :, 2]).sum(1))]),
        ("kf_m", "kz_m"),
    )
    ones = np.ones(len(seg))
    zeros = np.zeros(len(seg))
    fx = f(force[:, 0] - parasitic[:, 0])
    fy = f(force[:, 1] - parasitic[:, 1])
    rx = f((speeds * v_hub[:, :, 0]).sum(1))
    ry = f((speeds * v_hub[:, :, 1]).sum(1))
    out["drag"] = (
        np.r_[fx, fy],
        np.column_stack([np.r_[rx, ry], np.r_[ones, zeros], np.r_[zeros, ones]]),
        ("kd_m", "c_ax", "c_ay"),
    )
    moment = aero_moment(speeds, v_hub, pos, k_d, k_z, k_h, k_flap)
    spin = (speeds * s).sum(1)
    rate_dot = d(flight.rates)
    products = f(np.column_stack([rates[:, 1] * rates[:, 2], rates[:, 0] * rates[:, 2], rates[:, 0] * rates[:, 1]]))
    arms = {"roll": w2 @ y, "pitch": w2 @ -x, "yaw": w2 @ s}
    gyro_cols = {"roll": f(rates[:, 1] * spin), "pitch": f(-rates[:, 0] * spin), "yaw": d(spin)}
    for axis, name in enumerate(("roll", "pitch", "yaw")):
        cols = [products[:, axis], f(arms[name])]
        names = [f"k_{name}", f"b_{name}"]
        if np.any(moment[:, axis] != 0.0):
            cols.append(f(moment[:, axis]))
            names.append(f"a_{name}")
        if gyro:
            cols.append(gyro_cols[name])
            names.append(f"g_{name}")
        cols.append(ones)
        names.append(f"c_{name}")
        out[name] = (rate_dot[:, axis], np.column_stack(cols), tuple(names))
    return out


def fit_rigid_body(data: dict, rows: np.ndarray, segment: np.ndarray, window: int, covariance: bool = True):
    """Each channel's least squares and all coefficients' Newey-West covariance.

    Parameters
    ----------
    data : dict
        :func:`regressions`' output.
    rows : numpy.ndarray
        The samples fitted (bool).
    segment : numpy.ndarray
        Each sample's segment.
    window : int
        The filter window [samples] (the least HAC bandwidth is twice it).
    covariance : bool
        Compute the covariance (NaN without: the refits of the systematic terms need only the values).

    Returns
    -------
    tuple
        ``(names, values, cov, sigma, bandwidth, betas)``.
    """
    channels = list(data)
    n_all = len(segment)
    good = rows.copy()
    for c in channels:
        y, X, _ = data[c]
        ok = np.all(np.isfinite(X), axis=1) & np.isfinite(y)
        good &= ok[:n_all] & (ok[n_all:] if len(ok) > n_all else True)
    rows_of = {c: (np.r_[good, good] if len(data[c][0]) > n_all else good) for c in channels}
    betas, resid, sigma = {}, {}, {}
    for c in channels:
        y, X, _ = data[c]
        r = rows_of[c]
        betas[c], *_ = np.linalg.lstsq(X[r], y[r], rcond=None)
        resid[c] = y[r] - X[r] @ betas[c]
        # the paper plant's floor (estimate.py): a noise-free hover's residual is exactly 0, and
        # 1e-300 squared underflows to a division by zero (NaN covariance, eigh failing)
        sigma[c] = max(float(np.std(resid[c])), 1e-12)
    names = [n for c in channels for n in data[c][2]]
    p = len(names)
    values = np.concatenate([betas[c] for c in channels])
    if not covariance:
        return names, values, np.full((p, p), np.nan), sigma, 0, betas
    n = int(good.sum())
    bread = np.zeros((p, p))
    score = np.zeros((n, p))
    k = 0
    for c in channels:
        X = data[c][1][rows_of[c]]
        width = X.shape[1]
        bread[k : k + width, k : k + width] += X.T @ X / sigma[c] ** 2
        contrib = X * (resid[c] / sigma[c] ** 2)[:, None]
        if len(contrib) > n:  # the stacked x and y equations: one score per sample
            contrib = contrib[:n] + contrib[n:]
        score[:, k : k + width] += contrib
        k += width
    seg = segment[good]
    bandwidth = hac_bandwidth({c: resid[c][:n] for c in channels}, seg, window)
    meat = bartlett_meat(score, seg, bandwidth)
    cov = sandwich(bread, meat)
    return names, values, cov, sigma, bandwidth, betas


def bartlett_meat(score: np.ndarray, segment: np.ndarray, lag: int) -> np.ndarray:
    """The Newey-West (Bartlett) long-run covariance of the score rows, by moving sums:
    ``sum_t S_t S_t^T / (lag + 1)`` with ``S_t`` the sum of ``lag + 1`` consecutive rows of one segment,
    which is ``sum_j (1 - |j| / (lag + 1)) Gamma_j`` but for the segments' ends (``O(n p^2)``,
    not ``O(n p^2 lag)``).

    Examples
    --------
    >>> s = np.random.default_rng(1).standard_normal((4000, 1))
    >>> round(float(bartlett_meat(s, np.zeros(4000, int), 0)[0, 0] / (s.T @ s)[0, 0]), 6)
    1.0
    """
    out = np.zeros((score.shape[1], score.shape[1]))
    width = lag + 1
    for k in np.unique(segment):
        block = score[segment == k]
        if len(block) == 0:
            continue
        if len(block) < width:
            total = block.sum(0)
            out += np.outer(total, total) / width
            continue
        csum = np.vstack([np.zeros((1, block.shape[1])), np.cumsum(block, axis=0)])
        sums = csum[width:] - csum[:-width]
        # the ends: partial windows, so each row's own variance counts (lag + 1) times in all
        head = csum[1:width]
        tail = csum[-1] - csum[-width:-1]
        out += (sums.T @ sums + head.T @ head + tail.T @ tail) / width
    return out


def rigid_body_mapping(names, mass: float | None, n_rotors: int, g: float, weights: tuple[float, float]):
    """The map from the coefficient vector to the physical parameters.

    Parameters
    ----------
    names : sequence of str
        The coefficients' names, in order.
    mass : float or None
        The mass [kg]; None: per unit mass (``_per_m``).
    n_rotors : int
        Number of rotors.
    g : float
        Gravity [m/s^2].
    weights : tuple of float
        The weights of roll's and pitch's estimates of Jzz.

    Returns
    -------
    callable
        ``values -> {parameter: value}``: kf, km, Jxx, Jyy, Jzz, k_d, k_z, hover_speed (J_rotor).
    """
    idx = {n: i for i, n in enumerate(names)}
    scale = 1.0 if mass is None else float(mass)
    suffix = "_per_m" if mass is None else ""
    w1, w2 = weights

    def phys(v):
        kf = v[idx["kf_m"]]
        jxx, jyy = kf / v[idx["b_roll"]], kf / v[idx["b_pitch"]]
        jzz = w1 * (jyy - v[idx["k_roll"]] * jxx) + w2 * (jxx + v[idx["k_pitch"]] * jyy)
        out = {
            f"kf{suffix}": kf * scale,
            f"km{suffix}": v[idx["b_yaw"]] * jzz * scale,
            f"Jxx{suffix}": jxx * scale,
            f"Jyy{suffix}": jyy * scale,
            f"Jzz{suffix}": jzz * scale,
            f"k_d{suffix}": -v[idx["kd_m"]] * scale,
            f"k_z{suffix}": -v[idx["kz_m"]] * scale,
            "hover_speed": math.sqrt(g / (n_rotors * kf)) if kf > 0 else float("nan"),
        }
        if "g_yaw" in idx:
            out[f"J_rotor{suffix}"] = v[idx["g_yaw"]] * jzz * scale
        return out

    return phys


def rigid_body_parameters(names, values, cov, mass, n_rotors, g, systematic=None, coupling=(True, True)):
    """Physical parameters with 95 % intervals (delta method), as :func:`quadcruise.sysid.physical.parameters`.

    Parameters
    ----------
    names, values, cov : sequence, numpy.ndarray, numpy.ndarray
        The coefficients and their covariance (:func:`fit_rigid_body`).
    mass : float or None
        The mass [kg]; None: per unit mass.
    n_rotors : int
        Number of rotors.
    g : float
        Gravity [m/s^2].
    systematic : dict, optional
        Name -> a uniform systematic error's half-range, added in quadrature.
    coupling : tuple of bool
        Whether roll's and pitch's gyroscopic terms may give Jzz.

    Returns
    -------
    tuple
        (name -> ``{"value", "se", "ci95", "identifiable"}``, the Jzz weights used).
    """
    from quadcruise.sysid.physical import jacobian

    finite = np.where(np.isfinite(cov), cov, 0.0)
    blind = ~np.isfinite(np.diag(cov))
    est, jzz, grads = [], [], []
    for w in ((1.0, 0.0), (0.0, 1.0)):
        keys, vals, jac = jacobian(rigid_body_mapping(names, mass, n_rotors, g, w), values)
        k = next(i for i, n in enumerate(keys) if n.startswith("Jzz"))
        row = np.nan_to_num(jac[k])
        seen = np.all(np.isfinite(jac[k])) and not np.any(row[blind] != 0)
        est.append(float(row @ finite @ row) if seen else np.inf)
        jzz.append(float(vals[k]))
        grads.append(row)
    diff_var = float((grads[0] - grads[1]) @ finite @ (grads[0] - grads[1]))
    consistent = not (
        all(np.isfinite(est))
        and all(coupling)
        and diff_var > 0
        and abs(jzz[0] - jzz[1]) > CONSISTENCY_SIGMAS * math.sqrt(diff_var)
    )
    inv = [1.0 / v if v > 0 and np.isfinite(v) and ok else 0.0 for v, ok in zip(est, coupling, strict=False)]
    weights = (0.5, 0.5) if sum(inv) == 0 else (inv[0] / sum(inv), inv[1] / sum(inv))
    keys, vals, jac = jacobian(rigid_body_mapping(names, mass, n_rotors, g, weights), values)
    full = np.nan_to_num(jac) @ finite @ np.nan_to_num(jac).T
    unseen = ~np.all(np.isfinite(jac), axis=1) | np.any(np.abs(np.nan_to_num(jac[:, blind], nan=1.0)) > 0, axis=1)
    out = {}
    for i, name in enumerate(keys):
        var = np.inf if unseen[i] else max(full[i, i], 0.0)
        extra = (systematic or {}).get(name, 0.0)
        se = float(math.sqrt(var + extra * extra / 3.0))
        value = float(vals[i])
        ok = bool(np.isfinite(value) and np.isfinite(se) and value > 0 and Z95 * se <= RELATIVE_HALF_WIDTH * value)
        row = {"value": value, "se": se, "ci95": [value - Z95 * se, value + Z95 * se], "identifiable": ok}
        if not consistent and (name.startswith(("Jzz", "km", "J_rotor"))):
            row["identifiable"] = False
            row["inconsistent"] = (
                f"roll's and pitch's gyroscopic terms give Jzz {jzz[0]:.4g} and {jzz[1]:.4g} (more than "
                f"{CONSISTENCY_SIGMAS:g} standard errors apart): the log does not fit the model there"
            )
        if not all(coupling) and not any(coupling) and name.startswith(("Jzz", "km", "J_rotor")):
            row["identifiable"] = False
        out[name] = row
    return out, weights


def command_speeds(u: np.ndarray, shape_f: float) -> np.ndarray:
    """A normalised command's speed over full speed, through PX4's thrust model: ``sqrt((1-f) u + f u^2)``.

    Parameters
    ----------
    u : numpy.ndarray
        Normalised commands.
    shape_f : float
        PX4's ``THR_MDL_FAC``.

    Returns
    -------
    numpy.ndarray
        Speed over full speed.

    Examples
    --------
    >>> command_speeds(np.array([0.25, 1.0]), 1.0).tolist()
    [0.25, 1.0]
    """
    u = np.clip(u, 0.0, None)
    return np.sqrt((1.0 - shape_f) * u + shape_f * u * u)


def fit_motors(t, segment, rows, speeds, commands, *, scale0: float, fit_scale: bool, tau0: float, hover: float):
    """The motor time constants (and the command's speed scale) by one-step prediction.

    Parameters
    ----------
    t, segment : numpy.ndarray
        The grid [s] and its segments.
    rows : numpy.ndarray
        The samples k fitted (k + 1 in the same segment).
    speeds : numpy.ndarray
        (L, n) measured rotor speeds [rad/s].
    commands : numpy.ndarray
        (L, n) the commands in speed units of ``scale`` (1 for rad/s).
    scale0 : float
        The scale's starting value (``w_max`` of the base vehicle; 1 for rad/s).
    fit_scale : bool
        Fit the scale too.
    tau0 : float
        Starting time constant [s].
    hover : float
        The hover speed [rad/s]: a gap under 1 % of it carries no information on the direction.

    Returns
    -------
    dict
        name -> ``{"value", "se"}`` for ``tau_up``, ``tau_down`` (and ``w_max``), ``samples``
        (per direction), ``rmse`` [rad/s].
    """
    nxt = np.r_[rows[:-1] & (segment[1:] == segment[:-1]), False]
    k = np.flatnonzero(rows & nxt)
    dt = np.diff(t)[k][:, None]
    w0, w1, c = speeds[k], speeds[k + 1], commands[k]
    up_rows = (c * scale0 - w0) > 0.01 * hover
    down_rows = (w0 - c * scale0) > 0.01 * hover
    counts = {"up": int(up_rows.sum()), "down": int(down_rows.sum())}
    has_up, has_down = counts["up"] >= MIN_GAP_SAMPLES, counts["down"] >= MIN_GAP_SAMPLES
    if not (has_up or has_down):
        return {"samples": counts, "rmse": float("nan")}
    names = [n for n, ok in (("tau_up", has_up), ("tau_down", has_down)) if ok] + (["w_max"] if fit_scale else [])
    start = np.log([tau0] * (has_up + has_down) + ([scale0] if fit_scale else []))

    def predict(theta):
        vals = dict(zip(names, np.exp(theta), strict=False))
        scale = vals.get("w_max", scale0)
        target = c * scale
        rising = target > w0
        tau_u = vals.get("tau_up", vals.get("tau_down"))
        tau_d = vals.get("tau_down", vals.get("tau_up"))
        tau = np.where(rising, tau_u, tau_d)
        return target + (w0 - target) * np.exp(-dt / tau)

    use = (up_rows if has_up else False) | (down_rows if has_down else False) | np.zeros_like(up_rows)
    if not has_up:
        use = use & ~up_rows
    if not has_down:
        use = use & ~down_rows

    def residual(theta):
        return (w1 - predict(theta))[use]

    sol = least_squares(residual, start, method="lm", x_scale=np.ones(len(start)))
    r = residual(sol.x)
    jac = sol.jac
    sigma = max(float(np.std(r)), 1e-300)
    # Newey-West over time: per-sample scores summed over the rotors
    score_full = np.zeros((len(k), len(names)))
    flat = np.flatnonzero(use.ravel())
    sample = flat // use.shape[1]
    np.add.at(score_full, sample, jac * (r / sigma**2)[:, None])
    bread = jac.T @ jac / sigma**2
    lag = max(2, min(50, len(k) // 5))
    meat = score_full.T @ score_full
    seg = segment[k]
    for j in range(1, lag + 1):
        same = (seg[j:] == seg[:-j])[:, None]
        gamma = (score_full[j:] * same).T @ score_full[:-j]
        meat += (1.0 - j / (lag + 1.0)) * (gamma + gamma.T)
    cov = sandwich(bread, meat)
    out = {"samples": counts, "rmse": float(np.sqrt(np.mean(r**2)))}
    for i, name in enumerate(names):
        value = float(np.exp(sol.x[i]))
        se = value * math.sqrt(cov[i, i]) if np.isfinite(cov[i, i]) else float("inf")  # d exp(x) = exp(x) dx
        out[name] = {"value": value, "se": se}
    return out


__all__ = [
    "ROTOR_UNITS",
    "aero_moment",
    "body_airspeed",
    "command_speeds",
    "fit_motors",
    "fit_rigid_body",
    "hub_airspeeds",
    "regressions",
    "rigid_body_mapping",
    "rigid_body_parameters",
]
