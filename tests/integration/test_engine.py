"""The engine: accuracy (RK4 order, agreement with solve_ivp), batching, divergence."""

import numpy as np
import pytest
from scipy.integrate import solve_ivp

import quadcruise as qc
from quadcruise.control.openloop import duty_schedule, pack_schedule
from quadcruise.disturbances import CustomDisturbance, SensorNoise
from quadcruise.layout import F1, STATE_SIZE, X, Z
from quadcruise.workflows.fly_inputs import hover_state
from quadcruise.workflows.replay import no_reference
from support.reference_model import rhs

V = qc.Vehicle.paper()


def wobbly_schedule(duration=4.0, rate=50.0, seed=3):
    """Hover duties with small random differential and collective changes."""
    rng = np.random.default_rng(seed)
    t = np.arange(0.0, duration + 1e-9, 1.0 / rate)
    h = V.hover_duty
    u = h + 0.002 * rng.standard_normal((t.size, 4)) + 0.003 * np.sin(t)[:, None]
    return qc.DutySchedule(t=t, duties=u)


def solve_ivp_replay(schedule, **vehicle):
    """Integrate the reference model interval by interval with DOP853, rtol 1e-10."""
    x = np.zeros(STATE_SIZE)
    x[12:] = vehicle.get("K", 120.0) * schedule.duties[0]
    out = [x.copy()]
    for k in range(len(schedule.t) - 1):
        u = schedule.duties[k]
        sol = solve_ivp(
            lambda _t, s: rhs(s, u, **vehicle),  # noqa: B023 - called here
            (schedule.t[k], schedule.t[k + 1]),
            x,
            method="DOP853",
            rtol=1e-10,
            atol=1e-12,
        )
        x = sol.y[:, -1]
        out.append(x.copy())
    return np.array(out)


def test_replay_matches_solve_ivp_to_a_micrometre():
    schedule = wobbly_schedule()
    res = qc.replay(schedule)
    ref = solve_ivp_replay(schedule)
    assert res.ok[0]
    moved = np.max(np.abs(ref[:, :3]))
    assert moved > 0.05, "the test flight should go somewhere"
    err = np.max(np.abs(res.states[0, :, :3] - ref[:, :3]))
    assert err < 1e-6, err
    np.testing.assert_allclose(res.states[0, :, 6:9], ref[:, 6:9], atol=1e-7)


def test_rk4_error_falls_sixteen_fold_when_step_halves():
    schedule = wobbly_schedule(duration=2.0, rate=10.0)
    exact = qc.replay(schedule, max_step=0.02 / 32).final_state[0]
    e1 = np.abs(qc.replay(schedule, max_step=0.02).final_state[0] - exact)
    e2 = np.abs(qc.replay(schedule, max_step=0.01).final_state[0] - exact)
    ratio = np.linalg.norm(e1[:6]) / np.linalg.norm(e2[:6])
    assert 14.0 < ratio < 18.0, ratio


def test_turned_angles_equal_the_library_sine_and_cosine():
    import math

    from quadcruise.sim.fastmath import SHORT_TURN, SMALL_TURN, turned

    rng = np.random.default_rng(3)
    worst = 0.0
    for a, d in zip(
        rng.uniform(-4.0, 4.0, 2000), rng.uniform(-SMALL_TURN, SMALL_TURN, 2000) ** 3 / SMALL_TURN**2, strict=False
    ):
        s, c = turned(a + d, math.sin(a), math.cos(a), d)
        worst = max(worst, abs(s - math.sin(a + d)), abs(c - math.cos(a + d)))
    assert worst < 5e-16, worst
    for d in (SMALL_TURN, -SMALL_TURN, SHORT_TURN, -SHORT_TURN):  # each series' edge: its
        s, c = turned(1.0 + d, math.sin(1.0), math.cos(1.0), d)  # largest truncation
        assert abs(s - math.sin(1.0 + d)) < 5e-16 and abs(c - math.cos(1.0 + d)) < 5e-16
    # a larger turn than the series covers: the library's values exactly
    assert turned(2.5, 0.0, 1.0, 0.5) == (math.sin(2.5), math.cos(2.5))


def test_rk4_step_equals_four_plain_derivative_calls():
    """The step that carries sines and cosines between stages, and from one step to the
    next, is the classical RK4 of the plant's derivative, to rounding, on a tumbling vehicle
    (fast rates use the library) as well as on slow turns."""
    import math

    from quadcruise.layout import EXT_E1, EXT_SIZE, PHI, PSI, THETA, P
    from quadcruise.model.plant import derivative
    from quadcruise.sim.engine import TRIG, WORK_ROWS, rk4_step

    vp = V.rows(1)[0]
    ext = np.zeros(EXT_SIZE)
    ext[EXT_E1 : EXT_E1 + 4] = 1.0
    u = np.array([0.9, 0.1, 0.6, 0.3])
    for rates in ((0.3, -0.2, 0.1), (40.0, -25.0, 3.0)):  # slow turns, and a tumble
        x = np.zeros(STATE_SIZE)
        x[PHI : PHI + 3], x[P : P + 3], x[F1:] = (0.2, -0.4, 2.0), rates, 5.0
        y, h, k = x.copy(), 2e-3, [np.empty(STATE_SIZE) for _ in range(4)]
        work = np.empty((WORK_ROWS, STATE_SIZE))
        for i in range(200):
            rk4_step(x, u, vp, ext, True, h, work, i == 0)  # trig computed afresh once
            derivative(y, u, vp, ext, True, k[0])
            derivative(y + 0.5 * h * k[0], u, vp, ext, True, k[1])
            derivative(y + 0.5 * h * k[1], u, vp, ext, True, k[2])
            derivative(y + h * k[2], u, vp, ext, True, k[3])
            y = y + h / 6.0 * (k[0] + 2.0 * (k[1] + k[2]) + k[3])
        np.testing.assert_allclose(x, y, rtol=1e-11, atol=1e-11)
        # the carried sines and cosines are those of the final angles
        exact = [f(x[j]) for j in (PHI, THETA, PSI) for f in (math.sin, math.cos)]
        np.testing.assert_allclose(work[TRIG, :6], exact, rtol=0, atol=1e-14)


def test_batch_equals_one_by_one():
    masses = np.array([3.0, 3.499, 3.8, 4.2, 2.5])
    jzz = np.array([0.04, 0.05, 0.035, 0.04, 0.045])
    schedule = wobbly_schedule(duration=2.0)
    batch = qc.replay(schedule, vehicle=qc.Vehicle(m=masses, Jzz=jzz))
    assert batch.n == 5
    for i in range(5):
        single = qc.replay(schedule, vehicle=qc.Vehicle(m=masses[i], Jzz=jzz[i]))
        np.testing.assert_allclose(batch.states[i], single.states[0], rtol=0, atol=1e-12)
    # and different vehicles really flew differently
    assert np.ptp(batch.final_state[:, Z]) > 0.1


def test_batched_initial_states_and_schedules_through_simulate():
    schedule = wobbly_schedule(duration=1.0)
    gains = pack_schedule(schedule.t, schedule.duties)
    x0 = np.zeros((3, STATE_SIZE))
    x0[:, F1:] = V.K * schedule.duties[0]
    x0[:, X] = [0.0, 1.0, -2.0]
    res = qc.simulate(schedule.t, x0, V.rows(3), duty_schedule, gains, no_reference, np.zeros(1), memory=np.zeros(1))
    np.testing.assert_allclose(res.states[1, :, X] - res.states[0, :, X], 1.0, atol=1e-12)
    np.testing.assert_allclose(res.states[2, :, X] - res.states[0, :, X], -2.0, atol=1e-12)


def test_decimated_logging_keeps_every_kth_instant():
    schedule = wobbly_schedule(duration=1.0)
    gains = pack_schedule(schedule.t, schedule.duties)
    x0 = np.zeros(STATE_SIZE)
    x0[F1:] = V.K * schedule.duties[0]
    args = (schedule.t, x0, V.rows(), duty_schedule, gains, no_reference, np.zeros(1))
    full = qc.simulate(*args, memory=np.zeros(1))
    every5 = qc.simulate(*args, memory=np.zeros(1), log_every=5)
    assert every5.states.shape[1] == (len(schedule.t) - 1) // 5 + 1
    np.testing.assert_array_equal(every5.states[0], full.states[0, ::5])
    np.testing.assert_array_equal(every5.t, full.t[::5])
    np.testing.assert_array_equal(every5.final_state, full.final_state)


def test_divergence_stops_the_vehicle_and_says_why_and_when():
    # one rotor at full power, the opposite one off: the vehicle spins up in pitch
    t = np.linspace(0, 10, 1001)
    u = np.tile([1.0, 0.07, 0.0, 0.07], (t.size, 1))
    res = qc.replay(qc.DutySchedule(t=t, duties=u), limits=qc.Limits(max_rate=50.0))
    assert not res.ok[0]
    assert res.status[0] == 4
    assert 0 < res.t_stop[0] < 10
    assert "body rate" in res.status_text(0) and "t = " in res.status_text(0)
    stop = np.searchsorted(res.t, res.t_stop[0])
    assert np.all(np.isnan(res.states[0, stop + 1 :]))
    assert np.all(np.isfinite(res.states[0, : stop + 1]))


@pytest.mark.parametrize("log_every", [1, 3])
def test_rows_after_a_stop_are_nan_and_the_rest_of_the_batch_flies_on(log_every):
    t = np.linspace(0, 10, 1001)
    spin = np.tile([1.0, 0.07, 0.0, 0.07], (t.size, 1))
    hover = np.tile(V.hover_duty * np.ones(4), (t.size, 1))
    grid = np.linspace(0, 10, 1001)
    mission = qc.missions.Hover()
    x0 = hover_state(V, 2, mission)
    gains = np.stack([pack_schedule(t, spin), pack_schedule(t, hover)])
    res = qc.simulate(
        grid,
        x0,
        V.rows(2),
        duty_schedule,
        gains,
        mission.function,
        mission.params(),
        memory=np.zeros(1),
        log_every=log_every,
        limits=qc.Limits(max_rate=50.0),
    )
    assert list(res.ok) == [False, True]
    last = int(np.searchsorted(res.t, res.t_stop[0], side="right"))  # rows up to the stop
    for log in (res.states, res.commands[..., :4], res.references):
        assert np.all(np.isnan(log[0, last:]))
        assert np.all(np.isfinite(log[1]))
    assert np.all(np.isfinite(res.commands[0, : last - 1, :4]))
    assert np.all(np.isfinite(res.states[0, : last - 1]))


@pytest.mark.parametrize(
    "limit, status",
    [
        (dict(max_position=0.5), 2),
        (dict(max_speed=0.3), 3),
        (dict(max_rate=0.05), 4),
        (dict(max_tilt=0.01), 5),
    ],
)
def test_each_bound_stops_the_flight_with_its_own_status(limit, status):
    with pytest.warns(UserWarning, match="diverged"):
        res = qc.fly("step", duration=5.0, limits=qc.Limits(**limit))
    assert res.status[0] == status, res.status_text(0)
    assert 0 < res.t_stop[0] < 5.0


def test_a_nonfinite_state_stops_the_flight():
    from numba import njit

    from quadcruise.layout import DISTURBANCE_SIG, EXT_E1, EXT_FX, EXT_SIZE

    @njit(DISTURBANCE_SIG)
    def poisoned(t, dt, x, dp, dmem, rng, ext):
        for j in range(EXT_SIZE):
            ext[j] = 1.0 if j >= EXT_E1 else 0.0
        if t >= 0.25:
            ext[EXT_FX] = np.inf

    with pytest.warns(UserWarning, match="non-finite"):
        res = qc.fly("hover", duration=1.0, environment=CustomDisturbance(poisoned))
    assert res.status[0] == 1 and res.t_stop[0] == pytest.approx(0.251)
    assert "non-finite" in res.status_text(0)


def test_threads_and_pieces_do_not_change_a_batch():
    """The kernel flies a batch in pieces on numba's threads; any split gives the same
    flights, noisy and turbulent ones included (each vehicle draws from its own stream)."""
    import numba

    from quadcruise.disturbances import Environment, Turbulence
    from quadcruise.sim import engine

    masses = np.linspace(3.0, 4.0, 37)
    drag = dict(drag_linear=0.1, drag_quadratic=0.05)  # so that the turbulence acts
    vehicle = qc.Vehicle(m=masses, **drag)
    env = Environment(turbulence=Turbulence(intensity="severe", altitude=10.0))
    noise = SensorNoise(position_std=1e-3, velocity_std=1e-3, angle_std=1e-3, rate_std=1e-3)
    kw = dict(vehicle=vehicle, duration=1.0, sensors=noise, seed=4, environment=env)
    threads = numba.get_num_threads()
    try:
        numba.set_num_threads(1)
        one = qc.fly("circle", **kw)
        numba.set_num_threads(numba.config.NUMBA_NUM_THREADS)
        pieces, engine.PIECES_PER_THREAD = engine.PIECES_PER_THREAD, 5
        many = qc.fly("circle", **kw)
    finally:
        numba.set_num_threads(threads)
        engine.PIECES_PER_THREAD = pieces
    # what each vehicle carries through the flight (its controller's integrators, its
    # turbulence filters, its time in saturation) is its own, in any split
    ends = ("states", "commands", "memory", "disturbance_memory", "duty_clipped_s", "controller_limited_s")
    for name in ends:
        np.testing.assert_array_equal(getattr(one, name), getattr(many, name), err_msg=name)
    single = qc.fly("circle", **(kw | dict(vehicle=qc.Vehicle(m=masses[20], **drag), first_vehicle=20)))
    for name in ends:
        np.testing.assert_array_equal(getattr(single, name)[0], getattr(many, name)[20], err_msg=name)
    assert np.ptp(many.final_state[:, Z]) > 0.0
    assert np.all(many.memory != 0.0) and np.all(np.any(many.disturbance_memory != 0.0, axis=1))


def test_nonfinite_controller_command_stops_cleanly():
    from numba import njit

    from quadcruise.layout import CONTROLLER_SIG

    @njit(CONTROLLER_SIG)
    def broken(t, dt, x, ref, vp, gains, mem, cmd):
        for j in range(4):
            cmd[j] = np.nan if t >= 0.5 else 0.1

    res = qc.simulate(
        np.linspace(0, 1, 11), np.zeros(STATE_SIZE), V.rows(), broken, np.zeros(0), no_reference, np.zeros(1)
    )
    assert res.status[0] == 6 and res.t_stop[0] == pytest.approx(0.5)
    assert "non-finite command" in res.status_text(0)


def test_user_controller_plugs_in_and_engine_clips_and_reports_duties():
    from numba import njit

    from quadcruise.layout import CONTROLLER_SIG

    @njit(CONTROLLER_SIG)
    def too_much(t, dt, x, ref, vp, gains, mem, cmd):
        for j in range(4):
            cmd[j] = 1.5

    res = qc.simulate(
        np.linspace(0, 1, 101), np.zeros(STATE_SIZE), V.rows(), too_much, np.zeros(0), no_reference, np.zeros(1)
    )
    assert res.duty_clipped_s[0] == pytest.approx(1.0)
    assert res.final_state[0, F1] < V.K * 1.0 + 1e-9  # the plant saw duty 1, not 1.5


@pytest.mark.parametrize(
    "kwargs, words",
    [
        ({"max_step": 0.0}, "max_step"),
        ({"log_every": 0}, "log_every"),
    ],
)
def test_bad_engine_options(kwargs, words):
    schedule = wobbly_schedule(duration=0.2)
    gains = pack_schedule(schedule.t, schedule.duties)
    with pytest.raises(qc.InputError, match=words):
        qc.simulate(
            schedule.t,
            np.zeros(STATE_SIZE),
            V.rows(),
            duty_schedule,
            gains,
            no_reference,
            np.zeros(1),
            memory=np.zeros(1),
            **kwargs,
        )


def test_time_grid():
    g = qc.time_grid(1.0, 0.001)
    assert g.shape == (1001,) and g[-1] == pytest.approx(1.0)
    with pytest.raises(qc.InputError, match="larger than the duration"):
        qc.time_grid(0.1, 0.2)
    with pytest.raises(qc.InputError, match="duration"):
        qc.time_grid(-1.0, 0.01)
