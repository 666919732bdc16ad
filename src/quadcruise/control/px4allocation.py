"""PX4's control allocation for rotors (release v1.15): the effectiveness matrix of the
``CA_ROTOR*`` geometry, its normalised pseudo-inverse, and the sequential desaturation.

As ``src/modules/control_allocator/``: ``ActuatorEffectiveness/ActuatorEffectivenessRotors.cpp``
(rotor ``i`` at ``r_i`` with thrust axis ``a_i``, coefficient ``CT`` and moment ratio ``KM``
gives thrust ``CT a_i`` and moment ``CT r_i x a_i - CT KM a_i``, FRD body),
``ControlAllocation/ControlAllocationPseudoInverse.cpp`` (the mix is the pseudo-inverse,
its roll and pitch columns divided by one common scale, yaw by its largest entry, thrust by
the rotors' mean thrust-column norm, entries under 1e-3 set to 0) and
``ControlAllocationSequentialDesaturation.cpp`` (``MC_AIRMODE`` 0: thrust only reduced, then
roll, pitch desaturated, yaw mixed last with a 15 % headroom; 1 and 2 as PX4). Control axes
are PX4's: roll, pitch, yaw torque, thrust x, y, z (normalised; z negative up).
"""

from __future__ import annotations

import numpy as np
from numba import njit

__all__ = ["rotor_effectiveness", "mix_matrix", "allocate", "allocate_into", "rotors_from_params"]

_EPS32 = 1.1920929e-07


def rotor_effectiveness(positions, axes, ct, km) -> np.ndarray:
    """``ActuatorEffectivenessRotors::computeEffectivenessMatrix``: (6, n), rows roll, pitch,
    yaw moment, then thrust x, y, z, per rotor.

    Parameters
    ----------
    positions, axes : array_like, shape (n, 3)
        Rotor positions [m] and thrust axes (normalised here), FRD body.
    ct, km : array_like, shape (n,)
        Thrust coefficients and moment ratios (``CA_ROTORi_CT``, ``CA_ROTORi_KM``).

    Returns
    -------
    numpy.ndarray, shape (6, n)
        Moment (roll, pitch, yaw) and thrust (x, y, z) of each rotor at full command.

    Examples
    --------
    >>> e = rotor_effectiveness([[1, 1, 0]], [[0, 0, -1]], [1.0], [0.05])
    >>> e[:, 0].tolist()
    [-1.0, 1.0, 0.05, 0.0, 0.0, -1.0]
    """
    positions, axes = np.asarray(positions, float), np.asarray(axes, float)
    ct, km = np.asarray(ct, float), np.asarray(km, float)
    out = np.zeros((6, len(ct)))
    for i in range(len(ct)):
        norm = np.linalg.norm(axes[i])
        if norm <= _EPS32 or abs(ct[i]) < _EPS32:
            continue
        axis = axes[i] / norm
        out[:3, i] = ct[i] * np.cross(positions[i], axis) - ct[i] * km[i] * axis
        out[3:, i] = ct[i] * axis
    return out


def mix_matrix(effectiveness, normalize: bool = True) -> tuple[np.ndarray, np.ndarray]:
    """The allocation (mix) matrix (n, 6) and the normalisation scale (6) of PX4's pseudo-inverse.

    ``normalize`` False keeps the plain pseudo-inverse (scale 1), as PX4's allocator tests set
    it up; entries under 1e-3 in size are set to 0 either way.

    Parameters
    ----------
    effectiveness : array_like, shape (6, n)
        :func:`rotor_effectiveness`'s matrix.
    normalize : bool
        Normalise the columns as PX4's multicopter allocator does.

    Returns
    -------
    mix : numpy.ndarray, shape (n, 6)
        Rotor setpoints per unit of each normalised control axis.
    scale : numpy.ndarray, shape (6,)
        What each column was divided by.

    Examples
    --------
    >>> e = rotor_effectiveness([[1, 1, 0], [-1, -1, 0], [1, -1, 0], [-1, 1, 0]], [[0, 0, -1]] * 4,
    ...                         [1.0] * 4, [0.05, 0.05, -0.05, -0.05])
    >>> mix, scale = mix_matrix(e, normalize=False)
    >>> mix[0].round(4).tolist()
    [-0.25, 0.25, 5.0, 0.0, 0.0, -0.25]
    """
    mix = np.linalg.pinv(np.asarray(effectiveness, float))
    scale = np.ones(6)
    if normalize:
        roll = np.count_nonzero(np.abs(mix[:, 0]) > 1e-3)
        pitch = np.count_nonzero(np.abs(mix[:, 1]) > 1e-3)
        roll_scale = np.sqrt(np.sum(mix[:, 0] ** 2) / (roll / 2.0)) if roll else 1.0
        pitch_scale = np.sqrt(np.sum(mix[:, 1] ** 2) / (pitch / 2.0)) if pitch else 1.0
        scale[0] = scale[1] = max(roll_scale, pitch_scale)
        scale[2] = mix[:, 2].max()
        norms = np.linalg.norm(mix[:, 3:], axis=1)
        thrusting = np.count_nonzero(norms > _EPS32)
        scale[3:] = norms.sum() / thrusting if thrusting else 1.0
        if scale[0] > _EPS32:
            mix[:, 0] /= scale[0]
            mix[:, 1] /= scale[1]
        if scale[2] > _EPS32:
            mix[:, 2] /= scale[2]
        if scale[3] > _EPS32:
            mix[:, 3:] /= scale[3:]
    mix[np.abs(mix) < 1e-3] = 0.0
    return mix, scale


def rotors_from_params(params) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
    """``CA_ROTOR_COUNT`` rotors' positions, axes, ``CT`` and ``KM`` from PX4 parameters.

    Parameters
    ----------
    params : Mapping
        PX4 parameters by name (a ULog's ``initial_parameters``, say).

    Returns
    -------
    tuple of numpy.ndarray
        Positions (n, 3) [m], axes (n, 3), ``CT`` (n,), ``KM`` (n,): :func:`rotor_effectiveness`'s arguments.
    """
    n = int(params["CA_ROTOR_COUNT"])
    pos = np.array([[params[f"CA_ROTOR{i}_P{c}"] for c in "XYZ"] for i in range(n)], float)
    axes = np.array([[params[f"CA_ROTOR{i}_A{c}"] for c in "XYZ"] for i in range(n)], float)
    ct = np.array([params[f"CA_ROTOR{i}_CT"] for i in range(n)], float)
    km = np.array([params[f"CA_ROTOR{i}_KM"] for i in range(n)], float)
    return pos, axes, ct, km


@njit(cache=True, inline="always", error_model="numpy")
def _gain(mix, col, sp, lo, hi, headroom):
    """``computeDesaturationGain`` along ``mix[:, col]``: the step that removes the saturation
    (the upper bounds raised by ``headroom`` times the range); rotors whose entry is under 0.2
    in size are not used."""
    k_min = 0.0
    k_max = 0.0
    for i in range(sp.size):
        v = mix[i, col]
        if abs(v) < 0.2:
            continue
        top = hi[i] + headroom * (hi[i] - lo[i])
        if sp[i] < lo[i]:
            k = (lo[i] - sp[i]) / v
            k_min = min(k_min, k)
            k_max = max(k_max, k)
        if sp[i] > top:
            k = (top - sp[i]) / v
            k_min = min(k_min, k)
            k_max = max(k_max, k)
    return k_min + k_max


@njit(cache=True, inline="always", error_model="numpy")
def _desaturate(sp, mix, col, lo, hi, increase_only, headroom):
    """``desaturateActuators``: one full step, then half a step, along ``mix[:, col]``."""
    gain = _gain(mix, col, sp, lo, hi, headroom)
    if gain == 0.0 or (increase_only and gain < 0.0):
        return  # nothing saturated: the half step would be 0 too
    for i in range(sp.size):
        sp[i] += gain * mix[i, col]
    gain = 0.5 * _gain(mix, col, sp, lo, hi, headroom)
    for i in range(sp.size):
        sp[i] += gain * mix[i, col]


@njit(cache=True, inline="always", error_model="numpy")
def _mix_yaw(sp, mix, control, lo, hi):
    for i in range(sp.size):
        sp[i] += mix[i, 2] * control[2]
    _desaturate(sp, mix, 2, lo, hi, False, 0.15)  # some yaw response at full thrust
    _desaturate(sp, mix, 5, lo, hi, True, 0.0)


@njit(cache=True, error_model="numpy")
def allocate_into(sp, mix, control, airmode, lo, hi):
    """:func:`allocate` written into ``sp`` (shape (n,)), allocating nothing: the compiled
    controller's form (:mod:`quadcruise.control.px4`)."""
    n = mix.shape[0]
    inside = True  # every rotor within its range with all six axes mixed: no step would move it
    for i in range(n):
        v = 0.0
        for j in (0, 1, 2, 3, 4, 5) if airmode == 2 else (0, 1, 3, 4, 5, 2):  # the slow path's order
            v += mix[i, j] * control[j]
        sp[i] = v
        inside = inside and lo[i] <= v <= hi[i]
    if inside:
        return
    for i in range(n):
        sp[i] = 0.0
    if airmode == 2:
        for i in range(n):
            for j in range(6):
                sp[i] += mix[i, j] * control[j]
        _desaturate(sp, mix, 5, lo, hi, False, 0.0)
        _desaturate(sp, mix, 2, lo, hi, False, 0.0)
        return
    for i in range(n):
        for j in (0, 1, 3, 4, 5):
            sp[i] += mix[i, j] * control[j]
    if airmode == 1:
        _desaturate(sp, mix, 5, lo, hi, False, 0.0)
    else:
        _desaturate(sp, mix, 5, lo, hi, True, 0.0)  # thrust only reduced
        _desaturate(sp, mix, 0, lo, hi, False, 0.0)
        _desaturate(sp, mix, 1, lo, hi, False, 0.0)
    _mix_yaw(sp, mix, control, lo, hi)


@njit(cache=True)
def allocate(mix, control, airmode, lo, hi):
    """``ControlAllocationSequentialDesaturation::allocate`` (trims zero): rotor setpoints.

    Parameters
    ----------
    mix : numpy.ndarray, shape (n, 6)
        :func:`mix_matrix`'s.
    control : numpy.ndarray, shape (6,)
        Normalised roll, pitch, yaw torque and thrust x, y, z setpoints.
    airmode : int
        ``MC_AIRMODE``: 0 disabled, 1 roll and pitch, 2 roll, pitch and yaw.
    lo, hi : numpy.ndarray, shape (n,)
        Each rotor's setpoint range (PX4: 0 and 1).

    Returns
    -------
    numpy.ndarray, shape (n,)
        Rotor setpoints, before PX4's final clipping to ``[lo, hi]``.
    """
    sp = np.zeros(mix.shape[0])
    allocate_into(sp, mix, control, airmode, lo, hi)
    return sp
