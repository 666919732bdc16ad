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
  ``tests/support/compiled_code.py`` finds them in a compiled body; the controller and disturbance
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

- :func:`seed_sequence_words` and :func:`seeded_draws`: the words of
  ``numpy.random.SeedSequence([seed, i], spawn_key)`` computed for many ``i`` in one compiled
  call, NumPy's hashing restated, and a vehicle's draws taken from one reused PCG64 generator
  set to the state that words seed (about 4 us a vehicle, not 12). Plain:
  ``np.random.default_rng(np.random.SeedSequence([seed, i], spawn_key=(key,)))`` per vehicle.
  Bit for bit the same (tests/unit/test_fastmath_seeds.py); an environment's reset draws them.

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

import numpy as np
from numba import njit

from quadcruise.sim.rng import ziggurat

__all__ = [
    "seed_sequence_words",
    "seeded_draws",
    "turned",
    "SMALL_TURN",
    "SHORT_TURN",
    "TRIG_REFRESH",
    "five_normals",
    "same_period",
    "DT_TOLERANCE",
]

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


# NumPy's SeedSequence (numpy/random/bit_generator.pyx), on 32-bit words held in uint64
_U = np.uint64
_M32, _SHIFT, _WORD = _U(0xFFFFFFFF), _U(16), _U(32)
_INIT_A, _MULT_A, _INIT_B, _MULT_B = _U(0x43B0D7E5), _U(0x931E8875), _U(0x8B51F9DD), _U(0x58F38DED)
_MIX_L, _MIX_R = _U(0xCA01F9DD), _U(0x4973F715)
_POOL = 4


@njit(cache=True)
def _hashmix(value, h):
    """SeedSequence's hashmix: the mixed word and the next hash constant."""
    h_next = (h * _MULT_A) & _M32
    value = ((value ^ h) * h_next) & _M32
    return value ^ (value >> _SHIFT), h_next


@njit(cache=True)
def _output_word(value, h):
    """One 32-bit word of SeedSequence.generate_state from a pool word: the word and the next constant."""
    h_next = (h * _MULT_B) & _M32
    value = ((value ^ h) * h_next) & _M32
    return value ^ (value >> _SHIFT), h_next


@njit(cache=True)
def _mix(x, y):
    r = (_MIX_L * x - _MIX_R * y) & _M32
    return r ^ (r >> _SHIFT)


@njit(cache=True)
def _seed_words(seed_words, ids, spawn_key, out):
    """Row r of ``out``: ``SeedSequence([seed, ids[r]], spawn_key=(spawn_key,)).generate_state(W,
    uint64)`` (no spawn key when it is < 0), ``seed_words`` the seed's 32-bit words."""
    entropy = np.zeros(seed_words.shape[0] + 6, dtype=np.uint64)
    pool = np.zeros(_POOL, dtype=np.uint64)
    for r in range(ids.shape[0]):
        n = 0
        for w in seed_words:
            entropy[n] = w
            n += 1
        i = ids[r]
        entropy[n] = i & _M32  # an index's words, least significant first; 0 is one word
        n += 1
        i >>= _WORD
        while i > 0:
            entropy[n] = i & _M32
            n += 1
            i >>= _WORD
        if spawn_key >= 0:
            while n < _POOL:  # the run's entropy is padded to the pool before a spawn key
                entropy[n] = 0
                n += 1
            entropy[n] = spawn_key
            n += 1
        h = _INIT_A
        for k in range(_POOL):
            pool[k], h = _hashmix(entropy[k] if k < n else _U(0), h)
        for src in range(_POOL):
            for dst in range(_POOL):
                if src != dst:
                    v, h = _hashmix(pool[src], h)
                    pool[dst] = _mix(pool[dst], v)
        for src in range(_POOL, n):
            for dst in range(_POOL):
                v, h = _hashmix(entropy[src], h)
                pool[dst] = _mix(pool[dst], v)
        h = _INIT_B
        for k in range(out.shape[1]):  # a 64-bit word: two 32-bit ones, the low first
            low, h = _output_word(pool[(2 * k) % _POOL], h)
            high, h = _output_word(pool[(2 * k + 1) % _POOL], h)
            out[r, k] = low | (high << _WORD)


def seed_sequence_words(seed: int, ids, spawn_key: int | None, n_words: int) -> np.ndarray:
    """``np.random.SeedSequence([seed, i], spawn_key=(spawn_key,)).generate_state(n_words, np.uint64)``
    for each ``i`` of ``ids``, bit for bit, in one compiled call.

    Parameters
    ----------
    seed : int
        >= 0.
    ids : array_like of int
        The indices i, >= 0 and < 2**64.
    spawn_key : int or None
        One spawn key (>= 0, < 2**32), or None for none.
    n_words : int
        64-bit words per index.

    Returns
    -------
    numpy.ndarray
        (len(ids), n_words) uint64.

    Raises
    ------
    ValueError
        A negative seed or index (as SeedSequence).

    Examples
    --------
    >>> import numpy as np
    >>> w = seed_sequence_words(7, [3, 2**40], 1, 2)
    >>> bool((w[1] == np.random.SeedSequence([7, 2**40], spawn_key=(1,)).generate_state(2, np.uint64)).all())
    True
    """
    seed = int(seed)
    if not (isinstance(ids, np.ndarray) and ids.dtype.kind in "iu"):  # Python ints, some beyond int64
        ids = np.array([int(i) for i in np.ravel(np.asarray(ids, dtype=object))], dtype=object)
    ids = ids.ravel()
    if seed < 0 or (ids.size and ids.min() < 0):
        raise ValueError(f"seed and indices must be >= 0, got seed {seed}, indices from {ids.min(initial=0)}")
    ids = np.array(ids.tolist(), dtype=np.uint64) if ids.dtype == object else ids.astype(np.uint64)
    words = [seed & 0xFFFFFFFF]
    seed >>= 32
    while seed:
        words.append(seed & 0xFFFFFFFF)
        seed >>= 32
    out = np.empty((ids.shape[0], int(n_words)), dtype=np.uint64)
    _seed_words(np.array(words, dtype=np.uint64), ids, -1 if spawn_key is None else int(spawn_key), out)
    return out


_PCG_MULT = 0x2360ED051FC65DA44385DF649FCCF645
_M128 = (1 << 128) - 1


def seeded_draws(seed: int, ids, spawn_key: int, size: int, normal: bool) -> np.ndarray:
    """Row r: ``np.random.default_rng(np.random.SeedSequence([seed, ids[r]],
    spawn_key=(spawn_key,)))`` 's ``standard_normal(size)`` (or ``random(size)``), bit for bit.

    Each row's PCG64 state is set from the words as ``numpy.random.PCG64`` seeds itself
    (pcg_setseq_128_srandom_r: state 0, inc = 2 seq + 1, a step, state += seed, a step).

    Parameters
    ----------
    seed, ids, spawn_key
        As :func:`seed_sequence_words`.
    size : int
        Draws per row.
    normal : bool
        Standard normal draws; else uniform on [0, 1).

    Returns
    -------
    numpy.ndarray
        (len(ids), size) float64.
    """
    words = seed_sequence_words(seed, ids, spawn_key, 4)
    bits = np.random.PCG64(0)
    generator = np.random.Generator(bits)
    out = np.empty((words.shape[0], int(size)))
    for r, (s_hi, s_lo, i_hi, i_lo) in enumerate(words.tolist()):
        inc = (((i_hi << 64) | i_lo) << 1 | 1) & _M128
        state = ((inc + ((s_hi << 64) | s_lo)) * _PCG_MULT + inc) & _M128
        bits.state = {"bit_generator": "PCG64", "state": {"state": state, "inc": inc}, "has_uint32": 0, "uinteger": 0}
        out[r] = generator.standard_normal(size) if normal else generator.random(size)
    return out
