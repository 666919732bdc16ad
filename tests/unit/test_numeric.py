"""The one wrap_angle and the one clamp (quadcruise.numeric) against numpy references, from Python
and from compiled code, at the edges: +-pi, multiples of 2 pi, large angles, infinities, NaN (handled as before they
were shared)."""

from __future__ import annotations

import math

import numpy as np
import pytest
from numba import njit

from quadcruise.numeric import clamp, wrap_angle

PI = math.pi
ANGLES = [
    0.0,
    1e-300,
    -1e-300,
    0.5,
    -0.5,
    PI,
    -PI,
    math.nextafter(PI, 0.0),
    math.nextafter(-PI, 0.0),
    2 * PI,
    -2 * PI,
    3 * PI,
    -3 * PI,
    4 * PI + 0.25,
    -7 * PI / 2,
    100.0,
    -100.0,
    1e6 + 0.1,
    -1e6,
    1e12,
]


@njit(cache=False)
def _wrap_compiled(a):
    return wrap_angle(a)


@njit(cache=False)
def _clamp_compiled(v, lo, hi):
    return clamp(v, lo, hi)


@pytest.mark.parametrize("a", ANGLES)
def test_wrap_angle_matches_numpy_modulo_two_pi(a):
    w = wrap_angle(a)
    reference = np.mod(a + PI, 2 * PI) - PI  # numpy's wrap into [-pi, pi)
    slack = 4 * np.spacing(max(abs(a), 1.0))
    assert -PI - slack <= w < PI + slack
    assert abs(math.remainder(w - reference, 2 * PI)) <= slack  # the same direction
    assert abs(math.remainder(w - a, 2 * PI)) <= slack
    # the formula the controllers flew with before it was shared (bit for bit: no number changes)
    assert w == a - 2.0 * PI * math.floor((a + PI) / (2.0 * PI))
    assert _wrap_compiled(a) == w  # compiled and Python agree


def test_wrap_angle_edges():
    assert wrap_angle(PI) == -PI and wrap_angle(-PI) == -PI  # [-pi, pi): pi maps to -pi
    assert wrap_angle(2 * PI) == 0.0 and wrap_angle(-2 * PI) == 0.0
    assert wrap_angle(0.25) == 0.25
    assert math.isnan(wrap_angle(math.nan)) and math.isnan(_wrap_compiled(math.nan))
    for inf in (math.inf, -math.inf):  # not wrapped, as before
        assert wrap_angle(inf) == inf and _wrap_compiled(inf) == inf


@pytest.mark.parametrize("lo, hi", [(-1.0, 1.0), (0.0, 480.0), (-9.81, 9.81), (2.0, 2.0), (-math.inf, 0.0)])
def test_clamp_matches_numpy_clip(lo, hi):
    values = [
        lo - 1.0,
        lo,
        hi,
        hi + 1.0,
        0.5 * (lo + hi) if math.isfinite(lo) else -5.0,
        -math.inf,
        math.inf,
        math.nextafter(hi, math.inf),
        math.nextafter(lo, -math.inf),
    ]
    for v in values:
        out, moved = clamp(v, lo, hi)
        assert out == np.clip(v, lo, hi)
        assert moved == (v < lo or v > hi)
        assert _clamp_compiled(v, lo, hi) == (out, moved)


def test_clamp_passes_nan_through_unmoved():
    out, moved = clamp(math.nan, -1.0, 1.0)
    assert math.isnan(out) and moved is False
    out, moved = _clamp_compiled(math.nan, -1.0, 1.0)
    assert math.isnan(out) and not moved
    assert math.isnan(np.clip(math.nan, -1.0, 1.0))  # as numpy does
