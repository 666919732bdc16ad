"""The ``px4`` controller (PX4 v1.15's loops as an engine controller): it flies every preset's
step and circle by name and the Iris with the SITL log's own parameters; its output, period by
period, is PX4's pieces composed here independently (scipy's Butterworth for the gyro filter,
px4loops' rate loop, px4allocation's allocate, the vehicle's own allocation matrix); the
vehicle-dependent design written back as PX4 parameters flies the same flight; bad parameter
geometry is refused in one line."""

from __future__ import annotations

import dataclasses
import math
import warnings
from pathlib import Path

import numpy as np
import pytest
from scipy import signal

import quadcruise as qc
from quadcruise import layout as L
from quadcruise.control.px4 import Px4, px4_controller
from quadcruise.control.px4allocation import allocate, mix_matrix
from quadcruise.control.px4loops import G_THR_HOVER, ONE_G, rate_control
from quadcruise.control.registry import rotor_gains
from quadcruise.errors import InputError
from quadcruise.model.allocation import allocation_matrix
from quadcruise.model.equivalent import paper_equivalent
from quadcruise.model.rotor_vehicle import RotorVehicle

LOG = Path(__file__).parents[1] / "data" / "px4" / "sample_px4_events.ulg"
PRESETS = ("iris", "crazyflie", "hummingbird", "qball-x4", "paper")


@pytest.fixture(autouse=True)
def _quiet():
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        yield


@pytest.mark.parametrize("vehicle", PRESETS)
@pytest.mark.parametrize("mission", ["step", "circle"])
def test_px4_flies_every_presets_step_and_circle(vehicle, mission):
    res = qc.fly(mission, "px4", vehicle=vehicle, duration=10.0)
    assert res.status_text() == "finished", res.status_text()
    ref_end = res.references[0][-1, :3] if res.references.ndim == 3 else res.references[-1, :3]
    assert np.abs(res.final_state[0, :3] - ref_end).max() < 0.2  # the circle's lag at its end: 0.07-0.13 m


def test_px4_flies_the_iris_with_the_sitl_logs_parameters():
    """PX4's parameters as the log has them (CA_ROTOR* of the SITL Iris, THR_MDL_FAC 0,
    MPC_THR_HOVER 0.5): no hover-thrust estimator, so the Iris (u^2 thrust: hover at 0.73)
    sags at first, then the velocity integral holds it."""
    v = RotorVehicle.preset("iris")
    c = Px4.from_params(LOG, vehicle=v)
    assert c.params["CA_ROTOR_COUNT"] == 4 and c.params["MC_ROLLRATE_K"] == pytest.approx(1.05)
    assert len(c.params.unused) > 500  # listed, not dropped
    for mission in ("step", "circle"):
        res = qc.fly(mission, c, vehicle=v, duration=10.0)
        assert res.status_text() == "finished"
        z = res.states[0][:, L.Z]
        assert z.min() > 0.2 and abs(z[-1] - 1.0) < 0.05


def _plus_wrench(cmd):
    return cmd[L.CMD_THRUST], cmd[L.CMD_TAU_PHI], cmd[L.CMD_TAU_THETA], cmd[L.CMD_TAU_PSI]


def test_the_controllers_rate_loop_is_px4loops_on_the_same_inputs():
    """60 periods at 1 kHz, level on the reference (so the position and attitude loops ask for
    zero rates), body rates varying: each period's wrench equals PX4's pieces composed here,
    with the gyro filter from scipy and the vehicle's own rotor geometry."""
    v = RotorVehicle.preset("iris")
    eq = paper_equivalent(v)
    c = Px4.from_params(LOG, vehicle=v)
    vp, G, mem, cmd = eq.rows()[0], c.gains(), c.memory(), np.zeros(L.CMD_SIZE)
    g = c.loop_gains(eq)
    dt, n = 0.001, 60
    t = np.arange(n) * dt
    flu = np.column_stack([0.3 * np.sin(40 * t), -0.2 * np.cos(25 * t), 0.1 * np.sin(10 * t) + 0.05])
    frd = flu * [1.0, -1.0, -1.0]
    # the gyro filter: PX4's 2-pole Butterworth is scipy's butter at the same rate, settled at the first sample
    b, a = signal.butter(2, c.params["IMU_GYRO_CUTOFF"], fs=1.0 / dt)
    filtered = np.column_stack(
        [signal.lfilter(b, a, frd[:, k], zi=signal.lfilter_zi(b, a) * frd[0, k])[0] for k in range(3)]
    )
    alpha = dt / (dt + 1.0 / (2 * math.pi * c.params["IMU_DGYRO_CUTOFF"]))
    accel = np.zeros((n, 3))
    for k in range(1, n):
        accel[k] = accel[k - 1] + alpha * ((frd[k] - frd[k - 1]) / dt - accel[k - 1])
    eff, _ = c.geometry()
    mix, _ = mix_matrix(eff)
    B = allocation_matrix(v)
    full = v.kf * v.w_max**2
    integ, sat = (0.0, 0.0, 0.0), (False, False, False)
    hover = c.params["MPC_THR_HOVER"]
    assert g[G_THR_HOVER] == hover
    for k in range(n):
        x = np.zeros(L.STATE_SIZE)
        x[L.Z], x[L.P], x[L.Q], x[L.R] = 1.0, *flu[k]
        ref = np.zeros(L.REF_SIZE)
        ref[L.REF_Z] = 1.0
        px4_controller(t[k], dt, x, ref, vp, G, mem, cmd)
        torque, integ = rate_control(
            tuple(filtered[k]), (0.0, 0.0, 0.0), tuple(accel[k]), dt, False, g, sat, sat, integ
        )
        # the position loop on the reference: the hover thrust (level, no integral yet)
        sp = np.clip(allocate(mix, np.array([*torque, 0.0, 0.0, -hover]), 0, np.zeros(4), np.ones(4)), 0, 1)
        f = full * sp**2 if c.params["THR_MDL_FAC"] == 0 else None  # THR_MDL_FAC 0: command = thrust; rotor thrust u^2
        T, mx, my, mz = B @ f
        got = _plus_wrench(cmd)
        assert got[0] == pytest.approx(T, rel=1e-9)
        assert got[1] == pytest.approx(mx / eq.l, abs=1e-9)
        assert got[2] == pytest.approx(my / eq.l, abs=1e-9)
        assert got[3] == pytest.approx(mz, abs=1e-9)
    assert abs(integ[0]) > 0.0  # the integral took part
    assert ONE_G > 9.8


def test_a_wrong_rate_gain_is_seen_by_that_comparison():
    """The other direction: twice MC_ROLLRATE_P changes the roll moment (so the comparison above can fail)."""
    v = RotorVehicle.preset("iris")
    eq = paper_equivalent(v)
    outs = []
    for p in (0.15, 0.3):
        c = Px4.from_params({"MC_ROLLRATE_P": p}, vehicle=v)
        x = np.zeros(L.STATE_SIZE)
        x[L.Z], x[L.P] = 1.0, 0.3
        ref = np.zeros(L.REF_SIZE)
        ref[L.REF_Z] = 1.0
        cmd = np.zeros(L.CMD_SIZE)
        px4_controller(0.0, 0.001, x, ref, eq.rows()[0], c.gains(), c.memory(), cmd)
        outs.append(cmd[L.CMD_TAU_PHI])
    assert outs[0] < 0.0 and outs[1] == pytest.approx(2 * outs[0], rel=1e-6)


def test_the_design_written_as_px4_parameters_flies_the_same_flight():
    v = RotorVehicle.preset("iris")
    eq = paper_equivalent(v)
    designed = dataclasses.replace(Px4(), **rotor_gains("px4", eq.omega))
    plain = designed.resolved(eq)
    assert not plain.hover_from_vehicle and plain.rate_bandwidth == 0.0
    assert plain.params["MC_ROLLRATE_K"] == 1.0 and 0.0 < plain.params["MC_ROLLRATE_P"] < 0.5
    a = qc.fly("step", designed, vehicle=v, duration=4.0)
    b = qc.fly("step", plain, vehicle=v, duration=4.0)
    np.testing.assert_allclose(a.states, b.states, rtol=0, atol=1e-12)


def test_a_geometry_that_is_not_the_vehicles_is_refused_in_one_line():
    v = RotorVehicle.preset("iris")
    with pytest.raises(InputError, match=r"CA_ROTOR_COUNT = 6, the vehicle has 4 rotors"):
        Px4.from_params({"CA_ROTOR_COUNT": 6}, vehicle=v)
    with pytest.raises(InputError, match=r"CA_ROTOR_COUNT = 6, no rotor layout given: PX4's quadrotor x has 4 \("):
        Px4.from_params({"CA_ROTOR_COUNT": 6})  # no vehicle: not "the vehicle has 4 rotors"
    swapped = {"CA_ROTOR_COUNT": 4}
    for i, (x, y, km) in enumerate([(1, -1, 0.05), (-1, -1, 0.05), (1, -1, -0.05), (-1, 1, -0.05)]):
        swapped.update({f"CA_ROTOR{i}_PX": x, f"CA_ROTOR{i}_PY": y, f"CA_ROTOR{i}_KM": km})
    with pytest.raises(InputError, match=r"CA_ROTOR0 .* is not the vehicle's rotor 1"):
        Px4.from_params(swapped, vehicle=v)
    with pytest.raises(InputError, match=r"MC_ROLL_P = 13"):
        Px4.from_params({"MC_ROLL_P": 13}, vehicle=v)


def test_a_hexarotors_geometry_with_a_rotor_on_an_axis_is_its_own():
    """A hexarotor x whose rotors 1 and 2 sit on the body's y axis: a .params file that writes
    their PX as -1e-8 (float noise, as a geometry computed from angles gives) names the same
    rotors as 0 does; a rotor truly on the other side is still refused."""
    import math

    angles, kms = (90, 270, 330, 150, 30, 210), (-0.05, 0.05, -0.05, 0.05, 0.05, -0.05)
    frd = [
        (0.25 * math.cos(math.radians(a)), 0.25 * math.sin(math.radians(a)), km)
        for a, km in zip(angles, kms, strict=True)
    ]
    rotors = tuple((round(px, 9), round(-py, 9), 0.02, -1.0 if km > 0 else 1.0) for px, py, km in frd)
    hexa = RotorVehicle.preset("iris").replace(m=2.2, rotors=rotors)

    def params(noise, flip=None):
        out = {"CA_ROTOR_COUNT": 6}
        for i, (px, py, km) in enumerate(frd):
            px = noise if abs(px) < 1e-9 else (-px if i == flip else px)
            out.update({f"CA_ROTOR{i}_PX": px, f"CA_ROTOR{i}_PY": py, f"CA_ROTOR{i}_KM": km})
        return out

    exact = Px4.from_params(params(0.0), vehicle=hexa).geometry()[0]
    for noise in (-1e-8, 1e-8):
        noisy = Px4.from_params(params(noise), vehicle=hexa).geometry()[0]
        np.testing.assert_allclose(noisy, exact, rtol=0, atol=1e-7)
    with pytest.raises(InputError, match=r"CA_ROTOR2 .* is not the vehicle's rotor 3"):
        Px4.from_params(params(0.0, flip=2), vehicle=hexa)


def test_a_2000_vehicle_batch_flies():
    res = qc.fly("hover", "px4", vehicle="iris", n=2000, duration=2.0)
    assert res.n == 2000 and all(s == 0 for s in np.asarray(res.status))


def test_fly_params_flies_the_logs_parameters_and_lists_the_unused_once(tmp_path):
    from click.testing import CliRunner

    from quadcruise.cli.main import main

    out = tmp_path / "f"
    res = CliRunner().invoke(
        main, ["fly", "step", "--controller", "px4", "--vehicle", "iris", "--params", str(LOG), "--out", str(out)]
    )
    assert res.exit_code == 0, res.output
    assert res.stderr.count("not used by the px4 controller") == 1 and "BAT1_CAPACITY" in res.stderr
    record = (out / "quadcruise.json").read_text()
    assert "--params" in record and '"MC_ROLLRATE_K": 1.0499999523162842' in record
    again = CliRunner().invoke(main, ["fly", str(out / "scenario.toml"), "--out", str(tmp_path / "g")])
    assert again.exit_code == 0, again.output  # the folder's scenario flies the same flight
    assert (tmp_path / "g" / "metrics.csv").read_text() == (out / "metrics.csv").read_text()


def test_fly_params_with_c_says_which_wins(tmp_path):
    """``-c`` changes the px4 controller's own fields over ``--params``; one that replaces the
    file's parameters (``hover_from_vehicle``, ``rate_bandwidth``) says so, and ``-c params=``
    beside ``--params`` (two sources of the same parameters) is refused before flying."""
    from click.testing import CliRunner

    from quadcruise.cli.main import main

    (tmp_path / "a.params").write_text("1\t1\tMC_ROLL_P\t7\t9\n1\t1\tMPC_THR_HOVER\t0.45\t9\n")
    (tmp_path / "b.params").write_text("1\t1\tMC_ROLL_P\t8\t9\n")
    fly = ["fly", "hover", "--vehicle", "iris", "--duration", "0.2", "--params", str(tmp_path / "a.params")]
    res = CliRunner().invoke(main, [*fly, "-c", f"params={tmp_path / 'b.params'}", "--out", str(tmp_path / "x")])
    assert res.exit_code == 2 and "-c params=...: --params" in res.output and "give them once" in res.output
    assert not (tmp_path / "x").exists()
    res = CliRunner().invoke(main, [*fly, "-c", "hover_from_vehicle=true", "-c", "rate_bandwidth=15"])
    assert res.exit_code == 0, res.output
    assert "replaces" in res.stderr and "MPC_THR_HOVER (0.45)" in res.stderr
    assert "-c rate_bandwidth=15: rate gains designed" in res.stderr
    res = CliRunner().invoke(main, [*fly, "-c", "position_rate=50"])  # a field of its own: no word needed
    assert res.exit_code == 0 and "replace" not in res.stderr


def test_fly_a_scenario_with_params_keeps_its_px4_fields(tmp_path):
    """A scenario's px4 fields that set no PX4 parameter (thrust_curve, position_rate,
    hover_estimator) stay when ``--params`` gives other parameters; ``-c`` still wins."""
    from click.testing import CliRunner

    from quadcruise.cli.main import main
    from quadcruise.workflows.scenario import load_scenario

    (tmp_path / "a.params").write_text("1\t1\tMC_ROLL_P\t7\t9\n")
    (tmp_path / "b.params").write_text("1\t1\tMC_ROLL_P\t8\t9\n")
    first = ["fly", "hover", "--vehicle", "iris", "--duration", "0.2", "--params", str(tmp_path / "a.params")]
    first += ["-c", "thrust_curve=0.5", "-c", "position_rate=50", "-c", "hover_estimator=true"]
    assert CliRunner().invoke(main, [*first, "--out", str(tmp_path / "s")]).exit_code == 0
    again = ["fly", str(tmp_path / "s" / "scenario.toml"), "--params", str(tmp_path / "b.params")]
    res = CliRunner().invoke(main, [*again, "-c", "position_rate=80", "--out", str(tmp_path / "t")])
    assert res.exit_code == 0, res.output
    c = load_scenario(tmp_path / "t" / "scenario.toml").controller
    assert c.params["MC_ROLL_P"] == 8.0 and (c.thrust_curve, c.hover_estimator) == (0.5, True)
    assert c.position_rate == 80.0  # -c over the scenario's 50


def test_compare_params_keeps_a_scenarios_px4_fields(tmp_path):
    """``compare --params`` over a scenario's compared px4 (a controller, not a name) keeps its
    fields that set no PX4 parameter; a name gets the file's px4 as it is; px4 added once."""
    from quadcruise.cli.objects import with_px4_params

    (tmp_path / "b.params").write_text("1\t1\tMC_ROLL_P\t8\t9\n")
    world = {"vehicle": RotorVehicle.preset("iris")}
    mine = Px4(thrust_curve=0.5, position_rate=50.0, hover_estimator=True)
    out = with_px4_params({"mine": mine, "se3": "se3"}, str(tmp_path / "b.params"), world)
    assert set(out) == {"mine", "se3"} and out["se3"] == "se3"
    got = out["mine"]
    assert got.params["MC_ROLL_P"] == 8.0 and (got.thrust_curve, got.position_rate, got.hover_estimator) == (
        0.5,
        50.0,
        True,
    )
    named = with_px4_params("se3,px4", str(tmp_path / "b.params"), world)
    assert named["px4"].thrust_curve == 1.0 and named["px4"].params["MC_ROLL_P"] == 8.0  # the rotor plant's
    assert set(with_px4_params("se3", str(tmp_path / "b.params"), world)) == {"se3", "px4"}


@pytest.mark.parametrize(
    ("text", "args", "message"),
    [
        ("1\t1\tMC_ROLL_P\t13\t9\n", [], "bad.params, line 1: MC_ROLL_P = 13 1/s is outside PX4 v1.15's range"),
        ("1\t1\tMC_ROLL_P\tfast\t9\n", [], "bad.params, line 1"),
        ("1\t1\tMC_ROLL_P\t7\t9\n", ["--controller", "se3"], "--controller se3 has none"),
    ],
)
def test_fly_params_refuses_bad_input_in_one_line(tmp_path, text, args, message):
    from click.testing import CliRunner

    from quadcruise.cli.main import main

    bad = tmp_path / "bad.params"
    bad.write_text(text)
    res = CliRunner().invoke(main, ["fly", "hover", "--vehicle", "iris", "--params", str(bad), *args])
    assert res.exit_code == 2 and message in res.stderr and res.stderr.count("\n") == 1, res.stderr


def test_tune_px4_writes_tuned_params_that_fly_the_tuned_metrics_exactly(tmp_path):
    import csv

    from click.testing import CliRunner

    from quadcruise.cli.main import main
    from quadcruise.io.px4params import read_params

    out = tmp_path / "t"
    args = ["tune", "step", "--controller", "px4", "--vehicle", "iris", "--duration", "8", "--quiet"]
    args += ["--gains", "params.MPC_XY_P,params.MPC_XY_VEL_P_ACC", "--target", "rise_time_s=1.2"]
    res = CliRunner().invoke(main, [*args, "--budget", "3", "--popsize", "6", "--out", str(out)])
    assert res.exit_code in (0, 1), res.output
    tuned = read_params(out / "tuned.params")
    doc = (out / "tuned.params").read_text()
    assert "# PX4 v1.15" in doc and "MC_ROLL_P\t" not in doc  # only what differs from PX4's defaults
    assert "# tuned: MPC_XY_P, MPC_XY_VEL_P_ACC; the other lines are what the tune flew, not tuned" in doc
    from quadcruise.workflows.scenario import load_scenario

    values = load_scenario(out / "scenario.toml").controller.params  # the tuned controller, as the folder keeps it
    assert dict(tuned) == dict(values)  # the round trip is exact, every parameter
    assert tuned["MPC_XY_P"] != 0.95 and tuned["THR_MDL_FAC"] == 1.0
    flown = tmp_path / "f"
    again = CliRunner().invoke(
        main,
        ["fly", "step", "--vehicle", "iris", "--params", str(out / "tuned.params"), "--duration", "8"]
        + ["--log-every", "10", "--out", str(flown)],
    )
    assert again.exit_code == 0, again.output
    with open(out / "flights.csv") as f:
        best = next(csv.DictReader(f))
    with open(flown / "metrics.csv") as f:
        got = next(csv.DictReader(f))
    for name in ("rmse_m", "rise_time_s", "settling_time_s", "overshoot_pct", "effort"):
        assert float(got[name]) == float(best[name]), name


def test_tune_px4_on_the_paper_plant_says_why_there_is_no_tuned_params(tmp_path):
    """On the paper plant px4 flies gains designed for the vehicle that PX4's parameters cannot
    hold (the rate P below PX4's @min 0.01): no tuned.params, and the tune says so and why."""
    from click.testing import CliRunner

    from quadcruise.cli.main import main

    out = tmp_path / "t"
    args = ["tune", "step", "--controller", "px4", "--duration", "6", "--quiet", "--budget", "2", "--popsize", "5"]
    res = CliRunner().invoke(
        main, [*args, "--gains", "params.MPC_XY_P", "--target", "rise_time_s=1.5", "--out", str(out)]
    )
    assert res.exit_code in (0, 1), res.output
    assert (out / "tune.json").is_file() and not (out / "tuned.params").exists()
    assert f"note: no {out}/tuned.params: its gains are designed for the vehicle" in res.stderr
    assert "MC_ROLLRATE_P = 0.009375 is outside PX4 v1.15's range [0.01, 0.5]" in res.stderr


def test_tune_refuses_an_integer_px4_parameter_before_searching(tmp_path):
    """MC_AIRMODE, IMU_INTEG_RATE, ... are PX4 INT32 choices: --gains naming one is refused in
    one line before any flight (it used to fail mid-search on the first non-integer candidate)."""
    from click.testing import CliRunner

    from quadcruise.cli.main import main

    args = ["tune", "step", "--controller", "px4", "--vehicle", "iris", "--target", "rise_time_s=1.2", "--quiet"]
    for name in ("IMU_INTEG_RATE", "MC_AIRMODE"):
        res = CliRunner().invoke(
            main, [*args, "--gains", f"params.MPC_XY_P,params.{name}", "--out", str(tmp_path / name)]
        )
        assert res.exit_code == 2 and f"--gains params.{name}: PX4 declares it an integer (INT32)" in res.output
        assert res.output.count("\n") == 1 and not (tmp_path / name).exists()


def test_px4s_parameters_are_searched_by_name_within_pxs_range():
    from quadcruise.tune.space import GainSpace, tunable_values

    assert tunable_values(Px4())["params.MC_ROLL_P"] == (6.5, "1/s")
    space = GainSpace.build(Px4(), ["params.MC_ROLL_P", "params.MC_ROLLRATE_P"])
    (roll, rate) = space.gains
    assert (roll.low, roll.high) == (0.65, 12.0) and (rate.low, rate.high) == (0.015, 0.5)  # PX4's @max
    c = space.controllers([[7.0, 0.2]])[0]
    assert c.params["MC_ROLL_P"] == 7.0 and c.params["MC_ROLLRATE_P"] == 0.2


def test_compare_params_flies_px4_with_the_logs_parameters_beside_the_others(tmp_path):
    import csv

    from click.testing import CliRunner

    from quadcruise.cli.main import main

    common = ["step", "--vehicle", "iris", "--params", str(LOG), "--duration", "6"]
    res = CliRunner().invoke(
        main, ["compare", *common[:1], "--controllers", "se3", *common[1:], "--out", str(tmp_path / "c")]
    )
    assert res.exit_code == 0, res.output
    assert res.stderr.count("not used by the px4 controller") == 1
    fly = CliRunner().invoke(main, ["fly", *common, "--out", str(tmp_path / "f")])
    assert fly.exit_code == 0, fly.output
    with open(tmp_path / "c" / "metrics.csv") as f:
        rows = {r.get("controller") or r.get("label"): r for r in csv.DictReader(f)}
    with open(tmp_path / "f" / "metrics.csv") as f:
        alone = next(csv.DictReader(f))
    assert set(rows) == {"se3", "px4"}  # px4 added beside the named ones
    assert float(rows["px4"]["rise_time_s"]) == float(alone["rise_time_s"])


def test_montecarlo_params_flies_px4_with_the_logs_parameters(tmp_path):
    from click.testing import CliRunner

    from quadcruise.cli.main import main

    args = ["montecarlo", "--mission", "step", "--vehicle", "iris", "--params", str(LOG), "-n", "8"]
    args += ["--duration", "6", "--mass-spread", "0.05", "--scheduler", "none"]
    res = CliRunner().invoke(main, [*args, "--out", str(tmp_path / "m")])
    assert res.exit_code == 0, res.output
    assert res.stderr.count("not used by the px4 controller") == 1
    record = (tmp_path / "m" / "quadcruise.json").read_text()
    assert '"name": "px4"' in record and '"MC_ROLLRATE_K": 1.0499999523162842' in record
    bad = tmp_path / "bad.params"
    bad.write_text("1\t1\tMC_ROLL_P\t13\t9\n")
    res = CliRunner().invoke(main, [*args[:6], str(bad), *args[7:], "--out", str(tmp_path / "n")])
    assert res.exit_code == 2 and "MC_ROLL_P = 13" in res.stderr and not (tmp_path / "n").exists()


def _metrics(folder):
    import csv

    with open(folder / "metrics.csv") as f:
        return next(csv.DictReader(f))


def test_fly_ulog_holds_the_px4_parameters_flown_and_fly_params_of_it_flies_them(tmp_path):
    """``fly --params P --ulog f.ulg``: pyulog reads the px4 controller's parameters in the log by
    PX4's names and types (float32, INT32 as int); ``fly --params f.ulg`` flies the same metrics
    exactly (the float64 values float32 does not hold ride in ``quadcruise_px4_params``)."""
    from click.testing import CliRunner
    from pyulog import ULog

    from quadcruise.cli.main import main
    from quadcruise.io.px4params import read_params

    given = tmp_path / "p.params"
    given.write_text("1\t1\tMC_ROLL_P\t7.25\t9\n1\t1\tMPC_XY_P\t1.1\t9\n1\t1\tMC_PITCHRATE_P\t0.1612345678901\t9\n")
    common = ["--vehicle", "iris", "--duration", "3"]
    first = CliRunner().invoke(
        main,
        [
            "fly",
            "step",
            "--params",
            str(given),
            *common,
            "--ulog",
            str(tmp_path / "f.ulg"),
            "--out",
            str(tmp_path / "a"),
        ],
    )
    assert first.exit_code == 0, first.output
    assert "quadrotor x" not in first.stderr  # PX4's form: it flies back the same
    logged = ULog(str(tmp_path / "f.ulg"), message_name_filter_list=[]).initial_parameters
    assert logged["MC_ROLL_P"] == 7.25 and logged["MPC_XY_P"] == float(np.float32(1.1))  # PX4's float32
    assert logged["MC_PITCHRATE_P"] == float(np.float32(0.1612345678901))
    assert logged["MC_YAWRATE_P"] == float(np.float32(0.2))  # PX4's default, flown and logged
    assert isinstance(logged["MPC_USE_HTE"], int) and isinstance(logged["MC_AIRMODE"], int)
    read, want = read_params(tmp_path / "f.ulg"), read_params(given)
    assert dict(read) == dict(want)  # every parameter, the allocation's (CA_*, THR_MDL_FAC) too
    again = CliRunner().invoke(
        main, ["fly", "step", "--params", str(tmp_path / "f.ulg"), *common, "--out", str(tmp_path / "b")]
    )
    assert again.exit_code == 0, again.output
    a, b = _metrics(tmp_path / "a"), _metrics(tmp_path / "b")
    for name in ("rmse_m", "overshoot_pct", "effort"):
        assert float(a[name]) == float(b[name]), name
    flown_default = CliRunner().invoke(
        main, ["fly", "step", *common, "--controller", "px4", "--out", str(tmp_path / "c")]
    )
    assert float(_metrics(tmp_path / "c")["effort"]) != float(a["effort"]), flown_default.output  # it could differ


def test_fly_ulog_of_a_designed_px4_holds_the_design_as_px4_parameters(tmp_path):
    """``fly --controller px4 --ulog``: the rate gains designed for the vehicle and its hover
    thrust are in the log as ``MC_*RATE_*`` and ``MPC_THR_HOVER``; on the paper plant, where
    they lie outside PX4's range, ``fly --params`` of the log refuses it naming the parameter."""
    from click.testing import CliRunner
    from pyulog import ULog

    from quadcruise.cli.main import main

    res = CliRunner().invoke(
        main,
        [
            "fly",
            "hover",
            "--controller",
            "px4",
            "--vehicle",
            "iris",
            "--duration",
            "1",
            "--ulog",
            str(tmp_path / "i.ulg"),
        ],
    )
    assert res.exit_code == 0, res.output
    assert "allocates on PX4's quadrotor x, not the vehicle's rotors" in res.stderr  # said, not silent
    v = RotorVehicle.preset("iris")
    designed = dataclasses.replace(Px4(), **rotor_gains("px4", paper_equivalent(v).omega))
    plain = designed.resolved(paper_equivalent(v)).params
    logged = ULog(str(tmp_path / "i.ulg"), message_name_filter_list=[]).initial_parameters
    for name in ("MC_ROLLRATE_P", "MC_YAWRATE_I", "MPC_THR_HOVER"):
        assert logged[name] == float(np.float32(plain[name])) and plain[name] != Px4().params[name], name
    paper = CliRunner().invoke(
        main, ["fly", "hover", "--controller", "px4", "--duration", "1", "--ulog", str(tmp_path / "p.ulg")]
    )
    assert paper.exit_code == 0, paper.output
    back = CliRunner().invoke(main, ["fly", "hover", "--params", str(tmp_path / "p.ulg"), "--duration", "1"])
    assert back.exit_code == 2 and "MC_ROLLRATE_P = " in back.output and "outside PX4 v1.15's range" in back.output
    assert "Traceback" not in back.output


def test_from_params_of_a_file_warns_its_notes_once_and_already_read_parameters_do_not():
    """``Px4.from_params(LOG)``: one ParameterWarning with what ``--params`` prints (the unused
    parameters); parameters already read (what the command line passes) warn nothing."""
    from quadcruise.errors import ParameterWarning
    from quadcruise.io.px4params import read_params

    iris = RotorVehicle.preset("iris")
    with pytest.warns(ParameterWarning) as caught:
        Px4.from_params(LOG, vehicle=iris)
    assert len(caught) == 1
    text = str(caught[0].message)
    assert "parameters of" in text and "not used by the px4 controller" in text and "BAT1_CAPACITY" in text
    with warnings.catch_warnings():
        warnings.simplefilter("error", ParameterWarning)
        Px4.from_params(read_params(LOG), vehicle=iris)
        Px4.from_params({"MC_ROLL_P": 7.0}, vehicle=iris)
