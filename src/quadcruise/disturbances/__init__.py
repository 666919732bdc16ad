"""Disturbances and sensors, by role: wind (constant, gust), Dryden turbulence, faults (rotor
loss, external force and torque), sensor noise; the composite :class:`Environment` that flies
them; batched and seeded. The ``--wind`` text spec is parsed by :mod:`quadcruise.cli.wind`."""

from quadcruise.disturbances.custom import CustomDisturbance
from quadcruise.disturbances.environment import Environment, environment_disturbance
from quadcruise.disturbances.faults import ExternalForce, RotorLoss
from quadcruise.disturbances.sensors import SensorNoise
from quadcruise.disturbances.turbulence import AIRSPEED_FLOOR, INTENSITIES, Turbulence
from quadcruise.disturbances.wind import DEFAULT_DRAG, ConstantWind, Gust, default_drag_text, with_drag

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
    "default_drag_text",
    "environment_disturbance",
    "with_drag",
]
