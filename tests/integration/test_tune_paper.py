"""The gains fitted to the paper's reported transients: shipped in examples/scenarios with the
command that regenerates them, found again by the tuner, and flown by ``quadcruise reproduce``."""

import shlex
from pathlib import Path

import pytest
from click.testing import CliRunner

from quadcruise.cli import main
from quadcruise.workflows.reproduce import FITTED
from quadcruise.workflows.scenario import load_scenario

SCENARIOS = Path(__file__).resolve().parents[2] / "examples" / "scenarios"
FILES = {
    "nlpd (fitted)": SCENARIOS / "paper_fitted_nlpd.toml",
    "gonzalez (fitted)": SCENARIOS / "paper_fitted_gonzalez.toml",
}


def regenerate_command(path: Path) -> list[str]:
    line = next(x for x in path.read_text().splitlines() if x.startswith("# regenerate: "))
    words = shlex.split(line[len("# regenerate: ") :])
    assert words[:2] == ["quadcruise", "tune"]
    return words[1:]


@pytest.mark.parametrize("label", FITTED)
def test_reproduce_flies_the_shipped_gains(label):
    shipped = load_scenario(FILES[label]).controller
    assert FITTED[label]() == shipped


@pytest.mark.slow
@pytest.mark.parametrize("label", FITTED)
def test_the_tuner_finds_the_fitted_gains_again(tmp_path, label):
    res = CliRunner().invoke(main, regenerate_command(FILES[label]) + ["--out", str(tmp_path / "t"), "--quiet"])
    assert res.exit_code == 0, res.output
    assert "every target and requirement met" in res.output
    found, shipped = load_scenario(tmp_path / "t" / "scenario.toml").controller, load_scenario(FILES[label]).controller
    assert found.position.kp == pytest.approx(shipped.position.kp, rel=1e-6)
    assert found.position.kd == pytest.approx(shipped.position.kd, rel=1e-6)
