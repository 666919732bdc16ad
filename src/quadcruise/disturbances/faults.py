"""Faults the vehicle meets: the loss of part of one rotor's thrust, and a constant external
force and torque.

- Rotor loss: e_rotor = 1 - fraction from the first period that starts at t >= time.
- External force: earth frame; torque: body frame.

The compiled part is in :mod:`quadcruise.disturbances.environment`.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any

from quadcruise.disturbances.part import Part
from quadcruise.disturbances.part import batch_field as _f
from quadcruise.fields import between


@dataclass(frozen=True)
class RotorLoss(Part):
    """From ``time`` on, rotor ``rotor`` gives 1 - ``fraction`` of its thrust.

    Parameters
    ----------
    rotor : int or array of int
        The rotor that loses thrust, 1 to 4.
    fraction : float or array
        Fraction of its thrust lost [-], in [0, 1].
    time : float or array
        Time of the loss [s], >= 0: it acts from the first control period that starts at
        or after it.
    """

    rotor: Any = _f(1, "-", "rotor number", between(1, 4, whole=True))
    fraction: Any = _f(0.3, "-", "fraction of thrust lost", "frac")
    time: Any = _f(5.0, "s", "time of the loss", "nonneg")
    name = "loss"


@dataclass(frozen=True)
class ExternalForce(Part):
    """A constant force (earth frame) and torque (body frame).

    Parameters
    ----------
    force : sequence of 3 (float or array), or (N, 3) array
        Force (x, y, z), earth frame, z up [N].
    torque : sequence of 3 (float or array), or (N, 3) array
        Torque about the body axes (x, y, z) [N m].
    """

    force: Any = _f((0.0, 0.0, 0.0), "N", "force (x, y, z)", "vec")
    torque: Any = _f((0.0, 0.0, 0.0), "N m", "torque (x, y, z)", "vec")
    name = "force"
