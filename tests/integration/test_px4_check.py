"""``px4-check`` on a real PX4 v1.15 SITL log (tests/data/px4): the log's own attitude, rates
and positions through our PX4 loops, with the log's parameters, reproduce what PX4 logged;
the same loops with a gain PX4 did not fly miss it; bad input is one line and status 2."""

from __future__ import annotations

import json
from pathlib import Path

import pytest
from click.testing import CliRunner
from pyulog import ULog

from quadcruise.cli.main import main
from quadcruise.errors import InputError
from quadcruise.io.px4params import read_params
from quadcruise.workflows.px4check import GOOD_FIT, px4_check

LOG = Path(__file__).parents[1] / "data" / "px4" / "sample_px4_events.ulg"


@pytest.fixture(scope="module")
def check():
    return px4_check(LOG)


def r2(result, loop, axis):
    return result.loops[loop]["axes"][axis]["r2"]


def test_the_attitude_loop_gives_pxs_rate_setpoints(check):
    """Airborne roll and pitch rate setpoints at PX4 autotune's "good fit" or better (measured
    0.98 and 0.99; yaw 0.80, its setpoints 0.6 mrad/s in size)."""
    assert check.px4_version == "1.15.0 (dev)"
    for axis in ("roll", "pitch"):
        assert r2(check, "attitude", axis) >= GOOD_FIT
        assert check.loops["attitude"]["axes"][axis]["samples"] > 500  # 11 s airborne at 50 Hz


def test_the_rate_loop_gives_pxs_torques(check):
    """Matched by gyro sample, the torque setpoints are PX4's to R^2 0.99 on every axis."""
    for axis in ("roll", "pitch", "yaw"):
        assert r2(check, "rate", axis) >= 0.99


def test_our_rate_integral_follows_pxs(check):
    """Integrated by us from the log's first value at the logged 50 Hz gyro samples (PX4: the
    gyro rate), with the allocator's saturation and the land detector: PX4's integral to R^2
    0.99 in roll and pitch (yaw 0.85, its integral 1e-4 in size); a doubled MC_ROLLRATE_I, a
    halved MC_PITCHRATE_I or a tight MC_RR_INT_LIM miss it."""
    assert r2(check, "rate_integral", "roll") > 0.99 and r2(check, "rate_integral", "pitch") > 0.99
    params = read_params(LOG)
    wrong = px4_check(LOG, params.with_values(MC_ROLLRATE_I=0.4, MC_PITCHRATE_I=0.1))
    assert r2(wrong, "rate_integral", "roll") < 0.5 and r2(wrong, "rate_integral", "pitch") < GOOD_FIT
    capped = px4_check(LOG, params.with_values(MC_RR_INT_LIM=0.001))
    assert r2(capped, "rate_integral", "roll") < 0.5


def test_the_allocation_gives_pxs_motor_commands(check):
    motors = check.loops["allocation"]["axes"]
    assert set(motors) == {"motor1", "motor2", "motor3", "motor4"}
    assert all(f["r2"] > 0.9999 and f["rmse"] < 1e-6 and f["samples"] > 100 for f in motors.values())


def test_the_position_loop_is_checked_while_flying(check):
    position = check.loops["position"]["axes"]
    assert position["v_north"]["r2"] > 0.99 and position["v_down"]["r2"] > 0.95
    assert all(f["samples"] > 50 for f in position.values())
    assert all(f["r2"] is not None and f["rmse"] >= 0 for f in position.values())


def test_a_gain_pxs_did_not_fly_misses(check):
    """Both directions: halving MC_ROLL_P or doubling MC_PITCHRATE_P takes that axis below the
    good-fit level and leaves the others where they were."""
    params = read_params(LOG)
    soft = px4_check(LOG, params.with_values(MC_ROLL_P=params["MC_ROLL_P"] / 2))
    assert r2(soft, "attitude", "roll") < GOOD_FIT
    assert r2(soft, "attitude", "pitch") == pytest.approx(r2(check, "attitude", "pitch"))
    hard = px4_check(LOG, params.with_values(MC_PITCHRATE_P=2 * params["MC_PITCHRATE_P"]))
    assert r2(hard, "rate", "pitch") < GOOD_FIT
    assert r2(hard, "rate", "roll") == pytest.approx(r2(check, "rate", "roll"))


def test_the_cli_writes_check_json(tmp_path, check):
    out = tmp_path / "check"
    res = CliRunner().invoke(main, ["px4-check", str(LOG), "--out", str(out)])
    assert res.exit_code == 0, res.output
    assert "attitude      roll" in res.output and "not used by the loops" in res.output
    doc = json.loads((out / "check.json").read_text())
    assert doc["loops_px4_release"] == "v1.15" and doc["log_px4_version"] == "1.15.0 (dev)"
    assert doc["loops"]["attitude"]["axes"]["roll"]["r2"] == pytest.approx(r2(check, "attitude", "roll"))
    raw = ULog(str(LOG), message_name_filter_list=[]).initial_parameters
    assert set(doc["parameters_unused"]) | set(doc["parameters_used"]) == set(raw)  # each parameter once
    assert res.output.count("not used") == 1 and any("logged rates" in line for line in doc["limits"])


def test_the_cli_takes_a_params_file(tmp_path):
    (tmp_path / "soft.params").write_text("1\t1\tMC_ROLL_P\t3.25\t9\n1\t1\tSYS_AUTOSTART\t10017\t6\n")
    res = CliRunner().invoke(
        main, ["px4-check", str(LOG), "--params", str(tmp_path / "soft.params"), "--out", str(tmp_path / "c")]
    )
    assert res.exit_code == 0, res.output
    doc = json.loads((tmp_path / "c" / "check.json").read_text())
    assert doc["parameters_used"]["MC_ROLL_P"] == 3.25 and doc["parameters_unused"] == ["SYS_AUTOSTART"]
    assert "not used by the loops: SYS_AUTOSTART" in res.output
    assert doc["loops"]["attitude"]["axes"]["roll"]["r2"] < GOOD_FIT


@pytest.mark.parametrize(
    "args, message",
    [
        (["missing.ulg"], "missing.ulg: no such file"),
        ([str(LOG.parent / "README.md")], "px4-check reads a PX4 log (.ulg), got '.md'"),
        ([str(LOG), "--params", "gains.yaml"], "gains.yaml: PX4 parameters come from a PX4 log (.ulg)"),
    ],
    ids=["missing", "not-a-log", "params-format"],
)
def test_bad_input_is_one_line_and_status_2(tmp_path, args, message):
    res = CliRunner().invoke(main, ["px4-check", *args, "--out", str(tmp_path / "o")])
    assert res.exit_code == 2
    assert message in res.output and res.output.count("\n") == 1 and res.output.startswith("error: ")
    assert not (tmp_path / "o").exists()


def test_a_params_value_out_of_range_is_refused_before_any_work(tmp_path):
    (tmp_path / "bad.params").write_text("# x\n1\t1\tMC_PITCHRATE_P\t0.9\t9\n")
    res = CliRunner().invoke(
        main, ["px4-check", str(LOG), "--params", str(tmp_path / "bad.params"), "--out", str(tmp_path / "o")]
    )
    assert res.exit_code == 2 and "bad.params, line 2: MC_PITCHRATE_P = 0.9 is outside" in res.output
    assert not (tmp_path / "o").exists()


def test_a_truncated_log_is_refused(tmp_path):
    cut = tmp_path / "cut.ulg"
    cut.write_bytes(LOG.read_bytes()[:50000])
    with pytest.raises(InputError, match="cut.ulg: truncated PX4 log"):
        px4_check(cut)


def synthetic_log(path, armed=True, vtol=False, loops=True):
    """A small ULog written by quadcruise's own writer: status, land detector and (``loops``)
    the attitude loop's three topics, 2 s at 20 Hz, hovering level."""
    import numpy as np

    from quadcruise.io.ulog import Topic, write_ulog

    t = np.arange(40) * 50_000 + 1_000_000
    n = len(t)
    fields = (("uint64_t", 0, "timestamp"), ("uint8_t", 0, "arming_state"), ("uint8_t", 0, "system_type"))
    status = Topic(
        "vehicle_status",
        (*fields, ("bool", 0, "is_vtol")),
        {"timestamp": t[:1], "arming_state": np.array([2 if armed else 1]), "system_type": np.array([2]),
         "is_vtol": np.array([int(vtol)])},
    )  # fmt: skip
    land = Topic("vehicle_land_detected", (("uint64_t", 0, "timestamp"), ("bool", 0, "landed")),
                 {"timestamp": t[:1], "landed": np.array([0])})  # fmt: skip
    q = np.tile([1.0, 0.0, 0.0, 0.0], (n, 1))
    topics = [status, land]
    if loops:
        topics += [
            Topic("vehicle_attitude", (("uint64_t", 0, "timestamp"), ("float", 4, "q")), {"timestamp": t, "q": q}),
            Topic(
                "vehicle_attitude_setpoint",
                (("uint64_t", 0, "timestamp"), ("float", 0, "yaw_sp_move_rate"), ("float", 4, "q_d")),
                {"timestamp": t, "yaw_sp_move_rate": np.zeros(n), "q_d": q},
            ),  # fmt: skip
            Topic(
                "vehicle_rates_setpoint",
                (("uint64_t", 0, "timestamp"), ("float", 0, "roll"), ("float", 0, "pitch"), ("float", 0, "yaw")),
                {"timestamp": t + 10, "roll": np.zeros(n), "pitch": np.zeros(n), "yaw": np.zeros(n)},
            ),  # fmt: skip
        ]
    write_ulog(path, topics, info={"ver_sw_release": 0x010F00FF}, parameters={"MC_ROLL_P": 6.5})
    return path


def test_logs_that_cannot_be_checked_are_refused_in_one_line(tmp_path):
    level = px4_check(synthetic_log(tmp_path / "level.ulg"))  # our writer's log, armed and airborne: runs
    assert level.loops["attitude"]["axes"]["roll"]["samples"] > 30 and "absent" in level.loops["rate"]
    assert level.loops["attitude"]["axes"]["roll"]["rmse"] == 0.0  # level on a level setpoint: zero rates
    with pytest.raises(InputError, match="grounded.ulg: nothing to check: the vehicle was never airborne"):
        px4_check(synthetic_log(tmp_path / "grounded.ulg", armed=False))
    with pytest.raises(InputError, match=r"vtol.ulg: not a multicopter \(a VTOL\)"):
        px4_check(synthetic_log(tmp_path / "vtol.ulg", vtol=True))
    with pytest.raises(InputError, match="bare.ulg: none of the PX4 loops can be checked: the log has no vehicle_att"):
        px4_check(synthetic_log(tmp_path / "bare.ulg", loops=False))
