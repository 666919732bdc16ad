"""A flight on sensors and an estimator as PX4 logs it: the sensor models' readings and the EKF's
state and innovations as PX4's topics, with PX4's field meanings and units (``msg/*.msg`` of
PX4-Autopilot): NED world, FRD body, microseconds.

- ``sensor_combined``: the IMU model's readings at its instants, each the average over its last
  sampling period (``gyro_rad`` [rad/s], ``accelerometer_m_s2`` [m/s^2], FRD), with
  ``gyro_integral_dt`` the period [us]: what PX4 means, in place of the truth's;
- ``vehicle_gps_position`` (``SensorGps``): each fix at its arrival (``timestamp``), taken at
  ``timestamp_sample``: latitude and longitude [deg] of the ENU position on a plane tangent at
  :data:`HOME` (``lat = lat0 + north / R``, ``lon = lon0 + east / (R cos lat0)``, R the WGS84
  equatorial radius; exact to a millimetre over a kilometre), altitude [m] above mean sea level,
  NED velocity [m/s], ``eph``/``epv`` the receiver's standard deviations [m], a 3-D fix;
- ``sensor_baro``: each reading as the static pressure [Pa] of the ISA atmosphere at that altitude
  above :data:`HOME`'s, inverting PX4's own altitude formula (``vehicle_air_data``), at 15 degC;
- ``estimator_states``: PX4 EKF2's state vector order (``quat_nominal`` FRD to NED, ``vel``,
  ``pos`` NED, ``gyro_bias`` [rad/s], ``accel_bias`` [m/s^2] FRD; ``mag_I``, ``mag_B`` and
  ``wind_vel`` not estimated: 0), ``n_states`` 16, and the error covariance's diagonal in EKF2's
  order (rotation, velocity, position, biases; 23 entries, those not estimated 0);
- ``estimator_innovations`` and ``estimator_innovation_variances``: the last update's of each
  stream at each IMU instant, EKF2's sign (predicted minus observed, NED: ``gps_hpos`` north and
  east, ``gps_vpos`` down, ``baro_vpos``, ``heading`` [rad]).
"""

from __future__ import annotations

import math

import numpy as np

from quadcruise import layout as L
from quadcruise.io.ulog import Topic
from quadcruise.sim.px4 import ENU_TO_NED, FLU_TO_FRD, SENSOR_COMBINED

__all__ = ["ESTIMATOR_TOPICS", "HOME", "baro_pressure", "estimator_topics"]

HOME = (47.397742, 8.545594, 488.0)
"""The origin's latitude [deg], longitude [deg] and altitude above mean sea level [m]: PX4 SITL's
default home (``PX4_HOME_LAT``, ``PX4_HOME_LON``, ``PX4_HOME_ALT``)."""
EARTH_RADIUS = 6378137.0
"""WGS84 equatorial radius [m]."""
SENSOR_GPS = (
    ("uint64_t", 0, "timestamp"),
    ("uint64_t", 0, "timestamp_sample"),
    ("double", 0, "latitude_deg"),
    ("double", 0, "longitude_deg"),
    ("double", 0, "altitude_msl_m"),
    ("double", 0, "altitude_ellipsoid_m"),
    ("uint64_t", 0, "time_utc_usec"),
    ("uint32_t", 0, "device_id"),
    ("float", 0, "s_variance_m_s"),
    ("float", 0, "c_variance_rad"),
    ("float", 0, "eph"),
    ("float", 0, "epv"),
    ("float", 0, "hdop"),
    ("float", 0, "vdop"),
    ("int32_t", 0, "noise_per_ms"),
    ("int32_t", 0, "jamming_indicator"),
    ("float", 0, "vel_m_s"),
    ("float", 0, "vel_n_m_s"),
    ("float", 0, "vel_e_m_s"),
    ("float", 0, "vel_d_m_s"),
    ("float", 0, "cog_rad"),
    ("int32_t", 0, "timestamp_time_relative"),
    ("float", 0, "heading"),
    ("float", 0, "heading_offset"),
    ("float", 0, "heading_accuracy"),
    ("uint8_t", 0, "fix_type"),
    ("bool", 0, "vel_ned_valid"),
    ("uint8_t", 0, "satellites_used"),
)
SENSOR_BARO = (
    ("uint64_t", 0, "timestamp"),
    ("uint64_t", 0, "timestamp_sample"),
    ("uint32_t", 0, "device_id"),
    ("float", 0, "pressure"),
    ("float", 0, "temperature"),
    ("uint32_t", 0, "error_count"),
)
ESTIMATOR_STATES = (
    ("uint64_t", 0, "timestamp"),
    ("uint64_t", 0, "timestamp_sample"),
    ("float", 24, "states"),
    ("float", 23, "covariances"),
    ("uint8_t", 0, "n_states"),
)
ESTIMATOR_INNOVATIONS = (
    ("uint64_t", 0, "timestamp"),
    ("uint64_t", 0, "timestamp_sample"),
    ("float", 2, "gps_hvel"),
    ("float", 0, "gps_vvel"),
    ("float", 2, "gps_hpos"),
    ("float", 0, "gps_vpos"),
    ("float", 2, "ev_hvel"),
    ("float", 0, "ev_vvel"),
    ("float", 2, "ev_hpos"),
    ("float", 0, "ev_vpos"),
    ("float", 0, "rng_vpos"),
    ("float", 0, "baro_vpos"),
    ("float", 2, "aux_hvel"),
    ("float", 0, "aux_vvel"),
    ("float", 2, "flow"),
    ("float", 2, "terr_flow"),
    ("float", 0, "heading"),
    ("float", 3, "mag_field"),
    ("float", 2, "drag"),
    ("float", 0, "airspeed"),
    ("float", 0, "beta"),
    ("float", 0, "hagl"),
    ("float", 0, "hagl_rate"),
)
ESTIMATOR_TOPICS = (
    "sensor_combined",
    "vehicle_gps_position",
    "sensor_baro",
    "estimator_states",
    "estimator_innovations",
    "estimator_innovation_variances",
)
"""The topics :func:`estimator_topics` writes."""

# ISA troposphere, as PX4's vehicle_air_data turns pressure into altitude
_T1, _A, _R, _G, _P1 = 15.0 + 273.15, -6.5 / 1000.0, 287.05, 9.80665, 101325.0


def baro_pressure(altitude: np.ndarray) -> np.ndarray:
    """The static pressure [Pa] of the ISA atmosphere at ``altitude`` [m] above mean sea level: the
    inverse of PX4's ``altitude = ((p / p1)^(-a R / g) T1 - T1) / a``.

    Examples
    --------
    >>> float(baro_pressure(np.array([0.0]))[0])
    101325.0
    >>> round(float(baro_pressure(np.array([1000.0]))[0]) / 100.0, 1)   # hPa: ISA gives 898.7 hPa at 1 km
    898.7
    """
    return _P1 * ((np.asarray(altitude, float) * _A + _T1) / _T1) ** (-_G / (_A * _R))


def _col(obs: np.ndarray, name: str) -> np.ndarray:
    return obs[:, L.OBSERVATION_NAMES.index(name)]


def _cols(obs: np.ndarray, *names: str) -> np.ndarray:
    return obs[:, [L.OBSERVATION_NAMES.index(n) for n in names]]


def _rises(obs: np.ndarray, count: str) -> np.ndarray:
    c = np.nan_to_num(_col(obs, count))
    return np.flatnonzero(np.diff(np.r_[0.0, c]) > 0)


def estimator_topics(t: np.ndarray, obs: np.ndarray, sensors: dict, attitude_q: np.ndarray) -> list[Topic]:
    """One vehicle's sensor and estimator topics (the module says which, and their meanings).

    Parameters
    ----------
    t : numpy.ndarray
        (K,) the logged instants [s].
    obs : numpy.ndarray
        (K, OBSERVATION_SIZE) the vehicle's observation log at them.
    sensors : dict
        The flight's sensor models' fields (``meta["sensor_models"]``).
    attitude_q : numpy.ndarray
        (K, 4) the estimate's attitude as PX4's quaternion (FRD to NED, w first).

    Returns
    -------
    list of Topic
    """
    us = np.round(np.asarray(t) * 1e6).astype(np.uint64)
    topics = []
    imu = _rises(obs, "imu_count")
    if "imu" in sensors and imu.size:
        period = int(round(1e6 / float(sensors["imu"]["rate"])))
        topics.append(
            Topic(
                "sensor_combined",
                SENSOR_COMBINED,
                {
                    "timestamp": us[imu],
                    "gyro_rad": _cols(obs, "gyro_x", "gyro_y", "gyro_z")[imu] @ FLU_TO_FRD.T,
                    "accelerometer_m_s2": _cols(obs, "accel_x", "accel_y", "accel_z")[imu] @ FLU_TO_FRD.T,
                    "gyro_integral_dt": np.full(imu.size, period),
                    "accelerometer_integral_dt": np.full(imu.size, period),
                },
            )
        )
    fix = _rises(obs, "gps_count")
    if "gps" in sensors and fix.size:
        gps = sensors["gps"]
        enu = _cols(obs, "gps_x", "gps_y", "gps_z")[fix]
        vel = _cols(obs, "gps_vx", "gps_vy", "gps_vz")[fix] @ ENU_TO_NED.T
        lat0, lon0, alt0 = HOME
        topics.append(
            Topic(
                "vehicle_gps_position",
                SENSOR_GPS,
                {
                    "timestamp": us[fix],
                    "timestamp_sample": np.round(_col(obs, "gps_sample_t")[fix] * 1e6).astype(np.uint64),
                    "latitude_deg": lat0 + np.degrees(enu[:, 1] / EARTH_RADIUS),
                    "longitude_deg": lon0 + np.degrees(enu[:, 0] / (EARTH_RADIUS * math.cos(math.radians(lat0)))),
                    "altitude_msl_m": alt0 + enu[:, 2],
                    "altitude_ellipsoid_m": alt0 + enu[:, 2],
                    "eph": np.full(fix.size, float(gps["horizontal_std"])),
                    "epv": np.full(fix.size, float(gps["vertical_std"])),
                    "s_variance_m_s": np.full(fix.size, float(gps["velocity_std"])),
                    "vel_m_s": np.hypot(vel[:, 0], vel[:, 1]),
                    "vel_n_m_s": vel[:, 0],
                    "vel_e_m_s": vel[:, 1],
                    "vel_d_m_s": vel[:, 2],
                    "cog_rad": np.arctan2(vel[:, 1], vel[:, 0]),
                    "heading": np.full(fix.size, np.nan),
                    "heading_offset": np.full(fix.size, np.nan),
                    "fix_type": np.full(fix.size, 3),
                    "vel_ned_valid": np.ones(fix.size),
                    "satellites_used": np.full(fix.size, 12),
                },
            )
        )
    baro = _rises(obs, "baro_count")
    if "baro" in sensors and baro.size:
        topics.append(
            Topic(
                "sensor_baro",
                SENSOR_BARO,
                {
                    "timestamp": us[baro],
                    "timestamp_sample": us[baro],
                    "pressure": baro_pressure(HOME[2] + _col(obs, "baro_alt")[baro]),
                    "temperature": np.full(baro.size, 15.0),
                },
            )
        )
    est = imu[np.isfinite(_col(obs, "x_est")[imu])] if imu.size else imu
    if est.size:
        o = obs[est]
        states = np.zeros((est.size, 24))
        states[:, 0:4] = attitude_q[est]
        states[:, 4:7] = _cols(o, "vx_est", "vy_est", "vz_est") @ ENU_TO_NED.T
        states[:, 7:10] = _cols(o, "x_est", "y_est", "z_est") @ ENU_TO_NED.T
        states[:, 10:13] = _cols(o, "gyro_bias_x_est", "gyro_bias_y_est", "gyro_bias_z_est") @ FLU_TO_FRD.T
        states[:, 13:16] = _cols(o, "accel_bias_x_est", "accel_bias_y_est", "accel_bias_z_est") @ FLU_TO_FRD.T
        sd = o[:, L.O_SD : L.O_SD + 15]  # ours: position, velocity, attitude, gyro bias, accel bias
        cov = np.zeros((est.size, 23))
        cov[:, 0:3] = sd[:, 6:9] ** 2  # a rotation's variance per body axis (FLU and FRD alike)
        cov[:, 3:6] = (sd[:, 3:6] ** 2)[:, [1, 0, 2]]  # east, north, up -> north, east, down
        cov[:, 6:9] = (sd[:, 0:3] ** 2)[:, [1, 0, 2]]
        cov[:, 9:12] = sd[:, 9:12] ** 2
        cov[:, 12:15] = sd[:, 12:15] ** 2
        topics.append(
            Topic(
                "estimator_states",
                ESTIMATOR_STATES,
                {
                    "timestamp": us[est],
                    "timestamp_sample": us[est],
                    "states": states,
                    "covariances": cov,
                    "n_states": np.full(est.size, 16),
                },
            )
        )
        for name, first in (("estimator_innovations", L.O_INNOV), ("estimator_innovation_variances", L.O_INNOV_VAR)):
            v = np.nan_to_num(o[:, first : first + 8])  # gps x y z, gps vx vy vz, baro, heading (ENU)
            sign = -1.0 if name == "estimator_innovations" else 1.0  # predicted - observed, NED
            topics.append(
                Topic(
                    name,
                    ESTIMATOR_INNOVATIONS,
                    {
                        "timestamp": us[est],
                        "timestamp_sample": us[est],
                        "gps_hpos": sign * v[:, [1, 0]],
                        "gps_vpos": v[:, 2],
                        "gps_hvel": sign * v[:, [4, 3]],
                        "gps_vvel": v[:, 5],
                        "baro_vpos": v[:, 6],
                        "heading": v[:, 7],
                    },
                )
            )
    return topics
