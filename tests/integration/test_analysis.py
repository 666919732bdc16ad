"""Linear analysis about hover, checked against the hand-built cascade, the nonlinear flight,
the design's loop margins and itself (closing a broken loop gives the closed loop back)."""

from __future__ import annotations

import json
import warnings

import control
import numpy as np
import pytest
from matplotlib.figure import Figure
from numba import njit

import quadcruise as qc
from quadcruise.control.baselines import Gonzalez
from quadcruise.control.design import cascade_state_space, pd_from_poles
from quadcruise.control.design import loop_margins as design_margins
from quadcruise.control.design import loop_transfer as design_loop
from quadcruise.control.position import NLPD
from quadcruise.errors import InputError
from quadcruise.io.plainjson import dumps
from quadcruise.layout import CONTROLLER_SIG
from quadcruise.missions import Step
from quadcruise.workflows.analysis import LOOPS, HoverError, linearize


@pytest.fixture(scope="module")
def lin():
    return linearize("nlpd")


def _matched(found, wanted):
    """Largest relative distance from each wanted pole to the found poles, one to one."""
    found, worst = list(np.asarray(found, complex)), 0.0
    for p in np.asarray(wanted, complex):
        i = int(np.argmin([abs(q - p) for q in found]))
        worst = max(worst, abs(found.pop(i) - p) / abs(p))
    return worst, found


# (a) the full loop against design.cascade_state_space -----------------------------------------


@pytest.mark.parametrize("dt, tol", [(1e-3, 0.02), (1e-4, 0.002)])
def test_x_loop_poles_are_those_of_the_hand_built_cascade(dt, tol):
    c = NLPD()
    cascade = cascade_state_space(c.position, c.attitude).poles()
    full = linearize(c, dt=dt)
    worst, left = _matched(full.poles_continuous(), cascade)
    assert worst < tol  # and the gap shrinks with dt: it is the sampling
    worst_x, left_x = _matched(full.loop_poles("x"), cascade)
    assert worst_x < tol and left_x == []  # the x loop is exactly the cascade's 6 states


def test_yaw_and_z_loops_are_the_design_loops_with_rotor_lag(lin):
    """Broken at U4 and U1, the yaw and z loops are design.loop_margins' C(s) w/(s+w)/s^2."""
    for loop, gains in (("yaw", NLPD().yaw), ("z", NLPD().altitude)):
        ours, theirs = lin.margins(loop), design_margins(gains, 15.0)
        assert ours["phase_margin"] == pytest.approx(theirs["phase_margin"], abs=1.0)
        assert ours["gain_crossover"] == pytest.approx(theirs["gain_crossover"], rel=0.02)
    closed = control.feedback(design_loop(NLPD().yaw, 15.0), 1).poles()
    assert _matched(lin.loop_poles("yaw"), closed)[0] < 0.02


# (b) stability, and the baseline is the paper's controller to first order ---------------------


@pytest.mark.parametrize("name", ["nlpd", "gonzalez"])
def test_discrete_closed_loop_is_stable(name):
    lin = linearize(name)
    assert lin.stable and np.all(np.abs(lin.poles()) < 1.0)
    assert np.all(lin.poles_continuous().real < 0)
    assert lin.sys.nstates == 19 and lin.residual < 1e-9


def test_gonzalez_is_nlpd_to_first_order(lin):
    """Same small-signal poles by the baseline's gain rule: tanh slope k_p, u/g = asin(u/a)."""
    other = linearize(Gonzalez())
    np.testing.assert_allclose(other.sys.A, lin.sys.A, atol=1e-9)
    np.testing.assert_allclose(other.sys.B, lin.sys.B, atol=1e-9)


def test_continuous_equivalent_has_the_same_poles_and_unit_dc_gain(lin):
    cont = lin.continuous()
    assert _matched(cont.poles(), lin.poles_continuous())[0] < 1e-6
    dc = cont.dcgain()
    np.testing.assert_allclose([dc[0, 0], dc[1, 1], dc[2, 2], dc[5, 3]], 1.0, atol=1e-6)


def test_loops_partition_the_state(lin):
    idx = np.concatenate([lin.loops[k] for k in LOOPS])
    assert sorted(idx) == list(range(19))
    assert [len(lin.loops[k]) for k in LOOPS] == [6, 6, 3, 4]


# (c) the linear model predicts the nonlinear flight -------------------------------------------


def test_linear_step_follows_nonlinear_small_step(lin):
    res = qc.fly(Step(axis="x", size=0.01, time=1.0), duration=11.0)
    k0 = int(np.searchsorted(res.t, 1.0))
    T = lin.dt * np.arange(len(res.t) - k0)
    y = control.step_response(lin.sys, T=T, input=0, output=0).outputs
    assert np.max(np.abs(res.state("x")[0, k0:] / 0.01 - y)) < 1e-4
    assert abs(y[-1] - 1.0) < 0.01


# (d) margins -----------------------------------------------------------------------------------


def test_closing_a_broken_loop_gives_the_closed_loop_back(lin):
    want = lin.poles()
    for loop in LOOPS:
        for at in ("input", "output"):
            L = lin.loop_transfer(loop, at)
            closed = np.linalg.eigvals(L.A - L.B @ L.C)  # w = -L w: negative unity feedback
            assert _matched(closed, want)[0] < 1e-8, (loop, at)


def test_faster_position_poles_erode_the_margins():
    rows = []
    for k in (0.8, 1.0, 1.2, 1.4, 2.0):
        c = NLPD(position=pd_from_poles((-0.7 * k, -4.3 * k)))
        lin = linearize(c)
        rows.append((lin.stable, lin.margins("x")["phase_margin"], lin.margins("x", "output")["gain_increase"]))
    stable, pm, gm = map(np.array, zip(*rows, strict=False))
    assert np.all(np.diff(pm) < 0) and np.all(np.diff(gm[:4]) < 0)
    assert stable[:4].all() and pm[3] > 5.0
    assert not stable[4] and pm[4] < 0  # twice as fast: unstable


def test_unknown_loop_or_break_point_is_refused(lin):
    with pytest.raises(InputError, match="unknown loop 'pitch'"):
        lin.margins("pitch")
    with pytest.raises(InputError, match="at must be"):
        lin.loop_transfer("x", at="middle")


# (e) no hover, no linearisation ---------------------------------------------------------------


@njit(CONTROLLER_SIG)
def _idle(t, dt, x, ref, vp, gains, mem, cmd):
    for j in range(4):
        cmd[j] = 0.0


class Idle:
    name = "idle"
    function = staticmethod(_idle)

    def gains(self):
        return np.zeros(0)

    def memory(self):
        return np.zeros(0)


def test_a_controller_that_cannot_hover_is_refused():
    with pytest.raises(HoverError, match="idle does not hold hover at z = 1 m: 'F1' moves"):
        linearize(Idle())
    assert issubclass(HoverError, InputError)
    with pytest.raises(InputError, match="lacks function, gains, memory"):
        linearize(object())


class FirstCallFlag:
    """nlpd plus a memory entry set in its first period (as a derivative's first sample is):
    a plain Python function, which linearize can call as well as a compiled one."""

    name = "flagged"

    @staticmethod
    def function(t, dt, x, ref, vp, gains, mem, cmd):
        inner = np.ascontiguousarray(mem[:3])
        NLPD().function(t, dt, x, ref, vp, gains, inner, cmd)
        mem[:3], mem[3] = inner, 1.0

    def gains(self):
        return NLPD().gains()

    def memory(self):
        return np.zeros(4)


def test_memory_set_in_the_first_period_settles(lin):
    with pytest.raises(HoverError, match="'mem3' moves at 1e\\+03 per second"):
        linearize(FirstCallFlag(), settle=0)
    flagged = linearize(FirstCallFlag())
    np.testing.assert_allclose(flagged.sys.A[:19, :19], lin.sys.A, atol=1e-12)
    assert flagged.stable and flagged.poles_continuous()[-1].real == -np.inf  # the flag: z = 0
    with pytest.raises(InputError, match="no continuous equivalent"):
        flagged.continuous()
    np.testing.assert_allclose(flagged.loop_poles("x"), lin.loop_poles("x"), rtol=1e-9)


def test_hover_elsewhere_and_heavier_vehicle_still_linearise():
    lin = linearize("nlpd", qc.Vehicle.paper().replace(m=1.4), hover_z=3.0)
    assert lin.stable


# report and figure -----------------------------------------------------------------------------


def test_report_compares_with_the_design_poles(lin):
    r = lin.summary()
    doc = json.loads(dumps(r.to_dict()))  # strict JSON: -inf dB (no lower gain limit) is null
    assert doc["loops"]["z"]["margins_input"]["gain_decrease_db"] is None
    assert doc["loops"]["x"]["margins_input"] == json.loads(json.dumps(r["loops"]["x"]["margins_input"]))
    assert "nlpd about hover, dt = 0.001 s: stable" in str(r) and "-4.3:85%" in str(r)
    assert json.loads(dumps({"gm": float("inf")})) == {"gm": None}
    x = r["loops"]["x"]
    assert x["design_poles"] == [-0.7, -4.3]
    assert x["dominant"] == pytest.approx([-0.658, 0.0], abs=1e-3)  # the design's slow pole survives
    assert x["nearest_rel_distance"][0] < 0.1 < 0.5 < x["nearest_rel_distance"][1]  # its -4.3 does not
    assert 0.3 < x["min_damping"] < 0.45  # design.py: worst damping 0.37
    assert r["loops"]["y"]["poles"] == x["poles"]
    assert r["loops"]["yaw"]["margins_input"]["gain_decrease"] > 0  # PID on a double integrator
    assert all(e["margins_input"]["open_loop_unstable_poles"] == 0 for e in r["loops"].values())


def test_bode_draws_closed_loops_and_loop_transfers(lin):
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        assert len(lin.plot(loops=False).axes) == 2
        fig = lin.plot(at="output")
    assert isinstance(fig, Figure) and len(fig.axes) == 4
    assert len(fig.axes[0].lines) == 4 + 1  # four loops and the 0 dB line


@pytest.mark.parametrize("loops", [True, False])
def test_bode_legends_cover_no_axis(lin, loops):
    """The legends sit under the axes, clear of every panel with its ticks and labels (the loop
    transfers' legend, inside its magnitude panel, covered its axis and curves), and inside the figure."""
    from matplotlib.backends.backend_agg import FigureCanvasAgg

    fig = lin.plot(loops=loops)
    renderer = FigureCanvasAgg(fig).get_renderer()
    fig.draw(renderer)
    assert len(fig.legends) == (2 if loops else 1) and all(ax.get_legend() is None for ax in fig.axes)
    panels = [ax.get_tightbbox(renderer) for ax in fig.axes]
    for legend in fig.legends:
        box = legend.get_window_extent(renderer)
        assert fig.bbox.x0 <= box.x0 and box.x1 <= fig.bbox.x1 and fig.bbox.y0 <= box.y0, box
        assert not any(box.overlaps(panel) for panel in panels), box
    if loops:
        left, right = (legend.get_window_extent(renderer) for legend in fig.legends)
        assert not left.overlaps(right)


def test_bode_marks_each_loops_margins_at_its_crossovers(lin):
    fig = lin.plot()
    mag_l, phase_l = fig.axes[1], fig.axes[3]
    texts = [t.get_text() for t in fig.legends[-1].get_texts()]  # the loop transfers' legend, under them
    assert texts[0] == (
        "L x: PM 18.1° @ 10.8 rad/s (< 30°), GM down -3.98 dB @ 7.07 rad/s (> -6 dB), up +38.2 dB @ 134 rad/s"
    )
    assert texts[2] == "L z: PM 65° @ 4.8 rad/s, GM up +51.7 dB @ 169 rad/s"  # nothing short
    for loop, text in zip(LOOPS, texts, strict=False):
        m = lin.margins(loop)
        assert text.startswith(f"L {loop}: PM {m['phase_margin']:.3g}° @ {m['gain_crossover']:.3g} rad/s")
        curve = next(ln for ln in mag_l.get_lines() if ln.get_label() == text)
        w, gain = curve.get_xdata(), curve.get_ydata()
        phase = next(
            ln for ln in phase_l.get_lines() if ln.get_color() == curve.get_color() and len(ln.get_xdata()) > 2
        )
        pw, pv = phase.get_xdata(), phase.get_ydata()
        if loop == "y":  # the same margins as x: marked once
            assert not [ln for ln in phase_l.get_lines() if ln.get_label() == "PM y"]
            continue
        (pm,) = [ln for ln in phase_l.get_lines() if ln.get_label() == f"PM {loop}"]
        wgc, pm_deg = m["gain_crossover"], m["phase_margin"]
        base = pm.get_ydata()[0]
        assert list(pm.get_xdata()) == [wgc, wgc] and (base + 180.0) % 360.0 == 0.0  # from a -180 deg line
        assert pm.get_ydata()[1] == pytest.approx(base + pm_deg)
        # the segment ends on the drawn phase and the dot on the drawn 0 dB crossing
        assert np.interp(np.log(wgc), np.log(pw), pv) == pytest.approx(base + pm_deg, abs=0.5)
        assert np.interp(np.log(wgc), np.log(w), gain) == pytest.approx(0.0, abs=0.2)
        for way, key in (("down", "gain_decrease"), ("up", "gain_increase")):
            marks = [ln for ln in mag_l.get_lines() if ln.get_label() == f"GM {way} {loop}"]
            if not 0.0 < m[key] < np.inf:
                assert not marks
                continue
            (gm,) = marks
            wpc, gm_db = m[key + "_frequency"], -20 * np.log10(m[key])
            assert list(gm.get_xdata()) == [wpc, wpc] and gm.get_ydata()[1] == pytest.approx(gm_db)
            assert np.interp(np.log(wpc), np.log(w), gain) == pytest.approx(gm_db, abs=0.3)
            at_wpc = np.interp(np.log(wpc), np.log(pw), pv)  # on a -180 + 360 k line
            assert abs((at_wpc + 180.0 + 180.0) % 360.0 - 180.0) < 0.5
    assert [ln.get_label() for ln in mag_l.get_lines() if ln.get_label().startswith("GM ")] == [
        "GM down x",
        "GM up x",
        "GM up z",
        "GM down yaw",
        "GM up yaw",
    ]


@pytest.mark.parametrize("loops, at", [(False, "input"), (True, "input"), (True, "output")])
def test_bode_phases_are_unwrapped(lin, loops, at):
    """No phase jumps by a turn: each curve is continuous, a closed loop's starting near 0 deg,
    a loop transfer's near -180 deg, and equal to the response's angle up to whole turns."""
    fig = lin.plot(loops=loops, at=at)
    phase_axes = fig.axes[2:] if loops else fig.axes[1:]
    for col, ax in enumerate(phase_axes):
        assert ax.get_ylabel() == "phase [deg]"
        curves = [ln for ln in ax.get_lines() if len(ln.get_xdata()) > 2]
        assert len(curves) == 4
        for ln in curves:
            w, y = np.asarray(ln.get_xdata(), float), np.asarray(ln.get_ydata(), float)
            assert np.all(np.isfinite(y)) and np.max(np.abs(np.diff(y))) < 90.0, ln.get_label()
            assert abs(y[0] - (0.0 if col == 0 else -180.0)) <= 180.0
        low, high = ax.get_ylim()
        lines = sorted(
            ln.get_ydata()[0]
            for ln in ax.get_lines()
            if len(ln.get_xdata()) == 2 and list(ln.get_xdata()) == [0.0, 1.0]
        )  # axhline: x in axes units
        assert lines and all((v + 180.0) % 360.0 == 0.0 and low <= v <= high for v in lines)
    # the x curve drawn last (the loop transfer, or the closed loop) is the angle of its response, unwrapped
    x_curve = next(ln for ln in phase_axes[-1].get_lines() if len(ln.get_xdata()) > 2)
    w, y = np.asarray(x_curve.get_xdata(), float), np.asarray(x_curve.get_ydata(), float)
    system = lin.loop_transfer("x", at) if loops else lin.closed_loop("x")
    r = control.frequency_response(system, w).complex.ravel()
    np.testing.assert_allclose(np.exp(1j * np.radians(y)), r / np.abs(r), atol=1e-9)


class _Delay:
    """A duck-typed linearisation whose one closed loop is a pure delay of n periods."""

    controller, dt, loops = "delay", 0.001, {"x": None}

    def __init__(self, n):
        self.n = n

    def closed_loop(self, loop):
        shift = np.eye(self.n, k=-1)  # x+ = shift x + e1 u, y = x_n: y = z^-n u
        return control.ss(
            shift, np.eye(self.n)[:, :1], np.eye(self.n)[-1:], 0.0, self.dt, inputs=["x_ref"], outputs=["x"]
        )


def test_bode_unwraps_a_delay_over_several_turns():
    """A delay of 4 periods turns the phase by -4 w dt: 1.8 turns up to 0.9 of the Nyquist frequency."""
    from quadcruise.plots.bode import plot_bode

    fig = plot_bode(_Delay(4))
    (curve,) = [ln for ln in fig.axes[1].get_lines() if len(ln.get_xdata()) > 2]
    w = np.asarray(curve.get_xdata(), float)
    assert curve.get_ydata() == pytest.approx(np.degrees(-4 * 0.001 * w), abs=1e-6)
    assert curve.get_ydata()[-1] < -600.0


def test_gain_margins_in_db_bound_the_loop_gain_both_ways(lin):
    """A loop gain just inside either gain margin keeps the closed loop stable; just beyond it,
    unstable (independent of the margin code: the poles of the loop closed at k L)."""
    for loop in ("x", "yaw"):
        L = lin.loop_transfer(loop, "input")
        m = lin.margins(loop, "input")

        def stable_at(k, L=L):
            return bool(np.max(np.abs(np.linalg.eigvals(L.A - k * L.B @ L.C))) < 1.0)

        assert stable_at(1.0)
        for key in ("gain_decrease", "gain_increase"):
            assert m[key + "_db"] == pytest.approx(20 * np.log10(m[key]))
            assert stable_at(m[key] * (1.02 if key == "gain_decrease" else 0.98))
            assert not stable_at(m[key] * (0.98 if key == "gain_decrease" else 1.02))
    z = lin.margins("z", "input")
    assert z["gain_decrease"] == 0.0 and z["gain_decrease_db"] == -np.inf  # no lower limit


def test_summary_gives_margins_with_units_flags_and_explains_them(lin):
    text = str(lin.summary())
    lines = text.splitlines()
    assert lines[0] == (
        "nlpd about hover, dt = 0.001 s: stable (every pole inside the unit circle), margins short on x, y, yaw (!)"
    )
    row = {ln[:36].strip(): ln[36:].split("  ") for ln in lines[2:10]}
    assert "PM at the input [deg] @ [rad/s]" in row and "GM at the input [dB]: down, up" in row
    cells = " ".join(lines[7].split())
    assert cells.startswith("GM at the input [dB]: down, up -3.98 (!), +38.2 -3.98 (!), +38.2 none, +51.7 -25.8, +38.2")
    assert "18.1 (!) @ 10.8" in lines[6] and "65.0 @ 4.8" in lines[6]
    assert "conditionally stable" in text and "(!): below 30 deg of phase margin or within 6 dB" in text
    r = linearize("cascade").summary()
    assert not any(r["loops"]["z"]["low_margins"].values())
    assert r["loops"]["x"]["low_margins"]["input"] == ["PM 28.9 deg < 30 deg"]


@pytest.mark.parametrize("name, loop", [("se3", "yaw"), ("nlpd", "x")])
def test_dominant_pole_is_defined_once_and_a_pair_counts_as_one_mode(name, loop):
    """The dominant mode is the one of largest step-response weight, a complex pair weighing
    both its poles; for se3's yaw loop that is the lightly damped pair, which is also the slowest."""
    lin = linearize(name)
    r = lin.summary()["loops"][loop]
    p, weight = lin.loop_modes(loop)
    modes = {}
    for z, wt in zip(p, weight, strict=False):
        key = (round(z.real, 6), round(abs(z.imag), 6))
        modes[key] = modes.get(key, 0.0) + wt
    assert tuple(r["dominant"]) == max(modes, key=modes.get)
    if name == "se3":
        assert r["dominant"] == r["slowest"] and r["dominant"][1] > 10.0
    else:  # a slow pole nearly cancelled: not dominant
        assert r["slowest"][0] > r["dominant"][0]


# the result's four methods -----------------------------------------------------------------------


def test_the_table_holds_every_pole_with_python_controls_damping(lin):
    """One row per loop and mode; with each pair's conjugate the rows are the poles of the whole loop,
    and each row's natural frequency and damping are those control.damp gives for the same pole."""
    from quadcruise.protocols import ResultLike

    assert isinstance(lin, ResultLike)
    table = lin.to_pandas()
    assert list(table["loop"].unique()) == list(LOOPS)
    poles = table["real"].to_numpy() + 1j * table["imag"].to_numpy()
    both = np.concatenate([poles, np.conj(poles[table["imag"].to_numpy() > 0])])
    assert _matched(both, lin.poles_continuous())[0] < 1e-6 and len(both) == lin.sys.nstates
    wn, zeta, _ = control.damp(lin.sys, doprint=False)
    for p, w, z in zip(poles, table["natural_frequency"], table["damping"], strict=False):
        k = int(np.argmin(np.abs(wn - w) + np.abs(zeta - z)))
        assert wn[k] == pytest.approx(w, rel=1e-6) and zeta[k] == pytest.approx(z, abs=1e-6), p
    summary = lin.summary()
    for loop, rows in table.groupby("loop", sort=False):
        assert rows["dominant"].sum() == 1 and rows["slowest"].sum() == 1
        dom = rows[rows["dominant"]].iloc[0]
        assert [dom["real"], dom["imag"]] == summary["loops"][loop]["dominant"]
        for at in ("input", "output"):
            m = lin.margins(loop, at)
            assert (rows[f"{at}_phase_margin_deg"] == m["phase_margin"]).all()
            assert (rows[f"{at}_gain_increase_db"] == m["gain_increase_db"]).all()


def test_the_folder_is_written_whole_or_not_at_all(lin, tmp_path, monkeypatch):
    out = lin.write(tmp_path / "a")
    assert sorted(p.name for p in out.iterdir()) == ["analysis.json", "bode.png", "bode_output.png", "quadcruise.json"]
    doc = json.loads((out / "analysis.json").read_text())  # strict JSON: no lower gain limit is null
    assert doc["loops"]["z"]["margins_input"]["gain_decrease_db"] is None
    assert doc["loops"]["x"]["dominant"] == lin.summary()["loops"]["x"]["dominant"]
    assert json.loads((out / "quadcruise.json").read_text())["dt_s"] == 0.001
    (tmp_path / "mine").mkdir()
    (tmp_path / "mine" / "notes.txt").write_text("keep")
    with pytest.raises(InputError, match="mine"):
        lin.write(tmp_path / "mine")
    assert (tmp_path / "mine" / "notes.txt").read_text() == "keep"

    def broken(self, *, at="input", **kwargs):
        if at == "output":
            raise RuntimeError("disk full")
        return Figure()

    monkeypatch.setattr(type(lin), "plot", broken)
    with pytest.raises(RuntimeError, match="disk full"):
        lin.write(tmp_path / "b")
    assert sorted(p.name for p in tmp_path.iterdir()) == ["a", "mine"]  # no half-written folder
