"""Control allocation for any rotor layout: collective thrust and body moments to rotor thrusts
and rotor speeds, for a :class:`~quadcruise.model.rotor_vehicle.RotorVehicle`.

With every rotor's thrust f_i along body z, at (x_i, y_i, z_i), and its drag moment
s_i (km/kf) f_i about body z, the wrench is linear in the thrusts:

    [T, Mx, My, Mz]^T = B f,   B = [[1 ...], [y_i ...], [-x_i ...], [s_i km/kf ...]]   (4 x n)

(RotorPy's ``f_to_TM``). The allocation is f = B^+ [T, M] with B^+ the Moore-Penrose inverse:
for a quadrotor B is square and this is the exact inverse; for more rotors it is the smallest
set of thrusts (least squares) that makes the wrench. The paper's eqs (1)-(4) are the "+" case:
rotors 1..4 at (-l, 0), (0, l), (l, 0), (0, -l), directions +1, -1, +1, -1 and km/kf = d, with
U2 = Mx / l, U3 = My / l, U4 = Mz (``tests/unit/test_allocation.py`` checks it against
:func:`quadcruise.model.actuators.unmix`). A speed is sqrt(f / kf), held in [w_min, w_max]; a
thrust it cannot make is reported, never silently clipped.

Examples
--------
>>> from quadcruise.model.rotor_vehicle import RotorVehicle
>>> v = RotorVehicle.preset("crazyflie")
>>> f = thrusts(v, v.m * v.g, (0.0, 0.0, 0.0))
>>> [round(float(x), 6) for x in f]
[0.073575, 0.073575, 0.073575, 0.073575]
>>> speeds, clipped = rotor_speeds(v, f)
>>> round(float(speeds[0]), 2), bool(clipped.any())
(1788.55, False)
"""

from __future__ import annotations

import numpy as np

from quadcruise.errors import InputError
from quadcruise.model.rotor_vehicle import RotorVehicle


def allocation_matrix(vehicle: RotorVehicle) -> np.ndarray:
    """B, the map from rotor thrusts to the collective thrust and body moments.

    Parameters
    ----------
    vehicle : RotorVehicle
        The vehicle (its rotors, kf and km).

    Returns
    -------
    numpy.ndarray
        Shape (4, n): rows T [N], Mx, My, Mz [N m] per newton of each rotor's thrust.
    """
    rotors = np.asarray(vehicle.rotors, dtype=float)
    return np.vstack([np.ones(vehicle.n_rotors), rotors[:, 1], -rotors[:, 0], rotors[:, 3] * vehicle.km / vehicle.kf])


def mixer(vehicle: RotorVehicle) -> np.ndarray:
    """B^+, the map from (T, Mx, My, Mz) to rotor thrusts.

    Parameters
    ----------
    vehicle : RotorVehicle
        The vehicle.

    Returns
    -------
    numpy.ndarray
        Shape (n, 4).

    Raises
    ------
    InputError
        A layout whose rotors cannot make every one of T, Mx, My, Mz independently (B of rank
        under 4: e.g. every rotor spinning the same way, or km = 0, leaves no yaw moment).
    """
    B = allocation_matrix(vehicle)
    rank = np.linalg.matrix_rank(B)
    if rank < 4:
        raise InputError(
            f"vehicle field 'rotors': the rotors cannot make thrust, roll, pitch and yaw moments "
            f"independently (the allocation matrix has rank {rank} of 4: check the directions and km)"
        )
    return np.linalg.pinv(B)


def thrusts(vehicle: RotorVehicle, thrust: float, moments) -> np.ndarray:
    """The rotor thrusts that make a collective thrust and body moments (not limited).

    Parameters
    ----------
    vehicle : RotorVehicle
        The vehicle.
    thrust : float
        Collective thrust along body z [N].
    moments : sequence of 3 floats
        Body moments Mx, My, Mz [N m].

    Returns
    -------
    numpy.ndarray
        Shape (n,): each rotor's thrust [N]; negative where the wrench asks for one.
    """
    return mixer(vehicle) @ np.r_[float(thrust), np.asarray(moments, dtype=float)]


def rotor_speeds(vehicle: RotorVehicle, rotor_thrusts) -> tuple[np.ndarray, np.ndarray]:
    """The rotor speeds that make the given thrusts, held in the vehicle's speed range.

    Parameters
    ----------
    vehicle : RotorVehicle
        The vehicle.
    rotor_thrusts : sequence of n floats
        Each rotor's thrust [N].

    Returns
    -------
    speeds : numpy.ndarray
        Shape (n,): sqrt(f / kf) [rad/s], within [w_min, w_max].
    clipped : numpy.ndarray of bool
        Shape (n,): where the speed had to be held (a thrust below kf w_min^2, negative
        included, or above kf w_max^2).
    """
    f = np.asarray(rotor_thrusts, dtype=float)
    w = np.sqrt(np.maximum(f, 0.0) / vehicle.kf)
    held = np.clip(w, vehicle.w_min, vehicle.w_max)
    return held, (held != w) | (f < 0.0)
