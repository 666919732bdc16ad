"""Disturbances: wind (constant, gust, Dryden turbulence), rotor loss, external force and torque,
sensor noise; batched and seeded."""

from quadcruise.disturbances.custom import CustomDisturbance
from quadcruise.disturbances.environment import (
    AIRSPEED_FLOOR,
    DEFAULT_DRAG,
    INTENSITIES,
    ConstantWind,
    Environment,
    ExternalForce,
    Gust,
    RotorLoss,
    SensorNoise,
    Turbulence,
    environment_disturbance,
    parse_wind,
    wind_from_name,
    with_drag,
)

__all__ = [
    "AIRSPEED_FLOOR",
    "DEFAULT_DRAG",
    "INTENSITIES",
    "ConstantWind",
    "CustomDisturbance",
    "Environment",
    "ExternalForce",
    "Gust",
    "RotorLoss",
    "SensorNoise",
    "Turbulence",
    "environment_disturbance",
    "parse_wind",
    "wind_from_name",
    "with_drag",
]
