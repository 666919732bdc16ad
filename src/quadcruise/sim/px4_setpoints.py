"""What a flight's controller asked for, as the topics PX4's log viewers overlay on the measured ones.

The setpoints (NED world, FRD body, as :mod:`quadcruise.sim.px4` writes the measured states)::

    trajectory_setpoint               the mission's reference: position, velocity, acceleration,
                                      yaw = pi/2 - psi_ref, yawspeed = -psi_dot_ref (jerk NaN: not computed)
    vehicle_local_position_setpoint   the same, and the thrust vector R_d (0, 0, c_z) in NED
    vehicle_attitude_setpoint         the desired attitude (phi_d, theta_d, psi_d) as q_d and NED Euler
                                      angles; thrust_body (0, 0, c_z)
    vehicle_rates_setpoint            thrust_body (0, 0, c_z); roll, pitch, yaw rates NaN (PX4: "not
                                      controlled"): quadcruise's controllers go from attitude to moments
                                      without a body-rate setpoint
    vehicle_thrust_setpoint           (0, 0, c_z)
    vehicle_torque_setpoint           c_x, c_y, c_z of the moments

``c = s * (E r)``: PX4's normalised thrust and torque setpoints (control allocator,
``ControlAllocationPseudoInverse``): ``E`` the effectiveness of the ``CA_ROTOR*`` parameters
written (thrust ``CT a``, moment ``CT (p x a) - CT KM a``, ``a = (0, 0, -1)`` FRD), ``r`` each
rotor's *desired* relative thrust (the controller's, before any clipping) and ``s`` the
allocator's normalisation of ``pinv(E)`` (roll and pitch together, yaw alone, thrust by the
mean norm of the thrust rows). For n equal rotors ``c_z = -sum(r) / n = -U1_d / (n CT)``.

The parameters that go with ``actuator_outputs`` (:func:`quadcruise.sim.px4.actuator_outputs`:
the signal ``x`` PX4's output module makes of each relative thrust through ``THR_MDL_FAC``,
``rel = f x^2 + (1 - f) x``, as PWM ``PWM_MAIN_MINi + x (PWM_MAIN_MAXi - PWM_MAIN_MINi)`` [us]:
``FunctionMotors::updateValues`` and the PWM output's linear map): :func:`pwm_parameters`.
"""

from __future__ import annotations

import numpy as np
from scipy.spatial.transform import Rotation

from quadcruise.layout import REF_AX, REF_PSI, REF_PSI_DOT, REF_VX, REF_X
from quadcruise.sim.px4 import ENU_TO_NED, PWM_DISARMED, PWM_MAX, PWM_MIN, attitude_ned_frd

# PX4's formats (as PX4 v1.14/v1.15 logs them: tests/data/px4/sample_px4_events.ulg), field for field.
TRAJECTORY_SETPOINT = (
    ("uint64_t", 0, "timestamp"),
    ("float", 3, "position"),
    ("float", 3, "velocity"),
    ("float", 3, "acceleration"),
    ("float", 3, "jerk"),
    ("float", 0, "yaw"),
    ("float", 0, "yawspeed"),
)
VEHICLE_LOCAL_POSITION_SETPOINT = (
    ("uint64_t", 0, "timestamp"),
    ("float", 0, "x"),
    ("float", 0, "y"),
    ("float", 0, "z"),
    ("float", 0, "vx"),
    ("float", 0, "vy"),
    ("float", 0, "vz"),
    ("float", 3, "acceleration"),
    ("float", 3, "thrust"),
    ("float", 0, "yaw"),
    ("float", 0, "yawspeed"),
)
VEHICLE_ATTITUDE_SETPOINT = (
    ("uint64_t", 0, "timestamp"),
    ("float", 0, "roll_body"),
    ("float", 0, "pitch_body"),
    ("float", 0, "yaw_body"),
    ("float", 0, "yaw_sp_move_rate"),
    ("float", 4, "q_d"),
    ("float", 3, "thrust_body"),
    ("bool", 0, "reset_integral"),
    ("bool", 0, "fw_control_yaw_wheel"),
    ("uint8_t", 2, "_padding0"),
)
VEHICLE_RATES_SETPOINT = (
    ("uint64_t", 0, "timestamp"),
    ("float", 0, "roll"),
    ("float", 0, "pitch"),
    ("float", 0, "yaw"),
    ("float", 3, "thrust_body"),
    ("bool", 0, "reset_integral"),
    ("uint8_t", 7, "_padding0"),
)
VEHICLE_THRUST_SETPOINT = (
    ("uint64_t", 0, "timestamp"),
    ("uint64_t", 0, "timestamp_sample"),
    ("float", 3, "xyz"),
    ("uint8_t", 4, "_padding0"),
)
VEHICLE_TORQUE_SETPOINT = VEHICLE_THRUST_SETPOINT
"""Same fields as ``vehicle_thrust_setpoint``: ``xyz`` the normalised torques about FRD x, y, z."""
SETPOINT_TOPICS = (
    "trajectory_setpoint",
    "vehicle_local_position_setpoint",
    "vehicle_attitude_setpoint",
    "vehicle_rates_setpoint",
    "vehicle_thrust_setpoint",
    "vehicle_torque_setpoint",
)
"""The setpoint topics written."""


def pwm_parameters(n: int, thrust_factor: float) -> dict[str, float | int]:
    """``THR_MDL_FAC`` and, for the first ``n`` PWM outputs, motor ``i`` on output ``i``
    (``PWM_MAIN_FUNCi = 100 + i``) with :data:`PWM_MIN`, :data:`PWM_MAX` and :data:`PWM_DISARMED`.

    Examples
    --------
    >>> p = pwm_parameters(4, 0.0)
    >>> p["PWM_MAIN_FUNC1"], p["PWM_MAIN_MIN4"], p["PWM_MAIN_MAX4"], p["THR_MDL_FAC"]
    (101, 1000, 2000, 0.0)
    """
    out: dict[str, float | int] = {"THR_MDL_FAC": float(thrust_factor)}
    for i in range(1, n + 1):
        out[f"PWM_MAIN_FUNC{i}"] = 100 + i
        out[f"PWM_MAIN_MIN{i}"] = int(PWM_MIN)
        out[f"PWM_MAIN_MAX{i}"] = int(PWM_MAX)
        out[f"PWM_MAIN_DIS{i}"] = int(PWM_DISARMED)
    return out


def effectiveness(params: dict) -> np.ndarray:
    """The control allocator's effectiveness ``E`` (6 x n: torque x, y, z, thrust x, y, z in FRD per
    unit relative thrust) of the ``CA_ROTOR*`` parameters (PX4's ``ActuatorEffectivenessRotors``).

    Examples
    --------
    >>> p = {"CA_ROTOR_COUNT": 1, "CA_ROTOR0_PX": 0.1, "CA_ROTOR0_PY": 0.0, "CA_ROTOR0_PZ": 0.0,
    ...      "CA_ROTOR0_KM": 0.05, "CA_ROTOR0_CT": 10.0}
    >>> (effectiveness(p)[:, 0].round(6) + 0.0).tolist()     # pitch up, yaw right, thrust up
    [0.0, 1.0, 0.5, 0.0, 0.0, -10.0]
    """
    axis = np.array([0.0, 0.0, -1.0])
    cols = []
    for i in range(int(params["CA_ROTOR_COUNT"])):
        p = np.array([float(params[f"CA_ROTOR{i}_P{w}"]) for w in "XYZ"])
        ct, km = float(params[f"CA_ROTOR{i}_CT"]), float(params[f"CA_ROTOR{i}_KM"])
        cols.append(np.r_[ct * np.cross(p, axis) - ct * km * axis, ct * axis])
    return np.array(cols).T


def normalisation(e: np.ndarray) -> np.ndarray:
    """PX4's scale ``s`` (6,) of the normalised setpoints (``updateControlAllocationMatrixScale``)."""
    mix = np.linalg.pinv(e).T  # (6, n): column j of PX4's mix is row j here
    scale = np.ones(6)
    rp = []
    for j in (0, 1):
        nonzero = int(np.sum(np.abs(mix[j]) > 1e-3))
        rp.append(np.sqrt(np.sum(mix[j] ** 2) / (nonzero / 2.0)) if nonzero else 1.0)
    scale[0] = scale[1] = max(rp)
    scale[2] = float(mix[2].max())
    norms = np.linalg.norm(mix[3:6], axis=0)
    if np.any(norms > np.finfo(np.float32).eps):
        scale[3:6] = norms.sum() / np.count_nonzero(norms > np.finfo(np.float32).eps)
    return scale


def setpoint_values(
    reference: np.ndarray, attitude_d: np.ndarray, rel_desired: np.ndarray, params: dict
) -> dict[str, dict[str, np.ndarray]]:
    """Each setpoint topic's values (no timestamps), per logged instant.

    Parameters
    ----------
    reference : numpy.ndarray
        (L, REF_SIZE) the mission's reference (ENU, psi, psi_dot).
    attitude_d : numpy.ndarray
        (L, 3) the desired roll, pitch, yaw (phi_d, theta_d, psi_d) [rad] (ZYX, FLU to ENU).
    rel_desired : numpy.ndarray
        (L, n) each rotor's desired relative thrust.
    params : dict
        The ``CA_ROTOR*`` parameters written.

    Returns
    -------
    dict
        Topic name -> (its PX4 format, field -> values), as
        :func:`~quadcruise.sim.px4.px4_topics` takes them.
    """
    e = effectiveness(params)
    c = (e @ rel_desired.T).T * normalisation(e)  # (L, 6)
    c[:, 3:5] = 0.0
    thrust = np.column_stack([np.zeros(len(c)), np.zeros(len(c)), c[:, 5]])
    pos, vel, acc = (reference[:, k : k + 3] @ ENU_TO_NED.T for k in (REF_X, REF_VX, REF_AX))
    yaw = np.angle(np.exp(1j * (np.pi / 2 - reference[:, REF_PSI])))
    yawspeed = -reference[:, REF_PSI_DOT]
    finite = np.all(np.isfinite(attitude_d), axis=1)
    q_d = np.full((len(c), 4), np.nan)
    euler = np.full((len(c), 3), np.nan)
    if np.any(finite):
        q_d[finite] = attitude_ned_frd(attitude_d[finite, 0], attitude_d[finite, 1], attitude_d[finite, 2])
        rot = Rotation.from_quat(q_d[finite][:, [1, 2, 3, 0]])
        euler[finite] = rot.as_euler("ZYX")[:, ::-1]  # roll, pitch, yaw of FRD in NED
    thrust_ned = np.full((len(c), 3), np.nan)
    if np.any(finite):
        thrust_ned[finite] = Rotation.from_quat(q_d[finite][:, [1, 2, 3, 0]]).apply(thrust[finite])
    nan = np.full(len(c), np.nan)
    values = {
        "trajectory_setpoint": {
            "position": pos,
            "velocity": vel,
            "acceleration": acc,
            "jerk": np.full((len(c), 3), np.nan),
            "yaw": yaw,
            "yawspeed": yawspeed,
        },
        "vehicle_local_position_setpoint": {
            **{k: pos[:, i] for i, k in enumerate("xyz")},
            **{f"v{k}": vel[:, i] for i, k in enumerate("xyz")},
            "acceleration": acc,
            "thrust": thrust_ned,
            "yaw": yaw,
            "yawspeed": yawspeed,
        },
        "vehicle_attitude_setpoint": {
            "roll_body": euler[:, 0],
            "pitch_body": euler[:, 1],
            "yaw_body": euler[:, 2],
            "q_d": q_d,
            "thrust_body": thrust,
        },
        "vehicle_rates_setpoint": {"roll": nan, "pitch": nan, "yaw": nan, "thrust_body": thrust},
        "vehicle_thrust_setpoint": {"xyz": thrust},
        "vehicle_torque_setpoint": {"xyz": c[:, :3]},
    }
    return {name: (FORMATS[name], v) for name, v in values.items()}


FORMATS = {
    "trajectory_setpoint": TRAJECTORY_SETPOINT,
    "vehicle_local_position_setpoint": VEHICLE_LOCAL_POSITION_SETPOINT,
    "vehicle_attitude_setpoint": VEHICLE_ATTITUDE_SETPOINT,
    "vehicle_rates_setpoint": VEHICLE_RATES_SETPOINT,
    "vehicle_thrust_setpoint": VEHICLE_THRUST_SETPOINT,
    "vehicle_torque_setpoint": VEHICLE_TORQUE_SETPOINT,
}
"""Each topic's PX4 format."""
