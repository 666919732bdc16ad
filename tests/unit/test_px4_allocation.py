"""PX4's control allocation (:mod:`quadcruise.control.px4allocation`): the cases of PX4's
``ControlAllocationSequentialDesaturationTest.cpp`` (a quad-x with rotors at (+-1, +-1), CT 1,
KM +-0.05, no normalisation, airmode off) restated, and the v1.15 SITL log's own motor
commands (``actuator_motors``) rebuilt from its torque and thrust setpoints with its
``CA_ROTOR*`` geometry and PX4's normalisation."""

from __future__ import annotations

from pathlib import Path

import numpy as np
from pyulog import ULog

from quadcruise.control.px4allocation import allocate, mix_matrix, rotor_effectiveness, rotors_from_params

LOG = Path(__file__).parents[1] / "data" / "px4" / "sample_px4_events.ulg"
QUAD_X = rotor_effectiveness(
    [[1, 1, 0], [-1, -1, 0], [1, -1, 0], [-1, 1, 0]], [[0, 0, -1]] * 4, [1.0] * 4, [0.05, 0.05, -0.05, -0.05]
)
TOL = 1e-4  # PX4's EXPECT_NEAR_TOL


def run(roll=0.0, pitch=0.0, yaw=0.0, thrust_z=0.0):
    mix, _ = mix_matrix(QUAD_X, normalize=False)
    return allocate(mix, np.array([roll, pitch, yaw, 0.0, 0.0, thrust_z]), 0, np.zeros(4), np.ones(4))


def test_only_yaw_at_zero_thrust_gives_nothing():
    assert np.allclose(run(yaw=1.0), 0.0, atol=TOL)


def test_thrust_is_shared():
    assert np.allclose(run(thrust_z=-0.75), 0.75 / 4, atol=TOL)


def test_thrust_and_yaw():
    """Yaw effectiveness 0.05 per rotor: 0.02 of yaw is 5 x 0.02 on each rotor, up or down."""
    out = run(yaw=0.02, thrust_z=-0.75)
    assert np.allclose(out[:2], 0.1875 + 0.1, atol=TOL) and np.allclose(out[2:], 0.1875 - 0.1, atol=TOL)


def test_saturated_yaw_keeps_the_thrust_on_two_rotors():
    out = run(yaw=0.25, thrust_z=-0.75)
    assert np.allclose(out[:2], 0.75 / 2, atol=TOL) and np.allclose(out[2:], 0.0, atol=TOL)


def test_thrust_and_pitch():
    out = run(pitch=0.1, thrust_z=-0.75)
    assert np.allclose(out[[0, 2]], 0.1875 + 0.025, atol=TOL) and np.allclose(out[[1, 3]], 0.1875 - 0.025, atol=TOL)


def test_yaw_reduces_the_thrust_within_its_headroom():
    """0.8 of thrust per rotor and full yaw: with v1.15's 15 % yaw headroom the high rotors end
    at 1 and the low ones at 0.8 - (1 + 0.15 - 0.8) - 0.15 = 0.3."""
    out = run(yaw=1.0, thrust_z=-3.2)
    assert np.allclose(out[:2], 1.0, atol=TOL) and np.allclose(out[2:], 0.8 - (1.15 - 0.8) - 0.15, atol=TOL)


def test_pitch_reduces_the_thrust():
    overage = 0.75 + 2.0 / 4 - 1.0
    out = run(pitch=2.0, thrust_z=-3.0)
    assert np.allclose(out[[0, 2]], 0.75 + 0.5 - overage, atol=TOL)
    assert np.allclose(out[[1, 3]], 0.75 - 0.5 - overage, atol=TOL)


def test_the_sitl_logs_motor_commands_are_rebuilt():
    """Each airborne actuator_motors sample from the torque and thrust setpoints of the same gyro
    sample (timestamp_sample), through the log's CA_ROTOR* geometry normalised as PX4 does:
    equal to float32 precision."""
    log = ULog(
        str(LOG), message_name_filter_list=["actuator_motors", "vehicle_torque_setpoint", "vehicle_thrust_setpoint"]
    )
    topics = {d.name: d.data for d in log.data_list}
    params = log.initial_parameters
    assert params["MC_AIRMODE"] == 0 and params["THR_MDL_FAC"] == 0.0
    mix, _ = mix_matrix(rotor_effectiveness(*rotors_from_params(params)))
    motors, torque, thrust = (
        topics["actuator_motors"],
        topics["vehicle_torque_setpoint"],
        topics["vehicle_thrust_setpoint"],
    )
    row_t = {t: i for i, t in enumerate(torque["timestamp_sample"])}
    row_f = {t: i for i, t in enumerate(thrust["timestamp_sample"])}
    checked = 0
    for k, t in enumerate(motors["timestamp_sample"]):
        i, j = row_t.get(t), row_f.get(t)
        if i is None or j is None or thrust["xyz[2]"][j] > -0.05:  # PX4 stops the motors at zero thrust
            continue
        control = np.array(
            [torque[f"xyz[{a}]"][i] for a in range(3)] + [thrust[f"xyz[{a}]"][j] for a in range(3)], float
        )
        ours = np.clip(allocate(mix, control, 0, np.zeros(4), np.ones(4)), 0.0, 1.0)
        assert np.allclose(ours, [motors[f"control[{m}]"][k] for m in range(4)], atol=1e-6)
        checked += 1
    assert checked > 100
