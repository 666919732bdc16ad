"""Per-vehicle random numbers inside compiled code, reproducible whatever the batching.

Each vehicle owns one uint64 state advanced by SplitMix64 (Steele, Lea and Flood, 2014), seeded
from ``numpy.random.SeedSequence([seed, i])``: a vehicle's stream depends on (seed, i) only, so
chunks, or one vehicle flown alone, draw the same numbers. Normal draws use numpy's 256-layer
ziggurat (Marsaglia and Tsang, 2000); its speed against the polar method: docs/performance.md.

Examples
--------
>>> import numpy as np
>>> from quadcruise.sim.rng import vehicle_states, uniform
>>> a = vehicle_states(seed=1, n=4)
>>> b = vehicle_states(seed=1, n=2, first=2)        # vehicles 2 and 3 alone
>>> bool(np.all(a[2:] == b))
True
>>> 0.0 <= uniform(a[0]) < 1.0
True
>>> x = np.array([gauss(a[1]) for _ in range(20000)])
>>> bool(abs(x.mean()) < 0.03 and abs(x.std() - 1.0) < 0.03)
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
    """On a scalar state s: (a uniform float in [0, 1) with 53 random bits, the advanced state).

    Examples
    --------
    >>> s = vehicle_states(seed=1, n=1)[0, 0]
    >>> u, s2 = next_unit(s)
    >>> 0.0 <= u < 1.0, bool(s2 != s), next_unit(s) == (u, s2)   # the same state, the same draw
    (True, True, True)
    """
    s = s + _GOLDEN
    return float(_mix(s) >> uint64(11)) * (1.0 / 9007199254740992.0), s


@njit(cache=True)
def next_u64(state):
    """Advance ``state[0]`` (a row of :func:`vehicle_states`) in place and return 64 random bits.

    Examples
    --------
    >>> state = vehicle_states(seed=1, n=1)[0]
    >>> before = state[0]
    >>> bits = next_u64(state)
    >>> bool(state[0] != before)
    True
    """
    s = state[0] + _GOLDEN
    state[0] = s
    return _mix(s)


@njit(cache=True)
def uniform(state):
    """A float in [0, 1) with 53 random bits, advancing ``state[0]`` in place.

    Examples
    --------
    >>> state = vehicle_states(seed=1, n=1)[0]
    >>> u = uniform(state)
    >>> 0.0 <= u < 1.0
    True
    """
    u, state[0] = next_unit(state[0])
    return u


# --- normal draws: the ziggurat ------------------------------------------------------------
ZIGGURAT_R = 3.6541528853610088
"""Where the tail begins: the right edge of the base layer."""
ZIGGURAT_V = 0.00492867323399
"""The area of each of the 256 layers (the base layer with its tail included)."""


def ziggurat_tables(n: int = 256, r: float = ZIGGURAT_R, v: float = ZIGGURAT_V, bits: int = 52):
    """Marsaglia and Tsang's tables ``(ki, wi, fi)`` for f(x) = exp(-x^2/2): each layer's threshold
    of immediate acceptance (uint64, scaled to 2^bits), its width per unit of the abscissa, and f
    at its right edge.

    Examples
    --------
    >>> ki, wi, fi = ziggurat_tables()
    >>> ki.dtype, wi.shape, float(fi[0])
    (dtype('uint64'), (256,), 1.0)
    """
    scale = 2.0**bits
    ki, wi, fi = np.zeros(n, np.uint64), np.zeros(n), np.zeros(n)
    dn = tn = r
    fr = math.exp(-0.5 * r * r)
    q = v / fr
    ki[0], wi[0], fi[0] = int(dn / q * scale), q / scale, 1.0
    wi[n - 1], fi[n - 1] = dn / scale, fr
    for i in range(n - 2, 0, -1):
        dn = math.sqrt(-2.0 * math.log(v / dn + math.exp(-0.5 * dn * dn)))
        ki[i + 1] = int(dn / tn * scale)
        tn = dn
        fi[i], wi[i] = math.exp(-0.5 * dn * dn), dn / scale
    return ki, wi, fi


_KI, _WI, _FI = ziggurat_tables()  # frozen into the compiled code as constants
_BYTE = uint64(0xFF)
_MANTISSA = uint64(0x000FFFFFFFFFFFFF)


@njit(cache=True)
def next_normal(s):
    """On a scalar state s: (a standard normal draw, the advanced state).

    Examples
    --------
    >>> s = vehicle_states(seed=1, n=1)[0, 0]
    >>> next_normal(s) == next_normal(s)                     # a pure function of the state
    True
    """
    return ziggurat(s)


@njit(cache=True, inline="always")
def ziggurat(s):
    """:func:`next_normal`'s body, inlined once into a loop of draws (each inlined copy lengthens
    the first compile; docs/performance.md).

    Examples
    --------
    >>> s = vehicle_states(seed=1, n=1)[0, 0]
    >>> ziggurat(s) == next_normal(s)
    True
    """
    while True:
        s = s + _GOLDEN
        bits = _mix(s)
        layer = bits & _BYTE
        bits >>= uint64(8)
        rabs = (bits >> uint64(1)) & _MANTISSA
        x = float(rabs) * _WI[layer]
        if bits & uint64(1):
            x = -x
        if rabs < _KI[layer]:  # inside the layer's rectangle: ~99 %
            return x, s
        if layer == 0:  # the tail beyond r (Marsaglia, 1964)
            while True:
                u1, s = next_unit(s)
                u2, s = next_unit(s)
                xx = -math.log1p(-u1) / ZIGGURAT_R
                if -2.0 * math.log1p(-u2) > xx * xx:
                    return (-(ZIGGURAT_R + xx) if (rabs >> uint64(8)) & uint64(1) else ZIGGURAT_R + xx), s
        u, s = next_unit(s)  # the wedge: under the density?
        if (_FI[layer - 1] - _FI[layer]) * u + _FI[layer] < math.exp(-0.5 * x * x):
            return x, s


@njit(cache=True)
def gauss(state):
    """A standard normal draw (:func:`next_normal`), advancing ``state[0]`` in place.

    Examples
    --------
    >>> a, b = vehicle_states(seed=1, n=1)[0], vehicle_states(seed=1, n=1)[0]
    >>> [bool(gauss(a) == gauss(b)) for _ in range(3)]       # same seed, same stream
    [True, True, True]
    """
    x, state[0] = next_normal(state[0])
    return x


def vehicle_states(seed: int, n: int, first=0) -> np.ndarray:
    """(n, 1) uint64 generator states of vehicles ``first`` .. ``first + n - 1`` of a run.

    ``first`` may also be the (n,) indices of the vehicles (repeats allowed), so that vehicles
    flown side by side share a stream. Row k is drawn from ``SeedSequence([seed, i])``; a negative
    seed or indices that are not n whole numbers >= 0 raise ValueError.

    Examples
    --------
    >>> import numpy as np
    >>> states = vehicle_states(seed=1, n=3)
    >>> states.shape, states.dtype
    ((3, 1), dtype('uint64'))
    >>> bool(np.all(vehicle_states(1, 2, first=[2, 2]) == states[2]))   # vehicle 2 twice
    True
    """
    seed = int(seed)
    if seed < 0:
        raise ValueError(f"seed must be a non-negative integer, got {seed}")
    if np.ndim(first) == 0:
        ids = [int(first) + k for k in range(n)]
    else:
        ids = [int(i) for i in np.asarray(first).ravel()]
        if len(ids) != n or min(ids, default=0) < 0:
            raise ValueError(f"first must be one index >= 0 or {n} of them, got {len(ids)}")
    out = np.empty((n, 1), dtype=np.uint64)
    for k, i in enumerate(ids):
        out[k, 0] = np.random.SeedSequence([seed, i]).generate_state(1, dtype=np.uint64)[0]
    return out
