"""``qc.simulate`` flies both plants (issue 31): with the rotor plant's arrays (``alloc``) it is
``fly_rotor_vehicles`` and the Stepper bit for bit; without them the paper engine, bit for bit;
what does not fit the plant is one line naming the argument."""

from __future__ import annotations

import numpy as np
import pytest

import quadcruise as qc
from quadcruise.control import controller_from_name
from quadcruise.errors import InputError
from quadcruise.layout import F1, P_G, P_M, PARAM_SIZE, Z
from quadcruise.missions import Circle
from quadcruise.sim import engine
from quadcruise.sim.plants import ROTOR
from quadcruise.sim.rotor_batch import fly_rotor_vehicles
from quadcruise.sim.stepper import Stepper
from quadcruise.workflows.rotor_fly import flight_setup

DT, DURATION, N = 2e-3, 0.4, 3


def rotor_arrays(name: str = "iris"):
    """The arrays fly builds for a rotor-plant flight (the plant's own ``flight``)."""
    vehicle, mission = qc.Vehicle.preset(name), Circle(radius=1.0, period=4.0, yaw=2.0)
    _, ctrl = flight_setup(vehicle, None, "se3")
    grid = qc.time_grid(DURATION, DT)
    mp = np.tile(mission.params(), (N, 1))
    args, own = ROTOR.flight(
        grid, vehicle, None, ctrl.function, ctrl.gains(), mission, mp, N, x0=None, paper_x0=None, meta=None
    )
    return args, own


def test_a_rotor_flight_through_simulate_is_fly_rotor_vehicles_and_the_stepper():
    args, own = rotor_arrays()
    t, x0, rp, function, gains, mission, mp = args
    kw = dict(max_step=5e-4, seed=3)
    ours = qc.simulate(*args, **own, **kw)
    direct = fly_rotor_vehicles(t, x0, rp, own["alloc"], own["vp_ctrl"], function, gains, mission, mp,
                                psi0=own["psi0"], touchdown_speed=own["touchdown_speed"],
                                rotor_names=own["rotor_names"], **kw)  # fmt: skip
    assert ours.rotor_states is not None and ours.rotor_states.shape == (N, t.size, 17)
    assert ours.ok.all()
    for name in ("states", "commands", "references", "rotor_states", "memory", "duty_clipped_s"):
        assert np.array_equal(getattr(ours, name), getattr(direct, name), equal_nan=True), name
    assert ours.rotor_names == direct.rotor_names

    s = Stepper(t, x0, rp, function, gains, mission, mp, vp_ctrl=own["vp_ctrl"], alloc=own["alloc"],
                psi0=own["psi0"], touchdown_speed=own["touchdown_speed"], **kw)  # fmt: skip
    while not s.done.all():
        s.step()
    assert np.array_equal(s.state, ours.rotor_states[:, -1])


def test_a_paper_flight_through_simulate_is_the_engine_bit_for_bit():
    vehicle, mission, ctrl = qc.Vehicle.paper(), Circle(), controller_from_name("nlpd")
    vp = vehicle.rows(2)
    x0 = np.zeros(16)
    x0[Z], x0[F1 : F1 + 4] = 1.0, vp[0, P_M] * vp[0, P_G] / 4  # hovering
    args = (qc.time_grid(0.3, 1e-3), x0, vp, ctrl.function, ctrl.gains(), mission.function, mission.params())
    kw = dict(seed=1, memory=ctrl.memory())  # nlpd's integrators
    ours, theirs = qc.simulate(*args, **kw), engine.simulate(*args, **kw)
    for name in ("states", "commands", "references", "status", "t_stop", "memory", "duty_clipped_s"):
        assert np.array_equal(getattr(ours, name), getattr(theirs, name), equal_nan=True), name
    assert ours.rotor_states is None


@pytest.mark.parametrize(
    ("change", "named"),
    [
        (lambda a, o: (a[:2] + (np.zeros((N, PARAM_SIZE)),) + a[3:], o), "argument vp: shape (3, 21)"),
        (lambda a, o: (a[:1] + (np.zeros(16),) + a[2:], o), "argument x0: shape (16,)"),
        (lambda a, o: (a, {**o, "vp_ctrl": None}), "argument vp_ctrl is needed"),
        (lambda a, o: (a, {**o, "vp_ctrl": np.zeros(7)}), "argument vp_ctrl: shape (7,)"),
        (lambda a, o: (a, {**o, "alloc": np.zeros(10)}), "argument alloc: shape (10,)"),
        (lambda a, o: (a, {**o, "full_dynamics": True}), "argument full_dynamics: not for a rotor-plant vehicle"),
    ],
)
def test_rotor_arrays_that_do_not_fit_are_one_line_naming_the_argument(change, named):
    args, own = change(*rotor_arrays())
    with pytest.raises(InputError) as e:
        qc.simulate(*args, **own)
    assert str(e.value).startswith("simulate() ") and named in str(e.value) and "\n" not in str(e.value)


@pytest.mark.parametrize("option", ["psi0", "touchdown_speed", "rotor_names"])
def test_the_rotor_plants_own_options_are_refused_on_the_paper_plant(option):
    vehicle, mission, ctrl = qc.Vehicle.paper(), Circle(), controller_from_name("nlpd")
    args = (
        qc.time_grid(0.01, 1e-3),
        np.zeros(16),
        vehicle.rows(1),
        ctrl.function,
        ctrl.gains(),
        mission.function,
        mission.params(),
    )
    with pytest.raises(InputError, match=rf"^simulate\(\) argument {option}: the rotor plant's \(give alloc"):
        qc.simulate(*args, **{option: 0.0})


def test_a_law_given_no_memory_stops_with_a_bad_command_and_with_its_memory_flies():
    """memory=None hands the law a NaN row (sim.inputs.MEMORY_GUARD): nlpd, which keeps three
    values, stops at t = 0 with a non-finite command, the same on every run (it read past an empty
    row before: numbers that changed from run to run); with its memory it flies the circle."""
    from quadcruise.control import NLPD
    from quadcruise.missions import Circle
    from quadcruise.model.vehicle import Vehicle
    from quadcruise.sim.inputs import time_grid

    t, c, m, v = time_grid(0.5, 1e-3), NLPD(), Circle(), Vehicle.paper()
    x0 = np.zeros(16)
    x0[2], x0[12:] = 1.0, v.m * v.g / 4
    args = (t, x0, v.rows(1), c.function, c.gains(), m.function, m.params())
    for _ in range(2):
        r = qc.simulate(*args)
        assert r.status.tolist() == [int(qc.ExitStatus.BAD_COMMAND)] and r.t_stop.tolist() == [0.0]
    assert qc.simulate(*args, memory=c.memory()).status.tolist() == [int(qc.ExitStatus.FINISHED)]
