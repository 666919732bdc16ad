"""Baseline controllers; ``gonzalez`` is a RECONSTRUCTION of the paper's comparison controller.

What is known: the paper (Section IV) compares its inverse-model PD with "a nonlinear PD
controller based on Gonzalez's paper [5]" and reports for it rise 6 s, settling 12 s,
overshoot 11 %. Nothing else: no law, no gains. Reference [5] could not be found; its most
likely source (S. Gonzalez-Vazquez, J. Moreno-Valenzuela, "A new nonlinear PI/PID controller
for quadrotor posture regulation", IEEE CERMA 2010) builds its laws from saturating tanh
terms. What is assumed (everything below): the form, the mapping and the gains.

Control law, per axis (e = x_r - x, e_v = x_r' - x')::

    u_x = a_p tanh(k_p e_x / a_p) + a_d tanh(k_d e_vx / a_d)        [m/s^2], same for y

Each term has slope k_p (k_d) at zero and level a_p (a_d): for small errors the law *is* the
linear PD u = k_p e + k_d e_v, so pole placement keeps its meaning, and |u| < a_p + a_d
always. (The CERMA-style k tanh(e) is the case a_p = k_p with a 1 m saturation width; the
normalisation above separates the gain from the level.) The output is mapped to setpoints by
the SMALL-ANGLE relation of eqs (5)-(6) at yaw ~ 0 and U1 ~ m g,

    theta_d = u_x / g,   phi_d = -u_y / g,

i.e. without the paper's inverse model (eqs 16, 19): at large tilt the vehicle gets
g tan(u/g) > u, and at yaw away from 0 the axes mix (the mapping is for yaw holds near 0,
like the paper's own design). Setpoints are limited to ``max_tilt`` (FLAG_TILT_LIMIT). Altitude
is the same linear PD with tilt-compensated thrust as ``nlpd``, yaw holds the mission's yaw,
and the attitude loop is the same decoupled PID (eqs 13-15).

Gain rule (not fitted to the paper's numbers, which it does not reproduce):

* k_p, k_d: the SAME poles as the paper (-0.7, -4.3: k_p = 3.01, k_d = 5.0), so that the two
  controllers are identical to first order and differ only in the nonlinearity (saturation
  plus small-angle mapping). The slower poles typical of saturated designs would mix a gain
  change into the comparison.
* a_p = k_p x 1 m, a_d = k_d x 1 m/s: the literal form of the cited tanh family,
  u = k_p tanh(e) + k_d tanh(e_v) with errors in metres and metres per second (saturation
  widths of 1 m and 1 m/s). The P term then saturates at 3.01 m/s^2 (17 deg of tilt) and
  the D term at 5.0 m/s^2.

A second rule was considered and is kept one argument away: levels from the tilt budget,
a_p = a_d = g max_tilt / 2 (3.85 m/s^2 each at 45 deg), which lets the tilt limit, not the
tanh, shape large manoeuvres. With it the baseline behaves almost exactly like ``nlpd`` on
every reproduced scenario (settling within 0.1 s); with the literal form it settles
0.2-0.8 s later. The comparison is sensitive to this unknown of the reference, and the
reproduction report says so.

Consequence for the comparison: near the reference (tracking a gentle circle) the two laws
coincide; they part only during large transients (errors of metres, where k_p e or k_d e_v
approach a_p, a_d), where the saturated law accelerates less and brakes with a bounded D.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np
from numba import njit

from quadcruise.control.attitude import ATT_GAINS, ATT_MEMORY
from quadcruise.control.base import Controller, check_positive
from quadcruise.control.design import PDGains, PIDGains, altitude_pd_design, attitude_pid_design, position_pd_design
from quadcruise.control.position import attitude_block, finish, thrust_for_tilt, tilt_setpoint
from quadcruise.errors import InputError
from quadcruise.layout import (
    CONTROLLER_SIG,
    P_G,
    P_K,
    P_M,
    PHI,
    REF_PSI,
    REF_VX,
    REF_VY,
    REF_VZ,
    REF_X,
    REF_Y,
    REF_Z,
    THETA,
    VX,
    VY,
    VZ,
    X,
    Y,
    Z,
)

# gains layout after the attitude block
KP_XY, KD_XY, SAT_P, SAT_D, KP_Z, KD_Z, MAX_TILT, COS_MAX_TILT = range(ATT_GAINS, ATT_GAINS + 8)
GONZALEZ_GAINS = ATT_GAINS + 8
G0 = 9.81
"""Gravity [m/s^2] of the tilt-budget rule a_p = a_d = G0 max_tilt / 2 (not the default)."""
UNIT_ERROR = 1.0
"""Saturation width of the P term [m]: tanh(e / 1 m), the literal form of the tanh family."""
UNIT_RATE = 1.0
"""Saturation width of the D term [m/s]."""


@njit(cache=True, inline="always", error_model="numpy")
def saturated_pd(e, ev, kp, kd, ap, ad):
    """a_p tanh(k_p e / a_p) + a_d tanh(k_d e_v / a_d): slopes k_p, k_d at 0, |.| < a_p + a_d."""
    return ap * math.tanh(kp * e / ap) + ad * math.tanh(kd * ev / ad)


@njit(CONTROLLER_SIG, cache=True, error_model="numpy")
def gonzalez(t, dt, x, ref, vp, gains, mem, cmd):
    """Reconstructed Gonzalez baseline: saturated PD, small-angle mapping, decoupled PID."""
    kp, kd, ap, ad, tilt = gains[KP_XY], gains[KD_XY], gains[SAT_P], gains[SAT_D], gains[MAX_TILT]
    ux = saturated_pd(ref[REF_X] - x[X], ref[REF_VX] - x[VX], kp, kd, ap, ad)
    uy = saturated_pd(ref[REF_Y] - x[Y], ref[REF_VY] - x[VY], kp, kd, ap, ad)
    uz = gains[KP_Z] * (ref[REF_Z] - x[Z]) + gains[KD_Z] * (ref[REF_VZ] - x[VZ])
    g = vp[P_G]
    U1, flags = thrust_for_tilt(uz, math.cos(x[PHI]) * math.cos(x[THETA]), vp[P_M], g, vp[P_K],
                                gains[COS_MAX_TILT])
    theta_d, flags = tilt_setpoint(ux / g, False, tilt, flags)           # eq (5), small angle
    phi_d, flags = tilt_setpoint(-uy / g, False, tilt, flags)            # eq (6), small angle
    finish(U1, phi_d, theta_d, ref[REF_PSI], flags, dt, x, vp, gains, mem, cmd)


@dataclass(frozen=True)
class Gonzalez(Controller):
    """Reconstruction of the paper's baseline [5]: saturated (tanh) PD on x, y mapped to
    roll/pitch by the small-angle relation, PD altitude, decoupled PID attitude (eqs 13-15).

    Parameters
    ----------
    position : PDGains
        small-signal gains k_p [1/s^2], k_d [1/s] of x and y; the paper's poles by default.
    accel_p, accel_d : float or None
        saturation levels a_p, a_d of the P and D terms [m/s^2]; None: the literal tanh form,
        a_p = k_p x 1 m and a_d = k_d x 1 m/s.
    altitude : PDGains
        z loop (linear PD, tilt-compensated thrust).
    attitude, yaw : PIDGains
        decoupled attitude loops, as for ``nlpd``.
    max_tilt : float
        roll and pitch setpoint limit [rad]; 45 degrees by default.
    i_limit : float
        anti-windup bound on the attitude integral term [rad/s^2].

    Examples
    --------
    >>> from quadcruise.control.baselines import Gonzalez
    >>> c = Gonzalez()
    >>> round(c.position.kp, 2), round(c.position.kd, 2), round(c.accel_p, 3), round(c.accel_d, 3)
    (3.01, 5.0, 3.01, 5.0)
    >>> c.gains().shape, c.memory().shape
    ((15,), (3,))
    >>> Gonzalez(accel_d=-1.0)
    Traceback (most recent call last):
        ...
    quadcruise.errors.InputError: gonzalez parameter 'accel_d' must be a positive number, got -1.0
    """

    name = "gonzalez"
    memory_size = ATT_MEMORY

    position: PDGains = field(default_factory=position_pd_design)
    accel_p: float | None = None
    accel_d: float | None = None
    altitude: PDGains = field(default_factory=altitude_pd_design)
    attitude: PIDGains = field(default_factory=attitude_pid_design)
    yaw: PIDGains = field(default_factory=attitude_pid_design)
    max_tilt: float = math.radians(45.0)
    i_limit: float = 5.0

    def __post_init__(self) -> None:
        check_positive(self.name, max_tilt=self.max_tilt, i_limit=self.i_limit)
        if self.max_tilt >= math.pi / 2:
            raise InputError(f"{self.name} parameter 'max_tilt' must be below pi/2 rad, got {self.max_tilt!r}")
        for name in ("position", "altitude"):
            if not isinstance(getattr(self, name), PDGains):
                raise InputError(f"{self.name} parameter '{name}' must be PDGains, got {getattr(self, name)!r}")
        defaults = {"accel_p": self.position.kp * UNIT_ERROR, "accel_d": self.position.kd * UNIT_RATE}
        for name, default in defaults.items():
            if getattr(self, name) is None:
                object.__setattr__(self, name, default)
            check_positive(self.name, **{name: getattr(self, name)})
        for name in ("attitude", "yaw"):
            if not isinstance(getattr(self, name), PIDGains):
                raise InputError(f"{self.name} parameter '{name}' must be PIDGains, got {getattr(self, name)!r}")

    @property
    def function(self):
        return gonzalez

    def gains(self) -> np.ndarray:
        tail = [self.position.kp, self.position.kd, self.accel_p, self.accel_d,
                self.altitude.kp, self.altitude.kd, self.max_tilt, math.cos(self.max_tilt)]
        return np.array(attitude_block(self.attitude, self.yaw, self.i_limit) + tail)
