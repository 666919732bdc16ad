"""ThreadPlan: a short repeated call runs on one thread or all, whichever its timed trials favour."""

import numba
import pytest

from quadcruise.sim.threads import ThreadPlan


def _run(plan, cost, calls):
    used = []
    for _ in range(calls):
        k = plan.threads()
        plan.record(k, cost[k])
        used.append(k)
    return used


@pytest.mark.skipif(numba.get_num_threads() < 2, reason="needs two numba threads")
@pytest.mark.parametrize("faster", ["one", "all"])
def test_it_keeps_the_faster_after_its_trials(faster):
    most = numba.get_num_threads()
    cost = {1: 1.0, most: 2.0} if faster == "one" else {1: 2.0, most: 1.0}
    plan = ThreadPlan()
    used = _run(plan, cost, 2 * plan.TRIALS + plan.KEEP)
    assert used[: 2 * plan.TRIALS] == [1, most] * plan.TRIALS  # trials in turn
    kept = 1 if faster == "one" else most
    assert set(used[2 * plan.TRIALS :]) == {kept}
    # the next trials follow, and a change of the costs changes the choice
    cost = {1: cost[most], most: cost[1]}
    used = _run(plan, cost, 2 * plan.TRIALS + plan.KEEP)
    assert used[: 2 * plan.TRIALS] == [1, most] * plan.TRIALS
    assert set(used[2 * plan.TRIALS :]) == {most if kept == 1 else 1}


def test_one_thread_when_numba_has_one():
    most = numba.get_num_threads()
    numba.set_num_threads(1)
    try:
        plan = ThreadPlan()
        assert set(_run(plan, {1: 1.0}, 3 * plan.TRIALS)) == {1}
    finally:
        numba.set_num_threads(most)
