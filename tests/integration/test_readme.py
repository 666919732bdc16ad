"""The README's Python example, saved as a script and run with ``python example.py``, runs."""

from __future__ import annotations

import re
import shutil
import subprocess
import sys
from pathlib import Path

import pytest

from support.entry import run_entry

ROOT = Path(__file__).parents[2]


@pytest.mark.slow
def test_readme_python_example_runs_as_a_script(tmp_path):
    text = (ROOT / "README.md").read_text()
    blocks = re.findall(r"```python\n(.*?)```", text, re.S)
    assert blocks, "the README has a Python example"
    shutil.copytree(ROOT / "examples", tmp_path / "examples")
    script = tmp_path / "example.py"
    script.write_text("import matplotlib\nmatplotlib.use('Agg')\n" + "\n".join(blocks))
    run = subprocess.run([sys.executable, str(script)], cwd=tmp_path, capture_output=True, text=True, timeout=600)
    assert run.returncode == 0, run.stderr[-3000:]
    assert "Traceback" not in run.stderr
    # every flight that warns is one the README says fails, and how (the robustness example: off track)
    warned = re.findall(r"FlightWarning: (?:[^\n]*?: )?vehicle \d+ (\w+ \w+)", run.stderr)
    said = [ln for ln in text.splitlines() if "# off track: ..." in ln]
    assert warned == ["off track"] and len(said) == 1, run.stderr[-3000:]
    assert "off track: the position or altitude error after the transient" in run.stdout
    assert "flights of nlpd on circle" in run.stdout  # the Monte Carlo summary, as a table
    assert (tmp_path / "mc-out" / "quadcruise.json").is_file()
    assert "every target and requirement met" in run.stdout  # the tune example meets what it asks for


def readme_command(name: str) -> list[str]:
    """The README table's example of a command, its optional [...] parts left out."""
    text = (ROOT / "README.md").read_text()
    line = next(ln for ln in text.splitlines() if ln.startswith(f"| `quadcruise {name} "))
    command = line.split("`")[1]
    return re.sub(r"\s*\[[^\[\]]*\]", "", command).split()[1:]


@pytest.mark.slow
def test_readme_tune_and_montecarlo_commands_do_what_the_table_says(tmp_path):
    """Run as written (the Monte Carlo with fewer flights, in this process): the tune meets its
    targets and exits 0; the population is perturbed (its quantiles differ)."""

    def quadcruise(args):
        return run_entry(*args, cwd=tmp_path)  # the entry point, in this process (support.entry)

    tune = readme_command("tune")
    assert "--target" in tune and "DIR" in tune
    run = quadcruise([("out" if word == "DIR" else word) for word in tune])
    assert run.returncode == 0, run.stdout + run.stderr
    assert "every target and requirement met" in run.stdout and (tmp_path / "out" / "scenario.toml").is_file()
    again = quadcruise(["fly", "out/scenario.toml"])  # the folder flies the tuned gains
    assert again.returncode == 0, again.stderr

    montecarlo = readme_command("montecarlo")
    assert montecarlo[montecarlo.index("--n") + 1] == "10000"
    montecarlo[montecarlo.index("--n") + 1] = "20"
    run = quadcruise(montecarlo + ["--scheduler", "none", "--quiet"])
    assert run.returncode == 0, run.stdout + run.stderr
    row = next(ln for ln in run.stdout.splitlines() if ln.strip().startswith("rmse_m")).split()
    count, p5, p50, p95 = int(row[1]), *map(float, row[2:5])
    assert 10 <= count <= 20 and p5 < p50 < p95, row  # those that kept track (a sag beyond
    # half the altitude is off track)
