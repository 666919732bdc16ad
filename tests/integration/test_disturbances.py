"""Disturbance models: constant wind through drag, the 1 - cosine gust, Dryden turbulence
(variance, correlation, exact discretisation, seeding), rotor loss, closed-loop flights with
the paper's controller, sensor noise, parsing and input checks."""

import math
import warnings

import numpy as np
import pytest
from numba import njit
from scipy.integrate import quad

import quadcruise as qc
from quadcruise.cli.wind import parse_wind, wind_from_name
from quadcruise.control.openloop import duty_schedule, pack_schedule
from quadcruise.disturbances import (
    DEFAULT_DRAG,
    ConstantWind,
    Environment,
    ExternalForce,
    Gust,
    RotorLoss,
    SensorNoise,
    Turbulence,
    with_drag,
)
from quadcruise.disturbances.environment import MEMORY_SIZE, PARAMS_SIZE
from quadcruise.disturbances.turbulence import lateral_coefficients
from quadcruise.layout import EXT_E1, EXT_FX, EXT_SIZE, EXT_TX, EXT_WX, F1, PHI, PSI, STATE_SIZE, THETA, VX, VY, X, Y, Z
from quadcruise.missions import Circle, Hover
from quadcruise.sim.rng import vehicle_states
from quadcruise.workflows.replay import no_reference

V = qc.Vehicle.paper()


def quiet_drag(vehicle=V):
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        return with_drag(vehicle)


def ext_history(env, times, dt, n=1, seed=0):
    """What env.function writes at each time (called directly from Python), (n, T, EXT_SIZE)."""
    dp, dm, rng = env.params(n), env.memory(n), vehicle_states(seed, n)
    x, out = np.zeros(STATE_SIZE), np.empty((n, len(times), EXT_SIZE))
    for i in range(n):
        for k, t in enumerate(times):
            env.function(float(t), dt, x, dp[i], dm[i], rng[i], out[i, k])
    return out


@njit
def _wind_run(f, steps, dt, dp, dm, rng, out):
    x, ext = np.zeros(STATE_SIZE), np.zeros(EXT_SIZE)
    for i in range(dp.shape[0]):
        for k in range(steps):
            f(k * dt, dt, x, dp[i], dm[i], rng[i], ext)
            for j in range(3):
                out[i, k, j] = ext[EXT_WX + j]


def wind_run(env, n, steps, dt, seed=0, first=0):
    out = np.empty((n, steps, 3))
    _wind_run(env.function, steps, dt, env.params(n), env.memory(n), vehicle_states(seed, n, first), out)
    return out


def open_loop(vehicle, env, n=1, duration=10.0, dt=0.01, limits=None):
    """Level vehicle at the hover duties, open loop (no controller)."""
    grid = qc.time_grid(duration, dt)
    gains = pack_schedule(grid[[0, -1]], np.full((2, 4), float(V.hover_duty)))
    x0 = np.zeros((n, STATE_SIZE))
    x0[:, F1:] = V.m * V.g / 4
    return grid, qc.simulate(
        grid,
        x0,
        vehicle.rows(n),
        duty_schedule,
        gains,
        no_reference,
        np.zeros(1),
        memory=np.zeros(1),
        limits=limits,
        **env.kwargs(n),
    )


# --- constant wind -----------------------------------------------------------------------
def test_constant_wind_with_linear_drag_gives_the_exponential_approach():
    c = 1.5
    grid, res = open_loop(V.replace(drag_linear=c), Environment(wind=ConstantWind((3.0, -1.0, 0.0))))
    lag = 1 - np.exp(-c * grid / V.m)  # vx' = c (w - vx) / m
    np.testing.assert_allclose(res.states[0, :, VX], 3.0 * lag, atol=1e-6)
    np.testing.assert_allclose(res.states[0, :, VY], -1.0 * lag, atol=1e-6)


def test_per_vehicle_wind_speeds_give_different_flights_in_one_batch():
    c, speeds = 1.5, np.array([1.0, 2.0, 4.0])
    env = Environment(wind=ConstantWind((speeds, 0.0, 0.0)))
    assert env.batch_size == 3 and env.params().shape == (3, PARAMS_SIZE)
    grid, res = open_loop(V.replace(drag_linear=c), env, n=3)
    np.testing.assert_allclose(res.states[:, :, VX], speeds[:, None] * (1 - np.exp(-c * grid / V.m)), atol=1e-6)
    # an (N, 3) array gives one row per vehicle
    rows = Environment(wind=ConstantWind(np.column_stack([speeds, np.zeros(3), np.zeros(3)])))
    np.testing.assert_array_equal(rows.params(), env.params())


def test_empty_environment_is_still_air_bit_for_bit():
    a = qc.fly("step", n=2, duration=3.0)
    b = qc.fly("step", n=2, duration=3.0, environment=Environment())
    np.testing.assert_array_equal(a.states, b.states)


def test_external_force_and_torque():
    out = ext_history(Environment(force=ExternalForce((1.0, 2.0, 3.0), (0.1, 0.2, 0.3))), [0.0], 0.01)[0, 0]
    np.testing.assert_array_equal(out[EXT_FX : EXT_TX + 3], [1, 2, 3, 0.1, 0.2, 0.3])
    np.testing.assert_array_equal(out[EXT_E1:], 1.0)


# --- gust --------------------------------------------------------------------------------
def test_gust_follows_one_minus_cosine_at_the_sample_times():
    dt, amp, start, dur = 0.01, np.array([2.0, -1.0, 0.5]), 5.0, 2.0
    env = Environment(wind=ConstantWind((1.0, 0.0, 0.0)), gust=Gust(amp, start=start, duration=dur))
    t = np.arange(0.0, 10.0, dt)
    wind = ext_history(env, t, dt)[0, :, EXT_WX : EXT_WX + 3]
    s = t - start
    shape = np.where((s >= 0) & (s <= dur), 0.5 * (1 - np.cos(2 * np.pi * s / dur)), 0.0)
    np.testing.assert_allclose(wind, [1.0, 0.0, 0.0] + shape[:, None] * amp, atol=1e-12)
    peak = np.argmax(wind[:, 0])
    assert t[peak] == pytest.approx(start + dur / 2) and wind[peak, 0] == pytest.approx(3.0)
    assert np.all(wind[t < start, 0] == 1.0) and np.all(wind[t > start + dur, 0] == 1.0)


def test_gust_pushes_a_vehicle_with_drag_as_the_held_wind_predicts():
    c, dt = 1.0, 0.01
    env = Environment(gust=Gust((2.0, 0, 0), start=1.0, duration=1.0))
    grid, res = open_loop(V.replace(drag_linear=c), env, duration=4.0, dt=dt)
    # level, linear drag, wind w_k held over each period: vx_{k+1} = w_k + (vx_k - w_k) e^{-c dt/m}
    w, vx, decay = ext_history(env, grid[:-1], dt)[0, :, EXT_WX], [0.0], math.exp(-c * dt / V.m)
    for wk in w:
        vx.append(wk + (vx[-1] - wk) * decay)
    np.testing.assert_allclose(res.states[0, :, VX], vx, atol=1e-6)
    assert np.all(res.states[0, grid <= 1.0, VX] == 0.0) and res.states[0, -1, VX] > 0.1


# --- Dryden turbulence -------------------------------------------------------------------
def test_dryden_intensities_and_scales_follow_mil_f_8785c():
    tb = Turbulence(intensity="moderate", altitude=100 * 0.3048)  # h = 100 ft
    q = 0.177 + 0.000823 * 100
    su, sv, sw = tb.sigmas()
    assert sw == pytest.approx(0.1 * 30 * 0.514444) and su == sv == pytest.approx(sw / q**0.4)
    lu, lv, lw = tb.scales()
    assert lu == lv == pytest.approx(100 / q**1.2 * 0.3048) and lw == pytest.approx(30.48)
    assert Turbulence(w20=10.0).sigmas()[2] == pytest.approx(1.0)
    assert Turbulence(altitude=1.0).scales()[2] == pytest.approx(3.048)  # 10 ft floor
    assert Turbulence(airspeed=0.0).time_constants()[2] == pytest.approx(10.0 / 0.5)  # speed floor


@pytest.mark.parametrize("a", [1e-8, 1e-5, 1e-3, 0.1, 0.999, 1.0, 1.001, 3.0, 40.0])
def test_lateral_filter_discretisation_is_exact(a):
    """Phi P Phi^T + L L^T = P (the stationary covariance), for any a = dt / T."""
    e, a_back, l11, l21, l22 = lateral_coefficients(a)
    assert a_back == a and e == pytest.approx(math.exp(-a), rel=1e-15)
    phi = e * np.array([[1.0, 0.0], [a, 1.0]])
    low = np.array([[l11, 0.0], [l21, l22]])
    P = np.array([[0.5, 0.25], [0.25, 0.25]])
    np.testing.assert_allclose(phi @ P @ phi.T + low @ low.T, P, rtol=0, atol=1e-14)
    # and the noise covariance is int_0^a e^-2u [1 u; u u^2] du (checked by quadrature)
    q = [quad(lambda u: math.exp(-2 * u) * u**k, 0, a, epsabs=0, epsrel=1e-13)[0] for k in range(3)]  # noqa: B023 - called here
    np.testing.assert_allclose([l11**2, l11 * l21, l21**2 + l22**2], q, rtol=1e-9, atol=0)
    assert l22**2 == pytest.approx(q[2] - q[1] ** 2 / q[0], rel=1e-7)  # a^3/12 for small a


def test_dryden_output_has_the_specified_sigmas_and_correlations():
    tb = Turbulence(intensity="moderate", altitude=10.0, airspeed=10.0)
    dt, n, steps = 0.05, 16, 200_000  # 16 x 1e4 s: ~2e4 correlation times of w
    w = wind_run(Environment(turbulence=tb), n, steps, dt, seed=3)
    np.testing.assert_allclose(w.std(axis=(0, 1)), tb.sigmas(), rtol=0.02)
    assert np.all(np.abs(w.mean(axis=(0, 1))) < 0.05 * np.array(tb.sigmas()))
    y = w - w.mean(axis=1, keepdims=True)
    for ax, T in enumerate(tb.time_constants()):
        for tau in (0.5 * T, T, 1.5 * T):
            lag = round(tau / dt)
            r = (y[:, :-lag, ax] * y[:, lag:, ax]).mean() / (y[:, :, ax] ** 2).mean()
            s = lag * dt / T  # V tau / L
            expected = math.exp(-s) if ax == 0 else (1 - s / 2) * math.exp(-s)
            assert r == pytest.approx(expected, abs=0.02), (ax, tau)


def test_dryden_variance_is_stationary_from_the_start_at_1_khz():
    """The filters start from their stationary distribution: no warm-up, even with T = 60 s."""
    tb = Turbulence(intensity="light", altitude=10.0, airspeed=1.0)
    w = wind_run(Environment(turbulence=tb), 4000, 3, 1e-3, seed=9)
    for k in (0, 2):
        np.testing.assert_allclose(w[:, k].std(axis=0), tb.sigmas(), rtol=0.05)


def test_turbulence_is_seeded_per_vehicle_and_independent_of_the_batching():
    vehicle = quiet_drag()
    env = Environment(turbulence=Turbulence(intensity="severe", altitude=2.0, airspeed=2.0))

    def flight(n=4, **kw):
        return qc.fly("hover", vehicle=vehicle, n=n, duration=3.0, environment=env, **kw)

    a = flight(seed=5)
    np.testing.assert_array_equal(flight(seed=5).states, a.states)
    part = flight(n=2, seed=5, first_vehicle=2)
    np.testing.assert_array_equal(part.states, a.states[2:])
    np.testing.assert_array_equal(part.disturbance_memory, a.disturbance_memory[2:])
    assert not np.allclose(a.states[0, :, X], a.states[1, :, X])
    assert not np.allclose(flight(seed=6).states[0, :, X], a.states[0, :, X])
    assert np.abs(a.states[:, -1, X:Z] - 0.0).max() > 1e-3  # the wind moved them
    # the same holds for the wind itself
    w = wind_run(env, 4, 500, 0.01, seed=5)
    np.testing.assert_array_equal(wind_run(env, 2, 500, 0.01, seed=5, first=2), w[2:])


def test_nlpd_survives_moderate_turbulence_on_the_circle():
    n, vehicle = 8, quiet_drag()
    env = Environment(turbulence=Turbulence(intensity="moderate", altitude=1.0, airspeed=Circle().speed))
    res = qc.fly("circle", "nlpd", vehicle=vehicle, n=n, seed=1, duration=40.0, environment=env)
    calm = qc.fly("circle", "nlpd", vehicle=vehicle, duration=40.0)
    assert res.ok.all() and res.duty_clipped_s.max() == 0

    def error(r):
        late = r.t > 10.0  # after the 2 m start-up step
        return np.linalg.norm(r.states[:, late, :3] - r.references[:, late, :3], axis=2)

    e, e0 = error(res), error(calm)
    assert e.max() < 1.0  # bounded (measured ~0.53 m)
    assert np.sqrt((e**2).mean()) < 0.4  # measured ~0.25 m rms
    assert e.max() > 3 * e0.max()  # and the turbulence really acts (calm: 0.06 m)
    assert np.abs(res.states[:, :, [PHI, THETA]]).max() < np.radians(45)


# --- rotor loss --------------------------------------------------------------------------
def test_rotor_loss_changes_effectiveness_at_exactly_its_time():
    env = Environment(rotor_loss=RotorLoss(rotor=np.array([1, 3]), fraction=0.3, time=np.array([0.5, 0.25])))
    t = np.arange(0.0, 1.0, 0.01)
    e = ext_history(env, t, 0.01, n=2)[:, :, EXT_E1:]
    for i, (rotor, when) in enumerate(((0, 0.5), (2, 0.25))):
        np.testing.assert_array_equal(e[i, :, rotor], np.where(t >= when - 1e-12, 0.7, 1.0))
        np.testing.assert_array_equal(np.delete(e[i], rotor, axis=1), 1.0)
    # through the engine: the thrust leaves the hover value right after t = 0.5 s
    # open loop the vehicle tumbles past 90 degrees (diverged by default): let it, to read the thrusts
    grid, res = open_loop(
        V,
        Environment(rotor_loss=RotorLoss(rotor=2, fraction=0.3, time=0.5)),
        duration=3.0,
        limits=qc.Limits(max_tilt=np.inf),
    )
    F2, k = res.states[0, :, F1 + 1], 50
    assert F2[k] == pytest.approx(V.m * V.g / 4, rel=1e-12) and F2[k + 1] < F2[k] * 0.99
    assert res.states[0, -1, F1] == pytest.approx(V.m * V.g / 4, rel=1e-12)


def test_nlpd_hover_after_losing_30_percent_of_rotor_1():
    """The attitude PID's integrators take up the torque imbalance: roll, pitch and yaw come
    back to zero. But the pitch integrator reaches its anti-windup bound (i_limit = 5 rad/s^2
    of the 24.5 needed), so the rest is asked through a pitch setpoint by the position loop,
    which needs a steady x offset (~0.79 m); and the altitude PD, which believes the lost
    thrust is there, sags ~0.35 m. A larger i_limit removes the x offset, not the sag."""
    env = Environment(rotor_loss=RotorLoss(rotor=1, fraction=0.3, time=5.0))
    res = qc.fly(Hover(), "nlpd", duration=30.0, environment=env)
    s, t = res.states[0], res.t
    assert res.ok.all() and res.duty_clipped_s[0] == 0
    np.testing.assert_array_equal(s[t <= 5.0, :3], [[0.0, 0.0, 1.0]] * np.count_nonzero(t <= 5.0))
    assert np.abs(s[-1, PHI : PSI + 1]).max() < 1e-4  # attitude and yaw held
    assert np.degrees(np.abs(s[t > 5, THETA]).max()) < 20  # transient ~15 deg
    assert np.degrees(np.abs(s[t > 5, PSI]).max()) < 5  # ~2.3 deg of yaw
    assert s[-1, X] == pytest.approx(-0.79, abs=0.02) and abs(s[-1, Y]) < 1e-3
    assert 1.0 - s[-1, Z] == pytest.approx(0.35, abs=0.02)
    assert res.controller_limited_s[0] > 20  # integrator held
    wide = qc.fly(Hover(), qc.control.NLPD(i_limit=30.0), duration=30.0, environment=env)
    assert abs(wide.final_state[0, X]) < 1e-3 and 1.0 - wide.final_state[0, Z] == pytest.approx(0.35, abs=0.02)


# --- sensor noise, drag, parsing, checks -------------------------------------------------
def test_sensor_noise_vector_and_delay():
    sn = SensorNoise(position_std=0.01, velocity_std=0.02, angle_std=0.003, rate_std=0.004, delay=0.005)
    std = sn.std_vector()
    assert std.shape == (STATE_SIZE,) and std[X] == std[Y] == std[Z] == 0.01 and std[VY] == 0.02
    assert std[PSI] == 0.003 and std[F1:].sum() == 0
    assert sn.kwargs(1e-3)["sensor_delay"] == 5
    batch = SensorNoise(position_std=np.array([0.0, 0.1, 0.2])).std_vector()
    assert batch.shape == (3, STATE_SIZE) and batch[2, Z] == 0.2
    res = qc.fly(
        "hover", n=3, duration=1.0, seed=2, sensors=SensorNoise(position_std=np.array([0.0, 0.1, 0.2]), delay=0.005)
    )
    assert res.ok.all()
    # a delay is a time: 4 ms is 2 periods at dt = 2 ms
    assert SensorNoise(delay=0.004).kwargs(2e-3)["sensor_delay"] == 2
    with pytest.raises(qc.InputError, match="sede"):
        qc.fly("hover", sede=1)
    with pytest.raises(qc.InputError, match="delay"):
        SensorNoise(delay=0.0015).delay_periods(1e-3)


def test_with_drag_fills_only_drag_free_vehicles_and_warns_only_when_asked():
    with warnings.catch_warnings():
        warnings.simplefilter("error")  # asked for on purpose: no warning
        v = with_drag(V)
    with pytest.warns(
        UserWarning,
        match="the vehicle has no drag, and wind acts only through drag: it flies with "
        "DEFAULT_DRAG, drag_linear 0.3 N s/m",
    ):
        with_drag(V, warn=True)  # a workflow's own choice: said
    assert (v.drag_linear, v.drag_quadratic) == (DEFAULT_DRAG["drag_linear"], DEFAULT_DRAG["drag_quadratic"])
    assert DEFAULT_DRAG["drag_quadratic"] == pytest.approx(0.06, abs=0.005)
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        assert with_drag(V.replace(drag_linear=1.0)).drag_quadratic == 0.0
    with pytest.warns(UserWarning, match="1 of 2 vehicles have no drag"):
        mixed = with_drag(V.replace(drag_linear=np.array([0.0, 2.0])), warn=True)
    np.testing.assert_array_equal(mixed.drag_linear, [0.3, 2.0])
    np.testing.assert_array_equal(mixed.drag_quadratic, [DEFAULT_DRAG["drag_quadratic"], 0.0])


def test_parse_wind_grammar_and_round_trip():
    env = parse_wind("constant:3,0,0,gust:2,0,0@5+2, dryden:moderate@10 ;loss:2,0.3@4 force:0,0,-1/0,0,0.1")
    assert env.wind.velocity == (3.0, 0.0, 0.0) and env.gust.start == 5.0 and env.gust.duration == 2.0
    assert env.turbulence.intensity == "moderate" and env.turbulence.altitude == 10.0
    assert env.rotor_loss.rotor == 2.0 and env.force.torque[2] == 0.1 and env.needs_drag
    np.testing.assert_array_equal(Environment.from_dict(env.to_dict()).params(2), env.params(2))
    t = parse_wind("dryden:12.5@20/3").turbulence
    assert (t.w20, t.altitude, t.airspeed) == (12.5, 20.0, 3.0)
    assert parse_wind("none") == Environment() and not parse_wind("loss:1,0.5@1").needs_drag
    assert isinstance(wind_from_name("dryden", intensity="light"), Turbulence)
    kw = env.kwargs(3)
    assert set(kw) == {"disturbance", "disturbance_params", "disturbance_memory"}
    assert kw["disturbance_params"].flags.c_contiguous and kw["disturbance_memory"].shape == (3, MEMORY_SIZE)
    # without n, an unbatched environment gives one row that the engine hands every vehicle
    one = parse_wind("dryden:severe@2/1").kwargs()
    assert one["disturbance_params"].shape == (PARAMS_SIZE,) and one["disturbance_memory"].shape == (MEMORY_SIZE,)
    res = qc.fly("hover", vehicle=quiet_drag(), n=2, duration=1.0, environment=parse_wind("dryden:severe@2/1"))
    assert not np.allclose(res.states[0, :, X], res.states[1, :, X])


@pytest.mark.parametrize(
    "spec, match",
    [
        ("breeze:1,2,3", "unknown model 'breeze'"),
        ("constant:3,0", "needs 3 values"),
        ("constant:a,b,c", "must be numbers"),
        ("gust:2,0,0@5+-2", "'duration'"),
        ("gust:2,0,0@5", "expected gust:"),
        ("dryden:hurricane@10", "LEVEL"),
        ("dryden:moderate@500", "'altitude'"),
        ("loss:5,0.3@1", "'rotor'"),
        ("loss:1,1.3@1", "'fraction'"),
        ("constant:1,0,0,wind:2,0,0", "a second"),
    ],
)
def test_parse_wind_rejects_bad_specs_in_one_line(spec, match):
    with pytest.raises(qc.InputError, match=match) as err:
        parse_wind(spec)
    assert "\n" not in str(err.value)


def test_bad_inputs_name_the_field():
    cases = [
        (lambda: Gust(duration=-1.0), "'duration'"),
        (lambda: Gust(start=float("nan")), "'start'"),
        (lambda: ConstantWind(velocity=(1.0, 2.0)), "'velocity'"),
        (lambda: ConstantWind(velocity=np.ones((2, 2))), "'velocity'"),
        (lambda: Turbulence(intensity="extreme"), "'intensity'"),
        (lambda: Turbulence(w20=-3.0), "'w20'"),
        (lambda: Turbulence(airspeed=[[1.0]]), "'airspeed'"),
        (lambda: RotorLoss(rotor=1.5), "'rotor'"),
        (lambda: RotorLoss(fraction=-0.1), "'fraction'"),
        (lambda: SensorNoise(rate_std=-1.0), "'rate_std'"),
        (lambda: Environment(wind=Gust()), "'wind'"),
        (
            lambda: Environment(wind=ConstantWind((np.ones(3), 0, 0)), gust=Gust(start=np.ones(2))).params(),
            "batch lengths",
        ),
        (lambda: Environment(wind=ConstantWind((np.ones(3), 0, 0))).params(4), "3 values but 4"),
        (lambda: wind_from_name("tornado"), "unknown disturbance"),
        (lambda: wind_from_name("gust", length=3.0), "gust"),
    ]
    for make, match in cases:
        with pytest.raises(qc.InputError, match=match):
            make()


def test_turbulence_draws_come_from_the_vehicles_splitmix_stream():
    """The turbulence's normals are rng.next_normal's on the vehicle's scalar SplitMix64 state."""
    from quadcruise.sim.fastmath import five_normals
    from quadcruise.sim.rng import _GOLDEN, next_normal, next_unit, uniform

    state = vehicle_states(4, 1)[0]
    s0 = int(state[0])
    expected = [uniform(state) for _ in range(3)]
    got, s = [], np.uint64(s0)
    for _ in range(3):
        u, s_next = next_unit(s)
        assert int(s_next) == (int(s) + int(_GOLDEN)) % 2**64
        got.append(u)
        s = np.uint64(s_next)
    assert got == expected
    *five, s_after = five_normals(np.uint64(s0))
    one_by_one, s = [], np.uint64(s0)
    for _ in range(5):
        x, s = next_normal(s)
        s = np.uint64(s)  # back from Python: keep the state unsigned
        one_by_one.append(x)
    assert five == one_by_one and s_after == s != s0


def test_dryden_coefficients_follow_the_period_but_not_its_rounding():
    """Cached per period: a grid's rounding (1e-12 relative) keeps them, a new period
    (2 ms after 1 ms) recomputes them, as the exact discretisation of the new a = dt / T."""
    from quadcruise.disturbances.turbulence import DRY_COEF_DT, DRY_U_COEF, DRY_V_COEF
    from quadcruise.sim.fastmath import DT_TOLERANCE

    tb = Turbulence(intensity="moderate", altitude=10.0, airspeed=5.0)
    env = Environment(turbulence=tb)
    dp, dm, rng = env.params(1)[0], env.memory(1)[0], vehicle_states(1, 1)[0]
    x, ext = np.zeros(STATE_SIZE), np.zeros(EXT_SIZE)
    env.function(0.0, 1e-3, x, dp, dm, rng, ext)
    first = dm.copy()
    env.function(1e-3, 1e-3 * (1 + 1e-12), x, dp, dm, rng, ext)
    assert dm[DRY_COEF_DT] == 1e-3 and np.array_equal(dm[DRY_U_COEF:], first[DRY_U_COEF:])
    env.function(2e-3, 2e-3, x, dp, dm, rng, ext)
    T_u, T_v = tb.time_constants()[:2]
    assert dm[DRY_COEF_DT] == 2e-3 and dm[DRY_U_COEF] == pytest.approx(math.exp(-2e-3 / T_u), rel=1e-15)
    np.testing.assert_allclose(dm[DRY_V_COEF : DRY_V_COEF + 5], lateral_coefficients(2e-3 / T_v), rtol=1e-15)
    assert 1e-11 < DT_TOLERANCE < 1e-3


def test_compiled_disturbance_makes_no_reference_count_calls():
    """The disturbance runs every period on every thread, on rows of arrays the batch
    shares: an NRT_incref/decref there is an atomic write to a shared counter. A fresh,
    uncached compile shows what the engine runs (only the Python-facing wrapper counts)."""
    from quadcruise.disturbances import environment_disturbance
    from quadcruise.layout import DISTURBANCE_SIG
    from support.compiled_code import reference_count_calls

    calls = reference_count_calls(environment_disturbance.py_func, DISTURBANCE_SIG)
    assert calls == []


def test_compiled_disturbance_reads_its_rows_at_constant_offsets():
    """The parameter and memory rows are read through the offsets of their declarations
    (ENVIRONMENT_PARAMS, DRYDEN_MEMORY), module-level ints that numba folds: every entry is
    reached at a constant offset, none through an index computed at run time."""
    from quadcruise.disturbances import environment_disturbance
    from quadcruise.layout import DISTURBANCE_SIG
    from support.compiled_code import row_offsets

    function = environment_disturbance.py_func
    assert row_offsets(function, DISTURBANCE_SIG, "dp") == (set(range(PARAMS_SIZE)), 0)
    assert row_offsets(function, DISTURBANCE_SIG, "dmem") == (set(range(MEMORY_SIZE)), 0)
