"""Dryden turbulence, MIL-F-8785C low altitude, and its exact discretisation.

h in ft, < 1000 ft; below 10 ft taken as 10 ft, as MATLAB's Dryden block does; w20 = 15/30/45 kt
for light/moderate/severe: L_w = h, L_u = L_v = h/(0.177 + 0.000823 h)^1.2, sigma_w = 0.1 w20,
sigma_u = sigma_v = sigma_w/(0.177 + 0.000823 h)^0.4; forming filters
H_u = sigma_u sqrt(2 L_u/(pi V))/(1 + T_u s), H_v,w = sigma sqrt(L/(pi V))(1 + sqrt3 T s)/(1 + T s)^2,
T = L/V, V = max(airspeed, 0.5 m/s) (the transport speed of the frozen field, meaningless at
V -> 0, hence the floor). Axes u, v, w = earth x, y, z (fine for hover and slow cruise).
Discretised EXACTLY per period: the filter states advance by exp(A dt) plus Gaussian noise
with the covariance the continuous white noise builds up over dt, so the samples have the
variance sigma^2 and the correlations sigma_u^2 exp(-V tau/L_u), sigma^2 (1 - V tau/(2L))
exp(-V tau/L) of the continuous process, at any dt. The states, in the disturbance memory
(:data:`DRYDEN_MEMORY`), start from the stationary distribution (drawn on the first period):
no warm-up.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Any

import numpy as np
from numba import njit

from quadcruise.disturbances.part import Part
from quadcruise.disturbances.part import batch_field as _f
from quadcruise.fields import between
from quadcruise.layout import EXT_WX, Row
from quadcruise.sim.fastmath import five_normals, same_period

KNOT = 0.514444  # m/s
FOOT = 0.3048  # m
INTENSITIES = {"light": 15.0 * KNOT, "moderate": 30.0 * KNOT, "severe": 45.0 * KNOT}
AIRSPEED_FLOOR = 0.5  # m/s
_S3 = math.sqrt(3.0)
DRYDEN_MEMORY = Row.of(
    "dryden memory",
    "started",
    "u",
    ("v", 2),
    ("w", 2),
    "coef_dt",
    ("u_coef", 2),
    ("v_coef", 5),
    ("w_coef", 5),
    prefix="DRY_",
)
"""A vehicle's turbulence memory: a started flag, the filters' states (u; v and w, two each;
dimensionless, multiplied by the sigmas on output), the period the coefficients were computed
for [s], and the coefficients: u (e^-a, the noise gain), v and w (:func:`lateral_coefficients`)."""
DRY_STARTED, DRY_U, DRY_V, DRY_W, DRY_COEF_DT, DRY_U_COEF, DRY_V_COEF, DRY_W_COEF = DRYDEN_MEMORY.offsets


# The compiled parts follow the scalar-only rule of quadcruise.sim.fastmath: the caller loads
# rng[0] and the started flag first and stores them last, the normals come from fastmath.five_normals.


@njit(cache=True, error_model="numpy")
def lateral_coefficients(a):
    """Exact discretisation of (1 + sqrt3 T s)/(1 + T s)^2 over a = dt/T, states scaled to the
    stationary covariance [[1/2, 1/4], [1/4, 1/4]]: Phi = e^-a [[1, 0], [a, 1]] and noise of
    covariance Q = int_0^a e^-2u [[1, u], [u, u^2]] du. Returns (e^-a, a, Cholesky of Q)."""
    if a < 1.0:  # series: no cancellation for small a
        i0 = i1 = i2 = 0.0
        term = 1.0  # (-2a)^n / n!
        for n in range(60):
            i0 += term * a / (n + 1)
            i1 += term * a * a / (n + 2)
            i2 += term * a * a * a / (n + 3)
            term *= -2.0 * a / (n + 1)
            if abs(term) < 1e-18:
                break
    else:
        e2 = math.exp(-2.0 * a)
        i0, i1 = 0.5 * (1.0 - e2), 0.25 * (1.0 - e2 * (1.0 + 2.0 * a))
        i2 = 0.25 * (1.0 - e2 * (1.0 + 2.0 * a + 2.0 * a * a))
    l11 = math.sqrt(i0)
    l21 = i1 / l11
    return math.exp(-a), a, l11, l21, math.sqrt(max(i2 - l21 * l21, 0.0))


@njit(cache=True, inline="always", error_model="numpy")
def dryden_step(dt, sigma_u, sigma_v, sigma_w, t_u, t_w, dmem, started, state, ext):
    """Add the Dryden wind at the period's start to ``ext``'s wind, and advance the filters
    (in ``dmem``, laid out as :data:`DRYDEN_MEMORY`) over the period ``dt`` [s]."""
    if started == 0.0:  # first period: draw the stationary start
        n0, n1, n2, n3, n4, state = five_normals(state)
        started, dmem[DRY_U] = 1.0, n0
        dmem[DRY_V], dmem[DRY_V + 1] = n1 / math.sqrt(2.0), math.sqrt(2.0) / 4.0 * n1 + n2 / math.sqrt(8.0)
        dmem[DRY_W], dmem[DRY_W + 1] = n3 / math.sqrt(2.0), math.sqrt(2.0) / 4.0 * n3 + n4 / math.sqrt(8.0)
    n0, n1, n2, n3, n4, state = five_normals(state)
    if not same_period(dmem[DRY_COEF_DT], dt):  # coefficients, cached per period
        a = dt / t_u
        dmem[DRY_COEF_DT], dmem[DRY_U_COEF], dmem[DRY_U_COEF + 1] = dt, math.exp(-a), math.sqrt(-math.expm1(-2.0 * a))
        c = DRY_V_COEF
        dmem[c], dmem[c + 1], dmem[c + 2], dmem[c + 3], dmem[c + 4] = lateral_coefficients(a)
        a = dt / t_w
        c = DRY_W_COEF
        dmem[c], dmem[c + 1], dmem[c + 2], dmem[c + 3], dmem[c + 4] = lateral_coefficients(a)
    ext[EXT_WX] += sigma_u * dmem[DRY_U]
    dmem[DRY_U] = dmem[DRY_U_COEF] * dmem[DRY_U] + dmem[DRY_U_COEF + 1] * n0
    for k in range(2):  # v, then w
        j, c = (DRY_V, DRY_V_COEF) if k == 0 else (DRY_W, DRY_W_COEF)
        na, nb = (n1, n2) if k == 0 else (n3, n4)
        s1, s2, e = dmem[j], dmem[j + 1], dmem[c]
        ext[EXT_WX + 1 + k] += (sigma_v if k == 0 else sigma_w) * (_S3 * s1 + (1.0 - _S3) * s2)
        dmem[j] = e * s1 + dmem[c + 2] * na
        dmem[j + 1] = e * (dmem[c + 1] * s1 + s2) + dmem[c + 3] * na + dmem[c + 4] * nb
    return started, state


@dataclass(frozen=True)
class Turbulence(Part):
    """Dryden turbulence, MIL-F-8785C low altitude; ``w20``, if given, overrides ``intensity``.

    Parameters
    ----------
    intensity : {"light", "moderate", "severe"}
        MIL-F-8785C level: a wind speed at 20 ft of 15, 30 or 45 kt.
    w20 : float or array, optional
        Wind speed at 20 ft [m/s], > 0; replaces ``intensity``'s when given.
    altitude : float or array
        Height above ground h [m], in (0, 304.8) (below 1000 ft, the low-altitude model);
        below 10 ft (3.048 m) it counts as 10 ft.
    airspeed : float or array
        Speed V through the air that carries the frozen turbulence field past the vehicle
        [m/s], >= 0; below 0.5 m/s it counts as 0.5 m/s.
    """

    intensity: str = _f("moderate", "-", "MIL-F-8785C level", "choice", tuple(INTENSITIES))
    w20: Any = _f(None, "m/s", "wind speed at 20 ft", "pos")
    altitude: Any = _f(10.0, "m", "height above ground, low-altitude model", between(0.0, 1000 * FOOT, "()"))
    airspeed: Any = _f(1.0, "m/s", "speed through the air, floor 0.5 m/s", "nonneg")
    name = "dryden"

    def _h(self) -> Any:
        return np.maximum(self.altitude, 10 * FOOT) / FOOT  # ft, 10 ft floor

    def scales(self) -> tuple:
        """(L_u, L_v, L_w) [m].

        Returns
        -------
        tuple of 3 (float or numpy.ndarray)
            The turbulence scale lengths L_u = L_v = h / (0.177 + 0.000823 h)^1.2 and
            L_w = h [m] (h in ft in the formula, with its 10 ft floor); arrays when the
            altitude is per-vehicle.

        Examples
        --------
        >>> [round(float(L), 2) for L in Turbulence(altitude=10.0).scales()]
        [67.37, 67.37, 10.0]
        """
        h = self._h()
        lu = h / (0.177 + 0.000823 * h) ** 1.2 * FOOT
        return lu, lu, h * FOOT

    def sigmas(self) -> tuple:
        """(sigma_u, sigma_v, sigma_w) [m/s].

        Returns
        -------
        tuple of 3 (float or numpy.ndarray)
            The turbulence intensities sigma_w = 0.1 w20 and sigma_u = sigma_v =
            sigma_w / (0.177 + 0.000823 h)^0.4 [m/s]; floats, or arrays when a field is
            per-vehicle.

        Examples
        --------
        >>> [round(s, 3) for s in Turbulence(intensity="light", altitude=10.0).sigmas()]
        [1.457, 1.457, 0.772]
        """
        sw = 0.1 * np.asarray(INTENSITIES[self.intensity] if self.w20 is None else self.w20, dtype=float)
        su = sw / (0.177 + 0.000823 * self._h()) ** 0.4
        return (su, su, sw) if np.ndim(su) else (float(su), float(su), float(sw))

    def time_constants(self) -> tuple:
        """(T_u, T_v, T_w) = L / max(airspeed, 0.5 m/s) [s].

        Returns
        -------
        tuple of 3 (float or numpy.ndarray)
            The forming filters' time constants [s] (:meth:`scales` over the floored
            airspeed).

        Examples
        --------
        >>> [round(float(T), 2) for T in Turbulence(altitude=10.0, airspeed=2.0).time_constants()]
        [33.68, 33.68, 5.0]
        """
        return tuple(L / np.maximum(self.airspeed, AIRSPEED_FLOOR) for L in self.scales())
