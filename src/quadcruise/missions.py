"""Missions: the reference a vehicle is asked to follow, as a function of time.

At time t a mission writes position, velocity and acceleration (earth frame, z up), yaw and
yaw rate into a ``REF_SIZE`` vector laid out as in :mod:`quadcruise.layout`. Each kind is one
compiled function with the signature ``MISSION_SIG`` (``mission(t, mp, ref)``), so the engine
takes it as a first-class ``MissionType`` and its cache serves every kind, a user's own too.
``mp`` is the mission's flat parameter vector (one row per vehicle in a batch); its columns
are listed in each class's ``columns``. Missions are meant for t >= 0.

Kinds and defaults (the paper, Section IV, gives no numbers for its Figs 4-6, so the defaults
are sized for the Qball-X4 of Table I in an indoor arena: a few metres, tens of seconds):

- :class:`Hover` at (0, 0, 1 m): 1 m is a usual indoor flight height for the Qball-X4.
- :class:`Step` of 1 m in x at t = 1 s from hover at (0, 0, 1 m): a unit step gives rise time,
  settling time and overshoot directly; the 1 s of hover before it shows the initial state.
- :class:`Circle` of radius 2 m, period 20 s, at 1 m, centred on the origin, starting at
  (R, 0), counter-clockwise: the paper's search-and-rescue pattern (Fig 4). Cruise speed
  2 pi R / T = 0.63 m/s and centripetal acceleration 0.20 m/s^2 (about 1.2 deg of tilt) keep it
  a gentle cruise. A vehicle at rest at the origin sees a step of R in x at t = 0: that
  transient is what the paper's rise/settling/overshoot numbers measure. ``ramp_time`` > 0
  ramps the angular rate smoothly (C2 reference) from 0; afterwards the phase lags the
  unramped circle by omega * ramp_time / 2.
- :class:`Square` of side 4 m at 0.5 m/s (8 s per leg, 32 s per lap) at 1 m: the paper's
  mapping pattern (Fig 6), of the same size and speed as the circle. The first corner is at
  ``corner`` (default the origin, where the vehicle starts, so there is no position step) and
  the legs run +x, +y, -x, -y (``direction=-1`` mirrors y: +x, -y, -x, +y), dwelling ``dwell``
  seconds at each corner before leaving it. The reference is only C0 at the corners: the
  velocity jumps and the acceleration is zero on the legs (the corner impulses are left out).
  It repeats every lap.

Examples
--------
>>> from quadcruise.missions import Circle, mission_from_name
>>> c = Circle()
>>> c.params()[:3]                       # radius, omega = 2 pi / period, altitude
array([2.        , 0.31415927, 1.        ])
>>> ref = c.reference([0.0, 5.0])          # quarter period: at (0, R), moving in -x
>>> ref[1, :3].round(6) + 0.0, ref[1, 3:5].round(4) + 0.0
(array([0., 2., 1.]), array([-0.6283,  0.    ]))
>>> mission_from_name("square", side=2.0).to_dict()["side"]
2.0
>>> Circle(radius=0.0)
Traceback (most recent call last):
    ...
quadcruise.errors.InputError: circle field 'radius' (circle radius, m) must be > 0, got 0.0
"""

from __future__ import annotations

import dataclasses
import math
from dataclasses import dataclass, field
from typing import Any, ClassVar, Sequence

import numpy as np
from numba import njit, types

from .errors import InputError
from .layout import (
    MissionType, REF_PSI, REF_SIZE, REF_VX, REF_VY, REF_X, REF_Y, REF_Z,
    REF_AX, REF_AY,
)
from .params import shared_default

__all__ = ["Mission", "Hover", "Step", "Circle", "Square", "mission_from_name",
           "mission_from_dict", "stack_params", "MISSIONS"]

_AXES = {"x": REF_X, "y": REF_Y, "z": REF_Z, "yaw": REF_PSI}


# --- compiled references (scalar code, no allocation; error_model="numpy" drops the
# zero-division checks, the dataclasses having ruled zero divisors out). Each compiles
# (or loads from numba's cache) the first time a flight passes it to the engine, as a
# function with MISSION_SIG; a signature in the decorator would compile every mission
# when the package is imported (about 2 s of a cold start for missions not flown). -----
@njit(cache=True)
def _clear(ref):
    for i in range(REF_SIZE):
        ref[i] = 0.0


@njit(cache=True, error_model="numpy")
def hover_ref(t, mp, ref):
    """mp = (x, y, z, yaw): a constant point."""
    _clear(ref)
    ref[REF_X], ref[REF_Y], ref[REF_Z], ref[REF_PSI] = mp[0], mp[1], mp[2], mp[3]


@njit(cache=True, error_model="numpy")
def step_ref(t, mp, ref):
    """mp = (x, y, z, yaw, column, size, time): ref[column] += size from t >= time."""
    _clear(ref)
    ref[REF_X], ref[REF_Y], ref[REF_Z], ref[REF_PSI] = mp[0], mp[1], mp[2], mp[3]
    if t >= mp[6]:
        ref[int(mp[4])] += mp[5]


@njit(cache=True, error_model="numpy")
def circle_ref(t, mp, ref):
    """mp = (radius, omega, altitude, start_angle, cx, cy, yaw, ramp_time)."""
    radius, omega, ramp = mp[0], mp[1], mp[7]
    s, rate, drate = t, 1.0, 0.0          # phase time s(t) and its derivatives
    if ramp > 0.0:
        u = t / ramp
        if u <= 0.0:
            s, rate = 0.0, 0.0
        elif u < 1.0:                      # rate = smoothstep(u), s = its integral
            s = ramp * u * u * u * (1.0 - 0.5 * u)
            rate = u * u * (3.0 - 2.0 * u)
            drate = 6.0 * u * (1.0 - u) / ramp
        else:
            s = t - 0.5 * ramp
    a = mp[3] + omega * s
    ad, add = omega * rate, omega * drate
    c, sn = math.cos(a), math.sin(a)
    _clear(ref)
    ref[REF_X] = mp[4] + radius * c
    ref[REF_Y] = mp[5] + radius * sn
    ref[REF_Z] = mp[2]
    ref[REF_VX] = -radius * ad * sn
    ref[REF_VY] = radius * ad * c
    ref[REF_AX] = -radius * (add * sn + ad * ad * c)
    ref[REF_AY] = radius * (add * c - ad * ad * sn)
    ref[REF_PSI] = mp[6]


@njit(cache=True, error_model="numpy")
def square_ref(t, mp, ref):
    """mp = (side, speed, altitude, x0, y0, direction, dwell, yaw)."""
    side, speed, sgn, dwell = mp[0], mp[1], mp[5], mp[6]
    seg = dwell + side / speed            # one corner's dwell plus one leg
    lap = 4.0 * seg
    tau = t - lap * math.floor(t / lap)
    k = min(int(tau / seg), 3)
    s = tau - k * seg
    # corner k and the unit vector of leg k (y mirrored by direction)
    cx, cy = side * (0.0, 1.0, 1.0, 0.0)[k], side * (0.0, 0.0, 1.0, 1.0)[k]
    dx, dy = (1.0, 0.0, -1.0, 0.0)[k], (0.0, 1.0, 0.0, -1.0)[k]
    _clear(ref)
    moved = s - dwell                     # the leg is [departure, arrival): v jumps at corners
    if moved >= 0.0:
        ref[REF_VX], ref[REF_VY] = dx * speed, sgn * dy * speed
    else:
        moved = 0.0
    ref[REF_X] = mp[3] + cx + dx * speed * moved
    ref[REF_Y] = mp[4] + sgn * (cy + dy * speed * moved)
    ref[REF_Z] = mp[2]
    ref[REF_PSI] = mp[7]


@njit(types.void(MissionType, types.float64[::1], types.float64[::1], types.float64[:, ::1]),
      cache=True)
def _evaluate(fn, ts, mp, out):
    for i in range(ts.shape[0]):
        fn(ts[i], mp, out[i])


# --- Python side -----------------------------------------------------------------------
def _f(default: Any, unit: str, doc: str, check: str = "real", choices: tuple = ()):
    """A field with its unit and check: real, pos (> 0), nonneg (>= 0), sign, pair, choice
    (one of ``choices``) or custom (the subclass checks it)."""
    return field(default=default, metadata={"unit": unit, "doc": doc, "check": check, "choices": choices})


def _number(label: str, value: Any) -> float:
    if isinstance(value, bool) or not isinstance(value, (int, float, np.integer, np.floating)):
        raise InputError(f"{label} must be a number, got {value!r}")
    if not math.isfinite(value):
        raise InputError(f"{label} must be finite, got {float(value)!r}")
    return float(value)


@dataclass(frozen=True)
class Mission:
    """Shared code of every mission kind: validation, ``params``, ``reference``, ``to_dict``.

    A subclass sets ``name``, ``columns`` (names of the mp entries), ``function`` (the
    compiled reference, as a staticmethod) and ``_row()`` (the mp entries in order).
    """

    name: ClassVar[str] = ""
    columns: ClassVar[tuple] = ()

    def __post_init__(self) -> None:
        for f in dataclasses.fields(self):
            value, check = getattr(self, f.name), f.metadata["check"]
            label = f"{self.name} field '{f.name}' ({f.metadata['doc']}, {f.metadata['unit']})"
            if check == "custom":
                continue
            if check == "choice":
                if value not in f.metadata["choices"]:
                    raise InputError(f"{label} must be one of {', '.join(f.metadata['choices'])}, got {value!r}")
                continue
            if check == "pair":
                if isinstance(value, (str, bytes)) or np.ndim(value) != 1 or len(value) != 2:
                    raise InputError(f"{label} must be a pair of numbers, got {value!r}")
                object.__setattr__(self, f.name, tuple(_number(label, v) for v in value))
                continue
            num = _number(label, value)
            if (check == "pos" and num <= 0) or (check == "nonneg" and num < 0):
                raise InputError(f"{label} must be {'>' if check == 'pos' else '>='} 0, got {num!r}")
            if check == "sign" and num not in (1.0, -1.0):
                raise InputError(f"{label} must be +1 or -1, got {value!r}")
            object.__setattr__(self, f.name, int(num) if check == "sign" else num)

    def _row(self) -> tuple:
        raise NotImplementedError

    @property
    def duration(self) -> float:
        """The default flight time [s]: 5 s here; one lap, the step and 10 s after it, or
        the last waypoint and a settling time in the kinds that know better."""
        return 5.0

    def params(self) -> np.ndarray:
        """The mission's parameter vector mp (float64, C-contiguous), laid out as ``columns``."""
        return np.ascontiguousarray(self._row(), dtype=np.float64)

    def reference(self, t: Any) -> np.ndarray:
        """The reference at times ``t`` [s], shape (len(t), REF_SIZE), from the compiled function."""
        ts = np.array(np.atleast_1d(t), dtype=np.float64)    # a writable C-ordered copy
        if ts.ndim != 1 or not np.all(np.isfinite(ts)):
            raise InputError("mission reference times must be a 1-D array of finite numbers")
        out = np.empty((ts.shape[0], REF_SIZE))
        _evaluate(self.function, ts, self.params(), out)
        return out

    def replace(self, **changes: Any) -> "Mission":
        """A copy with some fields changed (validated again)."""
        _check_names(type(self), changes)
        return dataclasses.replace(self, **changes)

    def to_dict(self) -> dict:
        """``{'kind': name, field: value, ...}`` with plain values, for result bundles."""
        values = {f.name: getattr(self, f.name) for f in dataclasses.fields(self)}
        return {"kind": self.name, **{k: list(v) if isinstance(v, tuple) else v for k, v in values.items()}}

    @classmethod
    def units(cls) -> dict:
        """Each field's unit."""
        return {f.name: f.metadata["unit"] for f in dataclasses.fields(cls)}


@dataclass(frozen=True)
class Hover(Mission):
    """Hold a point. mp = (x, y, z, yaw).

    >>> Hover(z=2.0).reference(0.0)[0, :3]
    array([0., 0., 2.])
    """

    x: float = _f(0.0, "m", "hover x")
    y: float = _f(0.0, "m", "hover y")
    z: float = _f(1.0, "m", "hover altitude")
    yaw: float = _f(0.0, "rad", "hover yaw")

    name: ClassVar[str] = "hover"
    columns: ClassVar[tuple] = ("x", "y", "z", "yaw")
    function = staticmethod(hover_ref)

    def _row(self) -> tuple:
        return (self.x, self.y, self.z, self.yaw)


@dataclass(frozen=True)
class Step(Mission):
    """An ideal step of ``size`` on ``axis`` at ``time`` from hover at (x, y, z, yaw).

    Velocity and acceleration references stay zero. ``size`` is in m, or rad for yaw.
    mp = (x, y, z, yaw, column, size, time), ``column`` being the REF column stepped.

    >>> Step(axis="z", size=0.5, time=2.0).reference([1.999, 2.0])[:, 2]
    array([1. , 1.5])
    """

    axis: str = _f("x", "-", "stepped axis", "choice", tuple(_AXES))
    size: float = _f(1.0, "m or rad", "step size")
    time: float = _f(1.0, "s", "step time", "nonneg")
    x: float = _f(0.0, "m", "base x")
    y: float = _f(0.0, "m", "base y")
    z: float = _f(1.0, "m", "base altitude")
    yaw: float = _f(0.0, "rad", "base yaw")

    name: ClassVar[str] = "step"
    columns: ClassVar[tuple] = ("x", "y", "z", "yaw", "column", "size", "time")
    function = staticmethod(step_ref)

    @property
    def duration(self) -> float:
        """The step's time and 10 s to settle [s]."""
        return self.time + 10.0

    def _row(self) -> tuple:
        return (self.x, self.y, self.z, self.yaw, _AXES[self.axis], self.size, self.time)


@dataclass(frozen=True)
class Circle(Mission):
    """The paper's search-and-rescue circle (Fig 4), with exact velocity and acceleration.

    Position (cx + R cos a, cy + R sin a, altitude), a = start_angle + direction 2 pi t / period.
    mp = (radius, omega, altitude, start_angle, cx, cy, yaw, ramp_time) with
    omega = direction 2 pi / period [rad/s].
    """

    radius: float = _f(2.0, "m", "circle radius", "pos")
    period: float = _f(20.0, "s", "time per lap", "pos")
    altitude: float = _f(1.0, "m", "altitude")
    start_angle: float = _f(0.0, "rad", "angle of the start point from +x")
    center: tuple = _f((0.0, 0.0), "m", "centre (x, y)", "pair")
    direction: int = _f(1, "-", "+1 counter-clockwise, -1 clockwise", "sign")
    yaw: float = _f(0.0, "rad", "yaw")
    ramp_time: float = _f(0.0, "s", "smooth ramp-up of the speed", "nonneg")

    name: ClassVar[str] = "circle"
    columns: ClassVar[tuple] = ("radius", "omega", "altitude", "start_angle", "cx", "cy",
                                "yaw", "ramp_time")
    function = staticmethod(circle_ref)

    @property
    def speed(self) -> float:
        """Cruise speed 2 pi R / period [m/s]."""
        return 2.0 * math.pi * self.radius / self.period

    @property
    def duration(self) -> float:
        """One lap [s]."""
        return self.period

    def _row(self) -> tuple:
        return (self.radius, self.direction * 2.0 * math.pi / self.period, self.altitude,
                self.start_angle, *self.center, self.yaw, self.ramp_time)


@dataclass(frozen=True)
class Square(Mission):
    """The paper's mapping square (Fig 6): constant-speed legs, explicit corners, repeating.

    Starts at ``corner``; legs +x, +y, -x, -y (y mirrored for direction -1). Only C0 at the
    corners. mp = (side, speed, altitude, x0, y0, direction, dwell, yaw).

    >>> Square().reference([8.0, 16.0, 32.0])[:, :2]      # corners every side/speed = 8 s
    array([[4., 0.],
           [4., 4.],
           [0., 0.]])
    """

    side: float = _f(4.0, "m", "side length", "pos")
    speed: float = _f(0.5, "m/s", "speed on the legs", "pos")
    altitude: float = _f(1.0, "m", "altitude")
    corner: tuple = _f((0.0, 0.0), "m", "first corner (x, y)", "pair")
    direction: int = _f(1, "-", "+1 counter-clockwise, -1 clockwise", "sign")
    dwell: float = _f(0.0, "s", "hold at each corner", "nonneg")
    yaw: float = _f(0.0, "rad", "yaw")

    name: ClassVar[str] = "square"
    columns: ClassVar[tuple] = ("side", "speed", "altitude", "x0", "y0", "direction",
                                "dwell", "yaw")
    function = staticmethod(square_ref)

    @property
    def lap_time(self) -> float:
        """Time per lap, 4 (dwell + side / speed) [s]."""
        return 4.0 * (self.dwell + self.side / self.speed)

    @property
    def duration(self) -> float:
        """One lap [s]."""
        return self.lap_time

    def _row(self) -> tuple:
        return (self.side, self.speed, self.altitude, *self.corner, self.direction,
                self.dwell, self.yaw)


MISSIONS = {cls.name: cls for cls in (Hover, Step, Circle, Square)}


def _check_names(cls: type, kw: dict) -> None:
    unknown = set(kw) - {f.name for f in dataclasses.fields(cls)}
    if unknown:
        raise InputError(f"unknown {cls.name} field(s): {', '.join(sorted(unknown))}")


def mission_from_name(name: str, **kw: Any) -> Mission:
    """Build a mission by kind name ('hover', 'step', 'circle', 'square') and fields.

    >>> mission_from_name("circle", radius=3.0).speed == 2 * 3.1415926535897931 * 3 / 20
    True
    """
    cls = MISSIONS.get(str(name).strip().lower())
    if cls is None:
        raise InputError(f"unknown mission {name!r}; valid missions: {', '.join(MISSIONS)}")
    _check_names(cls, kw)
    return cls(**kw) if kw else shared_default(cls)


def mission_from_dict(d: dict) -> Mission:
    """Inverse of :meth:`Mission.to_dict`."""
    d = dict(d)
    return mission_from_name(d.pop("kind", ""), **d)


def stack_params(missions: Mission | Sequence[Mission], n: int | None = None) -> np.ndarray:
    """The (N, M) mp array of a batch: one row per mission, all of the same kind.

    A single mission (or a list of one) is broadcast to ``n`` rows when ``n`` is given.
    Rows of different lengths (waypoint tables of different sizes) are padded with zeros.

    >>> stack_params([Circle(radius=1.0), Circle(radius=2.0)])[:, 0]
    array([1., 2.])
    >>> stack_params(Hover(), n=3).shape
    (3, 4)
    """
    missions = [missions] if isinstance(missions, Mission) else list(missions)
    if not missions or not all(isinstance(m, Mission) for m in missions):
        raise InputError("stack_params needs a non-empty list of missions")
    kinds = sorted({type(m).name for m in missions})
    if len(kinds) > 1:
        raise InputError(f"a batch flies one mission kind, got {', '.join(kinds)}")
    params = [m.params() for m in missions]
    width = max(p.shape[0] for p in params)      # tables of waypoints differ in length:
    rows = np.zeros((len(params), width))        # pad; each function reads its own count
    for i, p in enumerate(params):
        rows[i, :p.shape[0]] = p
    if n is not None:
        if len(missions) == 1:
            rows = np.repeat(rows, n, axis=0)
        elif len(missions) != n:
            raise InputError(f"{len(missions)} missions given but {n} vehicles were asked for")
    return np.ascontiguousarray(rows)


# --- waypoint kinds (defined in waypoints.py, which builds on Mission above) ----------------
from .waypoints import MinimumSnap, Waypoints  # noqa: E402

MISSIONS.update({cls.name: cls for cls in (Waypoints, MinimumSnap)})
