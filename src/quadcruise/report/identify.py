"""The HTML report of an identification (``quadcruise identify --report PATH.html``).

Every section is built from the result's data (its parameters, validation, log and fit), as
tables and escaped text: the Markdown of ``report.md`` is for a Markdown reader, and pasted
into the page its tables were raw ``|`` pipes in a paragraph.
"""

from __future__ import annotations

import html
from pathlib import Path


def _verdict(result):
    """Whether the model fits the log, first (the summary's first line): the checks it passed, or
    each reason it does not fit, one row each."""
    import pandas as pd

    line = result.verdict_line().removeprefix("verdict: ")
    if result.fits or not result.verdict:
        return pd.DataFrame({"value": {"verdict": line}})
    facts = {"verdict": "the model DOES NOT FIT the log: no intervals"}
    facts.update({f"reason {i + 1}": why for i, why in enumerate(result.verdict.get("reasons", []))})
    return pd.DataFrame({"value": facts})


def _parameters(result):
    """One row per parameter: value, interval, unit, identifiable, where it comes from, note."""
    import pandas as pd

    rows = {
        name: {
            "value": p["value"],
            "ci95_low": p["ci95"][0] if p["identifiable"] else None,
            "ci95_high": p["ci95"][1] if p["identifiable"] else None,
            "unit": p["unit"],
            "identifiable": "yes" if p["identifiable"] else "no",
            "source": p.get("source", ""),
            "note": p.get("note", ""),
        }
        for name, p in result.parameters.items()
    }
    frame = pd.DataFrame(rows).T.astype({"value": float, "ci95_low": float, "ci95_high": float})
    frame.index.name = "parameter"
    return frame


def _log_and_fit(result):
    """What was read and how it was fitted, one row per fact."""
    import pandas as pd

    log, fit = result.log, result.fit
    facts = {
        "log": log.get("source"),
        "airborne [s]": f"{log['airborne_s']:.1f}" if "airborne_s" in log else None,
        "segments": log.get("segments"),
        "grid [Hz]": f"{log['grid_hz']:.0f}" if "grid_hz" in log else None,
        "resampling": log.get("resampling"),
        "commands": log.get("commands"),
        "rotor geometry": log.get("rotor_geometry"),
        "mass [kg]": f"{result.mass:g}" if result.mass is not None else "not given: K and the inertias per unit mass",
        "fitted on": (
            f"the first {1 - fit['holdout']:.0%} of the airborne samples ({fit['rows']})"
            if "holdout" in fit and "rows" in fit
            else None
        ),
        "Savitzky-Golay window [s]": f"{fit['window_s']:.3f}" if "window_s" in fit else None,
        "Newey-West bandwidth [samples]": fit.get("newey_west_bandwidth"),
        "PX4's hover_thrust_estimate (median)": (
            f"{log['px4_hover_thrust_estimate']:.4f}" if "px4_hover_thrust_estimate" in log else None
        ),
    }
    return pd.DataFrame({"value": {k: str(v) for k, v in facts.items() if v is not None}})


def _notes(result) -> str:
    """The cautions, the channels a low R² leaves in doubt, and the command, as escaped HTML."""
    from quadcruise.sysid.result import CHANNEL_LABELS

    items = [f"<strong>Caution</strong>: {html.escape(str(c))}" for c in result.fit.get("cautions", [])]
    low = [name for name in CHANNEL_LABELS if name in result.validation and not result.validation[name]["r2"] >= 0.5]
    if low:
        items.append(
            f"R² below 0.5 on {html.escape(', '.join(low))}: the held-out tail moves little there (or the "
            "model misses something); read the RMSE against the sensors' noise before trusting either."
        )
    if result.command:
        items.append(f"Written by: <code>{html.escape(result.command)}</code>")
    return "<ul>" + "".join(f"<li>{item}</li>" for item in items) + "</ul>" if items else ""


def identification_report(result, *, title: str | None = None) -> dict:
    """Keywords of :func:`quadcruise.report.html.html_report` for an identified vehicle: its
    parameters, held-out validation and what was read as tables, measured against predicted,
    the cautions as notes."""
    import pandas as pd

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
            "Verdict": _verdict(result),
            "Parameters (95 % intervals)": _parameters(result),
            "Held-out validation": pd.DataFrame(rows).T,
            "The log and the fit": _log_and_fit(result),
        },
        "figures": {"Held-out tail: measured against predicted": result.plot()},
        "notes": _notes(result),
        "config": result.to_json(),
    }
