"""The ground at z = 0 of a rotor-plant flight: it holds a vehicle at rest, lets one take off
exactly as in free flight, sets a gentle landing down, and ends a hard or upside-down one
``crashed``, at the moment free flight crosses z = 0."""

from __future__ import annotations

import numpy as np
import pytest

from quadcruise import ExitStatus
from quadcruise.model.rotor_plant import ROTOR_W1, state_names
from quadcruise.model.rotor_vehicle import RotorVehicle
from quadcruise.sim.rotor_engine import replay_rotor_speeds
from quadcruise.workflows.replay import SpeedSchedule, replay_rotors

CF = RotorVehicle.preset("crazyflie")
IRIS = RotorVehicle.preset("iris")


def schedule(rows):
    return SpeedSchedule(t=[r[0] for r in rows], speeds=[r[1] for r in rows])


def test_a_vehicle_at_rest_stays_on_the_ground_and_falls_through_without_one():
    idle = schedule([(0.0, [0.8 * CF.hover_speed] * 4), (2.0, [0.8 * CF.hover_speed] * 4)])
    held = replay_rotors(idle, CF, ground=True)
    assert held.ok[0] and held.final_state[0, 2] == 0.0 and held.final_state[0, 5] == 0.0
    np.testing.assert_array_equal(held.final_state[0, 6:10], [1, 0, 0, 0])
    falling = replay_rotors(idle, CF)
    assert falling.final_state[0, 2] < -3.0  # 36 % of g for 2 s


def test_a_takeoff_flies_as_in_free_flight():
    climb = schedule([(0.0, [1.1 * CF.hover_speed] * 4), (1.0, [1.1 * CF.hover_speed] * 4)])
    on_ground = replay_rotors(climb, CF, ground=True)
    free = replay_rotors(climb, CF)
    assert on_ground.ok[0] and on_ground.final_state[0, 2] > 0.5
    np.testing.assert_array_equal(on_ground.states, free.states)


def test_a_gentle_landing_is_set_down_level():
    h = CF.hover_speed
    rows = [(0.0, [1.05 * h] * 4), (0.3, [0.98 * h] * 4), (4.0, [0.98 * h] * 4)]  # down at 0.38 m/s at 2.3 s
    res = replay_rotors(schedule(rows), CF, ground=True)
    free = replay_rotors(schedule(rows), CF)
    assert free.final_state[0, 2] < -0.2  # without the ground it would sink through
    assert res.ok[0], res.status_text(0)
    assert res.final_state[0, 2] == 0.0
    assert np.abs(res.final_state[0, 3:6]).max() == 0.0


def test_a_hard_landing_crashes_where_free_flight_meets_the_ground():
    h = CF.hover_speed
    rows = [(0.0, [1.3 * h] * 4), (0.5, [0.0] * 4), (3.0, [0.0] * 4)]
    res = replay_rotors(schedule(rows), CF, ground=True, max_step=1e-4)
    assert ExitStatus(int(res.status[0])) is ExitStatus.CRASHED
    assert res.status_text(0).startswith("crashed: hit the ground faster than the vehicle's touchdown speed")
    free = replay_rotors(
        SpeedSchedule(
            t=np.linspace(0.0, 3.0, 30001),
            speeds=np.where(np.linspace(0.0, 3.0, 30001)[:, None] < 0.5, 1.3 * h, 0.0) * np.ones((1, 4)),
        ),
        CF,
    )
    z = free.states[0, :, 2]
    crossing = free.t[np.flatnonzero((z[:-1] >= 0) & (z[1:] < 0))[0] + 1]
    assert res.t_stop[0] == pytest.approx(crossing, abs=1.5e-4)
    assert -free.states[0, np.searchsorted(free.t, crossing), 5] > CF.touchdown_speed
    # the same drop with a gear that takes it is a landing
    assert replay_rotors(schedule(rows), CF.replace(touchdown_speed=20.0), ground=True).ok[0]


def test_upside_down_on_the_ground_is_a_crash():
    x0 = np.zeros(ROTOR_W1 + 4)
    x0[7] = 1.0  # 180 degrees about x: upside down
    res = replay_rotor_speeds(
        [0.0, 1.0], np.zeros((2, 4)), x0, CF.row(), max_step=1e-4, touchdown_speed=1.0, names=state_names(4)
    )
    assert ExitStatus(int(res.status[0])) is ExitStatus.CRASHED and res.t_stop[0] == pytest.approx(1e-4)


def test_an_iris_losing_sixty_percent_of_a_rotor_crashes():
    """Rotor 1 at 40 % of its thrust and drag moment, every rotor asked for 20 % more speed than hover:
    it lifts, rolls away over the weak rotor, and comes down hard."""
    n = 4
    x0 = np.zeros(ROTOR_W1 + n)
    x0[6] = 1.0
    w = np.full((2, n), 1.2 * IRIS.hover_speed)
    x0[ROTOR_W1:] = w[0]
    ext = np.r_[np.zeros(9), [0.4, 1.0, 1.0, 1.0]]
    res = replay_rotor_speeds(
        [0.0, 10.0],
        w,
        x0,
        IRIS.row(),
        ext=ext,
        max_step=1e-4,
        touchdown_speed=IRIS.touchdown_speed,
        names=state_names(n),
    )
    assert ExitStatus(int(res.status[0])) is ExitStatus.CRASHED, res.status_text(0)
    assert res.t_stop[0] < 10.0
    healthy = replay_rotor_speeds(
        [0.0, 10.0], w, x0, IRIS.row(), max_step=1e-4, touchdown_speed=IRIS.touchdown_speed, names=state_names(n)
    )
    assert healthy.ok[0] and healthy.final_state[0, 2] > 10.0  # the healthy one climbs away


def test_a_touchdown_speed_must_be_positive():
    from quadcruise import InputError

    with pytest.raises(InputError, match="touchdown_speed"):
        CF.replace(touchdown_speed=0.0)
    with pytest.raises(InputError, match="touchdown speed must be > 0"):
        replay_rotor_speeds(
            [0.0, 1.0], np.zeros((2, 4)), np.r_[0, 0, 0, 0, 0, 0, 1, np.zeros(10)], CF.row(), touchdown_speed=-1.0
        )
