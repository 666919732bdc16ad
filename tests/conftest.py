"""Fixtures shared by several test modules, and one BLAS thread per test process."""

import os

# The suite runs on pytest-xdist's workers, one per core (pyproject.toml). OpenBLAS would start
# a thread per core in each of them, and its threads wait for work by spinning: on cores that
# the other workers are using, a least-squares fit (sysid's) took five times the CPU. Set
# before numpy loads OpenBLAS here, and inherited by the workers and the processes the tests
# start; an OPENBLAS_NUM_THREADS of your own wins.
os.environ.setdefault("OPENBLAS_NUM_THREADS", "1")

import warnings  # noqa: E402

import numpy as np  # noqa: E402
import pytest  # noqa: E402

import quadcruise as qc  # noqa: E402


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
