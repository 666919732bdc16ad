"""The paper vehicle a controller believes when it flies a rotor-plant vehicle, and the map from
its duties to the rotor vehicle's commanded rotor speeds.

The built-in controllers compute duties u1..u4 of the paper's "+" quadrotor (eqs (1)-(4)) from a
paper-layout vehicle row. For a :class:`~quadcruise.model.rotor_vehicle.RotorVehicle` they are
given its *equivalent paper vehicle* (:func:`paper_equivalent`):

- m, Jxx, Jyy, Jzz, g: the rotor vehicle's own;
- K = (n / 4) kf w_max^2: a quarter of all n rotors' thrust at full speed, so that four duties
  of 1 are every rotor at full speed (for a quadrotor, one rotor's full thrust; a hexarotor's
  controller would otherwise cap its collective thrust, 4 K, at two thirds of what it has);
- omega = 1 / max(tau_up, tau_down): the motor lag's bandwidth. Thrust kf w^2 linearised about
  a speed w0 is 2 kf w0 dw, and dw lags the command by tau, so the thrust lags by the same tau.
  A moment is made by speeding some rotors up and slowing the others down, so the slower of
  the two lags is the one the attitude loops must respect (the Iris's 12.5 ms up, 25 ms down:
  40 rad/s; designed for 1 / tau_up = 80 rad/s, nlpd and gonzalez crash it within a second).
  The vehicle's ``control_bandwidth``, when set, replaces it: the Hummingbird's 5 ms motors
  would give 200 rad/s, and gains designed for it do not fly at the 1 kHz control rate (nlpd
  tips over within 0.1 s, se3 holds rotor speeds at their limits all flight), so its preset
  sets 40 rad/s, the Iris's;
- d = km / kf: the yaw moment per newton of thrust;
- l = the mean distance of the hubs from the z axis (a stated arm: the duties are turned back
  into moments with the same l, so the flight does not depend on it);
- no drag (the controllers do not model the rotor aerodynamics).

Each control period the duties become a wrench by the "+" equations of that vehicle
(F_i = K u_i, T = sum F_i, Mx = l (F2 - F4), My = l (F1 - F3), Mz = d (F1 + F3 - F2 - F4)), the
wrench becomes rotor thrusts by the controller vehicle's mixer B^+ (:mod:`.allocation`), and
each thrust a speed sqrt(f / kf). The three linear steps are one n x 4 matrix,
:func:`duty_to_thrust`.

Examples
--------
>>> from quadcruise.model.rotor_vehicle import RotorVehicle
>>> eq = paper_equivalent(RotorVehicle.preset("iris"))
>>> round(eq.K, 3), eq.omega, round(eq.d, 4), round(eq.l, 4)
(7.066, 40.0, 0.06, 0.247)
>>> from quadcruise.model.vehicle import Vehicle
>>> paper_equivalent(Vehicle.paper()) is Vehicle.paper()
True
"""

from __future__ import annotations

import math

import numpy as np

from quadcruise.model.allocation import mixer
from quadcruise.model.rotor_vehicle import RotorVehicle
from quadcruise.model.vehicle import Vehicle


def paper_equivalent(vehicle: RotorVehicle | Vehicle) -> Vehicle:
    """The paper-plant vehicle a controller believes for a vehicle (the module's rules): a
    rotor-plant vehicle's "+" equivalent, or a paper vehicle itself.

    Parameters
    ----------
    vehicle : RotorVehicle or Vehicle
        The vehicle; a :class:`~quadcruise.model.vehicle.Vehicle` (the paper's plant) is
        returned as given, so that a caller need not ask which plant it has.

    Returns
    -------
    Vehicle
        Same m, J and g; K = (n / 4) kf w_max^2 [N], omega = ``control_bandwidth`` or else
        1 / max(tau_up, tau_down) [rad/s], d = km / kf [m],
        l = the mean hub distance from the z axis [m], no drag.

    Raises
    ------
    InputError
        A vehicle whose equivalent cannot be (km = 0 gives d = 0: no yaw moment).
    """
    if isinstance(vehicle, Vehicle):
        return vehicle
    arm = float(np.mean([math.hypot(x, y) for x, y, _, _ in vehicle.rotors]))
    return Vehicle(
        m=vehicle.m,
        Jxx=vehicle.Jxx,
        Jyy=vehicle.Jyy,
        Jzz=vehicle.Jzz,
        l=arm,
        K=vehicle.n_rotors / 4.0 * vehicle.kf * vehicle.w_max**2,
        omega=vehicle.control_bandwidth or 1.0 / max(vehicle.tau_up, vehicle.tau_down),
        d=vehicle.km / vehicle.kf,
        g=vehicle.g,
    )


def duty_to_thrust(vehicle: RotorVehicle) -> np.ndarray:
    """The n x 4 matrix from the "+" equivalent's duties to the rotor thrusts of ``vehicle``.

    Parameters
    ----------
    vehicle : RotorVehicle
        The vehicle the controller believes (its layout, kf, km, w_max).

    Returns
    -------
    numpy.ndarray
        Shape (n, 4): B^+ W K, with W the "+" equations' map from thrusts F1..F4 to
        (T, Mx, My, Mz) of :func:`paper_equivalent` and K its thrust at duty 1 [N].

    Raises
    ------
    InputError
        A layout whose rotors cannot make T, Mx, My and Mz independently (fewer than four
        rotors, or all spinning one way).

    Examples
    --------
    >>> from quadcruise.model.rotor_vehicle import RotorVehicle
    >>> v = RotorVehicle.preset("crazyflie")
    >>> f = duty_to_thrust(v) @ [0.5, 0.5, 0.5, 0.5]      # half duty: half of full-speed thrust each
    >>> bool(np.allclose(f, 0.5 * v.kf * v.w_max**2))
    True
    """
    eq = paper_equivalent(vehicle)
    plus = np.array(
        [
            [1.0, 1.0, 1.0, 1.0],
            [0.0, eq.l, 0.0, -eq.l],
            [eq.l, 0.0, -eq.l, 0.0],
            [eq.d, -eq.d, eq.d, -eq.d],
        ]
    )
    return mixer(vehicle) @ plus * eq.K
