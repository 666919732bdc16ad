"""The identified model against the held-out tail of the log: R^2 and RMSE per channel.

Linear accelerations (ENU, the logged velocity's derivative against ``R (0, 0, T/m) - g e_z``),
angular accelerations (the fitted equations), and rates over short windows (:data:`WINDOW_S`)
predicted open loop from each window's start. docs/identify.md says what each shows.
"""

from __future__ import annotations

import numpy as np

from quadcruise.sysid.equations import CHANNELS, regressions, smooth
from quadcruise.sysid.estimate import Fit

WINDOW_S = 0.25
"""Length of the open-loop prediction windows [s]."""


def scores(measured: np.ndarray, predicted: np.ndarray) -> dict[str, float]:
    """``r2`` (1 - SSE/SST; NaN when the measurement does not vary) and ``rmse`` of a prediction.

    Examples
    --------
    >>> {k: round(v, 4) for k, v in scores(np.array([0.0, 1.0, 2.0]), np.array([0.0, 1.0, 2.5])).items()}
    {'r2': 0.875, 'rmse': 0.2887}
    """
    err = measured - predicted
    sst = float(np.sum((measured - measured.mean()) ** 2))
    sse = float(err @ err)
    return {"r2": 1.0 - sse / sst if sst > 0 else float("nan"), "rmse": float(np.sqrt(sse / max(len(err), 1)))}


def validate(sig, held: np.ndarray, fit: Fit, rotors: np.ndarray, flight, g: float) -> tuple[dict, dict]:
    """Score the fitted model on the held-out samples: ``(validation, traces)``.

    ``validation``: channel -> ``{"r2", "rmse", "unit"}`` and ``open_loop``; ``traces``: ``t`` and
    each channel's ``measured`` and ``predicted`` on the held-out samples.
    """
    data = regressions(sig, fit.omega, fit.shape_f, rotors, "KQ" in fit.names)
    beta = fit.coefficients()
    pred = {c: data[c][1] @ beta[c] for c in CHANNELS}
    accel = smooth(flight.velocity, sig.segment, sig.window, deriv=1, dt=sig.dt)
    thrust = np.zeros((len(sig.t), 3))
    thrust[:, 2] = pred["thrust"]
    world = flight.rotation().apply(thrust) - np.array([0.0, 0.0, g])
    out, traces = {}, {"t": sig.t[held]}
    for j, name in enumerate(("ax", "ay", "az")):
        out[name] = {**scores(accel[held, j], world[held, j]), "unit": "m/s^2"}
        traces[name] = (accel[held, j], world[held, j])
    for name, c in (("p_dot", "roll"), ("q_dot", "pitch"), ("r_dot", "yaw")):
        out[name] = {**scores(data[c][0][held], pred[c][held]), "unit": "rad/s^2"}
        traces[name] = (data[c][0][held], pred[c][held])
    out["open_loop"] = open_loop(sig, held, data, beta)
    return out, traces


def open_loop(sig, held: np.ndarray, data: dict, beta: dict) -> dict:
    """Rates predicted open loop over short windows: ``window_s``, ``windows``, each rate's R^2 and RMSE."""
    steps = max(1, round(WINDOW_S / sig.dt))
    idx = np.flatnonzero(held)
    starts = [
        i
        for i in idx[::steps]
        if i + steps < len(sig.t) and held[i + steps] and sig.segment[i + steps] == sig.segment[i]
    ]
    effect = {c: data[c][1][:, 1] * beta[c][1] + beta[c][2] for c in ("roll", "pitch", "yaw")}
    k = (beta["roll"][0], beta["pitch"][0], beta["yaw"][0])
    ends, truth = [], []
    for i in starts:
        w = sig.rates[i].copy()
        for s in range(i, i + steps):
            p, q, r = w
            w = w + sig.dt * np.array(
                [k[0] * q * r + effect["roll"][s], k[1] * p * r + effect["pitch"][s], k[2] * p * q + effect["yaw"][s]]
            )
        ends.append(w)
        truth.append(sig.rates[i + steps])
    out: dict = {"window_s": steps * sig.dt, "windows": len(starts)}
    if starts:
        ends_a, truth_a = np.array(ends), np.array(truth)
        for j, name in enumerate("pqr"):
            out[name] = {**scores(truth_a[:, j], ends_a[:, j]), "unit": "rad/s"}
    return out
