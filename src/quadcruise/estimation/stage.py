"""What a flight on sensors and an estimator is given: :class:`Sensors` (which sensors, each a
model of :mod:`quadcruise.sensors`), :class:`Ekf` (the filter's settings), and
:func:`observation`, which checks them against the flight's control period and packs them into
the :class:`~quadcruise.sim.observe.Observation` the kernels take (the compiled stage:
:mod:`quadcruise.estimation.onboard`).

Examples
--------
>>> from quadcruise.sensors import Gps, Imu
>>> obs = observation(Sensors(imu=Imu(rate=250.0), gps=Gps(rate=10.0)), Ekf(), n=2, dt=1e-3, seed=1)
>>> obs.params.shape[0], obs.active
(2, True)
>>> observation(Sensors(imu=Imu(rate=300.0)), None, n=1, dt=1e-3, seed=1)
Traceback (most recent call last):
    ...
quadcruise.errors.InputError: imu rate 300 Hz does not divide the control rate 1000 Hz
"""

from __future__ import annotations

import dataclasses
import math
from dataclasses import dataclass

import numpy as np

from quadcruise.errors import InputError
from quadcruise.estimation.onboard import PARAMS, memory_row, onboard
from quadcruise.estimation.run import EkfNoise
from quadcruise.fields import Validated, unit_field
from quadcruise.fields.checks import Check
from quadcruise.sensors import BMI088, ICM42688P, Baro, Gps, Imu, Magnetometer
from quadcruise.sensors.timing import periods_per_sample
from quadcruise.sim.observe import Observation, sensor_streams

SENSOR_NAMES = ("imu", "gps", "baro", "mag")
"""The sensors a vehicle may carry, by name (the fields of :class:`Sensors`)."""

TYPICAL_IMU = dataclasses.replace(BMI088, rate=250.0)
"""The IMU of ``Sensors.typical()``: :data:`~quadcruise.sensors.BMI088`'s noise, range and
switch-on biases, read at 250 Hz (a divisor of the default 1 kHz control rate; PX4 runs its
rate loop at its gyro's rate, ``IMU_GYRO_RATEMAX`` 400 Hz by default)."""

PRESETS = {
    "imu": {
        "typical": TYPICAL_IMU,
        "bmi088": BMI088,
        "bmi088_1khz": dataclasses.replace(BMI088, rate=1000.0),
        "icm42688p": ICM42688P,
        "ideal": Imu(),
    },
    "gps": {"typical": Gps(rate=10.0, latency=0.1), "ideal": Gps(horizontal_std=0.0, vertical_std=0.0,
                                                                 velocity_std=0.0, vertical_velocity_std=0.0)},
    "baro": {"typical": Baro(rate=50.0, noise_std=0.1), "ideal": Baro(noise_std=0.0)},
    "mag": {"typical": Magnetometer(rate=50.0), "ideal": Magnetometer(noise_std=0.0)},
}  # fmt: skip
"""Each sensor's models by name: ``typical`` is what ``fly --sensors imu,gps,baro,mag`` flies
(GPS at 10 Hz, 0.1 s late, 0.5 m / 0.8 m; barometer 50 Hz, 0.1 m; magnetometer 50 Hz, 5 mG at a
0.5 G field inclined 60 deg); the IMU presets carry their datasheets' sources
(:mod:`quadcruise.sensors.imu`), ``bmi088_1khz`` is the BMI088 read at 1 kHz (one of its gyro's
output rates; the rate the default control period reads it at every period); ``ideal`` reads the
truth without noise."""


def _model(kind):
    return Check(f"{kind.__name__}", f"a {kind.__name__} or None", lambda v: v is None or isinstance(v, kind))


@dataclass(frozen=True)
class Sensors(Validated):
    """The sensors a vehicle carries (None: not carried).

    Parameters
    ----------
    imu : Imu, optional
        Gyroscope and accelerometer.
    gps : Gps, optional
        Position and velocity fixes.
    baro : Baro, optional
        Barometric altitude.
    mag : Magnetometer, optional
        The earth's field in the body frame.

    Examples
    --------
    >>> Sensors.typical(("imu", "gps")).names()
    ('imu', 'gps')
    """

    imu: Imu | None = unit_field(None, "-", "IMU model", _model(Imu))
    gps: Gps | None = unit_field(None, "-", "GPS model", _model(Gps))
    baro: Baro | None = unit_field(None, "-", "barometer model", _model(Baro))
    mag: Magnetometer | None = unit_field(None, "-", "magnetometer model", _model(Magnetometer))
    name = "sensors"

    @classmethod
    def typical(cls, names=SENSOR_NAMES) -> Sensors:
        """The ``typical`` preset of each sensor named (:data:`PRESETS`).

        Parameters
        ----------
        names : sequence of str
            Of :data:`SENSOR_NAMES`.

        Returns
        -------
        Sensors
        """
        unknown = [n for n in names if n not in SENSOR_NAMES]
        if unknown:
            raise InputError(f"unknown sensor {unknown[0]!r}; known: {', '.join(SENSOR_NAMES)}")
        return cls(**{n: PRESETS[n]["typical"] for n in names})

    def names(self) -> tuple[str, ...]:
        """The sensors carried, in :data:`SENSOR_NAMES`' order.

        Returns
        -------
        tuple of str
        """
        return tuple(n for n in SENSOR_NAMES if getattr(self, n) is not None)

    def to_dict(self) -> dict:
        """Each sensor carried with its parameters (a scenario's ``[sensors]`` table).

        Returns
        -------
        dict
            ``{name: {field: value}}``.
        """
        return {n: dataclasses.asdict(getattr(self, n)) for n in self.names()}


@dataclass(frozen=True)
class Ekf(Validated):
    """The error-state EKF between the sensors and the controller (:mod:`quadcruise.estimation.ekf`).

    Parameters
    ----------
    init_position_std : float
        The initial estimate's position error std [m] per axis (drawn, and the filter's P0).
    init_velocity_std : float
        Its velocity error std [m/s].
    init_attitude_std : float
        Its attitude error std [rad] per axis.
    rate_cutoff : float
        Cutoff of a first-order low-pass on the body rates the controller sees [Hz]; 0 (the
        default): none, the rates are the gyro's average over its period less the estimated bias
        (already a low-pass, and half a period late). PX4 filters its rate loop's gyro at
        ``IMU_GYRO_CUTOFF`` (40 Hz by default), for gains tuned with it; the paper's attitude
        loop, whose derivative acts at some 500 rad/s, loses its margin to it (3 of 100 circles
        of ``benchmarks/estimator_cost.py``'s batch diverged at 40 Hz, 1 without).
    gate : float
        The innovation gate's chi-square probability (1: no gate).
    noise_scale : float
        The filter's noise settings are the sensors' own, times this (1: a matched filter).
    latency_compensation : bool
        Fuse a late GPS fix against the estimate of the instant it was taken (its latency known),
        rather than against the present one.
    noise : EkfNoise, optional
        The filter's noise settings given outright (then ``noise_scale`` and ``gate`` are not used).

    Examples
    --------
    >>> Ekf().rate_cutoff, Ekf(rate_cutoff=40.0).rate_cutoff
    (0.0, 40.0)
    """

    init_position_std: float = unit_field(0.1, "m", "initial position error std", "pos")
    init_velocity_std: float = unit_field(0.05, "m/s", "initial velocity error std", "pos")
    init_attitude_std: float = unit_field(math.radians(1.0), "rad", "initial attitude error std", "pos")
    rate_cutoff: float = unit_field(0.0, "Hz", "rate low-pass cutoff", "nonneg")
    gate: float = unit_field(0.999, "-", "innovation gate probability", "frac")
    noise_scale: float = unit_field(1.0, "-", "scale on the matched noise settings", "pos")
    latency_compensation: bool = unit_field(True, "-", "fuse a late GPS fix at its own time", "flag")
    noise: EkfNoise | None = unit_field(None, "-", "the filter's noise settings", _model(EkfNoise))
    name = "ekf"

    def settings(self, sensors: Sensors, g: float = 9.80665) -> EkfNoise:
        """The filter's noise settings: :attr:`noise`, else matched to ``sensors``.

        Matched: the IMU's densities with its resolution's quantisation noise (``lsb^2 / 12`` a
        sample) added, its bias walks; the GPS's and barometer's standard deviations; the
        heading's ``noise_std / H`` with H the field's horizontal strength; all times
        :attr:`noise_scale`. A barometer's drift and a magnetometer's hard-iron bias are not in
        the filter's model.

        Parameters
        ----------
        sensors : Sensors
        g : float
            Gravity [m/s^2].

        Returns
        -------
        EkfNoise
        """
        if self.noise is not None:
            return self.noise
        c = self.noise_scale
        imu, gps, baro, mag = sensors.imu or Imu(), sensors.gps or Gps(), sensors.baro or Baro(), sensors.mag
        quant = lambda n, lsb: math.sqrt(n**2 + lsb**2 / (12.0 * imu.rate))  # noqa: E731
        heading = 0.02 if mag is None else mag.noise_std / (mag.strength * math.cos(mag.inclination))
        floor = 1e-9
        return EkfNoise(
            gyro_noise=c * max(quant(imu.gyro_noise, imu.gyro_lsb), floor),
            accel_noise=c * max(quant(imu.accel_noise, imu.accel_lsb), floor),
            gyro_bias_walk=c * imu.gyro_bias_walk,
            accel_bias_walk=c * imu.accel_bias_walk,
            gps_horizontal_std=c * max(gps.horizontal_std, 1e-3),
            gps_vertical_std=c * max(gps.vertical_std, 1e-3),
            gps_velocity_std=c * max(gps.velocity_std, 1e-3),
            gps_vertical_velocity_std=c * max(gps.vertical_velocity_std, 1e-3),
            baro_std=c * max(baro.noise_std, 1e-3),
            heading_std=c * max(heading, 1e-4),
            gate=self.gate,
            gravity=g,
        )

    def p0(self, sensors: Sensors) -> np.ndarray:
        """The initial standard deviations of the 15 error states: position, velocity, attitude,
        then the biases the IMU's switch-on spreads (at least 1e-4 rad/s and 1e-3 m/s^2).

        Parameters
        ----------
        sensors : Sensors

        Returns
        -------
        numpy.ndarray
            (15,).
        """
        imu = sensors.imu or Imu()
        return np.repeat(
            [
                self.init_position_std,
                self.init_velocity_std,
                self.init_attitude_std,
                max(imu.gyro_bias_init, 1e-4),
                max(imu.accel_bias_init, 1e-3),
            ],
            3,
        )

    def to_dict(self) -> dict:
        """The settings (a scenario's ``[estimator]`` table, ``kind = "ekf"``).

        Returns
        -------
        dict
        """
        out = {"kind": "ekf", **dataclasses.asdict(self)}
        if self.noise is None:
            out.pop("noise")
        return out


def check_estimator(sensors: Sensors | None, estimator: Ekf | None, where: str = "estimator") -> None:
    """Refuse an estimator without the sensors it needs, in one line: the EKF predicts from the IMU
    and needs the GPS (without it the horizontal position is unobservable and drifts as the
    double integral of the accelerometer's error).

    Parameters
    ----------
    sensors : Sensors or None
    estimator : Ekf or None
    where : str
        How the message names the estimator's option.

    Raises
    ------
    InputError
    """
    if estimator is None:
        return
    have = () if sensors is None else sensors.names()
    for need, why in (
        ("imu", "it predicts from the IMU"),
        ("gps", "without it the horizontal position is unobservable"),
    ):
        if need not in have:
            raise InputError(
                f"{where} ekf needs the sensor {need!r} ({why}); sensors given: {', '.join(have) or 'none'}"
            )


def observation(
    sensors: Sensors, estimator: Ekf | None, *, n: int, dt: float, seed: int, first_vehicle=0, g: float = 9.80665
) -> Observation:
    """The observation stage of ``n`` vehicles flown at the control period ``dt``, checked.

    Parameters
    ----------
    sensors : Sensors
        What each vehicle carries.
    estimator : Ekf or None
        The filter; None: the sensors are logged and the controller sees the truth.
    n : int
        Vehicles.
    dt : float
        The control period [s].
    seed : int
        The flight's seed.
    first_vehicle : int or (n,) array of int
        The vehicles' indices (their streams: :func:`~quadcruise.sim.observe.sensor_streams`).
    g : float
        Gravity [m/s^2] the filter assumes.

    Returns
    -------
    Observation
        Its ``params`` rows (:data:`~quadcruise.estimation.onboard.PARAMS`) may be edited per
        vehicle before a flight (a spread of sensors in a population).

    Raises
    ------
    InputError
        A sensor whose rate does not divide the control rate, or is faster than the IMU; an
        estimator without the sensors it needs; no sensor.
    """
    if not sensors.names():
        raise InputError("sensors: none given (imu, gps, baro or mag)")
    check_estimator(sensors, estimator)
    every = {name: periods_per_sample(name, getattr(sensors, name).rate, dt) for name in sensors.names()}
    if sensors.imu is not None:
        for name in sensors.names()[1:]:
            if every[name] < every["imu"]:
                raise InputError(
                    f"{name} rate {getattr(sensors, name).rate:g} Hz is above the imu rate {sensors.imu.rate:g} Hz "
                    "(its readings are fused at the IMU's instants)"
                )
    gps = sensors.gps
    delay = 0 if gps is None else int(math.ceil(gps.latency / dt - 1e-9))
    slots = 1 if gps is None else delay // every["gps"] + 2
    compensate = estimator is not None and estimator.latency_compensation and gps is not None and delay > 0
    history = delay // every.get("imu", 1) + 3 if compensate else 0
    ekf = estimator.settings(sensors, g) if estimator is not None else EkfNoise(gravity=g)
    values = {
        **{f"{name}_on": float(getattr(sensors, name) is not None) for name in ("imu", "gps", "baro", "mag")},
        "ekf_on": float(estimator is not None),
        **{f"{name}_every": float(every.get(name, 1)) for name in ("imu", "gps", "baro", "mag")},
        "gps_delay": float(delay),
        "gps_slots": float(slots),
        "history": float(history),
        "imu": (sensors.imu or Imu()).row(),
        "gps": (gps or Gps()).row(),
        "baro": (sensors.baro or Baro()).row(),
        "mag": (sensors.mag or Magnetometer()).row(),
        "field": (sensors.mag or Magnetometer()).world_field(),
        "noise": ekf.noise_row(),
        "meas": ekf.meas_row(),
        "gates": ekf.gates(),
        "p0": (estimator or Ekf()).p0(sensors),
        "rate_alpha": 1.0,
    }
    if estimator is not None and estimator.rate_cutoff > 0 and sensors.imu is not None:
        values["rate_alpha"] = 1.0 - math.exp(-2.0 * math.pi * estimator.rate_cutoff * every["imu"] * dt)
    params = PARAMS.pack(values, n=n)
    memory = np.zeros((n, memory_row(slots, history).size))
    return Observation(onboard, params, memory, sensor_streams(seed, n, first_vehicle), True)


__all__ = ["PRESETS", "SENSOR_NAMES", "Ekf", "Sensors", "check_estimator", "observation"]
