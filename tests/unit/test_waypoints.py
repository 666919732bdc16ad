"""Tests of the waypoint missions: reading, straight legs, minimum snap, batches, flights."""

import json
import math
from pathlib import Path

import numpy as np
import pytest
from scipy.integrate import simpson
from scipy.interpolate import make_interp_spline
from scipy.linalg import null_space

import quadcruise as qc
from quadcruise.errors import InputError
from quadcruise.layout import REF_AX, REF_AY, REF_AZ, REF_PSI, REF_PSI_DOT, REF_VX, REF_VY, REF_VZ, REF_X, REF_Y, REF_Z
from quadcruise.missions import MISSIONS, mission_from_dict, mission_from_name, stack_params
from quadcruise.missions.minsnap import MinimumSnap, minimum_snap_coefficients
from quadcruise.missions.waypoints import SETTLE_S, Waypoints, WaypointTable, read_waypoints_csv

EXAMPLE = Path(__file__).resolve().parents[2] / "examples" / "waypoints.csv"
POS, VEL, ACC = [REF_X, REF_Y, REF_Z], [REF_VX, REF_VY, REF_VZ], [REF_AX, REF_AY, REF_AZ]

# an irregular 3-D table with yaw and explicit times (and one sharp turn back)
TIMED = WaypointTable(
    [[0, 0, 1], [2, 1, 1.5], [3, -1, 1.2], [1, -2, 1], [1.5, 0.5, 2]],
    yaw=[0.0, 0.4, -0.3, 1.0, 0.2],
    t=[0.0, 3.0, 5.5, 9.0, 12.0],
)


def central(mission, t, cols, h=1e-5):
    return (mission.reference(t + h)[:, cols] - mission.reference(t - h)[:, cols]) / (2 * h)


def inside(times, per_leg=50, margin=1e-3):
    """Times strictly inside each leg, away from the points."""
    return np.concatenate(
        [np.linspace(a + margin, b - margin, per_leg) for a, b in zip(times[:-1], times[1:], strict=False)]
    )


# --- the example and the table ---------------------------------------------------------------
def test_example_is_a_lawnmower_over_6_by_4_at_1_5m():
    tab = read_waypoints_csv(EXAMPLE)
    assert len(tab) == 8 and tab.t is None and tab.speed is not None
    np.testing.assert_array_equal(tab.points.min(axis=0), [0, 0, 1.5])
    np.testing.assert_array_equal(tab.points.max(axis=0), [6, 4, 1.5])
    legs = np.linalg.norm(np.diff(tab.points, axis=0), axis=1)
    np.testing.assert_allclose(np.diff(tab.times()), legs / tab.speed[1:])


def test_table_from_arrays_times_and_round_trip():
    tab = WaypointTable([[0, 0, 1], [3, 4, 1], [3, 4, 2]])
    np.testing.assert_allclose(tab.times(), [0, 10, 12])  # 0.5 m/s by default
    np.testing.assert_allclose(tab.times(speed=1.0), [0, 5, 6])
    np.testing.assert_array_equal(tab.yaws(), 0.0)
    for t in (tab, TIMED, read_waypoints_csv(EXAMPLE)):
        back = WaypointTable.from_dict(json.loads(json.dumps(t.to_dict())))
        assert back == t and hash(back) == hash(t)
    with pytest.raises(ValueError):
        tab.points[0, 0] = 5.0  # read-only


@pytest.mark.parametrize(
    "kw,match",
    [
        (dict(points=[[0, 0, 1]]), "at least two waypoints"),
        (dict(points=[[0, 0], [1, 1]]), r"expected \(n, 3\)"),
        (dict(points=[[0, 0, 1], [1, 0, 1]], yaw=[0.0]), r"yaw has shape \(1,\)"),
        (dict(points=[[0, 0, 1], [1, 0, np.nan]]), "row 2, column 'z': value is not finite"),
        (dict(points=[[0, 0, 1], [1, 0, 1]], t=[1.0, 2.0]), "row 1, column 't': the first arrival time must be 0"),
        (dict(points=[[0, 0, 1], [1, 0, 1]], t=[0.0, 2.0], speed=[0, 1]), "columns 't' and 'speed'"),
        (dict(points=[[0, 0, 1], [1, 0, 1]], speed=[0, -1.0]), "row 2, column 'speed'"),
        (dict(points=[[0, 0, 1], [0, 0, 1]]), "row 2, column 'x'.*zero-length leg"),
    ],
)
def test_table_errors(kw, match):
    with pytest.raises(InputError, match=match):
        WaypointTable(**kw)


# --- CSV errors: one line each, naming the file, the line and the column -------------------------
@pytest.mark.parametrize(
    "text,line,column",
    [
        ("x,y\n0,0\n1,1\n", 1, "z"),  # missing column
        ("x,y,z\n0,0,1\n1,abc,1\n", 3, "y"),  # not a number
        ("x,y,z\n0,0,1\n1,nan,1\n", 3, "y"),  # NaN
        ("x,y,z\n0,0,1\n", 2, None),  # fewer than two points
        ("x,y,z,t\n0,0,1,0\n1,0,1,2\n2,0,1,2\n", 4, "t"),  # non-increasing t
        ("x,y,z,t\n0,0,1,0.5\n1,0,1,2\n", 2, "t"),  # t does not start at 0
        ("x,y,z,t,speed\n0,0,1,0,\n1,0,1,2,1\n", 1, "t"),  # both t and speed
        ("x,y,z,speed\n0,0,1,\n1,0,1,0.5\n1,0,1,0.5\n", 4, "x"),  # zero-length leg, no dwell
        ("x,y,z\n\n0,0,1\n\n0,0,1\n", 5, "x"),  # ... blank lines still counted
        ("x,y,z,speed\n0,0,1,\n1,0,1,-0.5\n", 3, "speed"),  # negative speed
        ("x,y,z,speed\n0,0,1,\n1,0,1,0\n", 3, "speed"),  # zero speed
        ("x,y,z,speed\n0,0,1,\n1,0,1,\n", 3, "speed"),  # empty speed after the first
        ("x,y,z,yaw\n0,0,1,0\n1,0,1,inf\n", 3, "yaw"),  # infinite yaw
        ("x,y,z,x\n0,0,1,0\n1,0,1,1\n", 1, "x"),  # duplicate column
        ("x,y,z\n0,0,1\n1,0\n", 3, None),  # short row
    ],
)
def test_csv_errors_name_file_line_and_column(tmp_path, text, line, column):
    path = tmp_path / "wp.csv"
    path.write_text(text)
    with pytest.raises(InputError) as err:
        read_waypoints_csv(path)
    msg = str(err.value)
    assert "\n" not in msg and str(path) in msg and f"line {line}" in msg, msg
    if column is not None:
        assert f"'{column}'" in msg and "column" in msg, msg


def test_csv_missing_and_empty_files(tmp_path):
    with pytest.raises(InputError, match="no such file"):
        read_waypoints_csv(tmp_path / "nope.csv")
    (tmp_path / "empty.csv").write_text("\n \n")
    with pytest.raises(InputError, match="empty"):
        read_waypoints_csv(tmp_path / "empty.csv")


def test_csv_dwell_with_times_and_extra_column(tmp_path):
    path = tmp_path / "wp.csv"
    path.write_text("x,y,z,yaw,t,note\n0,0,1,0,0,a\n1,0,1,0,2,b\n1,0,1,1.5,5,turn\n")
    with pytest.warns(UserWarning, match="ignoring column"):
        tab = read_waypoints_csv(path)
    np.testing.assert_array_equal(tab.t, [0, 2, 5])
    ref = Waypoints(tab).reference([3.0, 3.5])  # dwelling, turning
    np.testing.assert_allclose(ref[:, VEL], 0.0)
    np.testing.assert_allclose(ref[:, [REF_PSI, REF_PSI_DOT]], [[0.5, 0.5], [0.75, 0.5]])


# --- straight legs ---------------------------------------------------------------------------
@pytest.mark.parametrize(
    "mission",
    [Waypoints(EXAMPLE), Waypoints(TIMED), Waypoints(WaypointTable([[0, 0, 1], [1, 1, 1], [0, 2, 0.5]]), speed=0.3)],
)
def test_legs_hit_the_points_at_their_times_exactly(mission):
    tab, times = mission.table, mission.times
    ref = mission.reference(times)
    np.testing.assert_array_equal(ref[:, POS], tab.points)
    np.testing.assert_array_equal(ref[:, REF_PSI], tab.yaws())
    after = mission.reference([times[-1], times[-1] + 1.0, 1e6])  # held after the end
    np.testing.assert_array_equal(after[:, POS], np.tile(tab.points[-1], (3, 1)))
    np.testing.assert_array_equal(after[:, VEL + ACC + [REF_PSI_DOT]], 0.0)
    np.testing.assert_array_equal(mission.reference(-1.0)[0, POS], tab.points[0])
    assert mission.params().shape == (2 + 5 * len(tab),)


def test_legs_speed_straight_lines_and_jumps_only_at_corners():
    mission = Waypoints(EXAMPLE)
    tab, times = mission.table, mission.times
    t = inside(times)
    ref = mission.reference(t)
    leg = np.searchsorted(times, t) - 1
    np.testing.assert_allclose(np.linalg.norm(ref[:, VEL], axis=1), tab.speed[1:][leg], rtol=1e-12)
    np.testing.assert_array_equal(ref[:, ACC + [REF_PSI_DOT]], 0.0)
    np.testing.assert_allclose(central(mission, t, POS), ref[:, VEL], atol=1e-9)
    direction = np.diff(tab.points, axis=0) / np.linalg.norm(np.diff(tab.points, axis=0), axis=1)[:, None]
    np.testing.assert_allclose(ref[:, VEL] / tab.speed[1:][leg, None], direction[leg], atol=1e-12)
    # velocity is piecewise constant: it changes between samples only across a point's time
    dense = np.linspace(0.0, times[-1] + 2.0, 20001)
    v = mission.reference(dense)[:, VEL]
    jumps = np.flatnonzero(np.any(np.abs(np.diff(v, axis=0)) > 1e-12, axis=1))
    crossed = [np.flatnonzero((dense[j] < times) & (times <= dense[j + 1])) for j in jumps]
    assert all(c.size == 1 for c in crossed) and len(jumps) == len(times) - 1
    before, at = mission.reference([times[1] - 1e-9, times[1]])[:, VEL]  # the leg is [t_k, t_k+1)
    np.testing.assert_allclose(before, [0, 0.6, 0])
    np.testing.assert_allclose(at, [0.4, 0, 0])


def test_legs_yaw_linear_or_held():
    t = np.array([1.0, 4.0, 7.0])
    lin = Waypoints(TIMED).reference(t)
    np.testing.assert_allclose(lin[:, REF_PSI], np.interp(t, TIMED.t, TIMED.yaw), atol=1e-14)
    np.testing.assert_allclose(central(Waypoints(TIMED), t, [REF_PSI])[:, 0], lin[:, REF_PSI_DOT], atol=1e-9)
    held = Waypoints(TIMED, yaw_mode="hold").reference(t)
    np.testing.assert_array_equal(held[:, REF_PSI], TIMED.yaw[[0, 1, 2]])
    np.testing.assert_array_equal(held[:, REF_PSI_DOT], 0.0)
    np.testing.assert_array_equal(held[:, POS], lin[:, POS])


def test_default_speed_and_duration():
    tab = WaypointTable([[0, 0, 1], [3, 0, 1], [3, 4, 1]])
    np.testing.assert_allclose(Waypoints(tab).times, [0, 6, 14])
    m = Waypoints(tab, speed=2.0)
    np.testing.assert_allclose(m.times, [0, 1.5, 3.5])
    assert m.duration == math.ceil(3.5 + SETTLE_S) == 9.0
    ex = MinimumSnap(EXAMPLE)
    assert ex.times[-1] + SETTLE_S <= ex.duration < ex.times[-1] + SETTLE_S + 1 and ex.duration % 1 == 0
    for bad in (dict(speed=0.0), dict(style="smooth"), dict(yaw_mode="spin")):
        with pytest.raises(InputError):
            Waypoints(tab, **bad)
    with pytest.raises(InputError, match="waypoint table"):
        Waypoints(42)


# --- minimum snap ----------------------------------------------------------------------------
def segment_polys(mission):
    """numpy Polynomials in t - t_i per segment and axis, from the solved coefficients."""
    tk = mission.times
    out = []
    for i, dur in enumerate(np.diff(tk)):
        scale = dur ** -np.arange(8.0)  # s^k = (t - t_i)^k / T^k
        out.append([np.polynomial.Polynomial(mission.coefficients[i, :, a] * scale) for a in range(4)])
    return tk, out


@pytest.mark.parametrize("mission", [MinimumSnap(EXAMPLE), MinimumSnap(TIMED)])
def test_minsnap_through_points_continuous_and_at_rest_at_the_ends(mission):
    tab, tk = mission.table, mission.times
    ref = mission.reference(tk)
    np.testing.assert_allclose(ref[:, POS], tab.points, rtol=0, atol=1e-9)
    np.testing.assert_allclose(ref[:, REF_PSI], tab.yaws(), rtol=0, atol=1e-9)
    tk, polys = segment_polys(mission)
    dur = np.diff(tk)
    for i in range(1, len(tk) - 1):  # left and right of interior knot i
        for a in range(4):
            left, right = polys[i - 1][a], polys[i][a]
            for r in range(7):  # C3 by constraint, C4..C6 by optimality
                lv, rv = left.deriv(r)(dur[i - 1]) if r else left(dur[i - 1]), right.deriv(r)(0.0) if r else right(0.0)
                assert lv == pytest.approx(rv, abs=1e-9), (i, a, r)
    for seg, s in ((polys[0], 0.0), (polys[-1], dur[-1])):  # rest at both ends
        for a in range(4):
            for r in (1, 2, 3):
                assert abs(seg[a].deriv(r)(s)) < 1e-9
    # the compiled function agrees with numpy, and with its own numerical derivatives
    t = inside(tk, margin=1e-4)
    seg = np.searchsorted(tk, t) - 1
    ref = mission.reference(t)
    for a, (col, vcol, _acol) in enumerate(zip(POS, VEL, ACC, strict=False)):
        p = np.array([polys[i][a](tt - tk[i]) for tt, i in zip(t, seg, strict=False)])
        v = np.array([polys[i][a].deriv()(tt - tk[i]) for tt, i in zip(t, seg, strict=False)])
        np.testing.assert_allclose(ref[:, col], p, atol=1e-10)
        np.testing.assert_allclose(ref[:, vcol], v, atol=1e-9)
    np.testing.assert_allclose(central(mission, t, POS), ref[:, VEL], atol=1e-7)
    np.testing.assert_allclose(central(mission, t, VEL), ref[:, ACC], atol=1e-7)
    np.testing.assert_allclose(central(mission, t, [REF_PSI]), ref[:, [REF_PSI_DOT]], atol=1e-7)
    end = mission.reference([tk[-1], tk[-1] + 3.0])
    np.testing.assert_array_equal(end[:, POS], np.tile(tab.points[-1], (2, 1)))
    np.testing.assert_array_equal(end[:, VEL + ACC], 0.0)
    np.testing.assert_allclose(mission.reference(0.0)[0, VEL + ACC], 0.0, atol=1e-12)


UNEVEN = WaypointTable(
    np.random.default_rng(3).uniform(-2, 2, (6, 3)),
    yaw=[0.0, 1.0, 0.5, -0.5, 0.0, 2.0],
    t=np.cumsum([0, 1, 50, 3, 0.5, 20]),
)


@pytest.mark.parametrize("tab", [TIMED, UNEVEN])
def test_minsnap_is_the_clamped_degree_7_spline(tab):
    """The optimum is C6 inside: scipy's interpolating septic spline with zero velocity,
    acceleration and jerk at the ends is the same curve (an independent check), even for
    segment times 100 times apart (whose path swings far out)."""
    m = MinimumSnap(tab)
    bc = [(1, np.zeros(4)), (2, np.zeros(4)), (3, np.zeros(4))]
    spline = make_interp_spline(tab.t, np.column_stack([tab.points, tab.yaw]), k=7, bc_type=(bc, bc))
    t = np.linspace(0.0, tab.t[-1], 1501)
    ref, want = m.reference(t), spline(t)
    scale = np.abs(want).max()
    np.testing.assert_allclose(ref[:, POS + [REF_PSI]], want, atol=1e-11 * scale)
    np.testing.assert_allclose(ref[:, ACC], spline(t, 2)[:, :3], atol=1e-11 * scale)
    np.testing.assert_allclose(m.reference(tab.t)[:, POS], tab.points, atol=1e-9)


def snap_integral(coef, tk, n=2001):
    """int |d^4 p / dt^4|^2 dt over the path, by Simpson's rule on each segment."""
    total = 0.0
    for i, dur in enumerate(np.diff(tk)):
        tt = np.linspace(0.0, dur, n)
        for a in range(3):
            snap = np.polynomial.Polynomial(coef[i, :, a] * dur ** -np.arange(8.0)).deriv(4)(tt)
            total += simpson(snap**2, x=tt)
    return total


def test_minsnap_has_less_snap_than_the_alternatives():
    m = MinimumSnap(EXAMPLE)
    tk, pts = m.times, m.table.points
    best = snap_integral(m.coefficients, tk)
    # 1. stopping at every point (rest-to-rest septics): the same constraints, and C3 too
    naive = minimum_snap_coefficients(pts, tk, stops=np.ones(len(tk), bool))
    assert best < 0.5 * snap_integral(naive, tk)
    # 2. any feasible change of the coefficients (same points, C3, rest at the ends) adds snap
    from quadcruise.missions.minsnap import _derivative_row

    m_seg = len(tk) - 1
    rows = []
    for j in range(len(tk)):
        for r in range(4):
            if j > 0:
                rows.append(
                    np.r_[
                        np.zeros(8 * (j - 1)),
                        _derivative_row(r, 1.0) / np.diff(tk)[j - 1] ** r,
                        np.zeros(8 * (m_seg - j)),
                    ]
                )
            if j < m_seg and (r == 0 or j == 0 or j == m_seg):
                rows.append(
                    np.r_[np.zeros(8 * j), _derivative_row(r, 0.0) / np.diff(tk)[j] ** r, np.zeros(8 * (m_seg - j - 1))]
                )
            elif j < m_seg:  # continuity: right minus left
                rows[-1] = (
                    rows[-1]
                    - np.r_[
                        np.zeros(8 * j), _derivative_row(r, 0.0) / np.diff(tk)[j] ** r, np.zeros(8 * (m_seg - j - 1))
                    ]
                )
    free = null_space(np.array(rows))
    rng = np.random.default_rng(7)
    for _ in range(5):
        step = (free @ rng.standard_normal((free.shape[1], 3))).reshape(m_seg, 8, 3)
        step *= 0.05 / np.abs(step).max()
        assert snap_integral(m.coefficients[:, :, :3] + step, tk) > best


def test_minsnap_dwell_is_a_stop_and_yaw_turns_rest_to_rest():
    tab = WaypointTable([[0, 0, 1], [2, 0, 1], [2, 0, 1], [2, 2, 1]], yaw=[0, 0, 1.0, 1.0], t=[0, 4, 7, 11])
    m = MinimumSnap(tab)
    ref = m.reference(np.linspace(4.0, 7.0, 31))
    np.testing.assert_allclose(ref[:, POS], np.tile([2, 0, 1], (31, 1)), atol=1e-9)
    np.testing.assert_allclose(ref[:, VEL + ACC], 0.0, atol=1e-9)
    assert ref[0, REF_PSI] == pytest.approx(0.0, abs=1e-9) and ref[-1, REF_PSI] == pytest.approx(1.0, abs=1e-9)
    assert np.all(np.diff(ref[:, REF_PSI]) >= -1e-12) and ref[15, REF_PSI_DOT] > 0


def test_minimum_snap_coefficients_single_segment_and_shapes():
    c = minimum_snap_coefficients([[0.0, 1.0], [1.0, -1.0]], [0.0, 3.0])
    assert c.shape == (1, 8, 2)
    np.testing.assert_allclose(c[0, :, 1], [1, 0, 0, 0, -70, 168, -140, 40], atol=1e-9)


# --- mp, batches, registration, dicts ---------------------------------------------------------
def test_layouts_registration_and_dicts():
    assert MISSIONS["waypoints"] is Waypoints and MISSIONS["minsnap"] is MinimumSnap
    m = mission_from_name("minsnap", table=str(EXAMPLE), speed=0.7)
    assert m.params().shape == (6 + 34 * 7,) and m.params()[0] == 7
    np.testing.assert_allclose(m.params()[1:6], [6, 0, 1.5, 0, m.times[-1]])
    for mission in (m, Waypoints(TIMED, yaw_mode="hold")):
        d = json.loads(json.dumps(mission.to_dict()))
        back = mission_from_dict(d)
        assert back == mission and type(back) is type(mission)
        np.testing.assert_array_equal(back.params(), mission.params())
    assert Waypoints(TIMED).replace(speed=1.0).table == TIMED


@pytest.mark.parametrize("cls", [Waypoints, MinimumSnap])
def test_stack_pads_tables_of_different_lengths(cls):
    long, short = cls(EXAMPLE), cls(WaypointTable([[0, 0, 1], [1, 0, 1]], t=[0, 2]))
    rows = stack_params([long, short])
    assert rows.shape == (2, long.params().size)
    np.testing.assert_array_equal(rows[1, short.params().size :], 0.0)
    t = np.linspace(-1, 50, 301)
    for row, mission in zip(rows, (long, short), strict=False):
        out = np.empty((t.size, 11))
        from quadcruise.missions.base import _evaluate

        _evaluate(cls.function, t, np.ascontiguousarray(row), out)
        np.testing.assert_array_equal(out, mission.reference(t))
    assert stack_params([short], n=3).shape == (3, short.params().size)
    np.testing.assert_array_equal(stack_params(long, n=2), np.vstack([long.params()] * 2))
    frozen = np.linspace(0.0, 10.0, 11)
    frozen.flags.writeable = False  # read-only times are fine too
    np.testing.assert_array_equal(long.reference(frozen), long.reference(frozen.copy()))


# --- flights ---------------------------------------------------------------------------------
def test_both_styles_fly_the_example():
    out = {}
    for mission in (Waypoints(EXAMPLE), MinimumSnap(EXAMPLE)):
        res = qc.fly(mission, "nlpd", duration=mission.duration)
        assert res.ok.tolist() == [True] and res.t[-1] == mission.duration
        row = res.metrics().iloc[0]
        assert row["rmse_m"] < 0.1 and row["max_error_m"] < 0.3, (mission.name, row)
        np.testing.assert_allclose(res.final_state[0, :3], mission.table.points[-1], atol=0.05)
        out[mission.name] = row
    # no velocity jumps: the smooth path never lags as far behind as the corners do
    assert out["minsnap"]["max_error_m"] < out["waypoints"]["max_error_m"]


@pytest.mark.parametrize("kind", ["waypoints", "minsnap"])
def test_yaw_through_plus_minus_pi_turns_the_short_way(kind):
    from quadcruise.layout import REF_PSI
    from quadcruise.missions import MinimumSnap, Waypoints, WaypointTable

    table = WaypointTable([[0, 0, 1], [2, 0, 1], [4, 0, 1]], yaw=[3.0, -3.0, 3.0])
    mission = (Waypoints if kind == "waypoints" else MinimumSnap)(table)
    psi = mission.reference(np.linspace(0.0, mission.duration, 2001))[:, REF_PSI]
    travel = np.abs(np.diff(psi)).sum()
    assert travel == pytest.approx(2 * (2 * np.pi - 6.0), rel=0.05)  # 0.57 rad, not 12
    assert np.allclose(np.cos(psi[[0, -1]]), np.cos(3.0)) and np.allclose(np.sin(psi[[0, -1]]), np.sin(3.0))


def kkt_minimum_snap(values, times, stops):
    """The minimum-snap QP in its other form, for comparison: all 8 coefficients of every
    segment as unknowns, the interpolation, rest and C1-C3 conditions as equality constraints,
    solved through the (dense) KKT system of min sum_i T_i^-7 a_i^T H a_i."""
    from quadcruise.missions.minsnap import _derivative_row

    w = np.asarray(values, dtype=float).reshape(len(times), -1)
    dur = np.diff(np.asarray(times, dtype=float))
    n, m = w.shape[0], w.shape[0] - 1
    stop = np.asarray(stops, bool).copy()
    stop[[0, -1]] = True
    g = (dur / dur[0]) ** 3.5  # unknowns b_i = a_i / g_i: every block weighs H alone
    rows, rhs = [], []

    def constrain(value, *terms):
        row = np.zeros(8 * m)
        for seg, d in terms:
            row[8 * seg : 8 * seg + 8] += d * g[seg]
        scale = np.abs(row).max()
        rows.append(row / scale)
        rhs.append(np.broadcast_to(value, (w.shape[1],)) / scale)

    for j in range(n):
        if j > 0:
            constrain(w[j], (j - 1, _derivative_row(0, 1.0)))
        if j < m:
            constrain(w[j], (j, _derivative_row(0, 0.0)))
        for r in range(1, 4):
            if stop[j]:
                if j > 0:
                    constrain(0.0, (j - 1, _derivative_row(r, 1.0)))
                if j < m:
                    constrain(0.0, (j, _derivative_row(r, 0.0)))
            else:
                constrain(
                    0.0, (j - 1, _derivative_row(r, 1.0) / dur[j - 1] ** r), (j, -_derivative_row(r, 0.0) / dur[j] ** r)
                )
    k = np.arange(4, 8)
    fall = np.array([math.perm(int(i), 4) for i in k], dtype=float)
    h = np.zeros((8, 8))
    h[4:, 4:] = np.outer(fall, fall) / (k[:, None] + k[None, :] - 7)
    a_eq = np.array(rows)
    kkt = np.block([[np.kron(np.eye(m), h), a_eq.T], [a_eq, np.zeros((len(rows), len(rows)))]])
    sol = np.linalg.solve(kkt, np.vstack([np.zeros((8 * m, w.shape[1])), np.array(rhs)]))
    return g[:, None, None] * sol[: 8 * m].reshape(m, 8, -1)


@pytest.mark.parametrize("seed", [0, 1, 2])
def test_banded_minimum_snap_equals_the_kkt_solution(seed):
    """The banded solver (the knots' derivatives as unknowns) and the KKT system over all
    coefficients are two forms of one QP: the same coefficients, dwells and uneven legs included."""
    rng = np.random.default_rng(seed)
    n = 12
    times = np.r_[0.0, np.cumsum(rng.uniform(0.2, 5.0, n - 1))]
    values = 3.0 * rng.standard_normal((n, 4))
    stops = rng.random(n) < 0.25
    want = kkt_minimum_snap(values, times, stops)
    got = minimum_snap_coefficients(values, times, stops)
    np.testing.assert_allclose(got, want, rtol=0, atol=1e-9 * np.abs(want).max())
    # and a wrong answer would be seen: the same path without its stops differs
    assert np.abs(minimum_snap_coefficients(values, times) - want).max() > 1e-3 * np.abs(want).max()


def test_minimum_snap_through_many_waypoints_is_the_septic_spline():
    """20,000 knots (a banded solve, linear in the knots): still scipy's clamped septic spline."""
    rng = np.random.default_rng(3)
    n = 20_000
    times = np.r_[0.0, np.cumsum(rng.uniform(0.05, 0.2, n - 1))]
    values = np.cumsum(rng.standard_normal((n, 3)) * 0.05, axis=0)
    coef = minimum_snap_coefficients(values, times)
    bc = [(1, np.zeros(3)), (2, np.zeros(3)), (3, np.zeros(3))]
    spline = make_interp_spline(times, values, k=7, bc_type=(bc, bc))
    seg = rng.integers(0, n - 1, 500)
    s = rng.random(500)
    ours = np.einsum("ik,ika->ia", s[:, None] ** np.arange(8), coef[seg])
    t = times[seg] + s * np.diff(times)[seg]
    np.testing.assert_allclose(ours, spline(t), rtol=0, atol=1e-9 * np.abs(values).max())
