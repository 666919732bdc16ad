"""Per-vehicle random numbers inside compiled code, reproducible whatever the batching.

Each vehicle owns a 64-bit generator state (one uint64) advanced by SplitMix64 (Steele,
Lea and Flood, 2014), a small, fast generator that passes BigCrush. The state of vehicle i
of a run with seed s is drawn from ``numpy.random.SeedSequence([s, i])``, so a vehicle's
random stream depends only on (seed, i): splitting a population into chunks, or flying one
vehicle alone, gives the same draws.

Normal draws (sensor noise, turbulence) use the 256-layer ziggurat of Marsaglia and Tsang
(2000), in the form of numpy's ``Generator.standard_normal``: one 64-bit word gives the
layer (8 bits), the sign (1 bit) and a 52-bit abscissa, accepted at once about 99 % of the
time; the wedges and the tail (beyond r = 3.654) are sampled exactly (its cost against the
polar method and Box-Muller: docs/performance.md).

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


# --- normal draws: the ziggurat ------------------------------------------------------------
ZIGGURAT_R = 3.6541528853610088
"""Where the tail begins: the right edge of the base layer."""
ZIGGURAT_V = 0.00492867323399
"""The area of each of the 256 layers (the base layer with its tail included)."""


def ziggurat_tables(n: int = 256, r: float = ZIGGURAT_R, v: float = ZIGGURAT_V, bits: int = 52):
    """Marsaglia and Tsang's tables for the normal density f(x) = exp(-x^2/2):
    ``(ki, wi, fi)``: the acceptance thresholds (uint64, scaled to ``bits``), the layer
    widths per unit of the abscissa and f at each layer's edge."""
    scale = 2.0 ** bits
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


_KI, _WI, _FI = ziggurat_tables()       # frozen into the compiled code as constants
_BYTE = uint64(0xFF)
_MANTISSA = uint64(0x000FFFFFFFFFFFFF)


@njit(cache=True)
def next_normal(s):
    """On a scalar state s: (a standard normal draw, the advanced state)."""
    return ziggurat(s)


@njit(cache=True, inline="always")
def ziggurat(s):
    """:func:`next_normal`'s body, for compiled code that inlines it once in a loop of draws
    (:func:`quadcruise.sim.fastmath.five_normals`)."""
    while True:
        s = s + _GOLDEN
        bits = _mix(s)
        layer = bits & _BYTE
        bits >>= uint64(8)
        rabs = (bits >> uint64(1)) & _MANTISSA
        x = float(rabs) * _WI[layer]
        if bits & uint64(1):
            x = -x
        if rabs < _KI[layer]:              # inside the layer's rectangle: ~99 %
            return x, s
        if layer == 0:                     # the tail beyond r (Marsaglia, 1964)
            while True:
                u1, s = next_unit(s)
                u2, s = next_unit(s)
                xx = -math.log1p(-u1) / ZIGGURAT_R
                if -2.0 * math.log1p(-u2) > xx * xx:
                    return (-(ZIGGURAT_R + xx) if (rabs >> uint64(8)) & uint64(1) else ZIGGURAT_R + xx), s
        u, s = next_unit(s)                 # the wedge: under the density?
        if (_FI[layer - 1] - _FI[layer]) * u + _FI[layer] < math.exp(-0.5 * x * x):
            return x, s


@njit(cache=True)
def gauss(state):
    """A standard normal draw (the ziggurat, :func:`next_normal`)."""
    x, state[0] = next_normal(state[0])
    return x


def vehicle_states(seed: int, n: int, first: int = 0) -> np.ndarray:
    """(n, 1) uint64 generator states of vehicles first .. first + n - 1 of a run."""
    seed = int(seed)
    if seed < 0:
        raise ValueError(f"seed must be a non-negative integer, got {seed}")
    out = np.empty((n, 1), dtype=np.uint64)
    for k in range(n):
        out[k, 0] = np.random.SeedSequence([seed, first + k]).generate_state(1, dtype=np.uint64)[0]
    return out
