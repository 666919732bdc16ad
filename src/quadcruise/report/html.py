"""A self-contained HTML report: metric tables, figures, an interactive 3-D view of the
flights and the configuration that produced them, in one file that needs no network.

Figures are embedded as base64 PNG, the 3-D view is plain JavaScript on a ``<canvas>``
(``viewer.js``, no library) fed by decimated paths embedded as JSON, and a
Content-Security-Policy forbids the page any request. The first script of the page
records every error (``window.onerror``, ``console.error``, a blocked request) in
``<pre id="qc-errors">``, and each canvas gets ``data-rendered="1"`` once drawn, so a
headless browser's DOM tells whether the page works. This module assembles the page and
renders its parts (tables, figures, 3-D views, markdown); what a flight's, a comparison's or the
reproduction's report holds: :mod:`quadcruise.report.sections`.

Examples
--------
>>> import quadcruise as qc
>>> from quadcruise.report import flight_report, html_report
>>> page = html_report(**flight_report(qc.fly("step", duration=2.0, log_every=10)))
>>> page.startswith("<!DOCTYPE html>"), page.count('<img src="data:image/png;base64,')
(True, 1)
>>> page.count("<canvas"), "http://" in page or "https://" in page
(1, False)
"""

from __future__ import annotations

import base64
import html
import io
import json
import math
import re
from importlib import resources
from pathlib import Path

import numpy as np

from quadcruise.errors import InputError
from quadcruise.io.files import atomic_path
from quadcruise.io.plainjson import dumps
from quadcruise.metrics.tables import DID_NOT_SETTLE, FAILED_FLIGHT, NO_OVERSHOOT, NO_TRANSIENT, metric_cell
from quadcruise.plots.thin import thinned

__all__ = [
    "html_report",
    "write_html_report",
    "markdown_html",
    "table_html",
]

MAX_POINTS = 2000
"""Most logged instants of one path embedded for the 3-D view."""
MAX_VEHICLES = 8
"""Most vehicles of one batched result shown in the 3-D view (stopped ones first)."""
COLORS = (
    "#1f77b4",
    "#ff7f0e",
    "#2ca02c",
    "#d62728",
    "#9467bd",
    "#8c564b",
    "#e377c2",
    "#7f7f7f",
    "#bcbd22",
    "#17becf",
)  # matplotlib's tab10, the C0..C9 of the figures
LABELS = {
    "rmse_m": "RMSE [m]",
    "settling_time_s": "settling time 2 % [s]",
    "settling_time_5pct_s": "settling time 5 % [s]",
    "overshoot_pct": "overshoot [%]",
    "steady_rmse_m": "RMSE after the transient [m]",
    "steady_max_error_m": "max error after the transient [m]",
    "effort": "effort about hover [s]",
    "axis": "transient axis",
}
MISSING = "—"


def _label(name, conventions: dict | None = None) -> str:
    """A column name as a heading: ``rise_time_s`` -> ``rise time [s]``; a settling time
    with the band its table's conventions give it."""
    if not isinstance(name, str):
        return str(name)
    bands = (conventions or {}).get("settling_columns", {})
    if name in bands:
        return f"settling time {format(100.0 * float(bands[name]), '.6g')} % [s]"
    if name in LABELS:
        return LABELS[name]
    for suffix, unit in (("_s", "s"), ("_m", "m"), ("_pct", "%"), ("_deg", "deg"), ("_rad", "rad")):
        if name.endswith(suffix) and len(name) > len(suffix):
            return f"{name[: -len(suffix)].replace('_', ' ')} [{unit}]"
    return name.replace("_", " ")


def table_html(frame) -> str:
    """A DataFrame as an HTML table.

    Numbers show 4 significant digits, NaN "—", and a NaN transient or steady metric as
    :func:`~quadcruise.metrics.tables.metric_cell` names it ("did not settle", "failed flight",
    "no transient", from the ``axis`` and ``status``, as columns or, in a transposed table, as
    rows); a status other than "finished" is shown in red. Column names become
    headings with their unit (``rise_time_s`` -> "rise time [s]").

    Parameters
    ----------
    frame : pandas.DataFrame
        The table; a meaningful index (not 0, 1, 2, ...) is shown as the first column(s).

    Returns
    -------
    str
        The ``<table>`` element, every text escaped.

    Examples
    --------
    >>> import pandas as pd
    >>> print(table_html(pd.DataFrame({"max_error_m": [0.012345]})))
    <table>
    <thead><tr><th>max error [m]</th></tr></thead>
    <tbody>
    <tr><td class="num">0.01235</td></tr>
    </tbody></table>
    """
    import pandas as pd

    def _axes(values):  # "" where the table measured no transient
        return None if values is None else values.map(lambda a: a if isinstance(a, str) else "")

    rows_axis = _axes(frame["axis"] if "axis" in frame.columns else None)
    cols_axis = _axes(frame.loc["axis"] if rows_axis is None and "axis" in frame.index else None)
    rows_status = frame["status"] if "status" in frame.columns else None
    cols_status = frame.loc["status"] if rows_status is None and "status" in frame.index else None
    shown_index = not (isinstance(frame.index, pd.RangeIndex) and frame.index.start == 0 and frame.index.step == 1)
    idx_names = [n for n in frame.index.names] if shown_index else []
    conventions = frame.attrs.get("conventions")
    head = [_label(n) if n is not None else "" for n in idx_names] + [_label(c, conventions) for c in frame.columns]
    out = ["<table>", "<thead><tr>" + "".join(f"<th>{html.escape(h)}</th>" for h in head) + "</tr></thead>", "<tbody>"]
    for r, (key, row) in enumerate(frame.iterrows()):
        keys = key if isinstance(key, tuple) else (key,)
        cells = [f'<th scope="row">{html.escape(_label(k, conventions))}</th>' for k in keys] if shown_index else []
        for c, (col, value) in enumerate(row.items()):
            axis = rows_axis.iloc[r] if rows_axis is not None else None
            status = rows_status.iloc[r] if rows_status is not None else None
            metric = col
            if cols_axis is not None or cols_status is not None:  # a transposed table: metrics down
                metric = key
                axis = cols_axis.iloc[c] if cols_axis is not None else None
                status = cols_status.iloc[c] if cols_status is not None else None
            text, num = metric_cell(value, metric, axis, MISSING, status=status)
            cls = ["num"] if num else []
            if text in (MISSING, DID_NOT_SETTLE, FAILED_FLIGHT, NO_TRANSIENT, NO_OVERSHOOT):
                cls.append("missing")
            if (col == "status" or key == "status") and isinstance(value, str):
                cls.append("ok" if value == "finished" else "bad")
            attr = f' class="{" ".join(cls)}"' if cls else ""
            cells.append(f"<td{attr}>{html.escape(text)}</td>")
        out.append("<tr>" + "".join(cells) + "</tr>")
    out.append("</tbody></table>")
    return "\n".join(out)


def _png_b64(fig) -> str:
    """A Figure, PNG bytes or a PNG file as base64."""
    if isinstance(fig, bytes | bytearray):
        data = bytes(fig)
    elif isinstance(fig, str | Path):
        data = Path(fig).read_bytes()
    elif hasattr(fig, "savefig"):
        buf = io.BytesIO()
        fig.savefig(buf, format="png", dpi=100)
        data = buf.getvalue()
    else:
        raise InputError(
            f"a report figure must be a matplotlib Figure, PNG bytes or a PNG file, got {type(fig).__name__}"
        )
    if not data.startswith(b"\x89PNG\r\n\x1a\n"):
        raise InputError("a report figure is not a PNG image")
    return base64.b64encode(data).decode("ascii")


def _series(t, pos, keep) -> dict:
    out = {"t": np.round(t[keep], 4).tolist()}
    for k, name in enumerate("xyz"):
        col = np.round(pos[keep, k], 4)
        out[name] = [None if v != v else v for v in col.tolist()]
    return out


def _view_data(flights: dict) -> dict:
    """The JSON of one 3-D view: each flight's decimated path, references deduplicated."""
    entries, refs = [], []
    for label, res in flights.items():
        picks = range(res.n)
        if res.n > MAX_VEHICLES:
            bad, good = np.flatnonzero(~res.ok), np.flatnonzero(res.ok)
            picks = sorted(np.concatenate([bad, good])[:MAX_VEHICLES].tolist())
        for v in picks:
            pos, ref = res.states[v, :, :3], res.references[v, :, :3]
            live = np.flatnonzero(np.all(np.isfinite(pos), axis=1))
            end = int(live[-1]) + 1 if live.size else 1
            step = max(1, math.ceil(end / MAX_POINTS))
            keep = thinned(0, end - 1, step)
            entry = {
                "label": label if res.n == 1 else f"{label} · vehicle {v}",
                "color": COLORS[len(entries) % len(COLORS)],
                "ok": bool(res.ok[v]),
                "status": res.status_text(v),
                "ref": None,
                **_series(res.t, pos, keep),
            }
            if np.any(np.all(np.isfinite(ref), axis=1)):
                rkeep = thinned(0, ref.shape[0] - 1, step)
                rdata = _series(res.t, ref, rkeep)
                entry["ref"] = next((i for i, r in enumerate(refs) if r == rdata), len(refs))
                if entry["ref"] == len(refs):
                    refs.append(rdata)
            entries.append(entry)
    return {"flights": entries, "refs": refs}


def _views(flights) -> list[tuple[str, dict]]:
    """``{label: SimResult}`` is one view; ``{title: {label: SimResult}}`` one per title."""
    from quadcruise.sim.result import SimResult

    if not flights:
        return []
    if all(isinstance(v, SimResult) for v in flights.values()):
        return [("", flights)]
    if all(isinstance(v, dict) and all(isinstance(r, SimResult) for r in v.values()) for v in flights.values()):
        return [(title, group) for title, group in flights.items() if group]
    raise InputError("flights must map labels to SimResults, or view titles to such mappings")


def _json_script(obj, cls: str) -> str:
    text = json.dumps(obj, separators=(",", ":"), allow_nan=False).replace("<", "\\u003c")
    return f'<script type="application/json" class="{cls}">{text}</script>'


def _asset(name: str) -> str:
    return resources.files("quadcruise.report").joinpath(name).read_text(encoding="utf-8")


CSS = """
:root { --ink: #1d2430; --muted: #5b6472; --line: #dde1e7; --bg: #f4f5f7; --card: #fff; --accent: #1f5fa8; }
* { box-sizing: border-box; }
body { margin: 0; background: var(--bg); color: var(--ink); font: 15px/1.5 system-ui, -apple-system,
  "Segoe UI", Roboto, "Helvetica Neue", Arial, sans-serif; }
header { background: #18212d; color: #fff; padding: 18px max(24px, calc(50vw - 620px)) 12px; }
header h1 { margin: 0; font-size: 24px; font-weight: 650; }
.qc-sub { margin: 2px 0 10px; color: #b9c2cf; font-size: 13px; }
nav a { color: #dce6f5; margin-right: 18px; text-decoration: none; font-size: 14px; }
nav a:hover { text-decoration: underline; }
main { max-width: 1240px; margin: 0 auto; padding: 8px 24px 40px; }
section { background: var(--card); border: 1px solid var(--line); border-radius: 8px; padding: 6px 20px 18px;
  margin: 18px 0; }
h2 { font-size: 19px; margin: 12px 0 10px; } h3 { font-size: 15px; margin: 14px 0 8px; color: #2b3442; }
#qc-errors { background: #fff0f0; color: #a40000; border: 1px solid #e5a0a0; padding: 10px;
  max-width: 1240px; margin: 12px auto; white-space: pre-wrap; }
.qc-tables { display: flex; flex-wrap: wrap; gap: 8px 36px; align-items: flex-start; }
.qc-table { max-width: 100%; overflow-x: auto; }
table { border-collapse: collapse; font-size: 13.5px; font-variant-numeric: tabular-nums; }
th, td { padding: 4px 12px; border-bottom: 1px solid var(--line); text-align: left; vertical-align: top; }
thead th { background: #eef1f5; font-weight: 600; border-bottom: 2px solid #c9cfd8; }
tbody tr:nth-child(even) { background: #fafbfc; } tbody tr:hover { background: #eef4fc; }
tbody th { font-weight: 500; color: #39424f; white-space: nowrap; }
td.num { text-align: right; } td.missing { color: #8a93a0; font-style: italic; text-align: right; white-space: nowrap; }
td.ok { color: #1e7b34; } td.bad { color: #c0201f; font-weight: 600; }
.qc-viewbox { display: flex; gap: 18px; flex-wrap: wrap; }
.qc-stage { flex: 1 1 640px; min-width: 0; }
.qc-canvas { display: block; width: 100%; height: 540px; border: 1px solid var(--line); border-radius: 6px;
  cursor: grab; touch-action: none; background: #fff; }
.qc-canvas.qc-dragging { cursor: grabbing; }
.qc-hint { color: var(--muted); font-size: 12.5px; margin-top: 4px; }
.qc-side { flex: 0 1 330px; font-size: 14px; }
.qc-flight { display: flex; align-items: center; gap: 7px; margin-top: 8px; cursor: pointer; font-weight: 550; }
.qc-swatch { width: 22px; height: 4px; border-radius: 2px; flex: none; }
.qc-dashed { background: repeating-linear-gradient(90deg, #222 0 6px, transparent 6px 10px); }
.qc-stopped { color: #c0201f; font-weight: 400; font-size: 12.5px; }
.qc-readout { margin-left: 29px; color: var(--muted); font-size: 12.5px; font-variant-numeric: tabular-nums; }
.qc-time { margin-top: 16px; } .qc-time input { width: 100%; }
.qc-trow { display: flex; align-items: center; gap: 10px; font-variant-numeric: tabular-nums; }
.qc-buttons { margin-top: 12px; display: flex; flex-wrap: wrap; gap: 6px; }
button { font: inherit; font-size: 13px; padding: 3px 10px; border: 1px solid #b9c1cc; border-radius: 5px;
  background: #f7f8fa; cursor: pointer; } button:hover { background: #e9eef5; }
figure { margin: 10px 0 22px; } figure img { max-width: 100%; height: auto; display: block;
  border: 1px solid var(--line); border-radius: 4px; }
figcaption { color: var(--muted); font-size: 13.5px; margin-top: 4px; }
.qc-notes { max-width: 860px; } .qc-notes p { margin: 8px 0; }
code { background: #eef1f5; padding: 0 4px; border-radius: 3px; font-size: 90%; }
pre.qc-config { background: #f7f8fa; border: 1px solid var(--line); border-radius: 6px; padding: 12px;
  max-height: 460px; overflow: auto; font-size: 12.5px; }
summary { cursor: pointer; color: var(--accent); margin: 6px 0; }
a { color: var(--accent); }
"""


ERROR_HOOK = """<script>
(function () {  /* first script of the page: every error is kept in pre#qc-errors */
  var errors = window.qcErrors = [];
  function show() {
    var box = document.getElementById("qc-errors");
    if (box && errors.length) { box.textContent = errors.join("\\n"); box.hidden = false; }
  }
  function record(text) { errors.push(String(text)); show(); }
  window.onerror = function (msg, src, line, col) { record("error: " + msg + " (line " + line + ":" + col + ")"); };
  window.addEventListener("error", function (e) {
    if (e.target && e.target !== window) record("could not load " + (e.target.alt || e.target.tagName));
  }, true);
  window.addEventListener("unhandledrejection", function (e) { record("unhandled rejection: " + e.reason); });
  document.addEventListener("securitypolicyviolation", function (e) { record("blocked request: " + e.blockedURI); });
  var original = console.error;
  console.error = function () {
    record("console.error: " + Array.prototype.join.call(arguments, " "));
    if (original) original.apply(console, arguments);
  };
  document.addEventListener("DOMContentLoaded", show);
})();
</script>"""

CSP = "default-src 'none'; img-src data:; style-src 'unsafe-inline'; script-src 'unsafe-inline'"


def html_report(
    *,
    title: str,
    tables: dict | None = None,
    figures: dict | None = None,
    flights: dict | None = None,
    config: dict | None = None,
    notes: str = "",
) -> str:
    """The report as one self-contained HTML page.

    Parameters
    ----------
    title : str
        The page's title and heading.
    tables : dict of str to pandas.DataFrame, optional
        Heading -> table, formatted by :func:`table_html`.
    figures : dict of str to Figure, PNG bytes or PNG file path, optional
        Caption -> figure, embedded as base64 PNG (100 dpi).
    flights : dict, optional
        ``{label: SimResult}`` for one interactive 3-D view, or ``{view title: {label:
        SimResult}}`` for several; paths are decimated to at most :data:`MAX_POINTS`
        logged instants, and at most :data:`MAX_VEHICLES` vehicles of a batch are shown.
    config : dict, optional
        The scenario or configuration that produced the report, shown as JSON.
    notes : str
        An HTML fragment inserted as is (see :func:`markdown_html` for text).

    Returns
    -------
    str
        The page; nothing in it is fetched from a network.
    """
    from quadcruise._version import __version__

    tables, figures, config = tables or {}, figures or {}, config or {}
    views = _views(flights or {})
    sections = []
    if tables:
        body = "".join(
            f'<div class="qc-table"><h3>{html.escape(name)}</h3>{table_html(frame)}</div>'
            for name, frame in tables.items()
        )
        sections.append(("tables", "Metrics", f'<div class="qc-tables">{body}</div>'))
    if views:
        body = []
        for i, (vtitle, group) in enumerate(views):
            head = f"<h3>{html.escape(vtitle)}</h3>" if vtitle else ""
            body.append(
                f'<div class="qc-view" id="qc-view-{i}">{head}'
                f'<div class="qc-viewbox"><div class="qc-stage"><canvas class="qc-canvas" '
                f'aria-label="{html.escape(vtitle or "flight")}: 3-D view">A 3-D view of the flight '
                f'(needs JavaScript).</canvas><div class="qc-hint">drag: orbit · shift-drag: '
                f'pan · wheel: zoom · double-click: reset</div></div><div class="qc-side">'
                f"</div></div>{_json_script(_view_data(group), 'qc-data')}</div>"
            )
        sections.append(("view", "3-D view", "".join(body)))
    if figures:
        body = "".join(
            f'<figure><img src="data:image/png;base64,{_png_b64(fig)}" alt="{html.escape(cap)}">'
            f"<figcaption>{html.escape(cap)}</figcaption></figure>"
            for cap, fig in figures.items()
        )
        sections.append(("figures", "Figures", body))
    if notes:
        sections.append(("notes", "Notes", f'<div class="qc-notes">{notes}</div>'))
    text = dumps(config, indent=2)
    link = base64.b64encode(text.encode()).decode("ascii")
    sections.append(
        (
            "config",
            "Scenario",
            f"<details open><summary>configuration that produced this report "
            f'(JSON)</summary><pre class="qc-config">{html.escape(text)}</pre></details><p>'
            f'<a download="quadcruise-config.json" href="data:application/json;base64,{link}">'
            f"save as quadcruise-config.json</a></p>",
        )
    )
    nav = " ".join(f'<a href="#{key}">{name}</a>' for key, name, _ in sections)
    main = "\n".join(f'<section id="{key}"><h2>{name}</h2>{body}</section>' for key, name, body in sections)
    return (
        f'<!DOCTYPE html>\n<html lang="en">\n<head>\n<meta charset="utf-8">\n{ERROR_HOOK}\n'
        f'<meta http-equiv="Content-Security-Policy" content="{CSP}">\n'
        f'<meta name="viewport" content="width=device-width, initial-scale=1">\n'
        f'<meta name="generator" content="quadcruise {html.escape(__version__)}">\n'
        f"<title>{html.escape(title)}</title>\n<style>\n{CSS}</style>\n</head>\n<body>\n"
        f'<pre id="qc-errors" hidden></pre>\n<header><h1>{html.escape(title)}</h1>'
        f'<p class="qc-sub">quadcruise {html.escape(__version__)} · self-contained report</p>'
        f"<nav>{nav}</nav></header>\n<main>\n{main}\n</main>\n"
        f"<script>\n{_asset('viewer.js')}</script>\n</body>\n</html>\n"
    )


def write_html_report(path, **kwargs) -> Path:
    """Write :func:`html_report` to ``path``, whole or not at all.

    Parameters
    ----------
    path : str or os.PathLike
        The HTML file; its folder is created if missing.
    **kwargs
        Keywords of :func:`html_report`.

    Returns
    -------
    pathlib.Path
        The file written.
    """
    page = html_report(**kwargs)
    path = Path(path)
    with atomic_path(path) as tmp:
        tmp.write_text(page, encoding="utf-8")
    return path


def _inline(text: str) -> str:
    text = html.escape(text, quote=False)
    text = re.sub(r"\*\*(.+?)\*\*", r"<strong>\1</strong>", text)
    text = re.sub(r"`([^`]+)`", r"<code>\1</code>", text)
    return re.sub(r"(?<![\w*])\*(?!\s)([^*]+?)\*(?!\w)", r"<em>\1</em>", text)


def markdown_html(text: str) -> str:
    """A little markdown as HTML: paragraphs, ``#`` headings, ``-`` lists, ``**bold**``,
    ``*italic*`` and ```code```; everything else is escaped.

    Parameters
    ----------
    text : str
        The markdown. Blocks are separated by blank lines; a heading of k ``#`` becomes
        ``<h{k+1}>`` (the page's sections are ``<h2>``).

    Returns
    -------
    str
        The HTML fragment, one element per line.

    Examples
    --------
    >>> markdown_html("## Why\\n\\nThe **pole** at <1.")
    '<h3>Why</h3>\\n<p>The <strong>pole</strong> at &lt;1.</p>'
    """
    out = []
    for block in re.split(r"\n\s*\n", text.strip()):
        lines = [line.strip() for line in block.strip().splitlines() if line.strip()]
        if not lines:
            continue
        heading = re.match(r"(#{1,4})\s+(.*)", lines[0])
        if heading:
            level = min(len(heading.group(1)) + 1, 6)
            out.append(f"<h{level}>{_inline(heading.group(2))}</h{level}>")
            lines = lines[1:]
        if lines and all(line.startswith(("- ", "* ")) for line in lines):
            out.append("<ul>" + "".join(f"<li>{_inline(line[2:])}</li>" for line in lines) + "</ul>")
        elif lines:
            out.append(f"<p>{_inline(' '.join(lines))}</p>")
    return "\n".join(out)
