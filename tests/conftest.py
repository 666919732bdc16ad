"""Fixtures shared by several test modules."""

import warnings

import numpy as np
import pytest

import quadcruise as qc


@pytest.fixture(scope="module")
def diverged():
    """A replay that diverges: one rotor at full power, the opposite one off, so the body
    rate leaves its bound (50 rad/s) early in the flight."""
    t = np.linspace(0, 10, 1001)
    u = np.tile([1.0, 0.07, 0.0, 0.07], (t.size, 1))
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        res = qc.replay(qc.DutySchedule(t=t, duties=u), limits=qc.Limits(max_rate=50.0))
    assert not res.ok[0]
    return res
