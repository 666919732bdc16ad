"""The speed tricks of an environment's reset against their plain formulas: NumPy's own
SeedSequence and default_rng (seeded draws)."""

import numpy as np
import pytest

from quadcruise.sim.fastmath import seed_sequence_words, seeded_draws

SEEDS = [0, 1, 11, 2**32 - 1, 2**32, 2**63 - 1, 2**64 + 7]
IDS = [0, 1, 2**32 - 1, 2**32, 2**33 + 5, 2**64 - 1, 1023 * 2**32 + 99, 123456789]


@pytest.mark.parametrize("seed", SEEDS)
@pytest.mark.parametrize("key", [None, 0, 1, 2, 2**31])
def test_seed_sequence_words_are_numpys(seed, key):
    kw = {} if key is None else {"spawn_key": (key,)}
    for words in (1, 2, 4):
        plain = np.array([np.random.SeedSequence([seed, i], **kw).generate_state(words, np.uint64) for i in IDS])
        assert np.array_equal(seed_sequence_words(seed, IDS, key, words), plain)


@pytest.mark.parametrize("seed", SEEDS)
@pytest.mark.parametrize("normal", [True, False])
def test_seeded_draws_are_default_rngs(seed, normal):
    def plain(i):
        g = np.random.default_rng(np.random.SeedSequence([seed, i], spawn_key=(1,)))
        return g.standard_normal(16) if normal else g.random(16)

    assert np.array_equal(seeded_draws(seed, IDS, 1, 16, normal), np.array([plain(i) for i in IDS]))
    # the keys and indices do matter: a different one gives different draws
    assert not np.array_equal(seeded_draws(seed, IDS, 2, 16, normal), seeded_draws(seed, IDS, 1, 16, normal))
    assert not np.array_equal(seeded_draws(seed, [5], 1, 16, normal), seeded_draws(seed, [6], 1, 16, normal))


def test_negative_seeds_and_indices_are_refused_as_by_numpy():
    with pytest.raises(ValueError, match=">= 0"):
        seed_sequence_words(-1, [0], None, 1)
    with pytest.raises(ValueError, match=">= 0"):
        seed_sequence_words(1, np.array([3, -2]), 1, 1)
    assert seeded_draws(1, [], 1, 16, True).shape == (0, 16)
