"""Our EKF on a PX4 log's own sensors, compared with what PX4's EKF2 estimated in flight.

:func:`estimate_log` reads the log (:func:`quadcruise.io.sensorlog.read_sensor_log`), aligns
the filter while the vehicle rests before its first GPS fix (roll and pitch from the mean
specific force, yaw from the magnetometer and the declination, the gyro bias from the mean
rate, the barometer's offset from the first fix), runs :func:`quadcruise.estimation.run_ekf`
from that fix to the end, and compares at EKF2's own instants: roll, pitch and yaw [deg],
altitude and horizontal position [m], RMS.
"""

from __future__ import annotations

import json
import math
import os
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np
from scipy.spatial.transform import Rotation

from quadcruise._version import __version__
from quadcruise.errors import InputError
from quadcruise.estimation import EkfNoise, EkfRun, run_ekf
from quadcruise.io.sensorlog import SensorLog, read_sensor_log

ALIGN_S = 2.0
"""The rest before the first GPS fix over which the filter is aligned [s]."""
LOG_NOISE = EkfNoise(
    gyro_noise=1.5e-3,
    accel_noise=3.5e-2,
    gyro_bias_walk=1e-4,
    accel_bias_walk=3e-4,
    gps_horizontal_std=0.5,
    gps_vertical_std=0.8,
    gps_velocity_std=0.3,
    gps_vertical_velocity_std=0.3,
    baro_std=0.5,
    heading_std=0.1,
    gate=0.9999,
)
"""The filter's settings for a PX4 log: EKF2's default noise parameters (EKF2_GYR_NOISE 0.015 rad/s,
EKF2_ACC_NOISE 0.35 m/s^2, EKF2_GYR_B_NOISE 1e-3, EKF2_ACC_B_NOISE 3e-3, per sample of its 100 Hz
update) as densities (times sqrt(0.01 s)), its GPS noise floors, and a 0.5 m barometer and 0.1 rad
heading noise."""


@dataclass(frozen=True, eq=False)
class EstimateResult:
    """Our EKF's run on a log, compared with EKF2's.

    Parameters
    ----------
    log : SensorLog
        The streams read.
    run : EkfRun
        Our filter's output.
    figures : dict
        RMS differences from EKF2 (``roll_deg``, ``pitch_deg``, ``yaw_deg``, ``altitude_m``,
        ``horizontal_m``), EKF2's own roll and pitch RMS (what an estimate of "level" would
        score: ``ekf2_roll_rms_deg``, ``ekf2_pitch_rms_deg``), the samples counted, the
        updates the gate refused and each stream's mean NIS (its degrees of freedom if the
        settings fit the log's sensors).
    config : dict
        What was run: settings, declination and its source, alignment, start.
    command : str
        The command line, for the record.
    series : dict
        What the figure draws: ``att_t``, ``ours_att``, ``ekf2_att`` (roll, pitch, yaw [deg])
        at EKF2's attitude instants; ``pos_t``, ``ours_pos``, ``ekf2_pos`` (ENU [m]) at its
        position instants.
    """

    log: SensorLog
    run: EkfRun
    figures: dict
    config: dict
    command: str = ""
    series: dict = field(default_factory=dict, repr=False)

    def summary(self) -> dict:
        """The RMS differences from EKF2.

        Returns
        -------
        dict
            Name -> value (degrees, metres, counts).
        """
        return dict(self.figures)

    def table(self) -> str:
        """One line per figure: name, RMS difference from EKF2.

        Returns
        -------
        str
            The lines.
        """
        units = {"roll_deg": "deg", "pitch_deg": "deg", "yaw_deg": "deg", "altitude_m": "m", "horizontal_m": "m"}
        return "\n".join(
            f"{k[: k.rfind('_')]:<11} RMS diff from EKF2 {self.figures[k]:8.3f} {u}" for k, u in units.items()
        )

    def plot(self):
        """Our estimate against EKF2's: roll, pitch, yaw, altitude, east and north.

        Returns
        -------
        matplotlib.figure.Figure
            Six panels over time.
        """
        from matplotlib.figure import Figure

        fig = Figure(figsize=(9, 9))
        axes = fig.subplots(6, 1, sharex=True)
        s = self.series
        labels = ["roll [deg]", "pitch [deg]", "yaw [deg]", "altitude [m]", "east [m]", "north [m]"]
        for i, ax in enumerate(axes):
            t, ours, theirs = (s["att_t"], s["ours_att"][:, i], s["ekf2_att"][:, i]) if i < 3 else (
                s["pos_t"], s["ours_pos"][:, [2, 0, 1][i - 3]], s["ekf2_pos"][:, [2, 0, 1][i - 3]])  # fmt: skip
            ax.plot(t, theirs, "k-", lw=1.0, label="EKF2 (log)")
            ax.plot(t, ours, "C1--", lw=1.0, label="quadcruise EKF")
            ax.set_ylabel(labels[i])
        axes[0].legend(loc="best", fontsize=8)
        axes[-1].set_xlabel("time in log [s]")
        fig.suptitle(Path(self.log.source).name)
        fig.tight_layout()
        return fig

    def write(self, folder: str | os.PathLike, *, force: bool = False) -> Path:
        """Write ``estimate.json``, ``estimate.png`` and the marker into ``folder``, whole or not at all.

        Parameters
        ----------
        folder : str or os.PathLike
            The output folder.
        force : bool
            Replace a folder quadcruise did not write.

        Returns
        -------
        pathlib.Path
            The folder.
        """
        from quadcruise.io.files import MARKER, atomic_dir, check_output_dir

        out = check_output_dir(folder, force)
        doc = {"log": self.log.source, "compared_with": "EKF2 (vehicle_attitude, vehicle_local_position)",
               "rms": self.figures, "config": self.config}  # fmt: skip
        with atomic_dir(out) as tmp:
            (Path(tmp) / "estimate.json").write_text(json.dumps(doc, indent=2) + "\n")
            self.plot().savefig(Path(tmp) / "estimate.png", dpi=100)
            marker = {"workflow": "estimate", "version": __version__, "command": self.command, "log": self.log.source}
            (Path(tmp) / MARKER).write_text(json.dumps(marker, indent=2) + "\n")
        return out


def _euler_deg(q: np.ndarray) -> np.ndarray:
    """Roll, pitch, yaw [deg] (ZYX) of w-first quaternions."""
    return Rotation.from_quat(q[:, [1, 2, 3, 0]]).as_euler("ZYX", degrees=True)[:, ::-1]


def align(log: SensorLog, t0: float, declination: float) -> tuple[np.ndarray, np.ndarray, float]:
    """The initial state, the world field and the barometer's offset from the rest before ``t0``.

    Parameters
    ----------
    log : SensorLog
        The streams.
    t0 : float
        The filter's start (the first GPS fix) [s].
    declination : float
        [rad], east of north.

    Returns
    -------
    tuple
        x0 (16,), field (3,) ENU [G], baro offset [m].

    Raises
    ------
    InputError
        The vehicle was not at rest before its first fix, or no magnetometer or barometer reading then.
    """
    rest = (log.imu_t >= t0 - ALIGN_S) & (log.imu_t <= t0)
    mrest = (log.mag_t >= t0 - ALIGN_S) & (log.mag_t <= t0)
    brest = (log.baro_t >= t0 - ALIGN_S) & (log.baro_t <= t0)
    if rest.sum() < 10 or not mrest.any() or not brest.any():
        raise InputError(
            f"{log.source}: too few IMU, magnetometer or barometer samples"
            f" in the {ALIGN_S:g} s before the first GPS fix"
        )
    gyro, acc = log.imu[rest, :3], log.imu[rest, 3:]
    if np.linalg.norm(gyro.mean(0)) > 0.05 or acc.std(0).max() > 0.5:
        raise InputError(
            f"{log.source}: the vehicle is not at rest in the {ALIGN_S:g} s before the first GPS fix (t = {t0:.2f} s)"
        )
    f = acc.mean(0)
    roll, pitch = math.atan2(f[1], f[2]), math.atan2(-f[0], math.hypot(f[1], f[2]))
    tilt = Rotation.from_euler("YX", [pitch, roll])
    m = tilt.apply(log.mag[mrest].mean(0))  # the field in the level frame
    yaw = (math.pi / 2 - declination) - math.atan2(m[1], m[0])
    q = Rotation.from_euler("ZYX", [yaw, pitch, roll]).as_quat()[[3, 0, 1, 2]]
    h = math.hypot(m[0], m[1])
    field = np.array([h * math.sin(declination), h * math.cos(declination), m[2]])
    x0 = np.r_[log.gps[0, :3], 0.0, 0.0, 0.0, q, gyro.mean(0), 0.0, 0.0, 0.0]
    return x0, field, float(log.baro[brest].mean() - log.gps[0, 2])


def estimate_log(
    path: str | os.PathLike, settings: EkfNoise = LOG_NOISE, declination: float | None = None, command: str = ""
) -> EstimateResult:
    """Run our EKF on a PX4 log's sensors and compare it with the log's EKF2 estimate.

    Parameters
    ----------
    path : str or os.PathLike
        The ``.ulg`` file.
    settings : EkfNoise
        The filter's noise settings.
    declination : float, optional
        [rad], east of north; by default the log's ``EKF2_MAG_DECL``, else 0.
    command : str
        The command line, for the record.

    Returns
    -------
    EstimateResult
        The run and its RMS differences from EKF2.

    Examples
    --------
    >>> r = estimate_log("tests/data/px4/sample_px4_events.ulg")
    >>> r.figures["roll_deg"] < 2.0 and r.figures["altitude_m"] < 0.5
    True
    """
    log = read_sensor_log(path)
    source = "EKF2_MAG_DECL" if declination is None and log.declination is not None else "given"
    if declination is None:
        declination, source = (log.declination, source) if log.declination is not None else (0.0, "default 0")
    t0 = float(log.gps_t[0])
    x0, field_w, offset = align(log, t0, declination)
    keep = log.imu_t >= t0
    sd0 = np.r_[[1.0] * 3, [0.3] * 3, [0.05, 0.05, 0.2], [0.01] * 3, [0.2] * 3]
    run = run_ekf(
        log.imu_t[keep], log.imu[keep], x0, np.diag(sd0**2), settings,
        gps=(log.gps_t, log.gps), baro=(log.baro_t[log.baro_t >= t0], log.baro[log.baro_t >= t0]),
        mag=(log.mag_t[log.mag_t >= t0], log.mag[log.mag_t >= t0]), field=field_w, baro_offset=offset, stride=50,
    )  # fmt: skip
    at = (log.att_t >= run.t[0]) & (log.att_t <= run.t[-1])
    pt = (log.pos_t >= run.t[0]) & (log.pos_t <= run.t[-1])
    if at.sum() < 2 or pt.sum() < 2:
        raise InputError(f"{log.source}: EKF2's estimate does not overlap the sensors' stretch after the first GPS fix")
    # ours at EKF2's instants: positions interpolated, attitudes by the nearest earlier IMU instant
    k = np.clip(np.searchsorted(run.t, log.att_t[at], side="right") - 1, 0, run.t.size - 1)
    ours_att, ekf2_att = _euler_deg(run.x[k, 6:10]), _euler_deg(log.att[at])
    d_att = (ours_att - ekf2_att + 180.0) % 360.0 - 180.0
    ours_pos = np.column_stack([np.interp(log.pos_t[pt], run.t, run.x[:, i]) for i in range(3)])
    d_pos = ours_pos - log.pos[pt]
    rms = lambda a: float(np.sqrt(np.mean(np.square(a))))  # noqa: E731
    figures = {
        "roll_deg": rms(d_att[:, 0]),
        "pitch_deg": rms(d_att[:, 1]),
        "yaw_deg": rms(d_att[:, 2]),
        "altitude_m": rms(d_pos[:, 2]),
        "horizontal_m": rms(np.hypot(d_pos[:, 0], d_pos[:, 1])),
        "ekf2_roll_rms_deg": rms(ekf2_att[:, 0]),
        "ekf2_pitch_rms_deg": rms(ekf2_att[:, 1]),
        "attitude_samples": int(at.sum()),
        "position_samples": int(pt.sum()),
        "gated_updates": {n: int(np.sum(v < 0)) for n, v in run.nis.items()},
        "mean_nis": {n: float(np.mean(np.abs(v))) if v.size else None for n, v in run.nis.items()},
    }
    config = {
        "settings": {f: getattr(settings, f) for f in settings.units()},
        "declination_rad": declination,
        "declination_source": source,
        "start_s": t0,
        "alignment_s": ALIGN_S,
        "world_field_G": field_w.tolist(),
        "baro_offset_m": offset,
        "frames": "ENU world about EKF2's origin, FLU body",
    }
    series = {"att_t": log.att_t[at], "ours_att": ours_att, "ekf2_att": ekf2_att, "pos_t": log.pos_t[pt],
              "ours_pos": ours_pos, "ekf2_pos": log.pos[pt]}  # fmt: skip
    return EstimateResult(log, run, figures, config, command, series)
