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
from quadcruise.control.design import PDGains, pd_from_poles
from quadcruise.disturbances import Environment, RotorLoss
from quadcruise.missions import Circle, Step
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
    bound = 1.0 + 4.0 * np.sqrt(2.0) + 2.0  # 1 m + the circle's box diagonal + the 2 m start offset
    assert res.meta["max_track_error_m"] == pytest.approx(bound)
    i = int(np.searchsorted(res.t, res.t_stop[0]))
    assert err[i] > bound >= err[:i].max()  # the first instant beyond it
    assert "lost track" in res.status_text(0) and f"{res.t_stop[0]:.4f}" in res.status_text(0)
    assert np.isfinite(res.metrics()["rmse_m"][0])  # it flew on: metrics still shown


def test_the_tracking_bound_is_settable_and_the_default_ignores_the_start_offset():
    assert fly_quietly("circle", duration=5.0).ok[0]  # starts 2 m off its circle
    short = fly_quietly("circle", duration=0.01, log_every=10)  # however short and sparse the log, the
    assert short.exit_status(0) is ExitStatus.OFF_TRACK  # start offset is no runaway; ending 2 m
    assert short.t_stop[0] == pytest.approx(0.01)  # off its path, it did not fly the circle
    far = np.zeros(16)
    far[:3], far[12:] = (0.0, 30.0, 1.0), qc.Vehicle.paper().hover_duty * 120.0
    back = fly_quietly("hover", x0=far, duration=3.0)  # nor a start far away: it flies on,
    assert back.exit_status(0) is ExitStatus.OFF_TRACK  # but ends 3 s later still far: off track
    tight = fly_quietly("circle", duration=5.0, max_track_error=0.5)
    assert tight.exit_status(0) is ExitStatus.LOST_TRACK and tight.t_stop[0] == 0.0
    assert fly_quietly(
        "circle",
        NLPD(position=pd_from_poles([-1000.0, -2000.0])),
        duration=3.0,
        max_track_error=np.inf,
        max_steady_error=np.inf,
    ).ok[0]
    with pytest.raises(qc.InputError, match="max_track_error"):
        qc.fly("hover", max_track_error=-1.0)


def error_of(res, i=0):
    return np.linalg.norm(res.states[i, :, :3] - res.references[i, :, :3], axis=1)


@pytest.mark.parametrize("case", ["never moves", "circle too fast", "limit cycle at dt 80 ms", "slow 50 m step"])
def test_a_vehicle_that_never_gets_onto_its_path_is_off_track(case):
    fly = {
        "never moves": lambda: fly_quietly("circle", NLPD(position=PDGains(kp=1e-6, kd=1e-3))),
        # 4 pi^2 R / P^2 = 19.7 m/s^2 needs 64 degrees of tilt against a 45 degree limit
        "circle too fast": lambda: fly_quietly(Circle(period=2.0), duration=8.0),
        "limit cycle at dt 80 ms": lambda: fly_quietly(
            Step(size=1.0, time=0.5), "se3", duration=20.0, dt=0.08, max_step=1e-3
        ),
        "slow 50 m step": lambda: fly_quietly(Step(size=50.0), "gonzalez", duration=25.0),
    }[case]
    res = fly()
    bound = res.meta["max_steady_error_m"]
    assert bound == pytest.approx(max(1.0, 0.25 * np.ptp(res.references[0, :, :3], axis=0).max()), rel=1e-3)
    assert res.exit_status(0) is ExitStatus.OFF_TRACK and not res.ok[0] and not res.stopped[0], res.status_text(0)
    m = res.metrics()
    after = m["steady_max_error_m"][0] if np.isfinite(m["steady_max_error_m"][0]) else error_of(res)[-1]
    assert after > bound  # the rule, from the traces
    assert "off track" in res.status_text(0)


def test_off_track_starts_at_the_first_instant_after_the_transient_beyond_the_bound():
    # hover has no transient (the window is the whole flight); a 30 % rotor loss at 3 s pushes it off
    env = Environment(rotor_loss=RotorLoss(rotor=1, fraction=0.3, time=3.0))
    res = fly_quietly("hover", environment=env, duration=10.0, max_steady_error=0.3)
    err = error_of(res)
    assert res.exit_status(0) is ExitStatus.OFF_TRACK, res.status_text(0)
    i = int(np.searchsorted(res.t, res.t_stop[0]))
    assert res.t[i] == res.t_stop[0] > 3.0 and err[i] > 0.3 >= err[:i].max()
    assert res.meta["max_steady_error_m"] == 0.3
    assert fly_quietly("hover", environment=env, duration=10.0, max_steady_error=np.inf).ok[0]
    with pytest.raises(qc.InputError, match="max_steady_error"):
        qc.fly("hover", max_steady_error=0.0)


def test_flights_that_track_are_not_off_track_at_any_yaw_or_size():
    # (the 20 m step with time to arrive: gonzalez's tanh caps its speed near 0.9 m/s)
    for mission, duration in (
        ("hover", None),
        ("step", None),
        ("circle", None),
        ("square", None),
        (Circle(radius=10.0, period=60.0, yaw=2.5), None),
        (Step(size=20.0, axis="y", yaw=-2.0), 40.0),
    ):
        for controller in ("nlpd", "gonzalez", "se3", "cascade"):
            res = fly_quietly(mission, controller, log_every=10, duration=duration)
            assert res.ok[0], (mission, controller, res.status_text(0))


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
        cmp = qc.compare(
            "circle", {"nominal": "nlpd", "fast": NLPD(position=pd_from_poles([-1000.0, -2000.0]))}, duration=6.0
        )
    assert cmp.ok == {"nominal": True, "fast": False}
    assert list(cmp.failed) == ["fast"] and cmp.failed["fast"] == cmp.results["fast"].status_text(0)
    assert cmp.table().loc["fast", "status"].startswith("lost track")
    scenario = tmp_path / "fast.toml"
    scenario.write_text(FAST_AND_NOMINAL)
    bad = RUNNER.invoke(main, ["compare", str(scenario), "--duration", "6", "--out", str(tmp_path / "out")])
    assert bad.exit_code == 1, bad.output
    assert "fast: vehicle 0 lost track" in bad.output and "rmse_m" in bad.output
    assert (tmp_path / "out" / "metrics.csv").exists()  # written before the exit
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
    assert not out.exists()  # refused before any work
    with pytest.raises(qc.InputError, match=r"vehicle 1 \(mass 60 kg\)"):
        qc.fly("hover", vehicle=qc.Vehicle(m=np.array([3.0, 60.0])))


def test_hovering_near_full_duty_warns():
    with pytest.warns(UserWarning, match="hovers at 82 % duty"):
        qc.fly("hover", vehicle=qc.Vehicle.paper().replace(m=40.0), duration=0.5)


def test_fly_and_a_monte_carlo_sweep_judge_a_flight_by_the_same_rule():
    from quadcruise.montecarlo import Population, montecarlo
    from quadcruise.workflows.fly_inputs import hover_state

    # heavy vehicles (hover duty about 0.9) on a 5 m step: some sag off their point, some do not
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        mc = montecarlo(
            Step(size=5.0), "se3", Population(mass_spread=0.04), 24, seed=1, vehicle=qc.Vehicle(m=44.0), duration=12.0
        )
        spec, table = mc.spec, mc.table
        draw = spec.population.draw(spec.seed, 0, 24, spec.vehicle, spec.dt)
        x0 = hover_state(draw.vehicle, 24, spec.mission)
        x0[:, :3] += draw.offsets
        res = qc.fly(
            spec.mission,
            spec.controller,
            vehicle=draw.vehicle,
            duration=spec.duration,
            dt=spec.dt,
            x0=x0,
            controller_vehicle=spec.vehicle,
        )  # the sweep's model error: the nominal 44 kg
    assert res.meta["max_steady_error_m"][0] == spec.max_track_error_m == 1.25  # a quarter of the 5 m step
    assert res.meta["max_altitude_error_m"][0] == spec.max_altitude_error_m == 0.5  # half its 1 m altitude
    failed = np.isin(res.status, [ExitStatus.LOST_TRACK, ExitStatus.OFF_TRACK])
    lost = table["lost_track"].to_numpy()
    # the worst of the two errors after the transient, each over its bound, from fly's full-rate log
    from quadcruise.metrics.batch import transient_batch

    pos, ref = res.states[:, :, :3], res.references[:, :, :3]
    settled = transient_batch(res.t, pos, ref, res.meta["mission"], [])["settled_at"]
    start = np.where(np.isnan(settled), res.t[-1], settled)
    after = np.where(
        res.t[None, :] >= start[:, None] - 1e-12,
        np.maximum(np.linalg.norm(pos - ref, axis=2) / 1.25, np.abs(pos[:, :, 2] - ref[:, :, 2]) / 0.5),
        0.0,
    ).max(axis=1)
    clear = np.abs(after - 1.0) > 0.02  # the sweep's metrics use a sparser log: not at the edge
    assert 4 <= lost.sum() <= 22 and clear.sum() >= 16 and (~lost).sum() >= 2
    assert np.array_equal(failed[clear], lost[clear])
    assert np.array_equal(failed, after > 1.0)  # fly's status is the rule, on its own log


def test_bounds_turned_off_replay_from_the_output_folder(tmp_path):
    from quadcruise.workflows.scenario import load_scenario

    res = fly_quietly(
        "circle",
        NLPD(position=pd_from_poles([-1000.0, -2000.0])),
        duration=3.0,
        max_track_error=np.inf,
        max_steady_error=np.inf,
    )
    res.write(tmp_path / "out")
    again = load_scenario(tmp_path / "out" / "scenario.toml").fly()
    assert res.ok[0] and again.ok[0] and np.array_equal(again.states, res.states, equal_nan=True)
