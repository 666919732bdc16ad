"""Controllers that fly a setpoint written into their gains row: the action modes of
:mod:`quadcruise.gym`.

Each is compiled with ``CONTROLLER_SIG`` and reads its setpoint, four numbers normalised to
[-1, 1], from ``gains[0:4]`` (what :meth:`quadcruise.sim.stepper.Stepper.step` writes), its
scales and loop gains from ``gains[4:]`` (the row :data:`SETPOINT_GAINS`, read at the ``S_*``
offsets). So a policy's action flies through the engine's kernel like any controller.

Modes (a = the four normalised numbers; T_h = m g, the hover thrust of the vehicle the
controller believes in):

- ``rotors``: rotor i's duty is the hover duty times (1 + a_i): a = 0 hovers, 1 asks twice
  the hover thrust of that rotor.
- ``rates``: collective thrust T_h (1 + a_0) [N] and body rates a_1..a_3 times the largest
  rates [rad/s], flown by a proportional rate loop (the gains of
  :func:`~quadcruise.control.cascade.rate_pid_design`'s proportional terms).
- ``attitude``: collective thrust as above, roll and pitch a_1, a_2 times the largest tilt
  [rad], yaw a_3 pi [rad]; a proportional attitude loop on the paper's Euler angles feeds the
  rate loop.
- ``velocity``: velocity a_0..a_2 times the largest speeds [m/s] (earth frame, z up), yaw
  a_3 pi [rad]; a proportional velocity loop asks an acceleration, turned into thrust and
  tilt (limited to the largest tilt), then the attitude and rate loops.

The choice of proportional loops: they have no memory, so an environment reset needs none,
and a rate loop on an integrator plant needs no integral term to hold a rate without a
disturbance torque. The duties are not clipped here: the engine clips and reports them.
"""

from __future__ import annotations

import math

import numpy as np
from numba import njit

from quadcruise import layout as L
from quadcruise.checks import describe
from quadcruise.control.base import write_command
from quadcruise.model.actuators import mix

DEFAULT_SCALES = {
    "max_rate_rp": 3.0,  # rad/s: the largest roll and pitch rate asked
    "max_rate_yaw": 1.5,  # rad/s
    "max_tilt": 0.5,  # rad
    "max_speed_xy": 3.0,  # m/s
    "max_speed_z": 2.0,  # m/s
    "kp_rate_rp": 15.0,  # 1/s: rate_pid_design()'s kp at the paper's 15 rad/s actuator bandwidth
    "kp_rate_yaw": 5.86,  # 1/s: rate_pid_design(yaw=True)'s kp
    "k_att": 5.0,  # 1/s: a third of the rate loop's gain, so the loops stay apart
    "k_att_yaw": 2.0,  # 1/s
    "k_vel": 2.0,  # 1/s
}
"""Scales and loop gains of the action modes, in the order of the ``S_*`` offsets."""


ACTION = ("a0", "a1", "a2", "a3")
"""The four normalised numbers of an action, the first entries of the gains row."""
SETPOINT_GAINS = L.Row.of("setpoint gains", *ACTION, *DEFAULT_SCALES, prefix="S_")
"""An action-mode controller's gains row: the action, then the scales and gains of
:data:`DEFAULT_SCALES`."""
(
    S_A0,
    S_A1,
    S_A2,
    S_A3,
    S_MAX_RATE_RP,
    S_MAX_RATE_YAW,
    S_MAX_TILT,
    S_MAX_SPEED_XY,
    S_MAX_SPEED_Z,
    S_KP_RATE_RP,
    S_KP_RATE_YAW,
    S_K_ATT,
    S_K_ATT_YAW,
    S_K_VEL,
) = SETPOINT_GAINS.offsets


def setpoint_gains(**scales: float) -> np.ndarray:
    """A gains row for an action-mode controller: zero setpoint (hover thrust, level, still),
    then :data:`DEFAULT_SCALES` with ``scales`` replacing some.

    Examples
    --------
    >>> setpoint_gains(max_tilt=0.3)[[0, S_MAX_TILT]].tolist()
    [0.0, 0.3]
    """
    unknown = set(scales) - set(DEFAULT_SCALES)
    if unknown:
        raise ValueError(f"unknown action scale {min(unknown)!r}; valid: {', '.join(DEFAULT_SCALES)}")
    values = {**DEFAULT_SCALES, **scales}
    for key, value in values.items():
        if not (isinstance(value, (int, float)) and math.isfinite(value) and value > 0):
            raise ValueError(f"action scale {key!r} must be a number > 0, got {describe(value)}")
    return SETPOINT_GAINS.pack({**dict.fromkeys(ACTION, 0.0), **{k: float(v) for k, v in values.items()}})


@njit(cache=True, inline="always", error_model="numpy")
def _rate_loop(sp1, sp2, sp3, p, q, r, kp_rp, kp_yaw, jx, jy, jz, l):
    """Roll, pitch and yaw inputs U2, U3 [N], U4 [N m] of a proportional body-rate loop."""
    return (jx * kp_rp * (sp1 - p) / l, jy * kp_rp * (sp2 - q) / l, jz * kp_yaw * (sp3 - r))


@njit(cache=True, inline="always", error_model="numpy")
def _wrapped(a):
    """An angle [rad] in [-pi, pi)."""
    return (a + math.pi) % (2.0 * math.pi) - math.pi


@njit(L.CONTROLLER_SIG, cache=True, error_model="numpy")
def rotor_setpoint(t, dt, x, ref, vp, G, mem, cmd):
    """Rotor duties from ``G[0:4]``: duty i = hover duty (1 + G[i]) (``CONTROLLER_SIG``)."""
    K, d = vp[L.P_K], vp[L.P_D]
    hover = vp[L.P_M] * vp[L.P_G] / (4.0 * K)
    u1, u2, u3, u4 = hover * (1.0 + G[S_A0]), hover * (1.0 + G[S_A1]), hover * (1.0 + G[S_A2]), hover * (1.0 + G[S_A3])
    U1, U2, U3, U4 = mix(K * u1, K * u2, K * u3, K * u4, d)
    cmd[0], cmd[1], cmd[2], cmd[3] = u1, u2, u3, u4
    cmd[L.CMD_THRUST], cmd[L.CMD_TAU_PHI], cmd[L.CMD_TAU_THETA], cmd[L.CMD_TAU_PSI] = U1, U2, U3, U4
    cmd[L.CMD_PHI_D], cmd[L.CMD_THETA_D], cmd[L.CMD_PSI_D], cmd[L.CMD_FLAGS] = 0.0, 0.0, 0.0, 0.0


@njit(L.CONTROLLER_SIG, cache=True, error_model="numpy")
def rate_setpoint(t, dt, x, ref, vp, G, mem, cmd):
    """Collective thrust m g (1 + G[0]) and body rates G[1:4] times the largest rates,
    through a proportional rate loop (``CONTROLLER_SIG``; parameters as :func:`rotor_setpoint`)."""
    m, g, K, d, l = vp[L.P_M], vp[L.P_G], vp[L.P_K], vp[L.P_D], vp[L.P_L]
    jx, jy, jz = vp[L.P_JXX], vp[L.P_JYY], vp[L.P_JZZ]
    p, q, r = x[L.P], x[L.Q], x[L.R]
    U1 = m * g * (1.0 + G[S_A0])
    sp1, sp2, sp3 = G[S_A1] * G[S_MAX_RATE_RP], G[S_A2] * G[S_MAX_RATE_RP], G[S_A3] * G[S_MAX_RATE_YAW]
    U2, U3, U4 = _rate_loop(sp1, sp2, sp3, p, q, r, G[S_KP_RATE_RP], G[S_KP_RATE_YAW], jx, jy, jz, l)
    write_command(cmd, U1, U2, U3, U4, 0.0, 0.0, 0.0, 0, d, K)


@njit(L.CONTROLLER_SIG, cache=True, error_model="numpy")
def attitude_setpoint(t, dt, x, ref, vp, G, mem, cmd):
    """Collective thrust m g (1 + G[0]), roll and pitch G[1:3] times the largest tilt, yaw
    G[3] pi, through proportional attitude and rate loops (``CONTROLLER_SIG``)."""
    m, g, K, d, l = vp[L.P_M], vp[L.P_G], vp[L.P_K], vp[L.P_D], vp[L.P_L]
    jx, jy, jz = vp[L.P_JXX], vp[L.P_JYY], vp[L.P_JZZ]
    phi, theta, psi, p, q, r = x[L.PHI], x[L.THETA], x[L.PSI], x[L.P], x[L.Q], x[L.R]
    U1 = m * g * (1.0 + G[S_A0])
    phi_d, theta_d, psi_d = G[S_A1] * G[S_MAX_TILT], G[S_A2] * G[S_MAX_TILT], G[S_A3] * math.pi
    k_att, k_yaw = G[S_K_ATT], G[S_K_ATT_YAW]
    sp1, sp2, sp3 = k_att * (phi_d - phi), k_att * (theta_d - theta), k_yaw * _wrapped(psi_d - psi)
    U2, U3, U4 = _rate_loop(sp1, sp2, sp3, p, q, r, G[S_KP_RATE_RP], G[S_KP_RATE_YAW], jx, jy, jz, l)
    write_command(cmd, U1, U2, U3, U4, phi_d, theta_d, psi_d, 0, d, K)


@njit(L.CONTROLLER_SIG, cache=True, error_model="numpy")
def velocity_setpoint(t, dt, x, ref, vp, G, mem, cmd):
    """Velocity G[0:3] times the largest speeds (earth frame) and yaw G[3] pi, through a
    proportional velocity loop, the thrust and tilt that give its acceleration (tilt limited),
    and the attitude and rate loops (``CONTROLLER_SIG``)."""
    m, g, K, d, l = vp[L.P_M], vp[L.P_G], vp[L.P_K], vp[L.P_D], vp[L.P_L]
    jx, jy, jz = vp[L.P_JXX], vp[L.P_JYY], vp[L.P_JZZ]
    vx, vy, vz = x[L.VX], x[L.VY], x[L.VZ]
    phi, theta, psi, p, q, r = x[L.PHI], x[L.THETA], x[L.PSI], x[L.P], x[L.Q], x[L.R]
    k_vel, tilt = G[S_K_VEL], G[S_MAX_TILT]
    ax = k_vel * (G[S_A0] * G[S_MAX_SPEED_XY] - vx)
    ay = k_vel * (G[S_A1] * G[S_MAX_SPEED_XY] - vy)
    az = max(k_vel * (G[S_A2] * G[S_MAX_SPEED_Z] - vz), -0.9 * g)
    psi_d = G[S_A3] * math.pi
    c, s = math.cos(psi), math.sin(psi)
    # eqs (5), (6) at small roll: x'' = (cos psi theta + sin psi phi) a, y'' = (sin psi theta - cos psi phi) a
    theta_d = math.atan((c * ax + s * ay) / (g + az))
    phi_d = math.atan((s * ax - c * ay) * math.cos(theta_d) / (g + az))
    flags = 0
    if abs(theta_d) > tilt or abs(phi_d) > tilt:
        flags = 1
        theta_d, phi_d = max(-tilt, min(tilt, theta_d)), max(-tilt, min(tilt, phi_d))
    U1 = m * (g + az) / (math.cos(phi_d) * math.cos(theta_d))
    k_att, k_yaw = G[S_K_ATT], G[S_K_ATT_YAW]
    sp1, sp2, sp3 = k_att * (phi_d - phi), k_att * (theta_d - theta), k_yaw * _wrapped(psi_d - psi)
    U2, U3, U4 = _rate_loop(sp1, sp2, sp3, p, q, r, G[S_KP_RATE_RP], G[S_KP_RATE_YAW], jx, jy, jz, l)
    write_command(cmd, U1, U2, U3, U4, phi_d, theta_d, psi_d, flags, d, K)


ACTION_CONTROLLERS = {
    "rotors": rotor_setpoint,
    "rates": rate_setpoint,
    "attitude": attitude_setpoint,
    "velocity": velocity_setpoint,
}
"""The action modes and their compiled controllers."""

__all__ = [
    "ACTION_CONTROLLERS",
    "DEFAULT_SCALES",
    "SETPOINT_GAINS",
    "attitude_setpoint",
    "rate_setpoint",
    "rotor_setpoint",
    "setpoint_gains",
    "velocity_setpoint",
]
