"""The speed tricks of the compiled hot path, in one place, each beside its plain formula.

A trick stays only while an alternating A/B run (``benchmarks/ab.py``) shows that it makes
the default path (the closed-loop circle of one vehicle and of 2,000, and the Monte Carlo
benchmark's sweep) at least 5 % faster; docs/performance.md gives each one's figures, and
those of the tricks that were taken out. Each result equals its plain formula's to a
rounding (the tests check it).

- **The scalar-only rule.** The code that runs every control period (the kernel's period
  loop, the controllers, the disturbance) reads the entries of its array arguments into
  scalars first, computes with helpers that take and return scalars, and writes its arrays
  last. Plain: helpers that take the arrays. A compiled helper that takes an array, inlined
  or called, keeps numba's reference-count increment and decrement of it (``NRT_incref``,
  ``NRT_decref``), and so does an array used only in a branch, a function ending in a
  branch, or a call of another compiled function (its error path): numba drops the pairs
  only where the function's control flow proves them redundant. Each is an atomic write to
  a counter that every thread of a batch shares (the rows are views of the batch's arrays).
  ``tests/compiled_code.py`` finds them in a compiled body; the controller and disturbance
  tests use it.
- :func:`turned`: the sines and cosines of the angles, carried through the four stages of
  an RK4 step (``sim.engine.rk4_step``) by the angle-addition formulas, within
  :data:`SHORT_TURN` by a shorter series. Plain: ``math.sin(angle), math.cos(angle)``.
- :data:`TRIG_REFRESH`: the step carries them on to the next step too, computing them
  afresh every TRIG_REFRESH steps. Plain: afresh at every step.
- :func:`five_normals`: five normal draws from one inlined copy of the ziggurat in a loop.
  Plain: five calls of :func:`quadcruise.sim.rng.next_normal`.
- :func:`same_period`: the Dryden filters' coefficients are kept while the control period
  stays the same up to the grid's rounding. Plain: computed afresh every period.

Three more are ways of arranging code, not formulas, so they stay where they act:

- Own copies (``sim.engine._kernel``): a vehicle's controller memory, disturbance memory
  and generator state are copied out of the batch's rows when its flight (or a resumed
  call's part of it) starts, into scratch arrays of the kernel call, and written back
  when it ends. Plain: ``mem[i]``, ``dmem[i]``, ``rng[i]`` updated in
  place, which makes threads flying neighbouring vehicles write to the same cache lines
  every period (false sharing).
- Still air set once (``sim.engine._kernel``): without a disturbance, the external inputs
  are set once per flight. Plain: ``still_air`` called every period.
- ``nlpd``'s library calls (``control.position``): eq (19)'s root for cos psi > 0 as
  ``atan(B / A) - asin(...)`` with R a square root (plain: ``math.hypot``, ``math.atan2``
  and both roots wrapped, the nearer taken, as for cos psi <= 0); sin theta_d as eq (16)'s
  asin argument (plain: ``math.sin(theta_d)``); cos and sin of the tilt limit carried in
  the gains (plain: ``math.cos(max_tilt)``, ``math.sin(max_tilt)`` every period).
"""

from __future__ import annotations

import math

from numba import njit

from quadcruise.sim.rng import ziggurat

__all__ = ["turned", "SMALL_TURN", "SHORT_TURN", "TRIG_REFRESH", "five_normals", "same_period", "DT_TOLERANCE"]

SMALL_TURN = 0.03
"""Largest change of an angle over an RK4 stage [rad] for which :func:`turned` uses the
angle-addition series (beyond it, the library's sine and cosine)."""
SHORT_TURN = 1.0e-3
"""Largest change [rad] for which :func:`turned` uses the short series: the usual case, as a
body rate of 1 rad/s turns an angle by 1 mrad in a 1 ms step."""


@njit(cache=True, inline="always")
def turned(angle, s, c, d):
    """sin and cos of ``angle`` = a + d, given s = sin a and c = cos a.

    Plain: ``math.sin(angle), math.cos(angle)``.

    For |d| <= SMALL_TURN by the angle-addition formulas with the series of sin d and
    cos d - 1, at a fraction of the cost of a sine and a cosine; else from ``angle``
    directly. Within SHORT_TURN the series stop at d^5 and d^6 (the next terms are below
    2e-25 and 3e-29), and the sine's is summed as d + d^3 (...), a shorter chain of
    dependent operations; beyond it they run to d^7 and d^8 (truncation below 1e-20). Either
    way the result is the library's to a rounding.

    Parameters
    ----------
    angle : float
        The new angle a + d [rad].
    s, c : float
        sin a and cos a [-].
    d : float
        The turn d [rad].

    Returns
    -------
    (float, float)
        sin(angle), cos(angle) [-].
    """
    d2 = d * d
    if abs(d) <= SHORT_TURN:
        sd = d + d2 * d * (-1.0 / 6.0 + d2 * (1.0 / 120.0))
        cm1 = d2 * (-0.5 + d2 * (1.0 / 24.0 - d2 * (1.0 / 720.0)))
    elif abs(d) <= SMALL_TURN:
        sd = d * (1.0 - d2 * (1.0 / 6.0) * (1.0 - d2 * (1.0 / 20.0) * (1.0 - d2 * (1.0 / 42.0))))
        cm1 = -d2 * 0.5 * (1.0 - d2 * (1.0 / 12.0) * (1.0 - d2 * (1.0 / 30.0) * (1.0 - d2 * (1.0 / 56.0))))
    else:
        return math.sin(angle), math.cos(angle)
    return s + (s * cm1 + c * sd), c + (c * cm1 - s * sd)


TRIG_REFRESH = 256
"""The RK4 step computes the angles' sines and cosines afresh every this many steps and
carries them by :func:`turned` in between (each turn adds a rounding, about 1e-16)."""


@njit(cache=True, inline="always")
def five_normals(s):
    """Five standard normals from a SplitMix64 state s (:mod:`quadcruise.sim.rng`'s ziggurat
    on the scalar state), and the new state: the turbulence's draws of one period.

    Plain: ``n0, s = next_normal(s)`` five times. A call of a compiled function may fail, and
    its error path keeps numba from dropping the reference counting of the caller's array
    arguments (see the scalar-only rule above); five inlined copies of the ziggurat instead
    of this loop over one compile several times slower (docs/performance.md).

    Parameters
    ----------
    s : int
        A SplitMix64 generator state (uint64).

    Returns
    -------
    (float, float, float, float, float, int)
        Five standard normal draws [-] and the advanced state.
    """
    n0 = n1 = n2 = n3 = n4 = 0.0
    for k in range(5):
        v, s = ziggurat(s)
        if k == 0:
            n0 = v
        elif k == 1:
            n1 = v
        elif k == 2:
            n2 = v
        elif k == 3:
            n3 = v
        else:
            n4 = v
    return n0, n1, n2, n3, n4, s


DT_TOLERANCE = 1e-6
"""Relative change of the control period within which :func:`same_period` holds. A uniform
grid's periods t[k+1] - t[k] differ in their last bits (at 1 kHz and t = 60 s, by up to
1e-11 relative), so an exact comparison would fail in two periods of three."""


@njit(cache=True, inline="always")
def same_period(cached, dt):
    """Whether what was computed for a period of ``cached`` seconds serves a period of ``dt``
    (the Dryden filters' coefficients: two exponentials, a series and three square roots).

    Plain: ``False``, i.e. compute them afresh every period.

    Parameters
    ----------
    cached : float
        The period the cached values were computed for [s].
    dt : float
        This period [s].

    Returns
    -------
    bool
        True when they differ by at most ``DT_TOLERANCE`` relative.
    """
    return abs(cached - dt) <= DT_TOLERANCE * dt
