"""What every controller object offers the engine: a compiled function, its parameter
vector for a vehicle, and the size of its memory.

A controller is a frozen dataclass of gains with units; :meth:`Controller.gains` packs
them into the flat vector the compiled function reads. A user's own controller only needs
a function compiled with ``layout.CONTROLLER_SIG`` and these three members.
"""

from __future__ import annotations

import dataclasses
import math
from typing import Any, ClassVar

import numpy as np
from numba import njit

from quadcruise.errors import InputError
from quadcruise.layout import (
    CMD_FLAGS,
    CMD_PHI_D,
    CMD_PSI_D,
    CMD_TAU_PHI,
    CMD_TAU_PSI,
    CMD_TAU_THETA,
    CMD_THETA_D,
    CMD_THRUST,
)
from quadcruise.model.actuators import duties


@dataclasses.dataclass(frozen=True)
class Controller:
    """Base class of the built-in controllers."""

    name: ClassVar[str] = "controller"
    memory_size: ClassVar[int] = 0

    @property
    def function(self):
        """The compiled function with ``CONTROLLER_SIG``."""
        raise NotImplementedError

    def gains(self) -> np.ndarray:
        """The flat float64 parameter vector of the compiled function."""
        raise NotImplementedError

    def memory(self) -> np.ndarray:
        """Initial memory: zeros."""
        return np.zeros(self.memory_size)

    def to_dict(self) -> dict[str, Any]:
        """Name and parameters, for result bundles."""
        out: dict[str, Any] = {"name": self.name}
        for f in dataclasses.fields(self):
            value = getattr(self, f.name)
            out[f.name] = dataclasses.asdict(value) if dataclasses.is_dataclass(value) else value
        return out


def check_positive(owner: str, **values: float) -> None:
    """InputError naming the first of ``values`` that is not a finite number > 0."""
    for name, value in values.items():
        if not (isinstance(value, (int, float)) and math.isfinite(value) and value > 0):
            raise InputError(f"{owner} parameter '{name}' must be a positive number, got {value!r}")


def check_type(owner: str, obj, names, cls) -> None:
    """InputError unless each field ``names`` of ``obj`` is a ``cls``."""
    for name in names:
        if not isinstance(getattr(obj, name), cls):
            raise InputError(f"{owner} parameter '{name}' must be {cls.__name__}, got {getattr(obj, name)!r}")


def check_tilt(owner: str, max_tilt) -> None:
    """InputError unless 0 < ``max_tilt`` < pi/2 [rad]."""
    check_positive(owner, max_tilt=max_tilt)
    if max_tilt >= math.pi / 2:
        raise InputError(f"{owner} parameter 'max_tilt' must be below pi/2 rad, got {max_tilt!r}")


@njit(cache=True, inline="always", error_model="numpy")
def write_command(cmd, U1, U2, U3, U4, phi_d, theta_d, psi_d, flags, d, K):
    """Fill a controller's output ``cmd``: the duties for (U1..U4) (yaw arm d [m], PWM gain
    K [N]; see :func:`quadcruise.model.actuators.duties`), the desired inputs, the attitude
    setpoints and the flag word. Straight-line code on scalars, so a controller that reads
    its arrays first and calls this last makes no reference-count calls."""
    u1, u2, u3, u4 = duties(U1, U2, U3, U4, d, K)
    cmd[0], cmd[1], cmd[2], cmd[3] = u1, u2, u3, u4
    cmd[CMD_THRUST], cmd[CMD_TAU_PHI], cmd[CMD_TAU_THETA], cmd[CMD_TAU_PSI] = U1, U2, U3, U4
    cmd[CMD_PHI_D], cmd[CMD_THETA_D], cmd[CMD_PSI_D] = phi_d, theta_d, psi_d
    cmd[CMD_FLAGS] = flags
