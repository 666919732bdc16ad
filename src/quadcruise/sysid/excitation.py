"""An open-loop excitation for identification: hover with 1-2-1 doublets on every axis.

Part of the roll and pitch doublets fly while the vehicle spins about z, so that the gyroscopic
terms carry the information on ``Jzz``. Open loop, the vehicle sinks (tens of metres over the
pattern): fly it from high up. :class:`ScheduleController` flies the schedule in
``quadcruise.fly``, with the sensor noise its PX4 log is written with. docs/identify.md.

Examples
--------
>>> import quadcruise as qc
>>> from quadcruise.missions import Hover
>>> t, u = doublets(qc.Vehicle.paper())
>>> u.shape[1], round(float(u[0, 0]), 4), bool(t[-1] > 20)
(4, 0.0715, True)
>>> flight = qc.fly(Hover(z=100.0), ScheduleController(t, u), duration=2.0, max_track_error=1e6)
>>> bool(flight.ok[0])
True
"""

from __future__ import annotations

import numpy as np

from quadcruise.control.openloop import duty_schedule, pack_schedule
from quadcruise.model.vehicle import Vehicle


class ScheduleController:
    """A duty schedule ``(t, duties)``, each row held until the next time, as an open-loop controller."""

    name = "schedule"

    def __init__(self, t: np.ndarray, duties: np.ndarray) -> None:
        self.t, self.duties = np.asarray(t, float), np.asarray(duties, float)
        self.function = duty_schedule

    def gains(self) -> np.ndarray:
        """The packed schedule (:func:`quadcruise.control.openloop.pack_schedule`)."""
        return pack_schedule(self.t, self.duties)

    def memory(self) -> np.ndarray:
        """The controller's memory: the current row."""
        return np.zeros(1)


def doublets(
    vehicle: Vehicle,
    *,
    rate: float = 1.0,
    spin: float = 1.5,
    accel: float = 1.0,
    pulse: float = 0.25,
    rest: float = 0.75,
    dt: float = 1e-3,
    repeats: int = 2,
) -> tuple[np.ndarray, np.ndarray]:
    """``(t, duties)``: the duty schedule of a doublet excitation around ``vehicle``'s hover.

    ``rate`` [rad/s] and ``accel`` [m/s^2] size the roll/pitch and thrust doublets, ``spin`` [rad/s]
    the yaw rate held meanwhile; ``pulse`` [s] is the doublet's unit step, ``rest`` [s] the hover
    between doublets, ``dt`` [s] the step; the pattern is flown ``repeats`` times, spinning each
    way in turn.
    """
    u0 = float(vehicle.hover_duty)
    K, l, d = float(vehicle.K), float(vehicle.l), float(vehicle.d)
    roll = rate / pulse * float(vehicle.Jxx) / (2 * l * K)  # duty step: p' = 2 l K a / Jxx
    pitch = rate / pulse * float(vehicle.Jyy) / (2 * l * K)
    yaw_rate = rate / pulse * float(vehicle.Jzz) / (4 * d * K)  # r' = 4 d K b / Jzz
    spin_step = spin / (2 * pulse) * float(vehicle.Jzz) / (4 * d * K)
    lift = accel * float(vehicle.m) / (4 * K)
    axes = {
        "roll": np.array([0.0, 1.0, 0.0, -1.0]) * roll,
        "pitch": np.array([1.0, 0.0, -1.0, 0.0]) * pitch,
        "yaw": np.array([1.0, -1.0, 1.0, -1.0]),
        "thrust": np.ones(4) * lift,
    }
    steps: list[tuple[float, np.ndarray]] = [(1.0, np.zeros(4))]

    def doublet(delta):
        steps.extend([(pulse, delta), (2 * pulse, -delta), (pulse, delta), (rest, np.zeros(4))])

    for k in range(repeats):
        sign = 1.0 if k % 2 == 0 else -1.0
        for name in ("roll", "pitch", "thrust"):
            doublet(axes[name])
        doublet(axes["yaw"] * yaw_rate)
        steps.extend([(2 * pulse, sign * axes["yaw"] * spin_step), (rest, np.zeros(4))])  # spin up, hold
        for name in ("roll", "pitch", "roll", "pitch"):
            doublet(axes[name])
        steps.extend([(2 * pulse, -sign * axes["yaw"] * spin_step), (rest, np.zeros(4))])  # spin down
    times = np.cumsum([0.0] + [s for s, _ in steps])
    t = np.arange(0.0, times[-1], dt)
    which = np.searchsorted(times, t, side="right") - 1
    deltas = np.array([v for _, v in steps])
    return t, u0 + deltas[which]
