"""The output folder of a Monte Carlo run: a finished sweep's table, summary, worst
flights, figures and report (beside its chunks), or one re-flown vehicle.

The folder's layout and its marker are those of :mod:`quadcruise.montecarlo.store`.
"""

from __future__ import annotations

import shutil
from pathlib import Path

import numpy as np

from quadcruise._version import __version__
from quadcruise.errors import InputError, WriteError
from quadcruise.io.files import MARKER, atomic_dir, atomic_path, check_output_dir, write_table
from quadcruise.io.plainjson import dumps
from quadcruise.io.scenario_file import montecarlo_document, scenario_text
from quadcruise.metrics.declared import metric
from quadcruise.montecarlo.schema import engine_stops
from quadcruise.montecarlo.store import holds_sweep, write_marker

__all__ = ["write_outputs", "write_case", "case_folder", "case_text", "report_markdown"]


def write_outputs(result, out, *, fmt: str = "csv", force: bool = False) -> Path:
    """The results of a sweep into ``out``, each file whole or not at all, quadcruise.json last (marked
    complete); see :mod:`quadcruise.montecarlo.store`."""
    from quadcruise.plots.flight import save_figure

    path = Path(out)
    meta, ours = holds_sweep(path, result.spec, force=force)
    if not ours:
        check_output_dir(path, force, workflow="montecarlo")
        if meta is not None and not force:
            raise InputError(f"{path}: holds another quadcruise result; use --force to replace it")
    try:
        if not ours and path.is_dir() and any(path.iterdir()):
            shutil.rmtree(path)
        path.mkdir(parents=True, exist_ok=True)
    except OSError as exc:
        raise WriteError(path, exc) from None
    name = write_table(result.table, path / "flights", fmt).name
    summary = result.summary_data()
    with atomic_path(path / "summary.json") as tmp:
        tmp.write_text(dumps({**summary, "info": result.info}, indent=2) + "\n")
    worst = result.worst(20)
    with atomic_path(path / "worst.csv") as tmp:
        worst.to_csv(tmp, index=False, float_format="%.10g")
    figures = {"histograms.png": result.plot_histograms(), "envelope.png": result.plot_envelope()}
    for fig_name, fig in figures.items():
        save_figure(fig, path / fig_name)
    with atomic_path(path / "report.md") as tmp:
        tmp.write_text(report_markdown(result, summary, worst, name))
    with atomic_path(path / "scenario.toml") as tmp:
        tmp.write_text(
            scenario_text(
                montecarlo_document(result.spec.to_dict(), result.n),
                header=(
                    "written by quadcruise from a Monte Carlo sweep; `quadcruise montecarlo --scenario THIS_FILE` "
                    "flies the same flights"
                ),
            )
        )
    write_marker(path, result.spec, result.n, complete=True, table=name, chunk_size=result.info.get("chunk_size"))
    return path


def write_case(case, out, *, fmt: str = "csv", force: bool = False) -> Path:
    """One re-flown vehicle into ``out``, whole or not at all: its traces, case.json, flight.png and
    quadcruise.json."""
    from quadcruise.plots.flight import plot_flight, save_figure

    path = check_output_dir(out, force)
    with atomic_dir(path) as tmp:
        tmp = Path(tmp)
        write_table(case.result.to_pandas(), tmp / "traces", fmt)
        (tmp / "case.json").write_text(dumps(case.row, indent=2) + "\n")
        save_figure(plot_flight(case.result), tmp / "flight.png")
        (tmp / MARKER).write_text(
            dumps({"workflow": "montecarlo-case", "vehicle": case.vehicle, **case.result.meta}, indent=2) + "\n"
        )
    return path


def case_text(case, seed: int) -> str:
    """One line on a re-flown vehicle: its status as ``fly`` says it (the same words and time
    as the vehicle flown alone), the sweep's outcome, its main metrics and its mass (to 10
    digits, to fly it alone: ``fly --vehicle m=...``)."""
    keys = ("rmse_m", "max_error_m", "steady_rmse_m", "steady_max_error_m", "settling_time_5pct_s")
    return (
        f"flight {case.vehicle} of seed {seed}: {case.result.status_text(0)} (the sweep's outcome: "
        f"{case.row['reason']}), " + ", ".join(f"{k} = {case.row[k]:.4g}" for k in keys) + f", m = {case.row['m']:.10g}"
    )


def case_folder(out, spec, case: int, *, force: bool = False) -> Path | None:
    """Where flight ``case`` of the sweep ``spec``, flown again alone, is written."""
    if out is None:
        return None
    target = Path(out)
    meta, same = holds_sweep(target, spec, force=force)
    if meta and meta.get("workflow") == "montecarlo":  # a sweep's folder: the case goes inside
        if not same:
            raise InputError(
                f"{out}: holds a sweep flown with other options or code (spec {meta.get('spec_hash')}, "
                f"these give {spec.hash()}); give the sweep's options to replay its flight"
            )
        target = target / f"case-{case:06d}"
    check_output_dir(target, force)
    return target


WORST_COLUMNS = (
    "rmse_m",
    "max_error_m",
    "steady_rmse_m",
    "steady_max_error_m",
    "settling_time_5pct_s",
    "stop_time_s",
    "m",
)
"""The columns of report.md's worst flights (and of :func:`case_text`, but the stop time)."""


def _missing(declared, measured: bool) -> str:
    """A missing value of the worst flights' table: its declared words if a transient was measured."""
    return declared.absent if declared is not None and declared.absent and measured else "-"


def report_markdown(result, summary: dict, worst, table_name: str) -> str:
    """report.md: what was flown, the failures, the quantiles, the worst flights, figures."""
    from quadcruise.plots.montecarlo import metric_label

    spec = result.spec
    pop = {k: v for k, v in spec.population.to_dict().items() if v not in (0.0, None)}
    f = summary["failures"]
    lines = [
        f"# Monte Carlo: {spec.controller.name} on {spec.mission.name}, {summary['flights']:,} flights\n",
        f"quadcruise {__version__}, seed {spec.seed}, {spec.duration:g} s at dt = {spec.dt:g} s, "
        f"metrics on a {spec.dt * spec.log_every:g} s log; spec hash `{spec.hash()}`.\n",
        "Population: " + (", ".join(f"{k} = {v}" for k, v in pop.items()) or "nominal") + ".\n",
        *[f"Vehicle: {said}.\n" for said in [spec.plant.describe(spec.vehicle)] if said],
        f"## Failures: {f['count']:,} of {summary['flights']:,} ({100 * f['rate']:.2f} %)\n",
        "Each flight counts once, under the first that applies: diverged (the engine stopped it), "
        f"lost track (its position error after the transient, or at the end if the transient never "
        f"settled into 5 %, above {spec.max_track_error_m:g} m, or its altitude error above "
        f"{spec.max_altitude_error_m:g} m), saturated (rotor duties clipped for "
        f"more than {spec.max_clipped_s:g} s), failed a requirement (missed one of the requirements "
        "below).\n",
        "| reason | flights | rate |",
        "|---|---|---|",
    ]
    for reason, v in f["by_reason"].items():
        lines.append(f"| {reason} | {v['count']:,} | {100 * v['rate']:.2f} % |")
    stops = engine_stops(summary)
    if stops:
        lines.append("\nHow the engine stopped the flights that diverged:\n")
        lines += [f"- {count:,}: {why}" for why, count in stops.items()]
    lines.append("\n### Requirements\n")
    if summary["requirements"]:
        lines += [
            "Flights that miss a requirement, whatever else they failed (an undefined value, such as "
            "the error after a transient that never settled, misses it).\n",
            "| requirement | flights that missed it | rate |",
            "|---|---|---|",
        ]
        lines += [
            f"| `{r['requirement']}` | {r['failed']:,} | {100 * r['rate']:.2f} % |" for r in summary["requirements"]
        ]
    else:
        lines.append('None given (`--require "steady_max_error_m<=0.2"`, or `requirements=` in Python).')
    ns = summary["not_settled"]
    lines.append(
        f"\nNot settled within {100 * ns['band']:g} % at the end (a metric, not a failure): "
        f"{ns['count']:,} flights ({100 * ns['rate']:.2f} %)."
    )
    if summary["stopped"]:
        lines.append(
            "\nWhy the engine stopped flights: " + "; ".join(f"{k}: {v:,}" for k, v in summary["stopped"].items()) + "."
        )
    left_out = summary["flights"] - summary["metrics_over"]
    lines += [
        "\n## Metrics\n",
        f"Over the {summary['metrics_over']:,} flights that kept track"
        + (
            f": the {left_out:,} that diverged or lost track are left out, so that their numbers do not pass "
            "for a good flight's."
            if left_out
            else "."
        )
        + "\n",
        "| metric | flights | p5 | p50 | p95 | max |",
        "|---|---|---|---|---|---|",
    ]
    for name, m in summary["metrics"].items():
        cells = " | ".join("-" if m[k] is None else f"{m[k]:.4g}" for k in ("p5", "p50", "p95", "max"))
        lines.append(f"| {name} | {m['count']:,} | {cells} |")
    lines += [
        "\n## Worst flights\n",
        "Fly one alone again: `quadcruise montecarlo <the same options> --case VEHICLE`, or in Python "
        "`quadcruise.montecarlo.montecarlo_case(spec, VEHICLE)`; it gives the same row.\n",
        "| vehicle | reason | " + " | ".join(metric_label(k) for k in WORST_COLUMNS) + " |",
        "|---|---|" + "---|" * len(WORST_COLUMNS),
    ]
    for _, r in worst.head(10).iterrows():
        cells = " | ".join(
            f"{r[k]:.4g}" if np.isfinite(r[k]) else _missing(metric(k), r["transient_axis"] >= 0) for k in WORST_COLUMNS
        )
        lines.append(f"| {int(r['vehicle'])} | {r['reason']} | {cells} |")
    info = result.info
    lines += [
        "\n## Figures\n",
        "![histograms](histograms.png)\n",
        "![envelope](envelope.png)\n",
        "\n## How it ran\n",
        f"{info.get('flown', 0):,} flights flown and {info.get('resumed', 0):,} resumed from disk on "
        f"{info.get('scheduler')}, chunks of {info.get('chunk_size')} vehicles, "
        f"{info.get('wall_s', 0):.1f} s. One row per flight: `{table_name}`; the chunks: `chunks/`.\n",
    ]
    return "\n".join(lines)
