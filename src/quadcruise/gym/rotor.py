"""What an environment's episode of a rotor-plant vehicle needs beyond the paper plant's: the
drawn vehicles' parameter rows, the controller's allocation, and the hover start.

Domain randomisation: a :class:`~quadcruise.montecarlo.population.Population` draws its spreads
(mass, inertia, thrust gain K, bandwidth omega, yaw arm d) on the nominal vehicle's equivalent
paper vehicle (:func:`~quadcruise.model.equivalent.paper_equivalent`); each drawn factor scales
the rotor vehicle's own fields: m, Jxx, Jyy, Jzz as they are; kf by K's factor (K is
proportional to kf); km by K's and d's (d = km / kf); tau_up and tau_down by 1 / omega's. So the
drawn vehicle's equivalent is the drawn paper vehicle, and a population means the same on
either plant.

Action ``rotors`` on the rotor plant commands the real rotors, in the vehicle's order (not the
"+" equivalent's virtual ones): rotor i's thrust is its hover thrust m g / n times (1 + a_i), its
speed sqrt(f / kf) held in [w_min, w_max] (the time held is counted as clipped). a = 0 hovers,
as in every mode and on either plant. It needs four rotors (the action has four entries).
"""

from __future__ import annotations

import numpy as np

from quadcruise.errors import InputError
from quadcruise.layout import P_D, P_JXX, P_JYY, P_JZZ, P_K, P_M, P_OMEGA, REF_PSI, REF_X
from quadcruise.model.equivalent import duty_to_thrust
from quadcruise.model.rotor_plant import (
    QW,
    QZ,
    ROTOR_P_G,
    ROTOR_P_JXX,
    ROTOR_P_JYY,
    ROTOR_P_JZZ,
    ROTOR_P_KF,
    ROTOR_P_KM,
    ROTOR_P_M,
    ROTOR_P_N_ROTORS,
    ROTOR_P_TAU_DOWN,
    ROTOR_P_TAU_UP,
    ROTOR_W1,
    RX,
)
from quadcruise.model.rotor_vehicle import RotorVehicle


def drawn_rows(nominal: RotorVehicle, nominal_eq: np.ndarray, drawn_eq: np.ndarray) -> np.ndarray:
    """Rotor vehicle rows scaled as the drawn equivalent paper rows are scaled from the nominal's.

    Parameters
    ----------
    nominal : RotorVehicle
        The nominal vehicle.
    nominal_eq : numpy.ndarray
        (PARAM_SIZE,) its equivalent paper row.
    drawn_eq : numpy.ndarray
        (K, PARAM_SIZE) the drawn paper rows (a population drawn on the equivalent).

    Returns
    -------
    numpy.ndarray
        (K, P) rotor rows (the module's rules).
    """
    k = drawn_eq.shape[0]
    rows = np.tile(nominal.row(), (k, 1))
    cols = [P_M, P_JXX, P_JYY, P_JZZ, P_K, P_D, P_OMEGA]  # nonzero on a vehicle that flies
    f = np.zeros_like(drawn_eq)
    f[:, cols] = drawn_eq[:, cols] / nominal_eq[cols]
    rows[:, ROTOR_P_M] *= f[:, P_M]
    rows[:, ROTOR_P_JXX] *= f[:, P_JXX]
    rows[:, ROTOR_P_JYY] *= f[:, P_JYY]
    rows[:, ROTOR_P_JZZ] *= f[:, P_JZZ]
    rows[:, ROTOR_P_KF] *= f[:, P_K]
    rows[:, ROTOR_P_KM] *= f[:, P_K] * f[:, P_D]
    rows[:, ROTOR_P_TAU_UP] /= f[:, P_OMEGA]
    rows[:, ROTOR_P_TAU_DOWN] /= f[:, P_OMEGA]
    return rows


def allocation_rows(believed: RotorVehicle, vp_ctrl: np.ndarray, action: str | None) -> np.ndarray:
    """The rotor kernel's ``alloc`` rows (duty-to-thrust matrix and kf) of the vehicles the
    controllers believe.

    Parameters
    ----------
    believed : RotorVehicle
        The nominal vehicle (its layout; the drawn vehicles share it).
    vp_ctrl : numpy.ndarray
        (K, PARAM_SIZE) the equivalent paper rows the controllers read.
    action : str or None
        The action mode; None for a baseline controller.

    Returns
    -------
    numpy.ndarray
        (K, 4 n + 1): for ``rotors``, K_eq times the identity (duty i is rotor i's share of K_eq),
        otherwise :func:`~quadcruise.model.equivalent.duty_to_thrust` scaled by the drawn K (d
        drawn moves the yaw column by its factor), then kf = K_eq / w_max^2 (n / 4 rotors' worth).

    Raises
    ------
    InputError
        ``rotors`` on a vehicle without exactly four rotors.
    """
    n = believed.n_rotors
    k = vp_ctrl.shape[0]
    nominal_eq_k = n / 4.0 * believed.kf * believed.w_max**2
    scale = vp_ctrl[:, P_K] / nominal_eq_k
    if action == "rotors":
        if n != 4:
            raise InputError(
                f"action 'rotors': the action has 4 entries and the vehicle {n} rotors; "
                "fly it with 'rates', 'attitude' or 'velocity'"
            )
        matrix = np.zeros((k, 4, 4))
        matrix[:, range(4), range(4)] = vp_ctrl[:, P_K, None]
    else:
        base = duty_to_thrust(believed)  # (n, 4): columns u1..u4 of the "+" equations
        d_factor = vp_ctrl[:, P_D] / (believed.km / believed.kf)
        # B^+ W K is linear in K; W and the mixer B depend on d, so where d was drawn the
        # matrix is computed afresh for that vehicle
        matrix = base[None, :, :] * scale[:, None, None]
        for i in np.flatnonzero(~np.isclose(d_factor, 1.0, rtol=0, atol=1e-15)):
            matrix[i] = duty_to_thrust(
                believed.replace(km=believed.km * scale[i] * d_factor[i], kf=believed.kf * scale[i])
            )
    return np.concatenate([matrix.reshape(k, -1), (believed.kf * scale)[:, None]], axis=1)


def hover_starts(rows: np.ndarray, start: np.ndarray, offsets: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Rotor states hovering level on the reference's first point plus an offset.

    Parameters
    ----------
    rows : numpy.ndarray
        (K, P) the flown vehicles' rotor rows.
    start : numpy.ndarray
        (1 or K, REF_SIZE) the references at t = 0.
    offsets : numpy.ndarray
        (K, 3) initial position offsets [m].

    Returns
    -------
    x0 : numpy.ndarray
        (K, 13 + n): position, zero velocity, the start yaw's quaternion, zero rates, each
        rotor at its vehicle's hover speed sqrt(m g / (n kf)).
    psi0 : numpy.ndarray
        (K,) the start yaws [rad].
    """
    k = rows.shape[0]
    n = int(rows[0, ROTOR_P_N_ROTORS])
    psi = np.broadcast_to(start[:, REF_PSI], (k,)).astype(float)
    x0 = np.zeros((k, ROTOR_W1 + n))
    x0[:, RX : RX + 3] = start[:, REF_X : REF_X + 3] + offsets
    x0[:, QW], x0[:, QZ] = np.cos(0.5 * psi), np.sin(0.5 * psi)
    x0[:, ROTOR_W1:] = np.sqrt(rows[:, ROTOR_P_M] * rows[:, ROTOR_P_G] / (n * rows[:, ROTOR_P_KF]))[:, None]
    return x0, psi


def rotor_episodes(env, vehicle, start: np.ndarray, offsets: np.ndarray, mp: np.ndarray, k: int) -> dict:
    """The arrays of k episodes of a rotor-plant vehicle (``vehicle`` the drawn paper equivalents):
    its drawn rows, the controller's paper rows and allocation, the hover starts, and in ``own``
    the Stepper's rotor-plant rows (``alloc``, ``psi0``), in ``fixed`` its ground."""
    pop = env.population
    vp = env._rows(vehicle, k)
    vp_ctrl = env._rows(env.nominal_eq, k) if pop is None or pop.model_error else vp
    rows = drawn_rows(env.nominal, env._nominal_row[0], vp)
    x0, psi0 = hover_starts(rows, start, offsets)
    alloc = allocation_rows(env.nominal, vp_ctrl, None if env.baseline is not None else env.action_mode)
    return {
        "vp": rows,
        "vp_ctrl": vp_ctrl,
        "x0": x0,
        "mp": mp,
        "own": {"alloc": alloc, "psi0": psi0},
        "fixed": {"touchdown_speed": env.nominal.touchdown_speed},
    }


__all__ = ["allocation_rows", "drawn_rows", "hover_starts"]
