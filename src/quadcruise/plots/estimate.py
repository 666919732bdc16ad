"""The estimate a flight flew on, against the truth: what the controller saw beside what the
vehicle did, the errors inside the filter's own 3-sigma bounds, and its NEES (issue 35).

A result is duck-typed (``t``, ``states``, ``observations``), as the other figures take it.

Examples
--------
>>> import quadcruise as qc
>>> from quadcruise.estimation import Ekf, Sensors
>>> r = qc.fly("hover", sensors=Sensors.typical(), estimator=Ekf(), duration=1.0, log_every=10)
>>> [ax.get_ylabel() for ax in plot_estimate(r).axes][:2]
['position [m]', 'position error [m]']
"""

from __future__ import annotations

import numpy as np
from matplotlib.figure import Figure

from quadcruise import layout as L
from quadcruise.metrics.estimate import estimate_metrics

__all__ = ["plot_estimate"]

AXES = ("x", "y", "z")
COLORS = ("tab:blue", "tab:orange", "tab:green")


def _wrap_deg(a: np.ndarray) -> np.ndarray:
    """Angles [rad] as degrees in (-180, 180]."""
    return np.degrees(np.angle(np.exp(1j * a)))


def plot_estimate(result, vehicle: int = 0, *, title: str | None = None) -> Figure:
    """Six panels of one vehicle: position and Euler angles, truth (solid) and estimate (dashed);
    position, velocity and Euler angle errors (truth minus estimate) per axis with the filter's
    ``+-3 sd`` (the attitude's about the body axes, which near level are roll, pitch and yaw's);
    the NEES of position, velocity and attitude (3 dof: 3 on average when consistent).

    Parameters
    ----------
    result : SimResult
        A flight on sensors and an estimator (``observations`` with an estimate).
    vehicle : int
        Which vehicle of a batch.
    title : str, optional
        The figure's title; by default the position and attitude error RMS.

    Returns
    -------
    matplotlib.figure.Figure
    """
    t, x, o = result.t, result.states[vehicle], result.observations[vehicle]
    fig = Figure(figsize=(11, 9), layout="constrained")
    ax = fig.subplots(3, 2, sharex=True).ravel()
    for j, (name, c) in enumerate(zip(AXES, COLORS, strict=True)):
        ax[0].plot(t, x[:, L.X + j], color=c, lw=1.0, label=f"{name}")
        ax[0].plot(t, o[:, L.O_X + j], color=c, lw=1.0, ls="--")
        err = x[:, L.X + j] - o[:, L.O_X + j]
        ax[1].plot(t, err, color=c, lw=0.9, label=f"{name}")
        ax[1].fill_between(t, -3 * o[:, L.O_SD + j], 3 * o[:, L.O_SD + j], color=c, alpha=0.12, lw=0)
        verr = x[:, L.VX + j] - o[:, L.O_VX + j]
        ax[3].plot(t, verr, color=c, lw=0.9, label=f"v{name}")
        ax[3].fill_between(t, -3 * o[:, L.O_SD + 3 + j], 3 * o[:, L.O_SD + 3 + j], color=c, alpha=0.12, lw=0)
    for j, (name, c) in enumerate(zip(("roll", "pitch", "yaw"), COLORS, strict=True)):
        ax[2].plot(t, np.degrees(x[:, L.PHI + j]), color=c, lw=1.0, label=name)
        ax[2].plot(t, np.degrees(o[:, L.O_PHI + j]), color=c, lw=1.0, ls="--")
        aerr = _wrap_deg(x[:, L.PHI + j] - o[:, L.O_PHI + j])
        ax[4].plot(t, aerr, color=c, lw=0.9, label=name)
        ax[4].fill_between(
            t, -3 * np.degrees(o[:, L.O_SD + 6 + j]), 3 * np.degrees(o[:, L.O_SD + 6 + j]), color=c, alpha=0.12, lw=0
        )
    for j, (name, c) in enumerate(zip(("position", "velocity", "attitude"), COLORS, strict=True)):
        ax[5].plot(t, o[:, L.O_NEES + j], color=c, lw=0.8, label=name)
    ax[5].axhline(3.0, color="k", lw=0.8, ls=":")
    ax[5].set_yscale("log")
    labels = (
        "position [m]",
        "position error [m]",
        "attitude [deg]",
        "velocity error [m/s]",
        "Euler angle error [deg]",
        "NEES (3 dof)",
    )
    for a, label in zip(ax, labels, strict=True):
        a.set_ylabel(label)
        a.grid(True, alpha=0.3)
        a.legend(fontsize="small", loc="upper right")
    ax[4].set_xlabel("t [s]")
    ax[5].set_xlabel("t [s]")
    if title is None:
        m = estimate_metrics(result.states, result.observations, vehicle)
        title = (
            f"estimate (dashed) against the truth (solid); shaded: the filter's +-3 sd; error RMS "
            f"{m['estimate_position_rmse_m']:.3g} m, {m['estimate_attitude_rmse_deg']:.3g} deg"
        )
    fig.suptitle(title, fontsize="medium")
    return fig
