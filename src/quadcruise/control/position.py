"""The paper's position controller: the inverse-model nonlinear PD (eqs 16 and 19), with a
tilt-compensated altitude law and a yaw hold, over the decoupled attitude PID.

Per control period, with a = U1 / m:

1. PD on each axis (eq 16, with the error sign fixed to e = x_r - x; the paper prints
   x - x_r, which is positive feedback)::

       u_x = Kp (x_r - x) + Kd (x_r' - x')   [+ x_r'' if acceleration feedforward is on]

   That is the default, ``derivative="measurement"``: the derivative acts on the measured
   velocity, with the reference's velocity. ``derivative="error"`` is eq (17) as printed,
   the derivative of the whole error e = x_r - x through a first-order filter N (Simulink's
   PID block, N = 100 1/s by default) whose state starts at rest::

       u_x = Kp e + Kd N s / (s + N) e

   A jump of the error by E (a step of the reference) then kicks u_x by Kd N E at once,
   decaying as exp(-N t); beyond a few centimetres the asin clip and the tilt limit cut the
   kick down to the largest tilt, held for a few hundredths of a second.

2. Altitude (not in the paper): u_z the same PD on z, and the tilt-compensated thrust
   U1 = m (g + u_z) / (cos phi cos theta), limited to [0, 4 K].
3. Roll and pitch setpoints: eqs (5) and (6) solved *together* (the default,
   ``inversion="joint"``). Rotated into the yaw frame they read
   x'' sin psi - y'' cos psi = a sin phi and x'' cos psi + y'' sin psi = a cos phi sin theta, so::

       sin phi_d = (u_x sin psi - u_y cos psi) / a
       sin theta_d = (u_x cos psi + u_y sin psi) / (a cos phi_d)

   with phi_d limited to ``max_tilt`` before theta_d is computed. The pair satisfies eqs (5)
   and (6) at once, at any yaw. At psi = 0 it is the paper's law with its sign fixed
   (phi_d = -asin(u_y / a)), except that eq (16) divides by the cosine of the *new* roll
   rather than the current one.

   ``inversion="sequential"`` is the paper's literal reading, kept as an option:

3'. Pitch setpoint from eq (5) solved for theta with the current phi, psi (eq 16)::

       sin theta_d = (u_x - sin phi sin psi a) / (cos phi cos psi a)

4'. Roll setpoint from eq (6) solved *exactly* for phi given theta_d and psi. The paper's
   eq (19) squares the equation and takes a square root, which loses the sign of phi;
   with A = cos psi, B = sin theta_d sin psi, eq (6) reads A sin phi - B cos phi = -u_y/a,
   i.e. sin(phi - gamma) = -u_y / (a R), R = hypot(A, B), gamma = atan2(B, A); of the two
   roots we take the one nearest level, which for cos psi > 0 is gamma - asin(u_y / (a R))
   with gamma = atan(B / A). At psi = 0 this is phi_d = -asin(u_y / a): the paper's form
   with its sign restored. sin theta_d is the asin argument of step 3 (or sin max_tilt when
   the pitch was limited), not a new sine.
5. Yaw setpoint: the mission's yaw (a hold at 0 by default).

Every asin argument outside [-1, 1] is clipped and flagged (FLAG_ASIN_CLIP), and roll and
pitch setpoints are limited to ``max_tilt`` (FLAG_TILT_LIMIT).

The sequential inversion loses its damping at a held yaw beyond about 39 degrees: linearised
about hover, solving eq (16) with the *current* roll and then eq (19) feeds the roll back
into the roll setpoint with gain -tan^2(psi) through the attitude loop and the rotor lag
(tests/integration/test_inversion_at_any_yaw.py measures the limit). The joint inversion has
no such loop: it is the default.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
from numba import njit

from quadcruise import layout as L
from quadcruise.control.attitude import ATTITUDE_GAINS, ATTITUDE_MEMORY, attitude_fields, decoupled_attitude
from quadcruise.control.base import TILT, Controller, write_command
from quadcruise.control.design import PDGains, PIDGains, altitude_pd_design, attitude_pid_design, position_pd_design
from quadcruise.control.inversion import pitch_eq16, roll_eq19, thrust_for_tilt, tilt_joint, tilt_setpoint
from quadcruise.fields import instance_of
from quadcruise.fields import unit_field as _f

NLPD_GAINS = L.Row.of(
    "nlpd gains",
    "kp_xy",
    "kd_xy",
    "kp_z",
    "kd_z",
    "max_tilt",
    "accel_ff",
    "cos_max_tilt",
    "sin_max_tilt",
    "inversion",
    "derivative",
    "filter_n",
    parent=ATTITUDE_GAINS,
    prefix="NL_",
)
"""The gains of :func:`nlpd`: the attitude block, then the x/y and z PD gains, max_tilt, the
feedforward switch, cos and sin of max_tilt (so that the step calls neither: a kept trick, see
quadcruise.sim.fastmath), the inversion (0 joint, 1 the paper's sequential eqs 16 then 19), the
derivative form (0 on the measurement with the reference's velocity, 1 on the whole error
through the filter N [1/s] of ``filter_n``)."""
(
    NL_KP_XY,
    NL_KD_XY,
    NL_KP_Z,
    NL_KD_Z,
    NL_MAX_TILT,
    NL_ACCEL_FF,
    NL_COS_MAX_TILT,
    NL_SIN_MAX_TILT,
    NL_INVERSION,
    NL_DERIVATIVE,
    NL_FILTER_N,
) = NLPD_GAINS.offsets
INVERSIONS = ("joint", "sequential")
DERIVATIVES = ("measurement", "error")
NLPD_MEMORY = L.Row.of("nlpd memory", "filter_x", "filter_y", parent=ATTITUDE_MEMORY, prefix="NL_")
NL_FILTER_X, NL_FILTER_Y = NLPD_MEMORY.offsets
"""The memory of :func:`nlpd`: the attitude loop's, then the derivative filter's states (the
filtered x and y errors [m]), there only with ``derivative="error"``."""


@njit(cache=True, inline="always", error_model="numpy")
def finish(U1, phi_d, theta_d, psi_d, flags, dt, x, vp, gains, mem, cmd):
    """Shared tail of the position controllers: the decoupled attitude PID (eqs 13-15), the
    mixer inverse to duties, and the logged command."""
    U2, U3, U4, att_flags = decoupled_attitude(x, phi_d, theta_d, psi_d, vp, gains, mem, dt)
    write_command(cmd, U1, U2, U3, U4, phi_d, theta_d, psi_d, flags | att_flags, vp[L.P_D], vp[L.P_K])


@njit(cache=True, inline="always", error_model="numpy")
def filtered_derivative(e, f, kd, n, decay):
    """The derivative term Kd N s / (s + N) of an error, and its filter's next state: f' = N (e - f),
    advanced over a period with e held, f+ = e + (f - e) exp(-N dt).

    Examples
    --------
    >>> import math
    >>> d, f = filtered_derivative(0.01, 0.0, 5.0, 100.0, math.exp(-0.1))   # a 1 cm step from rest
    >>> round(d, 6), round(f, 6)                          # the kick: Kd N per metre of step
    (5.0, 0.000952)
    """
    return kd * n * (e - f), e + (f - e) * decay


@njit(L.CONTROLLER_SIG, cache=True, error_model="numpy")
def nlpd(t, dt, x, ref, vp, gains, mem, cmd):
    """One period of :class:`NLPD`: the inverse-model nonlinear PD (eqs 16, 19) over decoupled attitude PID.
    Arguments: ``CONTROLLER_SIG`` (:mod:`quadcruise.layout`); gains at the offsets of :data:`NLPD_GAINS`.

    Examples
    --------
    >>> import numpy as np
    >>> import quadcruise as qc
    >>> from quadcruise.layout import CMD_THETA_D, REF_X
    >>> c, vp = NLPD(), qc.Vehicle.paper().rows()[0]
    >>> ref, cmd = np.zeros(11), np.zeros(12)
    >>> ref[REF_X] = 0.1                                    # 10 cm ahead in x: pitch forward
    >>> nlpd(0.0, 0.001, np.zeros(16), ref, vp, c.gains(), c.memory(), cmd)
    >>> round(float(cmd[CMD_THETA_D]), 4)
    0.0307
    """
    ff, tilt = gains[NL_ACCEL_FF], gains[NL_MAX_TILT]
    if gains[NL_DERIVATIVE] == 0.0:  # on the measurement, with the reference's velocity
        ux = (
            gains[NL_KP_XY] * (ref[L.REF_X] - x[L.X]) + gains[NL_KD_XY] * (ref[L.REF_VX] - x[L.VX]) + ff * ref[L.REF_AX]
        )
        uy = (
            gains[NL_KP_XY] * (ref[L.REF_Y] - x[L.Y]) + gains[NL_KD_XY] * (ref[L.REF_VY] - x[L.VY]) + ff * ref[L.REF_AY]
        )
    else:  # eq (17): on the whole error, filtered by N
        ex, ey, n = ref[L.REF_X] - x[L.X], ref[L.REF_Y] - x[L.Y], gains[NL_FILTER_N]
        decay = math.exp(-n * dt)
        dx, fx = filtered_derivative(ex, mem[NL_FILTER_X], gains[NL_KD_XY], n, decay)
        dy, fy = filtered_derivative(ey, mem[NL_FILTER_Y], gains[NL_KD_XY], n, decay)
        ux = gains[NL_KP_XY] * ex + dx + ff * ref[L.REF_AX]
        uy = gains[NL_KP_XY] * ey + dy + ff * ref[L.REF_AY]
        mem[NL_FILTER_X], mem[NL_FILTER_Y] = fx, fy
    uz = gains[NL_KP_Z] * (ref[L.REF_Z] - x[L.Z]) + gains[NL_KD_Z] * (ref[L.REF_VZ] - x[L.VZ]) + ff * ref[L.REF_AZ]
    phi, theta, psi, psi_d = x[L.PHI], x[L.THETA], x[L.PSI], ref[L.REF_PSI]
    m, g, K = vp[L.P_M], vp[L.P_G], vp[L.P_K]
    sphi, cphi = math.sin(phi), math.cos(phi)  # each computed once, shared
    spsi, cpsi = math.sin(psi), math.cos(psi)
    U1, flags = thrust_for_tilt(uz, cphi * math.cos(theta), m, g, K, gains[NL_COS_MAX_TILT])
    a = U1 / m
    if gains[NL_INVERSION] == 0.0:  # (5) and (6) together, at any yaw
        phi_d, theta_d, flags = tilt_joint(ux, uy, spsi, cpsi, a, tilt, flags)
    else:  # the paper's: (16) with the current roll, then (19)
        pitch, stheta_d, clipped = pitch_eq16(ux, sphi, cphi, spsi, cpsi, a)  # (16)
        theta_d, flags = tilt_setpoint(pitch, clipped, tilt, flags)
        if theta_d != pitch:  # limited: sin theta_d is no longer asin's argument
            stheta_d = math.copysign(gains[NL_SIN_MAX_TILT], theta_d)
        phi_d, clipped = roll_eq19(uy, stheta_d, spsi, cpsi, a)  # (19), sign kept
        phi_d, flags = tilt_setpoint(phi_d, clipped, tilt, flags)
    finish(U1, phi_d, theta_d, psi_d, flags, dt, x, vp, gains, mem, cmd)


@dataclass(frozen=True)
class NLPD(Controller):
    """The paper's controller: inverse-model nonlinear PD on x, y (eqs 16, 19), PD altitude
    with tilt-compensated thrust, decoupled PID attitude (eqs 13-15) and yaw hold.

    Parameters
    ----------
    position : PDGains
        x and y loops; the paper's poles -0.7, -4.3 give Kp = 3.01 1/s^2, Kd = 5.0 1/s (eq 18).
    altitude : PDGains
        z loop (not in the paper; the same poles by default).
    attitude : PIDGains
        roll and pitch loops on the decoupled double integrator (not in the paper).
    yaw : PIDGains
        yaw loop (not in the paper; same as attitude by default).
    max_tilt : float
        roll and pitch setpoint limit [rad]; 45 degrees by default.
    i_limit : float
        anti-windup bound on the integral term Ki int(e) [rad/s^2].
    accel_feedforward : bool
        add the reference acceleration to u_x, u_y, u_z (off: the paper's eq 16 has none).
    inversion : {"joint", "sequential"}
        how roll and pitch setpoints come from u_x, u_y: eqs (5) and (6) solved together (the
        default, exact at any yaw), or the paper's literal eq (16) with the current roll then
        eq (19), which loses its damping at a held yaw beyond about 39 degrees.
    derivative : {"measurement", "error"}
        where the x and y derivative acts: on the measured velocity, with the reference's
        velocity (u = Kp e + Kd (x_r' - x'), the default), or on the whole error as eq (17)
        writes it, Kd N s / (s + N) e, through a first-order filter of bandwidth
        ``derivative_filter`` whose state starts at rest (the filtered error is 0). A jump
        of the error (a step, the circle's start offset) then gives a kick of Kd N per
        metre of jump, decaying as exp(-N t); the asin clip and the tilt limit absorb it
        beyond a few centimetres (see docs/paper.md).
    derivative_filter : float
        the filter's bandwidth N [1/s] of the ``"error"`` form (Simulink's PID default,
        100); unused by the ``"measurement"`` form.

    Examples
    --------
    >>> from quadcruise.control.position import NLPD
    >>> c = NLPD()
    >>> round(c.position.kp, 2), round(c.position.kd, 2)
    (3.01, 5.0)
    >>> c.gains().shape, c.memory().shape
    ((18,), (3,))
    >>> NLPD(derivative="error").memory().shape        # and the derivative filter's states
    (5,)
    """

    name = "nlpd"
    memory_size = ATTITUDE_MEMORY.size

    position: PDGains = _f(unit="-", doc="x and y PD loops", check=instance_of(PDGains), factory=position_pd_design)
    altitude: PDGains = _f(unit="-", doc="z PD loop", check=instance_of(PDGains), factory=altitude_pd_design)
    attitude: PIDGains = _f(
        unit="-", doc="roll and pitch PID loops", check=instance_of(PIDGains), factory=attitude_pid_design
    )
    yaw: PIDGains = _f(unit="-", doc="yaw PID loop", check=instance_of(PIDGains), factory=attitude_pid_design)
    max_tilt: float = _f(math.radians(45.0), "rad", "roll and pitch setpoint limit", TILT)
    i_limit: float = _f(5.0, "rad/s^2", "anti-windup bound on the attitude integral term", "pos")
    accel_feedforward: bool = _f(False, "-", "reference acceleration fed forward", "flag")
    inversion: str = _f("joint", "-", "how roll and pitch setpoints are solved from u_x, u_y", "choice", INVERSIONS)
    derivative: str = _f("measurement", "-", "what the x and y derivative acts on", "choice", DERIVATIVES)
    derivative_filter: float = _f(100.0, "1/s", "bandwidth N of the derivative filter on the error", "pos")

    @property
    def function(self):
        """The compiled law, :func:`nlpd` (``CONTROLLER_SIG``)."""
        return nlpd

    def memory(self) -> np.ndarray:
        """Initial memory: the attitude integrals, and with ``derivative="error"`` the filter's
        states (the filtered x and y errors), all at rest (zeros).

        Returns
        -------
        numpy.ndarray
            Zeros: 3 float64 entries (the roll, pitch and yaw error integrals
            [rad s]), 5 with ``derivative="error"`` (and the filtered x and y errors [m]).
        """
        return np.zeros((NLPD_MEMORY if self.derivative == "error" else ATTITUDE_MEMORY).size)

    def gains(self) -> np.ndarray:
        """The parameter vector :func:`nlpd` reads.

        Returns
        -------
        numpy.ndarray
            :data:`NLPD_GAINS`, 18 float64 entries: the attitude block (``ATTITUDE_GAINS``:
            roll/pitch and yaw kp [1/s^2], ki [1/s^3], kd [1/s], i_limit [rad/s^2]), then
            Kp [1/s^2] and Kd [1/s] of x and y, the same of z, max_tilt [rad], the
            feedforward switch (1.0 on, 0.0 off), cos and sin of max_tilt, the inversion
            (index in ``INVERSIONS``), the derivative form (index in ``DERIVATIVES``) and
            derivative_filter N [1/s].
        """
        return NLPD_GAINS.pack(
            {
                **attitude_fields(self.attitude, self.yaw, self.i_limit),
                "kp_xy": self.position.kp,
                "kd_xy": self.position.kd,
                "kp_z": self.altitude.kp,
                "kd_z": self.altitude.kd,
                "max_tilt": self.max_tilt,
                "accel_ff": 1.0 if self.accel_feedforward else 0.0,
                "cos_max_tilt": math.cos(self.max_tilt),
                "sin_max_tilt": math.sin(self.max_tilt),
                "inversion": float(INVERSIONS.index(self.inversion)),
                "derivative": float(DERIVATIVES.index(self.derivative)),
                "filter_n": self.derivative_filter,
            }
        )
