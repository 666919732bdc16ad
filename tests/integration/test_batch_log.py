"""A batch that fits in memory (issue 26, item 6): a batch whose whole log would exceed
``LOG_BUDGET`` keeps every ``log_every``-th period, says so, and still judges every vehicle at
every period, to the same statuses and times as the full log (``log_every=1``, the checks of
``fly.mark_lost_track`` and ``fly.mark_off_track``); the kept log is the full log's rows."""

from __future__ import annotations

import warnings

import numpy as np
import pytest

import quadcruise as qc
from quadcruise.control import NLPD
from quadcruise.control.design import PDGains, pd_from_poles
from quadcruise.disturbances import Environment, RotorLoss, SensorNoise, Turbulence, with_drag
from quadcruise.errors import LogWarning
from quadcruise.missions import Circle, Step
from quadcruise.sim.status import ExitStatus
from quadcruise.workflows import fly_inputs
from quadcruise.workflows.fly_inputs import batch_log_every, hover_state, log_bytes

FIN, LOST, OFF = int(ExitStatus.FINISHED), int(ExitStatus.LOST_TRACK), int(ExitStatus.OFF_TRACK)


def quiet(*args, **kwargs):
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        return qc.fly(*args, **kwargs)


def full_and_watched(monkeypatch, *args, **kwargs):
    """The flight with its whole log (the checks on it), and as a default batch over a tiny budget."""
    full = quiet(*args, log_every=1, **kwargs)
    monkeypatch.setattr(fly_inputs, "LOG_BUDGET", 1)
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        watched = qc.fly(*args, **kwargs)
    monkeypatch.undo()
    said = [w for w in caught if issubclass(w.category, LogWarning)]
    assert len(said) == 1 and "\n" not in str(said[0].message), [str(w.message) for w in caught]
    every = watched.meta["log_every"]
    assert every > 1 and f"every {every} periods" in str(said[0].message)
    for name in ("states", "commands", "references"):  # the kept log is the full log's rows
        assert np.array_equal(getattr(full, name)[:, ::every], getattr(watched, name), equal_nan=True), name
    assert np.array_equal(full.t[::every], watched.t)
    assert np.array_equal(full.final_state, watched.final_state) and np.array_equal(full.memory, watched.memory)
    assert watched.meta["log_every_chosen"]
    if isinstance(watched.meta["mission"], dict):  # (a list of missions has no scenario file)
        assert "log_every" not in watched.scenario_toml()  # a scenario file flown again chooses it again
    return full, watched


def same_verdict(full, watched):
    assert full.status.tolist() == watched.status.tolist()
    assert np.array_equal(full.t_stop, watched.t_stop)


def test_a_circle_batch_where_some_lose_track_some_never_get_on_and_the_rest_fly(monkeypatch):
    controllers = [
        NLPD(position=pd_from_poles([-1000.0, -2000.0])),  # too fast for its plant: loses the circle
        NLPD(),
        NLPD(position=PDGains(kp=1e-6, kd=1e-3)),  # never moves: off track from the start
        NLPD(),
        NLPD(position=pd_from_poles([-1000.0, -2000.0])),
        NLPD(),
    ]
    full, watched = full_and_watched(monkeypatch, "circle", controllers, duration=4.0)
    same_verdict(full, watched)
    assert full.status.tolist() == [LOST, FIN, OFF, FIN, LOST, FIN]  # both directions
    assert 0.0 < full.t_stop[0] < 4.0 and full.t_stop[2] == 4.0  # it never settled: judged at the end


def test_rotor_losses_at_known_times_push_hovering_vehicles_off_track_after_them(monkeypatch):
    env = Environment(
        rotor_loss=RotorLoss(rotor=1, fraction=np.array([0.3, 0.0, 0.3, 0.05]), time=np.array([1.0, 1.0, 3.0, 1.0]))
    )
    full, watched = full_and_watched(monkeypatch, "hover", environment=env, duration=5.0, max_steady_error=0.3, n=4)
    same_verdict(full, watched)
    assert full.status.tolist() == [OFF, FIN, OFF, FIN]
    assert 1.0 < full.t_stop[0] < 3.0 < full.t_stop[2] < 5.0  # after each loss, not before


def test_steps_that_settle_that_sag_and_that_are_too_slow(monkeypatch):
    masses = qc.Vehicle.paper().m * np.array([1.0, 1.2, 1.7, 0.9])  # a heavy one sags below half its altitude
    full, watched = full_and_watched(
        monkeypatch, Step(size=1.0, time=0.5), "nlpd", vehicle=qc.Vehicle(m=masses), duration=5.0
    )
    same_verdict(full, watched)
    assert FIN in full.status.tolist()
    slow, _ = full_and_watched(monkeypatch, Step(size=50.0), "gonzalez", duration=25.0, n=2)
    assert slow.status.tolist() == [OFF, OFF]
    same_verdict(
        *full_and_watched(monkeypatch, Step(size=1.0, time=0.5), "se3", duration=20.0, dt=0.08, max_step=1e-3, n=2)
    )


def test_a_start_away_from_a_still_reference(monkeypatch):
    x0 = hover_state(qc.Vehicle.paper(), 4, qc.missions.Hover())
    x0[:, 0] = [0.0, 0.5, 3.0, 8.0]  # 8 m away is beyond the tracking bound at once
    full, watched = full_and_watched(monkeypatch, "hover", x0=x0, duration=3.0)
    same_verdict(full, watched)
    assert full.status.tolist()[0] == FIN and full.status.tolist()[-1] != FIN


def test_a_fast_circle_and_a_square_with_a_mass_spread(monkeypatch):
    same_verdict(*full_and_watched(monkeypatch, Circle(period=2.0), duration=8.0, n=2))
    masses = qc.Vehicle.paper().m * np.linspace(0.8, 1.6, 5)
    same_verdict(*full_and_watched(monkeypatch, "square", "gonzalez", vehicle=qc.Vehicle(m=masses), duration=8.0))


def test_one_mission_per_vehicle_and_a_turbulent_noisy_flight(monkeypatch):
    steps = [Step(size=s) for s in (0.5, 1.0, 20.0)]  # judged as fly judges a list: not as one step
    same_verdict(*full_and_watched(monkeypatch, "step", missions=steps, duration=6.0))
    env = Environment(turbulence=Turbulence(intensity="severe"))
    vehicle = with_drag(qc.Vehicle(m=qc.Vehicle.paper().m * np.linspace(0.8, 1.6, 4)))
    sensors = SensorNoise(position_std=0.05, delay=0.004)
    world = dict(vehicle=vehicle, environment=env, sensors=sensors, seed=3)
    same_verdict(*full_and_watched(monkeypatch, "circle", duration=4.0, **world))


def test_the_default_log_of_a_large_batch_fits_and_a_single_flight_logs_every_period():
    assert log_bytes(2000, 10_000, batch_log_every(2000, 10_000)) <= fly_inputs.LOG_BUDGET <= 2**30
    assert batch_log_every(1, 10**7) == 1  # one vehicle: every period, however long
    assert batch_log_every(100, 1000) == 1  # a log that fits: every period
    with warnings.catch_warnings():
        warnings.simplefilter("error", LogWarning)
        res = qc.fly("hover", n=3, duration=0.5)  # fits: no warning, every period
    assert res.meta["log_every"] == 1 and res.t.size == 501


def test_an_explicit_log_every_is_kept_and_one_too_large_is_refused(monkeypatch):
    monkeypatch.setattr(fly_inputs, "LOG_BUDGET", 1)
    with warnings.catch_warnings():
        warnings.simplefilter("error", LogWarning)
        res = qc.fly("hover", n=3, duration=0.5, log_every=1)  # asked for: kept, no warning
    assert res.meta["log_every"] == 1 and res.t.size == 501
    with pytest.raises(qc.InputError, match="log_every=.*: in Python"):
        qc.fly("hover", n=20_000, duration=60.0, log_every=1)  # 374 GB: refused before flying


def test_the_checks_keep_a_fixed_size_per_vehicle_whatever_the_flight_length():
    # (issue 31: a 200,000-vehicle 90 s circle was refused for 75 GiB of per-period checks)
    fly_inputs.check_run_size(200_000, 90_000, batch_log_every(200_000, 90_000), 1, watched=True)
    with pytest.raises(qc.InputError, match="log_every=.*: in Python"):  # the log itself is still sized
        fly_inputs.check_run_size(200_000, 90_000, 1, 1, watched=True)
