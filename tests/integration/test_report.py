"""Tests of quadcruise.report (the self-contained HTML page) and quadcruise.plots.animate.

The page is checked as text (no network reference, tables, images, 3-D views, the
configuration) and in a real headless Chromium: its DOM after the scripts ran (no error
recorded, every canvas drawn, the controls built) and a screenshot (the 3-D view is not
blank). A deliberately broken page proves the error check can fail.

The browser tests need Debian's chromium at /usr/bin/chromium (or QUADCRUISE_CHROMIUM); they
are skipped without it, unless QUADCRUISE_REQUIRE_BROWSER=1, which makes a missing browser a
failure (CI). With QUADCRUISE_ARTIFACTS=<folder>, the screenshot is also copied there.
"""

from __future__ import annotations

import html
import json
import os
import re
import shutil
import subprocess
import tempfile
import time
from html.parser import HTMLParser
from pathlib import Path

import numpy as np
import pytest
from PIL import Image

import quadcruise as qc
from quadcruise.io.plainjson import dumps
from quadcruise.metrics.tables import cell
from quadcruise.plots import animate
from quadcruise.report import html as report
from quadcruise.report.html import html_report, markdown_html, table_html, write_html_report
from quadcruise.report.sections import comparison_report, flight_report, reproduction_report
from quadcruise.workflows.compare import compare
from quadcruise.workflows.reproduce import fitted_nlpd_loop, reproduce

CHROMIUM = os.environ.get("QUADCRUISE_CHROMIUM", "/usr/bin/chromium")
FLAGS = (
    "--headless",
    "--no-sandbox",
    "--disable-gpu",
    "--disable-quic",
    "--no-first-run",
    "--disable-background-networking",
    "--disable-component-update",
    "--disable-sync",
)
WINDOW = (1280, 2000)


# --- fixtures ----------------------------------------------------------------------------


@pytest.fixture(scope="module")
def circle():
    return qc.fly("circle")  # 20 s at 1 kHz: 20,001 logged instants


@pytest.fixture(scope="module")
def flight_page(circle, tmp_path_factory):
    path = tmp_path_factory.mktemp("report") / "flight.html"
    return write_html_report(path, **flight_report(circle))


@pytest.fixture(scope="module")
def rep():
    return reproduce(scenarios=("circle", "square"), controllers=("nlpd", "gonzalez"), fitted=False)


class Dom(HTMLParser):
    """Elements of a page: tags with attributes, and the text of selected elements."""

    def __init__(self, text: str):
        super().__init__()
        self.tags: list[tuple[str, dict]] = []
        self.text: dict[str, str] = {}
        self._open: list[str] = []
        self.feed(text)

    def handle_starttag(self, tag, attrs):
        attrs = {k: v or "" for k, v in attrs}
        self.tags.append((tag, attrs))
        key = attrs.get("id") or attrs.get("class", "").split(" ")[0]
        if tag in ("pre", "script") and key:
            self._open.append(key)
            self.text.setdefault(key, "")

    def handle_endtag(self, tag):
        if tag in ("pre", "script") and self._open:
            self._open.pop()

    def handle_data(self, data):
        if self._open:
            self.text[self._open[-1]] += data

    def find(self, tag, **attrs):
        return [a for t, a in self.tags if t == tag and all(a.get(k) == v for k, v in attrs.items())]


# --- the page as text -------------------------------------------------------------------


def test_page_is_self_contained(flight_page, circle):
    page = flight_page.read_text()
    dom = Dom(page)
    # every src and href is inline data or an anchor: nothing to fetch
    refs = re.findall(r"""\b(?:src|href)\s*=\s*["']?([^"'\s>]*)""", page)
    assert refs and all(r.startswith(("data:", "#")) for r in refs), [r[:40] for r in refs]
    assert not re.search(r"https?://", page)
    assert "Content-Security-Policy" in page
    # the error hook is the first script, the recorder hidden and empty
    assert page.index("window.onerror") < page.index("<script", page.index("window.onerror") + 1)
    assert dom.find("pre", id="qc-errors") and dom.text["qc-errors"] == ""
    # tables (the metrics, what they measure, the run), with the formatting rules
    assert len(dom.find("table")) == 3
    rmse = cell(float(circle.metrics()["rmse_m"][0]))[0]  # 0.4205 m on the default circle
    assert f'<td class="num">{rmse}</td>' in page and "no overshoot" in page
    assert "RMSE after the transient [m]" in page and "effort about hover [s]" in page
    assert "10-90 % of the step" in page and "u_hover = m g / (4 K)" in page
    imgs = [a for a in dom.find("img")]
    assert len(imgs) == 1 and page.count('<img src="data:image/png;base64,') == 1
    assert len(dom.find("canvas")) == 1
    # the configuration, as JSON that reads back
    shown = json.loads(html.unescape(dom.text["qc-config"]))
    assert shown == json.loads(dumps(circle.meta))
    assert shown["mission"]["kind"] == "circle"


def test_paths_are_decimated(flight_page, circle):
    data = json.loads(Dom(flight_page.read_text()).text["qc-data"])
    (f,) = data["flights"]
    assert circle.t.size > 20000 and len(f["t"]) <= report.MAX_POINTS + 1
    assert f["t"][-1] == pytest.approx(circle.t[-1])
    assert [f["x"][-1], f["y"][-1], f["z"][-1]] == pytest.approx(circle.states[0, -1, :3], abs=1e-4)
    assert f["ref"] == 0 and len(data["refs"]) == 1 and f["ok"] and f["label"] == "nlpd on circle"


def test_stopped_flight_without_reference(diverged):
    kwargs = flight_report(diverged)
    data = report._view_data(kwargs["flights"])
    (f,) = data["flights"]
    assert data["refs"] == [] and f["ref"] is None and not f["ok"] and "diverged" in f["status"]
    assert None not in f["x"]  # cut where the vehicle stopped
    dom = Dom(html_report(**kwargs))
    for key in ("qc-data", "qc-config"):
        assert "Infinity" not in dom.text[key] and "NaN" not in dom.text[key]


def test_table_formatting():
    import pandas as pd

    frame = pd.DataFrame(
        {
            "status": ["finished", "diverged: x"],
            "axis": ["x", None],
            "rise_time_s": [2.86515, np.nan],
            "settling_time_s": [np.nan, np.nan],
            "effort": [12345.6, 1e-5],
            "n": [3, 4],
        }
    )
    text = table_html(frame)
    assert "did not settle" in text and text.count("did not settle") == 1  # not where no axis
    assert "2.865" in text and "12,346" in text and "1.000e-05" in text and "—" in text
    assert '<td class="bad">diverged: x</td>' in text and '<td class="ok">finished</td>' in text
    assert "rise time [s]" in text and "settling time 2 % [s]" in text
    assert "<th>" in text and 'scope="row"' not in text  # a 0, 1, ... index is not shown
    flipped = table_html(frame.iloc[:1].T.rename(columns={0: "nlpd"}))  # metrics down
    assert "did not settle" in flipped and 'scope="row"' in flipped


def test_markdown():
    out = markdown_html("## Why\n\nThe **pole** at <1 and `code`.\n\n- one\n- two *three*")
    assert out == (
        "<h3>Why</h3>\n<p>The <strong>pole</strong> at &lt;1 and <code>code</code>.</p>\n"
        "<ul><li>one</li><li>two <em>three</em></li></ul>"
    )


def test_builders(rep):
    cmp = compare("step", ("nlpd", "se3"), duration=3.0, log_every=10)
    kw = comparison_report(cmp)
    assert list(kw["tables"]["Metrics by controller"].columns) == ["nlpd", "se3"]
    assert list(kw["flights"]) == ["nlpd", "se3"] and "metrics" not in kw["config"]
    page = html_report(**kw)
    assert page.count("<canvas") == 1 and page.count("data:image/png;base64,") == 1

    kw = reproduction_report(rep, figures={})
    assert set(kw["flights"]) == {"circle", "square"}
    assert set(kw["flights"]["circle"]) == {"nlpd", "gonzalez"}
    table = kw["tables"]["Results against the paper"]
    assert len(table) == 4 and table["paper: settling_time_s"].tolist() == [2.0, 12.0, 2.0, 12.0]
    assert "<strong>Rise time" in kw["notes"] and "<h3>" in kw["notes"]
    dom = fitted_nlpd_loop()["dom_pole"]  # computed from analyze's linearised loop
    assert f"dominant pair at {dom.real:.2f} +- {dom.imag:.2f}j" in " ".join(kw["notes"].split())
    assert "does not say which convention" in kw["notes"]
    page = html_report(**kw)
    assert page.count("<canvas") == 2 and "did not settle" not in page


def test_a_single_flight_is_not_called_vehicle_0():
    kw = flight_report(qc.fly("step", duration=2.0, log_every=10))
    assert list(kw["figures"]) == ["Flight: nlpd on step"]
    assert list(kw["tables"]["Flight metrics"].columns) == ["nlpd on step"]
    assert "vehicle 0" not in html_report(**kw)
    kw = flight_report(qc.fly("step", duration=2.0, log_every=10, n=2))
    assert list(kw["figures"]) == ["Flight of vehicle 0: nlpd on step", "All 2 vehicles"]
    assert list(kw["tables"]["Flight metrics"].columns) == ["vehicle 0", "vehicle 1"]


def test_write_is_atomic(tmp_path, circle):
    with pytest.raises(qc.InputError, match="matplotlib Figure"):
        write_html_report(tmp_path / "r.html", title="x", figures={"bad": 42})
    assert list(tmp_path.iterdir()) == []
    with pytest.raises(qc.InputError, match="labels to SimResults"):
        html_report(title="x", flights={"a": 1})


# --- the page in a real browser ---------------------------------------------------------


def browser(path: str = CHROMIUM) -> str:
    """The browser's path; skip without one, fail if QUADCRUISE_REQUIRE_BROWSER=1."""
    if os.path.isfile(path) and os.access(path, os.X_OK):
        return path
    if os.environ.get("QUADCRUISE_REQUIRE_BROWSER") == "1":
        pytest.fail(f"QUADCRUISE_REQUIRE_BROWSER=1 but there is no browser at {path} (apt-get install chromium)")
    pytest.skip(
        f"no headless browser at {path}: apt-get install chromium to run this test "
        "(QUADCRUISE_REQUIRE_BROWSER=1 turns this skip into a failure)"
    )


def chromium(page: Path, *args: str) -> str:
    """Run headless Chromium on a local page; its stdout."""
    exe = browser()
    with tempfile.TemporaryDirectory(ignore_cleanup_errors=True) as profile:
        proc = subprocess.run(
            [
                exe,
                *FLAGS,
                f"--user-data-dir={profile}",
                "--virtual-time-budget=5000",
                f"--window-size={WINDOW[0]},{WINDOW[1]}",
                *args,
                page.resolve().as_uri(),
            ],
            capture_output=True,
            text=True,
            timeout=120,
        )
    assert proc.returncode == 0, proc.stderr[-3000:]
    return proc.stdout


def rendered_dom(page: Path) -> Dom:
    return Dom(chromium(page, "--dump-dom"))


def test_browser_skip_or_fail(monkeypatch):
    missing = "/nonexistent/chromium"
    monkeypatch.delenv("QUADCRUISE_REQUIRE_BROWSER", raising=False)
    with pytest.raises(pytest.skip.Exception, match="apt-get install chromium"):
        browser(missing)
    monkeypatch.setenv("QUADCRUISE_REQUIRE_BROWSER", "1")
    with pytest.raises(pytest.fail.Exception, match="QUADCRUISE_REQUIRE_BROWSER=1"):
        browser(missing)


@pytest.mark.browser
def test_browser_renders_flight_page(flight_page):
    dom = rendered_dom(flight_page)
    assert dom.text["qc-errors"] == "", dom.text["qc-errors"]
    canvases = dom.find("canvas")
    assert len(canvases) == 1 and all(c.get("data-rendered") == "1" for c in canvases)
    assert int(canvases[0]["width"]) > 300  # sized to its box
    assert len(dom.find("input", type="checkbox")) == 2  # the flight and the reference
    assert dom.find("input", type="range") and len(dom.find("table")) == 3  # metrics, conventions, run
    assert len([a for a in dom.find("img") if a["src"].startswith("data:image/png;base64,")]) == 1


@pytest.mark.browser
def test_browser_renders_several_views(rep, diverged, tmp_path):
    kw = reproduction_report(rep, figures={})
    kw["flights"]["replay"] = {"stopped": diverged}  # no reference, stops early
    page = write_html_report(tmp_path / "rep.html", **kw)
    dom = rendered_dom(page)
    assert dom.text["qc-errors"] == "", dom.text["qc-errors"]
    canvases = dom.find("canvas")
    assert len(canvases) == 3 and all(c.get("data-rendered") == "1" for c in canvases)
    assert len(dom.find("input", type="checkbox")) == 3 + 3 + 1


@pytest.mark.browser
@pytest.mark.parametrize(
    "notes, expected",
    [
        ("<script>undefined_function()</script>", "undefined_function"),
        ("<script>console.error('bad thing')</script>", "bad thing"),
        ('<img alt="remote" src="https://example.invalid/x.png">', "blocked"),
    ],
)
def test_browser_catches_a_broken_page(notes, expected, tmp_path, circle):
    page = write_html_report(
        tmp_path / "broken.html", title="broken", notes=notes, flights={"circle": circle.decimate(10)}
    )
    dom = rendered_dom(page)
    assert expected in dom.text["qc-errors"], dom.text["qc-errors"]
    assert dom.find("canvas")[0].get("data-rendered") == "1"  # the rest of the page still works


@pytest.mark.browser
def test_browser_screenshot(circle, tmp_path):
    # a test-only script reports where the canvas is, in page pixels
    where = (
        "<script>addEventListener('load', () => { const r = document.querySelector('canvas')"
        ".getBoundingClientRect(); document.body.setAttribute('data-canvas', [r.left + scrollX, "
        "r.top + scrollY, r.width, r.height].map(Math.round).join(',')); });</script>"
    )
    kw = flight_report(circle)
    kw["notes"] = where
    page = write_html_report(tmp_path / "flight.html", **kw)
    dom = rendered_dom(page)
    assert dom.text["qc-errors"] == "", dom.text["qc-errors"]
    x, y, w, h = map(int, dom.find("body")[0]["data-canvas"].split(","))
    assert w > 300 and h > 300 and y + h <= WINDOW[1], "the 3-D view must be on the first screen"
    shot = tmp_path / "flight.png"
    start = time.perf_counter()
    chromium(page, f"--screenshot={shot}")
    print(f"screenshot in {time.perf_counter() - start:.1f} s")
    img = np.asarray(Image.open(shot).convert("RGB")).astype(int)
    assert img.shape[:2] == (WINDOW[1], WINDOW[0])
    assert img.reshape(-1, 3).std(axis=0).max() > 20  # not one colour
    view = img[y + 5 : y + h - 5, x + 5 : x + w - 5]
    assert view.reshape(-1, 3).std(axis=0).max() > 10  # the 3-D view is not blank
    blue = np.all(np.abs(view - [0x1F, 0x77, 0xB4]) < 40, axis=2)  # the path, in tab:blue
    assert blue.sum() > 500, blue.sum()
    colours = np.unique(view.reshape(-1, 3) // 16, axis=0)
    assert len(colours) > 20
    if os.environ.get("QUADCRUISE_ARTIFACTS"):
        out = Path(os.environ["QUADCRUISE_ARTIFACTS"])
        out.mkdir(parents=True, exist_ok=True)
        shutil.copy(shot, out / "report_screenshot.png")


VIEWS = {"home": None, "top": 1, "side (x-z)": 2, "side (y-z)": 3}  # index of the view's button


@pytest.mark.browser
@pytest.mark.parametrize("view", list(VIEWS))
def test_browser_axis_labels_are_readable_in_every_view(view, circle, tmp_path):
    """The viewer reports the axis labels it drew (data-labels): none overlaps another or
    leaves the canvas, none is smaller than 12 px, each axis in the picture's plane is
    labelled, and the depth axis of a side view, seen end-on, is not."""
    button = VIEWS[view]
    kw = flight_report(circle.decimate(10))
    kw.pop("figures")
    if button is not None:
        kw["notes"] = (
            "<script>addEventListener('load', () => document.querySelectorAll("
            f"'.qc-buttons button')[{button}].click());</script>"
        )
    dom = rendered_dom(write_html_report(tmp_path / "view.html", **kw))
    assert dom.text["qc-errors"] == "", dom.text["qc-errors"]
    (canvas,) = dom.find("canvas")
    labels = json.loads(canvas["data-labels"])
    width, height = int(canvas["width"]), int(canvas["height"])
    boxes = [lb["box"] for lb in labels]
    for i, (x0, y0, x1, y1) in enumerate(boxes):
        assert 0 <= x0 < x1 <= width and 0 <= y0 < y1 <= height, labels[i]
        for j in range(i):
            a0, b0, a1, b1 = boxes[j]
            assert x1 <= a0 or a1 <= x0 or y1 <= b0 or b1 <= y0, (labels[j], labels[i])
    assert min(lb["px"] for lb in labels) >= 12
    by_kind = {}
    for lb in labels:
        by_kind.setdefault(lb["kind"], []).append(lb["text"])
    shown = {"home": "xyz", "top": "xy", "side (x-z)": "xz", "side (y-z)": "yz"}[view]
    for axis in shown:
        ticks = [float(t) for t in by_kind.get(axis, [])]
        assert len(ticks) >= (2 if axis == "z" else 4), (axis, by_kind)
        assert np.allclose(np.diff(ticks), np.diff(ticks)[0])  # evenly thinned
        assert by_kind[f"{axis} name"] == [f"{axis} [m]"]
    hidden = {"side (x-z)": "y", "side (y-z)": "x", "top": "z"}.get(view)
    if hidden:
        assert hidden not in by_kind and f"{hidden} name" not in by_kind, by_kind


# --- the animation ----------------------------------------------------------------------


def test_gif_frames_and_no_temp(tmp_path):
    res = qc.fly("circle", duration=4.0, log_every=10)
    out = animate.animate_flight(res, tmp_path / "a.gif", fps=10)
    assert out == tmp_path / "a.gif" and [p.name for p in tmp_path.iterdir()] == ["a.gif"]
    with Image.open(out) as img:
        assert img.n_frames == 40 and img.size == (640, 288)
    with Image.open(animate.animate_flight(res, tmp_path / "b.gif", every=20)) as img:
        assert img.n_frames == 21  # 401 instants, one frame per 20
    with Image.open(animate.animate_flight(res, tmp_path / "c.gif", fps=5, duration_s=2.0)) as img:
        assert img.n_frames == 10


def test_gif_of_twenty_seconds(circle, tmp_path):
    out = animate.animate_flight(circle, tmp_path / "circle.gif", fps=25)
    with Image.open(out) as img:
        assert img.n_frames == 500


def test_gif_of_a_stopped_vehicle(diverged, tmp_path):
    out = animate.animate_flight(diverged, tmp_path / "d.gif", fps=20)
    end = diverged.t[np.flatnonzero(np.isfinite(diverged.states[0, :, 0]))[-1]]
    with Image.open(out) as img:  # frames cover the flight up to the stop
        assert img.n_frames == max(2, round(20 * end))


def test_animation_errors(tmp_path, circle, monkeypatch):
    with pytest.raises(qc.InputError, match="gif or .mp4"):
        animate.animate_flight(circle, tmp_path / "a.avi")
    with pytest.raises(qc.InputError, match="vehicle 3"):
        animate.animate_flight(circle, tmp_path / "a.gif", vehicle=3)
    with pytest.raises(qc.InputError, match="every"):
        animate.animate_flight(circle, tmp_path / "a.gif", every=0)
    monkeypatch.setattr(animate, "_ffmpeg", lambda: None)
    with pytest.raises(qc.InputError, match=r"needs ffmpeg.*\.gif"):
        animate.animate_flight(circle, tmp_path / "a.mp4")
    assert list(tmp_path.iterdir()) == []


def test_mp4_with_ffmpeg(tmp_path):
    if animate._ffmpeg() is None:
        pytest.skip("ffmpeg is not installed; .mp4 is refused (tested above)")
    res = qc.fly("step", duration=2.0, log_every=10)
    out = animate.animate_flight(res, tmp_path / "s.mp4", fps=10)
    assert out.read_bytes()[4:8] == b"ftyp" and [p.name for p in tmp_path.iterdir()] == ["s.mp4"]


def test_labels_cannot_break_out_of_the_page(circle):
    evil = "</script><script>alert(1)</script>"
    dom = Dom(html_report(title=evil, flights={evil: circle.decimate(50)}, config={"x": evil}))
    assert evil not in dom.text["qc-data"] and json.loads(dom.text["qc-data"])["flights"][0]["label"] == evil
    assert not dom.find("script", src="") and len(dom.find("script")) == 3  # hook, data, viewer


# --- issue 33: the identify and reproduce reports show their tables -----------------------------


@pytest.fixture(scope="module")
def identified(tmp_path_factory):
    """An identification of a sysid flight's PX4 log (what `quadcruise identify --report` reports)."""
    folder = tmp_path_factory.mktemp("identify")
    log = qc.fly("sysid").to_ulog(folder / "sysid.ulg")
    return qc.identify(log, mass=3.499)


@pytest.fixture(scope="module")
def fitted_rep():
    return reproduce(scenarios=("step",), controllers=("nlpd",), fitted=True)


def no_markdown_table(page: str) -> None:
    """No line of a Markdown table (``| a | b |``, ``|---|``) anywhere in the page's text."""
    text = re.sub(r"<script.*?</script>|<style.*?</style>", "", page, flags=re.S)
    assert "|---" not in text and not re.search(r"\|\s*\w[^|<]*\|\s*\w", text), re.findall(r".{40}\|.{40}", text)[:3]


def test_the_identify_report_is_built_from_the_result(identified):
    from quadcruise.report.identify import identification_report

    kw = identification_report(identified)
    params = kw["tables"]["Parameters (95 % intervals)"]
    assert list(params.index) == list(identified.parameters)  # every parameter, one row each
    for name, p in identified.parameters.items():
        assert params.loc[name, "value"] == pytest.approx(p["value"])
        assert params.loc[name, "identifiable"] == ("yes" if p["identifiable"] else "no")
    assert kw["tables"]["The log and the fit"].loc["log", "value"] == identified.log["source"]
    assert "|" in identified.report_md()  # report.md keeps its Markdown tables, for a Markdown reader
    page = html_report(**kw)
    no_markdown_table(page)
    assert page.count("<table>") == 4 and "hover_duty" in page
    assert list(kw["tables"])[0] == "Verdict"  # first, as the summary's first line
    assert kw["tables"]["Verdict"].loc["verdict", "value"] == identified.verdict_line().removeprefix("verdict: ")


def test_the_reproduce_report_shows_the_fitted_table_it_speaks_of(fitted_rep, rep):
    kw = reproduction_report(fitted_rep, figures={})
    fitted = kw["tables"]["Fitted to the paper's transients (both rise conventions)"]
    runs = [r for r in fitted_rep.runs if r["scenario"] == "entry"]
    assert list(fitted.index) == [r["controller"] for r in runs] and len(runs) >= 3
    for r in runs:  # both conventions, as the text says, and the paper's numbers beside them
        assert fitted.loc[r["controller"], "rise_0_100_s"] == pytest.approx(r["rise_0_100_s"])
        assert fitted.loc[r["controller"], "rise_time_s"] == pytest.approx(r["rise_time_s"])
    assert fitted["paper: overshoot_pct"].notna().all()
    page = html_report(**kw)
    no_markdown_table(page)
    assert "table of fitted gains, where flown, gives both" in page and "below gives both" not in page
    assert "gains fitted to its numbers" in page  # the note that explains the table
    unfitted = reproduction_report(rep, figures={})  # not flown: no table, and no note of one
    assert list(unfitted["tables"]) == ["Results against the paper"]
    assert "gains fitted to its numbers" not in unfitted["notes"]


@pytest.mark.browser
def test_browser_renders_the_identify_and_reproduce_tables(identified, fitted_rep, tmp_path):
    from quadcruise.report.identify import identification_report

    for name, kw, tables in (
        ("identify", identification_report(identified), 4),  # the verdict, parameters, validation, the log
        ("reproduce", reproduction_report(fitted_rep, figures={}), 2),
    ):
        page = write_html_report(tmp_path / f"{name}.html", **kw)
        dom = rendered_dom(page)
        assert dom.text["qc-errors"] == "", dom.text["qc-errors"]
        assert len(dom.find("table")) == tables, name
        shot = tmp_path / f"{name}.png"
        chromium(page, f"--screenshot={shot}")
        img = np.asarray(Image.open(shot).convert("RGB")).astype(int)
        assert img.reshape(-1, 3).std(axis=0).max() > 20  # a page drawn, not one colour
        if os.environ.get("QUADCRUISE_ARTIFACTS"):
            out = Path(os.environ["QUADCRUISE_ARTIFACTS"])
            out.mkdir(parents=True, exist_ok=True)
            shutil.copy(shot, out / f"{name}_report_screenshot.png")
