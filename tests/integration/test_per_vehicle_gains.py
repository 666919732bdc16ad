"""One batch, one controller per vehicle: ``fly`` with a list of controllers of one kind, and the
population's vehicles by index (repeats share their draws and their random streams)."""

import numpy as np
import pytest

import quadcruise as qc
from quadcruise.control import NLPD, Gonzalez
from quadcruise.control.design import PDGains
from quadcruise.disturbances import SensorNoise
from quadcruise.errors import InputError
from quadcruise.missions import Step
from quadcruise.montecarlo import Population
from quadcruise.montecarlo.chunk import fly_chunk
from quadcruise.montecarlo.spec import MonteCarloSpec

STEP = Step(size=0.5, time=0.5)


def test_each_vehicle_flies_its_own_gains():
    a, b = NLPD(position=PDGains(kp=3.75, kd=2.7)), NLPD(position=PDGains(kp=1.0, kd=2.0))
    both = qc.fly(STEP, [a, b, a], duration=4.0)
    for i, c in enumerate((a, b, a)):
        alone = qc.fly(STEP, c, duration=4.0)
        np.testing.assert_array_equal(both.states[i], alone.states[0])
    assert [r["position"]["kp"] for r in both.meta["controllers"]] == [3.75, 1.0, 3.75]
    assert both.meta["controller"]["name"] == "nlpd" and both.n == 3


def test_controllers_of_another_kind_or_count_are_refused():
    with pytest.raises(InputError, match="one kind: vehicle 1 flies a Gonzalez"):
        qc.fly(STEP, [NLPD(), Gonzalez()], duration=1.0)
    with pytest.raises(InputError, match="ambiguous"):
        qc.fly(STEP, [NLPD(), NLPD()], vehicle=qc.Vehicle(m=[3.0, 3.1, 3.2]), duration=1.0)
    with pytest.raises(InputError, match="empty"):
        qc.fly(STEP, [], duration=1.0)


def test_repeated_vehicle_indices_share_draws_and_noise():
    spec = MonteCarloSpec(
        STEP, "nlpd", Population(mass_spread=0.1, noise=SensorNoise(position_std=0.01)), seed=4, duration=2.0
    )
    ids = np.array([0, 1, 0, 1])
    res, draw = fly_chunk(spec, ids, 4, controller=[NLPD()] * 2 + [NLPD(position=PDGains(kp=2.0, kd=3.0))] * 2)
    np.testing.assert_array_equal(draw.vehicle.m[:2], draw.vehicle.m[2:])
    alone, _ = fly_chunk(spec, 0, 2)  # the sweep's vehicles 0 and 1
    np.testing.assert_array_equal(res.states[:2], alone.states)
    assert not np.array_equal(res.states[0], res.states[2])  # other gains, same vehicle
