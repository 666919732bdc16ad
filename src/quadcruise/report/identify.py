"""The HTML report of an identification (``quadcruise identify --report PATH.html``)."""

from __future__ import annotations

from pathlib import Path


def identification_report(result, *, title: str | None = None) -> dict:
    """Keywords of :func:`quadcruise.report.html.html_report` for an identified vehicle: its
    parameters and held-out validation as tables, measured against predicted, the Markdown report."""
    import pandas as pd

    from quadcruise.report.html import markdown_html

    rows = {
        name: {"R2": v["r2"], "RMSE": v["rmse"], "unit": v["unit"]}
        for name, v in result.validation.items()
        if name != "open_loop"
    }
    for rate in "pqr":
        if rate in result.validation["open_loop"]:
            v = result.validation["open_loop"][rate]
            rows[f"{rate} (open loop, {result.validation['open_loop']['window_s']:.2f} s)"] = {
                "R2": v["r2"],
                "RMSE": v["rmse"],
                "unit": v["unit"],
            }
    name = Path(result.log["source"]).name
    return {
        "title": title or f"quadcruise identify: {name}",
        "tables": {
            "Parameters (95 % intervals)": result.to_pandas().set_index("parameter"),
            "Held-out validation": pd.DataFrame(rows).T,
        },
        "figures": {"Held-out tail: measured against predicted": result.plot()},
        "notes": markdown_html(result.report_md()),
        "config": result.to_json(),
    }
