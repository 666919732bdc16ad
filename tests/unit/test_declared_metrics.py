"""The metrics declared once (metrics/declared.py) are what the sweep's table, its histograms,
the tables' missing words and docs/metrics.md use."""

import re
from pathlib import Path

import numpy as np
import pandas as pd

from quadcruise.metrics import tables
from quadcruise.metrics.declared import KINDS, METRICS, Metric, metric, metric_names
from quadcruise.metrics.flight import FAILED_FLIGHT_METRICS
from quadcruise.montecarlo import schema
from quadcruise.plots import montecarlo as mc_plots

ROOT = Path(__file__).resolve().parents[2]


def test_every_reader_takes_the_declarations():
    names = tuple(m.name for m in METRICS)
    assert schema.METRICS == names and all(schema.COLUMNS[n] is float for n in names)
    assert mc_plots.HISTOGRAM_METRICS == tuple(m.name for m in METRICS if m.histogram)
    assert all(mc_plots.metric_label(m.name) == m.axis_label for m in METRICS)  # "[unit]" when it has one
    assert set(FAILED_FLIGHT_METRICS) == {m.name for m in METRICS if m.kind in ("transient", "steady")}
    assert {m.absent for m in METRICS} <= {"", tables.DID_NOT_SETTLE, tables.NO_OVERSHOOT}
    assert all(m.kind in KINDS and m.better in ("lower", "higher") for m in METRICS)


def test_missing_words_follow_the_declaration():
    nan = float("nan")
    # a band the table was asked for reads as the settling time
    assert metric("settling_time_3pct_s") is metric("settling_time_s") and metric("settling_time_xpct_s") is None
    assert tables.metric_cell(nan, "settling_time_3pct_s", "x") == (tables.DID_NOT_SETTLE, False)
    assert tables.metric_cell(nan, "peak_time_s", "xyz") == (tables.NO_OVERSHOOT, False)
    assert tables.metric_cell(nan, "rise_time_s", "") == (tables.NO_TRANSIENT, False)
    assert tables.metric_cell(nan, "steady_rmse_m", "x", status="lost track") == (tables.FAILED_FLIGHT, False)
    # whole-flight metrics and columns that are no metric: a dash, whatever the flight
    for name in ("rmse_m", "effort", "stop_time_s", "m"):
        assert tables.metric_cell(nan, name, "x", status="lost track") == ("-", False)
    assert tables.metric_cell(0.5, "steady_rmse_m", "x") == ("0.5", True)


def test_docs_table_is_the_declarations():
    text = (ROOT / "docs" / "metrics.md").read_text()
    rows = re.findall(r"^\| `([a-z0-9_]+)` \| (.*?) \| (.*?) \| (.*?) \| (.*?) \|$", text, flags=re.M)
    assert rows == [(m.name, m.unit, m.kind, m.better, m.definition) for m in METRICS]


def test_worst_ranks_by_the_declared_direction(monkeypatch):
    from quadcruise.metrics import declared
    from quadcruise.montecarlo.result import MonteCarloResult

    table = pd.DataFrame(
        {"vehicle": [0, 1, 2], "failure": [0, 0, 0], "stop_time_s": [1.0] * 3, "rmse_m": [0.2, 0.5, 0.1]}
    )
    result = MonteCarloResult.__new__(MonteCarloResult)
    object.__setattr__(result, "table", table)
    object.__setattr__(result, "spec", type("Spec", (), {"seed": 7})())
    assert result.worst(3, by="rmse_m")["vehicle"].tolist() == [1, 0, 2]  # lower is better: largest first
    higher = Metric("rmse_m", "m", "RMSE", "-", "flight", better="higher")
    monkeypatch.setattr(declared, "_BY_NAME", {**declared._BY_NAME, "rmse_m": higher})
    assert result.worst(3, by="rmse_m")["vehicle"].tolist() == [2, 0, 1]
    assert np.isfinite(table["rmse_m"]).all() and metric_names(kind="flight")[0] == "rmse_m"
