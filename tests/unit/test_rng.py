"""The per-vehicle generator's normal draws (the ziggurat) against scipy's normal law."""

import math

import numpy as np
from numba import njit
from scipy import stats

from quadcruise.sim.rng import ZIGGURAT_R, ZIGGURAT_V, gauss, next_normal, vehicle_states, ziggurat_tables


@njit  # not cached: numba would not see a change in quadcruise.sim.rng
def _draws(n, s):
    out = np.empty(n)
    for k in range(n):
        out[k], s = next_normal(s)
    return out


def test_ziggurat_layers_have_equal_area_and_cover_the_density():
    ki, wi, fi = ziggurat_tables()
    x = wi * 2.0**52  # layer edges x_i (x_0: the base's pseudo-width)
    assert math.isclose(x[255], ZIGGURAT_R) and fi[0] == 1.0
    assert np.all(np.diff(x[1:]) > 0) and np.all(np.diff(fi[1:]) < 0)  # narrower going up
    # every layer i >= 1 is the rectangle [0, x_i] x [f(x_i), f(x_{i-1})] of area V
    areas = x[1:] * (fi[:-1] - fi[1:])
    areas[0] = x[1] * (fi[0] - fi[1])
    np.testing.assert_allclose(areas[1:], ZIGGURAT_V, rtol=1e-9)
    # the top layer ends at the mode: f(x_1) is within one layer of 1
    assert fi[1] > 1.0 - 2 * ZIGGURAT_V / x[1]
    # base: rectangle r f(r) plus the tail's mass, also V
    tail = math.sqrt(math.pi / 2.0) * math.erfc(ZIGGURAT_R / math.sqrt(2.0))
    assert math.isclose(ZIGGURAT_R * fi[255] + tail, ZIGGURAT_V, rel_tol=1e-9)
    assert ki[1] == 0 and np.all(ki[2:] < 2**52)


def test_normal_draws_follow_the_standard_normal_law():
    x = _draws(1_000_000, np.uint64(vehicle_states(7, 1)[0, 0]))
    assert abs(x.mean()) < 4.0 / 1000.0 and abs(x.var() - 1.0) < 4.0 * math.sqrt(2.0) / 1000.0
    assert stats.kstest(x, "norm").pvalue > 1e-3
    # the tail beyond r (sampled by the slow path) and the wedges carry the right mass
    for edge in (1.0, 2.5, ZIGGURAT_R, 4.5):
        p = 2.0 * stats.norm.sf(edge)
        got = np.mean(np.abs(x) > edge)
        assert abs(got - p) < 5.0 * math.sqrt(p * (1 - p) / x.size) + 1e-6, (edge, got, p)
    assert np.all(np.isfinite(x))
    counts, _ = np.histogram(x, bins=np.linspace(-4, 4, 65))
    expected = x.size * np.diff(stats.norm.cdf(np.linspace(-4, 4, 65)))
    assert stats.chisquare(counts, expected * counts.sum() / expected.sum()).pvalue > 1e-3


def test_gauss_advances_the_array_state_like_next_normal():
    state = vehicle_states(3, 1)[0]
    s = np.uint64(state[0])
    for _ in range(100):
        want, s = next_normal(s)
        s = np.uint64(s)  # back from Python: keep the state unsigned
        assert gauss(state) == want and state[0] == s
