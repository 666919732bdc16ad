"""The rotor-speed plant on its own: conservation laws where nothing acts, the motors' two
time constants in closed form, hover, and flips through 180 degrees that fly on."""

from __future__ import annotations

import numpy as np
import pytest

from quadcruise.model.rotor_plant import ROTOR_W1, state_names
from quadcruise.model.rotor_vehicle import RotorVehicle
from quadcruise.sim.rotor_engine import replay_rotor_speeds
from quadcruise.workflows.replay import SpeedSchedule, replay_rotors

CF = RotorVehicle.preset("crazyflie")


def rotation(q):
    """Body-to-world rotation matrices of unit quaternions (L, 4), scalar first."""
    w, x, y, z = q.T
    return np.array(
        [
            [1 - 2 * (y * y + z * z), 2 * (x * y - w * z), 2 * (x * z + w * y)],
            [2 * (x * y + w * z), 1 - 2 * (x * x + z * z), 2 * (y * z - w * x)],
            [2 * (x * z - w * y), 2 * (y * z + w * x), 1 - 2 * (x * x + y * y)],
        ]
    ).transpose(2, 0, 1)


def fly(vehicle, t, speeds, rates=(0.0, 0.0, 0.0), w0=None):
    x0 = np.zeros(ROTOR_W1 + vehicle.n_rotors)
    x0[6] = 1.0
    x0[10:13] = rates
    x0[ROTOR_W1:] = speeds[0] if w0 is None else w0
    res = replay_rotor_speeds(t, speeds, x0, vehicle.row(), max_step=1e-4, names=state_names(vehicle.n_rotors))
    assert res.ok[0], res.status_text(0)
    return res.states[0]


def momentum(states, J, j_rotor=0.0, signs=None):
    """World-frame angular momentum of body and rotors: R (J Omega + h e3), h = -J_r sum s_i w_i."""
    body = states[:, 10:13] * J
    if signs is not None:
        body[:, 2] += -j_rotor * states[:, ROTOR_W1:] @ signs
    return np.einsum("lij,lj->li", rotation(states[:, 6:10]), body)


def test_a_free_tumble_keeps_energy_and_angular_momentum_and_falls_freely():
    """No rotor turning, no aerodynamics: Euler's torque-free rigid body under gravity. A spin
    near the intermediate axis tumbles (Dzhanibekov), and still conserves both."""
    v = CF.without_aero().replace(Jxx=1.0e-5, Jyy=2.0e-5, Jzz=3.0e-5)
    J = np.array([v.Jxx, v.Jyy, v.Jzz])
    t = np.linspace(0.0, 5.0, 51)
    states = fly(v, t, np.zeros((51, 4)), rates=(0.05, 20.0, 0.05))
    energy = 0.5 * np.sum(J * states[:, 10:13] ** 2, axis=1)
    L = momentum(states, J)
    assert np.abs(states[:, 11]).min() < 5.0  # it tumbled: the y rate went through 0
    assert np.abs(energy / energy[0] - 1).max() < 1e-9
    assert np.abs(L - L[0]).max() < 1e-9 * np.linalg.norm(L[0])
    np.testing.assert_allclose(states[:, 2], -0.5 * v.g * t**2, rtol=1e-12, atol=1e-12)
    np.testing.assert_allclose(np.linalg.norm(states[:, 6:10], axis=1), 1.0, atol=1e-14)


def test_rotor_inertia_exchanges_momentum_with_the_body_and_the_sum_is_kept():
    """Spinning rotors (J_r > 0) speeding up and slowing down with different time constants,
    no drag moment (km = 0), thrusts balanced: the body's momentum alone changes, body plus
    rotors' is kept. With the rotors' part left out of the sum, the check fails."""
    v = CF.without_aero().replace(km=0.0, J_rotor=1.0e-7, tau_up=0.02, tau_down=0.05)
    J = np.array([v.Jxx, v.Jyy, v.Jzz])
    signs = np.array([r[3] for r in v.rotors])
    t = np.array([0.0, 0.3, 0.6, 1.0, 1.5])
    a, b = [2000.0, 800.0, 2400.0, 1500.0, 1500.0], [900.0, 2300.0, 1000.0, 1500.0, 1500.0]
    speeds = np.column_stack([a, b, a, b])  # rotors 1, 3 (s = +1) and 2, 4 (s = -1): thrusts cancel in pairs
    fine = np.linspace(0.0, 1.5, 151)  # holds t's rows among its instants
    fine_speeds = speeds[np.searchsorted(t, fine, side="right") - 1]
    states = fly(v, fine, fine_speeds, rates=(3.0, -2.0, 1.0))
    L = momentum(states, J, v.J_rotor, signs)
    L_body = momentum(states, J)
    scale = np.linalg.norm(L[0])
    assert np.abs(L - L[0]).max() < 1e-9 * scale
    assert np.abs(L_body - L_body[0]).max() > 1e-2 * scale


def test_gyroscopic_torque_does_no_work():
    """Rotors at constant, unequal speeds (net rotor momentum along body z): the body precesses
    but its kinetic energy stays."""
    v = CF.without_aero().replace(km=0.0, J_rotor=1.0e-7)
    J = np.array([v.Jxx, v.Jyy, v.Jzz])
    t = np.linspace(0.0, 2.0, 41)
    speeds = np.tile([2000.0, 900.0, 2000.0, 900.0], (41, 1))
    states = fly(v, t, speeds, rates=(4.0, -3.0, 0.5))
    energy = 0.5 * np.sum(J * states[:, 10:13] ** 2, axis=1)
    assert np.abs(energy / energy[0] - 1).max() < 1e-9
    still = fly(v.replace(J_rotor=0.0), t, speeds, rates=(4.0, -3.0, 0.5))
    assert np.abs(still[:, 10:13] - states[:, 10:13]).max() > 0.1  # the rotors' momentum mattered


def test_motors_follow_first_order_lags_up_and_down():
    """The iris's motors: tau_up = 12.5 ms speeding up, tau_down = 25 ms slowing down, in closed form."""
    v = RotorVehicle.preset("iris")
    t = np.r_[np.linspace(0.0, 0.1, 11), np.linspace(0.11, 0.3, 20)]
    high, low = 1000.0, 400.0
    speeds = np.tile(np.where(t < 0.1, high, low)[:, None], (1, 4))
    states = fly(v, t, speeds, w0=np.full(4, low))
    up = high + (low - high) * np.exp(-t / v.tau_up)
    w_at_switch = high + (low - high) * np.exp(-0.1 / v.tau_up)
    down = low + (w_at_switch - low) * np.exp(-(t - 0.1) / v.tau_down)
    expected = np.where(t <= 0.1, up, down)
    np.testing.assert_allclose(states[:, ROTOR_W1:], np.tile(expected[:, None], (1, 4)), rtol=1e-9)


@pytest.mark.parametrize("name", ["crazyflie", "hummingbird", "iris"])
def test_each_preset_hovers_in_place_at_its_hover_speed(name):
    v = RotorVehicle.preset(name)
    res = replay_rotors(SpeedSchedule(t=[0.0, 2.0], speeds=[[v.hover_speed] * 4] * 2), v)
    assert res.ok[0]
    assert np.abs(res.final_state[0, :6]).max() < 1e-9
    np.testing.assert_allclose(res.final_state[0, 6:10], [1, 0, 0, 0], atol=1e-12)


@pytest.mark.parametrize("axis", ["roll", "pitch"])
def test_a_flip_through_180_degrees_flies_on(axis):
    """Full flips about x and about y (where ZYX Euler angles are singular at 90 degrees of
    pitch): the quaternion stays a unit one, the flight finishes, the vehicle comes round."""
    v = CF
    h = v.hover_speed
    burst = [2500, 1000, 1000, 2500] if axis == "roll" else [1000, 1000, 2500, 2500]
    counter = [1000, 2500, 2500, 1000] if axis == "roll" else [2500, 2500, 1000, 1000]
    t = np.array([0.0, 0.2, 0.32, 0.35, 0.47, 1.5])
    speeds = np.array([[h] * 4, burst, [h] * 4, counter, [h] * 4, [h] * 4], dtype=float)
    fine = np.linspace(0.0, 1.5, 301)
    states = fly(v, fine, speeds[np.searchsorted(t, fine, side="right") - 1])
    q = states[:, 6:10]
    R = rotation(q)
    np.testing.assert_allclose(np.linalg.norm(q, axis=1), 1.0, atol=1e-14)
    assert R[:, 2, 2].min() < -0.99  # upside down
    assert R[-1, 2, 2] > 0.99  # and round again
    turned = np.abs(states[:, 10 if axis == "roll" else 11]).max()
    assert turned > 30.0
