"""Disturbances: wind (constant, 1 - cosine gust, Dryden turbulence), rotor loss, external
force and torque, sensor noise; batched (any numeric field may hold one value per vehicle)
and seeded through the engine's per-vehicle generator.

:class:`Environment` hands the engine ONE compiled disturbance with a flat parameter row per
vehicle (absent parts are off by a 0/1 column). Each period [t, t + dt] it writes into ext:
the force (earth frame) and torque (body frame) of :class:`ExternalForce`; the wind (earth
frame) = :class:`ConstantWind` + :class:`Gust` + :class:`Turbulence`, which acts only through
the vehicle's drag -(c1 + c2 |v - w|)(v - w) (the paper's vehicle has none: :func:`with_drag`);
and the rotor effectiveness (:class:`RotorLoss`). t is the period's start; ext is held over it.

- Gust: w = (A/2)(1 - cos(2 pi (t - start)/duration)) for start <= t <= start + duration, else
  0: MIL-F-8785C's 1 - cosine rise (A/2)(1 - cos(pi x/d_m)) with the gust length d_m covered in
  duration/2 (peak A at start + duration/2), then mirrored back to 0 (the full 1 - cosine gust).
- Turbulence: Dryden, MIL-F-8785C low altitude (h in ft, < 1000 ft; below 10 ft taken as 10 ft,
  as MATLAB's Dryden block does; w20 = 15/30/45 kt for light/moderate/severe):
  L_w = h, L_u = L_v = h/(0.177 + 0.000823 h)^1.2, sigma_w = 0.1 w20,
  sigma_u = sigma_v = sigma_w/(0.177 + 0.000823 h)^0.4; forming filters
  H_u = sigma_u sqrt(2 L_u/(pi V))/(1 + T_u s), H_v,w = sigma sqrt(L/(pi V))(1 + sqrt3 T s)/(1 + T s)^2,
  T = L/V, V = max(airspeed, 0.5 m/s) (the transport speed of the frozen field, meaningless at
  V -> 0, hence the floor). Axes u, v, w = earth x, y, z (fine for hover and slow cruise).
  Discretised EXACTLY per period: the filter states advance by exp(A dt) plus Gaussian noise
  with the covariance the continuous white noise builds up over dt, so the samples have the
  variance sigma^2 and the correlations sigma_u^2 exp(-V tau/L_u), sigma^2 (1 - V tau/(2L))
  exp(-V tau/L) of the continuous process, at any dt. The states, in the disturbance memory,
  start from the stationary distribution (drawn on the first period): no warm-up.
- Rotor loss: e_rotor = 1 - fraction from the first period that starts at t >= time.

Examples
--------
>>> import quadcruise as qc
>>> from quadcruise.disturbances import DEFAULT_DRAG, Environment, Gust, Turbulence, parse_wind
>>> env = parse_wind("constant:2,0,0,dryden:light@5/1")
>>> sorted(env.kwargs(3)), env.params(3).shape, env.needs_drag
(['disturbance', 'disturbance_memory', 'disturbance_params'], (3, 25), True)
>>> [round(s, 3) for s in Turbulence(intensity="moderate", altitude=10.0).sigmas()]
[2.915, 2.915, 1.543]
>>> vehicle = qc.Vehicle.paper().replace(**DEFAULT_DRAG)     # wind needs drag to act
>>> res = qc.fly("hover", vehicle=vehicle, n=3, duration=2.0, seed=1, environment=env)
>>> res.ok.tolist(), bool(res.states[0, -1, 0] != res.states[1, -1, 0])
([True, True, True], True)
>>> three = Environment(gust=Gust(amplitude=([1.0, 2.0, 3.0], 0.0, 0.0), start=1.0, duration=2.0))
>>> three.batch_size, three.params()[:, 10].tolist()    # one gust peak per vehicle
(3, [1.0, 2.0, 3.0])
>>> parse_wind("gust:2,0@5+2")
Traceback (most recent call last):
    ...
quadcruise.errors.InputError: wind spec 'gust:2,0@5+2': needs 3 values AX,AY,AZ, got '2,0'
"""

from __future__ import annotations

import dataclasses
import math
import re
import warnings
from dataclasses import dataclass
from typing import Any

import numpy as np
from numba import njit

from quadcruise.errors import InputError
from quadcruise.fields import Validated, between, instance_of, parse_numbers, unit_field
from quadcruise.layout import DISTURBANCE_SIG, EXT_E1, EXT_FX, EXT_WX, PHI, STATE_SIZE, VX, P, X
from quadcruise.model.vehicle import Vehicle
from quadcruise.sim.fastmath import five_normals, same_period

__all__ = [
    "ConstantWind",
    "Gust",
    "Turbulence",
    "RotorLoss",
    "ExternalForce",
    "Environment",
    "SensorNoise",
    "DEFAULT_DRAG",
    "default_drag_text",
    "with_drag",
    "wind_from_name",
    "parse_wind",
    "environment_disturbance",
    "PARAMS_SIZE",
    "MEMORY_SIZE",
]

KNOT = 0.514444  # m/s
FOOT = 0.3048  # m
INTENSITIES = {"light": 15.0 * KNOT, "moderate": 30.0 * KNOT, "severe": 45.0 * KNOT}
AIRSPEED_FLOOR = 0.5  # m/s

#: Drag estimates for a Qball-X4-sized vehicle (assumptions, not measurements): quadratic
#: 0.5 rho Cd A with rho = 1.225 kg/m^3, Cd ~ 1 (bluff frame and cage), A ~ 0.1 m^2 frontal
#: area -> 0.06 N s^2/m^2; linear rotor drag (the induced drag of the rotors, linear in the
#: air-relative velocity: Martin and Salaun, ICRA 2010) ~ 0.3 N s/m, i.e. c1/m ~ 0.09 1/s;
#: an order-of-magnitude guess, not measured on the Qball-X4.
DEFAULT_DRAG = {"drag_linear": 0.3, "drag_quadratic": 0.5 * 1.225 * 1.0 * 0.1}

# parameter row: force 0-2, torque 3-5, constant wind 6-8, gust (on, A xyz, start, duration)
# 9-14, turbulence (on, sigma u v w, T_u, T_w) 15-20, rotor loss (on, rotor 0-3, e, time) 21-24
_GUST, _TURB, _LOSS, PARAMS_SIZE = 9, 15, 21, 25
# memory: started 0, states u 1, v 2-3, w 4-5, cached dt 6, coefficients (e_u, g_u) 7-8,
# v (e, a, l11, l21, l22) 9-13, w 14-18
_MDT, _CU, _CV, _CW, MEMORY_SIZE = 6, 7, 9, 14, 19
_S3 = math.sqrt(3.0)
DT_TOLERANCE = 1e-6
"""The Dryden filters' coefficients are recomputed when the period changes by more than
this fraction. A uniform grid's periods t[k+1] - t[k] differ in their last bits (at 1 kHz
and t = 60 s, by up to 1e-11 relative): an exact comparison would recompute them (two
exponentials, a series, three square roots) in most periods (see docs/performance.md)."""


# --- compiled ---------------------------------------------------------------------------
# The disturbance follows the scalar-only rule of quadcruise.sim.fastmath: rng[0] and dmem[0]
# loaded first and stored last, no trailing if, the normals from fastmath.five_normals.
@njit(cache=True, error_model="numpy")
def _lateral_coefficients(a):
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


@njit(DISTURBANCE_SIG, cache=True, error_model="numpy")
def environment_disturbance(t, dt, x, dp, dmem, rng, ext):
    """The composite disturbance of :class:`Environment` (see the module's formulas).

    Compiled with :data:`quadcruise.layout.DISTURBANCE_SIG`; the engine calls it once per
    control period and holds ``ext`` over the period.

    Parameters
    ----------
    t : float
        Time at the start of the period [s] (the gust's phase, the rotor loss's onset).
    dt : float
        Length of the period [s], > 0 (the turbulence filters' step).
    x : numpy.ndarray
        The true state, STATE_SIZE (16) float64 entries (not read: no part depends on it).
    dp : numpy.ndarray
        The vehicle's parameter row, PARAMS_SIZE (25) float64 entries
        (:meth:`Environment.params`): force (earth frame) [N] and torque (body frame)
        [N m]; steady wind [m/s]; gust (on 0/1, peak A [m/s] x, y, z, start [s], duration
        [s]); turbulence (on, sigma_u, sigma_v, sigma_w [m/s], T_u, T_w [s]); rotor loss
        (on, rotor index 0-3, effectiveness 1 - fraction [-], time [s]).
    dmem : numpy.ndarray
        The vehicle's disturbance memory, MEMORY_SIZE (19) float64 entries, zeros at the
        start of a flight (:meth:`Environment.memory`), updated in place: a started flag,
        the Dryden filters' states (dimensionless, multiplied by the sigmas on output),
        the period the coefficients were computed for [s] and the coefficients.
    rng : numpy.ndarray
        The vehicle's random generator state, (1,) uint64 (:mod:`quadcruise.sim.rng`),
        advanced in place when there is turbulence.
    ext : numpy.ndarray
        Output, EXT_SIZE (13) float64 entries, all written (``EXT_*`` of
        :mod:`quadcruise.layout`): force, earth frame [N]; torque, body frame [N m]; wind
        velocity, earth frame [m/s] (steady + gust + turbulence); each rotor's
        effectiveness [-] (1 healthy).

    Examples
    --------
    >>> import numpy as np
    >>> env = Environment(wind=ConstantWind(velocity=(2.0, 0.0, 0.0)),
    ...                   rotor_loss=RotorLoss(rotor=2, fraction=0.3, time=0.0))
    >>> ext = np.zeros(13)
    >>> environment_disturbance(0.0, 0.001, np.zeros(16), env.params()[0], env.memory()[0],
    ...                         np.zeros(1, np.uint64), ext)
    >>> ext[6:9].tolist(), ext[9:].tolist()                 # wind; rotor 2 at 70 %
    ([2.0, 0.0, 0.0], [1.0, 0.7, 1.0, 1.0])
    """
    state, started = rng[0], dmem[0]  # loaded first, stored last (see the note above)
    for j in range(6):
        ext[EXT_FX + j] = dp[j]
    for j in range(3):
        ext[EXT_WX + j] = dp[6 + j]
    if dp[_GUST] != 0.0:
        s = t - dp[_GUST + 4]
        if 0.0 <= s <= dp[_GUST + 5]:
            k = 0.5 * (1.0 - math.cos(2.0 * math.pi * s / dp[_GUST + 5]))
            for j in range(3):
                ext[EXT_WX + j] += k * dp[_GUST + 1 + j]
    if dp[_TURB] != 0.0:  # Dryden: output at t, then advance the filters to t + dt
        if started == 0.0:  # first period: draw the stationary start
            n0, n1, n2, n3, n4, state = five_normals(state)
            started, dmem[1] = 1.0, n0
            dmem[2], dmem[3] = n1 / math.sqrt(2.0), math.sqrt(2.0) / 4.0 * n1 + n2 / math.sqrt(8.0)
            dmem[4], dmem[5] = n3 / math.sqrt(2.0), math.sqrt(2.0) / 4.0 * n3 + n4 / math.sqrt(8.0)
        n0, n1, n2, n3, n4, state = five_normals(state)
        if not same_period(dmem[_MDT], dt):  # coefficients, cached per period
            a = dt / dp[_TURB + 4]
            dmem[_MDT], dmem[_CU], dmem[_CU + 1] = dt, math.exp(-a), math.sqrt(-math.expm1(-2.0 * a))
            dmem[_CV], dmem[_CV + 1], dmem[_CV + 2], dmem[_CV + 3], dmem[_CV + 4] = _lateral_coefficients(a)
            a = dt / dp[_TURB + 5]
            dmem[_CW], dmem[_CW + 1], dmem[_CW + 2], dmem[_CW + 3], dmem[_CW + 4] = _lateral_coefficients(a)
        ext[EXT_WX] += dp[_TURB + 1] * dmem[1]
        dmem[1] = dmem[_CU] * dmem[1] + dmem[_CU + 1] * n0
        for k in range(2):  # v (states 2, 3), w (4, 5)
            j, c = 2 + 2 * k, _CV + 5 * k
            na, nb = (n1, n2) if k == 0 else (n3, n4)
            s1, s2, e = dmem[j], dmem[j + 1], dmem[c]
            ext[EXT_WX + 1 + k] += dp[_TURB + 2 + k] * (_S3 * s1 + (1.0 - _S3) * s2)
            dmem[j] = e * s1 + dmem[c + 2] * na
            dmem[j + 1] = e * (dmem[c + 1] * s1 + s2) + dmem[c + 3] * na + dmem[c + 4] * nb
    lost = dp[_LOSS] != 0.0 and t >= dp[_LOSS + 3] - 1e-9 * (1.0 + abs(dp[_LOSS + 3]))
    for j in range(4):
        ext[EXT_E1 + j] = dp[_LOSS + 2] if lost and dp[_LOSS + 1] == j else 1.0
    rng[0], dmem[0] = state, started


# --- Python side -------------------------------------------------------------------------
def _f(*args: Any, **kw: Any):
    """A field with unit, doc and check (:func:`quadcruise.fields.unit_field`) that may hold one
    value per vehicle."""
    return unit_field(*args, batch=True, **kw)


@dataclass(frozen=True)
class _Part(Validated):
    """Batch size and ``to_dict`` shared by the models; validation and ``units()`` come from
    :mod:`quadcruise.fields`. Each numeric field is a number or a 1-D array with one value per
    vehicle; a vector field is (x, y, z) of such, or an (N, 3) numpy array."""

    name = "part"

    def sizes(self) -> set:
        """Lengths of the per-vehicle arrays among the fields."""
        vals = [getattr(self, f.name) for f in dataclasses.fields(self)]
        return {u.shape[0] for v in vals for u in (v if isinstance(v, tuple) else (v,)) if isinstance(u, np.ndarray)}

    @staticmethod
    def one_size(sizes: set, what: str) -> int | None:
        """The one batch length among ``sizes`` (None if empty); InputError if they differ."""
        if len(sizes) > 1:
            raise InputError(f"{what} fields have different batch lengths {sorted(sizes)}")
        return next(iter(sizes), None)

    def to_dict(self) -> dict:
        def plain(v):
            return [plain(u) for u in v] if isinstance(v, tuple) else v.tolist() if isinstance(v, np.ndarray) else v

        return {"model": self.name, **{f.name: plain(getattr(self, f.name)) for f in dataclasses.fields(self)}}


@dataclass(frozen=True)
class ConstantWind(_Part):
    """A steady wind (earth frame).

    Parameters
    ----------
    velocity : sequence of 3 (float or array), or (N, 3) array
        Wind velocity (x, y, z), earth frame, z up [m/s]; each component a number or one
        value per vehicle.

    Examples
    --------
    >>> ConstantWind(velocity=(3.0, 0.0, 0.0)).to_dict()
    {'model': 'constant', 'velocity': [3.0, 0.0, 0.0]}
    """

    velocity: Any = _f((0.0, 0.0, 0.0), "m/s", "wind velocity (x, y, z)", "vec")
    name = "constant"


@dataclass(frozen=True)
class Gust(_Part):
    """A full "1 - cosine" gust: (A/2)(1 - cos(2 pi (t - start)/duration)) over the duration.

    Parameters
    ----------
    amplitude : sequence of 3 (float or array), or (N, 3) array
        Peak wind A (x, y, z), earth frame [m/s], reached at start + duration / 2.
    start : float or array
        Time the gust begins [s], >= 0.
    duration : float or array
        Time from start until the wind is back to 0 [s], > 0.

    Examples
    --------
    >>> Gust(amplitude=(2.0, 0.0, 0.0), start=5.0, duration=2.0).start
    5.0
    """

    amplitude: Any = _f((1.0, 0.0, 0.0), "m/s", "gust peak (x, y, z)", "vec")
    start: Any = _f(1.0, "s", "gust start", "nonneg")
    duration: Any = _f(1.0, "s", "gust duration", "pos")
    name = "gust"


@dataclass(frozen=True)
class Turbulence(_Part):
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


@dataclass(frozen=True)
class RotorLoss(_Part):
    """From ``time`` on, rotor ``rotor`` gives 1 - ``fraction`` of its thrust.

    Parameters
    ----------
    rotor : int or array of int
        The rotor that loses thrust, 1 to 4.
    fraction : float or array
        Fraction of its thrust lost [-], in [0, 1].
    time : float or array
        Time of the loss [s], >= 0: it acts from the first control period that starts at
        or after it.
    """

    rotor: Any = _f(1, "-", "rotor number", between(1, 4, whole=True))
    fraction: Any = _f(0.3, "-", "fraction of thrust lost", "frac")
    time: Any = _f(5.0, "s", "time of the loss", "nonneg")
    name = "loss"


@dataclass(frozen=True)
class ExternalForce(_Part):
    """A constant force (earth frame) and torque (body frame).

    Parameters
    ----------
    force : sequence of 3 (float or array), or (N, 3) array
        Force (x, y, z), earth frame, z up [N].
    torque : sequence of 3 (float or array), or (N, 3) array
        Torque about the body axes (x, y, z) [N m].
    """

    force: Any = _f((0.0, 0.0, 0.0), "N", "force (x, y, z)", "vec")
    torque: Any = _f((0.0, 0.0, 0.0), "N m", "torque (x, y, z)", "vec")
    name = "force"


_SLOTS = {"wind": ConstantWind, "gust": Gust, "turbulence": Turbulence, "rotor_loss": RotorLoss, "force": ExternalForce}


def _columns(n: int, *values: Any) -> np.ndarray:
    return np.column_stack(np.broadcast_arrays(*values, np.zeros(n))[:-1])


@dataclass(frozen=True)
class Environment(Validated):
    """The disturbances a flight meets, each part optional: ``fly(..., environment=env)``.

    Parameters
    ----------
    wind : ConstantWind, optional
        Steady wind.
    gust : Gust, optional
        A 1 - cosine gust, added to the wind.
    turbulence : Turbulence, optional
        Dryden turbulence, added to the wind.
    rotor_loss : RotorLoss, optional
        The loss of part of one rotor's thrust.
    force : ExternalForce, optional
        A constant external force and torque.

    Examples
    --------
    >>> Environment(gust=Gust()).units()["gust.duration"]
    's'
    """

    wind: ConstantWind | None = unit_field(None, "-", "steady wind", instance_of(ConstantWind))
    gust: Gust | None = unit_field(None, "-", "1 - cosine gust", instance_of(Gust))
    turbulence: Turbulence | None = unit_field(None, "-", "Dryden turbulence", instance_of(Turbulence))
    rotor_loss: RotorLoss | None = unit_field(None, "-", "loss of a rotor's thrust", instance_of(RotorLoss))
    force: ExternalForce | None = unit_field(None, "-", "external force and torque", instance_of(ExternalForce))
    name = "environment"

    @classmethod
    def from_parts(cls, *parts: _Part) -> Environment:
        """Each part into its slot (one of each kind).

        Parameters
        ----------
        *parts : ConstantWind, Gust, Turbulence, RotorLoss or ExternalForce
            The parts, in any order, at most one of each kind.

        Returns
        -------
        Environment
            The parts in their slots, the others empty.

        Raises
        ------
        InputError
            A part of another type, or a second part of one kind.

        Examples
        --------
        >>> sorted(Environment.from_parts(Gust(), ConstantWind()).parts)
        ['gust', 'wind']
        """
        slots: dict = {}
        for part in parts:
            slot = next((s for s, c in _SLOTS.items() if isinstance(part, c)), None)
            if slot is None or slot in slots:
                raise InputError(f"{'unknown' if slot is None else 'a second'} disturbance part {part!r}")
            slots[slot] = part
        return cls(**slots)

    @classmethod
    def from_dict(cls, d: dict) -> Environment:
        """Inverse of :meth:`to_dict`.

        Parameters
        ----------
        d : dict
            Slot name -> a part's dict (with its ``model`` key, which is ignored) or None.

        Returns
        -------
        Environment

        Examples
        --------
        >>> env = Environment(gust=Gust(start=2.0))
        >>> Environment.from_dict(env.to_dict()).gust.start
        2.0
        """
        return cls(**{k: v and _SLOTS[k](**{a: b for a, b in v.items() if a != "model"}) for k, v in d.items()})

    def to_dict(self) -> dict:
        """Plain values of every slot (for result bundles and :meth:`from_dict`).

        Returns
        -------
        dict
            Slot name (``wind``, ``gust``, ``turbulence``, ``rotor_loss``, ``force``) -> the
            part's fields as plain values with its ``model`` name, or None if empty.
        """
        return {s: getattr(self, s) and getattr(self, s).to_dict() for s in _SLOTS}

    @property
    def parts(self) -> dict:
        """The parts present, by slot (empty: still air)."""
        return {s: getattr(self, s) for s in _SLOTS if getattr(self, s) is not None}

    @property
    def function(self):
        """The compiled composite disturbance (``DISTURBANCE_SIG``)."""
        return environment_disturbance

    @property
    def needs_drag(self) -> bool:
        """True if there is wind: it acts only through the vehicle's drag."""
        return any(getattr(self, s) is not None for s in ("wind", "gust", "turbulence"))

    @property
    def batch_size(self) -> int | None:
        """N if a field is per-vehicle, else None."""
        return _Part.one_size(set().union(*(p.sizes() for p in self.parts.values())), "disturbance")

    def params(self, n: int | None = None) -> np.ndarray:
        """(N, PARAMS_SIZE) float64 parameter rows; per-vehicle arrays must have N values.

        Parameters
        ----------
        n : int, optional
            Number of vehicles N; by default the batch size (1 if no field is per-vehicle).

        Returns
        -------
        numpy.ndarray
            (N, PARAMS_SIZE) float64: the ``dp`` rows of :func:`environment_disturbance`
            (absent parts are zeros, their on-column 0).

        Raises
        ------
        InputError
            Per-vehicle fields whose length is not n.
        """
        size = self.batch_size
        n = (size or 1) if n is None else int(n)
        if size is not None and size != n:
            raise InputError(f"disturbance fields have {size} values but {n} vehicles were asked for")
        out = np.zeros((n, PARAMS_SIZE))
        if self.force is not None:
            out[:, 0:6] = _columns(n, *self.force.force, *self.force.torque)
        if self.wind is not None:
            out[:, 6:9] = _columns(n, *self.wind.velocity)
        if (g := self.gust) is not None:
            out[:, _GUST : _GUST + 6] = _columns(n, 1.0, *g.amplitude, g.start, g.duration)
        if (tb := self.turbulence) is not None:
            tu, _, tw = tb.time_constants()
            out[:, _TURB : _TURB + 6] = _columns(n, 1.0, *tb.sigmas(), tu, tw)
        if (r := self.rotor_loss) is not None:
            out[:, _LOSS : _LOSS + 4] = _columns(n, 1.0, np.subtract(r.rotor, 1), np.subtract(1, r.fraction), r.time)
        return out

    def memory(self, n: int | None = None) -> np.ndarray:
        """(N, MEMORY_SIZE) zeros: the turbulence filters start on the first period.

        Parameters
        ----------
        n : int, optional
            Number of vehicles N; by default the batch size (1 if no field is per-vehicle).

        Returns
        -------
        numpy.ndarray
            (N, MEMORY_SIZE) float64 zeros: the ``dmem`` rows of
            :func:`environment_disturbance`.
        """
        return np.zeros(((self.batch_size or 1) if n is None else int(n), MEMORY_SIZE))

    def kwargs(self, n: int | None = None) -> dict:
        """``disturbance``, ``disturbance_params`` and ``disturbance_memory`` for simulate/fly
        ((N, ...) rows; one row each, which the engine gives every vehicle, if n is None and
        no field is per-vehicle).

        Parameters
        ----------
        n : int, optional
            Number of vehicles N.

        Returns
        -------
        dict
            ``disturbance``: the compiled function; ``disturbance_params``: :meth:`params`;
            ``disturbance_memory``: :meth:`memory` (each a single row when n is None and no
            field is per-vehicle).
        """
        one = n is None and self.batch_size is None
        dp, dm = self.params(n), self.memory(n)
        return {
            "disturbance": self.function,
            "disturbance_params": dp[0] if one else dp,
            "disturbance_memory": dm[0] if one else dm,
        }


@dataclass(frozen=True)
class SensorNoise(_Part):
    """White noise on what the controller sees, and a delay (a whole number of periods).

    Parameters
    ----------
    position_std : float or array
        Standard deviation of the noise on x, y and z [m], >= 0.
    velocity_std : float or array
        On the velocity [m/s], >= 0.
    angle_std : float or array
        On roll, pitch and yaw [rad], >= 0.
    rate_std : float or array
        On the body rates p, q, r [rad/s], >= 0.
    delay : float
        Sensor delay [s], >= 0, a whole number of control periods, the same for every
        vehicle.
    """

    position_std: Any = _f(0.0, "m", "position noise std", "nonneg")
    velocity_std: Any = _f(0.0, "m/s", "velocity noise std", "nonneg")
    angle_std: Any = _f(0.0, "rad", "angle noise std", "nonneg")
    rate_std: Any = _f(0.0, "rad/s", "body rate noise std", "nonneg")
    delay: Any = _f(0.0, "s", "sensor delay", "nonneg")
    name = "sensor"

    def std_vector(self) -> np.ndarray:
        """(16,) standard deviations per state ((N, 16) if a field is per-vehicle); rotors 0.

        Returns
        -------
        numpy.ndarray
            (STATE_SIZE,) or (N, STATE_SIZE) float64, in the state's units ([m], [m/s],
            [rad], [rad/s]); 0 for the rotor thrusts.

        Examples
        --------
        >>> SensorNoise(position_std=0.01).std_vector()[:4].tolist()
        [0.01, 0.01, 0.01, 0.0]
        """
        size = self.one_size(self.sizes(), "sensor")
        out = np.zeros((size or 1, STATE_SIZE))
        for name, j in (("position_std", X), ("velocity_std", VX), ("angle_std", PHI), ("rate_std", P)):
            out[:, j : j + 3] = np.asarray(getattr(self, name))[..., None]
        return out if size else out[0]

    def delay_periods(self, dt: float) -> int:
        """The delay in control periods; it must be a whole number of dt (to 1e-9 s).

        Parameters
        ----------
        dt : float
            Control period [s], > 0.

        Returns
        -------
        int
            delay / dt.

        Raises
        ------
        InputError
            A per-vehicle delay, or one that is not a whole number of periods.

        Examples
        --------
        >>> SensorNoise(delay=0.005).delay_periods(0.001)
        5
        """
        if np.ndim(self.delay):
            raise InputError("sensor field 'delay' must be one number for the whole batch")
        k = round(self.delay / dt)
        if abs(k * dt - self.delay) > 1e-9:
            raise InputError(f"sensor field 'delay' ({self.delay:g} s) is not a whole number of dt ({dt:g} s) periods")
        return int(k)

    def check_fits(self, duration: float) -> None:
        """Refuse a delay longer than the flight (its history buffer would be allocated first).

        Parameters
        ----------
        duration : float
            Flight time [s].

        Raises
        ------
        InputError
            Saying the delay and the flight time.

        Examples
        --------
        >>> SensorNoise(delay=30.0).check_fits(20.0)
        Traceback (most recent call last):
            ...
        quadcruise.errors.InputError: sensor field 'delay' (30 s) is longer than the flight (20 s)
        """
        if np.max(self.delay) > duration:
            raise InputError(
                f"sensor field 'delay' ({np.max(self.delay):g} s) is longer than the flight ({float(duration):g} s)"
            )

    def kwargs(self, dt: float) -> dict:
        """``sensor_std`` and ``sensor_delay`` for simulate/fly.

        Parameters
        ----------
        dt : float
            Control period [s], > 0.

        Returns
        -------
        dict
            ``sensor_std``: :meth:`std_vector`; ``sensor_delay``: :meth:`delay_periods`.
        """
        return {"sensor_std": self.std_vector(), "sensor_delay": self.delay_periods(dt)}


def with_drag(vehicle: Vehicle, *, warn: bool = False) -> Vehicle:
    """The vehicle with :data:`DEFAULT_DRAG` where both its drag coefficients are zero.

    Wind acts on a vehicle only through its drag, and the paper's vehicle has none. Calling
    this is asking for the default drag, so it says nothing; a workflow that gives the drag
    on its own (a scenario or a sweep with wind on a vehicle without drag) passes
    ``warn=True``, and the warning says what the vehicles fly with.

    Parameters
    ----------
    vehicle : Vehicle
        The vehicle, batched or not.
    warn : bool
        Warn (UserWarning) when a vehicle is given the default drag.

    Returns
    -------
    Vehicle
        The same vehicle if every one of its vehicles has some drag; else a copy with
        ``drag_linear`` [N s/m] and ``drag_quadratic`` [N s^2/m^2] of :data:`DEFAULT_DRAG`
        for the vehicles that had none.

    Examples
    --------
    >>> from quadcruise.model.vehicle import Vehicle
    >>> with_drag(Vehicle.paper()).drag_linear
    0.3
    >>> with_drag(Vehicle.paper().replace(drag_linear=0.1)).drag_quadratic
    0.0
    """
    c1, c2 = np.asarray(vehicle.drag_linear), np.asarray(vehicle.drag_quadratic)
    bare = (c1 == 0) & (c2 == 0)
    if not np.any(bare):
        return vehicle
    if warn:
        warnings.warn(default_drag_text(int(np.count_nonzero(bare)), int(bare.size)), stacklevel=2)
    new = {k: np.where(bare, v, c) for (k, v), c in zip(DEFAULT_DRAG.items(), (c1, c2), strict=False)}
    return vehicle.replace(**{k: float(v) if v.ndim == 0 else v for k, v in new.items()})


def default_drag_text(count: int = 1, total: int = 1) -> str:
    """What :func:`with_drag` does to a vehicle without drag, in one line.

    Parameters
    ----------
    count, total : int
        How many vehicles had no drag, of how many.

    Returns
    -------
    str

    Examples
    --------
    >>> print(default_drag_text())
    the vehicle has no drag, and wind acts only through drag: it flies with DEFAULT_DRAG, drag_linear 0.3 N s/m \
and drag_quadratic 0.06125 N s^2/m^2 (estimates; give the vehicle's own drag_linear and drag_quadratic to choose)
    """
    which = "the vehicle has no drag" if total == 1 else f"{count:,} of {total:,} vehicles have no drag"
    return (
        f"{which}, and wind acts only through drag: {'it flies' if count == 1 else 'they fly'} with "
        f"DEFAULT_DRAG, drag_linear {DEFAULT_DRAG['drag_linear']:g} N s/m and drag_quadratic "
        f"{DEFAULT_DRAG['drag_quadratic']:.4g} N s^2/m^2 (estimates; give the vehicle's own drag_linear and "
        "drag_quadratic to choose)"
    )


_NAMES = {
    "constant": ConstantWind,
    "wind": ConstantWind,
    "gust": Gust,
    "dryden": Turbulence,
    "turbulence": Turbulence,
    "loss": RotorLoss,
    "rotor_loss": RotorLoss,
    "force": ExternalForce,
}


def wind_from_name(name: str, **kw: Any) -> _Part:
    """A part by name (``constant``/``wind``, ``gust``, ``dryden``/``turbulence``,
    ``loss``/``rotor_loss``, ``force``) with its fields as keywords.

    Parameters
    ----------
    name : str
        The part's name, in any case.
    **kw
        Its fields, in their units (see each class).

    Returns
    -------
    ConstantWind, Gust, Turbulence, RotorLoss or ExternalForce

    Raises
    ------
    InputError
        An unknown name or field, or a bad value.

    Examples
    --------
    >>> wind_from_name("Gust", start=2.0).duration
    1.0
    """
    cls = _NAMES.get(str(name).lower())
    if cls is None:
        raise InputError(f"unknown disturbance {name!r}; choose one of {', '.join(_NAMES)}")
    try:
        return cls(**kw)
    except TypeError as e:
        raise InputError(f"{name}: {e}") from None


def _floats(text: str, k: int, what: str) -> list:
    return parse_numbers(text, what, k)


def _part(text: str) -> _Part:
    name, _, body = text.partition(":")
    cls, body = _NAMES.get(name.strip().lower()), re.sub(r"\s+", "", body)
    first, at, rest = body.partition("@")
    if cls is None:
        raise InputError(f"unknown model {name.strip()!r}; choose one of {', '.join(_NAMES)}")
    if cls is ConstantWind:
        return ConstantWind(velocity=_floats(body, 3, "WX,WY,WZ"))
    if cls is Gust:
        start, plus, dur = rest.partition("+")
        if not plus:
            raise InputError("expected gust:AX,AY,AZ@START+DURATION")
        return Gust(_floats(first, 3, "AX,AY,AZ"), _floats(start, 1, "START")[0], _floats(dur, 1, "DURATION")[0])
    if cls is Turbulence:
        alt, _, speed = rest.partition("/")
        kw: dict = (
            {"intensity": first.lower()}
            if first.lower() in INTENSITIES
            else {"w20": _floats(first, 1, "LEVEL (light, moderate, severe or w20 m/s)")[0]}
        )
        return Turbulence(**kw, **{k: _floats(v, 1, k)[0] for k, v in (("altitude", alt), ("airspeed", speed)) if v})
    if cls is RotorLoss:
        if not at:
            raise InputError("expected loss:ROTOR,FRACTION@TIME")
        return RotorLoss(*_floats(first, 2, "ROTOR,FRACTION"), _floats(rest, 1, "TIME")[0])
    force, _, torque = body.partition("/")
    return ExternalForce(_floats(force, 3, "FX,FY,FZ"), _floats(torque, 3, "TX,TY,TZ") if torque else (0.0, 0.0, 0.0))


def parse_wind(text: str) -> Environment:
    """An :class:`Environment` from a command-line spec: parts separated by ``,`` ``;`` or spaces.

    Grammar (SI units; each kind at most once; ``none`` or ``calm``: still air)::

        constant:WX,WY,WZ                  steady wind [m/s]                   (or wind:)
        gust:AX,AY,AZ@START+DURATION       1 - cosine gust [m/s, s, s]
        dryden:LEVEL[@ALTITUDE[/AIRSPEED]] LEVEL light|moderate|severe or w20 [m/s];
                                           altitude [m] (10), airspeed [m/s] (1)  (or turbulence:)
        loss:ROTOR,FRACTION@TIME           rotor 1-4 loses FRACTION of its thrust at TIME [s]
        force:FX,FY,FZ[/TX,TY,TZ]          force [N] (earth frame), torque [N m] (body frame)

    e.g. ``constant:3,0,0,gust:2,0,0@5+2,dryden:moderate@10``. Bad input raises a one-line
    :class:`InputError` quoting the part.

    Parameters
    ----------
    text : str
        The spec, in the grammar above.

    Returns
    -------
    Environment
        The parts in their slots (empty for ``none``, ``calm`` or a blank spec).

    Raises
    ------
    InputError
        An unknown model, a malformed or out-of-range value, or a kind given twice.

    Examples
    --------
    >>> sorted(parse_wind("constant:3,0,0 gust:2,0,0@5+2").parts)
    ['gust', 'wind']
    >>> parse_wind("calm").parts
    {}
    """
    text = str(text).strip()
    if text.lower() in ("", "none", "calm"):
        return Environment()
    parts = []
    for piece in filter(None, re.split(r"[,;\s]+(?=[A-Za-z_]+\s*:)", text)):
        try:
            parts.append(_part(piece))
        except InputError as e:
            raise InputError(f"wind spec {piece!r}: {e}") from None
    return Environment.from_parts(*parts)
