"""The whole loop: the PX4 1.15 SITL log's takeoff flown again (its trajectory_setpoints, its
parameters, PX4's takeoff ramp, land detector and hover-thrust estimator) on the vehicle the log
flew, jMAVSim's Iris, and its height and attitude compared with the log; the wrong vehicle or the
wrong hover thrust fits clearly worse; ``px4-check --fly`` writes it; bad options are one line."""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np
import pytest
from click.testing import CliRunner

from quadcruise.cli.main import main
from quadcruise.control import px4kernel as K
from quadcruise.control.px4 import Px4
from quadcruise.io.px4params import read_params
from quadcruise.workflows.px4check import TOPICS, _read
from quadcruise.workflows.px4fly import compare_takeoff, fly_takeoff, jmavsim_iris, takeoff_segment

LOG = Path(__file__).parents[1] / "data" / "px4" / "sample_px4_events.ulg"
DEG = np.pi / 180.0


@pytest.fixture(scope="module")
def log():
    T, info, _ = _read(LOG, TOPICS + ("vehicle_constraints", "sensor_combined"))
    return T, int(info["start_timestamp_us"]), read_params(LOG)


@pytest.fixture(scope="module")
def flown(log):
    T, start, params = log
    flight = fly_takeoff(T, params, log_start_us=start)
    compare_takeoff(flight, T)
    return flight


def fit_of(log, **kw):
    T, start, params = log
    flight = fly_takeoff(T, kw.pop("params", params), log_start_us=start, **kw)
    assert flight.status == "finished"
    return compare_takeoff(flight, T)


def test_the_segment_is_the_logs_ramp_to_its_return(log):
    """From takeoff_status's ramp-up (15.94 s into the log) to the return (RTL at 22.14 s), read
    off the log's own messages: 'Takeoff detected' at 16.75 s, 'RTL: start return' at 22.14 s."""
    T, start, _ = log
    a, b = takeoff_segment(T)
    assert (a - start) * 1e-6 == pytest.approx(15.94, abs=0.01)
    assert (b - start) * 1e-6 == pytest.approx(22.136, abs=0.01)


def test_the_takeoff_flies_as_the_log_did(flown):
    """The height over the ramp's start tracks the log's (EKF2's vehicle_local_position, 10 Hz)
    with R^2 >= 0.995 and an RMSE under 0.05 m, no sample off by 0.1 m (measured 0.999, 0.023 m,
    0.050 m: the climb up to 5 cm ahead). Bound: twice the measured error, under a third of what
    a 20 % wrong mass gives (0.17 to 0.18 m). Roll and pitch
    stay within 0.6 deg RMS of the log's (its 0.1 to 0.45 deg offsets are the estimator's,
    which the simulated vehicle, level on a flat ground, has not: R^2 means nothing at that
    size), yaw within 0.3 deg."""
    assert flown.status == "finished"
    h = flown.fit["height"]
    assert h["samples"] >= 60
    assert h["r2"] >= 0.995 and h["rmse"] < 0.05 and h["max_error"] < 0.1
    for name, bound in (("roll", 0.6), ("pitch", 0.6), ("yaw", 0.3)):
        assert flown.fit[name]["samples"] >= 120
        assert flown.fit[name]["rmse"] < bound * DEG
    t, logged, ours = flown.series["height"]
    assert logged.max() > 2.0 and ours[-1] == pytest.approx(logged[-1], abs=0.1)  # both climbed the 2 m


def test_the_takeoff_ramps_the_thrust_as_pxs_did(flown):
    """The collective thrust setpoint against the log's vehicle_thrust_setpoint (50 Hz): PX4's
    ramp from zero thrust, the kink where the climb limit stops binding, the step when the ramp
    ends (MPC_THR_MIN replaces 0), near hover at the top: R^2 >= 0.995, RMSE under 0.01 (measured
    0.9993 and 0.0039, 0.025 at most, at the ramp's end). Ramping to the flight task's 3.6 m/s,
    not capped at MPC_Z_VEL_MAX_UP 3 m/s as PX4 caps it, gave 0.988 and 0.017."""
    f = flown.fit["thrust"]
    assert f["samples"] > 300
    assert f["r2"] >= 0.995 and f["rmse"] < 0.01 and f["max_error"] < 0.05
    t, logged, ours = flown.series["thrust"]
    assert logged[0] < 0.01 and ours[0] < 0.01  # the ramp starts from no thrust
    late = t > 4.5  # slowing the climb at 2 m, near the vehicle's hover thrust 0.4905
    assert np.mean(ours[late]) == pytest.approx(np.mean(logged[late]), abs=0.01)
    assert np.mean(ours[late]) == pytest.approx(0.4905, abs=0.04)


def test_pxs_takeoff_state_machine_ran(flown):
    """The controller ended flying (takeoff state 5 after the 3 s ramp), not landed, in the air,
    its tilt limit slewed back to MPC_TILTMAX_AIR; the estimator converged to the vehicle's hover
    thrust (0.8 g / 16 N = 0.4905) as PX4's did in the log (0.490)."""
    mem = flown.result.memory[0]
    assert mem[K.Y_TKO_STATE] == K.TAKEOFF_FLIGHT and mem[K.Y_LANDED] == 0.0 and mem[K.Y_IN_AIR] == 1.0
    assert mem[K.Y_TILT] == pytest.approx(np.radians(45.0))
    assert mem[K.Y_HTE] == pytest.approx(0.4905, abs=0.005)


@pytest.mark.parametrize(
    "change",
    [
        {"vehicle": jmavsim_iris(1.0)},
        {"vehicle": jmavsim_iris(0.65)},
        {"hover": 0.35, "hover_estimator": False},
        {"hover": 0.65},
        {"thrust_curve": 1.0},
    ],
    ids=["mass 1.0 kg", "mass 0.65 kg", "MPC_THR_HOVER 0.35", "MPC_THR_HOVER 0.65", "thrust u^2"],
)
def test_the_wrong_vehicle_or_hover_thrust_fits_clearly_worse(log, flown, change):
    """A mass 25 % off, MPC_THR_HOVER 0.15 off the vehicle's hover thrust, or a thrust growing with
    the square of the command (identify says linear): the height's RMSE is over five times the
    right vehicle's (measured 0.18, 0.17, 0.32, 0.20, 0.30 m against 0.023 m), the thrust
    setpoint's over ten times (0.05 to 0.15 against 0.004). The estimator does
    not rescue the takeoff: PX4 uses it only once valid (2 s after its first estimate over 1 m),
    which is after this segment in the log as here."""
    change = dict(change)
    if "hover" in change:
        change["params"] = log[2].with_values(MPC_THR_HOVER=change.pop("hover"))
    worse = fit_of(log, **change)
    assert worse["height"]["rmse"] > 5.0 * flown.fit["height"]["rmse"]
    assert worse["height"]["r2"] < flown.fit["height"]["r2"] - 0.03
    assert worse["thrust"]["rmse"] > 10.0 * flown.fit["thrust"]["rmse"]


def test_the_estimator_finds_a_heavier_vehicles_hover_thrust():
    """On a hover flight of jMAVSim's Iris made 1.0 kg (true hover thrust 1.0 g / 16 N = 0.613)
    with the log's MPC_THR_HOVER 0.5, the estimator's valid estimate replaces it (within 0.01)
    and the velocity integral no longer carries the weight PX4's hover thrust missed; without it
    MPC_THR_HOVER stays 0.5 and the integral holds the difference, g (0.613 - 0.5) / 0.5."""
    import quadcruise as qc

    vehicle = jmavsim_iris(1.0)
    truth = vehicle.m * vehicle.g / (4 * vehicle.kf * vehicle.w_max**2)
    ends = {}
    for on in (True, False):
        c = Px4.from_params(LOG, vehicle, thrust_curve=0.0, hover_estimator=on)
        res = qc.fly("hover", c, vehicle=vehicle, duration=12.0, dt=1 / 250)
        assert res.status_text() == "finished"
        ends[on] = res.memory[0]
    assert ends[True][K.Y_HTE_VALID] == 1.0
    assert ends[True][K.Y_G + K.G_THR_HOVER] == pytest.approx(truth, abs=0.01)
    assert abs(ends[True][K.Y_VEL_INT + 2]) < 0.1
    assert ends[False][K.Y_G + K.G_THR_HOVER] == 0.5
    assert abs(ends[False][K.Y_VEL_INT + 2]) == pytest.approx(9.80665 * (truth - 0.5) / 0.5, rel=0.1)


def test_px4_check_fly_writes_the_comparison(tmp_path):
    """``px4-check LOG --fly --out DIR``: the loops' table, then the flight's; check.json's
    ``flight`` with the fit read back; takeoff.png."""
    out = tmp_path / "check"
    r = CliRunner().invoke(main, ["px4-check", str(LOG), "--fly", "--out", str(out)])
    assert r.exit_code == 0, r.output
    assert "takeoff flight 6.2 s of the log (15.94 to 22.14 s), finished" in r.output
    doc = json.loads((out / "check.json").read_text())
    fit = doc["flight"]["fit"]
    assert fit["height"]["r2"] >= 0.995 and fit["height"]["rmse"] < 0.05 and fit["thrust"]["rmse"] < 0.01
    assert doc["flight"]["vehicle"]["m"] == 0.8 and doc["flight"]["controller"]["hover_estimator"] is True
    assert doc["command"].endswith("--fly")
    assert (out / "takeoff.png").stat().st_size > 10_000


@pytest.mark.parametrize(
    "args, message",
    [
        (["--vehicle", "m=1.0"], "error: --vehicle is for the flight: give --fly too"),
        (["--fly", "--vehicle", "paper"], "--fly: the paper's plant has no ground"),
        (["--fly", "--vehicle", "m=-1"], "--vehicle 'm=-1': "),
        (["--fly", "--thrust-curve", "2"], "Invalid value for '--thrust-curve'"),
        (["--fly", "--thrust-curve", "nan"], "error: --thrust-curve nan: must be a number in [0, 1]"),
        (["--fly-until", "25"], "error: --fly-until is for the flight: give --fly too"),
        (["--fly", "--fly-until", "nan"], "error: --fly-until nan: must be a finite time in the log [s]"),
        (
            ["--fly", "--fly-until", "10"],
            "--fly-until: the flight runs from the takeoff ramp's start to the log's end, 15.94 to 31.09 s of the log",
        ),
    ],
)
def test_bad_fly_options_are_one_line(tmp_path, args, message):
    out = tmp_path / "bad"
    r = CliRunner().invoke(main, ["px4-check", str(LOG), "--out", str(out), *args])
    assert r.exit_code == 2, r.output
    assert message in r.output and "Traceback" not in r.output
    assert not out.exists()


def test_a_flight_that_crashes_says_so(tmp_path):
    """A vehicle with a thousandth of jMAVSim's roll and pitch inertia tumbles at lift-off: the
    table, check.json's status and the exit status (1) say it crashed; the comparison stops there."""
    out = tmp_path / "crash"
    r = CliRunner().invoke(main, ["px4-check", str(LOG), "--fly", "--vehicle", "Jxx=2e-6,Jyy=2e-6", "--out", str(out)])
    assert r.exit_code == 1, r.output
    assert "error: the takeoff flight did not finish: crashed" in r.output
    doc = json.loads((out / "check.json").read_text())
    assert doc["flight"]["status"].startswith("crashed")
    assert doc["flight"]["fit"]["height"]["samples"] < 40  # 62 in the whole segment


def test_a_log_without_a_takeoff_is_one_line(tmp_path):
    """quadcruise's own PX4 log of an Iris hover (no takeoff_status): refused in one line naming
    the log and the topic, exit 2, nothing written."""
    import quadcruise as qc

    own = tmp_path / "own.ulg"
    qc.fly("hover", "px4", vehicle="iris", duration=1.0).to_ulog(own)
    out = tmp_path / "out"
    r = CliRunner().invoke(main, ["px4-check", str(own), "--fly", "--out", str(out)])
    assert r.exit_code == 2, r.output
    assert r.output.strip() == f"error: {own}: the log has no takeoff_status: cannot fly its takeoff"
    assert not out.exists()


def test_fly_until_flies_the_return_too(log):
    """``--fly-until 25.5``: the takeoff, the hold and the return's descent to just above the
    ground (the log touches down at 25.7 s): the height still within 0.06 m RMS (measured
    0.035 m), the thrust setpoint within 0.01 (0.004); the estimator, valid from 22.5 s on, holds
    the vehicle's hover thrust, as PX4's did (0.490)."""
    T, start, params = log
    flight = fly_takeoff(T, params, log_start_us=start, until_s=25.5)
    assert flight.status == "finished"
    assert (flight.end_us - start) * 1e-6 == pytest.approx(25.5)
    fit = compare_takeoff(flight, T)
    assert fit["height"]["samples"] > 90 and fit["height"]["rmse"] < 0.06 and fit["height"]["r2"] > 0.99
    assert fit["thrust"]["rmse"] < 0.01
    mem = flight.result.memory[0]
    assert mem[K.Y_HTE_VALID] == 1.0 and mem[K.Y_G + K.G_THR_HOVER] == pytest.approx(0.4905, abs=0.005)
