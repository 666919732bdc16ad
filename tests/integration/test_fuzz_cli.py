"""Property-based: a bad value for any option of any command, or for any key of a scenario file,
is answered with one line, ``error: ...``, exit status 2, no traceback and no file left behind.

The options are read from the click commands themselves, so a new option is fuzzed as soon as it
exists. Each bad value is chosen to be invalid for its kind of option (garbage for a number, a
missing file for an input, a folder that cannot be written for an output, ...).
"""

from __future__ import annotations

import contextlib
import math
import sys
import tempfile
from pathlib import Path

import click
import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

from quadcruise.cli.main import main, run

BASE = {
    "fly": ["fly", "hover", "--duration", "0.05"],
    "compare": ["compare", "hover", "--controllers", "nlpd", "--duration", "0.05"],
    "analyze": ["analyze"],
    "montecarlo": [
        "montecarlo",
        "--mission",
        "hover",
        "--n",
        "2",
        "--duration",
        "0.05",
        "--mass-spread",
        "0.1",
        "--scheduler",
        "none",
        "--quiet",
    ],
    "replay": ["replay", "pwm.csv", "-o", "states.csv"],
    "reproduce": ["reproduce", "--out", "rep"],
    "tune": [
        "tune",
        "hover",
        "--target",
        "rmse_m=0.1",
        "--budget",
        "1",
        "--popsize",
        "5",
        "--duration",
        "0.05",
        "--quiet",
    ],
}
NUMBER_GARBAGE = ["abc", "", "nan", "inf", "-inf", "-1", "1e999", "0x10", "1,2"]
TEXT_GARBAGE = ["xyz", "=", ",", "foo=", "=1", "1,2,3,4,5,6,7", "@@"]
UNWRITABLE = "/proc/quadcruise/out"
SKIP = {("replay", "pwm_csv"), ("replay", "out")}  # the base's own file arguments, fuzzed below


def options():
    out = []
    for name, cmd in main.commands.items():
        if name not in BASE:
            continue
        for p in cmd.params:
            if isinstance(p, click.Option) and (p.is_flag or p.count):
                continue
            out.append((name, p))
    return out


OPTIONS = options()


def bad_values(command: str, p: click.Parameter) -> list[str]:
    if isinstance(p.type, (click.types.FloatParamType, click.types.IntParamType)):
        return NUMBER_GARBAGE
    if isinstance(p.type, click.Choice):
        return ["xyz", ""]
    if p.name in ("out", "report", "animate"):
        return [UNWRITABLE]
    if p.name in ("scenario", "pwm_csv"):
        return ["missing.toml" if p.name == "scenario" else "missing.csv"]
    if p.name == "mission":
        return ["missing.csv", "missing.toml", "xyz", "circle.txt"]
    return TEXT_GARBAGE


def invoke(args: list[str], capsys) -> tuple[int, str]:
    old = sys.argv
    sys.argv = ["quadcruise", *args]
    try:
        with pytest.raises(SystemExit) as stop:
            run()
    finally:
        sys.argv = old
    out = capsys.readouterr()
    return stop.value.code, out.out + out.err


def with_value(command: str, p: click.Parameter, value: str) -> list[str]:
    args = list(BASE[command])
    if isinstance(p, click.Argument):
        position = 1  # every fuzzed argument is the command's first
        return (
            args[:position]
            + [value]
            + (args[position + 1 :] if len(args) > position and not args[position].startswith("-") else args[position:])
        )
    flag = max(p.opts, key=len)
    if flag in args:  # replace the base's own value
        i = args.index(flag)
        return args[:i] + [flag, value] + args[i + 2 :]
    return args + [flag, value]


def check(args: list[str], capsys) -> None:
    with tempfile.TemporaryDirectory() as tmp, contextlib.chdir(tmp):
        Path("pwm.csv").write_text("t,u1,u2,u3,u4\n0,0.07,0.07,0.07,0.07\n0.1,0.07,0.07,0.07,0.07\n")
        before = sorted(str(p) for p in Path(".").rglob("*"))
        code, output = invoke(args, capsys)
        after = sorted(str(p) for p in Path(".").rglob("*"))
    lines = output.strip().splitlines()
    assert code == 2, f"{args}: exit {code}\n{output[-2000:]}"
    assert len(lines) == 1 and lines[0].startswith("error: "), f"{args}:\n{output[-2000:]}"
    assert after == before, f"{args} left {sorted(set(after) - set(before))}"


@pytest.mark.slow
@settings(
    max_examples=120,
    deadline=None,
    derandomize=True,
    suppress_health_check=[HealthCheck.function_scoped_fixture, HealthCheck.too_slow],
)
@given(data=st.data())
def test_a_bad_value_for_any_option_is_one_line_and_exit_2(data, capsys):
    command, p = data.draw(st.sampled_from([o for o in OPTIONS if (o[0], o[1].name) not in SKIP]), label="option")
    value = data.draw(st.sampled_from(bad_values(command, p)), label="value")
    check(with_value(command, p, value), capsys)


def scenario_keys() -> list[tuple[str, str, str]]:
    """(table, key, kind of value) for every key a scenario file can hold."""
    import dataclasses

    from quadcruise.control import CONTROLLERS
    from quadcruise.missions import MISSIONS
    from quadcruise.model.vehicle import Vehicle
    from quadcruise.workflows.scenario import OFF_WHEN_INFINITE, SIMULATION_KEYS

    keys = [("vehicle", f.name, "number") for f in dataclasses.fields(Vehicle)]
    for name in ("hover", "step", "circle", "square", "sysid"):
        for f in dataclasses.fields(MISSIONS[name]):
            keys.append((f"mission:{name}", f.name, "text" if f.name == "axis" else "number"))
    for name in CONTROLLERS:
        cls = CONTROLLERS[name]
        for f in dataclasses.fields(cls):
            default = getattr(cls(), f.name)
            kind = (
                "table"
                if dataclasses.is_dataclass(default)
                else "text"
                if isinstance(default, str)
                else "flag"
                if isinstance(default, bool)
                else "rows"
                if isinstance(default, tuple)
                else "number"
            )
            keys.append((f"controller:{name}", f.name, kind))
    keys += [
        ("simulation", k, "flag" if t is bool else "bound" if k in OFF_WHEN_INFINITE else "number")
        for k, t in SIMULATION_KEYS.items()
    ]
    keys += [("disturbances", k, "table") for k in ("gust", "turbulence", "rotor_loss", "force", "sensor_noise")]
    return keys


BAD_TOML = {
    "number": ['"xyz"', "[]", "{}", "true", "nan", "inf"],
    "text": ["1", "[]", "true"],
    "bound": ['"xyz"', "[]", "true", "nan", "-inf", "0", "-1"],  # inf turns a bound off: not bad
    "flag": ['"xyz"', "2", "[]"],
    "table": ["1", '"xyz"', "[1, 2]", "{ nonsense = 1 }"],
    "rows": ['"xyz"', "1", "[1, 2]", "[[1, 2, 3]]", "true"],  # a tuple of rows ([] is its default: not bad)
}


@pytest.mark.slow
@settings(
    max_examples=120,
    deadline=None,
    derandomize=True,
    suppress_health_check=[HealthCheck.function_scoped_fixture, HealthCheck.too_slow],
)
@given(data=st.data())
def test_a_bad_value_for_any_scenario_key_is_one_line_and_exit_2(data, capsys):
    table, key, kind = data.draw(st.sampled_from(scenario_keys()), label="key")
    value = data.draw(st.sampled_from(BAD_TOML[kind]), label="value")
    lines = []
    if table.startswith("mission:"):
        lines += ["[mission]", f'kind = "{table.split(":")[1]}"', f"{key} = {value}"]
    elif table.startswith("controller:"):
        lines += ["[controller]", f'name = "{table.split(":")[1]}"', f"{key} = {value}"]
    else:
        lines += [f"[{table}]", f"{key} = {value}"]
    if table != "simulation":
        lines += ["[simulation]", "duration = 0.05"]
    with tempfile.TemporaryDirectory() as tmp:
        path = Path(tmp) / "bad.toml"
        path.write_text("\n".join(lines) + "\n")
        check(["fly", str(path), "--out", str(Path(tmp) / "out")], capsys)


def test_the_fuzzed_options_cover_every_command():
    assert {c for c, _ in OPTIONS} == set(BASE) and len(OPTIONS) > 40
    assert not math.isnan(len(scenario_keys()))
