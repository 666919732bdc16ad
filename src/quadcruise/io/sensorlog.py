"""A PX4 log's raw sensor streams and EKF2's estimate, read into quadcruise's frames (ENU world,
FLU body, quaternions w first body to world, seconds from the log's start), for running our own
estimator on them (:mod:`quadcruise.workflows.estimate`).

Read: ``sensor_combined`` (gyro, accelerometer), ``vehicle_gps_position`` (else
``sensor_gps``: latitude, longitude, altitude AMSL, NED velocity), ``vehicle_air_data``
(``baro_alt_meter``), ``vehicle_magnetometer`` (``magnetometer_ga``), and EKF2's
``vehicle_attitude`` and ``vehicle_local_position`` (with its origin ``ref_lat``, ``ref_lon``,
``ref_alt``). GPS fixes are placed in EKF2's local frame by the equirectangular approximation
about its origin (under 1 mm apart from PX4's azimuthal projection within a few hundred m).
"""

from __future__ import annotations

import contextlib
import io
import math
import os
import struct
from dataclasses import dataclass
from pathlib import Path

import numpy as np
from scipy.spatial.transform import Rotation

from quadcruise.errors import InputError
from quadcruise.io import logchecks
from quadcruise.io.flightlog import FRD_TO_FLU, NED_TO_ENU

EARTH_RADIUS = 6371000.0
"""[m], for the GPS fixes' local coordinates."""
NEEDED = (
    ("sensor_combined",),
    ("vehicle_gps_position", "sensor_gps"),
    ("vehicle_air_data",),
    ("vehicle_magnetometer",),
    ("vehicle_attitude",),
    ("vehicle_local_position",),
)
"""The topics an estimate needs (one of each tuple, the first found)."""


@dataclass(frozen=True, eq=False)
class SensorLog:
    """A log's sensor streams and EKF2's estimate, in quadcruise's frames.

    Parameters
    ----------
    source : str
        The file.
    imu_t, imu : numpy.ndarray
        (K,) [s]; (K, 6) gyro [rad/s] and accelerometer [m/s^2], FLU.
    gps_t, gps : numpy.ndarray
        (G,) [s]; (G, 6) ENU position about EKF2's origin [m] and velocity [m/s].
    baro_t, baro : numpy.ndarray
        (B,) [s]; (B,) barometric altitude [m].
    mag_t, mag : numpy.ndarray
        (M,) [s]; (M, 3) field [G], FLU.
    att_t, att : numpy.ndarray
        EKF2's attitude: (A,) [s]; (A, 4) quaternion w first, FLU to ENU.
    pos_t, pos : numpy.ndarray
        EKF2's local position: (L,) [s]; (L, 3) ENU [m].
    declination : float or None
        ``EKF2_MAG_DECL`` [rad], the declination PX4 used, if the log has it.
    """

    source: str
    imu_t: np.ndarray
    imu: np.ndarray
    gps_t: np.ndarray
    gps: np.ndarray
    baro_t: np.ndarray
    baro: np.ndarray
    mag_t: np.ndarray
    mag: np.ndarray
    att_t: np.ndarray
    att: np.ndarray
    pos_t: np.ndarray
    pos: np.ndarray
    declination: float | None = None


def read_sensor_log(path: str | os.PathLike) -> SensorLog:
    """Read a PX4 ULog's sensors and EKF2's estimate.

    Parameters
    ----------
    path : str or os.PathLike
        The ``.ulg`` file.

    Returns
    -------
    SensorLog
        The streams in ENU/FLU.

    Raises
    ------
    InputError
        An unreadable file, or one without a needed topic (named), or with too few samples.

    Examples
    --------
    >>> from pathlib import Path
    >>> log = read_sensor_log(Path("tests/data/px4/sample_px4_events.ulg"))
    >>> log.imu.shape[1], round(float(log.imu_t[1] - log.imu_t[0]), 3)
    (6, 0.004)
    """
    from pyulog import ULog
    from pyulog.core import ULogException

    path = Path(path)
    logchecks.check_ulog_framing(path)
    names = [n for group in NEEDED for n in group]
    try:
        with contextlib.redirect_stdout(io.StringIO()):
            log = ULog(str(path), names)
    except (ULogException, struct.error, ValueError, IndexError, UnicodeDecodeError) as exc:
        raise InputError(f"{path}: not a readable PX4 log ({exc})") from None
    topics: dict = {}
    for d in log.data_list:
        if d.multi_id == 0 or d.name not in topics:
            topics[d.name] = d.data
    chosen = []
    for group in NEEDED:
        found = [n for n in group if n in topics and len(topics[n]["timestamp"]) >= 2]
        if not found:
            raise InputError(f"{path}: no {' or '.join(group)} topic: an estimate needs it")
        chosen.append(found[0])
    sc, gps, air, mag, att, lp = (topics[n] for n in chosen)

    def times(d: dict) -> np.ndarray:
        t = d.get("timestamp_sample", d["timestamp"]).astype(np.int64)
        t = np.where(t > 0, t, d["timestamp"].astype(np.int64))
        return (t - int(log.start_timestamp)) * 1e-6

    def cols(d: dict, fmt: str, n: int = 3) -> np.ndarray:
        return np.column_stack([d[fmt.format(i)].astype(np.float64) for i in range(n)])

    B, A = FRD_TO_FLU, NED_TO_ENU
    imu = np.column_stack([cols(sc, "gyro_rad[{}]") @ B, cols(sc, "accelerometer_m_s2[{}]") @ B])
    ok = lp["xy_global"].astype(bool) if "xy_global" in lp else np.ones(len(lp["timestamp"]), bool)
    if not ok.any():
        raise InputError(f"{path}: vehicle_local_position never has a global origin (ref_lat, ref_lon)")
    lat0, lon0 = math.radians(lp["ref_lat"][ok][-1]), math.radians(lp["ref_lon"][ok][-1])
    alt0 = float(lp["ref_alt"][ok][-1])
    fix = gps["fix_type"] >= 3 if "fix_type" in gps else np.ones(len(gps["timestamp"]), bool)
    north = (np.radians(gps["latitude_deg"][fix]) - lat0) * EARTH_RADIUS
    east = (np.radians(gps["longitude_deg"][fix]) - lon0) * EARTH_RADIUS * math.cos(lat0)
    up = gps["altitude_msl_m"][fix] - alt0
    vel = np.column_stack([gps[f"vel_{c}_m_s"][fix] for c in "ned"]) @ A
    quat = Rotation.from_matrix(A @ Rotation.from_quat(cols(att, "q[{}]", 4)[:, [1, 2, 3, 0]]).as_matrix() @ B)
    pos = np.column_stack([lp["x"], lp["y"], lp["z"]]).astype(np.float64) @ A
    decl = log.initial_parameters.get("EKF2_MAG_DECL")
    return SensorLog(
        source=str(path),
        imu_t=(sc["timestamp"].astype(np.int64) - int(log.start_timestamp)) * 1e-6,
        imu=imu,
        gps_t=times(gps)[fix],
        gps=np.column_stack([east, north, up, vel]),
        baro_t=times(air),
        baro=air["baro_alt_meter"].astype(np.float64),
        mag_t=times(mag),
        mag=cols(mag, "magnetometer_ga[{}]") @ B,
        att_t=times(att),
        att=quat.as_quat()[:, [3, 0, 1, 2]],
        pos_t=times(lp),
        pos=pos,
        declination=None if decl is None else math.radians(float(decl)),
    )
