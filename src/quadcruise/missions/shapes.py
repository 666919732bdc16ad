"""Missions: the reference a vehicle is asked to follow, as a compiled function of time.

Each kind writes position, velocity, acceleration, yaw and yaw rate into a ``REF_SIZE`` vector
(``mission(t, mp, ref)``, ``MISSION_SIG``) from its flat parameter row ``mp`` (the class's
``columns``). The kinds here, :class:`Hover`, :class:`Step`, :class:`Circle` and :class:`Square`,
and why their defaults: docs/missions.md.

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

import math
from dataclasses import dataclass
from typing import ClassVar

from numba import njit

from quadcruise.errors import InputError
from quadcruise.fields import unit_field as _f
from quadcruise.layout import REF_AX, REF_AY, REF_PSI, REF_SIZE, REF_VX, REF_VY, REF_X, REF_Y, REF_Z
from quadcruise.missions.base import Mission

__all__ = ["Circle", "Hover", "Square", "Step", "circle_ref", "hover_ref", "square_ref", "step_ref"]

_AXES = {"x": REF_X, "y": REF_Y, "z": REF_Z, "yaw": REF_PSI}


# --- compiled references (scalar code, no allocation; error_model="numpy" drops the
# zero-division checks, the dataclasses having ruled zero divisors out). Each compiles
# (or loads from numba's cache) the first time a flight passes it to the engine, as a
# function with MISSION_SIG; a signature in the decorator would compile every mission
# when the package is imported, missions not flown included. -----
@njit(cache=True)
def _clear(ref):
    for i in range(REF_SIZE):
        ref[i] = 0.0


@njit(cache=True, error_model="numpy")
def hover_ref(t, mp, ref):
    """Hover reference: a constant point, zero velocity and acceleration.

    Parameters
    ----------
    t : float
        Time [s].
    mp : numpy.ndarray
        The mission's parameter vector (float64, 1-D): (x [m], y [m], z [m], yaw [rad]).
    ref : numpy.ndarray
        Output, REF_SIZE float64 entries: position [m], velocity [m/s], acceleration
        [m/s^2], yaw [rad] and yaw rate [rad/s] at ``t`` (overwritten).

    Examples
    --------
    >>> import numpy as np
    >>> ref = np.empty(REF_SIZE)
    >>> hover_ref(3.0, np.array([1.0, 2.0, 1.5, 0.5]), ref)
    >>> ref[[REF_X, REF_Y, REF_Z, REF_PSI]]
    array([1. , 2. , 1.5, 0.5])
    """
    _clear(ref)
    ref[REF_X], ref[REF_Y], ref[REF_Z], ref[REF_PSI] = mp[0], mp[1], mp[2], mp[3]


@njit(cache=True, error_model="numpy")
def step_ref(t, mp, ref):
    """Step reference: hover at (x, y, z, yaw), and ``ref[column] += size`` from t >= time.

    Velocity and acceleration stay zero.

    Parameters
    ----------
    t : float
        Time [s].
    mp : numpy.ndarray
        The mission's parameter vector (float64, 1-D): (x [m], y [m], z [m], yaw [rad],
        column [-] (the REF column stepped, as a float), size [m] or [rad] (yaw), time [s]).
    ref : numpy.ndarray
        Output, REF_SIZE float64 entries: position [m], velocity [m/s], acceleration
        [m/s^2], yaw [rad] and yaw rate [rad/s] at ``t`` (overwritten).
    """
    _clear(ref)
    ref[REF_X], ref[REF_Y], ref[REF_Z], ref[REF_PSI] = mp[0], mp[1], mp[2], mp[3]
    if t >= mp[6]:
        ref[int(mp[4])] += mp[5]


@njit(cache=True, error_model="numpy")
def circle_ref(t, mp, ref):
    """Circle reference with exact velocity and acceleration.

    The angle is a = start_angle + omega s(t), s(t) = t without a ramp; with ``ramp_time``
    T_r > 0 the angular rate rises as smoothstep(t / T_r) from 0 (s = 0 for t <= 0) and
    s(t) = t - T_r / 2 after the ramp.

    Parameters
    ----------
    t : float
        Time [s].
    mp : numpy.ndarray
        The mission's parameter vector (float64, 1-D): (radius [m], omega [rad/s]
        (signed: > 0 counter-clockwise), altitude [m], start_angle [rad], cx [m], cy [m],
        yaw [rad], ramp_time [s]).
    ref : numpy.ndarray
        Output, REF_SIZE float64 entries: position [m], velocity [m/s], acceleration
        [m/s^2], yaw [rad] and yaw rate [rad/s] at ``t`` (overwritten).
    """
    radius, omega, ramp = mp[0], mp[1], mp[7]
    s, rate, drate = t, 1.0, 0.0  # phase time s(t) and its derivatives
    if ramp > 0.0:
        u = t / ramp
        if u <= 0.0:
            s, rate = 0.0, 0.0
        elif u < 1.0:  # rate = smoothstep(u), s = its integral
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
    """Square reference: constant-speed legs +x, +y, -x, -y (y mirrored for direction -1)
    from the corner (x0, y0), dwelling at each corner, repeating every lap.

    On a leg the velocity is ``speed`` along it and the acceleration zero; during a dwell
    both are zero (the velocity jumps at departure and arrival).

    Parameters
    ----------
    t : float
        Time [s].
    mp : numpy.ndarray
        The mission's parameter vector (float64, 1-D): (side [m], speed [m/s], altitude [m],
        x0 [m], y0 [m], direction [-] (+1 or -1), dwell [s], yaw [rad]).
    ref : numpy.ndarray
        Output, REF_SIZE float64 entries: position [m], velocity [m/s], acceleration
        [m/s^2], yaw [rad] and yaw rate [rad/s] at ``t`` (overwritten).
    """
    side, speed, sgn, dwell = mp[0], mp[1], mp[5], mp[6]
    seg = dwell + side / speed  # one corner's dwell plus one leg
    lap = 4.0 * seg
    tau = t - lap * math.floor(t / lap)
    k = min(int(tau / seg), 3)
    s = tau - k * seg
    # corner k and the unit vector of leg k (y mirrored by direction)
    cx, cy = side * (0.0, 1.0, 1.0, 0.0)[k], side * (0.0, 0.0, 1.0, 1.0)[k]
    dx, dy = (1.0, 0.0, -1.0, 0.0)[k], (0.0, 1.0, 0.0, -1.0)[k]
    _clear(ref)
    moved = s - dwell  # the leg is [departure, arrival): v jumps at corners
    if moved >= 0.0:
        ref[REF_VX], ref[REF_VY] = dx * speed, sgn * dy * speed
    else:
        moved = 0.0
    ref[REF_X] = mp[3] + cx + dx * speed * moved
    ref[REF_Y] = mp[4] + sgn * (cy + dy * speed * moved)
    ref[REF_Z] = mp[2]
    ref[REF_PSI] = mp[7]


@dataclass(frozen=True)
class Hover(Mission):
    """Hold a point. mp = (x, y, z, yaw).

    Parameters
    ----------
    x, y : float
        Horizontal position [m].
    z : float
        Altitude [m] (z up).
    yaw : float
        Yaw [rad].

    Examples
    --------
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

    Parameters
    ----------
    axis : str
        The stepped axis: 'x', 'y', 'z' or 'yaw'.
    size : float
        Step size [m] (or [rad] for 'yaw'), nonzero.
    time : float
        Time of the step [s], >= 0.
    x, y : float
        Horizontal position before the step [m].
    z : float
        Altitude before the step [m].
    yaw : float
        Yaw before the step [rad].

    Examples
    --------
    >>> Step(axis="z", size=0.5, time=2.0).reference([1.999, 2.0])[:, 2]
    array([1. , 1.5])
    """

    axis: str = _f("x", "-", "stepped axis", "choice", tuple(_AXES))
    size: float = _f(1.0, "m or rad", "step size", "nonzero")  # a step of 0 is a hover: no step to measure
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

    Position (cx + R cos a, cy + R sin a, altitude), a = start_angle + direction 2 pi t / period
    (with ``ramp_time`` > 0, t is replaced by the ramped phase time of :func:`circle_ref`).
    mp = (radius, omega, altitude, start_angle, cx, cy, yaw, ramp_time) with
    omega = direction 2 pi / period [rad/s].

    Parameters
    ----------
    radius : float
        Circle radius R [m], > 0.
    period : float
        Time per lap [s], > 0.
    altitude : float
        Altitude [m].
    start_angle : float
        Angle of the start point from +x about the centre [rad].
    center : tuple of float
        Centre (cx, cy) [m].
    direction : int
        +1 counter-clockwise, -1 clockwise.
    yaw : float
        Yaw, held [rad].
    ramp_time : float
        Time over which the angular rate ramps smoothly up from 0 [s], >= 0 (0: none; the
        phase then lags the unramped circle by omega * ramp_time / 2).

    Examples
    --------
    >>> c = Circle(radius=1.0, period=4.0, center=(1.0, 0.0))
    >>> c.reference(1.0)[0, :3].round(12) + 0.0       # a quarter lap: at (cx, cy + R)
    array([1., 1., 1.])
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
    columns: ClassVar[tuple] = ("radius", "omega", "altitude", "start_angle", "cx", "cy", "yaw", "ramp_time")
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
        return (
            self.radius,
            self.direction * 2.0 * math.pi / self.period,
            self.altitude,
            self.start_angle,
            *self.center,
            self.yaw,
            self.ramp_time,
        )


MIN_LEG_S = 1e-6
"""The shortest leg of a square [s] (side / speed): shorter is a hover, and the reference's
arithmetic underflows."""


@dataclass(frozen=True)
class Square(Mission):
    """The paper's mapping square (Fig 6): constant-speed legs, explicit corners, repeating.

    Starts at ``corner``; legs +x, +y, -x, -y (y mirrored for direction -1). Only C0 at the
    corners. mp = (side, speed, altitude, x0, y0, direction, dwell, yaw).

    Parameters
    ----------
    side : float
        Side length [m], > 0.
    speed : float
        Speed on the legs [m/s], > 0.
    altitude : float
        Altitude [m].
    corner : tuple of float
        First corner (x0, y0) [m], where the square starts.
    direction : int
        +1 counter-clockwise (legs +x, +y, -x, -y), -1 clockwise (+x, -y, -x, +y).
    dwell : float
        Hold at each corner before leaving it [s], >= 0.
    yaw : float
        Yaw, held [rad].

    Examples
    --------
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
    columns: ClassVar[tuple] = ("side", "speed", "altitude", "x0", "y0", "direction", "dwell", "yaw")
    function = staticmethod(square_ref)

    def __post_init__(self) -> None:
        super().__post_init__()
        leg = float(self.side) / float(self.speed)
        if not leg >= MIN_LEG_S:
            raise InputError(
                f"square: a side of {self.side:g} m at {self.speed:g} m/s takes {leg:g} s, "
                f"under {MIN_LEG_S:g} s: too short a leg to fly"
            )

    @property
    def lap_time(self) -> float:
        """Time per lap, 4 (dwell + side / speed) [s]."""
        return 4.0 * (self.dwell + self.side / self.speed)

    @property
    def duration(self) -> float:
        """One lap [s]."""
        return self.lap_time

    def _row(self) -> tuple:
        return (self.side, self.speed, self.altitude, *self.corner, self.direction, self.dwell, self.yaw)
