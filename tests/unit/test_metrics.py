"""Tests of quadcruise.metrics, with python-control and closed forms as independent paths."""

from __future__ import annotations

import dataclasses
import doctest

import control
import numpy as np
import pandas as pd
import pytest
from scipy.optimize import brentq

from quadcruise.errors import InputError
from quadcruise.metrics import (
    StepInfo,
    control_effort,
    conventions,
    signals,
    step,
    step_info,
    step_info_batch,
    time_in_saturation,
    tracking_errors,
    transient_info,
)
from quadcruise.metrics import flight as metrics

# The linear design loop G = (5 s + 3.01) / (s^2 + 5 s + 3.01), poles -4.3 and -0.7.
G = control.tf([5.0, 3.01], [1.0, 5.0, 3.01])


def design_loop_exact(t):
    """Closed-form unit step response of G (partial fractions)."""
    t = np.asarray(t, dtype=float)
    a = (-5.0 * 4.3 + 3.01) / (-4.3 * (-4.3 + 0.7))
    b = (-5.0 * 0.7 + 3.01) / (-0.7 * (-0.7 + 4.3))
    return 1.0 + a * np.exp(-4.3 * t) + b * np.exp(-0.7 * t)


def second_order(t, zeta, wn):
    """Unit step response of wn^2 / (s^2 + 2 zeta wn s + wn^2), 0 < zeta < 1."""
    wd = wn * np.sqrt(1.0 - zeta**2)
    return 1.0 - np.exp(-zeta * wn * t) / np.sqrt(1.0 - zeta**2) * np.sin(wd * t + np.arccos(zeta))


@pytest.fixture(scope="module")
def design_loop():
    resp = control.step_response(G, T=np.linspace(0.0, 20.0, 20001))
    return np.asarray(resp.time), np.asarray(resp.outputs)


# --- step_info -------------------------------------------------------------------------


def test_design_loop_agrees_with_python_control(design_loop):
    t, y = design_loop
    ours = step_info(t, y)
    ref2 = control.step_info(y, T=t, SettlingTimeThreshold=0.02)
    ref5 = control.step_info(y, T=t, SettlingTimeThreshold=0.05)
    assert ours.rise_time == pytest.approx(ref2["RiseTime"], abs=1e-3)
    assert ours.settling_time == pytest.approx(ref2["SettlingTime"], abs=1e-3)
    assert ours.settling_time_5pct == pytest.approx(ref5["SettlingTime"], abs=1e-3)
    assert ours.overshoot_pct == pytest.approx(ref2["Overshoot"], abs=0.01)
    assert ours.undershoot_pct == pytest.approx(ref2["Undershoot"], abs=0.01)
    assert ours.peak == pytest.approx(ref2["Peak"], abs=1e-9)
    assert ours.peak_time == pytest.approx(ref2["PeakTime"], abs=1e-9)
    assert ours.settled
    # The design values (python-control's own default, coarser grid rounds them up to
    # 0.35 s and 3.27 s; the 1 ms grid gives these).
    assert ours.rise_time == pytest.approx(0.342, abs=1e-3)
    assert ours.settling_time == pytest.approx(3.249, abs=1e-3)
    assert ours.settling_time_5pct == pytest.approx(1.932, abs=1e-3)
    assert ours.overshoot_pct == pytest.approx(8.04, abs=0.01)


def test_design_loop_agrees_with_closed_form(design_loop):
    t, y = design_loop
    assert np.max(np.abs(y - design_loop_exact(t))) < 1e-9  # the simulation is exact
    ours = step_info(t, y, y_final=1.0)

    def cross(level, lo, hi):
        return brentq(lambda s: design_loop_exact(s) - level, lo, hi, xtol=1e-14)

    t_peak = np.log(4.3 * 1.1944444444444444 / (0.7 * 0.19444444444444445)) / 3.6
    rise = cross(0.9, 0.0, t_peak) - cross(0.1, 0.0, t_peak)
    settle2 = cross(1.02, t_peak, 20.0)  # last exit: falling through the upper edge
    settle5 = cross(1.05, t_peak, 20.0)
    # Linear interpolation on a 1 ms grid is accurate far below a sample interval.
    assert ours.rise_time == pytest.approx(rise, abs=1e-6)
    assert ours.settling_time == pytest.approx(settle2, abs=1e-6)
    assert ours.settling_time_5pct == pytest.approx(settle5, abs=1e-6)
    assert ours.overshoot_pct == pytest.approx(100 * (design_loop_exact(t_peak) - 1), abs=1e-4)
    assert ours.peak_time == pytest.approx(t_peak, abs=1e-3)


@pytest.mark.parametrize("zeta", [0.1, 0.3, 0.5, 0.7])
def test_second_order_overshoot_matches_analytic(zeta):
    wn = 3.0
    t = np.linspace(0.0, 5.0, 5001)
    sys2 = control.tf([wn**2], [1, 2 * zeta * wn, wn**2])
    y = np.asarray(control.step_response(sys2, T=t).outputs)
    info = step_info(t, y, y_final=1.0)
    analytic = 100 * np.exp(-zeta * np.pi / np.sqrt(1 - zeta**2))
    assert info.overshoot_pct == pytest.approx(analytic, abs=0.01)
    assert info.peak_time == pytest.approx(np.pi / (wn * np.sqrt(1 - zeta**2)), abs=1e-3)
    assert info.undershoot_pct == 0.0


def test_downward_step_mirrors_upward():
    t = np.linspace(0.0, 15.0, 3001)
    up = second_order(t, 0.4, 2.0)
    a = step_info(t, up, y_final=1.0)
    b = step_info(t, 5.0 - 2.0 * up, y_final=3.0)  # from 5 m down to 3 m
    assert (b.y_initial, b.y_final) == pytest.approx((5.0, 3.0))
    for name in ("rise_time", "settling_time", "settling_time_5pct", "overshoot_pct", "undershoot_pct", "peak_time"):
        assert getattr(b, name) == pytest.approx(getattr(a, name), abs=1e-9), name
    assert b.peak == pytest.approx(5.0 - 2.0 * a.peak)  # the lowest point
    assert b.peak < 3.0 and b.overshoot_pct > 20.0


def test_delayed_step_from_nonzero_level():
    t = np.linspace(0.0, 20.0, 20001)
    t_step = 2.5004  # between samples
    y = 1.5 + np.where(t > t_step, -0.8 * second_order(np.maximum(t - t_step, 0.0), 0.5, 3.0), 0.0)
    delayed = step_info(t, y, y_final=0.7, t_step=t_step)
    t0 = np.linspace(0.0, 20.0 - t_step, 20001)
    plain = step_info(t0, second_order(t0, 0.5, 3.0), y_final=1.0)
    assert delayed.y_initial == pytest.approx(1.5)  # interpolated at t_step
    for name in ("rise_time", "settling_time", "settling_time_5pct", "overshoot_pct"):
        assert getattr(delayed, name) == pytest.approx(getattr(plain, name), abs=2e-6), name
    assert delayed.peak_time == pytest.approx(plain.peak_time, abs=1e-3)  # from the step
    # Measured from t[0] instead, the same record is a different (wrong) step.
    assert step_info(t, y, y_final=0.7).settling_time > delayed.settling_time + 2.0


def test_response_that_does_not_settle():
    t = np.linspace(0.0, 3.5, 3501)
    info = step_info(t, 1.0 - np.exp(-t), y_final=1.0)  # 3 % short at the end
    assert info.settling_time is None and not info.settled
    assert info.settling_time_5pct == pytest.approx(np.log(20.0), abs=1e-6)
    slow = step_info(t, 1.0 - np.exp(-t / 10.0), y_final=1.0)
    assert slow.rise_time is None and slow.settling_time_5pct is None
    t_osc = np.linspace(0, 9.8, 981)  # undamped, ends off the band
    osc = step_info(t_osc, 1.0 - 0.5 * np.cos(t_osc), y_final=1.0)
    assert osc.settling_time is None and osc.settling_time_5pct is None
    assert osc.to_dict()["settling_time"] is None


def test_interpolation_coarse_vs_fine():
    fine_t = np.linspace(0.0, 20.0, 40001)
    coarse_t = np.linspace(0.0, 20.0, 401)  # dt = 50 ms
    fine = step_info(fine_t, second_order(fine_t, 0.3, 3.0), y_final=1.0)
    coarse = step_info(coarse_t, second_order(coarse_t, 0.3, 3.0), y_final=1.0)
    # Snapping to samples would be off by up to dt = 0.05 s; interpolation by far less.
    for name in ("rise_time", "settling_time", "settling_time_5pct"):
        assert getattr(coarse, name) == pytest.approx(getattr(fine, name), abs=5e-3), name
    assert coarse.overshoot_pct == pytest.approx(fine.overshoot_pct, abs=0.01)


def test_stepinfo_is_frozen_and_dicts():
    info = step_info([0.0, 1.0, 2.0], [0.0, 1.0, 1.0])
    with pytest.raises(dataclasses.FrozenInstanceError):
        info.rise_time = 0.0
    d = info.to_dict()
    assert set(d) == {f.name for f in dataclasses.fields(StepInfo)}
    assert d["rise_time"] == pytest.approx(0.8) and d["settled"] is True


@pytest.mark.parametrize(
    "t, y, kw, words",
    [
        ([0.0, 1.0, 1.0], [0.0, 1.0, 2.0], {}, "strictly increasing"),
        ([0.0, 2.0, 1.0], [0.0, 1.0, 2.0], {}, "strictly increasing"),
        ([0.0, 1.0, 2.0], [0.0, 1.0], {}, "shape"),
        ([0.0, 1.0, 2.0], [0.0, np.nan, 2.0], {}, "NaN"),
        ([0.0, np.nan, 2.0], [0.0, 1.0, 2.0], {}, "NaN"),
        ([0.0], [1.0], {}, "at least 2"),
        ([0.0, 1.0, 2.0], [3.0, 3.0, 3.0], {}, "step size"),
        ([0.0, 1.0, 2.0], [0.0, 1.0, 2.0], {"y_initial": 2.0}, "step size"),
        ([0.0, 1.0, 2.0], [0.0, 1.0, 2.0], {"t_step": 2.0}, "t_step"),
        ([0.0, 1.0, 2.0], [0.0, 1.0, 2.0], {"rise": (0.9, 0.1)}, "rise"),
    ],
)
def test_step_info_bad_input(t, y, kw, words):
    with pytest.raises(InputError, match=words) as err:
        step_info(t, y, **kw)
    assert "\n" not in str(err.value)


def test_step_info_batch_matches_loop_and_marks_nan():
    t = np.linspace(0.0, 6.0, 601)
    zetas = np.array([0.2, 0.5, 0.8, 1.2])
    y = np.array([control.step_response(control.tf([4.0], [1, 4 * z, 4.0]), T=t).outputs for z in zetas])
    y[-1] *= 0.9  # settles 10 % short of 1
    out = step_info_batch(t, y, y_final=np.ones(4))
    for i in range(3):
        one = step_info(t, y[i], y_final=1.0).to_dict()
        for name, value in one.items():
            expected = np.nan if value is None else value
            assert out[name][i] == pytest.approx(expected, nan_ok=True), name
    assert np.isnan(out["settling_time"][0]) and out["settling_time_5pct"][0] > 0  # zeta 0.2
    assert np.isnan(out["settling_time"][-1]) and not out["settled"][-1]
    assert out["settled"].dtype == bool and out["rise_time"].shape == (4,)


# --- transient_info --------------------------------------------------------------------


def test_transient_with_constant_reference_is_the_step(design_loop):
    t, y = design_loop
    for act, ref in ((y, 1.0), (3.0 - 4.0 * y, -1.0)):
        step = step_info(t, act, y_final=ref)
        tr = transient_info(t, act, np.full_like(t, ref))
        for name in (
            "rise_time",
            "settling_time",
            "settling_time_5pct",
            "overshoot_pct",
            "undershoot_pct",
            "peak_time",
            "settled",
        ):
            assert getattr(tr, name) == pytest.approx(getattr(step, name), abs=1e-9), name
        assert (tr.y_initial, tr.y_final) == (0.0, 1.0)


def test_transient_chasing_a_circle():
    t = np.linspace(0.0, 10.0, 10001)
    ref = np.c_[2.0 * np.cos(t), 2.0 * np.sin(t), np.full_like(t, 1.0)]
    act = ref - np.c_[2.0 * np.exp(-t), np.zeros_like(t), np.zeros_like(t)]
    info = transient_info(t, act, ref)  # starts 2 m away, error 2 e^-t
    assert info.rise_time == pytest.approx(np.log(9.0), abs=1e-6)
    assert info.settling_time == pytest.approx(np.log(50.0), abs=1e-6)
    assert info.overshoot_pct == 0.0
    # One axis with a moving reference: the same progress, signed.
    one = transient_info(t, ref[:, 1] - 0.5 * np.exp(-t), ref[:, 1])
    assert one.settling_time_5pct == pytest.approx(np.log(20.0), abs=1e-6)


def test_transient_without_initial_error_is_rejected():
    t = np.linspace(0.0, 1.0, 11)
    with pytest.raises(InputError, match="no transient"):
        transient_info(t, np.sin(t), np.sin(t) + 1e-15 * t)


# --- tracking, effort, saturation --------------------------------------------------------


def test_tracking_errors_on_nonuniform_grid():
    rng = np.random.default_rng(1)
    # Dense in the first second, sparse in the second one: a plain sample mean is biased.
    t = np.sort(np.r_[0.0, rng.uniform(0.0, 1.0, 3000), rng.uniform(1.0, 2.0, 300), 2.0])
    out = tracking_errors(t, t + 0.5, np.full_like(t, 0.5))  # error e(t) = t
    assert out["rmse"] == pytest.approx(np.sqrt(4.0 / 3.0), abs=1e-4)
    assert out["max_error"] == pytest.approx(2.0)
    assert np.sqrt(np.mean(t**2)) < np.sqrt(4.0 / 3.0) - 0.3  # the bias we avoid


def test_tracking_errors_euclidean_and_t_from():
    t = np.array([0.0, 1.0, 2.0, 3.0])
    act = np.c_[[3.0, 3.0, 3.0, 3.0], [4.0, 4.0, 4.0, 4.0], [0.0, 0.0, 0.0, 0.0]]
    out = tracking_errors(t, act, np.zeros((4, 3)))
    assert out["rmse"] == pytest.approx(5.0) and out["max_error"] == pytest.approx(5.0)
    np.testing.assert_allclose(out["rmse_axes"], [3.0, 4.0, 0.0])
    e = np.array([10.0, 0.0, 0.0, 0.0])
    assert tracking_errors(t, e, 0.0, t_from=1.0)["max_error"] == 0.0
    half = tracking_errors(t, e, 0.0, t_from=0.5)  # error 5 interpolated at 0.5 s
    assert half["max_error"] == pytest.approx(5.0)
    assert half["rmse"] == pytest.approx(np.sqrt(0.5 * 25.0 * 0.5 / 2.5))
    with pytest.raises(InputError, match="t_from"):
        tracking_errors(t, e, 0.0, t_from=3.0)


def test_batch_metrics_are_vectorised_and_match_single():
    rng = np.random.default_rng(2)
    n, length = 10000, 100
    t = np.cumsum(rng.uniform(0.005, 0.015, length))
    ref = rng.normal(size=(length, 3))
    act = ref + 0.1 * rng.normal(size=(n, length, 3))
    u = rng.uniform(0.0, 1.0, size=(n, length, 4))
    flags = rng.integers(0, 16, size=(n, length)) > 12
    t_from = t[10] + 1e-4
    trk = tracking_errors(t, act, ref, t_from=t_from)
    eff, sat = control_effort(t, u), time_in_saturation(t, flags)
    assert trk["rmse"].shape == (n,) and trk["rmse_axes"].shape == (n, 3)
    assert eff["integral"].shape == (n,) and sat["seconds"].shape == (n,)
    for i in (0, 4321, n - 1):
        one = tracking_errors(t, act[i], ref, t_from=t_from)
        assert trk["rmse"][i] == pytest.approx(one["rmse"])
        assert trk["max_error"][i] == pytest.approx(one["max_error"])
        assert eff["mean"][i] == pytest.approx(control_effort(t, u[i])["mean"])
        assert sat["fraction"][i] == pytest.approx(time_in_saturation(t, flags[i])["fraction"])


def test_control_effort_closed_form():
    t = np.linspace(0.0, 2.0, 2001)
    u = np.c_[np.full_like(t, 0.5), np.sin(np.pi * t)]  # 0.25 + sin^2: mean 0.75
    out = control_effort(t, u)
    assert out["integral"] == pytest.approx(1.5, abs=1e-6)
    assert out["mean"] == pytest.approx(0.75, abs=1e-6)
    with pytest.raises(InputError, match="u must"):
        control_effort(t, np.zeros((5, 4)))


def test_time_in_saturation_sample_and_hold():
    t = np.array([0.0, 0.5, 2.0, 2.5, 4.0])
    bits = np.array([0, 4, 4, 0, 8])  # bit masks; the last holds 0 s
    out = time_in_saturation(t, bits)
    assert out["seconds"] == pytest.approx(2.0) and out["fraction"] == pytest.approx(0.5)
    both = time_in_saturation(t, np.array([bits != 0, np.ones(5, bool)]))
    np.testing.assert_allclose(both["seconds"], [2.0, 4.0])
    with pytest.raises(InputError, match="flags"):
        time_in_saturation(t, bits[:4])


@pytest.mark.parametrize("module", [step, signals, conventions, metrics], ids=lambda m: m.__name__)
def test_docstring_examples(module):
    result = doctest.testmod(module, raise_on_error=False)
    assert result.attempted >= 2 and result.failed == 0


# --- a whole flight: tracking after the transient, peak time, conventions, effort ------------


def as_result(t, pos, ref, *, duties=None, status=None, meta=None):
    """A SimResult of N vehicles from positions and references (N, L, 3) [m]."""
    from quadcruise.layout import CMD_SIZE, CMD_U1, REF_SIZE, REF_X, STATE_SIZE, X
    from quadcruise.sim.result import SimResult

    n, length = pos.shape[:2]
    states = np.zeros((n, length, STATE_SIZE))
    states[:, :, X : X + 3] = pos
    refs = np.zeros((n, length, REF_SIZE))
    refs[:, :, REF_X : REF_X + 3] = ref
    commands = np.zeros((n, length, CMD_SIZE))
    commands[:, :, CMD_U1 : CMD_U1 + 4] = 0.25 if duties is None else duties
    status = np.zeros(n, dtype=np.int64) if status is None else np.asarray(status)
    return SimResult(
        t=t,
        states=states,
        commands=commands,
        references=refs,
        final_state=states[:, -1],
        status=status,
        t_stop=np.full(n, t[-1]),
        memory=np.zeros((n, 0)),
        duty_clipped_s=np.zeros(n),
        controller_limited_s=np.zeros(n),
        meta={"vehicle": {"m": 1.0, "g": 10.0, "K": 10.0}} if meta is None else meta,
    )


def step_mission(time=0.0, size=1.0):
    return {"kind": "step", "axis": "x", "time": time, "size": size, "x": 0.0, "y": 0.0, "z": 1.0, "yaw": 0.0}


@pytest.fixture(scope="module")
def default_circle():
    import warnings

    import quadcruise as qc

    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        return qc.fly("circle", "nlpd")


def test_steady_tracking_of_the_default_circle(default_circle):
    res = default_circle
    row = res.metrics().iloc[0]
    assert row["max_error_m"] == pytest.approx(2.0) and row["rmse_m"] > 0.4  # the start offset dominates
    # independently, written out sample by sample: the 3-D error's level over the last quarter,
    # the last exit above the 5 % line over it, the steady window the last half of the flight
    t, pos, ref = res.t, res.states[0, :, :3], res.references[0, :, :3]
    err = [float(np.sqrt(sum((pos[k, a] - ref[k, a]) ** 2 for a in range(3)))) for k in range(t.size)]
    level = max(e for tk, e in zip(t, err, strict=False) if tk >= 15.0)
    line = level + 0.05 * (err[0] - level)
    k = max(i for i, e in enumerate(err) if e > line)
    t_from = t[k] + (line - err[k]) / (err[k + 1] - err[k]) * (t[k + 1] - t[k])
    assert row["axis"] == "xyz" and row["settling_time_5pct_s"] == pytest.approx(t_from, abs=1e-9)
    tw = [tk for tk in t if tk >= 10.0]
    ew = [e for tk, e in zip(t, err, strict=False) if tk >= 10.0]
    area = sum(0.5 * (ew[i] ** 2 + ew[i + 1] ** 2) * (tw[i + 1] - tw[i]) for i in range(len(tw) - 1))
    assert row["steady_rmse_m"] == pytest.approx(np.sqrt(area / 10.0), rel=1e-9)
    assert row["steady_max_error_m"] == pytest.approx(max(ew), rel=1e-12)
    # centimetres, far below the whole flight's RMSE; no overshoot, so no peak time
    assert 0.01 < row["steady_rmse_m"] < 0.1 and row["steady_rmse_m"] < row["rmse_m"] / 5
    assert row["overshoot_pct"] == 0.0 and np.isnan(row["peak_time_s"])


def test_steady_metrics_are_undefined_when_the_transient_never_settles():
    from quadcruise.metrics import flight_metrics
    from quadcruise.metrics.tables import vehicle_metrics_text

    t = np.linspace(0.0, 10.0, 1001)
    pos = np.zeros((3, t.size, 3))
    pos[0, :, 0] = np.exp(-t)  # settles
    pos[1, :, 0] = 0.5 + 0.5 * np.exp(-t)  # halves and stays: never within 5 %
    pos[2, :, 1] = 0.005 * np.sin(t)  # no transient (below 1 cm): all steady
    table = flight_metrics(as_result(t, pos, np.zeros_like(pos)))
    assert np.isnan(table["steady_rmse_m"][1]) and np.isnan(table["steady_max_error_m"][1])
    assert table["steady_rmse_m"][0] < 0.05 and table["steady_max_error_m"][0] == pytest.approx(0.05, rel=1e-9)
    assert pd.isna(table["axis"][2])
    assert table["steady_rmse_m"][2] == table["rmse_m"][2] and table["steady_max_error_m"][2] == table["max_error_m"][2]
    text = vehicle_metrics_text(table).splitlines()
    steady = next(line for line in text if line.startswith("steady_rmse_m"))
    assert "did not settle" in steady and steady.count("did not settle") == 1


def test_peak_time_of_a_second_order_step_matches_the_closed_form():
    from quadcruise.metrics import flight_metrics, flight_metrics_batch

    zeta, wn, t_step = 0.4, 3.0, 1.0
    t = np.linspace(0.0, 12.0, 12001)
    pos = np.zeros((1, t.size, 3))
    pos[0, :, 2] = 1.0
    pos[0, :, 0] = np.where(t > t_step, second_order(np.maximum(t - t_step, 0.0), zeta, wn), 0.0)
    ref = pos.copy()
    ref[0, :, 0] = np.where(t >= t_step, 1.0, 0.0)
    res = as_result(t, pos, ref, meta={"mission": step_mission(t_step)})
    row = flight_metrics(res).iloc[0]
    assert row["peak_time_s"] == pytest.approx(np.pi / (wn * np.sqrt(1 - zeta**2)), abs=1e-3)
    batch = flight_metrics_batch(t, pos, ref, np.zeros((1, t.size, 4)), mission=step_mission(t_step))
    assert batch["peak_time_s"][0] == row["peak_time_s"]


def test_rise_and_settling_conventions_against_python_control():
    from quadcruise.metrics import flight_metrics

    t = np.linspace(0.0, 10.0, 10001)
    y = np.asarray(control.step_response(G, T=t).outputs)
    pos = np.zeros((1, t.size, 3))
    pos[0, :, 0], pos[0, :, 2] = y, 1.0
    ref = pos.copy()
    ref[0, :, 0] = 1.0
    res = as_result(t, pos, ref, meta={"mission": step_mission(0.0)})
    ours = flight_metrics(res, rise=(0.0, 1.0), settle_bands=(0.02, 0.03)).iloc[0]
    theirs = control.step_info(y, T=t, yfinal=1.0, RiseTimeLimits=(0.0, 1.0), SettlingTimeThreshold=0.03)
    assert ours["rise_time_s"] == pytest.approx(theirs["RiseTime"], abs=1e-3)  # within a sample
    assert ours["settling_time_3pct_s"] == pytest.approx(theirs["SettlingTime"], abs=1e-3)
    default = flight_metrics(res).iloc[0]
    theirs = control.step_info(y, T=t, yfinal=1.0, SettlingTimeThreshold=0.05)
    assert default["rise_time_s"] == pytest.approx(theirs["RiseTime"], abs=1e-3)
    assert default["settling_time_5pct_s"] == pytest.approx(theirs["SettlingTime"], abs=1e-3)
    assert ours["rise_time_s"] > default["rise_time_s"] + 0.1  # 0-100 % is longer
    # the columns say which band they hold, and the table records its conventions
    table = flight_metrics(res, rise="0-100", settle_bands=(0.01, 0.03))
    assert "settling_time_3pct_s" in table.columns and "settling_time_5pct_s" not in table.columns
    conv = table.attrs["conventions"]
    assert conv["rise"] == [0.0, 1.0] and conv["settle_bands"] == [0.01, 0.03] and conv["steady_band"] == 0.05
    assert conv["settling_columns"] == {"settling_time_s": 0.01, "settling_time_3pct_s": 0.03}
    # the steady window does not move with the bands shown
    assert table["steady_rmse_m"][0] == default["steady_rmse_m"]
    with pytest.raises(InputError, match="settle_bands"):
        flight_metrics(res, settle_bands=(0.02, 1.5))
    with pytest.raises(InputError, match="rise"):
        flight_metrics(res, rise="5-95")


def test_effort_is_measured_about_hover():
    import warnings

    import quadcruise as qc

    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        hovers = {
            c: qc.fly("hover", c, duration=2.0, vehicle=qc.Vehicle(m=[2.5, 3.5, 4.5]))
            for c in ("nlpd", "gonzalez", "se3", "cascade")
        }
        circles = qc.compare("circle", duration=6.0, log_every=10).table()
    for name, res in hovers.items():
        effort = res.metrics()["effort"].to_numpy()
        assert np.all(np.abs(effort) < 1e-9), name  # each vehicle about its own hover duty
    # from zero duty, a hover of 2 s would read 4 (m g / 4 K)^2 2 s: about 0.04 s
    assert 4 * qc.Vehicle.paper().hover_duty ** 2 * 2.0 > 0.03
    # controllers that fly differently spend differently
    assert circles["effort"].nunique() == len(circles) and (circles["effort"] > 0).all()
    # a result that records no vehicle has no hover duty to measure about
    t = np.linspace(0.0, 1.0, 11)
    assert np.isnan(
        metrics.flight_metrics(as_result(t, np.zeros((1, 11, 3)), np.zeros((1, 11, 3)), meta={}))["effort"][0]
    )


def test_batch_agrees_with_flight_metrics_at_the_edges():
    from quadcruise.metrics import flight_metrics, flight_metrics_batch, hover_duties

    t = np.linspace(0.0, 8.0, 801)
    n = 5
    rng = np.random.default_rng(4)
    pos = np.zeros((n, t.size, 3))
    pos[0, :, 0] = 2.0 * np.exp(-t) * np.cos(3 * t)  # settles, with overshoot
    pos[1, :, 1] = 0.4 + 1.6 * np.exp(-t)  # never settles within 5 %
    pos[2, :, 2] = 0.004 * np.sin(t)  # no transient
    pos[3, :, 0] = 1.0 * np.exp(-t)  # stops early
    pos[3, 400:] = np.nan
    pos[4, :, 0] = 1.5 * np.exp(-2 * t) + 0.01 * rng.normal(size=t.size)  # noisy, settles
    ref = np.zeros_like(pos)
    duties = 0.2 + 0.01 * rng.normal(size=(n, t.size, 4))
    meta = {"vehicle": {"m": [1.0, 1.2, 1.4, 1.6, 1.8], "g": 9.81, "K": 30.0}}
    res = as_result(t, pos, ref, duties=duties, status=[0, 0, 0, 2, 0], meta=meta)
    for kw in ({}, {"rise": (0.0, 1.0), "settle_bands": (0.01, 0.03)}, {"transient_until": 5.0}):
        slow = flight_metrics(res, **kw)
        bands = kw.get("settle_bands", (0.02, 0.05))
        live = [0, 1, 2, 4]
        fast = flight_metrics_batch(
            t,
            pos[live],
            ref[live],
            duties[live],
            bands=bands,
            rise=kw.get("rise", (0.1, 0.9)),
            transient_until=kw.get("transient_until"),
            hover_duty=hover_duties(meta, n)[live],
        )
        columns = [c for c in slow.columns if c.startswith("settling")]
        for key in (
            "rmse_m",
            "max_error_m",
            "steady_rmse_m",
            "steady_max_error_m",
            "rise_time_s",
            "overshoot_pct",
            "peak_time_s",
            "effort",
            *columns,
        ):
            got = fast["settling_s"][columns.index(key)] if key in columns else fast[key]
            np.testing.assert_allclose(
                got, slow[key].to_numpy(dtype=float)[live], rtol=1e-12, atol=1e-15, err_msg=f"{kw} {key}"
            )
        assert np.isnan(fast["steady_rmse_m"][1]) and fast["transient_axis"][2] == -1
        assert slow[["steady_rmse_m", "peak_time_s", "effort"]].iloc[3].isna().all()  # stopped early


def test_window_errors_batch_matches_tracking_errors():
    from quadcruise.metrics.batch import window_errors_batch

    rng = np.random.default_rng(5)
    t = np.cumsum(rng.uniform(0.005, 0.015, 200))
    pos, ref = rng.normal(size=(4, 200, 3)), rng.normal(size=(200, 3))
    t_from = np.array([t[0], t[10] + 1e-4, t[-1], np.nan])
    got = window_errors_batch(t, pos, np.broadcast_to(ref, pos.shape), t_from)
    for i in range(2):
        one = tracking_errors(t, pos[i], ref, t_from=t_from[i])
        assert got["rmse"][i] == pytest.approx(float(one["rmse"]), rel=1e-12)
        assert got["max_error"][i] == pytest.approx(float(one["max_error"]), rel=1e-12)
    assert got["rmse"][2] == got["max_error"][2] == pytest.approx(np.linalg.norm(pos[2, -1] - ref[-1]))
    assert np.isnan(got["rmse"][3]) and np.isnan(got["max_error"][3])
