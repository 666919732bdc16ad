"""A controller of one's own, declared once; then it flies by name (docs/extending.md)."""

import dataclasses

from quadcruise.control import NLPD, register_controller
from quadcruise.control.design import PDGains, attitude_pid_design, pd_from_poles
from quadcruise.fields import instance_of, unit_field


@dataclasses.dataclass(frozen=True)
class Gentle(NLPD):
    """The paper's controller with slower x, y poles (-0.5, -2): less tilt, more lag."""

    name = "gentle"
    position: PDGains = unit_field(
        unit="-", doc="x and y PD loops", check=instance_of(PDGains), factory=lambda: pd_from_poles((-0.5, -2.0))
    )


register_controller(
    "gentle",
    Gentle,
    rotor_design=lambda w: {"attitude": attitude_pid_design(w), "yaw": attitude_pid_design(w)},
    baseline=True,  # scored by quadcruise.gym.evaluate.baselines()
    compared=False,  # not flown by compare() unless named
    replace=True,  # this file may be run twice in one process
)
