"""What the sections of a report hold for each kind of result: the keywords of
:func:`~quadcruise.report.html.html_report` (tables, figures, 3-D views, configuration, notes)
for a flight, a comparison of controllers and the paper's reproduction. The page itself is
assembled by :mod:`quadcruise.report.html` (whose example builds a flight's page); an
identification's report: :mod:`quadcruise.report.identify`.
"""

from __future__ import annotations

from quadcruise.report.html import markdown_html

__all__ = ["comparison_report", "flight_report", "reproduction_report"]


def _metrics_table(frame, label: str = "value"):
    """Metrics down, vehicles across for a few vehicles (one flight: one column, ``label``);
    one row per vehicle otherwise."""
    if len(frame) > 6:
        return frame
    shown = frame.set_index("vehicle").T
    shown.columns = [label] if len(frame) == 1 else [f"vehicle {v}" for v in shown.columns]
    return shown


def _conventions_table(frame) -> dict:
    """``{"Metric conventions": table}`` of what a metrics table's columns measure (its
    ``attrs["conventions"]``), or ``{}`` if it records none."""
    import pandas as pd

    conv = frame.attrs.get("conventions")
    if not conv:
        return {}
    values = {
        "rise_time_s": "{:g}-{:g} % of the step (axis xyz: of the error's way to its steady level)".format(
            *(100.0 * v for v in conv["rise"])
        )
    }
    values.update({name: f"{100.0 * band:g} % band" for name, band in conv["settling_columns"].items()})
    values["steady_rmse_m, steady_max_error_m"] = (
        f"3-D position error from the {100.0 * conv['steady_band']:g} % "
        "settling time on (axis xyz, a moving reference: over the last "
        "half of the flight, once converged; the whole flight without a "
        "transient)"
    )
    values["effort"] = conv["effort"]
    return {"Metric conventions": pd.DataFrame({"meaning": values})}


def flight_report(result, *, title: str | None = None, metrics=None) -> dict:
    """Keywords of :func:`html_report` for one flight (one ``fly``).

    Parameters
    ----------
    result : SimResult
        The flight, of one vehicle or a batch.
    title : str, optional
        The page's title; by default "quadcruise: " and what the flight was.
    metrics : pandas.DataFrame, optional
        ``result.metrics()``, if already computed (saves computing them again).

    Returns
    -------
    dict
        ``title``, ``tables`` (the metrics, vehicles across for up to 6 vehicles, and the
        run: controller, mission, duration [s], dt [s], vehicles, seed, version),
        ``figures`` (the flight, of vehicle 0 in a batch, a batch's envelope, and after a flight
        on an estimator its estimate against the truth),
        ``flights`` (the 3-D view) and ``config`` (``result.meta``).
    """
    import pandas as pd

    from quadcruise.metrics.estimate import flew_an_estimator
    from quadcruise.plots.flight import describe, plot_envelope, plot_flight

    meta = result.meta or {}
    ctrl, mission = meta.get("controller"), meta.get("mission")
    mission = mission[0] if isinstance(mission, list) and mission else mission
    run = {
        "controller": ctrl.get("name") if isinstance(ctrl, dict) else ctrl,
        "mission": mission.get("kind") if isinstance(mission, dict) else mission,
        "duration_s": float(result.t[-1] - result.t[0]),
        "dt_s": meta.get("dt_s"),
        "vehicles": result.n,
        "finished": f"{int(result.ok.sum())} of {result.n}",
        "seed": meta.get("seed"),
        "version": meta.get("version"),
    }
    run_table = pd.DataFrame({"value": {k: v for k, v in run.items() if v is not None}})
    label = describe(result)
    figures = {(f"Flight of vehicle 0: {label}" if result.n > 1 else f"Flight: {label}"): plot_flight(result)}
    if result.n > 1:
        figures[f"All {result.n} vehicles"] = plot_envelope(result)
    if flew_an_estimator(result):  # the controller flew on an estimate: it beside the truth
        from quadcruise.plots.estimate import plot_estimate

        estimator = (meta.get("estimator") or {}).get("kind", "estimator")
        sensors = ", ".join(meta.get("sensor_models") or {})
        caption = f"The {estimator}'s estimate the controller flew on ({sensors}), against the truth"
        figures[caption + (" (vehicle 0)" if result.n > 1 else "")] = plot_estimate(result)
    metrics = result.metrics() if metrics is None else metrics
    return {
        "title": title or f"quadcruise: {label}",
        "tables": {"Flight metrics": _metrics_table(metrics, label), **_conventions_table(metrics), "Run": run_table},
        "figures": figures,
        "flights": {label: result},
        "config": meta,
    }


def comparison_report(cmp, *, title: str | None = None, **metric_kw) -> dict:
    """Keywords of :func:`html_report` for a :class:`~quadcruise.workflows.compare.Comparison`.

    Parameters
    ----------
    cmp : Comparison
        The flights of several controllers.
    title : str, optional
        The page's title; by default the controllers and the mission.
    **metric_kw
        Keywords of :meth:`Comparison.table` (``rise``, ``settle_bands``, ...).

    Returns
    -------
    dict
        ``title``, ``tables`` (the metrics by controller, transposed when every flight
        has one vehicle, and their conventions), ``figures`` (the paths), ``flights`` (one
        3-D view of all) and ``config`` (:meth:`Comparison.to_dict` without the metrics).
    """
    table = cmp.metrics(**metric_kw)
    if all(r.n == 1 for r in cmp.results.values()):
        table = table.T  # metrics down, controllers across
    config = {k: v for k, v in cmp.to_dict(**metric_kw).items() if k != "metrics"}
    name = getattr(cmp.mission, "name", "mission")
    return {
        "title": title or f"quadcruise: {' vs '.join(cmp.results)} on {name}",
        "tables": {"Metrics by controller": table, **_conventions_table(table)},
        "figures": {f"Paths on {name}": cmp.plot()},
        "flights": dict(cmp.results),
        "config": config,
    }


def _fitted_table(rep):
    """The fit scenario's flights, the paper's gains and the fitted ones, with both rise conventions
    beside the paper's numbers (report.md's fitted table, as data); empty if it was not flown."""
    import pandas as pd

    from quadcruise.workflows.reproduce import CONTROLLERS, FIT_SCENARIO, FITTED, paper_numbers

    factories = {**CONTROLLERS, **FITTED}
    rows = []
    for r in rep.runs:
        if r["scenario"] != FIT_SCENARIO[0]:
            continue
        gains, paper = factories[r["controller"]]().position, paper_numbers(r)
        rows.append(
            {
                "controller": r["controller"],
                "fitted": "yes" if r["fitted"] else "no",
                "Kp": gains.kp,
                "Kd": gains.kd,
                "zeta": gains.damping,
                "wn_rad_s": gains.natural_frequency,
                "rise_time_s": r["rise_time_s"],
                "rise_0_100_s": r.get("rise_0_100_s"),
                "paper: rise_time_s": paper.get("rise_time_s"),
                "settling_time_s": r["settling_time_s"],
                "paper: settling_time_s": paper.get("settling_time_s"),
                "overshoot_pct": r["overshoot_pct"],
                "paper: overshoot_pct": paper.get("overshoot_pct"),
                "status": r["status"],
            }
        )
    if not rows:
        return pd.DataFrame()
    return pd.DataFrame(rows).set_index("controller").astype({c: float for c in rows[0] if c.endswith(NUMERIC)})


NUMERIC = ("_s", "_pct", "Kp", "Kd", "zeta")


def reproduction_report(rep, figures: dict | None = None, *, title: str | None = None) -> dict:
    """Keywords of :func:`html_report` for a :class:`~quadcruise.workflows.reproduce.Reproduction`.

    Parameters
    ----------
    rep : Reproduction
        The runs.
    figures : dict, optional
        Caption -> Figure, PNG bytes or PNG file (e.g. those that
        :func:`~quadcruise.workflows.reproduce.write_reproduction` wrote); ``None`` draws
        them here.
    title : str, optional
        The page's title; by default the version and "reproduction of the paper".

    Returns
    -------
    dict
        ``title``, ``tables`` (each run beside the paper's numbers; the fit scenario's gains and
        both rise conventions, when it was flown), ``figures``,
        ``flights`` (3-D views of the circle and the square, each with every controller),
        ``config`` and ``notes`` (where the numbers differ from the paper's, and why).
    """
    import pandas as pd

    from quadcruise._version import __version__
    from quadcruise.workflows.reproduce import (
        FIGURES,
        FITTED_NOTE,
        INTRO,
        TRACE_EVERY,
        baseline_comparison,
        differences,
        paper_figure,
        paper_numbers,
    )

    rows = []
    for r in rep.runs:
        paper = paper_numbers(r)
        rows.append(
            {
                "scenario": r["scenario"],
                "controller": r["controller"],
                "axis": r["axis"],
                "rise_time_s": r["rise_time_s"],
                "paper: rise_time_s": paper.get("rise_time_s"),
                "settling_time_s": r["settling_time_s"],
                "paper: settling_time_s": paper.get("settling_time_s"),
                "settling_time_5pct_s": r["settling_time_5pct_s"],
                "overshoot_pct": r["overshoot_pct"],
                "paper: overshoot_pct": paper.get("overshoot_pct"),
                "rmse_m": r["rmse_m"],
                "max_error_m": r["max_error_m"],
                "status": r["status"],
            }
        )
    table = (
        pd.DataFrame(rows).astype({c: float for c in rows[0] if c.endswith(("_s", "_pct", "_m"))})
        if rows
        else pd.DataFrame()
    )
    if figures is None:
        light = {key: res.decimate(TRACE_EVERY) for key, res in rep.results.items()}
        figures = {cap: fig for name, cap in FIGURES.items() if (fig := paper_figure(name, cap, light)) is not None}
    flights = {scen: {c: res for (s, c), res in rep.results.items() if s == scen} for scen in ("circle", "square")}
    fitted = _fitted_table(rep)
    notes = markdown_html(
        INTRO + "\n" + (FITTED_NOTE if len(fitted) else "") + differences() + baseline_comparison(rep)
    )
    return {
        "title": title or f"quadcruise {__version__}: reproduction of the paper",
        "tables": {
            "Results against the paper": table,
            **({"Fitted to the paper's transients (both rise conventions)": fitted} if len(fitted) else {}),
        },
        "figures": figures,
        "flights": {k: v for k, v in flights.items() if v},
        "config": {"workflow": "reproduce", **rep.config, "version": __version__},
        "notes": notes,
    }
