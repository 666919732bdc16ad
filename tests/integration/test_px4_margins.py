"""``analyze --controller px4``: the px4 loops' margins (quadcruise.workflows.px4margins) checked
against independent paths: the compiled px4 controller flying the engine's plant with a sine
injected (the rate loops, broken at the torque) or in its setpoint (the velocity and position
closed loops), and the attitude loop's frequency response composed from scipy's transfer
functions and the decimation (alias) sum instead of the state-space lifting."""

from __future__ import annotations

import dataclasses
import json
import math

import control
import numpy as np
import pytest
import scipy.signal

from quadcruise import layout as L
from quadcruise.control.px4 import Px4
from quadcruise.control.px4filters import alpha_of, lpf2p_coefficients
from quadcruise.control.px4kernel import px4_controller
from quadcruise.model.actuators import duties
from quadcruise.model.equivalent import paper_equivalent
from quadcruise.sim.engine import WORK_ROWS, rk4_step
from quadcruise.workflows.px4margins import px4_margins, rotor_gains
from quadcruise.workflows.rotor_fly import flight_setup
from quadcruise.workflows.scenario_vehicle import vehicle_preset

DT = 1e-3


LOG = "tests/data/px4/sample_px4_events.ulg"


def _iris_with(source, **values):
    """The Iris and px4 by name (``designed``) or with the SITL log's parameters (``log``: its
    CA_ROTOR*, THR_MDL_FAC 0 on a thrust per command u^2, MPC_THR_HOVER 0.5), ``values`` set over them."""
    v = vehicle_preset("iris")
    px4 = flight_setup(v, None, "px4")[1] if source == "designed" else Px4.from_params(LOG, vehicle=v)
    return v, dataclasses.replace(px4, params=px4.params.with_values(**values)) if values else px4


def _hover(vp):
    x = np.zeros(L.STATE_SIZE)
    x[L.Z], x[L.F1 : L.F1 + 4] = 1.0, vp[L.P_M] * vp[L.P_G] / 4.0
    ref = np.zeros(len(L.REF_NAMES))
    ref[L.REF_Z] = 1.0
    ext = np.zeros(L.EXT_SIZE)
    ext[L.EXT_E1 : L.EXT_E1 + 4] = 1.0
    return x, ref, ext, np.empty((WORK_ROWS, L.STATE_SIZE))


def _phasor(signal, t, w):
    s = np.asarray(signal) - np.mean(signal)
    return np.sum(s * np.exp(-1j * w * t))


def _injected_loop(controller, vehicle, w, axis, settle=3.0, periods=6):
    """The loop transfer at the plant input measured on the compiled controller and the engine's
    RK4 plant: a sine d added to the controller's moment U2..U4 (held over each period), the
    controller's own moment c = -L/(1 + L) d, so L = -r / (1 + r) with r = c / d."""
    vp = np.ascontiguousarray(paper_equivalent(vehicle).rows()[0])
    gains, mem, cmd = controller.gains(), controller.memory(), np.zeros(L.CMD_SIZE)
    x, ref, ext, work = _hover(vp)
    amp = 5e-4 * vp[L.P_M] * vp[L.P_G]
    n_set, n_meas = int(round(settle / DT)), int(round(periods * 2 * math.pi / w / DT))
    d_log, c_log = [], []
    for k in range(n_set + n_meas):
        px4_controller(k * DT, DT, x, ref, vp, gains, mem, cmd)
        U = [cmd[L.CMD_THRUST], cmd[L.CMD_TAU_PHI], cmd[L.CMD_TAU_THETA], cmd[L.CMD_TAU_PSI]]
        d = amp * math.sin(w * k * DT)
        c = U[1 + axis]
        U[1 + axis] += d
        rk4_step(x, np.ascontiguousarray(duties(*U, vp[L.P_D], vp[L.P_K])), vp, ext, False, DT, work, True)
        if k >= n_set:
            d_log.append(d)
            c_log.append(c)
    t = (np.arange(n_meas) + n_set) * DT
    r = _phasor(c_log, t, w) / _phasor(d_log, t, w)
    return -r / (1.0 + r)


def _closed_loop(controller, vehicle, w, ref_col, out_col, settle=8.0, periods=3, tp=0.01, amp=0.02):
    """The closed loop from a setpoint to its output measured on the compiled controller and the
    engine's plant: the mission's reference moved by a sine of ``amp`` at the position loop's instants."""
    vp = np.ascontiguousarray(paper_equivalent(vehicle).rows()[0])
    gains, mem, cmd = controller.gains(), controller.memory(), np.zeros(L.CMD_SIZE)
    x, ref, ext, work = _hover(vp)
    base = ref[ref_col]
    n_set, n_meas, steps = int(round(settle / tp)), int(round(periods * 2 * math.pi / w / tp)), int(round(tp / DT))
    s_log, y_log = [], []
    for j in range(n_set + n_meas):
        s = amp * math.sin(w * j * tp)
        ref[ref_col] = base + s
        if j >= n_set:
            s_log.append(s)
            y_log.append(x[out_col])
        for i in range(steps):
            px4_controller(j * tp + i * DT, DT, x, ref, vp, gains, mem, cmd)
            rk4_step(x, np.ascontiguousarray(cmd[:4]), vp, ext, False, DT, work, True)
    t = (np.arange(n_meas) + n_set) * tp
    return _phasor(y_log, t, w) / _phasor(s_log, t, w)


def _at(sys, w):
    return complex(np.asarray(control.frequency_response(sys, [w]).complex).ravel()[0])


@pytest.mark.slow
@pytest.mark.parametrize(
    ("source", "axis", "name"),
    [
        ("designed", 0, "roll"),
        ("designed", 1, "pitch"),
        ("designed", 2, "yaw"),
        ("log", 0, "roll"),
        ("log", 1, "pitch"),
    ],
)
def test_rate_loop_is_the_compiled_controllers_loop_at_the_torque(source, axis, name):
    # the attitude loop open (P = 0): the rate loop alone, as the model breaks it; the log's
    # parameters have their own rotor mix and thrust model (the torque's slope at hover)
    vehicle, px4 = _iris_with(source, MC_ROLL_P=0.0, MC_PITCH_P=0.0, MC_YAW_P=0.0)
    model = px4_margins(px4, vehicle, dt=DT)
    m = model.margins("rate", name)
    wc = m["gain_crossover"]
    for w in (0.5 * wc, wc, 2.0 * wc):
        measured, predicted = _injected_loop(px4, vehicle, w, axis, settle=5.0), _at(model.loops[("rate", name)].L, w)
        assert abs(measured / predicted - 1.0) < 2e-3, (w, measured, predicted)
    at_crossover = _injected_loop(px4, vehicle, wc, axis, settle=5.0)
    assert abs(abs(at_crossover) - 1.0) < 2e-3
    assert math.degrees(np.angle(at_crossover)) + 180.0 == pytest.approx(m["phase_margin"], abs=0.3)


_ASYMMETRIC = {"MC_ROLL_P": 9.0, "MC_PITCH_P": 3.0}  # x (through the pitch) and y (the roll) far apart


@pytest.mark.slow
@pytest.mark.parametrize(
    ("source", "loop", "axis", "ref_col", "out_col", "values", "settle", "amp"),
    [
        # horizontally 0.5 m, 0.3 m/s: tilts well above the 3.45e-4 rad that PX4's limitTilt turns north
        ("designed", "position", "x", L.REF_X, L.X, {}, 8.0, 0.5),
        ("designed", "position", "z", L.REF_Z, L.Z, {}, 8.0, 0.02),
        ("designed", "velocity", "x", L.REF_VX, L.VX, {"MPC_XY_P": 0.0}, 8.0, 0.3),  # v_sp: the mission's velocity
        ("designed", "velocity", "z", L.REF_VZ, L.VZ, {"MPC_Z_P": 0.0}, 8.0, 0.02),
        ("log", "position", "x", L.REF_X, L.X, _ASYMMETRIC, 8.0, 0.5),
        ("log", "position", "y", L.REF_Y, L.Y, _ASYMMETRIC, 8.0, 0.5),
        # the log's hover 0.5 against the Iris's 0.73: the vertical integral takes ~20 s to hold it
        ("log", "velocity", "z", L.REF_VZ, L.VZ, {"MPC_Z_P": 0.0}, 30.0, 0.02),
    ],
)
def test_outer_closed_loops_are_the_compiled_controllers(source, loop, axis, ref_col, out_col, values, settle, amp):
    vehicle, px4 = _iris_with(source, **values)
    model = px4_margins(px4, vehicle, dt=DT)
    wc = model.margins(loop, axis)["gain_crossover"]
    apart = 0.0
    for w in (0.5 * wc, wc, 2.0 * wc):
        measured = _closed_loop(px4, vehicle, w, ref_col, out_col, settle=settle, amp=amp)
        predicted = _at(model.loops[(loop, axis)].T, w)
        assert abs(measured / predicted - 1.0) < 0.015, (w, measured, predicted)
        assert abs(math.degrees(np.angle(measured / predicted))) < 0.5
        if values is _ASYMMETRIC:
            apart = max(apart, abs(_at(model.loops[(loop, "y" if axis == "x" else "x")].T, w) / measured - 1.0))
    assert values is not _ASYMMETRIC or apart > 0.3  # the other horizontal axis's loop is not this one
    # the loop itself, L = T / (1 - T) for the position loop (unity feedback), crosses 1 where the model says
    if loop == "position":
        T = _closed_loop(px4, vehicle, wc, ref_col, out_col, settle=settle, amp=amp)
        assert abs(abs(T / (1.0 - T)) - 1.0) < 0.02


def test_the_horizontal_loops_are_linear_only_above_px4s_smallest_tilt():
    """PX4's ControlMath::limitTilt turns a tilt whose rejection is under FLT_EPSILON (squared norm;
    3.45e-4 rad) about the x axis, north: a 2 cm sine in y at half the crossover commands tilts mostly
    below it and misses the linear loop by percents, where 0.5 m meets it."""
    from quadcruise.control.px4math import limit_tilt

    east = limit_tilt((0.0, -3e-4, math.sqrt(1.0 - 9e-8)), (0.0, 0.0, 1.0), 0.7)
    assert east[0] == pytest.approx(3e-4, rel=1e-6) and abs(east[1]) < 1e-3 * east[0]  # turned north, angle kept
    vehicle, px4 = _iris_with("designed")
    model = px4_margins(px4, vehicle, dt=DT)
    w = 0.5 * model.margins("position", "y")["gain_crossover"]
    predicted = _at(model.loops[("position", "y")].T, w)
    small = _closed_loop(px4, vehicle, w, L.REF_Y, L.Y, amp=0.02)
    large = _closed_loop(px4, vehicle, w, L.REF_Y, L.Y, amp=0.5)
    assert abs(small / predicted - 1.0) > 0.02 and abs(large / predicted - 1.0) < 0.005


def _attitude_by_transfer_functions(px4, vehicle, a, w):
    """The attitude loop broken at the rate setpoint, from scipy's transfer functions: the rate
    loop closed at the gyro rate (z^-1 polynomials of PX4's filters and PID, the plant sampled by
    scipy's zero-order hold), then held over N periods and sampled every N (the decimation sum)."""
    p, vp = px4.params, np.asarray(paper_equivalent(vehicle).rows()[0])
    g = px4.loop_gains(paper_equivalent(vehicle))
    from quadcruise.control.px4loops import G_ATT_P, G_RATE_D, G_RATE_FF, G_RATE_I, G_RATE_P

    kp, ki, kd, ff, P = (g[o + a] for o in (G_RATE_P, G_RATE_I, G_RATE_D, G_RATE_FF, G_ATT_P))
    k_tau, J, wm = rotor_gains(px4, paper_equivalent(vehicle))["torque"][a], vp[L.P_JXX + a], vp[L.P_OMEGA]
    b0, b1, b2, a1, a2 = lpf2p_coefficients(1.0 / DT, p["IMU_GYRO_CUTOFF"])
    al = alpha_of(1.0 / DT, p["IMU_DGYRO_CUTOFF"])
    zoh = [scipy.signal.cont2discrete(([k_tau * wm / J], np.polymul([1.0, wm], [1.0] + [0.0] * n)), DT) for n in (1, 2)]
    N = max(1, round(1.0 / (p["IMU_INTEG_RATE"] * DT)))

    def fast(z):
        zi = 1.0 / z
        lpf = (b0 + b1 * zi + b2 * zi**2) / (1.0 + a1 * zi + a2 * zi**2)
        acc = (al / DT) * (1.0 - zi) / (1.0 - (1.0 - al) * zi)
        integ = ki * DT * zi / (1.0 - zi)
        G_rate, G_angle = (np.polyval(num.ravel(), z) / np.polyval(den, z) for num, den, _ in zoh)
        u_per_r = (kp + integ + ff) / (1.0 + G_rate * ((kp + integ) * lpf + kd * acc))
        hold = sum(zi**i for i in range(N))
        return G_angle * u_per_r * hold

    omega = w * N * DT
    return P * sum(fast(np.exp(1j * (omega - 2.0 * math.pi * k) / N)) for k in range(N)) / N


@pytest.mark.parametrize("vehicle_name", ["iris", "paper"])
@pytest.mark.parametrize(("a", "axis"), [(0, "roll"), (2, "yaw")])
def test_attitude_loop_is_the_decimated_rate_loop_of_scipys_transfer_functions(vehicle_name, a, axis):
    vehicle = vehicle_preset(vehicle_name)
    px4 = flight_setup(vehicle, None, "px4")[1] if vehicle_name == "iris" else Px4()
    model = px4_margins(px4, vehicle, dt=DT)
    wc = model.margins("attitude", axis)["gain_crossover"]
    for w in (0.2 * wc, wc, 3.0 * wc):
        ours, theirs = _at(model.loops[("attitude", axis)].L, w), _attitude_by_transfer_functions(px4, vehicle, a, w)
        assert abs(ours / theirs - 1.0) < 1e-6, (w, ours, theirs)


def test_a_gain_past_what_the_loop_bears_is_flagged_and_the_default_passes():
    px4 = Px4()
    default = px4_margins(px4, "paper").summary()
    assert default["meets_margins"]
    assert all(e["meets_margins"] and e["stable"] for loops in default["loops"].values() for e in loops.values())
    # PX4's largest roll gain (12 1/s) on the paper's slow rotors: the roll attitude loop rings
    hot = px4_margins(dataclasses.replace(px4, params=px4.params.with_values(MC_ROLL_P=12.0)), "paper").summary()
    roll, pitch = hot["loops"]["attitude"]["roll"], hot["loops"]["attitude"]["pitch"]
    assert not hot["meets_margins"] and not roll["meets_margins"] and roll["stable"]
    assert roll["phase_margin_deg"] < 30.0 and roll["gain_margin_up_db"] < 6.0
    assert pitch == default["loops"]["attitude"]["pitch"]  # the pitch loop is the default's
    # the gain margin is the factor that destabilises: the loop scaled by it sits on the unit circle
    L = px4_margins(dataclasses.replace(px4, params=px4.params.with_values(MC_ROLL_P=12.0)), "paper").loops
    L = L[("attitude", "roll")].L
    for factor, stable in ((0.97, True), (1.03, False)):
        k = factor * 10 ** (roll["gain_margin_up_db"] / 20.0)
        poles = control.feedback(k * L, 1).poles()
        poles = poles[np.abs(poles - 1.0) > 1e-9]  # the angle's integrals (velocity, position): outside the loop
        assert bool(np.max(np.abs(poles)) < 1.0) is stable


def test_a_vehicle_too_slow_for_the_gains_is_unstable_in_the_summary():
    import quadcruise as qc

    slow = dataclasses.replace(qc.Vehicle.paper(), omega=3.0)  # rotors 5 times slower than the design's
    s = px4_margins(Px4(), slow).summary()
    assert not s["meets_margins"]
    assert not s["loops"]["attitude"]["roll"]["stable"]
    assert "UNSTABLE" in str(s)


def test_rise_time_and_bandwidth_agree_with_the_step_and_the_gain_of_the_closed_loop():
    from quadcruise.workflows.px4margins_result import bandwidth, rise_time

    model = px4_margins(Px4(), "paper")
    T = model.loops[("rate", "roll")].T
    w = bandwidth(T)
    assert abs(_at(T, w)) == pytest.approx(abs(_at(T, 1e-4)) / math.sqrt(2.0), rel=1e-3)
    t, y = control.step_response(T, T=np.arange(0.0, 3.0, DT))
    y = np.asarray(y).ravel() / np.asarray(y).ravel()[-1]
    assert rise_time(T) == pytest.approx(t[np.argmax(y >= 0.9)] - t[np.argmax(y >= 0.1)], abs=1.5 * DT)


def test_analyze_px4_cli_prints_and_writes_the_loops(tmp_path):
    from click.testing import CliRunner

    from quadcruise.cli.main import main

    out = tmp_path / "a"
    res = CliRunner().invoke(main, ["analyze", "--controller", "px4", "--vehicle", "iris", "--out", str(out)])
    assert res.exit_code == 0, res.output
    assert "rate      roll" in res.output and "every loop meets its margins" in res.output
    data = json.loads((out / "analysis.json").read_text())
    api = px4_margins("px4", "iris").summary()
    assert data["loops"]["rate"]["roll"]["phase_margin_deg"] == pytest.approx(
        api["loops"]["rate"]["roll"]["phase_margin_deg"], rel=1e-12
    )
    assert "MC_AT_RISE_TIME" in data["targets"]["rate_rise_time_s"]["source"]
    assert (out / "bode.png").stat().st_size > 10_000 and (out / "quadcruise.json").exists()


def test_analyze_params_reads_the_logs_parameters(tmp_path):
    from click.testing import CliRunner

    from quadcruise.cli.main import main

    log = LOG
    res = CliRunner().invoke(main, ["analyze", "--vehicle", "iris", "--params", log])
    assert res.exit_code == 0, res.output
    assert f"px4 ({log}) about hover" in res.stdout
    assert res.stderr.count("not used by the px4 controller") == 1
    api = px4_margins(Px4.from_params(log, vehicle=vehicle_preset("iris")), "iris").summary()
    line = next(ln for ln in res.stdout.splitlines() if ln.startswith("rate      pitch"))
    assert f"{api['loops']['rate']['pitch']['phase_margin_deg']:.1f}" in line


@pytest.mark.parametrize(
    ("text", "args", "message"),
    [
        ("1\t1\tMC_ROLL_P\t13\t9\n", [], "bad.params, line 1: MC_ROLL_P = 13 1/s is outside PX4 v1.15's range"),
        ("1\t1\tMC_ROLL_P\tfast\t9\n", [], "bad.params, line 1"),
        ("1\t1\tMC_ROLL_P\t7\t9\n", ["--controller", "nlpd"], "--controller nlpd has none"),
        ("1\t1\tMC_ROLL_P\t7\t9\n", ["--poles", "-1,-2"], "--poles"),
        ("1\t1\tMC_ROLL_P\t7\t9\n", ["--dt", "0.1"], "--dt 0.1"),
    ],
)
def test_analyze_params_refuses_bad_input_in_one_line(tmp_path, text, args, message):
    from click.testing import CliRunner

    from quadcruise.cli.main import main

    bad = tmp_path / "bad.params"
    bad.write_text(text)
    res = CliRunner().invoke(main, ["analyze", "--vehicle", "iris", "--params", str(bad), *args])
    assert res.exit_code == 2 and message in res.stderr and res.stderr.count("\n") == 1, res.stderr


def test_analyze_refuses_an_unknown_suffix_and_poles_for_px4(tmp_path):
    from click.testing import CliRunner

    from quadcruise.cli.main import main

    bad = tmp_path / "x.json"
    bad.write_text("{}")
    res = CliRunner().invoke(main, ["analyze", "--params", str(bad)])
    assert res.exit_code == 2 and "x.json" in res.stderr and res.stderr.count("\n") == 1, res.stderr
    res = CliRunner().invoke(main, ["analyze", "--controller", "px4", "--poles", "-1,-2"])
    assert res.exit_code == 2 and "--poles" in res.stderr and res.stderr.count("\n") == 1, res.stderr


def test_linearize_refuses_the_multi_rate_px4_controller():
    from quadcruise.errors import InputError
    from quadcruise.workflows.analysis import linearize

    with pytest.raises(InputError, match="px4_margins"):
        linearize("px4")  # one period at t = 0 runs only the rate loop: an answer that would look right


@pytest.mark.parametrize("controller", ["px4", "nlpd"])
def test_analyze_exits_1_on_an_unstable_loop_and_0_on_a_stable_one(controller):
    """A closed loop that could never have flown says so in the exit status as well as the table."""
    from click.testing import CliRunner

    from quadcruise.cli.main import main

    slow = "omega=3.0" if controller == "px4" else "omega=0.5"  # rotors far slower than the design's
    res = CliRunner().invoke(main, ["analyze", "--controller", controller, "--vehicle", slow])
    assert res.exit_code == 1 and "UNSTABLE" in res.output, res.output
    res = CliRunner().invoke(main, ["analyze", "--controller", controller])
    assert res.exit_code == 0 and "UNSTABLE" not in res.output, res.output
