"""The rotor-speed plant against RotorPy 3.0, an implementation nobody here wrote.

RotorPy's own state derivative (``Multirotor._s_dot_fn``, with its own parameter files),
integrated by scipy's DOP853 at tolerances of 1e-12, against quadcruise's compiled replay
(fixed-step RK4) of the same commanded rotor speeds: the crazyflie and the hummingbird,
aerodynamics on (in a steady wind) and off, over seconds of random rotor speeds drawn from a
fixed seed that tumble the vehicle. Position within 1e-4 m, quaternion within 1e-5.
"""

from __future__ import annotations

import importlib

import numpy as np
import pytest
from scipy.integrate import solve_ivp

from quadcruise.model.rotor_vehicle import RotorVehicle
from quadcruise.workflows.replay import SpeedSchedule, replay_rotors

rotorpy_multirotor = pytest.importorskip("rotorpy.vehicles.multirotor")

DURATION = 3.0  # s
ROW = 0.1  # s between commands
WIND = (2.0, -1.0, 0.5)  # m/s, with the aerodynamics on


def schedule_for(params: dict, seed: int) -> SpeedSchedule:
    """Random speeds between 30 % and 100 % of the maximum, a new row every 0.1 s."""
    rng = np.random.default_rng(seed)
    t = np.arange(0.0, DURATION + ROW / 2, ROW)
    speeds = rng.uniform(0.3, 1.0, size=(t.shape[0], 4)) * params["rotor_speed_max"]
    return SpeedSchedule(t=t, speeds=speeds, source=f"seed {seed}")


def rotorpy_flight(params: dict, schedule: SpeedSchedule, aero: bool, wind) -> np.ndarray:
    """RotorPy's derivative integrated row by row: (L, 20) states in RotorPy's layout
    (x, v, q as x y z w, body rates, wind, rotor speeds)."""
    vehicle = rotorpy_multirotor.Multirotor(params, aero=aero)
    s = np.zeros(20)
    s[9] = 1.0  # identity quaternion, scalar last
    s[13:16] = wind
    s[16:] = schedule.speeds[0]
    out = [s.copy()]
    for k in range(schedule.t.shape[0] - 1):
        cmd = schedule.speeds[k]
        sol = solve_ivp(
            lambda _t, y, c=cmd: vehicle._s_dot_fn(_t, y, c),
            (schedule.t[k], schedule.t[k + 1]),
            s,
            method="DOP853",
            rtol=1e-12,
            atol=1e-12,
        )
        assert sol.success
        s = sol.y[:, -1]
        out.append(s.copy())
    return np.array(out)


@pytest.mark.slow
@pytest.mark.parametrize("aero", [False, True], ids=["aero-off", "aero-on"])
@pytest.mark.parametrize("name", ["crazyflie", "hummingbird"])
def test_replay_agrees_with_rotorpy_through_a_tumble(name, aero):
    params = importlib.import_module(f"rotorpy.vehicles.{name}_params").quad_params
    vehicle = RotorVehicle.preset(name)
    wind = WIND if aero else (0.0, 0.0, 0.0)
    if not aero:
        vehicle = vehicle.without_aero()
    schedule = schedule_for(params, seed=23)
    ours = replay_rotors(schedule, vehicle, max_step=1e-4, wind=wind)
    theirs = rotorpy_flight(params, schedule, aero, wind)

    assert ours.ok[0], ours.status_text(0)
    # the schedule tumbles the vehicle: its body z axis points down at some time
    q = ours.states[0, :, 6:10]
    body_z_up = 1.0 - 2.0 * (q[:, 1] ** 2 + q[:, 2] ** 2)
    assert body_z_up.min() < -0.5
    assert np.abs(ours.states[0, :, 10:13]).max() > 10.0  # rad/s

    position_error = np.abs(ours.states[0, :, 0:3] - theirs[:, 0:3]).max()
    q_theirs = theirs[:, [9, 6, 7, 8]] / np.linalg.norm(theirs[:, 6:10], axis=1, keepdims=True)
    quaternion_error = np.abs(q - q_theirs).max()
    velocity_error = np.abs(ours.states[0, :, 3:6] - theirs[:, 3:6]).max()
    speed_error = np.abs(ours.states[0, :, 13:17] - theirs[:, 16:20]).max()
    assert position_error < 1e-4, position_error
    assert quaternion_error < 1e-5, quaternion_error
    assert velocity_error < 1e-4, velocity_error
    assert speed_error < 1e-6 * params["rotor_speed_max"], speed_error


@pytest.mark.slow
def test_the_comparison_tells_a_different_vehicle_apart():
    """The other direction: the same comparison fails for a vehicle 1 % off in one parameter
    (so the tolerances above are not loose enough to pass anything)."""
    params = importlib.import_module("rotorpy.vehicles.crazyflie_params").quad_params
    schedule = schedule_for(params, seed=23)
    theirs = rotorpy_flight(params, schedule, True, WIND)
    for change in ({"Jxx": 1.01 * 1.43e-5}, {"k_d": 1.01 * 10.2506e-07}, {"km": 1.01 * 7.8e-10}):
        vehicle = RotorVehicle.preset("crazyflie").replace(**change)
        ours = replay_rotors(schedule, vehicle, max_step=1e-4, wind=WIND)
        position_error = np.abs(ours.states[0, :, 0:3] - theirs[:, 0:3]).max()
        assert position_error > 1e-3, (change, position_error)
