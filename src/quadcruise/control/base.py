"""What every controller object offers the engine: a name, a compiled function, its
parameter vector, and its initial memory.

A controller is a frozen dataclass of gains with units (its fields come from
:func:`quadcruise.fields.unit_field` and are checked by :func:`quadcruise.fields.validate`);
:meth:`Controller.gains` packs them into the flat vector the compiled function reads. A
user's own controller needs no base class: ``name``, a ``function`` compiled with
``layout.CONTROLLER_SIG``, ``gains()`` and ``memory()``
(:class:`quadcruise.protocols.ControllerLike`).
"""

from __future__ import annotations

import dataclasses
import math
from typing import Any, ClassVar

import numpy as np
from numba import njit

from quadcruise import layout as L
from quadcruise.fields import Validated, between
from quadcruise.model.actuators import duties

TILT = between(0.0, math.pi / 2, "()", text="(0, pi/2)")
"""The check of a tilt limit [rad]: above 0 and below pi/2."""


@dataclasses.dataclass(frozen=True)
class Controller(Validated):
    """Base class of the built-in controllers: validation and ``units()`` of the fields
    (:class:`quadcruise.fields.Validated`; messages call them parameters), ``memory``,
    ``to_dict``.

    Examples
    --------
    >>> from quadcruise.control.se3 import SE3
    >>> SE3.units()["attitude.kp"], SE3.units()["max_tilt"]
    ('1/s^2', 'rad')
    """

    name: ClassVar[str] = "controller"
    field_noun: ClassVar[str] = "parameter"
    memory_size: ClassVar[int] = 0

    @property
    def function(self):
        """The compiled function with ``CONTROLLER_SIG``."""
        raise NotImplementedError

    def gains(self) -> np.ndarray:
        """The flat parameter vector of the compiled function.

        Returns
        -------
        numpy.ndarray
            1-D float64, laid out as the subclass's compiled function reads it (gains in
            their SI units).
        """
        raise NotImplementedError

    def memory(self) -> np.ndarray:
        """The controller's memory at the start of a flight (integrals, previous samples).

        Returns
        -------
        numpy.ndarray
            Zeros, ``memory_size`` float64 entries.
        """
        return np.zeros(self.memory_size)

    def to_dict(self) -> dict[str, Any]:
        """Name and parameters, for result bundles.

        Returns
        -------
        dict
            ``{'name': name, field: value, ...}``, a gain set as a dict of its gains.
        """
        out: dict[str, Any] = {"name": self.name}
        for f in dataclasses.fields(self):
            value = getattr(self, f.name)
            out[f.name] = dataclasses.asdict(value) if dataclasses.is_dataclass(value) else value
        return out


@njit(cache=True, inline="always", error_model="numpy")
def write_command(cmd, U1, U2, U3, U4, phi_d, theta_d, psi_d, flags, d, K):
    """Fill a controller's output ``cmd`` (``CMD_*``): the duties for U1..U4 (not clipped), the
    inputs, the attitude setpoints and the flags; call it last, after every read.

    Examples
    --------
    >>> import numpy as np
    >>> cmd = np.zeros(12)
    >>> write_command(cmd, 10.0, -2.0, -2.0, -1.0, 0.1, 0.2, 0.3, 4, 0.5, 4.0)
    >>> cmd.tolist()
    [0.25, 0.5, 0.75, 1.0, 10.0, -2.0, -2.0, -1.0, 0.1, 0.2, 0.3, 4.0]
    """
    u1, u2, u3, u4 = duties(U1, U2, U3, U4, d, K)
    cmd[0], cmd[1], cmd[2], cmd[3] = u1, u2, u3, u4
    cmd[L.CMD_THRUST], cmd[L.CMD_TAU_PHI], cmd[L.CMD_TAU_THETA], cmd[L.CMD_TAU_PSI] = U1, U2, U3, U4
    cmd[L.CMD_PHI_D], cmd[L.CMD_THETA_D], cmd[L.CMD_PSI_D] = phi_d, theta_d, psi_d
    cmd[L.CMD_FLAGS] = flags
