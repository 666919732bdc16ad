"""Sensor models for one vehicle: an IMU, a GNSS receiver, a barometer and a magnetometer.

Each is a frozen parameter class with units (:mod:`quadcruise.fields`) whose ``measure``
turns a true trajectory (ENU world, FLU body) into readings, through compiled noise
processes (:mod:`quadcruise.sensors.noise`) drawn from an explicit seed. The models, their
parameters and sources: docs/sensors.md.
"""

from quadcruise.sensors.baro import Baro
from quadcruise.sensors.gps import Gps
from quadcruise.sensors.imu import BMI088, ICM42688P, Imu
from quadcruise.sensors.mag import Magnetometer

__all__ = ["BMI088", "ICM42688P", "Baro", "Gps", "Imu", "Magnetometer"]
