"""`quadcruise replay`: the file workflow, good and bad input."""

import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest
from click.testing import CliRunner

import quadcruise as qc
from quadcruise.cli import main

EXAMPLE = Path(__file__).resolve().parents[2] / "examples" / "pwm_step.csv"


def run(*args):
    return CliRunner().invoke(main, list(args))


def test_example_replays_and_writes_states(tmp_path):
    out = tmp_path / "states.csv"
    result = run("replay", str(EXAMPLE), "-o", str(out))
    assert result.exit_code == 0, result.output
    header = out.read_text().splitlines()[0]
    assert header == "t,x,y,z,vx,vy,vz,phi,theta,psi,p,q,r,F1,F2,F3,F4"
    data = np.loadtxt(out, delimiter=",", skiprows=1)
    schedule = qc.read_commands(EXAMPLE)
    assert data.shape == (len(schedule.t), 17)
    np.testing.assert_array_equal(data[:, 0], schedule.t)
    np.testing.assert_allclose(
        data, np.column_stack([schedule.t, qc.replay(schedule).states[0]]), rtol=1e-14, atol=1e-14
    )
    assert list(tmp_path.iterdir()) == [out]  # no temporary left behind


BAD = {
    "missing_column": ("t,u1,u2,u3\n0,0.1,0.1,0.1\n1,0.1,0.1,0.1\n", "column(s) 'u4': missing"),
    "not_a_number": (
        "t,u1,u2,u3,u4\n0,0.1,0.1,0.1,0.1\n1,0.1,abc,0.1,0.1\n",
        "line 3, column 'u2': 'abc' is not a number",
    ),
    "nan": ("t,u1,u2,u3,u4\n0,0.1,0.1,0.1,0.1\n1,0.1,0.1,nan,0.1\n", "line 3, column 'u3': value is NaN"),
    "time_not_increasing": (
        "t,u1,u2,u3,u4\n0,0.1,0.1,0.1,0.1\n1,0.1,0.1,0.1,0.1\n1,0.1,0.1,0.1,0.1\n",
        "line 4, column 't': time 1 is not after",
    ),
    "duty_above_one": (
        "t,u1,u2,u3,u4\n0,0.1,0.1,0.1,0.1\n1,1.2,0.1,0.1,0.1\n",
        "line 3, column 'u1': duty 1.2 is outside [0, 1]",
    ),
    "duty_negative": (
        "t,u1,u2,u3,u4\n0,0.1,0.1,0.1,-0.1\n1,0.1,0.1,0.1,0.1\n",
        "line 2, column 'u4': duty -0.1 is outside",
    ),
    "empty": ("", "the file is empty"),
    "header_only": ("t,u1,u2,u3,u4\n", "needs at least two data rows"),
    "ragged": ("t,u1,u2,u3,u4\n0,0.1,0.1,0.1,0.1\n1,0.1,0.1\n", "line 3: has 3 cells"),
}


@pytest.mark.parametrize("case", sorted(BAD))
def test_bad_input_is_one_line_exit_two_no_output(tmp_path, case):
    text, words = BAD[case]
    src = tmp_path / "pwm.csv"
    src.write_text(text)
    out = tmp_path / "states.csv"
    result = run("replay", str(src), "-o", str(out))
    assert result.exit_code == 2
    lines = result.output.strip().splitlines()
    assert len(lines) == 1 and lines[0].startswith("error: "), result.output
    assert words in lines[0]
    assert str(src) in lines[0]
    assert not out.exists()
    assert sorted(p.name for p in tmp_path.iterdir()) == ["pwm.csv"]


def test_missing_file(tmp_path):
    result = run("replay", str(tmp_path / "nope.csv"), "-o", str(tmp_path / "o.csv"))
    assert result.exit_code == 2
    assert result.output.strip() == f"error: {tmp_path / 'nope.csv'}: no such file"


def test_extra_columns_warn(tmp_path):
    src = tmp_path / "pwm.csv"
    src.write_text("t,u1,u2,u3,u4,note\n0,0.1,0.1,0.1,0.1,a\n1,0.1,0.1,0.1,0.1,b\n")
    result = run("replay", str(src), "-o", str(tmp_path / "o.csv"))
    assert result.exit_code == 0
    assert "warning:" in result.output and "note" in result.output


def test_console_script_runs_as_a_process(tmp_path):
    out = tmp_path / "s.csv"
    proc = subprocess.run(
        [sys.executable, "-m", "quadcruise", "replay", str(EXAMPLE), "-o", str(out)], capture_output=True, text=True
    )
    assert proc.returncode == 0, proc.stderr
    bad = subprocess.run(
        [sys.executable, "-m", "quadcruise", "replay", str(tmp_path / "x.csv"), "-o", str(out)],
        capture_output=True,
        text=True,
    )
    assert bad.returncode == 2 and "Traceback" not in bad.stderr


def test_a_long_schedule_names_its_first_bad_row():
    """The checks run over whole arrays and still name the first row at fault."""
    t = np.arange(3000) * 1e-3
    u = np.full((3000, 4), 0.5)
    u[2000, 1], u[2500, 2] = 1.5, np.nan
    with pytest.raises(qc.InputError, match=r"schedule, row 2001, column 'u2': duty 1.5 is outside \[0, 1\]"):
        qc.CommandSchedule(t=t, duties=u)
    t[1200] = t[1199]
    with pytest.raises(qc.InputError, match=r"row 1201, column 't': time 1.199 is not after"):
        qc.CommandSchedule(t=t, duties=u)
