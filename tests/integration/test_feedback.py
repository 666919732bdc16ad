"""Feedback on long work: bars on stderr for what takes seconds, and one line when numba
compiles (quadcruise.cli.feedback); on a terminal, or forced with QUADCRUISE_PROGRESS=1, and
nothing at all otherwise. The library reports through ``progress(done, total)`` without
changing its results."""

import os
import re
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest
from click.testing import CliRunner

import quadcruise as qc
from quadcruise.cli import main

ENV = "QUADCRUISE_PROGRESS"
COMPILING = "compiling the engine and controllers for this machine, once"
BAR_TEXT = re.compile(r"\r|\d+ ?%|\d+/\d+")  # a carriage return, "40%", "2/5": any progress text


def write_schedule(path: Path, rows: int) -> Path:
    """A hover schedule of ``rows`` rows at 1 kHz."""
    t = np.arange(rows) * 1e-3
    u = np.full((rows, 4), float(qc.Vehicle.paper().hover_duty))
    np.savetxt(path, np.column_stack([t, u]), delimiter=",", header="t,u1,u2,u3,u4", comments="", fmt="%.6g")
    return path


def invoke(monkeypatch, forced: bool, args: list[str]):
    """Run the command line in this process, stdout and stderr apart (stderr is not a
    terminal here: without the variable no bar is drawn, and the plain lines said off a
    terminal are pushed beyond any run, so that a slow host does not print one)."""
    from quadcruise.cli import feedback

    if forced:
        monkeypatch.setenv(ENV, "1")
    else:
        monkeypatch.delenv(ENV, raising=False)
        monkeypatch.setattr(feedback, "LINE_EVERY_S", float("inf"))
    res = CliRunner().invoke(main, [str(a) for a in args])
    assert res.exit_code == 0, res.output
    return res


# each command that can take long: its arguments (tmp_path for "{tmp}") and what its bar says
COMMANDS = {
    "montecarlo": (
        ["montecarlo", "--n", "6", "--duration", "1", "--mass-spread", "0.1", "--scheduler", "none"],
        ["flying", "/6 ["],
    ),
    "compare": (["compare", "step", "--duration", "2", "--controllers", "nlpd,se3"], ["flying", "/2 [", "controller"]),
    "compare-population": (
        ["compare", "step", "--duration", "1", "--controllers", "nlpd,se3", "--population", "3"],
        ["flying the population", "/6 ["],
    ),
    "animate": (
        ["fly", "step", "--duration", "2", "--animate", "{tmp}/flight.gif"],
        ["drawing the animation", "frame"],
    ),
    "replay": (
        ["replay", "{tmp}/long.csv", "-o", "{tmp}/states.csv"],
        ["reading", "flying", "writing", "/5000 [", "row"],
    ),
    "analyze": (["analyze", "--out", "{tmp}/analysis"], ["linearising about hover", "margins", "Bode plots"]),
}


@pytest.mark.parametrize("name", list(COMMANDS))
def test_each_long_command_shows_a_bar_when_asked_and_nothing_otherwise(name, tmp_path, monkeypatch):
    args, words = COMMANDS[name]
    runs = {}
    for forced in (True, False):
        folder = tmp_path / ("shown" if forced else "quiet")
        folder.mkdir()
        write_schedule(folder / "long.csv", 5000)
        res = invoke(monkeypatch, forced, [a.replace("{tmp}", str(folder)) for a in args])
        runs[forced] = res.stdout.replace(str(folder), "{tmp}"), res.stderr
    (shown_out, shown), (quiet_out, quiet) = runs[True], runs[False]
    for word in words:
        assert word in shown, f"{name}: {word!r} not in {shown!r}"
    assert not BAR_TEXT.search(quiet), quiet
    assert not any(word in quiet for word in words), quiet
    if name == "montecarlo":  # its last line says how long it took
        shown_out, quiet_out = shown_out.rsplit("\n", 2)[0], quiet_out.rsplit("\n", 2)[0]
    assert shown_out == quiet_out  # the results are the same, and stdout holds no bar


def test_montecarlo_quiet_draws_no_bar(monkeypatch):
    args = ["montecarlo", "--n", "4", "--duration", "1", "--mass-spread", "0.1", "--scheduler", "none"]
    assert "flying" in invoke(monkeypatch, True, args).stderr
    assert invoke(monkeypatch, True, args + ["--quiet"]).stderr == ""


def test_an_error_starts_on_a_line_of_its_own(tmp_path, monkeypatch):
    """A bar still drawn when the command fails is cleared before ``error: ...``."""
    monkeypatch.setenv(ENV, "1")
    bad = tmp_path / "bad.csv"
    bad.write_text("t,u1,u2,u3,u4\n0,0.5,0.5,0.5,0.5\n1,0.5,abc,0.5,0.5\n")
    res = CliRunner().invoke(main, ["replay", str(bad), "-o", str(tmp_path / "s.csv")])
    assert res.exit_code == 2
    assert "reading" in res.stderr  # the bar was drawn
    assert res.stderr.split("\r")[-1] == f"error: {bad}, line 3, column 'u2': 'abc' is not a number\n"


def test_feedback_follows_the_terminal_unless_the_variable_says(monkeypatch):
    from quadcruise.cli import feedback

    class Terminal:
        def isatty(self):
            return True

        def write(self, text):
            pass

        def flush(self):
            pass

    monkeypatch.delenv(ENV, raising=False)
    assert not feedback.feedback_on()  # pytest's captured stderr
    monkeypatch.setattr(sys, "stderr", Terminal())
    assert feedback.feedback_on()
    monkeypatch.setenv(ENV, "0")
    assert not feedback.feedback_on()
    monkeypatch.undo()
    monkeypatch.setenv(ENV, "1")
    assert feedback.feedback_on()


PIPED = """
import sys
from quadcruise.cli import feedback
feedback.LINE_EVERY_S = float(sys.argv[1])
from quadcruise.cli import main
main(sys.argv[2:])
"""


@pytest.mark.parametrize("every", [0.0, 3600.0])
def test_off_a_terminal_progress_is_said_in_plain_lines_a_log_can_hold(every):
    """stderr a pipe (a CI log): a line every LINE_EVERY_S (0 here: at every chunk) and one at the
    end, no carriage return or bar; work shorter than LINE_EVERY_S writes nothing to stderr."""
    args = ["montecarlo", "--n", "6", "--duration", "1", "--mass-spread", "0.1", "--scheduler", "none"]
    env = {k: v for k, v in os.environ.items() if k != ENV}
    run = subprocess.run(
        [sys.executable, "-c", PIPED, str(every), *args, "--chunk-size", "2"],
        capture_output=True,  # stdout and stderr: pipes
        text=True,
        env=env,
        timeout=600,
    )
    assert run.returncode == 0, run.stderr
    assert "6 flights of nlpd on circle" in run.stdout and "flying" not in run.stdout
    lines = [line for line in run.stderr.splitlines() if line.startswith("flying")]
    if every == 0.0:
        assert "\r" not in run.stderr
        assert [line.split(" (")[0] for line in lines] == [
            "flying: 2 of 6 flights",
            "flying: 4 of 6 flights",
            "flying: 6 of 6 flights",
        ], run.stderr
        assert re.fullmatch(r"flying: 2 of 6 flights \(33 %\) after \d+ s, about \d+ s left", lines[0])
        assert re.fullmatch(r"flying: 6 of 6 flights \(100 %\) in \d+ s", lines[-1])
    else:
        assert lines == [] and not BAR_TEXT.search(run.stderr), run.stderr


def test_the_bar_takes_a_note_for_reuse(capsys, monkeypatch):
    """``Bar(label, unit)`` is any ``progress(done, total)``, with an optional note (a tuner's
    best cost); it closes itself at the end and ignores calls after."""
    from quadcruise.cli.feedback import Bar

    monkeypatch.setenv(ENV, "1")
    bar = Bar("tuning", unit="generation")
    bar(0, 3)
    bar(1, 3, "best cost 0.25")
    drawn = capsys.readouterr().err.split("\r")[-1]
    assert drawn.startswith("tuning") and "1/3" in drawn and "best cost 0.25" in drawn
    bar(3, 3)
    assert bar.closed
    bar(2, 3)
    assert capsys.readouterr().err.strip() == ""  # cleared, and nothing after


def test_compiling_is_said_once_when_numba_compiles_and_only_then(capsys, monkeypatch):
    from numba import njit

    from quadcruise.cli.feedback import compile_notice

    def fresh():
        return njit(lambda x: x + 1)  # a new function: numba compiles it at its first call

    monkeypatch.setenv(ENV, "1")
    with compile_notice():
        fresh()(1)
        fresh()(2.0)
    assert capsys.readouterr().err.count(COMPILING) == 1
    fresh()(3)  # outside: nothing
    monkeypatch.setenv(ENV, "0")
    with compile_notice():
        fresh()(4)
    assert COMPILING not in capsys.readouterr().err


def test_the_command_line_loads_no_engine_before_its_command():
    """Importing the command line compiles nothing (the package exports lazily), so the
    compile line can come before the compiling."""
    code = "import sys, quadcruise.cli.main; print(sorted(m for m in sys.modules if m.startswith('quadcruise.sim')))"
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, check=True).stdout
    assert out.strip() == "[]"


@pytest.mark.slow
def test_a_cold_cache_says_it_compiles_once_and_a_warm_one_says_nothing(tmp_path):
    """With numba's cache empty, the first run says it is compiling (once, before it flies);
    the next run, on the cache the first one left, says nothing."""
    env = {**os.environ, ENV: "1", "NUMBA_CACHE_DIR": str(tmp_path / "numba")}
    cmd = [sys.executable, "-m", "quadcruise", "fly", "hover", "--duration", "0.1"]
    cold = subprocess.run(cmd, env=env, capture_output=True, text=True, timeout=600)
    assert cold.returncode == 0, cold.stderr
    assert cold.stderr.count(COMPILING) == 1 and "s\n" in cold.stderr.split(COMPILING)[1]
    assert "nlpd on hover" in cold.stdout
    warm = subprocess.run(cmd, env=env, capture_output=True, text=True, timeout=600)
    assert warm.returncode == 0 and COMPILING not in warm.stderr and warm.stdout == cold.stdout


# the library: progress(done, total), results unchanged


def calls():
    seen = []
    return seen, lambda done, total: seen.append((done, total))


def test_compare_reports_each_controller():
    seen, progress = calls()
    cmp = qc.compare("step", ["nlpd", "se3"], duration=2.0, progress=progress)
    assert seen == [(0, 2), (1, 2), (2, 2)]
    plain = qc.compare("step", ["nlpd", "se3"], duration=2.0)
    assert cmp.table().equals(plain.table())


def test_compare_population_reports_every_flight():
    from quadcruise.montecarlo import Population
    from quadcruise.montecarlo.compare import compare_population

    seen, progress = calls()
    table = compare_population(
        "step",
        ["nlpd", "se3"],
        Population(mass_spread=0.05),
        n=3,
        seed=1,
        duration=1.0,
        scheduler="none",
        progress=progress,
    )
    assert seen[-1] == (6, 6) and all(t == 6 for _, t in seen) and [d for d, _ in seen] == sorted(d for d, _ in seen)
    plain = compare_population(
        "step", ["nlpd", "se3"], Population(mass_spread=0.05), n=3, seed=1, duration=1.0, scheduler="none"
    )
    assert table.equals(plain)


def test_the_analysis_reports_its_steps():
    from quadcruise.workflows.analysis import linearize

    seen, progress = calls()
    lin = linearize("nlpd", progress=progress)
    assert seen == [(0, 3), (1, 3), (2, 3), (3, 3)]
    np.testing.assert_array_equal(lin.sys.A, linearize("nlpd").sys.A)
    seen.clear()
    rep = lin.summary(progress=progress)
    assert seen == [(k, 4) for k in range(5)] and rep == lin.summary()
    seen.clear()
    lin.plot(loops=False, progress=progress)
    assert seen == [(k, 4) for k in range(5)]


def test_the_animation_reports_each_frame(tmp_path):
    from PIL import Image

    from quadcruise.plots.animate import animate_flight

    res = qc.fly("step", duration=2.0, log_every=10)
    seen, progress = calls()
    animate_flight(res, tmp_path / "a.gif", fps=10, progress=progress)
    assert seen == [(k, 20) for k in range(21)]
    animate_flight(res, tmp_path / "b.gif", fps=10)
    with Image.open(tmp_path / "a.gif") as gif:
        assert gif.n_frames == 20
    assert (tmp_path / "a.gif").read_bytes() == (tmp_path / "b.gif").read_bytes()


def test_replay_reports_rows_read_flown_and_written(tmp_path):
    path = write_schedule(tmp_path / "long.csv", 5000)
    seen, progress = calls()
    schedule = qc.read_duty_csv(path, progress=progress)
    assert seen[0] == (0, 5000) and seen[-1] == (5000, 5000)
    seen.clear()
    res = qc.replay(schedule, progress=progress)
    assert seen == [(0, 5000), (5000, 5000)]
    seen.clear()
    qc.write_states_csv(res, tmp_path / "states.csv", progress=progress)
    assert seen[0] == (0, 5000) and seen[-1] == (5000, 5000) and len(seen) > 2
    # written in blocks, the same bytes as in one go
    whole = tmp_path / "whole.csv"
    np.savetxt(
        whole,
        np.column_stack([res.t, res.states[0]]),
        delimiter=",",
        header="t,x,y,z,vx,vy,vz,phi,theta,psi,p,q,r,F1,F2,F3,F4",
        comments="",
        fmt="%.15g",
    )
    assert (tmp_path / "states.csv").read_bytes() == whole.read_bytes()
