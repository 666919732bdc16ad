"""An exception raised in a compiled controller, mission or disturbance reaches the caller on
every path the engine flies (issue 31): ``qc.simulate``, ``fly`` with its whole log and on its
chunked, watched path, ``Stepper.step``, the rotor plant, a Gymnasium step, a Monte Carlo chunk
on Dask; the same functions without the raise fly to the end, finished. A batched flight in a
process leaves a child made by ``fork`` able to fly its own batch."""

import os
import subprocess
import sys
import warnings
from pathlib import Path

import numpy as np
import pytest

import quadcruise as qc
from quadcruise.errors import LogWarning
from quadcruise.workflows import fly_inputs
from quadcruise.workflows.stepwise import stepper
from support.raising import MESSAGE, Law, RaisingHover, raising_environment

QUIET = dict(duration=1.0)  # the raise comes at 0.5 s


def fly_quietly(*args, **kw):
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        return qc.fly(*args, **kw)


@pytest.fixture
def chunked(monkeypatch):
    """fly takes its watched, chunked path (a batch over the log budget) for any batch."""
    monkeypatch.setattr(fly_inputs, "LOG_BUDGET", 1)


def test_simulate():
    law, hover = Law(), qc.missions.Hover()
    args = (qc.time_grid(1.0, 1e-3), np.zeros(16), qc.Vehicle.paper().rows(2))
    with pytest.raises(ValueError, match=MESSAGE):
        qc.simulate(*args, law.function, law.gains(), hover.function, hover.params(), memory=law.memory())
    calm = Law(raising=False)
    res = qc.simulate(*args, calm.function, calm.gains(), hover.function, hover.params(), memory=calm.memory())
    assert res.status.tolist() == [0, 0]


@pytest.mark.parametrize("n", [1, 8])
def test_fly_whole_log(n):
    with pytest.raises(ValueError, match=MESSAGE):
        fly_quietly("hover", Law(), n=n, log_every=1, **QUIET)
    assert fly_quietly("hover", Law(raising=False), n=n, log_every=1, **QUIET).ok.all()


def test_fly_chunked(chunked):
    with pytest.raises(ValueError, match=MESSAGE):
        fly_quietly("hover", Law(), n=8, **QUIET)
    with pytest.warns(LogWarning):
        res = qc.fly("hover", Law(raising=False), n=8, **QUIET)
    assert res.meta.get("log_every_chosen") and res.ok.all()  # it did take the chunked path


@pytest.mark.parametrize("path", ["whole", "chunked"])
def test_mission_and_disturbance(path, monkeypatch):
    if path == "chunked":
        monkeypatch.setattr(fly_inputs, "LOG_BUDGET", 1)
    with pytest.raises(ValueError, match=MESSAGE):
        fly_quietly(RaisingHover(), "nlpd", n=4, **QUIET)
    with pytest.raises(ValueError, match=MESSAGE):
        fly_quietly("hover", "nlpd", n=4, environment=raising_environment(), **QUIET)
    assert fly_quietly(qc.missions.Hover(), "nlpd", n=4, **QUIET).ok.all()


@pytest.mark.parametrize("vehicle", [None, "crazyflie"])
def test_stepper(vehicle):
    for raising in (True, False):
        s = stepper("hover", Law(raising), vehicle=vehicle, n=3, periods=100, **QUIET)
        for _ in range(5):  # the periods before 0.5 s: no raise yet
            s.step()
        assert s.status.tolist() == [0, 0, 0]
        if raising:
            with pytest.raises(ValueError, match=MESSAGE):
                s.step()
        else:
            for _ in range(5):
                s.step()
            assert s.done.all() and s.status.tolist() == [0, 0, 0]


def test_rotor_plant_fly():
    with pytest.raises(ValueError, match=MESSAGE):
        fly_quietly("hover", Law(), vehicle="crazyflie", n=2, **QUIET)
    assert fly_quietly("hover", Law(raising=False), vehicle="crazyflie", n=2, **QUIET).ok.all()


def test_gym_step():
    pytest.importorskip("gymnasium")
    from quadcruise.gym.env import QuadEnv

    for raising in (True, False):
        env = QuadEnv(controller=Law(raising), **QUIET)
        env.reset(seed=0)
        steps = 0
        try:
            while True:
                _, _, terminated, truncated, _ = env.step(None)
                steps += 1
                assert not terminated
                if truncated:
                    break
        except ValueError as exc:
            assert raising and MESSAGE in str(exc)
            assert steps > 0  # it flew until the raise
        else:
            assert not raising


def test_sweep_in_process():
    from quadcruise.montecarlo import montecarlo

    with pytest.raises(ValueError, match=MESSAGE):
        montecarlo("hover", Law(), None, 4, scheduler="none", chunk_size=2, **QUIET)
    res = montecarlo("hover", Law(raising=False), None, 4, scheduler="none", chunk_size=2, **QUIET)
    assert (res.metrics()["status"] == 0).all()


def test_dask_sweep(tmp_path):
    distributed = pytest.importorskip("distributed")
    from quadcruise.montecarlo import montecarlo

    with distributed.LocalCluster(
        n_workers=1, threads_per_worker=1, processes=True, dashboard_address=":0", env={"NUMBA_NUM_THREADS": "1"}
    ) as cluster:
        address = cluster.scheduler_address
        with pytest.raises(ValueError, match=MESSAGE):
            montecarlo("hover", Law(), None, 4, scheduler=address, chunk_size=2, **QUIET)
        res = montecarlo("hover", Law(raising=False), None, 4, scheduler=address, chunk_size=2, **QUIET)
    assert (res.metrics()["status"] == 0).all()


@pytest.mark.skipif(not hasattr(os, "fork"), reason="os.fork is POSIX")
def test_a_forked_child_flies_its_own_batch():
    script = Path(__file__).parents[1] / "support" / "fork_child.py"
    env = dict(os.environ, NUMBA_NUM_THREADS="2")  # a batch on two threads: the helper pool at work
    out = subprocess.run(
        [sys.executable, "-W", "ignore", str(script), "60"], env=env, capture_output=True, text=True, timeout=400
    )
    assert out.returncode == 0, out.stderr[-2000:]
    assert out.stdout.split("\n")[:2] == ["os.fork 0", "multiprocessing 0"]
