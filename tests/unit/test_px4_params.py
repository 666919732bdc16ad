"""PX4 parameters in and out (:mod:`quadcruise.io.px4params`): a ULog's read as pyulog reads
them, PX4 v1.15's defaults checked against the defaults a v1.15 SITL log itself records, a
QGroundControl file read, written and read back exactly, and every bad file refused in one
line naming the file and the parameter."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest
from pyulog import ULog

from quadcruise.errors import InputError
from quadcruise.io.px4defaults import PX4_PARAMETERS, RELEASE
from quadcruise.io.px4params import Px4Parameters, changed, parse_params_text, read_params, write_params

LOG = Path(__file__).parents[1] / "data" / "px4" / "sample_px4_events.ulg"


@pytest.fixture(scope="module")
def ulog():
    return ULog(str(LOG), message_name_filter_list=[])


def test_a_ulogs_parameters_are_pyulogs(ulog):
    p = read_params(LOG)
    raw = ulog.initial_parameters
    assert set(p.from_file) == set(PX4_PARAMETERS)  # the log has every one
    for name in PX4_PARAMETERS:
        assert p[name] == raw[name]
    assert p["MC_ROLLRATE_K"] == pytest.approx(1.05)  # the SITL airframe's own
    assert set(p.unused) == set(raw) - set(PX4_PARAMETERS) and list(p.unused) == sorted(p.unused)
    assert p.source == str(LOG)


def test_the_defaults_are_those_the_v115_log_records(ulog):
    """The log (PX4 1.15.0 dev) records PX4's system default of each parameter whose value
    differs from it; the others hold their default. Our table must agree with both."""
    assert ulog.msg_info_dict["ver_sw_release"] >> 16 == 0x010F  # v1.15
    system = ulog.get_default_parameters(0)
    for name, spec in PX4_PARAMETERS.items():
        expected = system.get(name, ulog.initial_parameters[name])
        assert np.float32(spec.default) == np.float32(expected), name
    assert "MC_ROLLRATE_K" in system  # one that the airframe changed


def test_a_params_file_round_trips_exactly(tmp_path):
    values = dict(Px4Parameters.defaults())
    values.update(MC_ROLLRATE_P=0.1873456789012345, MPC_XY_VEL_P_ACC=2.25, MPC_USE_HTE=0, MC_YAW_P=2.8)
    path = write_params(tmp_path / "tuned.params", values, note="made by a test")
    text = path.read_text()
    assert f"PX4 {RELEASE}" in text and "# made by a test" in text
    rows = [line.split("\t") for line in text.splitlines() if not line.startswith("#")]
    assert [r[2] for r in rows] == ["MC_ROLLRATE_P", "MPC_USE_HTE", "MPC_XY_VEL_P_ACC"]  # only what changed
    assert [r[4] for r in rows] == ["9", "6", "9"] and all(r[:2] == ["1", "1"] for r in rows)
    back = read_params(path)
    assert dict(back) == values  # exact, float for float
    assert back.unused == () and set(back.from_file) == {"MC_ROLLRATE_P", "MPC_USE_HTE", "MPC_XY_VEL_P_ACC"}


def test_a_qgroundcontrol_file_is_read(tmp_path):
    text = (
        "# Onboard parameters for Vehicle 1\n#\n# Stack: PX4 Pro\n# Vehicle-Id Component-Id Name Value Type\n"
        "1\t1\tMC_PITCHRATE_P\t0.180000007152557373\t9\n"
        "1\t1\tSYS_AUTOSTART\t4001\t6\n"
        "1\t1\tMPC_TILTMAX_AIR\t35\t9\n"
        "1\t1\tBAT1_N_CELLS\t4\t6\n"
    )
    (tmp_path / "x500.params").write_text(text)
    p = read_params(tmp_path / "x500.params")
    assert p["MC_PITCHRATE_P"] == pytest.approx(0.18) and p["MPC_TILTMAX_AIR"] == 35.0
    assert p["MC_ROLL_P"] == 6.5  # the default where the file is silent
    assert p.unused == ("BAT1_N_CELLS", "SYS_AUTOSTART")
    assert changed(p) == {"MC_PITCHRATE_P": p["MC_PITCHRATE_P"], "MPC_TILTMAX_AIR": 35.0}


@pytest.mark.parametrize(
    "text, message",
    [
        ("1\t1\tMC_ROLL_P\t13\t9\n", "f.params, line 1: MC_ROLL_P = 13 1/s is outside PX4 v1.15's range [0, 12]"),
        ("1\t1\tMPC_THR_MIN\t0.01\t9\n", "f.params, line 1: MPC_THR_MIN = 0.01 norm is outside PX4 v1.15's range"),
        ("# c\n1\t1\tMC_ROLL_P\tfast\t9\n", "f.params, line 2: MC_ROLL_P = 'fast' is not a number"),
        ("1\t1\tMC_ROLL_P\tnan\t9\n", "f.params, line 1: MC_ROLL_P = 'nan' is not a finite number"),
        ("1\t1\tMC_ROLL_P\t6\n", "f.params, line 1: not a QGroundControl parameter line"),
        ("1\t1\tMC_ROLL_P\t6\t12\n", "f.params, line 1: MC_ROLL_P: type '12' is not a MAV_PARAM_TYPE"),
        ("1\t1\tMPC_USE_HTE\t0.5\t6\n", "f.params, line 1: MPC_USE_HTE = '0.5' is not an integer"),
        ("1\t1\tMC_ROLL_P\t6\t9\n1\t1\tMC_ROLL_P\t7\t9\n", "f.params, line 2: MC_ROLL_P is set twice"),
        ("# only comments\n", "f.params: no parameters"),
    ],
    ids=["high", "low", "word", "nan", "fields", "type", "fraction", "twice", "empty"],
)
def test_bad_params_files_are_refused_in_one_line(tmp_path, text, message):
    (tmp_path / "f.params").write_text(text)
    with pytest.raises(InputError) as caught:
        read_params(tmp_path / "f.params")
    said = str(caught.value)
    assert said.startswith(str(tmp_path / "f.params")) and message.split("f.params")[1] in said
    assert "\n" not in said


def test_a_value_below_a_floor_without_ceiling_is_refused():
    with pytest.raises(InputError, match=r"MC_RR_INT_LIM = -0.1 is outside PX4 v1.15's range \[0, inf\]"):
        parse_params_text("1\t1\tMC_RR_INT_LIM\t-0.1\t9\n", "g.params")
    assert parse_params_text("1\t1\tMC_RR_INT_LIM\t2.5\t9\n")["MC_RR_INT_LIM"] == 2.5  # no ceiling


def test_other_formats_and_files_are_refused(tmp_path):
    with pytest.raises(InputError, match=r"gains.yaml: PX4 parameters come from a PX4 log \(.ulg\)"):
        read_params(tmp_path / "gains.yaml")
    with pytest.raises(InputError, match="missing.params: no such file"):
        read_params(tmp_path / "missing.params")
    (tmp_path / "fake.ulg").write_bytes(b"not a log at all, just text")
    with pytest.raises(InputError, match="fake.ulg: not a PX4 log"):
        read_params(tmp_path / "fake.ulg")
    (tmp_path / "binary.params").write_bytes(b"\xff\xfe\x00\x01")
    with pytest.raises(InputError, match="binary.params: not a text file"):
        read_params(tmp_path / "binary.params")


def test_writing_refuses_a_value_out_of_range_and_writes_nothing(tmp_path):
    with pytest.raises(InputError, match="MPC_THR_HOVER = 0.95 norm is outside"):
        write_params(tmp_path / "t.params", {"MPC_THR_HOVER": 0.95})
    assert not (tmp_path / "t.params").exists()
    with pytest.raises(InputError, match="NOT_A_PARAM is not a parameter of the PX4 loops"):
        Px4Parameters.defaults().with_values(NOT_A_PARAM=1.0)


@pytest.mark.parametrize(
    "text, message",
    [
        ("1\t1\tMC_ROLL_P\t12.00001\t9\n", "MC_ROLL_P = 12.00001 1/s is outside PX4 v1.15's range [0, 12]"),
        ("1\t1\tMC_ROLLRATE_P\t0.00999\t9\n", "MC_ROLLRATE_P = 0.00999 is outside PX4 v1.15's range [0.01, 0.5]"),
        ("1\t1\tMPC_USE_HTE\t1\t9\n", "MPC_USE_HTE has type 9 but PX4 declares it INT32 (type 6)"),
        ("1\t1\tMC_ROLL_P\t7\t6\n", "MC_ROLL_P has type 6 but PX4 declares it FLOAT (type 9)"),
        ("a\t1\tMC_ROLL_P\t7\t9\n", "MC_ROLL_P: Vehicle-Id 'a' and Component-Id '1' must be whole numbers"),
    ],
    ids=["just-above-max", "just-below-min", "int-as-float", "float-as-int", "vehicle-id"],
)
def test_just_outside_a_bound_and_type_mismatches_are_refused_naming_the_value(tmp_path, text, message):
    """A value one float32 step outside PX4's range is named as it was written (not rounded to
    the bound it exceeds); a line whose MAV_PARAM_TYPE is not the one PX4 declares is refused,
    as QGroundControl refuses it on load."""
    (tmp_path / "f.params").write_text(text)
    with pytest.raises(InputError) as caught:
        read_params(tmp_path / "f.params")
    said = str(caught.value)
    assert said.startswith(f"{tmp_path / 'f.params'}, line 1: {message}") and "\n" not in said


def test_values_exactly_at_the_bounds_and_qgc_file_quirks_are_read(tmp_path):
    """PX4's @min and @max themselves pass; a byte-order mark, CRLF line ends, blank lines,
    comments and another vehicle's id are read; integer widths 1-8 for an INT32 parameter too."""
    text = (
        "\ufeff# Onboard parameters for Vehicle 2\r\n\r\n# Vehicle-Id Component-Id Name Value Type\r\n"
        "2\t1\tMC_ROLL_P\t12\t9\r\n2\t1\tMC_ROLLRATE_P\t0.01\t9\r\n2\t1\tMPC_TILTMAX_AIR\t89\t9\r\n"
        "2\t1\tMC_AIRMODE\t2\t5\r\n2\t1\tIMU_INTEG_RATE\t1000\t6\r\n"
    )
    (tmp_path / "v2.params").write_bytes(text.encode("utf-8"))
    p = read_params(tmp_path / "v2.params")
    assert (p["MC_ROLL_P"], p["MC_ROLLRATE_P"], p["MPC_TILTMAX_AIR"]) == (12.0, 0.01, 89.0)
    assert (p["MC_AIRMODE"], p["IMU_INTEG_RATE"]) == (2.0, 1000.0)
    assert p.unused == ()


def test_px4s_own_constraints_are_applied_and_said():
    """``MulticopterPositionControl::parameters_update`` (v1.15) constrains MPC_THR_HOVER into
    [MPC_THR_MIN, MPC_THR_MAX] and MPC_TILTMAX_LND to at most MPC_TILTMAX_AIR; the px4
    controller flies what PX4 flies, and the reader says it (the flown value named)."""
    from quadcruise.control.px4 import Px4
    from quadcruise.control.px4kernel import X_TILT_LND
    from quadcruise.control.px4loops import G_THR_HOVER
    from quadcruise.io.px4params import px4_constrained

    base = Px4Parameters.defaults()
    assert px4_constrained(base) == (dict(base), ())  # PX4's defaults are consistent
    for given, flown in (
        ({"MPC_THR_HOVER": 0.2, "MPC_THR_MIN": 0.4}, 0.4),
        ({"MPC_THR_HOVER": 0.7, "MPC_THR_MAX": 0.6}, 0.6),
        ({"MPC_THR_HOVER": 0.4, "MPC_THR_MIN": 0.4, "MPC_THR_MAX": 0.4}, 0.4),  # at the bounds: kept
    ):
        values, notes = px4_constrained(base.with_values(**given))
        assert values["MPC_THR_HOVER"] == flown
        assert len(notes) == (given["MPC_THR_HOVER"] != flown)
        assert all(n.startswith(f"MPC_THR_HOVER = {given['MPC_THR_HOVER']:g} is outside") for n in notes)
        gains = Px4.from_params(given).gains()
        assert gains[G_THR_HOVER] == flown
    values, notes = px4_constrained(base.with_values(MPC_TILTMAX_LND=60.0, MPC_TILTMAX_AIR=30.0))
    assert values["MPC_TILTMAX_LND"] == 30.0 and "MPC_TILTMAX_LND = 60 deg is above" in notes[0]
    gains = Px4.from_params({"MPC_TILTMAX_LND": 60.0, "MPC_TILTMAX_AIR": 30.0}).gains()
    assert gains[X_TILT_LND] == pytest.approx(np.radians(30.0))
    assert Px4.from_params({"MPC_TILTMAX_LND": 25.0}).gains()[X_TILT_LND] == pytest.approx(np.radians(25.0))


def _shared_log(name: str) -> Path:
    for folder in (Path(__file__).resolve().parents[3] / "shared" / "px4-logs", Path("/work/shared/px4-logs")):
        if (folder / name).is_file():
            return folder / name
    pytest.skip(f"the real PX4 log {name} is not on this machine")


def test_a_log_of_another_release_says_what_it_lacks_and_its_older_names():
    """A log holds every parameter of its release: the loops' parameters it lacks fly at PX4
    v1.15's defaults, and the reader says so once, naming the release pyulog reads and them;
    an older release's velocity gains (``MPC_XY_VEL_P``: thrust per m/s, not m/s^2 per m/s)
    are said not converted. The v1.15 SITL log gets no note."""
    assert read_params(LOG).notes == ()
    small = _shared_log("sample_log_small.ulg")  # PX4 v1.11.2 (dev): ver_sw_release 0x010b0200
    raw = ULog(str(small), message_name_filter_list=[]).initial_parameters
    lacking = sorted(n for n in PX4_PARAMETERS if n not in raw and not n.startswith("CA_"))
    assert lacking == ["HTE_THR_RANGE", "HTE_VXY_THR", "HTE_VZ_THR", "MPC_THR_XY_MARG"]
    (note,) = read_params(small).notes
    assert f"{small} is a log of PX4 v1.11.2 (dev), not PX4 v1.15: it has no {', '.join(lacking)}" in note
    old = _shared_log("sample.ulg")  # no ver_sw_release; MPC_XY_VEL_P and no MPC_XY_VEL_P_ACC
    renamed, release = read_params(old).notes
    assert "MPC_XY_VEL_P, MPC_Z_VEL_D" in renamed and "not converted" in renamed
    assert "a PX4 release it does not state" in release and "MPC_XY_VEL_P_ACC" in release
    text = "1\t1\tMPC_XY_VEL_P\t0.09\t9\n1\t1\tMC_ROLL_P\t7\t9\n"  # a .params file: its older names only
    (said,) = parse_params_text(text, "old.params").notes
    assert said.startswith("old.params names MPC_XY_VEL_P, an older PX4 release's gains in other units")
    assert parse_params_text("1\t1\tMC_ROLL_P\t7\t9\n").notes == ()  # a partial file of this release: nothing


def _ulog_bytes(params, changes) -> bytes:
    """A minimal ULog as the format's specification lays it out (header, info, parameters, one
    topic's format, subscription and data; parameter messages among the data are changes)."""
    import struct

    def msg(kind, payload):
        return struct.pack("<HB", len(payload), ord(kind)) + payload

    def kv(key, value):
        return bytes([len(key)]) + key.encode() + value

    out = b"ULog\x01\x12\x35" + bytes([1]) + struct.pack("<Q", 0) + msg("I", kv("char[3] sys_name", b"PX4"))
    out += b"".join(msg("P", kv(f"float {n}", struct.pack("<f", v))) for n, v in params)
    out += msg("F", b"topic_x:uint64_t timestamp;float a;") + msg("A", struct.pack("<BH", 0, 0) + b"topic_x")
    for stamp, name, value in changes:
        out += msg("D", struct.pack("<HQf", 0, stamp, 0.0))
        out += msg("P", kv(f"float {name}", struct.pack("<f", value))) if name else b""
    return out + msg("D", struct.pack("<HQf", 0, 20_000_000, 0.0))


def test_a_log_that_changes_a_used_parameter_in_flight_says_so(tmp_path):
    """pyulog reads the written log's changes; the reader takes the values at the log's end and
    says which used parameters changed (a change to the same value, or of an unused one, is not said);
    a log without parameters is refused in one line."""
    path = tmp_path / "changed.ulg"
    path.write_bytes(
        _ulog_bytes(
            [("MC_ROLL_P", 6.5), ("MC_PITCH_P", 6.5), ("SYS_X", 1.0)],
            [
                (1_000_000, None, 0.0),
                (5_000_000, "MC_ROLL_P", 8.0),
                (6_000_000, "MC_PITCH_P", 6.5),
                (7_000_000, "SYS_X", 2.0),
            ],
        )
    )
    assert [(n, v) for _, n, v in ULog(str(path)).changed_parameters] == [
        ("MC_ROLL_P", 8.0),
        ("MC_PITCH_P", 6.5),
        ("SYS_X", 2.0),
    ]
    p = read_params(path)
    assert p["MC_ROLL_P"] == 8.0 and p["MC_PITCH_P"] == 6.5
    assert f"{path} changes MC_ROLL_P during the log: the values at its end are used for the whole log" in p.notes
    assert not any("MC_PITCH_P during" in n or "SYS_X during" in n for n in p.notes)
    (tmp_path / "none.ulg").write_bytes(_ulog_bytes([], [(1_000_000, None, 0.0)]))
    with pytest.raises(InputError, match=r"none.ulg: the log holds no parameters$"):
        read_params(tmp_path / "none.ulg")


def test_another_components_parameters_are_not_the_autopilots_and_two_vehicles_are_refused(tmp_path):
    """QGroundControl saves every component's parameters: a gimbal's (Component-Id 154) of the
    same name as the autopilot's is listed as unused, never flown nor "set twice"; a file of two
    vehicles is refused naming both."""
    text = "1\t1\tMC_ROLL_P\t7\t9\n1\t154\tMC_ROLL_P\t3\t9\n1\t154\tMNT_MODE_IN\t1\t6\n"
    p = parse_params_text(text, "gimbal.params")
    assert p["MC_ROLL_P"] == 7.0 and p.from_file == ("MC_ROLL_P",)
    assert p.unused == ("MC_ROLL_P@component154", "MNT_MODE_IN@component154")
    with pytest.raises(
        InputError, match=r"^two.params, line 2: MC_ROLL_P: the file holds the parameters of vehicles 1"
    ):
        parse_params_text("1\t1\tMC_ROLL_P\t7\t9\n2\t1\tMC_ROLL_P\t8\t9\n", "two.params")


def test_a_note_of_several_lines_is_written_as_comments(tmp_path):
    path = write_params(tmp_path / "t.params", {"MC_ROLL_P": 7.0}, note="quadcruise tune step\ntuned: MC_ROLL_P")
    text = path.read_text()
    assert "# quadcruise tune step\n# tuned: MC_ROLL_P\n" in text
    assert dict(read_params(path)) == dict(Px4Parameters.defaults().with_values(MC_ROLL_P=7.0))


def test_a_quadcruise_logs_exact_values_are_read_only_where_the_float32_is_theirs(tmp_path):
    """The info ``quadcruise_px4_params`` gives the float64 a float32 parameter was rounded from;
    a parameter section whose value is not that rounding (edited) wins."""
    from quadcruise.io.ulog import Topic, write_ulog

    topic = Topic("t", (("uint64_t", 0, "timestamp"),), {"timestamp": np.array([1])})
    exact = "MC_PITCHRATE_P=0.1612345678901;MC_ROLLRATE_P=0.15"
    path = tmp_path / "a.ulg"
    write_ulog(
        path,
        [topic],
        info={"quadcruise_px4_params": exact},
        parameters={"MC_PITCHRATE_P": 0.1612345678901, "MC_ROLLRATE_P": 0.2, "MPC_USE_HTE": 0},
    )
    got = read_params(path)
    assert got["MC_PITCHRATE_P"] == 0.1612345678901  # float32 in the section, exact back
    assert got["MC_ROLLRATE_P"] == float(np.float32(0.2))  # the section's own value, not 0.15
    plain = tmp_path / "b.ulg"
    write_ulog(plain, [topic], parameters={"MC_PITCHRATE_P": 0.1612345678901, "MPC_USE_HTE": 0})
    assert read_params(plain)["MC_PITCHRATE_P"] == float(np.float32(0.1612345678901))  # a PX4 log: its float32
