"""The API of objects: environment=, sensors=, seed= on fly/compare/montecarlo; unknown keywords
named; any object offering the engine's needs is a controller; every result speaks one vocabulary."""

from __future__ import annotations

import numpy as np
import pandas as pd
import pytest

import quadcruise as qc
from quadcruise.control import NLPD
from quadcruise.disturbances import Environment, SensorNoise, Turbulence, with_drag
from quadcruise.metrics.summary import Summary
from quadcruise.montecarlo import MonteCarloResult, Population, montecarlo
from quadcruise.protocols import ControllerLike, ResultLike
from quadcruise.workflows.fly_inputs import engine_inputs


class PlainController:
    """A controller that does not subclass quadcruise.control.Controller."""

    name = "mine"

    def __init__(self):
        self._inner = NLPD()

    @property
    def function(self):
        return self._inner.function

    def gains(self):
        return self._inner.gains()

    def memory(self):
        return self._inner.memory()


def test_a_controller_is_anything_with_the_protocol():
    mine = PlainController()
    assert isinstance(mine, ControllerLike) and not isinstance(mine, qc.control.Controller)
    ours, theirs = qc.fly("step", "nlpd", duration=3.0), qc.fly("step", mine, duration=3.0)
    np.testing.assert_array_equal(ours.states, theirs.states)
    assert theirs.meta["controller"]["name"] == "mine" and len(theirs.meta["controller"]["gains"]) == mine.gains().size
    cmp = qc.compare("step", {"paper": "nlpd", "mine": mine}, duration=3.0)
    np.testing.assert_array_equal(cmp.results["paper"].states, cmp.results["mine"].states)
    mc = montecarlo("hover", mine, n=2, duration=0.5)
    assert mc.n == 2 and mc.spec.controller is mine
    with pytest.raises(qc.InputError, match="ControllerLike"):
        qc.fly("step", object())


@pytest.mark.parametrize(
    "call,name",
    [
        (lambda: qc.fly("hover", sede=1), "fly()"),
        (lambda: qc.compare("hover", sede=1), "compare()"),
        (lambda: montecarlo("hover", n=1, sede=1), "montecarlo()"),
    ],
)
def test_a_misspelt_keyword_is_named_with_the_choices(call, name):
    with pytest.raises(qc.InputError) as err:
        call()
    message = str(err.value)
    assert message.startswith(f"{name} has no option 'sede'") and "did you mean 'seed'" in message
    assert "\n" not in message


def test_a_sensor_delay_is_a_time_whatever_the_flight_dt():
    noise = SensorNoise(delay=0.004)
    assert engine_inputs(None, noise, 1, 1e-3)["sensor_delay"] == 4
    assert engine_inputs(None, noise, 1, 2e-3)["sensor_delay"] == 2
    # flown: the same delay at 2 ms is not the 8 ms one
    four = qc.fly("step", dt=2e-3, duration=3.0, sensors=noise)
    eight = qc.fly("step", dt=2e-3, duration=3.0, sensors=SensorNoise(delay=0.008))
    assert not np.array_equal(four.states, eight.states)


def test_environment_and_seed_reach_every_workflow():
    env = Environment(turbulence=Turbulence(intensity="moderate"))
    vehicle = with_drag(qc.Vehicle.paper())
    a = qc.fly("hover", vehicle=vehicle, duration=1.0, environment=env, seed=1)
    b = qc.fly("hover", vehicle=vehicle, duration=1.0, environment=env, seed=1)
    c = qc.fly("hover", vehicle=vehicle, duration=1.0, environment=env, seed=2)
    np.testing.assert_array_equal(a.states, b.states)
    assert not np.array_equal(a.states, c.states) and a.meta["seed"] == 1
    cmp = qc.compare("hover", ["nlpd"], vehicle=vehicle, duration=1.0, environment=env, seed=1)
    np.testing.assert_array_equal(cmp.results["nlpd"].states, a.states)
    mc = montecarlo("hover", n=2, seed=1, duration=0.5, environment=env, vehicle=vehicle)
    assert mc.spec.population.environment == env
    with pytest.raises(qc.InputError, match="not both"):
        montecarlo("hover", population=Population(environment=env), n=1, environment=env)


def test_every_result_speaks_one_vocabulary(tmp_path):
    flight = qc.fly("step", duration=2.0)
    cmp = qc.compare("step", ["nlpd", "se3"], duration=2.0)
    mc = montecarlo("hover", n=3, duration=0.5)
    for i, result in enumerate((flight, cmp, mc)):
        assert isinstance(result, ResultLike)
        assert isinstance(result.to_pandas(), pd.DataFrame) and len(result.to_pandas()) > 0
        summary = result.summary()
        assert isinstance(summary, Summary) and len(summary) > 0
        text = str(summary)
        assert "{" not in text and len(text.splitlines()) >= 2  # a table, not a raw dict
        assert hasattr(result.plot(), "savefig")
        folder = result.write(tmp_path / f"r{i}")
        assert (folder / "quadcruise.json").is_file()
    assert isinstance(mc, MonteCarloResult) and mc.summary()["flights"] == 3
    assert flight.summary()["status"] == {"finished": 1}
