"""Metrics of a flight (rise, settling, overshoot, tracking after the transient, effort about hover)
and the same vectorised over vehicles; how a metric reads in a table. Pure functions of arrays:
they take results duck-typed."""

from quadcruise.metrics.batch import flight_metrics_batch
from quadcruise.metrics.conventions import metric_conventions
from quadcruise.metrics.flight import flight_metrics, hover_duties
from quadcruise.metrics.signals import control_effort, time_in_saturation, tracking_errors
from quadcruise.metrics.step import StepInfo, step_info, step_info_batch, transient_info
from quadcruise.metrics.tracking import STEADY_BAND, TRANSIENT_MIN_ERROR

__all__ = [
    "STEADY_BAND",
    "TRANSIENT_MIN_ERROR",
    "StepInfo",
    "control_effort",
    "flight_metrics",
    "flight_metrics_batch",
    "hover_duties",
    "metric_conventions",
    "step_info",
    "step_info_batch",
    "time_in_saturation",
    "tracking_errors",
    "transient_info",
]
