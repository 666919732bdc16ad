"""The noise processes every sensor model is made of, compiled on scalars.

A sensor sampled at ``rate`` [Hz] with white noise of density ``n`` (its datasheet's noise
density, unit/sqrt(Hz)) has a per-sample standard deviation ``n * sqrt(rate)``; a bias random
walk of density ``b`` (unit/s/sqrt(Hz), i.e. unit/sqrt(s) per second of flight) grows by
``b * sqrt(dt)`` per step of ``dt`` seconds, so that its spread after time T is ``b * sqrt(T)``
(IEEE Std 952-1997, Annex C: angle and rate random walk). Every draw comes from a SplitMix64
state (:mod:`quadcruise.sim.rng`) handed in and returned, so that a stream depends on its seed
only. The state must reach a compiled function as a ``numpy.uint64`` (a row of
:func:`~quadcruise.sim.rng.vehicle_states`, or ``np.uint64(s)``): a state returned to Python
comes back as an ``int``, which numba would type as int64, and the generator would then stall;
the ``measure`` methods cast it.

Examples
--------
>>> from quadcruise.sim.rng import vehicle_states
>>> s = vehicle_states(seed=3, n=1)[0, 0]
>>> x, s2 = noisy(1.0, 0.0, 0.0, s)          # no noise: the value itself
>>> x
1.0
>>> sample_std(0.01, 400.0)                  # 0.01 unit/sqrt(Hz) at 400 Hz
0.2
"""

from __future__ import annotations

import math

import numpy as np
from numba import njit

from quadcruise.sim.rng import next_normal


@njit(cache=True, inline="always")
def sample_std(density, rate):
    """The standard deviation of one sample of white noise: ``density * sqrt(rate)``.

    Examples
    --------
    >>> sample_std(1.0, 100.0)
    10.0
    """
    return density * math.sqrt(rate)


@njit(cache=True, inline="always")
def noisy(value, bias, std, s):
    """``value + bias + std * w`` with w standard normal: (the reading, the advanced state).

    Examples
    --------
    >>> from quadcruise.sim.rng import vehicle_states
    >>> noisy(2.0, 0.5, 0.0, vehicle_states(1, 1)[0, 0])[0]
    2.5
    """
    if std == 0.0:
        return value + bias, s
    w, s = next_normal(s)
    return value + bias + std * w, s


@njit(cache=True, inline="always")
def walk(bias, density, dt, s):
    """One step of a random walk: ``bias + density * sqrt(dt) * w`` (the new bias, the state).

    Examples
    --------
    >>> from quadcruise.sim.rng import vehicle_states
    >>> walk(0.1, 0.0, 0.01, vehicle_states(1, 1)[0, 0])[0]
    0.1
    """
    if density == 0.0:
        return bias, s
    w, s = next_normal(s)
    return bias + density * math.sqrt(dt) * w, s


@njit(cache=True, inline="always")
def digitise(value, lsb, limit):
    """A reading clipped to ``[-limit, limit]`` (``limit`` 0: none) and rounded to a multiple of
    ``lsb`` (0: none), as an ADC gives it.

    Examples
    --------
    >>> digitise(1.26, 0.1, 0.0), digitise(40.0, 0.0, 16.0)
    (1.3, 16.0)
    """
    if limit > 0.0:
        value = min(max(value, -limit), limit)
    if lsb > 0.0:
        value = lsb * round(value / lsb)
    return value


def sample_times(t0: float, t1: float, rate: float) -> np.ndarray:
    """The instants ``t0 + k / rate`` in ``[t0, t1]`` at which a sensor samples.

    Parameters
    ----------
    t0, t1 : float
        First and last instant of the flight [s].
    rate : float
        Sample rate [Hz], > 0.

    Returns
    -------
    numpy.ndarray
        (K,) float64 [s].

    Examples
    --------
    >>> sample_times(0.0, 1.0, 4.0).tolist()
    [0.0, 0.25, 0.5, 0.75, 1.0]
    """
    n = int(math.floor((t1 - t0) * rate + 1e-9)) + 1
    return t0 + np.arange(n) / rate
