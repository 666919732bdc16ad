"""A flight in PX4's conventions, as the topics of a PX4 log (:meth:`SimResult.to_ulog`).

With ``A`` the ENU-to-NED swap and ``B = diag(1, -1, -1)`` (FLU to FRD)::

    p_ned = A p_enu = (y, x, -z)                      position, velocity, acceleration
    R_ned_frd = A R_enu_flu B                          attitude, quaternion (w, x, y, z)
    w_frd = B w_flu = (p, -q, -r)                      body rates
    f_frd = B R_enu_flu^T (a_enu + g e_z)              accelerometer: specific force

The paper's "+" rotors (1 at -x, 2 at +y, 3 at +x, 4 at -y in FLU; 1 and 3 clockwise seen from
above) are written as PX4's ``CA_ROTOR*`` parameters, so that a reader of the log can rebuild
eqs (1)-(4).

The commands are written with PX4's meanings: ``actuator_motors`` holds each rotor's *relative
thrust* (thrust over the rotor's thrust at full command, ``CA_ROTORi_CT``), ``actuator_outputs``
the *signal* ``x`` the output module makes of it through ``THR_MDL_FAC`` (``rel = f x^2 + (1 - f)
x``), as PWM between ``PWM_MAIN_MINi`` and ``PWM_MAIN_MAXi`` (:mod:`quadcruise.sim.px4_setpoints`).
The paper's vehicle: thrust ``K u``, so ``f = 0`` and both are the duty ``u``. A rotor-plant
flight (:mod:`quadcruise.model.rotor_plant`): the signal is the commanded speed over ``w_max``
and ``f = 1`` (thrust ``kf w^2 = CT x^2``, ``CT = kf w_max^2``); it is written as PX4 logs a
vehicle whose ESCs report their speed: ``esc_status`` the rotors' *measured* speeds [rpm] as ESC
telemetry reports them (an integer), and ``CA_ROTOR*`` the vehicle's own rotors (``KM = -s km /
kf``, positive counter-clockwise) (:func:`rotor_plant_parameters`). The setpoints PX4's viewers
overlay are written too (:func:`quadcruise.sim.px4_setpoints.setpoint_values`).

The topics carry the sensor noise the controller saw, drawn again from the flight's seed
(:data:`NOISE_STREAM`); the accelerometer has none of its own.
"""

from __future__ import annotations

import numpy as np
from scipy.spatial.transform import Rotation

from quadcruise.io.ulog import Topic
from quadcruise.layout import CMD_U1, PHI, PSI, THETA, VX, P, X

ENU_TO_NED = np.array([[0.0, 1.0, 0.0], [1.0, 0.0, 0.0], [0.0, 0.0, -1.0]])
"""``A``: ENU (or FLU) vectors to NED."""
FLU_TO_FRD = np.diag([1.0, -1.0, -1.0])
"""``B``: FLU body vectors to FRD."""
NOISE_STREAM = 0x554C4F47
"""The third word of the noise generator's seed, ``[seed, vehicle, NOISE_STREAM]`` ("ULOG")."""
RATES_HZ = {
    "vehicle_local_position": 50.0,
    "vehicle_attitude": 250.0,
    "vehicle_angular_velocity": 250.0,
    "actuator_motors": 250.0,
    "sensor_combined": 250.0,
    "esc_status": 250.0,
    "vehicle_status": 1.0,
    "vehicle_land_detected": 1.0,
    "actuator_outputs": 10.0,
    "trajectory_setpoint": 5.0,
    "vehicle_local_position_setpoint": 10.0,
    "vehicle_attitude_setpoint": 20.0,
    "vehicle_rates_setpoint": 50.0,
    "vehicle_thrust_setpoint": 50.0,
    "vehicle_torque_setpoint": 50.0,
}
"""Each topic's rate at most [Hz]: PX4's default logging profile's order of magnitude (the
setpoints and ``actuator_outputs`` at its intervals, ``logged_topics.cpp``), capped by the
flight's own log interval (a topic is written every k-th logged instant)."""
SYSID_TOPICS = ("vehicle_attitude", "vehicle_angular_velocity", "actuator_motors", "sensor_combined", "esc_status")
"""The topics PX4's system-identification logging profile writes at their full rate."""
SYSID_PROFILE_BIT = 8
"""``SDLOG_PROFILE``'s bit for PX4's system-identification profile: the commands at the rate the
rate controller publishes them. Written only when the log holds every control period."""
PROFILES = {
    "default": (RATES_HZ, 1),
    "sysid": ({**RATES_HZ, **dict.fromkeys(SYSID_TOPICS, float("inf"))}, 1 | SYSID_PROFILE_BIT),
}
"""Logging profiles: each topic's rate at most [Hz] and the ``SDLOG_PROFILE`` bits PX4 writes
for it (1 default, 8 system identification: every logged instant; why, docs/identify.md)."""

# PX4's formats (uORB, as PX4 v1.15 logs them), field for field.
VEHICLE_LOCAL_POSITION = (
    ("uint64_t", 0, "timestamp"),
    ("uint64_t", 0, "timestamp_sample"),
    ("uint64_t", 0, "ref_timestamp"),
    ("double", 0, "ref_lat"),
    ("double", 0, "ref_lon"),
    ("float", 0, "x"),
    ("float", 0, "y"),
    ("float", 0, "z"),
    ("float", 2, "delta_xy"),
    ("float", 0, "delta_z"),
    ("float", 0, "vx"),
    ("float", 0, "vy"),
    ("float", 0, "vz"),
    ("float", 0, "z_deriv"),
    ("float", 2, "delta_vxy"),
    ("float", 0, "delta_vz"),
    ("float", 0, "ax"),
    ("float", 0, "ay"),
    ("float", 0, "az"),
    ("float", 0, "heading"),
    ("float", 0, "heading_var"),
    ("float", 0, "unaided_heading"),
    ("float", 0, "delta_heading"),
    ("float", 0, "tilt_var"),
    ("float", 0, "ref_alt"),
    ("float", 0, "dist_bottom"),
    ("float", 0, "eph"),
    ("float", 0, "epv"),
    ("float", 0, "evh"),
    ("float", 0, "evv"),
    ("float", 0, "vxy_max"),
    ("float", 0, "vz_max"),
    ("float", 0, "hagl_min"),
    ("float", 0, "hagl_max"),
    ("bool", 0, "xy_valid"),
    ("bool", 0, "z_valid"),
    ("bool", 0, "v_xy_valid"),
    ("bool", 0, "v_z_valid"),
    ("uint8_t", 0, "xy_reset_counter"),
    ("uint8_t", 0, "z_reset_counter"),
    ("uint8_t", 0, "vxy_reset_counter"),
    ("uint8_t", 0, "vz_reset_counter"),
    ("uint8_t", 0, "heading_reset_counter"),
    ("bool", 0, "heading_good_for_control"),
    ("bool", 0, "xy_global"),
    ("bool", 0, "z_global"),
    ("bool", 0, "dist_bottom_valid"),
    ("uint8_t", 0, "dist_bottom_sensor_bitfield"),
    ("bool", 0, "dead_reckoning"),
    ("uint8_t", 5, "_padding0"),
)
VEHICLE_ATTITUDE = (
    ("uint64_t", 0, "timestamp"),
    ("uint64_t", 0, "timestamp_sample"),
    ("float", 4, "q"),
    ("float", 4, "delta_q_reset"),
    ("uint8_t", 0, "quat_reset_counter"),
    ("uint8_t", 7, "_padding0"),
)
VEHICLE_ANGULAR_VELOCITY = (
    ("uint64_t", 0, "timestamp"),
    ("uint64_t", 0, "timestamp_sample"),
    ("float", 3, "xyz"),
    ("float", 3, "xyz_derivative"),
)
ACTUATOR_MOTORS = (
    ("uint64_t", 0, "timestamp"),
    ("uint64_t", 0, "timestamp_sample"),
    ("float", 12, "control"),
    ("uint16_t", 0, "reversible_flags"),
    ("uint8_t", 6, "_padding0"),
)
SENSOR_COMBINED = (
    ("uint64_t", 0, "timestamp"),
    ("float", 3, "gyro_rad"),
    ("uint32_t", 0, "gyro_integral_dt"),
    ("int32_t", 0, "accelerometer_timestamp_relative"),
    ("float", 3, "accelerometer_m_s2"),
    ("uint32_t", 0, "accelerometer_integral_dt"),
    ("uint8_t", 0, "accelerometer_clipping"),
    ("uint8_t", 0, "gyro_clipping"),
    ("uint8_t", 0, "accel_calibration_count"),
    ("uint8_t", 0, "gyro_calibration_count"),
)
ESC_REPORT = (
    ("uint64_t", 0, "timestamp"),
    ("uint32_t", 0, "esc_errorcount"),
    ("int32_t", 0, "esc_rpm"),
    ("float", 0, "esc_voltage"),
    ("float", 0, "esc_current"),
    ("float", 0, "esc_temperature"),
    ("uint16_t", 0, "failures"),
    ("int8_t", 0, "esc_power"),
    ("uint8_t", 0, "esc_address"),
    ("uint8_t", 0, "esc_cmdcount"),
    ("uint8_t", 0, "esc_state"),
    ("uint8_t", 0, "actuator_function"),
    ("uint8_t", 1, "_padding0"),
)
ESC_STATUS = (
    ("uint64_t", 0, "timestamp"),
    ("uint16_t", 0, "counter"),
    ("uint8_t", 0, "esc_count"),
    ("uint8_t", 0, "esc_connectiontype"),
    ("uint8_t", 0, "esc_online_flags"),
    ("uint8_t", 0, "esc_armed_flags"),
    ("uint8_t", 2, "_padding0"),
    ("esc_report", 8, "esc"),
)
"""PX4's ``esc_status`` (ESC telemetry): eight nested ``esc_report`` (:data:`ESC_REPORT`)."""
MAX_ESCS = 8
"""Rotors ``esc_status`` reports at most."""
VEHICLE_STATUS = (
    ("uint64_t", 0, "timestamp"),
    ("uint64_t", 0, "armed_time"),
    ("uint64_t", 0, "takeoff_time"),
    ("uint8_t", 0, "arming_state"),
    ("uint8_t", 0, "nav_state"),
    ("uint8_t", 0, "vehicle_type"),
    ("bool", 0, "is_vtol"),
    ("uint8_t", 0, "system_type"),
)
VEHICLE_LAND_DETECTED = (
    ("uint64_t", 0, "timestamp"),
    ("bool", 0, "freefall"),
    ("bool", 0, "ground_contact"),
    ("bool", 0, "maybe_landed"),
    ("bool", 0, "landed"),
)
PWM_MIN, PWM_MAX, PWM_DISARMED = 1000.0, 2000.0, 900.0
"""The PWM range [us] written as ``PWM_MAIN_MINi``/``PWM_MAIN_MAXi`` and ``PWM_MAIN_DISi`` (PX4's defaults)."""
N_OUTPUTS = 16
"""``actuator_outputs``' channels (PX4's ``NUM_ACTUATOR_OUTPUTS``)."""

ACTUATOR_OUTPUTS = (
    ("uint64_t", 0, "timestamp"),
    ("uint32_t", 0, "noutputs"),
    ("float", 16, "output"),
    ("uint8_t", 4, "_padding0"),
)
ARMING_STATE_ARMED = 2
"""``vehicle_status.arming_state`` of an armed vehicle (PX4's ARMING_STATE_ARMED)."""
MAV_TYPE_QUADROTOR = 2
"""MAVLink's MAV_TYPE_QUADROTOR (``vehicle_status.system_type``, parameter ``MAV_TYPE``)."""


def attitude_ned_frd(phi: np.ndarray, theta: np.ndarray, psi: np.ndarray) -> np.ndarray:
    """PX4's attitude quaternions (w, x, y, z), FRD body to NED, from the paper's ZYX angles, with no
    sign jumps from one to the next.

    Examples
    --------
    >>> q = attitude_ned_frd(np.zeros(1), np.zeros(1), np.zeros(1))   # nose east: NED yaw +90 deg
    >>> (np.round(q, 6) + 0.0).tolist()
    [[0.707107, 0.0, 0.0, 0.707107]]
    """
    r_enu = Rotation.from_euler("ZYX", np.column_stack([psi, theta, phi]))
    r_ned = Rotation.from_matrix(ENU_TO_NED) * r_enu * Rotation.from_matrix(FLU_TO_FRD)
    xyzw = r_ned.as_quat()
    q = np.column_stack([xyzw[:, 3], xyzw[:, :3]])
    if len(q) and q[0, 0] < 0.0:
        q = -q
    if len(q) > 1:  # keep the hemisphere
        flips = np.cumprod(np.where(np.einsum("ij,ij->i", q[1:], q[:-1]) < 0.0, -1.0, 1.0))
        q[1:] *= flips[:, None]
    return q


def specific_force_frd(states: np.ndarray, accel_enu: np.ndarray, g: float) -> np.ndarray:
    """What an accelerometer reads, ``B R^T (a + g e_z)`` [m/s^2] in FRD: (0, 0, -g) at rest, level."""
    rot = Rotation.from_euler("ZYX", states[:, [PSI, THETA, PHI]])
    return rot.inv().apply(accel_enu + np.array([0.0, 0.0, g])) @ FLU_TO_FRD.T


def rotor_parameters(arm: float, yaw_per_thrust: float, max_thrust: float) -> dict[str, float | int]:
    """The paper's "+" rotors as PX4's ``CA_ROTOR*`` parameters (FRD positions, ``KM`` the yaw moment
    per unit thrust, positive counter-clockwise, ``CT`` the thrust at full command) and ``MAV_TYPE``.
    """
    flu = [(-arm, 0.0, -1.0), (0.0, arm, 1.0), (arm, 0.0, -1.0), (0.0, -arm, 1.0)]  # x, y, +1 = CCW
    out: dict[str, float | int] = {"CA_ROTOR_COUNT": 4, "MAV_TYPE": MAV_TYPE_QUADROTOR}
    for i, (x, y, ccw) in enumerate(flu):
        out.update(
            {
                f"CA_ROTOR{i}_PX": x,
                f"CA_ROTOR{i}_PY": -y,
                f"CA_ROTOR{i}_PZ": 0.0,
                f"CA_ROTOR{i}_KM": ccw * yaw_per_thrust,
                f"CA_ROTOR{i}_CT": max_thrust,
            }
        )
    return out


def rotor_plant_parameters(rotors, kf: float, km: float, w_max: float) -> dict[str, float | int]:
    """A rotor-plant vehicle's rotors as PX4's ``CA_ROTOR*`` parameters, with ``THR_MDL_FAC = 1``.

    Parameters
    ----------
    rotors : sequence of (x, y, z, s)
        The hubs in FLU [m] and each direction s (+1: drag moment about +z, clockwise from above).
    kf, km : float
        Thrust [N/(rad/s)^2] and yaw-moment [N m/(rad/s)^2] coefficients.
    w_max : float
        The rotor speed of a full command [rad/s].

    Returns
    -------
    dict
        ``CA_ROTOR_COUNT``, per rotor ``PX``, ``PY``, ``PZ`` (FRD), ``KM`` (yaw moment per unit thrust,
        positive counter-clockwise: ``-s km / kf``) and ``CT`` (thrust at full command, ``kf w_max^2``),
        ``THR_MDL_FAC`` 1 (thrust quadratic in the command, which is the speed over ``w_max``) and
        ``MAV_TYPE`` (quadrotor, hexarotor, octorotor).

    Examples
    --------
    >>> p = rotor_plant_parameters([(0.1, 0.1, 0.0, 1)], kf=1e-6, km=2e-8, w_max=1000.0)
    >>> p["CA_ROTOR0_PY"], p["CA_ROTOR0_KM"], p["CA_ROTOR0_CT"]
    (-0.1, -0.02, 1.0)
    """
    n = len(rotors)
    out: dict[str, float | int] = {
        "CA_ROTOR_COUNT": n,
        "MAV_TYPE": {6: 13, 8: 14}.get(n, MAV_TYPE_QUADROTOR),
        "THR_MDL_FAC": 1.0,
    }
    for i, (x, y, z, s) in enumerate(rotors):
        out.update(
            {
                f"CA_ROTOR{i}_PX": float(x),
                f"CA_ROTOR{i}_PY": -float(y),
                f"CA_ROTOR{i}_PZ": -float(z),
                f"CA_ROTOR{i}_KM": -float(s) * km / kf,
                f"CA_ROTOR{i}_CT": kf * w_max**2,
            }
        )
    return out


def controller_parameters(flown: dict) -> tuple[dict[str, float | int], str]:
    """The px4 controller's PX4 parameters for a log's parameter section, and their exact values.

    A ULog holds PX4's float parameters as float32 (PX4's own type); the exact float64 values
    the flight flew go in the info message ``quadcruise_px4_params`` (``NAME=repr;...``, only
    those float32 does not hold), which :func:`quadcruise.io.px4params.read_params` reads back
    where the parameter section's float32 value is theirs rounded, as a ``.params`` file's
    shortest repr reads back exactly. The allocation's (``CA_*``, ``THR_MDL_FAC``) are the
    controller's, replacing the plant's (:func:`rotor_parameters`), as PX4 logs what it flew.

    Parameters
    ----------
    flown : dict
        Name -> value (``int`` for PX4's INT32), :meth:`quadcruise.control.px4.Px4.log_parameters`.

    Returns
    -------
    params : dict
        The parameters to add.
    exact : str
        The info message's value.

    Examples
    --------
    >>> p, exact = controller_parameters({"MC_ROLL_P": 6.5, "MC_ROLLRATE_P": 0.15, "CA_ROTOR_COUNT": 0})
    >>> p, exact
    ({'MC_ROLL_P': 6.5, 'MC_ROLLRATE_P': 0.15, 'CA_ROTOR_COUNT': 0}, 'MC_ROLLRATE_P=0.15')
    """
    kept = dict(flown)  # PX4 logs the parameters it flew: the allocation's too
    exact = ";".join(f"{k}={v!r}" for k, v in kept.items() if isinstance(v, float) and float(np.float32(v)) != v)
    return kept, exact


def _every(t: np.ndarray, rate_hz: float) -> np.ndarray:
    step = float(t[1] - t[0]) if len(t) > 1 else 1.0
    k = max(1, int(round(1.0 / (rate_hz * step)))) if np.isfinite(rate_hz) else 1
    return np.arange(0, len(t), k)


def px4_topics(
    t: np.ndarray,
    states: np.ndarray,
    signal: np.ndarray,
    *,
    g: float,
    thrust_factor: float = 0.0,
    noise_std: np.ndarray | None = None,
    rng: np.random.Generator | None = None,
    rates_hz: dict[str, float] | None = None,
    rotor_speeds: np.ndarray | None = None,
    system_type: int = MAV_TYPE_QUADROTOR,
    setpoints: dict[str, tuple] | None = None,
) -> list[Topic]:
    """One vehicle's flight as PX4 topics at ``rates_hz`` (a profile of :data:`PROFILES`;
    :data:`RATES_HZ` by default), from its logged ``t``, ``states`` and motor ``signal`` x (L, n)
    in [0, 1] with ``thrust_factor`` f (``THR_MDL_FAC``): ``actuator_motors`` the relative thrust
    ``f x^2 + (1 - f) x``, ``actuator_outputs`` x as PWM; the sensor noise ``noise_std``
    (``SensorNoise.std_vector``) drawn from ``rng``; ``rotor_speeds`` [rad/s] (L, n), when given,
    as ``esc_status`` [rpm]; ``setpoints``, when given, as
    :func:`~quadcruise.sim.px4_setpoints.setpoint_values` returns them.
    """

    us = np.round(t * 1e6).astype(np.uint64)
    accel = np.gradient(states[:, VX : VX + 3], t, axis=0, edge_order=2) if len(t) > 2 else np.zeros((len(t), 3))
    rate_dot = np.gradient(states[:, P : P + 3], t, axis=0, edge_order=2) if len(t) > 2 else np.zeros((len(t), 3))
    force = specific_force_frd(states, accel, g)
    seen = states.copy()
    if noise_std is not None and np.any(noise_std > 0.0):
        seen += rng.standard_normal(seen.shape) * noise_std
    q = attitude_ned_frd(seen[:, PHI], seen[:, THETA], seen[:, PSI])
    pos, vel, acc = (seen[:, X : X + 3] @ ENU_TO_NED.T, seen[:, VX : VX + 3] @ ENU_TO_NED.T, accel @ ENU_TO_NED.T)
    gyro = seen[:, P : P + 3] @ FLU_TO_FRD.T
    heading = np.arctan2(2.0 * (q[:, 0] * q[:, 3] + q[:, 1] * q[:, 2]), 1.0 - 2.0 * (q[:, 2] ** 2 + q[:, 3] ** 2))
    signal = np.asarray(signal, dtype=np.float64)
    control = np.full((len(t), 12), np.nan)
    control[:, : signal.shape[1]] = thrust_factor * signal**2 + (1.0 - thrust_factor) * signal

    rates_hz = RATES_HZ if rates_hz is None else rates_hz

    def topic(name, fields, nested=None, **values):
        rows = _every(t, rates_hz[name])
        values = {k: np.asarray(v)[rows] for k, v in values.items()}
        return Topic(name, fields, {"timestamp": us[rows], **values}, nested or {})

    ones = np.ones(len(t), bool)
    esc = []
    if rotor_speeds is not None:
        n = rotor_speeds.shape[1]
        rpm = np.zeros((len(t), MAX_ESCS), np.int32)
        rpm[:, :n] = np.round(rotor_speeds * (60.0 / (2.0 * np.pi)))
        esc = [
            topic(
                "esc_status",
                ESC_STATUS,
                nested={"esc_report": ESC_REPORT},
                counter=np.arange(len(t)) % 65536,
                esc_count=np.full(len(t), n),
                esc_online_flags=np.full(len(t), (1 << n) - 1),
                esc_armed_flags=np.full(len(t), (1 << n) - 1),
                **{"esc.timestamp": np.repeat(us[:, None], MAX_ESCS, 1), "esc.esc_rpm": rpm},
            )
        ]
    extra = [topic("actuator_outputs", ACTUATOR_OUTPUTS, **actuator_outputs(signal))]
    for name, (fields, values) in (setpoints or {}).items():
        stamp = {"timestamp_sample": us} if any(f[2] == "timestamp_sample" for f in fields) else {}
        extra.append(topic(name, fields, **stamp, **values))
    return (
        esc
        + extra
        + [
            topic(
                "vehicle_local_position",
                VEHICLE_LOCAL_POSITION,
                timestamp_sample=us,
                x=pos[:, 0],
                y=pos[:, 1],
                z=pos[:, 2],
                vx=vel[:, 0],
                vy=vel[:, 1],
                vz=vel[:, 2],
                z_deriv=vel[:, 2],
                ax=acc[:, 0],
                ay=acc[:, 1],
                az=acc[:, 2],
                heading=heading,
                xy_valid=ones,
                z_valid=ones,
                v_xy_valid=ones,
                v_z_valid=ones,
                heading_good_for_control=ones,
                dist_bottom=-pos[:, 2],
            ),
            topic("vehicle_attitude", VEHICLE_ATTITUDE, timestamp_sample=us, q=q),
            topic(
                "vehicle_angular_velocity",
                VEHICLE_ANGULAR_VELOCITY,
                timestamp_sample=us,
                xyz=gyro,
                xyz_derivative=rate_dot @ FLU_TO_FRD.T,
            ),
            topic("actuator_motors", ACTUATOR_MOTORS, timestamp_sample=us, control=control),
            topic(
                "sensor_combined",
                SENSOR_COMBINED,
                gyro_rad=gyro,
                accelerometer_m_s2=force,
                gyro_integral_dt=np.full(len(t), int(np.diff(us[_every(t, rates_hz["sensor_combined"])][:2]).sum())),
            ),
            topic(
                "vehicle_status",
                VEHICLE_STATUS,
                armed_time=np.zeros(len(t), np.uint64),
                arming_state=np.full(len(t), ARMING_STATE_ARMED),
                system_type=np.full(len(t), system_type),
                vehicle_type=np.ones(len(t)),
            ),
            topic(
                "vehicle_land_detected", VEHICLE_LAND_DETECTED, landed=~ones, maybe_landed=~ones, ground_contact=~ones
            ),
        ]
    )


def actuator_outputs(signal: np.ndarray) -> dict[str, np.ndarray]:
    """``actuator_outputs``' values: each rotor's signal ``x`` (L, n) as PWM [us], the other
    channels at the disarmed value."""
    out = np.full((len(signal), N_OUTPUTS), PWM_DISARMED)
    out[:, : signal.shape[1]] = PWM_MIN + np.clip(signal, 0.0, 1.0) * (PWM_MAX - PWM_MIN)
    return {"noutputs": np.full(len(signal), N_OUTPUTS), "output": out}


def rotor_speed_commands(commands: np.ndarray, flown: dict, believed: dict | None = None, *, wanted: bool = False):
    """The rotor speeds [rad/s] a rotor-plant flight commanded, from its logged "+" equivalent duties.

    As :mod:`quadcruise.sim.rotor_flight` computes them each control period: the controller
    vehicle's :func:`~quadcruise.model.equivalent.duty_to_thrust` matrix, each thrust a speed
    ``sqrt(f / kf)`` of the controller vehicle, held in the flown vehicle's [w_min, w_max].

    Parameters
    ----------
    commands : numpy.ndarray
        (L, CMD_SIZE) the logged commands.
    flown, believed : dict
        The flown and the controller vehicle's fields (``RotorVehicle.to_dict``; ``plant`` may be
        among them); ``believed`` None: the flown vehicle.
    wanted : bool
        Also return the thrusts the controller wanted of each rotor, before any limit [N].

    Returns
    -------
    numpy.ndarray
        (L, n) commanded rotor speeds [rad/s] (and, with ``wanted``, the (L, n) thrusts).
    """
    from quadcruise.model.equivalent import duty_to_thrust
    from quadcruise.model.rotor_vehicle import RotorVehicle

    def vehicle(fields: dict) -> RotorVehicle:
        return RotorVehicle(**{k: v for k, v in fields.items() if k != "plant"})

    controller = vehicle(believed or flown)
    thrust = commands[:, CMD_U1 : CMD_U1 + 4] @ duty_to_thrust(controller).T
    speed = np.sqrt(np.clip(thrust, 0.0, None) / controller.kf)
    speed = np.clip(speed, float(flown["w_min"]), float(flown["w_max"]))
    return (speed, thrust) if wanted else speed


def duties_of(commands: np.ndarray) -> np.ndarray:
    """The rotor duties of the logged commands, clipped to [0, 1] as the engine applies them."""
    return np.clip(commands[:, CMD_U1 : CMD_U1 + 4], 0.0, 1.0)
