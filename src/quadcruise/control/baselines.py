"""Baseline controllers; ``gonzalez`` is a RECONSTRUCTION of the paper's comparison controller.

What is known: the paper (Section IV) compares its inverse-model PD with "a nonlinear PD
controller based on Gonzalez's paper [5]" and reports for it rise 6 s, settling 12 s,
overshoot 11 %. Nothing else: no law, no gains. Reference [5] could not be found; its most
likely source (S. Gonzalez-Vazquez, J. Moreno-Valenzuela, "A new nonlinear PI/PID controller
for quadrotor posture regulation", IEEE CERMA 2010) builds its laws from saturating tanh
terms. What is assumed (everything below): the form, the mapping and the gains.

Control law, per axis of the yaw frame (e = x_r - x, e_v = x_r' - x', rotated by the yaw psi
into forward f = (cos psi, sin psi) and left l = (-sin psi, cos psi))::

    u_f = a_p tanh(k_p e_f / a_p) + a_d tanh(k_d e_vf / a_d)        [m/s^2], same for l

Each term has slope k_p (k_d) at zero and level a_p (a_d): for small errors the law *is* the
linear PD u = k_p e + k_d e_v, so pole placement keeps its meaning, and |u| < a_p + a_d
always. (The CERMA-style k tanh(e) is the case a_p = k_p with a 1 m saturation width; the
normalisation above separates the gain from the level.) The output is mapped to setpoints by
the SMALL-ANGLE relation of eqs (5)-(6) in the yaw frame at U1 ~ m g,

    theta_d = u_f / g,   phi_d = -u_l / g,

i.e. without the paper's inverse model (eqs 16, 19): at large tilt the vehicle gets
g tan(u/g) > u. Working in the yaw frame makes the law the same at any held yaw (at yaw 0,
f = x and l = y: theta_d = u_x / g, phi_d = -u_y / g); mapped in the earth frame instead, the
axes would mix at yaw away from 0 (146 % overshoot on a 1 m step at 45 degrees). Setpoints are limited to
``max_tilt`` (FLAG_TILT_LIMIT). Altitude
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
from dataclasses import dataclass

import numpy as np
from numba import njit

from quadcruise import layout as L
from quadcruise.control.attitude import ATTITUDE_GAINS, ATTITUDE_MEMORY, attitude_fields
from quadcruise.control.base import TILT, Controller
from quadcruise.control.design import PDGains, PIDGains, altitude_pd_design, attitude_pid_design, position_pd_design
from quadcruise.control.inversion import thrust_for_tilt, tilt_setpoint
from quadcruise.control.position import finish
from quadcruise.fields import instance_of
from quadcruise.fields import unit_field as _f

GONZALEZ_GAINS = L.Row.of(
    "gonzalez gains",
    "kp_xy",
    "kd_xy",
    "sat_p",
    "sat_d",
    "kp_z",
    "kd_z",
    "max_tilt",
    "cos_max_tilt",
    parent=ATTITUDE_GAINS,
    prefix="GZ_",
)
"""The gains of :func:`gonzalez`: the attitude block, then k_p [1/s^2], k_d [1/s] of x and y,
the saturation levels a_p, a_d [m/s^2], the z PD gains [1/s^2], [1/s], max_tilt [rad] and its
cosine."""
GZ_KP_XY, GZ_KD_XY, GZ_SAT_P, GZ_SAT_D, GZ_KP_Z, GZ_KD_Z, GZ_MAX_TILT, GZ_COS_MAX_TILT = GONZALEZ_GAINS.offsets
G0 = 9.81
"""Gravity [m/s^2] of the tilt-budget rule a_p = a_d = G0 max_tilt / 2 (not the default)."""
UNIT_ERROR = 1.0
"""Saturation width of the P term [m]: tanh(e / 1 m), the literal form of the tanh family."""
UNIT_RATE = 1.0
"""Saturation width of the D term [m/s]."""


@njit(cache=True, inline="always", error_model="numpy")
def saturated_pd(e, ev, kp, kd, ap, ad):
    """a_p tanh(k_p e / a_p) + a_d tanh(k_d e_v / a_d): slopes k_p, k_d at 0, |.| < a_p + a_d.

    Examples
    --------
    >>> round(saturated_pd(0.01, 0.0, 3.01, 5.0, 3.01, 5.0), 6)   # small error: about k_p e
    0.030099
    >>> round(saturated_pd(100.0, 100.0, 3.01, 5.0, 3.01, 5.0), 6)  # large: a_p + a_d
    8.01
    """
    return ap * math.tanh(kp * e / ap) + ad * math.tanh(kd * ev / ad)


@njit(L.CONTROLLER_SIG, cache=True, error_model="numpy")
def gonzalez(t, dt, x, ref, vp, gains, mem, cmd):
    """One period of :class:`Gonzalez`: saturated PD, small-angle mapping, decoupled PID.
    Arguments: ``CONTROLLER_SIG`` (:mod:`quadcruise.layout`); gains at the offsets of :data:`GONZALEZ_GAINS`.

    Examples
    --------
    >>> import numpy as np
    >>> import quadcruise as qc
    >>> from quadcruise.layout import CMD_THETA_D, REF_X
    >>> c, vp = Gonzalez(), qc.Vehicle.paper().rows()[0]
    >>> ref, cmd = np.zeros(11), np.zeros(12)
    >>> ref[REF_X] = 0.1                                    # 10 cm ahead in x: pitch forward
    >>> gonzalez(0.0, 0.001, np.zeros(16), ref, vp, c.gains(), c.memory(), cmd)
    >>> round(float(cmd[CMD_THETA_D]), 4)                  # a_p tanh(k_p e / a_p) / g, no asin
    0.0306
    """
    kp, kd, ap, ad, tilt = gains[GZ_KP_XY], gains[GZ_KD_XY], gains[GZ_SAT_P], gains[GZ_SAT_D], gains[GZ_MAX_TILT]
    spsi, cpsi = math.sin(x[L.PSI]), math.cos(x[L.PSI])
    ex, ey, evx, evy = ref[L.REF_X] - x[L.X], ref[L.REF_Y] - x[L.Y], ref[L.REF_VX] - x[L.VX], ref[L.REF_VY] - x[L.VY]
    uf = saturated_pd(cpsi * ex + spsi * ey, cpsi * evx + spsi * evy, kp, kd, ap, ad)  # forward
    ul = saturated_pd(cpsi * ey - spsi * ex, cpsi * evy - spsi * evx, kp, kd, ap, ad)  # left
    uz = gains[GZ_KP_Z] * (ref[L.REF_Z] - x[L.Z]) + gains[GZ_KD_Z] * (ref[L.REF_VZ] - x[L.VZ])
    g = vp[L.P_G]
    U1, flags = thrust_for_tilt(
        uz, math.cos(x[L.PHI]) * math.cos(x[L.THETA]), vp[L.P_M], g, vp[L.P_K], gains[GZ_COS_MAX_TILT]
    )
    theta_d, flags = tilt_setpoint(uf / g, False, tilt, flags)  # eq (5), small angle, yaw frame
    phi_d, flags = tilt_setpoint(-ul / g, False, tilt, flags)  # eq (6), small angle, yaw frame
    finish(U1, phi_d, theta_d, ref[L.REF_PSI], flags, dt, x, vp, gains, mem, cmd)


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
    quadcruise.errors.InputError: gonzalez parameter 'accel_d' (saturation level of the D term (None: k_d x 1 ...
    """

    name = "gonzalez"
    memory_size = ATTITUDE_MEMORY.size

    position: PDGains = _f(
        unit="-", doc="small-signal PD of x and y", check=instance_of(PDGains), factory=position_pd_design
    )
    accel_p: float | None = _f(None, "m/s^2", "saturation level of the P term (None: k_p x 1 m)", "pos")
    accel_d: float | None = _f(None, "m/s^2", "saturation level of the D term (None: k_d x 1 m/s)", "pos")
    altitude: PDGains = _f(unit="-", doc="z PD loop", check=instance_of(PDGains), factory=altitude_pd_design)
    attitude: PIDGains = _f(
        unit="-", doc="roll and pitch PID loops", check=instance_of(PIDGains), factory=attitude_pid_design
    )
    yaw: PIDGains = _f(unit="-", doc="yaw PID loop", check=instance_of(PIDGains), factory=attitude_pid_design)
    max_tilt: float = _f(math.radians(45.0), "rad", "roll and pitch setpoint limit", TILT)
    i_limit: float = _f(5.0, "rad/s^2", "anti-windup bound on the attitude integral term", "pos")

    def __post_init__(self) -> None:
        super().__post_init__()
        defaults = {"accel_p": self.position.kp * UNIT_ERROR, "accel_d": self.position.kd * UNIT_RATE}
        for name, default in defaults.items():
            if getattr(self, name) is None:
                object.__setattr__(self, name, default)

    @property
    def function(self):
        """The compiled law, :func:`gonzalez` (``CONTROLLER_SIG``)."""
        return gonzalez

    def gains(self) -> np.ndarray:
        """The parameter vector :func:`gonzalez` reads.

        Returns
        -------
        numpy.ndarray
            :data:`GONZALEZ_GAINS`, 15 float64 entries: the attitude block
            (:data:`~quadcruise.control.attitude.ATTITUDE_GAINS`: roll/pitch and yaw kp
            [1/s^2], ki [1/s^3], kd [1/s], i_limit [rad/s^2]), then k_p [1/s^2] and k_d
            [1/s] of x and y, a_p and a_d [m/s^2], Kp [1/s^2] and Kd [1/s] of z, max_tilt
            [rad] and cos(max_tilt).
        """
        return GONZALEZ_GAINS.pack(
            {
                **attitude_fields(self.attitude, self.yaw, self.i_limit),
                "kp_xy": self.position.kp,
                "kd_xy": self.position.kd,
                "sat_p": self.accel_p,
                "sat_d": self.accel_d,
                "kp_z": self.altitude.kp,
                "kd_z": self.altitude.kd,
                "max_tilt": self.max_tilt,
                "cos_max_tilt": math.cos(self.max_tilt),
            }
        )
