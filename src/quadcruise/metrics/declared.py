"""The flight metrics, each declared once: name, unit, what it measures, which way is better,
and how a table reads it when missing. The Monte Carlo table's columns
(:data:`quadcruise.montecarlo.schema.METRICS`), its chunks, its report, its histograms and the
terminal and HTML tables (:func:`quadcruise.metrics.tables.metric_cell`) read this list
instead of naming the metrics themselves. How each is computed: docs/metrics.md.

Examples
--------
>>> m = metric("overshoot_pct")
>>> m.unit, m.better, m.axis_label
('%', 'lower', 'overshoot [%]')
>>> metric("settling_time_3pct_s").name          # any band's column reads as the settling time
'settling_time_s'
>>> metric("stop_time_s") is None
True
"""

from __future__ import annotations

import dataclasses
import re

__all__ = ["KINDS", "METRICS", "Metric", "metric", "metric_names"]

KINDS = ("flight", "transient", "steady", "input", "estimate")
"""What a metric covers: the whole flight's error, the entry transient, the steady window after
it, the commands (effort, saturation), or the estimate the controller flew on (a flight on
sensors and an estimator only: docs/sensors.md)."""


@dataclasses.dataclass(frozen=True)
class Metric:
    """One metric of a flight.

    Parameters
    ----------
    name : str
        Its column, ending in its unit (``_m``, ``_s``, ``_pct``) where it has one.
    unit : str
        Its unit (``m``, ``s``, ``%``).
    label : str
        Its name in words, for a figure's axis.
    definition : str
        What it measures, in one line.
    kind : str
        One of :data:`KINDS`. A flight that did not finish has no ``transient`` or ``steady``
        metric (NaN; a table says "failed flight"), and a flight without a transient no
        ``transient`` metric ("no transient").
    better : {"lower", "higher"}
        Which way is better (the worst flights of a sweep rank the other way first).
    absent : str
        How a table reads it when missing although the transient was measured ("did not
        settle", "no overshoot"); "" for a plain dash.
    histogram : bool
        Drawn by default in a sweep's histograms.
    """

    name: str
    unit: str
    label: str
    definition: str
    kind: str
    better: str = "lower"
    absent: str = ""
    histogram: bool = False

    def __post_init__(self) -> None:
        if self.kind not in KINDS or self.better not in ("lower", "higher"):
            raise ValueError(f"metric {self.name!r}: kind must be one of {KINDS}, better 'lower' or 'higher'")

    @property
    def axis_label(self) -> str:
        """The label with its unit, for a figure's axis.

        Returns
        -------
        str
        """
        return f"{self.label} [{self.unit}]" if self.unit else self.label


_SETTLE = "did not settle"
METRICS: tuple[Metric, ...] = (
    Metric("rmse_m", "m", "RMSE", "RMS of the 3-D position error over the flight", "flight", histogram=True),
    Metric("max_error_m", "m", "max error", "largest 3-D position error over the flight", "flight", histogram=True),
    Metric(
        "steady_rmse_m", "m", "steady RMSE", "RMS of the 3-D error over the steady window", "steady", absent=_SETTLE
    ),
    Metric(
        "steady_max_error_m",
        "m",
        "steady max error",
        "largest 3-D error over the steady window",
        "steady",
        absent=_SETTLE,
    ),
    Metric("final_error_m", "m", "final error", "3-D position error at the last instant", "flight", histogram=True),
    Metric("rise_time_s", "s", "rise time", "from 10 % to 90 % of the step (or 0-100 %)", "transient", histogram=True),
    Metric("settling_time_s", "s", "settling time 2 %", "last exit from the 2 % band", "transient", absent=_SETTLE),
    Metric(
        "settling_time_5pct_s",
        "s",
        "settling time 5 %",
        "last exit from the 5 % band",
        "transient",
        absent=_SETTLE,
        histogram=True,
    ),
    Metric(
        "overshoot_pct",
        "%",
        "overshoot",
        "excursion beyond the commanded value, in % of the step",
        "transient",
        absent=_SETTLE,
        histogram=True,
    ),
    Metric("peak_time_s", "s", "peak time", "time of the overshoot's peak", "transient", absent="no overshoot"),
    Metric(
        "effort",
        "s",
        "effort",
        "integral of sum_i (u_i - u_hover)^2 dt over the four rotor duties",
        "input",
        histogram=True,
    ),
    Metric(
        "duty_clipped_s",
        "s",
        "duty clipped",
        "time a commanded duty (or rotor speed) was clipped to its range",
        "input",
        histogram=True,
    ),
    Metric(
        "controller_limited_s", "s", "controller limited", "time the controller flagged one of its own limits", "input"
    ),
    Metric(
        "estimate_position_rmse_m",
        "m",
        "estimate position error",
        "RMS of the 3-D distance between the position the controller saw and the truth",
        "estimate",
    ),
    Metric(
        "estimate_attitude_rmse_deg",
        "deg",
        "estimate attitude error",
        "RMS of the angle of the rotation between the attitude the controller saw and the truth",
        "estimate",
    ),
    Metric(
        "nees_position",
        "",
        "NEES position",
        "mean NEES of the filter's position (3 dof: 3 when consistent, above: overconfident)",
        "estimate",
    ),
    Metric("nees_velocity", "", "NEES velocity", "mean NEES of the filter's velocity (3 dof)", "estimate"),
    Metric("nees_attitude", "", "NEES attitude", "mean NEES of the filter's attitude (3 dof)", "estimate"),
)
"""Every metric, in the order of the tables' columns."""

_BY_NAME = {m.name: m for m in METRICS}
_SETTLING_COLUMN = re.compile(r"settling_time_[0-9p]+pct_s")


def metric(name: str) -> Metric | None:
    """The declaration of a metric's column; None for a column that is no metric.

    Parameters
    ----------
    name : str
        A column: a metric's name, or ``settling_time_<band>pct_s`` of any band (read as
        ``settling_time_s``).

    Returns
    -------
    Metric or None
    """
    if not isinstance(name, str):
        return None
    if name in _BY_NAME:
        return _BY_NAME[name]
    return _BY_NAME["settling_time_s"] if _SETTLING_COLUMN.fullmatch(name) else None


def metric_names(*, kind: str | tuple[str, ...] | None = None, histogram: bool | None = None) -> tuple[str, ...]:
    """The names of the declared metrics, in order, optionally of some kinds or drawn by default.

    Parameters
    ----------
    kind : str or tuple of str, optional
        Only metrics of these :data:`KINDS`.
    histogram : bool, optional
        Only those drawn (True) or not drawn (False) by default.

    Returns
    -------
    tuple of str

    Examples
    --------
    >>> metric_names(kind="steady")
    ('steady_rmse_m', 'steady_max_error_m')
    """
    kinds = (kind,) if isinstance(kind, str) else kind
    return tuple(
        m.name
        for m in METRICS
        if (kinds is None or m.kind in kinds) and (histogram is None or m.histogram == histogram)
    )
