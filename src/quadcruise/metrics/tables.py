"""How a metric reads in a table: one rule for the terminal (``fly``, ``compare``) and the
HTML report.

Numbers show 4 significant digits (scientific notation when very large or small), a missing
value a dash, or why it is missing (:func:`metric_cell`): "did not settle" is not "no transient",
and neither is "failed flight". :func:`conventions_text` says in words what the columns measure.

>>> import pandas as pd
>>> frame = pd.DataFrame({"axis": ["x", None], "settling_time_s": [float("nan")] * 2, "rmse_m": [0.01234, 2e-5]})
>>> print(metrics_text(frame, ["vehicle 0", "vehicle 1"]))
                      vehicle 0     vehicle 1
axis                          x             -
settling_time_s  did not settle  no transient
rmse_m                  0.01234     2.000e-05
"""

from __future__ import annotations

import math
import re
from typing import Any

import numpy as np

from quadcruise.metrics.declared import metric as declared_metric

__all__ = [
    "cell",
    "metric_cell",
    "metrics_text",
    "vehicle_metrics_text",
    "conventions_text",
    "DID_NOT_SETTLE",
    "FAILED_FLIGHT",
    "NO_TRANSIENT",
    "NO_OVERSHOOT",
]

DID_NOT_SETTLE = "did not settle"
FAILED_FLIGHT = "failed flight"
"""A transient or steady metric of a flight that did not finish: there is none to measure."""
NO_TRANSIENT = "no transient"
"""A transient metric of a flight that started on its reference (the default square): nothing to measure."""
NO_OVERSHOOT = "no overshoot"
"""The peak time of a moving reference's entry that never went below its steady level."""


def cell(value: Any, missing: str = "-") -> tuple[str, bool]:
    """How one value reads in a table.

    Parameters
    ----------
    value : Any
        A number, bool, string or None; None and NaN are missing.
    missing : str
        The text of a missing value.

    Returns
    -------
    text : str
        4 significant digits (scientific notation below 1e-3 or from 1e7 on, thousands
        separators from 1e4 on), ``yes``/``no`` for a bool, ``missing`` for None or NaN.
    is_number : bool
        True if ``text`` is a number (right-aligned in a table).

    Examples
    --------
    >>> cell(3.14159), cell(12345.6), cell(None), cell(True)
    (('3.142', True), ('12,346', True), ('-', False), ('yes', False))
    """
    if value is None or (isinstance(value, float | np.floating) and math.isnan(value)):
        return missing, False
    if isinstance(value, bool | np.bool_):
        return ("yes" if value else "no"), False
    if isinstance(value, int | np.integer):
        return str(int(value)), True
    if isinstance(value, float | np.floating):
        a = abs(float(value))
        if a == 0.0:
            return "0", True
        if math.isinf(a) or a >= 1e7 or a < 1e-3:
            return f"{value:.3e}", True
        return (f"{value:,.0f}" if a >= 1e4 else f"{value:.4g}"), True
    return str(value), False


def metric_cell(value: Any, metric: Any, axis: Any, missing: str = "-", status: Any = None) -> tuple[str, bool]:
    """:func:`cell` of ``metric``'s value for a flight whose transient axis is ``axis``.

    A missing transient or steady metric reads :data:`FAILED_FLIGHT` for a flight whose
    ``status`` is not "finished"; a missing settling time, overshoot or steady error of a
    measured transient :data:`DID_NOT_SETTLE`, its missing peak time :data:`NO_OVERSHOOT`;
    a missing transient metric of a flight without a transient (``axis`` ``""``)
    :data:`NO_TRANSIENT`.

    Parameters
    ----------
    value : Any
        The metric's value.
    metric : Any
        The metric's name (a column of :func:`~quadcruise.metrics.flight_metrics`).
    axis : Any
        The flight's transient axis (``"x"``, ``"y"``, ``"z"``, ``"xyz"``), ``""`` if the
        table measured none for this flight, None if unknown.
    missing : str
        The text of a missing value.
    status : Any
        The flight's status text, if known.

    Returns
    -------
    text : str
        As :func:`cell` writes it, or for a missing value the words above.
    is_number : bool
        True if ``text`` is a number.

    Examples
    --------
    >>> metric_cell(float("nan"), "settling_time_s", "x")
    ('did not settle', False)
    >>> metric_cell(float("nan"), "steady_rmse_m", "x"), metric_cell(float("nan"), "settling_time_s", None)
    (('did not settle', False), ('-', False))
    >>> metric_cell(float("nan"), "rise_time_s", ""), metric_cell(float("nan"), "rise_time_s", "x", status="off track")
    (('no transient', False), ('failed flight', False))
    """
    text, number = cell(value, missing)
    declared = declared_metric(metric)  # its kind and its missing words: metrics/declared.py
    if text != missing or declared is None:
        return text, number
    if isinstance(status, str) and status != "finished" and declared.kind in ("transient", "steady"):
        return FAILED_FLIGHT, False
    measured = isinstance(axis, str) and bool(axis.strip())
    if measured and declared.absent:
        return declared.absent, False
    if axis == "" and declared.kind == "transient":
        return NO_TRANSIENT, False
    return text, number


def _short_status(status) -> str:
    """A status as a table's cell: its kind (``off track``), not its reason, which is said in
    full under the table (a reason of 130 characters padded every row of ``fly``'s table)."""
    text = str(status)
    kind = text.split(":", 1)[0].strip() or text
    when = re.search(r" at t = \S+ s$", text) if kind != text else None
    return kind + (when.group(0) if when else "")


def metrics_text(frame, labels) -> str:
    """A table of metrics as aligned text, with the metrics down and the flights across.

    Parameters
    ----------
    frame : pandas.DataFrame
        One row per flight, one column per metric (with an ``axis`` column, if any
        transient was measured).
    labels : sequence of str
        The flights' column headings, one per row of ``frame``.

    Returns
    -------
    str
        The table, each value as :func:`metric_cell` writes it (see the module's example).
    """
    import pandas as pd

    axes = [a if isinstance(a, str) else "" for a in frame["axis"]] if "axis" in frame.columns else [None] * len(frame)
    statuses = frame["status"].tolist() if "status" in frame.columns else [None] * len(frame)
    shown = pd.DataFrame(
        {
            label: [
                _short_status(v) if col == "status" else metric_cell(v, col, axis, status=status)[0]
                for col, v in row.items()
            ]
            for label, axis, status, (_, row) in zip(labels, axes, statuses, frame.iterrows(), strict=False)
        },
        index=list(frame.columns),
    )
    return shown.to_string()


def vehicle_metrics_text(frame) -> str:
    """The metrics of a flight, one column per vehicle, as aligned text (for a terminal).

    Parameters
    ----------
    frame : pandas.DataFrame
        One row per vehicle with a ``vehicle`` column, as
        :meth:`quadcruise.sim.result.SimResult.metrics` returns.

    Returns
    -------
    str
        :func:`metrics_text` of the other columns, headed ``vehicle 0``, ``vehicle 1``, ...

    Examples
    --------
    >>> import pandas as pd
    >>> frame = pd.DataFrame({"vehicle": [0], "axis": ["x"], "rmse_m": [0.5]})
    >>> print(vehicle_metrics_text(frame))
           vehicle 0
    axis           x
    rmse_m       0.5
    """
    return metrics_text(frame.drop(columns=["vehicle"]), [f"vehicle {c}" for c in frame["vehicle"]])


def conventions_text(conventions: dict | None) -> str:
    """What the columns of a metrics table measure, in a few lines (for under the table).

    Parameters
    ----------
    conventions : dict or None
        A table's ``attrs["conventions"]``
        (:func:`quadcruise.metrics.conventions.metric_conventions`); None or empty for none.

    Returns
    -------
    str
        The rise levels, the band of each settling column, the steady window and the
        effort's definition; "" without conventions.

    Examples
    --------
    >>> from quadcruise.metrics.conventions import metric_conventions
    >>> print(conventions_text(metric_conventions(rise=(0.0, 1.0))))
    rise_time_s: 0-100 % of the step (axis xyz: of the error's way to its steady level); settling_time_s: 2 % ...
    steady_*: 3-D position error from the 5 % settling time on (axis xyz, a moving reference: over the last ...
    effort: integral of sum_i (u_i - u_hover)^2 dt over the four rotor duties, u_hover = m g / (4 K) [s]
    """
    if not conventions:
        return ""
    lo, hi = (format(100.0 * float(v), ".6g") for v in conventions["rise"])
    parts = [f"rise_time_s: {lo}-{hi} % of the step (axis xyz: of the error's way to its steady level)"]
    parts += [
        f"{name}: {format(100.0 * float(band), '.6g')} % band" for name, band in conventions["settling_columns"].items()
    ]
    steady = format(100.0 * float(conventions["steady_band"]), ".6g")
    return "\n".join(
        [
            "; ".join(parts),
            f"steady_*: 3-D position error from the {steady} % settling time on (axis xyz, a moving "
            "reference: over the last half of the flight, once converged; the whole flight without a "
            "transient)",
            f"effort: {conventions['effort']}",
        ]
    )
