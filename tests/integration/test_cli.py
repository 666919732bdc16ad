"""The command line: fly, compare, analyze; outputs and one-line errors."""

import json
import subprocess
import sys
from pathlib import Path

import numpy as np
import pandas as pd
import pytest
from click.testing import CliRunner

from quadcruise.cli import main
from support.entry import run_entry


def run(*args):
    return CliRunner().invoke(main, [str(a) for a in args])


def test_fly_prints_metrics_and_writes_the_folder(tmp_path):
    out = tmp_path / "flight"
    res = run(
        "fly", "step", "--duration", "4", "--out", out, "--report", tmp_path / "r.html", "--animate", tmp_path / "a.gif"
    )
    assert res.exit_code == 0, res.output
    assert "nlpd on step: 4 s" in res.output and "rise_time_s" in res.output
    assert sorted(p.name for p in out.iterdir()) == [
        "flight.png",
        "metrics.csv",
        "quadcruise.json",
        "scenario.toml",
        "traces.csv",
    ]
    traces = pd.read_csv(out / "traces.csv")
    assert len(traces) == 4001 and list(traces.columns[:5]) == ["vehicle", "t", "x", "y", "z"]
    meta = json.loads((out / "quadcruise.json").read_text())
    assert meta["controller"]["name"] == "nlpd" and meta["mission"]["kind"] == "step" and meta["version"]
    assert (tmp_path / "r.html").read_text().startswith("<!DOCTYPE html>")
    assert (tmp_path / "a.gif").read_bytes()[:6] == b"GIF89a"


def test_fly_parquet(tmp_path):
    pytest.importorskip("pyarrow")
    res = run("fly", "hover", "--duration", "1", "--out", tmp_path / "o", "--format", "parquet")
    assert res.exit_code == 0, res.output
    frame = pd.read_parquet(tmp_path / "o" / "traces.parquet")
    assert np.allclose(frame["z"], 1.0)


def test_fly_controller_options_reach_the_controller(tmp_path):
    res = run(
        "fly",
        "step",
        "--duration",
        "3",
        "--controller",
        "gonzalez",
        "--poles",
        "-1,-2",
        "-c",
        "max_tilt=0.3",
        "-m",
        "size=0.5",
        "--out",
        tmp_path / "o",
    )
    assert res.exit_code == 0, res.output
    meta = json.loads((tmp_path / "o" / "quadcruise.json").read_text())
    assert meta["controller"]["position"] == {"kp": 2.0, "kd": 3.0}
    assert meta["controller"]["max_tilt"] == 0.3 and meta["mission"]["size"] == 0.5


@pytest.mark.parametrize(
    "args, words",
    [
        (["fly", "loop"], "unknown mission 'loop'"),
        (["fly", "circle", "--duration", "-1"], "'--duration': -1.0 is not in the range x>0"),
        (["fly", "circle", "--dt", "30"], "dt (30 s) is larger than the duration (20 s)"),
        (["fly", "circle", "--poles", "0.7,-4.3"], "pole 0.7 is not in the open left half plane"),
        (["fly", "circle", "--poles", "fast"], "--poles 'fast': expected comma-separated poles"),
        (["fly", "circle", "--controller", "pid"], "unknown controller 'pid'"),
        (["fly", "circle", "-m", "radius"], "--mission-param 'radius': expected KEY=VALUE"),
        (["fly", "circle", "-m", "radius=-2"], "circle field 'radius' (circle radius, m) must be > 0"),
        (["fly", "circle", "--animate", "a.png"], "an animation is written as .gif or .mp4"),
        (["fly", "circle", "--bogus"], "No such option '--bogus'"),
        (["compare", "circle", "--controllers", "nlpd,pid"], "unknown controller 'pid'"),
        (["fly", "hover", "--settle-band", "1.5"], "settle_bands must be one or two fractions in (0, 1)"),
        (
            ["compare", "hover", "--settle-band", "0.01", "--settle-band", "0.02", "--settle-band", "0.03"],
            "settle_bands must be one or two fractions",
        ),
        (["fly", "hover", "--rise", "5-95"], "Invalid value for '--rise'"),
        (["montecarlo", "--n", "3", "--require", "steady_max_error<=0.2"], "choose one of rmse_m, max_error_m, steady"),
        (["analyze", "--poles", "0.7,-4"], "pole 0.7 is not in the open left half plane"),
    ],
)
def test_bad_options_are_one_line_with_status_two(args, words, tmp_path):
    """Through the real entry point (click's own usage errors included), in this process
    (support.entry); the next test runs two of them as processes."""
    proc = run_entry(*args, cwd=tmp_path)
    assert proc.returncode == 2, proc.stderr
    lines = proc.stderr.strip().splitlines()
    assert len(lines) == 1 and lines[0].startswith("error: ") and words in lines[0], proc.stderr
    assert not proc.stdout and list(tmp_path.iterdir()) == []


@pytest.mark.parametrize(
    "args, words",
    [
        (["fly", "circle", "--bogus"], "No such option '--bogus'"),  # click's usage error
        (["fly", "circle", "-m", "radius=-2"], "circle field 'radius' (circle radius, m) must be > 0"),  # ours
    ],
)
def test_a_bad_option_ends_the_process_with_one_line_and_status_two(args, words, tmp_path):
    """``python -m quadcruise`` as a process: its exit status, its stderr, nothing written."""
    proc = subprocess.run([sys.executable, "-m", "quadcruise", *args], capture_output=True, text=True, cwd=tmp_path)
    assert proc.returncode == 2, proc.stderr
    assert proc.stderr.count("\n") == 1 and proc.stderr.startswith("error: ") and words in proc.stderr, proc.stderr
    assert not proc.stdout and list(tmp_path.iterdir()) == []


def test_fly_refuses_a_foreign_out_folder(tmp_path):
    (tmp_path / "keep.txt").write_text("mine")
    res = run("fly", "hover", "--duration", "1", "--out", tmp_path)
    assert res.exit_code == 2 and "not written by quadcruise" in res.output
    assert sorted(p.name for p in tmp_path.iterdir()) == ["keep.txt"]


def test_fly_and_compare_take_the_metric_conventions(tmp_path):
    out = tmp_path / "flight"
    res = run("fly", "step", "--duration", "4", "--rise", "0-100", "--settle-band", "0.03", "--out", out)
    assert res.exit_code == 0, res.output
    assert "settling_time_s: 3 % band" in res.output and "rise_time_s: 0-100 % of the step" in res.output
    assert "steady_rmse_m" in res.output and "u_hover = m g / (4 K)" in res.output
    metrics = pd.read_csv(out / "metrics.csv")
    assert {"steady_rmse_m", "steady_max_error_m", "peak_time_s", "settling_time_5pct_s"} <= set(metrics.columns)
    conv = json.loads((out / "quadcruise.json").read_text())["metrics_conventions"]
    assert conv["rise"] == [0.0, 1.0] and conv["settle_bands"] == [0.03, 0.05]
    assert conv["settling_columns"] == {"settling_time_s": 0.03, "settling_time_5pct_s": 0.05}
    plain = run("fly", "step", "--duration", "4")
    assert plain.output != res.output and "rise_time_s: 10-90 % of the step" in plain.output
    res = run(
        "compare",
        "step",
        "--duration",
        "4",
        "--controllers",
        "nlpd,se3",
        "--settle-band",
        "0.01",
        "--settle-band",
        "0.04",
        "--out",
        tmp_path / "c",
        "--report",
        tmp_path / "c.html",
    )
    assert res.exit_code == 0, res.output
    assert "settling_time_4pct_s" in res.output and "settling_time_s: 1 % band" in res.output
    assert "settling_time_4pct_s" in pd.read_csv(tmp_path / "c" / "metrics.csv").columns
    doc = json.loads((tmp_path / "c" / "quadcruise.json").read_text())
    assert doc["metrics_conventions"]["settle_bands"] == [0.01, 0.04] and "steady_rmse_m" in doc["metrics"]["nlpd"]
    page = (tmp_path / "c.html").read_text()
    assert "settling time 1 % [s]" in page and "settling time 4 % [s]" in page


def test_compare_and_analyze(tmp_path):
    res = run("compare", "step", "--duration", "3", "--controllers", "nlpd,gonzalez", "--out", tmp_path / "c")
    assert res.exit_code == 0, res.output
    assert "nlpd" in res.output and "gonzalez" in res.output
    assert (tmp_path / "c" / "comparison.png").stat().st_size > 10_000
    res = run("analyze", "--out", tmp_path / "a")
    assert res.exit_code == 0, res.output
    assert "PM at the input" in res.output
    doc = json.loads((tmp_path / "a" / "analysis.json").read_text())
    assert doc


def test_analyze_takes_a_vehicle(tmp_path):
    """--vehicle: a paper-plant preset is linearised as given; a rotor-plant one as its equivalent "+"
    vehicle with the gains fly designs for its motors (se3's attitude kp = (0.6 w)^2, w = 1/40 ms for
    the Iris), recorded in quadcruise.json."""
    from quadcruise.model.equivalent import paper_equivalent
    from quadcruise.model.rotor_vehicle import RotorVehicle

    docs = {}
    for name in ("paper", "qball-x4", "iris"):
        res = run("analyze", "--controller", "se3", "--vehicle", name, "--out", tmp_path / name)
        assert res.exit_code == 0, res.output
        docs[name] = json.loads((tmp_path / name / "quadcruise.json").read_text())
    iris = paper_equivalent(RotorVehicle.preset("iris"))
    assert docs["iris"]["vehicle"]["omega"] == pytest.approx(iris.omega) == pytest.approx(40.0)
    assert docs["iris"]["vehicle"]["m"] == pytest.approx(1.535)
    assert docs["iris"]["controller"]["attitude"]["kp"] == pytest.approx((0.6 * 40.0) ** 2)
    assert docs["qball-x4"]["vehicle"]["m"] == pytest.approx(1.4)
    assert docs["paper"]["controller"] == docs["qball-x4"]["controller"]  # same motors: same gains
    poles = {k: json.loads((tmp_path / k / "analysis.json").read_text())["loops"]["x"]["poles"] for k in docs}
    assert poles["iris"] != poles["paper"]
    # the Qball-X4 is Table I at 1.4 kg: a controller that knows the mass scales its thrust with it,
    # so the linear loop (per unit mass, same inertia and motors) is the paper vehicle's
    assert np.allclose(poles["qball-x4"], poles["paper"], atol=1e-5)
    res = run("analyze", "--vehicle", "jumbo")
    assert res.exit_code == 2 and "unknown vehicle preset 'jumbo'" in res.output


def test_montecarlo_runs_writes_and_replays_a_case(tmp_path):
    out = tmp_path / "mc"
    args = [
        "montecarlo",
        "-n",
        "6",
        "--duration",
        "2",
        "--mass-spread",
        "0.05",
        "--seed",
        "3",
        "--scheduler",
        "none",
        "--quiet",
    ]
    res = run(*args, "--out", out)
    assert res.exit_code == 0, res.output
    assert "6 flights of nlpd on circle, seed 3" in res.output
    flights = pd.read_csv(out / "flights.csv")
    assert sorted(flights["vehicle"]) == list(range(6))
    assert json.loads((out / "summary.json").read_text())
    case = run(*args, "--case", "4")
    assert case.exit_code == 0, case.output
    row = flights[flights["vehicle"] == 4].iloc[0]
    assert f"{row['rmse_m']:.4g}" in case.output


@pytest.mark.parametrize(
    "args, words",
    [
        (["montecarlo", "-n", "0"], "the number of flights must be a whole number >= 1"),
        (["montecarlo", "--mass-spread", "-0.1"], "'mass_spread' must be a number >= 0"),
        (["montecarlo", "--wind", "tornado:3"], "unknown model 'tornado'"),
        (
            [
                "montecarlo",
                "-n",
                "4",
                "--mass-spread",
                "0.1",
                "--scheduler",
                "tcp://127.0.0.1:9",
                "--connect-timeout",
                "1",
            ],
            "scheduler",
        ),
    ],
)
def test_montecarlo_bad_input(tmp_path, args, words):
    res = run(*args, "--out", tmp_path / "mc")
    assert res.exit_code == 2 and words in res.output, res.output
    assert res.output.count("error:") == 1
    assert not (tmp_path / "mc").exists()


def test_montecarlo_and_reproduce_accept_a_scenario(tmp_path):
    scen = Path(__file__).resolve().parents[2] / "examples" / "scenarios"
    res = run(
        "montecarlo",
        "--scenario",
        scen / "montecarlo_circle.toml",
        "-n",
        "5",
        "--duration",
        "2",
        "--scheduler",
        "none",
        "--quiet",
        "--out",
        tmp_path / "mc",
    )
    assert res.exit_code == 0, res.output
    assert "5 flights of nlpd on circle, seed 1" in res.output  # seed from [montecarlo]
    meta = json.loads((tmp_path / "mc" / "quadcruise.json").read_text())
    assert "0.1" in json.dumps(meta) and "turbulence" in json.dumps(meta)
    # an option given explicitly wins over the scenario, even when it equals the default
    res = run(
        "montecarlo",
        "--scenario",
        scen / "montecarlo_circle.toml",
        "-n",
        "3",
        "--duration",
        "2",
        "--seed",
        "0",
        "--mass-spread",
        "0",
        "--scheduler",
        "none",
        "--quiet",
        "--worst",
        "0",
        "--out",
        tmp_path / "mc0",
    )
    assert res.exit_code == 0, res.output
    assert "3 flights of nlpd on circle, seed 0" in res.output
    meta = json.dumps(json.loads((tmp_path / "mc0" / "quadcruise.json").read_text()))
    assert '"mass_spread": 0.0' in meta and '"inertia_spread": 0.05' in meta
    # the control period too: the scenario's unless --dt is given
    coarse = tmp_path / "coarse.toml"
    coarse.write_text(
        (scen / "montecarlo_circle.toml").read_text().replace("duration = 20.0", "duration = 1.0\ndt = 0.002")
    )
    for extra, dt in (((), 0.002), (("--dt", "0.001"), 0.001)):
        res = run(
            "montecarlo",
            "--scenario",
            coarse,
            "-n",
            "2",
            *extra,
            "--scheduler",
            "none",
            "--quiet",
            "--worst",
            "0",
            "--out",
            tmp_path / f"dt{dt}",
        )
        assert res.exit_code == 0, res.output
        assert json.loads((tmp_path / f"dt{dt}" / "quadcruise.json").read_text())["spec"]["dt"] == dt
    bad = tmp_path / "bad.toml"
    bad.write_text("[montecarlo]\nmass_sprad = 0.1\n")
    res = run("montecarlo", "--scenario", bad, "-n", "2", "--scheduler", "none")
    assert res.exit_code == 2 and "[montecarlo] unknown key(s) mass_sprad" in res.output
    res = run("reproduce", "--scenario", scen / "light_vehicle_square.toml", "--out", tmp_path / "r")
    assert res.exit_code == 0, res.output
    assert json.loads((tmp_path / "r" / "metrics.json").read_text())["config"]["vehicle"]["m"] == 1.4
    assert (
        "with the scenario's vehicle and dt only; not used: [mission], [controller], [simulation] duration"
        in res.output
    )  # not silently


def test_compare_on_the_same_population():
    res = run(
        "compare",
        "step",
        "--duration",
        "9",
        "--controllers",
        "nlpd, gonzalez",
        "--population",
        "5",
        "--mass-spread",
        "0.05",
        "--seed",
        "2",
    )
    assert res.exit_code == 0, res.output
    assert "the same 5 perturbed vehicles (seed 2" in res.output
    table = res.output.split("perturbed vehicles")[1]
    assert "nlpd" in table and "gonzalez" in table and "failure_rate" in table
    # the list is read the same way for both tables: a space after the comma is fine
    assert table.count("nlpd") == 1 and table.count("gonzalez") == 1


def test_a_failed_flights_table_stays_narrow_and_its_reason_is_said_in_full():
    """The status cell holds the kind and the time; the reason (130 characters) is the line
    under the table: it padded every row of the table to about 150 columns."""
    res = run("fly", "circle", "--vehicle", "m=4.549", "--controller-vehicle", "paper")
    assert res.exit_code == 1, res.output
    lines = res.output.splitlines()
    status = next(line for line in lines if line.startswith("status"))
    reason = next(line for line in lines if line.startswith("vehicle 0 did not fly its mission: "))
    kind, why = reason.removeprefix("vehicle 0 did not fly its mission: ").split(": ", 1)
    when = why[why.rindex(" at t = ") :]
    assert len(why) > 80 and " ".join(status.split()[1:]) == f"{kind}{when}", (status, reason)
    table = lines[1 : lines.index(next(line for line in lines if line.startswith("controller_limited_s"))) + 1]
    assert max(map(len, table)) < 60, table


@pytest.mark.parametrize(
    "args",
    [
        ["fly", "hover", "--duration", "0.2", "--out", "F.html", "--report", "F.html"],
        ["fly", "hover", "--duration", "0.2", "--out", "F.ulg", "--ulog", "./F.ulg"],
        ["fly", "hover", "--duration", "0.2", "--report", "r.html", "--animate", "r.html"],
        ["compare", "hover", "--controllers", "nlpd,se3", "--out", "F.html", "--report", "F.html"],
        ["reproduce", "--out", "F.htm", "--report", "F.htm"],
        ["identify", "log.ulg", "--out", "F.html", "--report", "F.html"],
    ],
)
def test_a_file_option_naming_the_out_folder_or_another_file_is_refused_before_any_work(tmp_path, args):
    """The folder and the file would be written one over the other after the work (a report
    written where --out put its folder failed, exit 74, after flying)."""
    proc = run_entry(*args, cwd=tmp_path)
    assert proc.returncode == 2, proc.stderr
    (line,) = proc.stderr.splitlines()
    assert line.startswith("error: --") and "name the same path: give each its own" in line, line
    assert sorted(p.name for p in tmp_path.iterdir()) == []  # nothing flown, nothing written
