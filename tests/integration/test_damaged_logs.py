"""Damaged flight logs: each refused by ``quadcruise identify`` in one line naming the file and what
is wrong, exit 2, nothing written, before any fitting; and the intact log they were made from
still passes (both directions).

The damaged PX4 logs are made from the SITL log nobody here wrote (tests/data/px4, BSD licence):
by editing its bytes (a length field) or by rewriting the topics pyulog reads from it with our
ULog writer after one change (a NaN quaternion, an inf acceleration, a parameter, a field left
out, a clock that jumps back). The CSVs are a quadcruise flight's.
"""

from __future__ import annotations

import json
import re
import struct
from pathlib import Path

import numpy as np
import pandas as pd
import pytest
from click.testing import CliRunner
from pyulog import ULog

import quadcruise as qc
from quadcruise.cli.main import main
from quadcruise.io.flightlog import ULOG_TOPICS, read_flight_log
from quadcruise.io.ulog import NUMPY_TYPES, Topic, write_ulog

SITL = Path(__file__).resolve().parents[1] / "data" / "px4" / "sample_px4_events.ulg"
DAMAGED = (21.0, 22.0)
"""Where the values are damaged [s of the log's clock]: inside its airborne stretch, 19.4 s to 25.4 s."""


def run(*args):
    return CliRunner().invoke(main, [str(a) for a in args])


def sitl_topics() -> tuple[list[Topic], dict, int]:
    """The SITL log's topics that identify reads, as our writer's Topics (fields as the log's formats;
    ``esc_status``, nested, left out)."""
    log = ULog(str(SITL), message_name_filter_list=list(ULOG_TOPICS))
    out = []
    for d in log.data_list:
        if d.multi_id != 0:
            continue
        fields = [(f[0], f[1], f[2]) for f in log.message_formats[d.name].fields]
        if any(kind not in NUMPY_TYPES for kind, _, _ in fields):
            continue  # a nested format (esc_status, at 4 Hz): not read for the paper's vehicle
        values = {}
        for _kind, length, name in fields:
            if name.startswith("_padding"):
                continue
            if length:
                values[name] = np.column_stack([d.data[f"{name}[{i}]"] for i in range(length)])
            else:
                values[name] = d.data[name]
        out.append(Topic(d.name, fields, values))
    return out, dict(log.initial_parameters), int(log.start_timestamp)


def rewrite(path: Path, topic_edit=None, param_edit=None) -> Path:
    topics, params, start = sitl_topics()
    if topic_edit:
        topics = [topic_edit(tp, start) for tp in topics]
    if param_edit:
        param_edit(params)
    write_ulog(path, topics, parameters=params, start_us=start)
    return path


def window(tp: Topic, start: int) -> np.ndarray:
    t = (tp.values["timestamp"].astype(np.float64) - start) * 1e-6
    return (t >= DAMAGED[0]) & (t <= DAMAGED[1])


def with_values(tp: Topic, **values) -> Topic:
    return Topic(tp.name, tp.fields, {**tp.values, **values}, tp.nested)


def nan_quaternions(tp, start):
    if tp.name != "vehicle_attitude":
        return tp
    q = tp.values["q"].astype(np.float64).copy()
    q[window(tp, start)] = np.nan
    return with_values(tp, q=q)


def inf_accelerations(tp, start):
    if tp.name != "sensor_combined":
        return tp
    a = tp.values["accelerometer_m_s2"].astype(np.float64).copy()
    a[window(tp, start), 2] = np.inf
    return with_values(tp, accelerometer_m_s2=a)


def motor_at_five(tp, start):
    if tp.name != "actuator_motors":
        return tp
    u = tp.values["control"].astype(np.float64).copy()
    u[window(tp, start), 0] = 5.0
    return with_values(tp, control=u)


def without_vx(tp, start):
    if tp.name != "vehicle_local_position":
        return tp
    return Topic(tp.name, [f for f in tp.fields if f[2] != "vx"], {k: v for k, v in tp.values.items() if k != "vx"})


def clock_back(path: Path) -> Path:
    """The SITL log with every topic's clock 3 s back from 23 s of the log on (mid-flight), the
    messages in the order they were written (our writer sorts by time: the two stretches are
    written one after the other, under one header)."""
    from quadcruise.io.ulog import ulog_bytes

    topics, params, start = sitl_topics()

    def part(later: bool) -> list[Topic]:
        out = []
        for tp in topics:
            stamps = tp.values["timestamp"].astype(np.int64)
            rows = (stamps - start > 23_000_000) == later
            values = {k: np.asarray(v)[rows] for k, v in tp.values.items()}
            if later:
                values["timestamp"] = (stamps[rows] - 3_000_000).astype(np.uint64)
            out.append(Topic(tp.name, tp.fields, values))
        return out

    empty = [Topic(tp.name, tp.fields, {k: np.asarray(v)[:0] for k, v in tp.values.items()}) for tp in topics]
    head = len(ulog_bytes(empty, parameters=params, start_us=start))
    first = ulog_bytes(part(False), parameters=params, start_us=start)
    then = ulog_bytes(part(True), parameters=params, start_us=start)
    path.write_bytes(first + then[head:])
    return path


def rotor_count(params):
    params["CA_ROTOR_COUNT"] = -1


def rotors_at_centre(params):
    for i in range(params["CA_ROTOR_COUNT"]):
        params[f"CA_ROTOR{i}_PX"] = 0.0
        params[f"CA_ROTOR{i}_PY"] = 0.0


def length_65535(path: Path) -> Path:
    """The SITL log's bytes with one data message's length field, mid-flight, set to 65535."""
    data = bytearray(SITL.read_bytes())
    pos = 16
    while pos + 3 <= len(data):
        length, kind = struct.unpack_from("<HB", data, pos)
        if kind == ord("D") and pos > len(data) // 2:
            struct.pack_into("<H", data, pos, 65535)
            break
        pos += 3 + length
    path.write_bytes(bytes(data))
    return path


ULOG_CASES = {
    "NaN quaternions": (
        lambda p: rewrite(p, nan_quaternions),
        r"vehicle_attitude\.q\[0\] is NaN at t = 21(\.\d+)? s, in the airborne stretch",
    ),
    "inf accelerations": (
        lambda p: rewrite(p, inf_accelerations),
        r"sensor_combined\.accelerometer_m_s2\[2\] is inf at t = 21(\.\d+)? s",
    ),
    "a relative thrust of 5": (
        lambda p: rewrite(p, motor_at_five),
        r"actuator_motors\.control\[0\] at t = 21\.0\d* s: 5 is outside \[0, 1\]",  # the log's sample, not the grid's
    ),
    "CA_ROTOR_COUNT -1": (
        lambda p: rewrite(p, param_edit=rotor_count),
        r"parameter CA_ROTOR_COUNT = -1: a multicopter has 1 to 12 rotors",
    ),
    "a field missing": (lambda p: rewrite(p, without_vx), r"topic vehicle_local_position has no field vx"),
    "every rotor at the centre": (
        lambda p: rewrite(p, param_edit=rotors_at_centre),
        r"CA_ROTOR0\.\.3_PX/PY put every rotor at the centre",
    ),
    "a length field 65535": (
        length_65535,
        r"corrupt PX4 log: the data message at byte \d+ says it is 65535 bytes long",
    ),
    "the clock jumps back": (
        clock_back,
        r"timestamps go back (2\.9\d*|3(\.0\d*)?) s at t = 2[23]\.\d+ s .*not monotonic",
    ),
}


@pytest.mark.parametrize("case", list(ULOG_CASES))
def test_a_damaged_px4_log_is_one_line_exit_2(case, tmp_path):
    make, match = ULOG_CASES[case]
    path = make(tmp_path / "damaged.ulg")
    result = run("identify", path, "--out", tmp_path / "out")
    assert result.exit_code == 2, result.output
    assert result.stdout == ""  # no table, no pyulog complaint
    lines = result.stderr.strip().splitlines()
    assert len(lines) == 1, lines
    assert lines[0].startswith(f"error: {path}: ")
    assert re.search(match, lines[0]), lines
    assert not (tmp_path / "out").exists()


def test_the_rewritten_intact_log_reads_as_the_original():
    """The other direction: the SITL log rewritten with no change reads exactly as itself."""
    import tempfile

    with tempfile.TemporaryDirectory() as folder:
        again = read_flight_log(rewrite(Path(folder) / "intact.ulg"))
    original = read_flight_log(SITL)
    assert np.array_equal(again.t, original.t)
    for name in ("u", "velocity", "quaternion", "rates", "specific_force"):
        assert np.allclose(getattr(again, name), getattr(original, name), rtol=0, atol=1e-6), name
    assert np.array_equal(again.rotors, original.rotors)


def test_the_intact_sitl_log_still_identifies(tmp_path):
    result = run("identify", SITL, "--out", tmp_path / "out")
    assert result.exit_code in (0, 1), result.output  # 1: a model that does not fit (a verdict), not bad input
    assert (tmp_path / "out" / "identify.json").is_file()


@pytest.fixture(scope="module")
def flight_csv(tmp_path_factory):
    """A quadcruise flight as a CSV in quadcruise's frames (duties u1..u4 in [0, 1])."""
    from scipy.spatial.transform import Rotation

    flight = qc.fly("step", "se3", duration=4.0, log_every=4)
    s = flight.states[0]
    q = Rotation.from_euler("ZYX", s[:, [8, 7, 6]]).as_quat()
    table = pd.DataFrame(
        {
            "t": flight.t,
            **{f"u{i + 1}": np.clip(flight.commands[0][:, i], 0, 1) for i in range(4)},
            **dict(zip(("vx", "vy", "vz"), s[:, 3:6].T, strict=True)),
            "qw": q[:, 3],
            "qx": q[:, 0],
            "qy": q[:, 1],
            "qz": q[:, 2],
            **dict(zip(("p", "q", "r"), s[:, 9:12].T, strict=True)),
        }
    )
    path = tmp_path_factory.mktemp("csv") / "flight.csv"
    table.to_csv(path, index=False)
    return path, table


@pytest.mark.parametrize(
    "change,args,match",
    [
        (lambda t: t.iloc[:1], (), r"1 row\(s\): a flight log needs rows over at least 1 s airborne"),
        (
            lambda t: t.assign(**{f"u{i}": 1000 + 1000 * t[f"u{i}"] for i in range(1, 5)}),
            (),
            r"row 2, column u1: 10\d\d\.?\d* is outside \[0, 1\].*--commands pwm:MIN:MAX",
        ),
        (
            lambda t: t.assign(**{f"u{i}": 1000 + 1000 * t[f"u{i}"] for i in range(1, 5)}),
            ("--commands", "pwm:1000:1050"),
            r"column u1: .* is outside \[0, 1\].*outside the PWM range 1000\.\.1050 us",
        ),
    ],
)
def test_a_bad_csv_is_one_line_exit_2(flight_csv, tmp_path, change, args, match):
    _, table = flight_csv
    path = tmp_path / "bad.csv"
    change(table).to_csv(path, index=False)
    result = run("identify", path, *args, "--out", tmp_path / "out")
    assert result.exit_code == 2, result.output
    lines = result.stderr.strip().splitlines()
    assert len(lines) == 1 and lines[0].startswith(f"error: {path}: "), lines
    assert re.search(match, lines[0]), lines
    assert not (tmp_path / "out").exists()


def test_pwm_commands_read_with_their_range_give_the_duties(flight_csv, tmp_path):
    """The other direction: the same PWM CSV with --commands pwm:1000:2000 reads as the duties."""
    path, table = flight_csv
    pwm = tmp_path / "pwm.csv"
    table.assign(**{f"u{i}": 1000 + 1000 * table[f"u{i}"] for i in range(1, 5)}).to_csv(pwm, index=False)
    assert np.allclose(read_flight_log(pwm, commands="pwm:1000:2000").u, read_flight_log(path).u, atol=1e-9)


def test_identify_never_deletes_the_log_it_reads(tmp_path):
    """``identify D/flight.ulg --out D``, D a folder quadcruise wrote: refused before any work, the
    log kept; --force does not change that."""
    folder = tmp_path / "D"
    flown = run("fly", "sysid", "--duration", "2", "--out", folder, "--ulog", tmp_path / "f.ulg")
    assert flown.exit_code == 0, flown.output
    log = folder / "flight.ulg"
    log.write_bytes((tmp_path / "f.ulg").read_bytes())
    before = sorted(p.name for p in folder.iterdir())
    for extra in ((), ("--force",)):
        result = run("identify", log, "--out", folder, *extra)
        assert result.exit_code == 2, result.output
        lines = result.stderr.strip().splitlines()
        assert len(lines) == 1 and "holds the log being read" in lines[0], lines
        assert log.read_bytes() == (tmp_path / "f.ulg").read_bytes()
        assert sorted(p.name for p in folder.iterdir()) == before


def test_the_library_write_never_deletes_the_log_it_read(tmp_path):
    """``IdentifyResult.write(D)`` with the log read inside D (a folder quadcruise wrote, so it
    would be replaced whole): refused in one line before anything is written, ``force`` or not;
    the same result writes to another folder."""
    from quadcruise.errors import InputError

    folder = tmp_path / "D"
    qc.identify(SITL).write(folder)  # D: a folder quadcruise wrote
    log = folder / "flight.ulg"
    log.write_bytes(SITL.read_bytes())
    before = sorted(p.name for p in folder.iterdir())
    result = qc.identify(log)
    for force in (False, True):
        with pytest.raises(InputError, match="holds .*flight.ulg, which this run reads") as caught:
            result.write(folder, force=force)
        assert "\n" not in str(caught.value)
        assert log.read_bytes() == SITL.read_bytes()
        assert sorted(p.name for p in folder.iterdir()) == before
    other = result.write(tmp_path / "E")  # the other direction: elsewhere it writes
    assert (other / "identify.json").is_file() and log.read_bytes() == SITL.read_bytes()


def test_fly_never_deletes_the_scenario_or_vehicle_it_read(tmp_path):
    """``fly D/scenario.toml --out D`` and ``fly ... --vehicle D/vehicle.toml --out D`` (D written
    by quadcruise): refused in one line, exit 2, before flying, the inputs kept; the library's
    ``SimResult.write(D)`` of a flight flown from D's scenario likewise; to another folder it flies."""
    from quadcruise.errors import InputError
    from quadcruise.workflows.scenario import load_scenario

    folder = tmp_path / "D"
    assert run("fly", "hover", "--duration", "0.5", "--out", folder).exit_code == 0
    scenario = folder / "scenario.toml"
    (folder / "vehicle.toml").write_text('[vehicle]\npreset = "paper"\nm = 3.6\n')
    kept = {p.name: p.read_bytes() for p in folder.iterdir() if p.is_file()}
    for args in ((scenario,), ("hover", "--duration", "0.5", "--vehicle", folder / "vehicle.toml")):
        for extra in ((), ("--force",)):
            result = run("fly", *args, "--out", folder, *extra)
            assert result.exit_code == 2, result.output
            lines = result.stderr.strip().splitlines()
            assert len(lines) == 1 and "which this run reads" in lines[0], lines
            assert {p.name: p.read_bytes() for p in folder.iterdir() if p.is_file()} == kept
    flight = load_scenario(scenario).fly()
    with pytest.raises(InputError, match="which this run reads"):
        flight.write(folder)
    assert {p.name: p.read_bytes() for p in folder.iterdir() if p.is_file()} == kept
    elsewhere = run("fly", scenario, "--out", tmp_path / "E")
    assert elsewhere.exit_code == 0, elsewhere.output
    assert (tmp_path / "E" / "scenario.toml").is_file()


def test_a_log_too_short_to_fit_says_how_long_it_needs(tmp_path):
    """3 s of a flight: one line with the seconds usable and the seconds needed, exit 2, nothing
    written; 5 s of the same flight is identified (a verdict, exit 0 or 1)."""
    for seconds, codes in ((3.0, (2,)), (5.0, (0, 1))):
        log = qc.fly("sysid", "nlpd", duration=seconds).to_ulog(tmp_path / f"s{seconds:g}.ulg")
        result = run("identify", log, "--out", tmp_path / f"out{seconds:g}")
        assert result.exit_code in codes, result.output
        if seconds == 3.0:
            lines = result.stderr.strip().splitlines()
            assert len(lines) == 1 and lines[0].startswith(f"error: {log}: 3.0 s airborne is too short"), lines
            assert re.search(r"\d\.\d\d s to fit, \d\.\d\d s held out; at least 2 s and 0\.5 s\)$", lines[0]), lines
            assert not (tmp_path / "out3").exists()
        else:
            assert (tmp_path / "out5" / "identify.json").is_file()


def test_the_thrust_curve_note_names_the_topic_the_commands_came_from(tmp_path):
    """The SITL log read from actuator_motors (relative thrust) and, with that topic left out, from
    actuator_outputs (PWM through THR_MDL_FAC): each note names its own topic."""
    topics, params, start = sitl_topics()
    pwm = tmp_path / "pwm.ulg"
    write_ulog(pwm, [tp for tp in topics if tp.name != "actuator_motors"], parameters=params, start_us=start)
    for log, topic in ((SITL, "actuator_motors"), (pwm, "actuator_outputs")):
        out = tmp_path / topic
        result = run("identify", log, "--out", out)
        assert result.exit_code in (0, 1), result.output
        note = json.loads((out / "identify.json").read_text())["parameters"]["thrust_curve_f"]["note"]
        assert topic in note and ({"actuator_motors", "actuator_outputs"} - {topic}).pop() not in note, note
