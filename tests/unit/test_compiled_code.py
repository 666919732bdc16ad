"""The compiled-code checker of the tests (tests/support/compiled_code.py), both ways: it finds
constant and run-time indexing, into inlined helpers too, and the reference counting that a
call of a compiled function on an array leaves, and finds none where there is none."""

from numba import njit, types

from quadcruise import layout as L
from support.compiled_code import reference_count_calls, row_offsets

SIG = types.void(types.float64[::1], types.float64[::1])


@njit(inline="always")
def _write(cmd, a):
    cmd[L.CMD_U1] = a
    cmd[1] = a


def _offsets(x, cmd):
    a = x[L.PHI] + x[2]
    for j in range(3):  # unrolled: constants
        a += x[L.P + j]
    a += x[int(cmd[0])]  # an index known at run time only
    _write(cmd, a)


@njit(cache=False)
def _may_raise(x):
    if x[0] < -1e300:
        raise ValueError("a call's error path")
    return x[1]


def _counted(x, cmd):
    for i in range(2):
        if x[i] > 0.0:
            cmd[i] = _may_raise(x)


def test_row_offsets_tell_constant_from_run_time_indices():
    assert row_offsets(_offsets, SIG, "x") == ({L.PHI, 2, L.P, L.P + 1, L.P + 2}, 1)
    assert row_offsets(_offsets, SIG, "cmd") == ({0, L.CMD_U1, 1}, 0)  # written in the inlined helper


def test_reference_count_calls_found_where_they_are_and_only_there():
    assert reference_count_calls(_counted, SIG)  # an array handed to a call that may raise
    assert reference_count_calls(_offsets, SIG) == []
