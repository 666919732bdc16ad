"""The metrics table of a flight: one row per vehicle of a result, each metric measured on the
transient and the steady window that the mission gives it (:func:`flight_metrics`).

The definitions are those of :mod:`~quadcruise.metrics.step` (rise, settling, overshoot),
:mod:`~quadcruise.metrics.signals` (tracking error, effort, saturation) and
:mod:`~quadcruise.metrics.tracking` (a moving reference's transient), under the conventions of
:mod:`~quadcruise.metrics.conventions`. The same table for a batch, vectorised:
:mod:`quadcruise.metrics.batch`. Each definition and its reason: docs/metrics.md.
"""

from __future__ import annotations

import numpy as np

from quadcruise.errors import InputError
from quadcruise.metrics.conventions import metric_conventions, settling_column
from quadcruise.metrics.declared import metric_names
from quadcruise.metrics.estimate import estimate_metrics, flew_an_estimator
from quadcruise.metrics.signals import control_effort, tracking_errors
from quadcruise.metrics.step import StepInfo, step_info, transient_info
from quadcruise.metrics.tracking import STEADY_BAND, TRANSIENT_MIN_ERROR, moving_reference, tracking_transient_batch

__all__ = [
    "FAILED_FLIGHT_METRICS",
    "TRACKING_AXIS_NAME",
    "flight_metrics",
    "hover_duties",
]


_AXIS_NAMES = ("x", "y", "z")
FAILED_FLIGHT_METRICS = metric_names(kind=("transient", "steady"))
"""The metrics that are NaN for a flight that did not finish (those declared of kind
``transient`` or ``steady``, :mod:`~quadcruise.metrics.declared`): a vehicle that lost its
track has no transient or steady state to measure."""
TRACKING_AXIS_NAME = "xyz"
"""The ``axis`` a moving reference's transient is measured on: the size of the 3-D error."""


def hover_duties(meta, n: int) -> np.ndarray | None:
    """Each vehicle's hover duty m g / (4 K), from the vehicle a result records.

    Parameters
    ----------
    meta : dict
        A result's ``meta``: its ``vehicle`` entry (the flown vehicle's ``to_dict()``: ``m``
        [kg], ``g`` [m/s^2] and ``K`` [N], each a number or one per vehicle) is read; for a
        rotor-plant vehicle its ``paper_equivalent`` (the "+" vehicle whose duties were flown).
    n : int
        Number of vehicles.

    Returns
    -------
    ndarray, shape (n,), or None
        The duty per rotor [-] that holds each vehicle in hover; None if ``meta`` records no
        vehicle (a result built by :func:`quadcruise.simulate` without one).

    Examples
    --------
    >>> hover_duties({"vehicle": {"m": [3.0, 6.0], "g": 10.0, "K": 100.0}}, 2)
    array([0.075, 0.15 ])
    """
    vehicle = (meta.get("paper_equivalent") or meta.get("vehicle")) if isinstance(meta, dict) else None
    if not isinstance(vehicle, dict) or not all(k in vehicle for k in ("m", "g", "K")):
        return None
    try:
        m, g, k = (np.broadcast_to(np.asarray(vehicle[key], dtype=float), (n,)) for key in ("m", "g", "K"))
    except ValueError:
        raise InputError(f"the recorded vehicle does not describe {n} vehicle(s)") from None
    return m * g / (4.0 * k)


def flight_metrics(
    result,
    *,
    transient_axis: str | None = None,
    transient_until: float | None = None,
    rise=(0.1, 0.9),
    settle_bands=(0.02, 0.05),
):
    """Per-vehicle metrics of a :class:`~quadcruise.sim.result.SimResult`, as a DataFrame.

    The transient is measured on ``transient_axis`` if given; else, for a moving reference, on the
    size of the 3-D error against its own steady level (``axis`` ``xyz``); for a step mission, on
    its stepped axis as a step response; else on the axis of the largest initial error if it
    reaches :data:`TRANSIENT_MIN_ERROR`; otherwise not at all. The steady metrics cover the steady
    window of that definition (the whole flight without a transient). NaN: a settling time that
    does not exist, the steady metrics of a transient that never settles, every metric of a
    vehicle that stopped early, and the transient and steady metrics of one that did not finish
    (:data:`FAILED_FLIGHT_METRICS`). Each definition and its reason: docs/metrics.md.

    Parameters
    ----------
    result : SimResult
        The flight (duck-typed: ``t``, ``states``, ``references``, ``commands``, ``status``,
        ``meta`` and the saturation times; ``meta["vehicle"]`` gives the hover duty of the
        effort, :func:`hover_duties`).
    transient_axis : {"x", "y", "z"}, optional
        The axis whose transient is measured, instead of the one chosen as above.
    transient_until : float, optional
        End [s] of the window in which the transient is measured.
    rise : (float, float) or str
        Rise-time levels as fractions of the step: ``(0.1, 0.9)`` (default), ``(0.0, 1.0)``
        (also ``"0-100"``), or any ``0 <= low < high <= 1``.
    settle_bands : (float, float) or float
        Settling bands as fractions of the step: ``settling_time_s`` and the column
        :func:`settling_column` names (5 % if only one is given).

    Returns
    -------
    pandas.DataFrame
        One row per vehicle: ``vehicle``, ``status``, ``rmse_m``, ``max_error_m`` (3-D position
        error over the flight [m]), ``steady_rmse_m``, ``steady_max_error_m``, ``axis``,
        ``rise_time_s``, ``settling_time_s``, ``settling_time_<band>pct_s``, ``overshoot_pct``,
        ``peak_time_s``, ``effort`` (:data:`EFFORT_DEFINITION` [s]; NaN without a vehicle),
        ``duty_clipped_s``, ``controller_limited_s`` [s]; after a flight on an estimator, its
        estimation error (:func:`~quadcruise.metrics.estimate.estimate_metrics`: position [m],
        attitude [deg], NEES); ``attrs["conventions"]`` records the
        conventions (:func:`metric_conventions`).

    Examples
    --------
    >>> import quadcruise as qc
    >>> res = qc.fly("step", duration=2.0)
    >>> flight_metrics(res)[["vehicle", "status", "axis"]]
       vehicle    status axis
    0        0  finished    x
    >>> flight_metrics(res, settle_bands=(0.02, 0.03)).attrs["conventions"]["settle_bands"]
    [0.02, 0.03]
    """
    import pandas as pd

    from quadcruise.layout import CMD_U1, REF_X, X

    conventions = metric_conventions(rise, settle_bands)
    levels, bands = tuple(conventions["rise"]), tuple(conventions["settle_bands"])
    second = settling_column(bands[1])
    t = result.t
    mission = result.meta.get("mission") if isinstance(result.meta.get("mission"), dict) else {}
    hover = hover_duties(result.meta, result.n)
    rows = []
    for i in range(result.n):
        row = {
            "vehicle": i,
            "status": result.status_text(i),
            "rmse_m": np.nan,
            "max_error_m": np.nan,
            "steady_rmse_m": np.nan,
            "steady_max_error_m": np.nan,
            "axis": None,
            "rise_time_s": np.nan,
            "settling_time_s": np.nan,
            second: np.nan,
            "overshoot_pct": np.nan,
            "peak_time_s": np.nan,
            "effort": np.nan,
            "duty_clipped_s": float(result.duty_clipped_s[i]),
            "controller_limited_s": float(result.controller_limited_s[i]),
        }
        rows.append(row)
        if result.stopped[i]:  # the engine stopped it: its later rows are NaN
            continue
        pos, ref = result.states[i, :, X : X + 3], result.references[i, :, REF_X : REF_X + 3]
        if np.all(np.isfinite(ref)):
            err = tracking_errors(t, pos, ref)
            row["rmse_m"], row["max_error_m"] = float(err["rmse"]), float(err["max_error"])
            keep = slice(None) if transient_until is None else t <= transient_until
            transient = _flight_transient(t[keep], pos[keep], ref[keep], mission, transient_axis, levels, bands)
            steady = (row["rmse_m"], row["max_error_m"])  # no transient: the whole flight
            if transient is not None:
                info, axis, t_step, settled = transient
                row.update(
                    axis=axis,
                    rise_time_s=_nan(info.rise_time),
                    settling_time_s=_nan(info.settling_time),
                    overshoot_pct=info.overshoot_pct,
                    peak_time_s=info.peak_time,
                )
                row[second] = _nan(info.settling_time_5pct)
                steady = (np.nan, np.nan) if settled is None else _steady_errors(t, pos, ref, t_step + settled)
            row["steady_rmse_m"], row["steady_max_error_m"] = steady
            if not result.ok[i]:  # lost or off track: no transient or steady state to speak of
                row.update({key: np.nan for key in row if key in FAILED_FLIGHT_METRICS or key == second})
        if hover is not None:
            duties = result.commands[i, :, CMD_U1 : CMD_U1 + 4]
            row["effort"] = float(control_effort(t, duties - hover[i])["integral"])
    if flew_an_estimator(result):  # a flight on its sensors' estimate: how far it was from the truth
        for i, row in enumerate(rows):
            row.update(estimate_metrics(result.states, result.observations, i))
    frame = pd.DataFrame(rows)
    frame.attrs["conventions"] = conventions
    return frame


def _steady_errors(t: np.ndarray, pos: np.ndarray, ref: np.ndarray, t_from: float) -> tuple[float, float]:
    """RMS and maximum 3-D error from ``t_from`` on; the error at the end if that is the last sample."""
    if t_from >= t[-1]:
        last = float(np.linalg.norm(pos[-1] - ref[-1]))
        return last, last
    err = tracking_errors(t, pos, ref, t_from=max(t_from, float(t[0])))
    return float(err["rmse"]), float(err["max_error"])


def _flight_transient(t, pos, ref, mission: dict, axis: str | None, rise: tuple, bands: tuple):
    """(StepInfo, axis name, start time [s], start of the steady window from the start time [s]
    or None if it did not settle), or None where no transient is measured."""
    if axis is None and moving_reference(t, ref[None], mission):
        got = tracking_transient_batch(t, np.linalg.norm(pos - ref, axis=1)[None], list(bands) + [STEADY_BAND], rise)
        if not got["measured"][0]:
            return None
        settle = [None if np.isnan(s[0]) else float(s[0]) for s in got["settling_s"]]
        info = StepInfo(
            rise_time=None if np.isnan(got["rise_time_s"][0]) else float(got["rise_time_s"][0]),
            settling_time=settle[0],
            settling_time_5pct=settle[1],
            overshoot_pct=float(got["overshoot_pct"][0]),
            undershoot_pct=np.nan,
            peak=np.nan,
            peak_time=float(got["peak_time_s"][0]),
            y_initial=0.0,
            y_final=1.0,
            settled=settle[0] is not None,
        )
        steady_from = float(got["steady_from"][0])
        return info, TRACKING_AXIS_NAME, float(t[0]), None if np.isnan(steady_from) else steady_from - float(t[0])
    if axis is None and mission.get("kind") == "step" and mission.get("axis") in _AXIS_NAMES:
        j = _AXIS_NAMES.index(mission["axis"])
        t_step = float(mission["time"])
        if not t[0] <= t_step < t[-1]:
            return None
        before = float(mission[mission["axis"]])  # the hover point the step leaves

        def measure(levels, settle):
            return step_info(
                t,
                pos[:, j],
                y_initial=before,
                y_final=before + float(mission["size"]),
                t_step=t_step,
                rise=levels,
                settle_bands=settle,
            )

        name = mission["axis"]
    else:
        e0 = np.abs(ref[0] - pos[0])
        j = _AXIS_NAMES.index(axis) if axis is not None else int(np.argmax(e0))
        if e0[j] < TRANSIENT_MIN_ERROR:
            return None
        t_step = float(t[0])

        def measure(levels, settle):
            return transient_info(t, pos[:, j], ref[:, j], rise=levels, settle_bands=settle)

        name = _AXIS_NAMES[j]
    info = measure(rise, bands)
    if bands[1] == STEADY_BAND:
        steady = info.settling_time_5pct
    elif bands[0] == STEADY_BAND:
        steady = info.settling_time
    else:
        steady = measure(rise, (STEADY_BAND, STEADY_BAND)).settling_time
    return info, name, t_step, steady


def _nan(value):
    return np.nan if value is None else float(value)
