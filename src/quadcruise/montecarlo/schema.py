"""The Monte Carlo table's schema: its failure codes, summarised metrics and typed columns (a leaf)."""

from __future__ import annotations

import numpy as np

from quadcruise.metrics.declared import metric_names
from quadcruise.montecarlo.population import SLOTS

__all__ = ["COLUMNS", "ESTIMATE_METRICS", "FAILURES", "METRICS", "engine_stops"]

FAILURES = ("ok", "diverged", "lost track", "saturated", "failed a requirement")
"""Failure codes 0..4 of the table's ``failure`` column, in order of precedence: the engine
stopped the flight; its error after the transient exceeded the spec's ``max_track_error_m``
(or its altitude error ``max_altitude_error_m``: fly's off-track rule);
its rotor duties were clipped for longer than ``max_clipped_s``; it missed one of the
spec's ``requirements``. A transient that did not settle is a metric (``not_settled``),
not a failure."""
METRICS = metric_names()
"""The metrics summarised by quantiles (NaN where not applicable is left out), and those a
requirement may name: every metric declared in :mod:`quadcruise.metrics.declared` (the
estimate's defined on a population that flies an estimator only)."""
ESTIMATE_METRICS = metric_names(kind="estimate")
"""The metrics of the estimate the controller flew on (NaN for a flight on the truth)."""
COLUMNS = {
    "vehicle": np.int64,
    "status": np.int64,
    "stop_time_s": float,
    "failure": np.int64,
    "diverged": bool,
    "lost_track": bool,
    "saturated": bool,
    "failed_requirement": bool,
    "not_settled": bool,
    "transient_axis": np.int64,
    **{m: float for m in METRICS},
    **{k: float for k in SLOTS},
    "imu_noise_factor": float,
    "gps_noise_factor": float,
}
"""Columns of the per-flight table and their types: engine ``status`` (see
:data:`quadcruise.sim.status.ExitStatus`), ``failure`` (see :data:`FAILURES`), a flag per
failure reason (a flight may have several; ``failure`` names the first), ``not_settled``
(the transient still outside the spec's ``settle_band`` at the end),
``transient_axis`` (0, 1, 2 for x, y, z; -1 if none), the metrics and the drawn values
(``dx0``..: initial offset [m]; ``wind_x``, ``wind_y``: steady wind [m/s]; ``imu_noise_factor``,
``gps_noise_factor``: the sensors' noise against the nominal's [-])."""


def engine_stops(summary: dict) -> dict[str, int]:
    """The flights the engine stopped (the "diverged" failures), by the reason it gave.

    Parameters
    ----------
    summary : dict
        :meth:`quadcruise.montecarlo.MonteCarloResult.summary_data`.

    Returns
    -------
    dict of str to int
        Status reason (:data:`quadcruise.sim.status.STATUS_REASONS`: ``"crashed: hit the
        ground ..."``, ``"diverged: tilt left the bound"``, ...) -> flights; the statuses of
        flights that flew on (lost track, off track) left out.

    Examples
    --------
    >>> engine_stops({"stopped": {"crashed: hit the ground": 2, "lost track: ...": 1}})
    {'crashed: hit the ground': 2}
    """
    flew_on = ("lost track", "off track")
    return {k: v for k, v in summary["stopped"].items() if not k.startswith(flew_on)}
