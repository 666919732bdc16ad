"""Tests of quadcruise.plots: figure structure, labels with units, that the drawn data
are the result's traces, early-stop marking, NaN references, and atomic PNG writing."""

from __future__ import annotations

import dataclasses
import doctest
import os
import threading
import warnings
from types import SimpleNamespace

import numpy as np
import pytest
from matplotlib.figure import Figure

import quadcruise as qc
from quadcruise.disturbances import Environment, Gust, RotorLoss
from quadcruise.layout import CMD_FLAGS, CMD_U1
from quadcruise.missions import Step
from quadcruise.plots import flight as plots
from quadcruise.plots import marks, plot_envelope, plot_flight, plot_paths, save_figure
from quadcruise.plots import montecarlo as mc_plots
from quadcruise.workflows.fly_inputs import hover_state

PNG_MAGIC = b"\x89PNG\r\n\x1a\n"


@pytest.fixture(scope="module")
def step():
    return qc.fly("step", duration=3.0, log_every=10)


@pytest.fixture(scope="module")
def circle():
    return qc.fly("circle", duration=3.0, log_every=10)


def axis_by_ylabel(fig, start):
    hits = [ax for ax in fig.axes if ax.name != "3d" and ax.get_ylabel().startswith(start)]
    assert len(hits) == 1, [ax.get_ylabel() for ax in fig.axes]
    return hits[0]


def line(ax, label):
    hits = [ln for ln in ax.get_lines() if ln.get_label() == label]
    assert len(hits) == 1, [ln.get_label() for ln in ax.get_lines()]
    return hits[0]


def labels(ax):
    return [ln.get_label() for ln in ax.get_lines()]


def test_plot_flight_structure_labels_and_data(step):
    fig = plot_flight(step)
    assert isinstance(fig, Figure)
    assert len(fig.axes) == 9
    path = fig.axes[0]
    assert path.name == "3d"
    assert [path.get_xlabel(), path.get_ylabel(), path.get_zlabel()] == ["x [m]", "y [m]", "z [m]"]
    for name in "xyz":
        ax = axis_by_ylabel(fig, f"{name} [m]")
        np.testing.assert_array_equal(line(ax, name).get_xdata(), step.t)
        np.testing.assert_array_equal(line(ax, name).get_ydata(), step.state(name)[0])
        np.testing.assert_array_equal(line(ax, "reference").get_ydata(), step.state(f"{name}_ref")[0])
    for name, sp, label in (("phi", "phi_d", "roll"), ("theta", "theta_d", "pitch"), ("psi", "psi_d", "yaw")):
        ax = axis_by_ylabel(fig, label)
        assert ax.get_ylabel().endswith("[deg]")
        trace = [ln for ln in ax.get_lines() if ln.get_label().startswith(label)][0]
        np.testing.assert_allclose(trace.get_ydata(), np.degrees(step.state(name)[0]))
        np.testing.assert_allclose(line(ax, "setpoint").get_ydata(), np.degrees(step.state(sp)[0]))
    duty = axis_by_ylabel(fig, "rotor duty")
    assert duty.get_ylabel().endswith("[-]")
    for j in range(1, 5):
        np.testing.assert_array_equal(line(duty, f"u{j}").get_ydata(), step.state(f"u{j}")[0])
    limits = [ln for ln in duty.get_lines() if ln.get_linestyle() == "-."]
    assert sorted(ln.get_ydata()[0] for ln in limits) == [0.0, 1.0]
    time_axes = [ax for ax in fig.axes[1:] if ax.get_xlabel()]
    assert len(time_axes) == 3 and all(ax.get_xlabel() == "time [s]" for ax in time_axes)
    assert duty.get_xlim() == (step.t[0], step.t[-1])
    assert "nlpd" in fig._suptitle.get_text() and "step" in fig._suptitle.get_text()
    assert not any(ln.get_label().startswith("stopped") for ax in fig.axes for ln in ax.get_lines())


def test_plot_flight_path_3d_has_markers_and_dashed_reference(circle):
    fig = circle.plot(title="my title")  # SimResult.plot delegates here
    assert fig._suptitle.get_text() == "my title"
    path = fig.axes[0]
    ref = line(path, "reference")
    assert ref.get_linestyle() == "--"
    xs, ys, zs = line(path, "actual").get_data_3d()
    np.testing.assert_array_equal(xs, circle.state("x")[0])
    np.testing.assert_array_equal(zs, circle.state("z")[0])
    legend = [t.get_text() for t in path.get_legend().get_texts()]
    assert {"actual", "reference", "start", "end"} <= set(legend)


def test_flagged_controller_limits_are_shaded(step):
    commands = step.commands.copy()
    commands[0, 5:9, CMD_FLAGS] = 1.0
    flagged = dataclasses.replace(step, commands=commands)
    duty = axis_by_ylabel(plot_flight(flagged), "rotor duty")
    assert "controller limit flagged" in [c.get_label() for c in duty.collections]
    duty = axis_by_ylabel(plot_flight(step), "rotor duty")
    assert "controller limit flagged" not in [c.get_label() for c in duty.collections]


def legend_texts(ax):
    legend = ax.get_legend()
    return [t.get_text() for t in legend.get_texts()] if legend is not None else []


def all_legend_texts(fig):
    return [text for ax in fig.axes for text in legend_texts(ax)]


def test_flight_has_a_log_position_error_panel(step, circle):
    """After the transient the error is centimetres on a circle, millimetres on a step: a
    log axis keeps it readable next to the metres of the transient."""
    for res in (step, circle):
        ax = axis_by_ylabel(plot_flight(res), "position error")
        assert ax.get_yscale() == "log" and ax.get_ylabel() == "position error [m]"
        err = np.linalg.norm(res.states[0, :, :3] - res.references[0, :, :3], axis=1)
        curve = line(ax, "|p - p_ref|")
        np.testing.assert_array_equal(curve.get_xdata(), res.t)
        np.testing.assert_allclose(curve.get_ydata(), np.maximum(err, marks.ERROR_FLOOR))
        lo, hi = ax.get_ylim()
        assert lo < err[-1] < hi and lo < err.max() < hi and hi / lo >= 10
        assert ax.get_xlim() == (res.t[0], res.t[-1])
    # the step holds its reference exactly before t = 1 s: drawn on the named 0.1 mm floor
    assert "≤ 0.1 mm (drawn here)" in legend_texts(axis_by_ylabel(plot_flight(step), "position error"))
    assert not any("≤" in text for text in legend_texts(axis_by_ylabel(plot_flight(circle), "position error")))


def test_events_of_the_environment_are_marked():
    env = Environment(
        gust=Gust(amplitude=(3.0, 4.0, 0.0), start=0.5, duration=1.0),
        rotor_loss=RotorLoss(rotor=2, fraction=0.3, time=2.0),
    )
    res = qc.fly("step", duration=3.0, log_every=10, environment=env)
    fig = plot_flight(res)
    for ax in fig.axes[1:]:  # on every time panel
        loss = [ln for ln in ax.get_lines() if ln.get_color() == marks.EVENT_COLORS["rotor_loss"]]
        assert len(loss) == 1 and list(loss[0].get_xdata()) == [2.0, 2.0]
        gust = [p for p in ax.patches if p.get_facecolor()[:3] == pytest.approx((0.09, 0.745, 0.812), abs=0.01)]
        assert len(gust) == 1 and gust[0].get_x() == 0.5 and gust[0].get_width() == pytest.approx(1.0)
    err = axis_by_ylabel(fig, "position error")
    events = [text for text in legend_texts(err) if text.startswith(("gust", "rotor"))]
    assert events == ["gust 5 m/s, 0.5-1.5 s", "rotor 2 loses 30 % at 2 s"]
    # per-vehicle fields: each vehicle's own; an event after the end is left out
    meta = {**res.meta, "environment": {"rotor_loss": {"rotor": [1, 3], "fraction": [0.1, 0.5], "time": [1.0, 9.0]}}}
    two = dataclasses.replace(res, meta=meta)
    assert [e.label for e in marks.flight_events(meta, 1)] == ["rotor 3 loses 50 % at 9 s"]
    assert "rotor 1 loses 10 % at 1 s" in legend_texts(axis_by_ylabel(plot_flight(two), "position error"))
    # no environment, or one that cannot be read: no marker
    for meta in (
        {},
        {"environment": None},
        {"environment": {"custom": "mine"}},
        {"environment": {"gust": {"start": "soon"}, "rotor_loss": {"rotor": 1}}},
    ):
        assert marks.flight_events(meta) == []
        fig = plot_flight(dataclasses.replace(res, meta=meta))
        assert legend_texts(axis_by_ylabel(fig, "position error")) == ["|p - p_ref|", "≤ 0.1 mm (drawn here)"]


def test_clipped_duties_are_shaded_and_named_only_when_they_happen(step):
    assert not any("clip" in text for text in all_legend_texts(plot_flight(step)))
    commands = step.commands.copy()
    commands[0, 100:120, CMD_U1 + 2] = 1.3  # asked for more than full duty
    commands[0, 200:201, CMD_U1] = -0.1  # and less than none, once
    fig = plot_flight(dataclasses.replace(step, commands=commands))
    duty = axis_by_ylabel(fig, "rotor duty")
    assert "duty clipped (asked outside [0, 1])" in legend_texts(duty)
    (shaded,) = [c for c in duty.collections if c.get_label().startswith("duty clipped")]
    spans = [(p.vertices[:, 0].min(), p.vertices[:, 0].max()) for p in shaded.get_paths()]
    assert spans == [(pytest.approx(1.0), pytest.approx(1.2)), (pytest.approx(2.0), pytest.approx(2.01))]
    assert not any("flagged" in text for text in legend_texts(duty))


def test_a_brief_limit_flag_survives_thinning():
    """The flight is thinned for drawing; its saturation intervals are not."""
    res = qc.fly("step", duration=7.0)  # 7,001 instants, drawn every third
    assert len(plots.drawable(res).t) < len(res.t)
    commands = res.commands.copy()
    commands[0, 3001, CMD_FLAGS] = 1.0  # one period, between drawn instants
    duty = axis_by_ylabel(plot_flight(dataclasses.replace(res, commands=commands)), "rotor duty")
    (shaded,) = [c for c in duty.collections if c.get_label() == "controller limit flagged"]
    (path,) = shaded.get_paths()
    assert path.vertices[:, 0].min() == pytest.approx(3.001)


def test_one_vehicle_is_not_called_vehicle_0(step):
    fig = plot_flight(step)
    texts = [fig._suptitle.get_text()] + all_legend_texts(fig) + [ax.get_title() for ax in fig.axes]
    assert not any("vehicle" in text for text in texts), texts
    x0 = hover_state(qc.Vehicle.paper(), 2, Step())
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        two = qc.fly("step", duration=1.0, log_every=10, x0=x0)
    assert plot_flight(two, vehicle=1)._suptitle.get_text() == "nlpd on step — vehicle 1"


def test_early_stop_is_marked_and_explained(diverged):
    fig = plot_flight(diverged)
    t_stop = diverged.t_stop[0]
    time_axes = fig.axes[1:]
    for ax in time_axes:
        stops = [ln for ln in ax.get_lines() if ln.get_color() == "tab:red" and ln.get_linestyle() == ":"]
        assert len(stops) == 1
        assert np.all(np.asarray(stops[0].get_xdata()) == t_stop)
    assert any(lb.startswith("stopped, t = ") for lb in labels(axis_by_ylabel(fig, "rotor duty")))
    title = fig._suptitle.get_text()
    assert diverged.status_text(0) in title and "body rate" in title
    # the time axes end shortly after the stop instead of at the scheduled end
    assert t_stop < time_axes[0].get_xlim()[1] < diverged.t[-1]


@pytest.mark.parametrize("which", ["circle", "step", "diverged", "clipped"])
def test_plot_flight_panels_stay_inside_and_apart(which, request):
    """The flight figure's grid is fixed, not found by a layout engine: each panel with its
    tick labels, axis labels and legends stays inside the figure and clear of the others and
    of the title (two lines when the flight stopped). The legends right of the wide panels are
    measured and the grid narrowed for them: "duty clipped (asked outside [0, 1])" was cut."""
    from matplotlib.backends.backend_agg import FigureCanvasAgg

    if which == "clipped":
        step = request.getfixturevalue("step")
        commands = step.commands.copy()
        commands[0, 100:120, CMD_U1 + 2] = 1.3  # asked for more than full duty
        fig = plot_flight(dataclasses.replace(step, commands=commands))
        assert "duty clipped (asked outside [0, 1])" in legend_texts(axis_by_ylabel(fig, "rotor duty"))
    else:
        fig = plot_flight(request.getfixturevalue(which))
    renderer = FigureCanvasAgg(fig).get_renderer()
    fig.draw(renderer)
    boxes = [ax.get_tightbbox(renderer) for ax in fig.axes] + [fig._suptitle.get_window_extent(renderer)]
    frame = fig.bbox
    for i, a in enumerate(boxes):
        assert frame.x0 <= a.x0 and a.x1 <= frame.x1 and frame.y0 <= a.y0 and a.y1 <= frame.y1, (i, a, frame)
        for j, b in enumerate(boxes[:i]):
            assert not a.overlaps(b), (j, i, b, a)


def test_nan_references_are_skipped(diverged):
    assert np.all(np.isnan(diverged.references))
    fig = plot_flight(diverged)
    for ax in fig.axes:
        assert "reference" not in labels(ax) and "setpoint" not in labels(ax)
    assert "x [m]" in fig.axes[0].get_xlabel()
    fig = plot_paths({"replay": diverged})
    assert all("reference" not in labels(ax) for ax in fig.axes)
    fig = plot_envelope(diverged)
    assert any("no reference" in t.get_text() for t in fig.axes[1].texts)


def test_plot_paths_overlays_flights_with_one_reference(step, circle, diverged):
    x0 = hover_state(qc.Vehicle.paper(), 1, Step())
    x0[0, 1] = 0.3  # start 0.3 m off in y
    other = qc.fly("step", duration=3.0, log_every=10, x0=x0)
    fig = plot_paths({"A": step, "B": other, "bad": diverged})
    assert len(fig.axes) == 4
    top, ax_x, ax_y, ax_e = fig.axes
    assert (top.get_xlabel(), top.get_ylabel()) == ("x [m]", "y [m]")
    assert ax_x.get_ylabel() == "x [m]" and ax_y.get_ylabel() == "y [m]" and ax_e.get_xlabel() == "time [s]"
    for ax in fig.axes[:3]:
        assert labels(ax).count("reference") == 1
    np.testing.assert_array_equal(line(top, "B").get_xdata(), other.state("x")[0])
    np.testing.assert_array_equal(line(top, "B").get_ydata(), other.state("y")[0])
    np.testing.assert_array_equal(line(ax_y, "A").get_ydata(), step.state("y")[0])
    assert any(lb.startswith("bad (stopped at") for lb in labels(top))
    assert "A vs B vs bad" in fig._suptitle.get_text()
    with pytest.raises(ValueError):
        plot_paths({})


def test_comparison_has_a_position_error_panel_with_events_and_saturation(step):
    """Four controllers' positions overlap after the transient; their errors, on a log
    axis, do not. Events and saturation are marked, and named only when drawn."""
    cmp = qc.compare("circle", duration=8.0, log_every=10)
    fig = cmp.plot()
    top, ax_x, ax_y, ax_z, ax_e = fig.axes
    assert ax_e.get_ylabel() == "position error [m]" and ax_e.get_yscale() == "log"
    assert ax_e.get_xlabel() == "time [s]" and ax_z.get_xlabel() == ""
    finals = []
    for label, res in cmp.results.items():
        err = np.linalg.norm(res.states[0, :, :3] - res.references[0, :, :3], axis=1)
        (curve,) = [ln for ln in ax_e.get_lines() if ln.get_label() == label]
        np.testing.assert_allclose(curve.get_ydata(), np.maximum(err, marks.ERROR_FLOOR))
        assert curve.get_color() == line(top, label).get_color()
        finals.append(err[-1])
    lo, hi = ax_e.get_ylim()
    assert lo < min(finals) and max(finals) / min(finals) > 5  # told apart after 7 s
    texts = legend_texts(top)
    assert texts[:5] == ["reference", *cmp.results] and not any(
        word in text for text in texts for word in ("gust", "rotor", "flagged", "clipped", "vehicle")
    )
    assert len(ax_e.collections) == 0  # no saturation: no strip
    # the same flights in a gust, one of them saturating: marked and named
    env = {"gust": {"amplitude": [2.0, 0.0, 0.0], "start": 1.0, "duration": 2.0}}
    flights = {
        label: dataclasses.replace(res, meta={**res.meta, "environment": env}) for label, res in cmp.results.items()
    }
    commands = flights["se3"].commands.copy()
    commands[0, 300:350, CMD_U1] = 1.5
    flights["se3"] = dataclasses.replace(flights["se3"], commands=commands)
    fig = plot_paths(flights, axes="xyz")
    texts = legend_texts(fig.axes[0])
    assert texts.count("gust 2 m/s, 1-3 s") == 1 and "duty clipped (strip in the flight's colour)" in texts
    assert not any("flagged" in text for text in texts)
    ax_e = fig.axes[-1]
    (strip,) = ax_e.collections
    assert tuple(strip.get_facecolor()[0][:3]) == pytest.approx((0.17, 0.63, 0.17), abs=0.01)  # se3 is C2
    for ax in fig.axes[1:]:
        assert len([p for p in ax.patches if p.get_x() == 1.0 and p.get_width() == 2.0]) == 1
    with pytest.raises(ValueError, match="axes must be"):
        plot_paths({"A": step}, axes="xz")


def test_plot_envelope_median_band_and_path_cap():
    n = 12
    x0 = hover_state(qc.Vehicle.paper(), n, Step())
    x0[:, 0] = np.linspace(-0.5, 0.5, n)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        res = qc.fly("step", duration=2.0, log_every=20, x0=x0)
    fig = plot_envelope(res, max_paths=5)
    assert len(fig.axes) == 2
    top, ax_e = fig.axes
    assert (top.get_xlabel(), top.get_ylabel()) == ("x [m]", "y [m]")
    assert ax_e.get_xlabel() == "time [s]" and ax_e.get_ylabel().endswith("[m]")
    drawn = [ln for ln in top.get_lines() if ln.get_label().startswith("_") and len(ln.get_xdata()) > 1]
    assert len(drawn) == 5
    err = np.linalg.norm(res.states[:, :, :3] - res.references[:, :, :3], axis=2)
    np.testing.assert_allclose(line(ax_e, "median").get_ydata(), np.median(err, axis=0))
    assert "5-95 %" in [c.get_label() for c in ax_e.collections]
    assert plots._pick_paths(np.array([True, False, True, True, False]), 3).tolist() == [0, 1, 4]


def sweep_like(n=30, ok=10, seed=0):
    """A Monte Carlo result as the figures read it (duck-typed): its table, spec and traces,
    the first ``ok`` flights finished, the others failed (diverged or saturated)."""
    import pandas as pd

    rng = np.random.default_rng(seed)
    failure = np.r_[np.zeros(ok, int), rng.integers(1, 3, n - ok)]
    table = pd.DataFrame(
        {
            "vehicle": np.arange(n),
            "failure": failure,
            "diverged": failure == 1,
            "lost_track": np.zeros(n, bool),
            "rmse_m": rng.gamma(2.0, 0.1, n),
            "max_error_m": rng.gamma(3.0, 0.2, n),
            "final_error_m": np.r_[rng.gamma(2.0, 0.01, n - 3), [np.nan] * 3],
            "rise_time_s": np.full(n, np.nan),
            "settling_time_5pct_s": rng.uniform(2, 4, n),
            "overshoot_pct": rng.uniform(0, 20, n),
            "effort": rng.uniform(1, 2, n),
            "duty_clipped_s": np.zeros(n),
        }
    )
    t = np.linspace(0.0, 5.0, 51)
    pos = np.cumsum(rng.normal(0, 0.1, (n, t.size, 3)), axis=1)
    spec = SimpleNamespace(controller=SimpleNamespace(name="nlpd"), mission=SimpleNamespace(name="step"), seed=seed)
    traces = SimpleNamespace(vehicle=np.arange(n), t=t, pos=pos, ref=np.zeros_like(pos), sample=np.ones(n, bool))
    return SimpleNamespace(
        table=table, spec=spec, n=n, failure_names=("ok", "diverged", "saturated", "did not settle"), traces=traces
    )


def test_histograms_have_axis_labels():
    metrics = ["rmse_m", "max_error_m", "final_error_m", "settling_time_5pct_s", "overshoot_pct", "effort"]
    fig = mc_plots.plot_histograms(sweep_like(), metrics=metrics)
    shown = [ax for ax in fig.axes if ax.get_visible()]
    hists = shown[:-1]
    assert [ax.get_title().split()[0] for ax in hists] == metrics
    assert [ax.get_xlabel() for ax in hists] == [
        "RMSE [m]",
        "max error [m]",
        "final error [m]",
        "settling time 5 % [s]",
        "overshoot [%]",
        "effort [s]",
    ]
    assert all(ax.get_ylabel() == "flights" for ax in shown)
    assert shown[-1].get_title() == "outcome of 30 flights" and shown[-1].get_xlabel() == "outcome"
    kept = sweep_like().table.query("not diverged")  # the flights the summary's quantiles are over
    gone = int(kept["final_error_m"].isna().sum())
    assert sum(p.get_height() for p in hists[0].patches) == len(kept) < 30
    assert f"{len(kept) - gone}, {gone} n/a" in hists[2].get_title() and gone > 0
    assert mc_plots.metric_label("hover_time_s") == "hover time [s]"


def test_histograms_leave_out_degenerate_metrics_and_say_so():
    fig = mc_plots.plot_histograms(sweep_like())  # rise time never measured, no duty ever clipped
    shown = [ax for ax in fig.axes if ax.get_visible()]
    assert len(shown) == 6 + 1
    assert not any(word in ax.get_title() for ax in shown for word in ("rise_time", "duty_clipped"))
    assert not any("not measured" in t.get_text() for ax in fig.axes for t in ax.texts)
    note = fig._supxlabel.get_text().replace("\u00a0", " ")  # no break inside an item
    kept = int((~sweep_like().table["diverged"]).sum())  # the flights that kept track
    assert note == f"not drawn: rise_time_s (not measured), duty_clipped_s (0 in all {kept} flights)"
    # nothing left out: no note
    fig = mc_plots.plot_histograms(sweep_like(), metrics=["rmse_m", "settling_time_5pct_s"])
    assert fig._supxlabel is None and len([ax for ax in fig.axes if ax.get_visible()]) == 3
    assert mc_plots.degenerate(np.array([np.nan, 2.0, 2.0]), 3) == "2 in all 2 flights measured"


def drawn_paths(ax):
    return [ln for ln in ax.get_lines() if ln.get_label().startswith("_") and len(ln.get_xdata()) > 1]


@pytest.mark.parametrize("kind", ["sweep", "batch"])
def test_envelope_keeps_the_finished_paths_visible(kind):
    """Failed flights are drawn first, thin and translucent, underneath: however many
    there are, the finished ones stay on top and visibly opaque."""
    if kind == "sweep":
        fig = mc_plots.plot_envelope(sweep_like(n=60, ok=15))
    else:
        n = 24
        x0 = hover_state(qc.Vehicle.paper(), n, Step())
        x0[:, 1] = np.linspace(-1.0, 1.0, n)
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")
            res = qc.fly("step", duration=1.0, log_every=10, x0=x0)
        status = np.where(np.arange(n) % 4 == 0, 0, 1)  # three quarters "stopped"
        fig = plot_envelope(dataclasses.replace(res, status=status))
    paths = drawn_paths(fig.axes[0])
    ok = [ln for ln in paths if ln.get_color() == "tab:blue"]
    failed = [ln for ln in paths if ln.get_color() != "tab:blue"]
    assert len(ok) >= 6 and len(failed) >= 18
    assert min(ln.get_zorder() for ln in ok) > max(ln.get_zorder() for ln in failed)
    assert min(ln.get_alpha() for ln in ok) >= 0.35 and max(ln.get_alpha() for ln in failed) <= 0.4
    assert max(paths.index(ln) for ln in failed) < min(paths.index(ln) for ln in ok)  # drawn last
    assert min(ln.get_linewidth() for ln in ok) > max(ln.get_linewidth() for ln in failed)


def test_save_figure_writes_png_atomically(tmp_path, step):
    target = tmp_path / "sub" / "flight.png"
    save_figure(plot_flight(step), target)
    data = target.read_bytes()
    assert data[:8] == PNG_MAGIC and len(data) > 10_000
    assert os.listdir(target.parent) == ["flight.png"]
    # a failing draw leaves neither the file nor a temporary behind
    broken = Figure()
    broken.add_subplot().plot([0, 1], [0, 1])
    broken.savefig = lambda *a, **k: (_ for _ in ()).throw(RuntimeError("boom"))
    with pytest.raises(RuntimeError):
        save_figure(broken, tmp_path / "sub" / "broken.png")
    assert os.listdir(target.parent) == ["flight.png"]


def test_figures_can_be_drawn_in_threads(step, tmp_path):
    errors = []

    def work(i):
        try:
            save_figure(plot_flight(step), tmp_path / f"f{i}.png")
        except Exception as exc:  # pragma: no cover - reported below
            errors.append(exc)

    threads = [threading.Thread(target=work, args=(i,)) for i in range(3)]
    for th in threads:
        th.start()
    for th in threads:
        th.join()
    assert not errors
    assert sorted(os.listdir(tmp_path)) == ["f0.png", "f1.png", "f2.png"]


def test_docstring_examples():
    assert doctest.testmod(plots, raise_on_error=False).failed == 0
