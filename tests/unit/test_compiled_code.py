"""The compiled-code checker of the tests (tests/support/compiled_code.py), both ways: it finds
constant and run-time indexing, into inlined helpers too, and the reference counting that a
call of a compiled function on an array leaves, and finds none where there is none."""

from numba import njit, types

from quadcruise import layout as L
from quadcruise.model.rotor_plant import rotor_derivative
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


def test_the_rotor_plant_reads_its_rows_at_constant_offsets():
    """The rotor plant's compiled code reads its state and parameter rows through the constants
    of their ``layout.Row``s (quadcruise.model.rotor_plant): every rigid-body column and every
    parameter of the row's head at a constant offset; at run time only what depends on the rotor
    count (a rotor's speed, its arm)."""
    from quadcruise.model.rotor_plant import (
        ROTOR_ARM,
        ROTOR_BODY,
        ROTOR_P_ROTORS,
        ROTOR_P_W_MAX,
        ROTOR_P_W_MIN,
        ROTOR_PARAMS,
        rotor_stages,
    )
    from quadcruise.sim.rotor_flight import paper_state

    row = types.float64[::1]
    signature = types.void(row, row, row, row, types.float64, types.float64[:, ::1], types.int64)
    body = set(range(ROTOR_BODY.size))
    position = {ROTOR_BODY.offsets[0], ROTOR_BODY.offsets[1], ROTOR_BODY.offsets[2]}  # not read: no force depends on it
    assert row_offsets(rotor_stages.py_func, signature, "x") == (body - position, 1)  # a rotor's speed: in the loop
    # the stage derivatives, by (stage, column): the previous stage's read where the state is, all written
    assert row_offsets(rotor_stages.py_func, signature, "k") == (body, 2)  # a rotor's: read and written
    head = set(range(ROTOR_PARAMS.size)) - {ROTOR_P_W_MIN, ROTOR_P_W_MAX}  # the speed range: the kernel's
    assert ROTOR_P_ROTORS == ROTOR_PARAMS.size
    assert row_offsets(rotor_stages.py_func, signature, "rp") == (head, ROTOR_ARM.size)  # one rotor's arm
    ext = row_offsets(rotor_stages.py_func, signature, "ext")
    assert ext == ({L.EXT_FX, L.EXT_FY, L.EXT_FZ, L.EXT_TX, L.EXT_TY, L.EXT_TZ, L.EXT_WX, L.EXT_WY, L.EXT_WZ}, 1)
    # the kernel's view of it in the paper layout: the rigid body at constant offsets, all 16 written
    paper_sig = types.float64(row, row, row, types.float64, row)
    rotors_1_to_4 = {ROTOR_BODY.size + i for i in range(4)}  # its loop over range(4): unrolled
    assert row_offsets(paper_state.py_func, paper_sig, "xr") == (body | rotors_1_to_4, 0)
    assert row_offsets(paper_state.py_func, paper_sig, "out") == (set(range(L.STATE_SIZE)), 0)


def _step_with_row_views(x, w_cmd, rp, ext, h, work):
    for stage in range(4):  # the rotor plant's stages through row views of the workspace
        rotor_derivative(x, w_cmd, rp, ext, work[stage])


def test_the_rotor_step_makes_no_reference_count_calls():
    """The rotor plant's RK4 step (quadcruise.sim.rotor_engine.rotor_rk4_step, flown every substep)
    reference-counts no array: its four stages are one loop of one body and its workspace is
    indexed, not sliced. The same stages through row views (``work[stage]``) and a call per stage
    do, and the checker finds them there."""
    from quadcruise.sim.rotor_engine import rotor_rk4_step

    row = types.float64[::1]
    signature = types.void(row, row, row, row, types.float64, types.float64[:, ::1])
    assert reference_count_calls(rotor_rk4_step.py_func, signature) == []
    assert reference_count_calls(_step_with_row_views, signature)
