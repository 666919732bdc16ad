"""Per-vehicle random numbers inside compiled code, reproducible whatever the batching.

Each vehicle owns a 64-bit generator state (one uint64) advanced by SplitMix64 (Steele,
Lea and Flood, 2014), a small, fast generator that passes BigCrush. The state of vehicle i
of a run with seed s is drawn from ``numpy.random.SeedSequence([s, i])``, so a vehicle's
random stream depends only on (seed, i): splitting a population into chunks, or flying one
vehicle alone, gives the same draws.

Normal draws (sensor noise, turbulence) use the 256-layer ziggurat of Marsaglia and Tsang
(2000), in the form of numpy's ``Generator.standard_normal``: one 64-bit word gives the
layer (8 bits), the sign (1 bit) and a 52-bit abscissa, accepted at once about 99 % of the
time; the wedges and the tail (beyond r = 3.654) are sampled exactly. It is faster than the
polar method and Box-Muller (see docs/performance.md).

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

    For compiled code that keeps the state in a local variable and stores it once.

    Parameters
    ----------
    s : numpy.uint64 or int
        A SplitMix64 generator state (an entry of :func:`vehicle_states`, or the state a
        previous draw returned).

    Returns
    -------
    u : float
        A uniform draw in [0, 1), a multiple of 2^-53.
    s : int
        The advanced state (a uint64 value; numba returns it as a Python int), to pass to
        the next draw.

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
    """Advance ``state`` (uint64 array, entry 0) and return the next 64 random bits.

    Parameters
    ----------
    state : numpy.ndarray
        A vehicle's generator state, uint64, at least one entry (entry 0 is advanced in
        place; a row of :func:`vehicle_states`).

    Returns
    -------
    int
        64 random bits (SplitMix64's output, a uint64 value returned as a Python int).

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
    """A float in [0, 1) with 53 random bits.

    Parameters
    ----------
    state : numpy.ndarray
        A vehicle's generator state, uint64, at least one entry (entry 0 is advanced in
        place; a row of :func:`vehicle_states`).

    Returns
    -------
    float
        A uniform draw in [0, 1), a multiple of 2^-53 (the first value of
        :func:`next_unit` on ``state[0]``).

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
    """Marsaglia and Tsang's tables for the normal density f(x) = exp(-x^2/2):
    ``(ki, wi, fi)``: the acceptance thresholds (uint64, scaled to ``bits``), the layer
    widths per unit of the abscissa and f at each layer's edge.

    Parameters
    ----------
    n : int
        Number of layers (256: one byte of a draw picks the layer).
    r : float
        Where the tail begins, the base layer's right edge [-] (standard normal units);
        it must match ``v`` and ``n``.
    v : float
        The area of each layer [-].
    bits : int
        Bits of the abscissa drawn per sample (52).

    Returns
    -------
    ki : numpy.ndarray
        (n,) uint64: for each layer, the largest abscissa (scaled to 2^bits) that is
        inside the layer below at any height, i.e. accepted at once.
    wi : numpy.ndarray
        (n,) float64: each layer's right edge [-] per unit of the scaled abscissa.
    fi : numpy.ndarray
        (n,) float64: f at each layer's right edge [-] (1 for the top layer).

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

    Parameters
    ----------
    s : numpy.uint64 or int
        A SplitMix64 generator state (an entry of :func:`vehicle_states`, or the state a
        previous draw returned).

    Returns
    -------
    x : float
        A standard normal draw [-] (the ziggurat).
    s : int
        The advanced state (a uint64 value, returned as a Python int; one or more steps:
        the wedges and the tail draw again).

    Examples
    --------
    >>> s = vehicle_states(seed=1, n=1)[0, 0]
    >>> next_normal(s) == next_normal(s)                     # a pure function of the state
    True
    """
    return ziggurat(s)


@njit(cache=True, inline="always")
def ziggurat(s):
    """:func:`next_normal`'s body, for compiled code that inlines it once (a loop of
    draws): every inlined copy adds to the first compile of the function holding it, so
    the turbulence inlines one copy in a loop rather than five
    (:func:`quadcruise.sim.fastmath.five_normals`; see docs/performance.md).

    Parameters
    ----------
    s : numpy.uint64 or int
        A SplitMix64 generator state.

    Returns
    -------
    x : float
        A standard normal draw [-].
    s : int
        The advanced state (a uint64 value, returned as a Python int).

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
    """A standard normal draw (the ziggurat, :func:`next_normal`).

    Parameters
    ----------
    state : numpy.ndarray
        A vehicle's generator state, uint64, at least one entry (entry 0 is advanced in
        place; a row of :func:`vehicle_states`).

    Returns
    -------
    float
        A standard normal draw [-].

    Examples
    --------
    >>> a, b = vehicle_states(seed=1, n=1)[0], vehicle_states(seed=1, n=1)[0]
    >>> [bool(gauss(a) == gauss(b)) for _ in range(3)]       # same seed, same stream
    [True, True, True]
    """
    x, state[0] = next_normal(state[0])
    return x


def vehicle_states(seed: int, n: int, first=0) -> np.ndarray:
    """(n, 1) uint64 generator states of vehicles first .. first + n - 1 of a run.

    ``first`` may also be an (n,) array of whole numbers: the index of each vehicle in the
    run, so that vehicles flown side by side can share a stream (a tuner flies each
    candidate on the same perturbed vehicles, noise included).

    Parameters
    ----------
    seed : int
        The run's seed, >= 0.
    n : int
        Number of vehicles.
    first : int or array_like of int
        The index of the first vehicle in the run (the rest follow it), or the (n,) indices
        of the vehicles, each >= 0 (repeats allowed).

    Returns
    -------
    numpy.ndarray
        (n, 1) uint64: row k is the state of vehicle i, drawn from
        ``numpy.random.SeedSequence([seed, i])``, so it depends on (seed, i) only.

    Raises
    ------
    ValueError
        A negative seed, or indices that are not n whole numbers >= 0.

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
