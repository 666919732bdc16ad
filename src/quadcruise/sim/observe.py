"""The kernels' side of the observation stage: what a controller sees when the vehicle flies on its
sensors and an estimator instead of the (delayed, noisy) truth.

The stage itself is a compiled function with :data:`quadcruise.layout.OBSERVER_SIG` (the sensors
and the EKF of :mod:`quadcruise.estimation.onboard`), passed to the kernels as controllers and
disturbances are; this module holds what the kernels need around it: :class:`Observation` (the
function, its parameter rows, memories and random streams, one row per vehicle), :func:`blind`
(the function of a flight without sensors: the kernels skip the stage then, by their flag
``observed``), and the plants' specific force, which the IMU measures:

    f = R^T (dv/dt + g e_z)     (FLU body frame, [m/s^2])

taken from the plant's own derivative at the period's end, so the accelerometer reads the
acceleration the integrator flies (no finite difference, which would lag by half a period). The
kernel writes it into the observer's memory at :data:`quadcruise.layout.OM_FORCE` after each
period (and at period 0 before the first), so a flight cut into calls reads the same numbers.
"""

from __future__ import annotations

import math
from typing import NamedTuple

import numpy as np
from numba import njit

from quadcruise import layout as L
from quadcruise.model.plant import derivative_at
from quadcruise.model.rotor_plant import (
    ARM_S,
    ARM_SIZE,
    QW,
    QX,
    QY,
    QZ,
    ROTOR_P_G,
    ROTOR_P_KF,
    ROTOR_P_M,
    ROTOR_P_N_ROTORS,
    ROTOR_P_ROTORS,
    ROTOR_W1,
    RP,
    RQ,
    RR,
    RVX,
    RVY,
    RVZ,
    rotor_derivative,
)


@njit(L.OBSERVER_SIG, cache=True)
def blind(t, k, logging, x, op, omem, rng, seen, obs):
    """No sensors: the function the kernels are handed when nothing observes (they do not call it).

    Parameters
    ----------
    t : float
        The instant [s] (not read).
    k : int
        The period (not read).
    logging : bool
        Whether the period is logged (not read).
    x, op, omem : numpy.ndarray
        True state, parameters, memory (not read).
    rng : numpy.ndarray
        Generator state (not read).
    seen : numpy.ndarray
        (STATE_SIZE,) output: the true state.
    obs : numpy.ndarray
        The log row (not written).
    """
    for j in range(L.STATE_SIZE):
        seen[j] = x[j]


class Observation(NamedTuple):
    """The observation stage of a batch, as the kernels take it: one row per vehicle.

    Parameters
    ----------
    function : numba function with ``OBSERVER_SIG``
        The stage (:func:`blind` when nothing observes).
    params : numpy.ndarray
        (N, P) its parameter rows.
    memory : numpy.ndarray
        (N, M) its memories, M >= 6 (their first entries :data:`quadcruise.layout.OBSERVER_KERNEL`),
        updated by a flight.
    rng : numpy.ndarray
        (N, 1) uint64 its generator states, updated by a flight.
    active : bool
        False: no sensors (the kernels skip the stage, at no cost).
    """

    function: object
    params: np.ndarray
    memory: np.ndarray
    rng: np.ndarray
    active: bool

    @classmethod
    def none(cls, n: int) -> Observation:
        """No sensors, for ``n`` vehicles.

        Parameters
        ----------
        n : int
            Vehicles.

        Returns
        -------
        Observation

        Examples
        --------
        >>> Observation.none(2).active
        False
        """
        return cls(blind, np.zeros((n, 1)), np.zeros((n, L.OBSERVER_KERNEL.size)), np.zeros((n, 1), np.uint64), False)

    def take(self, rows) -> Observation:
        """The rows of some vehicles (copies).

        Parameters
        ----------
        rows : array_like of int
            The vehicles.

        Returns
        -------
        Observation
        """
        rows = np.asarray(rows)
        return Observation(
            self.function, self.params[rows].copy(), self.memory[rows].copy(), self.rng[rows].copy(), self.active
        )

    def log(self, n: int, n_log: int) -> np.ndarray:
        """An empty log of ``n`` vehicles and ``n_log`` rows (no row when nothing observes).

        Parameters
        ----------
        n, n_log : int
            Vehicles and logged instants.

        Returns
        -------
        numpy.ndarray
            (n, n_log or 0, OBSERVATION_SIZE), uninitialised.

        Examples
        --------
        >>> Observation.none(2).log(2, 5).shape
        (2, 0, 81)
        """
        return np.empty((n, n_log if self.active else 0, L.OBSERVATION_SIZE))


SENSOR_STREAM = 35
"""The third entry of a vehicle's sensor stream's seed, ``SeedSequence([seed, i, 35])``: apart
from its disturbance's stream ``(seed, i)``, so turning sensors on leaves the turbulence as it was."""


def sensor_streams(seed: int, n: int, first_vehicle=0) -> np.ndarray:
    """(n, 1) uint64: vehicle i's sensor stream from ``SeedSequence([seed, first_vehicle + i, 35])``.

    Parameters
    ----------
    seed : int
        The flight's seed, >= 0.
    n : int
        Vehicles.
    first_vehicle : int or (n,) array of int
        The vehicles' indices (as :func:`quadcruise.sim.rng.vehicle_states`).

    Returns
    -------
    numpy.ndarray

    Examples
    --------
    >>> bool((sensor_streams(1, 3)[2] == sensor_streams(1, 1, first_vehicle=2)[0]).all())
    True
    """
    ids = np.arange(n) + int(first_vehicle) if np.ndim(first_vehicle) == 0 else np.asarray(first_vehicle).ravel()
    out = np.empty((n, 1), dtype=np.uint64)
    for k, i in enumerate(ids):
        out[k, 0] = np.random.SeedSequence([int(seed), int(i), SENSOR_STREAM]).generate_state(1, dtype=np.uint64)[0]
    return out


@njit(cache=True, inline="always")
def body_force(ax, ay, az, g, r00, r01, r02, r10, r11, r12, r20, r21, r22, om):
    """``R^T (a + g e_z)`` into ``om[OM_FORCE:OM_FORCE + 3]``: the specific force [m/s^2], FLU,
    of the world acceleration a [m/s^2] at the attitude R (body to world) under gravity g."""
    fz = az + g
    om[L.OM_FORCE] = r00 * ax + r10 * ay + r20 * fz
    om[L.OM_FORCE + 1] = r01 * ax + r11 * ay + r21 * fz
    om[L.OM_FORCE + 2] = r02 * ax + r12 * ay + r22 * fz


@njit(cache=True, inline="always")
def paper_force(x, u, vp, ext, full, dx, om):
    """The paper plant's specific force at state x (16,) under the held duties u and external
    inputs ext, and the body's angular velocity ``(phi' - s_theta psi', c_phi theta' + s_phi c_theta psi',
    -s_phi theta' + c_phi c_theta psi')`` of its Euler rates (which is (p, q, r) with the full
    kinematics), into the observer memory ``om`` (``dx``: a (16,) scratch row).

    R = Rz(psi) Ry(theta) Rx(phi), eqs. (5)-(7) of the paper."""
    sa, ca = math.sin(x[L.PHI]), math.cos(x[L.PHI])
    sb, cb = math.sin(x[L.THETA]), math.cos(x[L.THETA])
    sc, cc = math.sin(x[L.PSI]), math.cos(x[L.PSI])
    derivative_at(x, sa, ca, sb, cb, sc, cc, u, vp, ext, full, dx)
    om[L.OM_RATE] = dx[L.PHI] - sb * dx[L.PSI]  # the body's angular velocity of the Euler rates (ZYX)
    om[L.OM_RATE + 1] = ca * dx[L.THETA] + sa * cb * dx[L.PSI]
    om[L.OM_RATE + 2] = -sa * dx[L.THETA] + ca * cb * dx[L.PSI]
    body_force(
        dx[L.VX], dx[L.VY], dx[L.VZ], vp[L.P_G],
        cc * cb, cc * sb * sa - sc * ca, cc * sb * ca + sc * sa,
        sc * cb, sc * sb * sa + cc * ca, sc * sb * ca - cc * sa,
        -sb, cb * sa, cb * ca,
        om,
    )  # fmt: skip


@njit(cache=True, inline="always")
def rotor_force(xr, w_cmd, rp, ext_r, dx, om):
    """The rotor plant's specific force at its state xr under the held speeds and external
    inputs, and its body rates, into the observer memory ``om`` (``dx``: a scratch row of xr's size)."""
    rotor_derivative(xr, w_cmd, rp, ext_r, dx)
    om[L.OM_RATE], om[L.OM_RATE + 1], om[L.OM_RATE + 2] = xr[RP], xr[RQ], xr[RR]
    qw, qx, qy, qz = xr[QW], xr[QX], xr[QY], xr[QZ]
    s = 2.0 / (qw * qw + qx * qx + qy * qy + qz * qz)
    body_force(
        dx[RVX], dx[RVY], dx[RVZ], rp[ROTOR_P_G],
        1.0 - s * (qy * qy + qz * qz), s * (qx * qy - qw * qz), s * (qx * qz + qw * qy),
        s * (qx * qy + qw * qz), 1.0 - s * (qx * qx + qz * qz), s * (qy * qz - qw * qx),
        s * (qx * qz - qw * qy), s * (qy * qz + qw * qx), 1.0 - s * (qx * qx + qy * qy),
        om,
    )  # fmt: skip


@njit(cache=True, inline="always")
def rotor_shake(xr, rp, dt, om):
    """The rotors' imbalance vibration averaged over the period ``dt`` [s] just ended, into
    ``om[OM_SHAKE:OM_SHAKE + 3]`` (``dt = 0``: the start, the speeds kept and nothing else).

    Rotor i's imbalance shakes the body in its plane at its angle phi_i about +z (advanced by
    ``-s_i`` times the trapezoid of its speeds at the period's ends, ``s_i = +1`` a rotor that
    spins clockwise seen from above), with
    the amplitude ``a_i = A w_i^2 / w_h^2`` (A: ``om[OM_VIBRATION]``, each rotor's amplitude [m/s^2] at the
    hover speed ``w_h^2 = m g / (n kf)``; w_i the period's mean speed). Over the period the
    frequency is constant, so the average is exact in closed form:

        mean a_i (cos phi, sin phi, 0) = a_i (sin phi_1 - sin phi_0, cos phi_0 - cos phi_1, 0) / (phi_1 - phi_0)

    and the IMU averages these periods' means over its own period (an average, not a point
    sample: a vibration near the IMU's rate aliases as a real averaged IMU's does). Nothing is
    computed while A is 0."""
    n = min(xr.shape[0] - ROTOR_W1, L.MAX_VIBRATING_ROTORS)
    amplitude = om[L.OM_VIBRATION]
    if dt > 0.0 and amplitude != 0.0:
        scale = amplitude * rp[ROTOR_P_N_ROTORS] * rp[ROTOR_P_KF] / (rp[ROTOR_P_M] * rp[ROTOR_P_G])
        sx = sy = 0.0
        for r in range(n):
            w = 0.5 * (om[L.OM_SPIN + r] + xr[ROTOR_W1 + r])
            a = scale * w * w
            p0 = om[L.OM_PHASE + r]
            step = -rp[ROTOR_P_ROTORS + ARM_SIZE * r + ARM_S] * w * dt  # s = +1: clockwise from above
            p1 = p0 + step
            if abs(step) > 1e-12:
                sx += a * (math.sin(p1) - math.sin(p0)) / step
                sy += a * (math.cos(p0) - math.cos(p1)) / step
            else:
                sx += a * math.cos(p0)
                sy += a * math.sin(p0)
            om[L.OM_PHASE + r] = p1 - 2.0 * math.pi * math.floor(p1 / (2.0 * math.pi))
        om[L.OM_SHAKE], om[L.OM_SHAKE + 1], om[L.OM_SHAKE + 2] = sx, sy, 0.0
    if dt == 0.0 or amplitude != 0.0:
        for r in range(n):
            om[L.OM_SPIN + r] = xr[ROTOR_W1 + r]


__all__ = [
    "SENSOR_STREAM",
    "Observation",
    "blind",
    "body_force",
    "paper_force",
    "rotor_force",
    "rotor_shake",
    "sensor_streams",
]
