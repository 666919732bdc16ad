"""Per-vehicle random numbers inside compiled code, reproducible whatever the batching.

Each vehicle owns a 64-bit generator state (one uint64) advanced by SplitMix64 (Steele,
Lea and Flood, 2014), a small, fast generator that passes BigCrush. The state of vehicle i
of a run with seed s is drawn from ``numpy.random.SeedSequence([s, i])``, so a vehicle's
random stream depends only on (seed, i): splitting a population into chunks, or flying one
vehicle alone, gives the same draws.

Examples
--------
>>> import numpy as np
>>> from quadcruise.rng import vehicle_states, uniform
>>> a = vehicle_states(seed=1, n=4)
>>> b = vehicle_states(seed=1, n=2, first=2)        # vehicles 2 and 3 alone
>>> bool(np.all(a[2:] == b))
True
>>> 0.0 <= uniform(a[0]) < 1.0
True
"""

from __future__ import annotations

import math

import numpy as np
from numba import njit, uint64

_GOLDEN = uint64(0x9E3779B97F4A7C15)
_MIX1 = uint64(0xBF58476D1CE4E5B9)
_MIX2 = uint64(0x94D049BB133111EB)


@njit(cache=True, inline="always")
def _mix(z):
    """SplitMix64's output function: 64 random bits from the advanced state z."""
    z = (z ^ (z >> uint64(30))) * _MIX1
    z = (z ^ (z >> uint64(27))) * _MIX2
    return z ^ (z >> uint64(31))


@njit(cache=True, inline="always")
def next_unit(s):
    """On a scalar state s: (a float in [0, 1) with 53 random bits, the advanced state).

    For compiled code that keeps the state in a local variable and stores it once."""
    s = s + _GOLDEN
    return float(_mix(s) >> uint64(11)) * (1.0 / 9007199254740992.0), s


@njit(cache=True)
def next_u64(state):
    """Advance ``state`` (uint64 array, entry 0) and return the next 64 random bits."""
    s = state[0] + _GOLDEN
    state[0] = s
    return _mix(s)


@njit(cache=True)
def uniform(state):
    """A float in [0, 1) with 53 random bits."""
    u, state[0] = next_unit(state[0])
    return u


@njit(cache=True)
def gauss(state):
    """A standard normal draw (Box-Muller; one of the pair is discarded)."""
    u1 = uniform(state)
    u2 = uniform(state)
    return math.sqrt(-2.0 * math.log(1.0 - u1)) * math.cos(2.0 * math.pi * u2)


def vehicle_states(seed: int, n: int, first: int = 0) -> np.ndarray:
    """(n, 1) uint64 generator states of vehicles first .. first + n - 1 of a run."""
    seed = int(seed)
    if seed < 0:
        raise ValueError(f"seed must be a non-negative integer, got {seed}")
    out = np.empty((n, 1), dtype=np.uint64)
    for k in range(n):
        out[k, 0] = np.random.SeedSequence([seed, first + k]).generate_state(1, dtype=np.uint64)[0]
    return out
