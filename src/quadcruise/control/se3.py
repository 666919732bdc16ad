"""State-of-the-art controllers on the paper's plant: geometric control on SE(3) and a
PX4-style cascade, both flying the same model, missions and engine as ``nlpd``.

``se3`` (:class:`SE3`): Lee, Leok and McClamroch, "Geometric tracking control of a quadrotor
UAV on SE(3)", CDC 2010, in the form RotorPy and crazyflow fly it. With e = ref - actual::

    F = m (kx e_x + kv e_v + a_ref + g e3)           desired force, earth frame [N]
    b3_d = F / |F|,  b1_d from the yaw reference,    R_d = [b1_d, b2_d, b3_d]
    U1 = F . R e3                                    thrust along the current b3 [N]
    e_R = vee(R_d^T R - R^T R_d) / 2,  e_w = w - w_d,  w_d = (0, 0, psi_dot_d)
    M = J (-kR e_R - kw e_w) + w x J w               moments, body frame [N m]
    U2 = M_x / l,  U3 = M_y / l,  U4 = M_z

R = Rz(psi) Ry(theta) Rx(phi) from the state's angles (so R e3 is eqs 5-7's thrust
direction), w = (p, q, r) the state's body rates. The desired body rate w_d is the
reference's yaw rate psi_dot_d about b3, exactly as RotorPy's ``SE3Control`` writes it
(``w_des = [0, 0, yaw_dot]``): waypoint and minimum-snap paths turn the yaw, and without w_d
the kw term would hold the vehicle back by kw / kR psi_dot_d (2.6 deg at 0.26 rad/s). Lee's
full term R^T R_d w_d, with the roll and pitch rates of a tilting R_d, needs the reference's
jerk, which missions do not carry; it differs from (0, 0, psi_dot_d) by terms of the order of
the tilt times psi_dot_d. kR and kw multiply the inertia (RotorPy's form), i.e. they are per
unit inertia; the w x J w term cancels the gyroscopic terms of eq (11) exactly, so
J w' = J (-kR e_R - kw e_w).
Added to Lee's law: the horizontal part of F is scaled down to keep b3_d within ``max_tilt``
(FLAG_TILT_LIMIT) and U1 is limited to [0, 4 K] (FLAG_THRUST_LIMIT); neither acts in the
default missions.

Gain rule, for a fair comparison with ``nlpd``: kx, kv place the paper's position poles
(-0.7, -4.3: kx = 3.01 1/s^2, kv = 5.0 1/s), and so do the altitude gains; kR, kw put each
attitude axis (a double integrator per unit inertia behind the 15 rad/s rotor lag) at the
attitude design's pair wn = 0.6 w = 9 rad/s, zeta = 0.8: kR = 81 1/s^2, kw = 14.4 1/s
(:func:`se3_attitude_design`; ``nlpd``'s attitude PID without its slow integrator). With
the rotor lag each attitude axis keeps a 26 deg phase margin at a 12.3 rad/s crossover.

``cascade`` (:class:`Cascade`): PX4's multicopter cascade, P position -> PID velocity -> P
attitude -> PID body rate; the law is in :mod:`quadcruise.control.cascade`. Its gains are
PX4's defaults where they are in SI units; the rate gains, which PX4 gives in normalized
torque, are designed for this vehicle's rotor lag (:func:`rate_pid_design`).

Examples
--------
>>> import quadcruise as qc
>>> from quadcruise.control.cascade import Cascade
>>> res = qc.fly("step", Cascade(), duration=12.0)
>>> bool(abs(res.final_state[0, 0] - 1.0) < 0.02)
True
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
from numba import njit

from quadcruise import layout as L
from quadcruise.control.base import TILT, Controller
from quadcruise.control.design import ATTITUDE_WN_RATIO, ATTITUDE_ZETA, PDGains, altitude_pd_design, position_pd_design
from quadcruise.control.so3 import attitude_lee, command_from_rotation, error_lee, limit_tilt, rotation_zyx
from quadcruise.fields import check_value, instance_of
from quadcruise.fields import unit_field as _f
from quadcruise.numeric import clamp

__all__ = ["SE3", "se3", "se3_attitude_design"]

SE3_GAINS = L.Row.of("se3 gains", "kx", "kv", "kx_z", "kv_z", "k_r", "k_w", "max_tilt", prefix="SE3_")
"""The gains of :func:`se3`: kx [1/s^2], kv [1/s] of x and y, the same of z, kR [1/s^2], kw
[1/s], max_tilt [rad]."""
SE3_KX, SE3_KV, SE3_KX_Z, SE3_KV_Z, SE3_K_R, SE3_K_W, SE3_MAX_TILT = SE3_GAINS.offsets


@njit(L.CONTROLLER_SIG, cache=True, error_model="numpy")
def se3(t, dt, x, ref, vp, gains, mem, cmd):
    """One period of :class:`SE3`: geometric tracking on SE(3) (Lee et al. 2010), moments per unit inertia.
    Arguments: ``CONTROLLER_SIG`` (:mod:`quadcruise.layout`); the law is in the module docstring.

    Examples
    --------
    >>> import numpy as np
    >>> import quadcruise as qc
    >>> from quadcruise.layout import CMD_THRUST, P_G, P_M
    >>> vp = qc.Vehicle.paper().rows()[0]
    >>> x, ref, cmd = np.zeros(16), np.zeros(11), np.zeros(12)
    >>> se3(0.0, 0.001, x, ref, vp, SE3().gains(), np.zeros(0), cmd)   # level, on the reference
    >>> bool(np.isclose(cmd[CMD_THRUST], vp[P_M] * vp[P_G])), bool(np.all(cmd[5:8] == 0.0))  # m g, no moments
    (True, True)
    """
    # every array entry read first, the command written last (fastmath's scalar-only rule)
    phi, theta, psi, p, q, r = x[L.PHI], x[L.THETA], x[L.PSI], x[L.P], x[L.Q], x[L.R]
    m, g, K, l, d = vp[L.P_M], vp[L.P_G], vp[L.P_K], vp[L.P_L], vp[L.P_D]
    jx, jy, jz = vp[L.P_JXX], vp[L.P_JYY], vp[L.P_JZZ]
    kx, kv, kx_z, kv_z = gains[SE3_KX], gains[SE3_KV], gains[SE3_KX_Z], gains[SE3_KV_Z]
    kr, kw, max_tilt = gains[SE3_K_R], gains[SE3_K_W], gains[SE3_MAX_TILT]
    psi_d, yaw_rate_d = ref[L.REF_PSI], ref[L.REF_PSI_DOT]
    fx = m * (kx * (ref[L.REF_X] - x[L.X]) + kv * (ref[L.REF_VX] - x[L.VX]) + ref[L.REF_AX])
    fy = m * (kx * (ref[L.REF_Y] - x[L.Y]) + kv * (ref[L.REF_VY] - x[L.VY]) + ref[L.REF_AY])
    fz = m * (kx_z * (ref[L.REF_Z] - x[L.Z]) + kv_z * (ref[L.REF_VZ] - x[L.VZ]) + ref[L.REF_AZ] + g)
    fx, fy, tilted = limit_tilt(fx, fy, fz, max_tilt)
    flags = L.FLAG_TILT_LIMIT if tilted else 0
    Rm = rotation_zyx(phi, theta, psi)
    n = math.sqrt(fx * fx + fy * fy + fz * fz) if fz > 0.0 else 0.0
    if n > 0.0:
        Rd = attitude_lee(fx / n, fy / n, fz / n, psi_d)
    else:  # F points down: b3_d = e3, U1 -> 0
        Rd = attitude_lee(0.0, 0.0, 1.0, psi_d)
    U1, limited = clamp(fx * Rm[0][2] + fy * Rm[1][2] + fz * Rm[2][2], 0.0, 4.0 * K)
    if limited:
        flags |= L.FLAG_THRUST_LIMIT
    ex, ey, ez = error_lee(Rm, Rd)
    mx = -jx * (kr * ex + kw * p) + (jz - jy) * q * r  # + (w x J w)_x
    my = -jy * (kr * ey + kw * q) + (jx - jz) * p * r
    mz = -jz * (kr * ez + kw * (r - yaw_rate_d)) + (jy - jx) * p * q
    command_from_rotation(U1, mx / l, my / l, mz, Rd, flags, d, K, cmd)


def se3_attitude_design(actuator_bandwidth: float = 15.0) -> PDGains:
    """kR = wn^2 [1/s^2], kw = 2 zeta wn [1/s] per unit inertia at the attitude design's
    wn = 0.6 w, zeta = 0.8 (see :func:`quadcruise.control.design.attitude_pid_design`).

    Examples
    --------
    >>> from quadcruise.control.design import loop_margins
    >>> g = se3_attitude_design()
    >>> round(g.kp, 6), round(g.kd, 6), round(loop_margins(g, 15.0)["phase_margin"], 1)
    (81.0, 14.4, 26.1)
    """
    actuator_bandwidth = check_value(
        "se3_attitude_design argument 'actuator_bandwidth' (rotor lag bandwidth, rad/s)", actuator_bandwidth, "pos"
    )
    wn = ATTITUDE_WN_RATIO * actuator_bandwidth
    return PDGains(kp=wn * wn, kd=2.0 * ATTITUDE_ZETA * wn)


@dataclass(frozen=True)
class SE3(Controller):
    """Geometric tracking control on SE(3) (Lee, Leok, McClamroch 2010).

    Parameters
    ----------
    position : PDGains
        kx (kp) [1/s^2] and kv (kd) [1/s] of x and y, per unit mass; the paper's poles.
    altitude : PDGains
        the same for z; the paper's poles.
    attitude : PDGains
        kR (kp) [1/s^2] and kw (kd) [1/s] per unit inertia, all three axes; 81 and 14.4.
    max_tilt : float
        largest angle of b3_d from the vertical [rad]; 45 degrees.

    Examples
    --------
    >>> c = SE3()
    >>> c.gains().round(3).tolist()
    [3.01, 5.0, 3.01, 5.0, 81.0, 14.4, 0.785]
    >>> SE3(max_tilt=-1.0)
    Traceback (most recent call last):
        ...
    quadcruise.errors.InputError: se3 parameter 'max_tilt' (largest tilt of b3_d from the vertical, rad) must ...
    """

    name = "se3"
    memory_size = 0

    position: PDGains = _f(
        unit="-",
        doc="kx (kp) and kv (kd) of x and y, per unit mass",
        check=instance_of(PDGains),
        factory=position_pd_design,
    )
    altitude: PDGains = _f(
        unit="-", doc="kx and kv of z, per unit mass", check=instance_of(PDGains), factory=altitude_pd_design
    )
    attitude: PDGains = _f(
        unit="-", doc="kR (kp) and kw (kd) per unit inertia", check=instance_of(PDGains), factory=se3_attitude_design
    )
    max_tilt: float = _f(math.radians(45.0), "rad", "largest tilt of b3_d from the vertical", TILT)

    @property
    def function(self):
        """The compiled law, :func:`se3` (``CONTROLLER_SIG``)."""
        return se3

    def gains(self) -> np.ndarray:
        """The parameter vector :func:`se3` reads.

        Returns
        -------
        numpy.ndarray
            7 float64 entries: kx [1/s^2] and kv [1/s] of x and y (``position``), the same
            of z (``altitude``), kR [1/s^2] and kw [1/s] (``attitude``), max_tilt [rad].
        """
        return SE3_GAINS.pack(
            {
                "kx": self.position.kp,
                "kv": self.position.kd,
                "kx_z": self.altitude.kp,
                "kv_z": self.altitude.kd,
                "k_r": self.attitude.kp,
                "k_w": self.attitude.kd,
                "max_tilt": self.max_tilt,
            }
        )
