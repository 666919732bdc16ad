"""State estimation for one vehicle: an error-state EKF on position, velocity, attitude and the
IMU's biases, driven by the IMU and corrected by GPS, barometer and magnetometer
(docs/sensors.md), in the engine's period too (``stage.py``, ``onboard.py``); its consistency
checks (NEES, NIS) and a closed-form flight to check it on.
"""

from quadcruise.estimation.consistency import average_bounds, errors, nees
from quadcruise.estimation.run import EkfNoise, EkfRun, run_ekf
from quadcruise.estimation.stage import Ekf, Sensors, observation
from quadcruise.estimation.truth import tilted_circle

__all__ = [
    "Ekf",
    "EkfNoise",
    "EkfRun",
    "Sensors",
    "average_bounds",
    "errors",
    "nees",
    "observation",
    "run_ekf",
    "tilted_circle",
]
