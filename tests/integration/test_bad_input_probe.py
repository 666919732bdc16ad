"""Bad inputs found by probing every command (each a traceback, a hang or an answer after the
work before): one line, exit 2, before anything flies, nothing written."""

from __future__ import annotations

import subprocess
import sys

import pytest

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
    return subprocess.run([sys.executable, "-m", "quadcruise", *map(str, args)], capture_output=True, text=True,
                          cwd=cwd, timeout=120)


@pytest.mark.parametrize("args, words", [
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
    (["fly", "circle", "--max-step", "0", "--duration", "0.1"], "max_step must be a positive number"),
    (["fly", "circle", "--max-step", "1e-12", "--duration", "0.1"], "RK4 substeps each"),
    (["replay", "{pwm}", "-o", "{pwm}"], "is the input file"),
    (["replay", "{pwm}", "-o", ""], "an output path is empty"),
    (["tune", "step", "--target", "rise_time_s=1", "--samples", "100000000", "--popsize", "5", "--duration", "2"],
     "vehicle-steps, hours of computing"),
    (["tune", "step", "--target", "rise_time_s=1", "--dt", "0", "--duration", "2"], "dt must be a positive number"),
])
def test_probed_bad_input_is_one_line_exit_2_and_writes_nothing(tmp_path, args, words):
    files = {"huge_path": ("huge.csv", HUGE_PATH), "pwm": ("pwm.csv", "t,u1,u2,u3,u4\n0,0.3,0.3,0.3,0.3\n1,0.3,0.3,0.3,0.3\n"),
             **{k: (f"{k}.toml", v) for k, v in SCENARIOS.items()}}
    names = {}
    for key, (name, text) in files.items():
        (tmp_path / name).write_text(text)
        names[key] = name
    before = sorted(p.name for p in tmp_path.iterdir())
    proc = quadcruise(*(a.format(**names) for a in args), cwd=tmp_path)
    assert proc.returncode == 2, proc.stdout + proc.stderr
    lines = proc.stderr.strip().splitlines()
    assert len(lines) == 1 and lines[0].startswith("error: ") and words in lines[0], proc.stderr
    assert "Traceback" not in proc.stdout + proc.stderr and not proc.stdout.strip()      # nothing flew
    assert sorted(p.name for p in tmp_path.iterdir()) == before
