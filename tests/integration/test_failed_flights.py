"""A flight that failed says so: in its status, the command line's exit code and its output;
a vehicle that cannot fly is refused before anything flies."""

from __future__ import annotations

import warnings

import numpy as np
import pytest
from click.testing import CliRunner

import quadcruise as qc
from quadcruise.cli import main
from quadcruise.control import NLPD
from quadcruise.control.design import pd_from_poles
from quadcruise.sim.status import ExitStatus

RUNNER = CliRunner()


def fly_quietly(*args, **kwargs):
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        return qc.fly(*args, **kwargs)


def test_a_controller_that_loses_the_circle_is_not_finished():
    res = fly_quietly("circle", NLPD(position=pd_from_poles([-1000.0, -2000.0])), duration=8.0)
    assert res.exit_status(0) is ExitStatus.LOST_TRACK and not res.ok[0] and not res.stopped[0]
    err = np.linalg.norm(res.states[0, :, :3] - res.references[0, :, :3], axis=1)
    bound = 1.0 + 4.0 * np.sqrt(2.0) + 2.0     # 1 m + the circle's box diagonal + the 2 m start offset
    assert res.meta["max_track_error_m"] == pytest.approx(bound)
    i = int(np.searchsorted(res.t, res.t_stop[0]))
    assert err[i] > bound >= err[:i].max()                               # the first instant beyond it
    assert "lost track" in res.status_text(0) and f"{res.t_stop[0]:.4f}" in res.status_text(0)
    assert np.isfinite(res.metrics()["rmse_m"][0])                      # it flew on: metrics still shown


def test_the_tracking_bound_is_settable_and_the_default_ignores_the_start_offset():
    assert fly_quietly("circle", duration=5.0).ok[0]                   # starts 2 m off its circle
    assert fly_quietly("circle", duration=0.01, log_every=1000).ok[0]  # however short and sparse the log
    far = np.zeros(16)
    far[:3], far[12:] = (0.0, 30.0, 1.0), qc.Vehicle.paper().hover_duty * 120.0
    assert fly_quietly("hover", x0=far, duration=3.0).ok[0]             # nor a start far away
    tight = fly_quietly("circle", duration=5.0, max_track_error=0.5)
    assert tight.exit_status(0) is ExitStatus.LOST_TRACK and tight.t_stop[0] == 0.0
    assert fly_quietly("circle", NLPD(position=pd_from_poles([-1000.0, -2000.0])), duration=3.0,
                       max_track_error=np.inf).ok[0]
    with pytest.raises(qc.InputError, match="max_track_error"):
        qc.fly("hover", max_track_error=-1.0)


def test_the_command_line_exits_1_after_printing_the_reason():
    bad = RUNNER.invoke(main, ["fly", "circle", "--poles=-1000,-2000", "--duration", "4"])
    assert bad.exit_code == 1, bad.output
    assert "rmse_m" in bad.output and "did not fly its mission: lost track" in bad.output
    good = RUNNER.invoke(main, ["fly", "step", "--duration", "3"])
    assert good.exit_code == 0, good.output


FAST_AND_NOMINAL = """
[mission]
kind = "circle"
[[compare.controllers]]
name = "nlpd"
[[compare.controllers]]
name = "nlpd"
label = "fast"
position_poles = [-1000, -2000]
"""


def test_compare_names_the_controller_whose_flight_failed_and_exits_1(tmp_path):
    with pytest.warns(UserWarning, match=r"^fast: vehicle 0 lost track"):
        cmp = qc.compare("circle", {"nominal": "nlpd", "fast": NLPD(position=pd_from_poles([-1000.0, -2000.0]))},
                         duration=6.0)
    assert cmp.ok == {"nominal": True, "fast": False}
    assert list(cmp.failed) == ["fast"] and cmp.failed["fast"] == cmp.results["fast"].status_text(0)
    assert cmp.table().loc["fast", "status"].startswith("lost track")
    scenario = tmp_path / "fast.toml"
    scenario.write_text(FAST_AND_NOMINAL)
    bad = RUNNER.invoke(main, ["compare", str(scenario), "--duration", "6", "--out", str(tmp_path / "out")])
    assert bad.exit_code == 1, bad.output
    assert "fast: vehicle 0 lost track" in bad.output and "rmse_m" in bad.output
    assert (tmp_path / "out" / "metrics.csv").exists()            # written before the exit
    good = RUNNER.invoke(main, ["compare", "step", "--controllers", "nlpd,se3", "--duration", "4"])
    assert good.exit_code == 0, good.output


@pytest.mark.parametrize("mass", [60.0, 1e300])
def test_a_vehicle_that_cannot_lift_itself_is_refused_before_flying(mass, tmp_path):
    with pytest.raises(qc.InputError, match="cannot lift itself"):
        qc.fly("hover", vehicle=qc.Vehicle.paper().replace(m=mass))
    scenario = tmp_path / "heavy.toml"
    scenario.write_text(f'[vehicle]\nm = {mass!r}\n\n[mission]\nkind = "hover"\n')
    out = tmp_path / "out"
    run = RUNNER.invoke(main, ["fly", str(scenario), "--out", str(out)])
    assert run.exit_code == 2 and "cannot lift itself" in run.output and "Traceback" not in run.output
    assert not out.exists()                                              # refused before any work
    with pytest.raises(qc.InputError, match=r"vehicle 1 \(mass 60 kg\)"):
        qc.fly("hover", vehicle=qc.Vehicle(m=np.array([3.0, 60.0])))


def test_hovering_near_full_duty_warns():
    with pytest.warns(UserWarning, match="hovers at 82 % duty"):
        qc.fly("hover", vehicle=qc.Vehicle.paper().replace(m=40.0), duration=0.5)
