"""Bad input found by hand, each answered before any work: one line naming what is wrong,
exit status 2, no traceback, nothing written. (tests/integration/test_fuzz_cli.py generates more.)"""

from __future__ import annotations

import sys

import pytest

from quadcruise.cli.main import run


def invoke(args, capsys, monkeypatch) -> tuple[int, str]:
    """The real entry point (its one-line usage errors included): exit status and all output."""
    monkeypatch.setattr(sys, "argv", ["quadcruise", *args])
    with pytest.raises(SystemExit) as stop:
        run()
    out = capsys.readouterr()
    return stop.value.code, out.out + out.err


CASES = [
    (["fly", "circle", "-c", "foo=1"], "nlpd has no parameter 'foo'"),
    (["fly", "circle", "--duration", "1e9"], "control periods"),
    (["fly", "circle", "--duration", "1e5"], "log less often"),
    # inf and nan named by the option, not the library's Python argument ("fly() argument duration")
    (["fly", "circle", "--duration", "inf"], "Invalid value for '--duration'"),
    (["fly", "circle", "--dt", "nan"], "Invalid value for '--dt'"),
    (["fly", "circle", "--max-step", "inf"], "Invalid value for '--max-step'"),
    (["montecarlo", "--n", "2", "--duration", "inf"], "Invalid value for '--duration'"),
    (["fly", "waypoints"], "give its CSV file as the mission"),
    (["fly", "minsnap"], "--smooth"),
    (["fly", "circle", "--smooth"], "--smooth"),
    (["fly", "circle", "--out", "/proc/out"], "cannot write there"),
    (["fly", "circle", "--report", "/proc/r.html"], "cannot write there"),
    (["fly", "circle", "--animate", "/proc/r.gif"], "cannot write there"),
    (["compare", "circle", "--out", "/proc/out"], "cannot write there"),
    (["compare", "circle", "--report", "/proc/r.html"], "cannot write there"),
    (["montecarlo", "--n", "2", "--out", "/proc/out"], "cannot write there"),
    (["analyze", "--out", "/proc/out"], "cannot write there"),
    (["reproduce", "--out", "/proc/out"], "cannot write there"),
    (["replay", "examples/pwm_step.csv", "-o", "/proc/states.csv"], "cannot write there"),
]


@pytest.mark.parametrize("args, words", CASES, ids=[" ".join(a) for a, _ in CASES])
def test_bad_input_is_one_line_and_exit_2_before_any_work(args, words, tmp_path, monkeypatch, capsys):
    monkeypatch.chdir(tmp_path)
    (tmp_path / "examples").mkdir()
    (tmp_path / "examples" / "pwm_step.csv").write_text("t,u1,u2,u3,u4\n0,0.07,0.07,0.07,0.07\n1,0.07,0.07,0.07,0.07\n")
    before = sorted(p.name for p in tmp_path.rglob("*"))
    code, output = invoke(args, capsys, monkeypatch)
    lines = output.strip().splitlines()
    assert code == 2 and len(lines) == 1 and lines[0].startswith("error: ") and words in lines[0], output
    assert sorted(p.name for p in tmp_path.rglob("*")) == before


def test_bare_quadcruise_prints_the_usage(tmp_path):
    import subprocess
    import sys

    run = subprocess.run([sys.executable, "-m", "quadcruise"], capture_output=True, text=True, cwd=tmp_path)
    assert run.returncode == 0 and run.stdout.startswith("Usage: quadcruise") and "error" not in run.stdout + run.stderr


def test_a_vehicle_file_out_of_physical_range_names_the_file_and_key(tmp_path, monkeypatch, capsys):
    """kf = 1e300 (full thrust 3e305 times the Iris's weight) had passed every field check and failed
    later as "allocation matrix rank 3: check the directions and km", with no file named: now one line
    naming the file and 'kf', exit 2, nothing written. The other direction: kf ten times the Iris's
    (full thrust 19 times the weight, a racing quadrotor's) loads."""
    monkeypatch.chdir(tmp_path)
    bad, fast = tmp_path / "bad.toml", tmp_path / "fast.toml"
    bad.write_text('[vehicle]\npreset = "iris"\nkf = 1e300\n')
    fast.write_text('[vehicle]\npreset = "iris"\nkf = 5.84e-5\n')
    code, output = invoke(["fly", "hover", "--vehicle", str(bad), "--duration", "1"], capsys, monkeypatch)
    lines = output.strip().splitlines()
    assert code == 2 and len(lines) == 1 and "bad.toml" in lines[0] and "'kf'" in lines[0], output
    assert "rank" not in lines[0] and sorted(p.name for p in tmp_path.iterdir()) == ["bad.toml", "fast.toml"]
    import quadcruise as qc

    assert qc.Vehicle.load(fast).kf == 5.84e-5
