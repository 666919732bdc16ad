"""A Monte Carlo over the vehicles a log is consistent with (``montecarlo --population DIR/identify.json``).

A 1.4 kg vehicle of the paper's kind flies ``sysid`` with sensor noise, is identified with its
mass, and the sweep draws each identified parameter from its estimate: the flights' drawn K,
Jxx, Jyy, Jzz, d and omega must centre on the estimates and spread as the 95 % intervals say
(sigma = half-width / 1.96: ~95 % of the draws inside each interval), checked on the sweep's own
table by sample statistics; ``identify.json``'s covariance must come back as the draws'
correlation, and without one the draws are independent (both directions); the sweep's
``scenario.toml`` flies the same vehicles again. Bad inputs are one line.
"""

from __future__ import annotations

import json
import math
import shutil

import numpy as np
import pandas as pd
import pytest
from click.testing import CliRunner

import quadcruise as qc
from quadcruise.cli.main import main
from quadcruise.disturbances import SensorNoise
from quadcruise.errors import InputError
from quadcruise.missions import Sysid
from quadcruise.montecarlo.population import Population

N = 400


def run(*args):
    return CliRunner().invoke(main, [str(a) for a in args])


@pytest.fixture(scope="module")
def identified(tmp_path_factory):
    folder = tmp_path_factory.mktemp("ident")
    vehicle = qc.Vehicle.paper().replace(m=1.4, Jxx=0.02, Jyy=0.025, Jzz=0.035)
    flight = qc.fly(Sysid(), "se3", vehicle=vehicle, sensors=SensorNoise(rate_std=0.01), seed=5)
    result = qc.identify(flight.to_ulog(folder / "flight.ulg"), mass=1.4)
    result.write(folder / "ident")
    return folder / "ident"


def test_the_sweep_spreads_as_the_intervals_say(identified, tmp_path):
    assert json.loads((identified / "identify.json").read_text()).get("verdict", "fits") == "fits"
    out = tmp_path / "mc"
    result = run(
        "montecarlo", "--mission", "hover", "--duration", "0.2", "-n", N, "--seed", 4,
        "--population", identified / "identify.json", "--scheduler", "none", "--quiet", "--out", out,
    )  # fmt: skip
    assert result.exit_code == 0, result.output
    table = pd.read_csv(out / "flights.csv")
    params = json.loads((identified / "identify.json").read_text())["parameters"]
    drawn = [k for k in ("K", "Jxx", "Jyy", "Jzz", "d", "omega") if params[k]["identifiable"]]
    assert len(drawn) >= 5, params
    for name in drawn:
        lo, hi = params[name]["ci95"]
        sigma = (hi - lo) / (2 * 1.959964)
        values = table[name].to_numpy()
        assert abs(values.mean() - params[name]["value"]) < 4 * sigma / math.sqrt(N), name
        assert values.std(ddof=1) == pytest.approx(sigma, rel=4 / math.sqrt(2 * N)), name  # 4 standard errors
        inside = np.mean((values >= lo) & (values <= hi))
        assert abs(inside - 0.95) < 4 * math.sqrt(0.95 * 0.05 / N), (name, inside)
    assert np.allclose(table["m"], 1.4)  # given, not drawn


def test_the_scenario_flies_the_same_vehicles(identified, tmp_path):
    out = tmp_path / "mc"
    args = ("--mission", "hover", "--duration", "0.2", "-n", 30, "--seed", 2, "--scheduler", "none", "--quiet")
    assert run("montecarlo", *args, "--population", identified, "--out", out).exit_code == 0
    again = run(
        "montecarlo", "--scenario", out / "scenario.toml", "--scheduler", "none", "--quiet", "--out", tmp_path / "b"
    )  # noqa: E501
    assert again.exit_code == 0, again.output
    a, b = (pd.read_csv(p / "flights.csv").sort_values("vehicle") for p in (out, tmp_path / "b"))
    for name in ("K", "Jxx", "Jyy", "Jzz", "d", "omega"):
        assert np.array_equal(a[name].to_numpy(), b[name].to_numpy()), name


def test_a_covariance_comes_back_as_the_draws_correlation(identified, tmp_path):
    """identify.json's own covariance (the delta method's): the draws' correlations are its own; a
    covariance written in (Jxx-Jyy 0.8) comes back; without one, the draws are independent."""
    nominal = qc.Vehicle.paper().replace(m=1.4)
    data = json.loads((identified / "identify.json").read_text())
    assert "covariance" in data
    own = Population.from_identification(identified)
    assert own.identified.correlated
    names = list(own.identified.names)
    listed = data["covariance"]["names"]
    at = [listed.index(n) for n in names]
    matrix = np.asarray(data["covariance"]["matrix"])[np.ix_(at, at)]
    expected = matrix / np.sqrt(np.outer(np.diag(matrix), np.diag(matrix)))
    cols = own.draw(seed=3, first=0, count=4000, nominal=nominal).columns
    drawn = np.corrcoef(np.array([cols[n] for n in names]))
    assert np.allclose(drawn, expected, atol=0.06), (names, drawn.round(2), expected.round(2))

    folder = tmp_path / "ident"
    shutil.copytree(identified, folder)
    sig = np.sqrt(np.diag(matrix))
    rho, i, j = 0.8, names.index("Jxx"), names.index("Jyy")
    written = np.diag(sig**2)
    written[i, j] = written[j, i] = rho * sig[i] * sig[j]
    data["covariance"] = {"names": names[::-1], "matrix": written[::-1, ::-1].tolist()}  # its own order
    (folder / "identify.json").write_text(json.dumps(data))
    cols = Population.from_identification(folder).draw(seed=3, first=0, count=4000, nominal=nominal).columns
    assert np.corrcoef(cols["Jxx"], cols["Jyy"])[0, 1] == pytest.approx(rho, abs=0.03)
    assert abs(np.corrcoef(cols["Jxx"], cols["Jzz"])[0, 1]) < 0.06
    assert np.std(cols["Jyy"], ddof=1) == pytest.approx(sig[j], rel=0.05)

    del data["covariance"]
    (folder / "identify.json").write_text(json.dumps(data))
    independent = Population.from_identification(folder)
    assert not independent.identified.correlated
    cols = independent.draw(seed=3, first=0, count=4000, nominal=nominal).columns
    assert abs(np.corrcoef(cols["Jxx"], cols["Jyy"])[0, 1]) < 0.06


def test_bad_identifications_are_one_line(identified, tmp_path):
    per_m = tmp_path / "per_m.json"
    data = json.loads((identified / "identify.json").read_text())
    per_m.write_text(json.dumps({**data, "per_unit_mass": True}))
    with pytest.raises(InputError, match="per unit mass"):
        Population.from_identification(per_m)
    unfit = tmp_path / "unfit.json"
    unfit.write_text(json.dumps({**data, "verdict": "does not fit", "verdict_reasons": ["held-out R^2 ax -0.3"]}))
    with pytest.raises(InputError, match="does not fit the log .held-out R.2 ax -0.3"):
        Population.from_identification(unfit)
    with pytest.raises(InputError, match="no such file"):
        Population.from_identification(tmp_path / "none.json")
    with pytest.raises(InputError, match="inertia_spread.*Jxx.*draws from its estimate"):
        Population.from_identification(identified, inertia_spread=0.1)
    result = run("montecarlo", "--mission", "hover", "-n", 3, "--population", tmp_path / "none.json")
    assert result.exit_code == 2 and len(result.stderr.strip().splitlines()) == 1, result.output
    with pytest.raises(InputError, match="does not have"):
        Population.from_identification(identified).draw(1, 0, 2, qc.Vehicle.preset("iris"))
