"""Bad inputs found by probing every command (each a traceback, a hang or an answer after the
work before): one line, exit 2, before anything flies, nothing written.

Each runs the entry point in this process (support.entry: its status, stdout and stderr as
a process gives them); tests/integration/test_cli.py runs the same kind of error as a process."""

from __future__ import annotations

import pytest

from support.entry import run_entry

HUGE_PATH = "x,y,z\n0,0,1\n1e300,0,1\n"
SCENARIOS = {
    "name_list": '[controller]\nname = ["nlpd"]\n',
    "kind_list": "[mission]\nkind = []\n",
    "ragged_state": "[simulation]\ninitial_state = [[0,0,1,0,0,0,0,0,0,0,0,0,0,0,0,0],[0,0,1]]\n",
    "state_flag": "[simulation]\ninitial_state = true\n",
    "huge_delay": "[disturbances]\nsensor_noise = { delay = 1e300 }\n",
    "long_delay": "[disturbances]\nsensor_noise = { delay = 1e9 }\n",
}


def quadcruise(*args, cwd):
    return run_entry(*args, cwd=cwd)


@pytest.mark.parametrize(
    "args, words",
    [
        (["fly", "{name_list}"], "unknown controller name ['nlpd']"),
        (["fly", "{kind_list}"], "'kind' must be one of"),
        (["fly", "{ragged_state}"], "equal lists of numbers"),
        (["fly", "{state_flag}"], "'initial_state' must be a list of numbers"),
        (["fly", "{huge_delay}", "--duration", "1"], "sensor field 'delay' (1e+300 s) is longer than the flight (1 s)"),
        (["montecarlo", "-n", "4", "--duration", "1", "--noise", "delay=1e9"], "is longer than the flight (1 s)"),
        (["fly", "{huge_path}"], "flying the path takes inf s"),
        (["fly", "{huge_path}", "--smooth"], "flying the path takes inf s"),
        (["fly", "square", "-m", "speed=1e300", "--duration", "0.1"], "too short a leg to fly"),
        (["fly", "square", "-m", "side=1e-300", "--duration", "0.1"], "too short a leg to fly"),
        (["fly", "circle", "--duration", "0.1", "--out", ".", "--force"], "not this folder or its parent"),
        (["fly", "circle", "--duration", "0.1", "--out", "", "--force"], "an output path is empty"),
        (["fly", "circle", "--duration", "0.1", "--report", ""], "an output path is empty"),
        (["fly", "circle", "--max-step", "0", "--duration", "0.1"], "'--max-step': 0.0 is not in the range x>0"),
        (["fly", "circle", "--max-step", "1e-12", "--duration", "0.1"], "RK4 substeps each"),
        (["replay", "{pwm}", "-o", "{pwm}"], "is the input file"),
        (["replay", "{pwm}", "-o", ""], "an output path is empty"),
        (
            [
                "tune",
                "step",
                "--target",
                "rise_time_s=1",
                "--samples",
                "100000000",
                "--popsize",
                "5",
                "--duration",
                "2",
            ],
            "vehicle-steps, hours of computing",
        ),
        (
            ["tune", "step", "--target", "rise_time_s=1", "--dt", "0", "--duration", "2"],
            "'--dt': 0.0 is not in the range",
        ),
        (["fly", "circle", "--duration", "100000", "--dt", "0.0001"], "log less often"),  # said at once, not after 23 s
        (["replay", "{long_pwm}", "-o", "s.csv"], "RK4 substeps, hours of computing"),
        (["replay", "{pwm}", "-o", "s.csv", "--max-step", "1e-12"], "RK4 substeps, hours of computing"),
        (
            ["montecarlo", "--scheduler", "none", "-n", "100000000000", "--mass-spread", "0.1", "--out", "mc"],
            "days of computing",
        ),
        (["compare", "circle", "--controllers", "nlpd", "--population", "100000000000"], "days of computing"),
        (["fly", "circle", "--report", "r.txt"], "the file is written as .html or .htm"),
        (["replay", "{pwm}", "-o", "s.parquet"], "the file is written as .csv"),
        (["fly", "circle", "--force"], "--force shapes the --out folder"),
        (["compare", "circle", "--force"], "--force shapes the --out folder"),
        (["fly", "circle", "--controller", ""], "unknown controller ''"),
        (["compare", "circle", "--controllers", "nlpd,,se3"], "an empty name"),
        (["fly", "{folder}"], "is a folder, not a file"),
        (["analyze", "--dt", "1e-12"], "would lie within rounding of 1"),  # it answered UNSTABLE
    ],
)
def test_probed_bad_input_is_one_line_exit_2_and_writes_nothing(tmp_path, args, words):
    (tmp_path / "folder.csv").mkdir()
    files = {
        "huge_path": ("huge.csv", HUGE_PATH),
        "pwm": ("pwm.csv", "t,u1,u2,u3,u4\n0,0.3,0.3,0.3,0.3\n1,0.3,0.3,0.3,0.3\n"),
        "long_pwm": ("long.csv", "t,u1,u2,u3,u4\n0,0.3,0.3,0.3,0.3\n1e12,0.3,0.3,0.3,0.3\n"),
        **{k: (f"{k}.toml", v) for k, v in SCENARIOS.items()},
    }
    names = {"folder": "folder.csv"}
    for key, (name, text) in files.items():
        (tmp_path / name).write_text(text)
        names[key] = name
    before = sorted(p.name for p in tmp_path.iterdir())
    proc = quadcruise(*(a.format(**names) for a in args), cwd=tmp_path)
    assert proc.returncode == 2, proc.stdout + proc.stderr
    lines = proc.stderr.strip().splitlines()
    assert len(lines) == 1 and lines[0].startswith("error: ") and words in lines[0], proc.stderr
    assert "Traceback" not in proc.stdout + proc.stderr and not proc.stdout.strip()  # nothing flew
    assert sorted(p.name for p in tmp_path.iterdir()) == before


@pytest.mark.parametrize(
    "args, words",
    [
        (["compare", "circle", "--mass-spread", "0.2"], "--mass-spread describes the population that --population N"),
        (["fly", "circle", "-m", "radius=3", "-m", "radius=4"], "'radius' is given twice"),
        (
            ["tune", "step", "--target", "rise_time_s=1", "--bounds", "position.kp=1:2", "--bounds", "position.kp=3:4"],
            "position.kp is bounded twice",
        ),
    ],
)
def test_an_option_that_would_change_nothing_or_is_given_twice_is_refused(tmp_path, args, words):
    proc = quadcruise(*args, cwd=tmp_path)
    assert proc.returncode == 2, proc.stdout + proc.stderr
    assert proc.stderr.strip().splitlines() == [proc.stderr.strip()] and words in proc.stderr


POPULATION_SCENARIO = (
    '[vehicle]\nm = 1.4\n[mission]\nkind = "step"\nsize = 1.0\n[disturbances]\nwind = [4.0, 0.0, 0.0]\n'
)


def test_options_given_with_a_scenario_win_and_the_scenario_fills_the_rest(tmp_path):
    from click.testing import CliRunner

    from quadcruise.cli import main

    scenario = tmp_path / "pop.toml"
    scenario.write_text(POPULATION_SCENARIO + '[controller]\nname = "gonzalez"\n')
    run = CliRunner().invoke
    # montecarlo: --mission and --controller replace the scenario's; left out, the scenario's fly
    res = run(
        main,
        [
            "montecarlo",
            "--scenario",
            str(scenario),
            "--mission",
            "square",
            "--controller",
            "se3",
            "-n",
            "2",
            "--offset",
            "0.01",
            "--duration",
            "2",
            "--quiet",
        ],
    )
    assert res.exit_code == 0 and "2 flights of se3 on square" in res.output, res.output
    res = run(
        main, ["montecarlo", "--scenario", str(scenario), "-n", "2", "--duration", "2", "--offset", "0.01", "--quiet"]
    )
    assert res.exit_code == 0 and "2 flights of gonzalez on step" in res.output, res.output
    # tune: --controller replaces the scenario's; -c alone changes the scenario's controller
    tuned = [
        run(
            main,
            [
                "tune",
                str(scenario),
                *extra,
                "--target",
                "rise_time_s=3",
                "--budget",
                "1",
                "--popsize",
                "5",
                "--duration",
                "6",
                "--quiet",
            ],
        )
        for extra in (["--controller", "nlpd", "--gains", "position.kp"], ["-c", "max_tilt=0.5", "--gains", "accel_p"])
    ]
    assert "tuned nlpd on step" in tuned[0].output and "tuned gonzalez on step" in tuned[1].output, tuned[1].output
    # compare --population: the scenario's vehicle and wind act on the population too
    res = run(main, ["compare", str(scenario), "--controllers", "nlpd", "--population", "2", "--mass-spread", "0.001"])
    assert res.exit_code == 0, res.output
    nominal = float(next(ln for ln in res.output.splitlines() if ln.startswith("rmse_m")).split()[1])
    population = float(next(ln for ln in res.output.splitlines() if ln.startswith("nlpd ")).split()[3])
    assert population == pytest.approx(nominal, rel=0.01)  # the same vehicle in the same wind


def test_a_byte_order_mark_is_read_as_nothing(tmp_path):
    bom = "\ufeff"
    (tmp_path / "path.csv").write_text(bom + "x,y,z\n0,0,1\n1,0,1\n", encoding="utf-8")
    (tmp_path / "duties.csv").write_text(
        bom + "t,u1,u2,u3,u4\n0,0.07,0.07,0.07,0.07\n0.05,0.07,0.07,0.07,0.07\n", encoding="utf-8"
    )
    (tmp_path / "s.toml").write_text(bom + '[mission]\nkind = "hover"\n', encoding="utf-8")
    for args in (
        ["fly", "path.csv", "--duration", "1"],
        ["replay", "duties.csv", "-o", "s.csv"],
        ["fly", "s.toml", "--duration", "0.5"],
    ):
        proc = quadcruise(*args, cwd=tmp_path)
        assert proc.returncode == 0, proc.stderr


def test_another_command_does_not_replace_a_monte_carlo_sweep_unless_forced(tmp_path):
    assert (
        quadcruise(
            "montecarlo", "-n", "2", "--duration", "1", "--mass-spread", "0.1", "--out", "mc", "--quiet", cwd=tmp_path
        ).returncode
        == 0
    )
    proc = quadcruise("fly", "hover", "--duration", "0.5", "--out", "mc", cwd=tmp_path)
    assert proc.returncode == 2 and "holds a Monte Carlo sweep" in proc.stderr
    assert (tmp_path / "mc" / "chunks").is_dir()
    assert quadcruise("fly", "hover", "--duration", "0.5", "--out", "mc", "--force", cwd=tmp_path).returncode == 0
    assert not (tmp_path / "mc" / "chunks").exists()


BASES = {
    "fly": ["fly", "hover", "--duration", "0.5"],
    "compare": ["compare", "hover", "--controllers", "nlpd", "--duration", "0.5"],
    "tune": ["tune", "hover", "--target", "rmse_m=0.1", "--budget", "1", "--popsize", "5", "--duration", "0.5"],
    "montecarlo": [
        "montecarlo",
        "--mission",
        "hover",
        "-n",
        "2",
        "--mass-spread",
        "0.1",
        "--duration",
        "0.5",
        "--scheduler",
        "none",
    ],
}


@pytest.mark.parametrize("command", sorted(BASES))
@pytest.mark.parametrize(
    "args, words",
    [
        (["--vehicle", "jumbo"], "--vehicle 'jumbo': unknown vehicle preset 'jumbo' (known: paper, "),
        (["--vehicle", "m=-1"], "--vehicle 'm=-1': vehicle field 'm' (mass, kg) must be > 0"),
        (["--vehicle", "mass=1.4"], "--vehicle 'mass=1.4': unknown key 'mass'"),
        (["--vehicle", "m=1,2"], "m must be one number"),
        (["--vehicle", "missing.toml"], "--vehicle missing.toml: no such file"),
        (["--controller-vehicle", "m=abc"], "--controller-vehicle"),
        (["--vehicle", "m=100"], "cannot lift itself"),
        (["--turbulence", "hurricane"], "--turbulence 'hurricane'"),
        (["--turbulence", "moderate", "--wind", "dryden:light"], "give it once"),
        (["--wind", "tornado:3"], "unknown model 'tornado'"),
        (["--log-every", "0"], "--log-every must be a whole number >= 1"),
    ],
)
def test_a_bad_vehicle_or_world_option_is_one_line_exit_2_on_every_command(tmp_path, command, args, words):
    proc = quadcruise(*BASES[command], *args, cwd=tmp_path)
    assert proc.returncode == 2, proc.stdout + proc.stderr
    lines = proc.stderr.strip().splitlines()
    assert len(lines) == 1 and lines[0].startswith("error: ") and words in lines[0], proc.stderr
    assert not proc.stdout.strip() and list(tmp_path.iterdir()) == []


@pytest.mark.parametrize(
    "args",
    [
        ["fly", "circle", "-m", "m=1.4"],
        ["compare", "circle", "-m", "m=1.4"],
        ["tune", "circle", "-m", "m=1.4", "--target", "rmse_m=0.1"],
    ],
)
def test_a_vehicle_field_given_to_the_mission_points_to_vehicle(tmp_path, args):
    proc = quadcruise(*args, cwd=tmp_path)
    assert proc.returncode == 2 and proc.stderr.strip() == (
        "error: -m m=1.4: m is a field of the vehicle, not of the mission: give it as --vehicle m=1.4"
    ), proc.stderr


@pytest.mark.parametrize(
    "args",
    [
        ["montecarlo", "--mission", "circle", "--n", "10000", "--seed", "1"],
        ["montecarlo", "--mission", "hover", "-n", "5", "--wind", "constant:2,0,0"],
        ["compare", "hover", "--population", "4", "--mass-spread", "0"],
    ],
)
def test_a_population_that_perturbs_nothing_is_refused_with_a_hint(tmp_path, args):
    proc = quadcruise(*args, cwd=tmp_path)
    assert proc.returncode == 2, proc.stdout + proc.stderr
    assert proc.stderr.startswith("error: the population perturbs nothing") and "--mass-spread" in proc.stderr
    assert len(proc.stderr.strip().splitlines()) == 1 and not proc.stdout.strip()


@pytest.mark.parametrize(
    "extra",
    [
        ["--mass-spread", "0.1"],
        ["--offset", "0.05"],
        ["--turbulence", "light"],
        ["--noise", "position=0.01"],
        ["--wind-spread", "0.5"],
    ],
)
def test_a_population_that_perturbs_something_flies(tmp_path, extra):
    proc = quadcruise(
        "montecarlo",
        "--mission",
        "hover",
        "-n",
        "3",
        "--duration",
        "1",
        "--scheduler",
        "none",
        "--quiet",
        *extra,
        cwd=tmp_path,
    )
    assert proc.returncode == 0 and "3 flights of nlpd on hover" in proc.stdout, proc.stderr


def test_reproduce_replaces_only_its_own_folder_unless_forced(tmp_path):
    from quadcruise.io.files import MARKER, check_output_dir

    assert quadcruise("fly", "hover", "--duration", "0.5", "--out", "f", cwd=tmp_path).returncode == 0
    before = sorted(p.name for p in (tmp_path / "f").iterdir())
    proc = quadcruise("reproduce", "--out", "f", cwd=tmp_path)
    assert proc.returncode == 2 and proc.stderr.strip() == (
        "error: f: holds the output of quadcruise fly, not of reproduce; "
        "use --force to replace it or choose another --out"
    )
    assert sorted(p.name for p in (tmp_path / "f").iterdir()) == before
    (tmp_path / "r").mkdir()
    (tmp_path / "r" / MARKER).write_text('{"workflow": "reproduce"}')
    assert check_output_dir(tmp_path / "r", workflow="reproduce") == tmp_path / "r"  # its own: replaced
    assert check_output_dir(tmp_path / "f", True, workflow="reproduce") == tmp_path / "f"  # forced
