"""PX4's own unit tests of its loops, restated: the inputs and expected outputs of
PX4-Autopilot's ``rate_control_test.cpp``, ``AttitudeControlTest.cpp``,
``PositionControlTest.cpp`` and ``ControlMathTest.cpp`` (release v1.15's tests; the
integrator wind-up case is from the later ``rate_control_test.cpp``, with nothing refused,
which v1.15's integrator meets as well). The numbers are PX4's; the code under test is
:mod:`quadcruise.control.px4loops` and :mod:`quadcruise.control.px4math`.

PX4's ``EXPECT_EQ`` on its ``matrix`` types compares within 1e-4 and ``EXPECT_FLOAT_EQ``
within 4 float32 ulps; we compare float64 results within 1e-6 (relative) unless PX4 says
otherwise.
"""

from __future__ import annotations

import math

import numpy as np
import pytest
from scipy.spatial.transform import Rotation

from quadcruise.control.px4loops import (
    PX4_GAINS,
    attitude_control,
    hover_thrust_integral,
    position_control,
    px4_gains,
    rate_control,
)
from quadcruise.control.px4math import (
    body_z_to_attitude,
    constrain_xy,
    dcm_from_quat,
    dcm_z,
    euler_from_dcm,
    limit_tilt,
    qcanonical,
    qmul,
    qnormalize,
)
from quadcruise.io.px4params import Px4Parameters

NAN3 = (math.nan, math.nan, math.nan)
ZERO3 = (0.0, 0.0, 0.0)
NO = (False, False, False)


def gains(**fields):
    """A gain row of PX4's defaults, the named fields replaced."""
    g = px4_gains(Px4Parameters.defaults())
    offsets = dict(zip((f for f, _ in PX4_GAINS.fields), PX4_GAINS.offsets, strict=True))
    widths = dict(PX4_GAINS.fields)
    for name, value in fields.items():
        g[offsets[name] : offsets[name] + widths[name]] = value
    return g


# --- rate_control_test.cpp --------------------------------------------------------------------


def test_rate_all_zero_case():
    torque, integ = rate_control(ZERO3, ZERO3, ZERO3, 0.0, False, gains(), NO, NO, ZERO3)
    assert torque == ZERO3 and integ == ZERO3


@pytest.mark.parametrize("error", [1.0, -1.0])
def test_rate_integrator_winds_up_to_its_limit(error):
    """Integral gain 1, limit 0.3, dt 0.01 s, a constant roll rate error of +-1 rad/s for
    1000 steps: the integral stops at +-0.3 (PX4: NothingRefusedKeepsFullIntegratorLimit)."""
    g = gains(rate_p=(0.0, 0.0, 0.0), rate_i=(1.0, 1.0, 1.0), rate_d=(0.0, 0.0, 0.0), rate_ilim=(0.3, 0.3, 0.3))
    integ = ZERO3
    for _ in range(1000):
        torque, integ = rate_control(ZERO3, (error, 0.0, 0.0), ZERO3, 0.01, False, g, NO, NO, integ)
    assert integ[0] == pytest.approx(0.3 * error, abs=1e-6)
    assert torque[0] == pytest.approx(0.3 * error, abs=1e-6)  # the output is the integral (P, D, FF zero)


def test_rate_integral_is_held_while_landed_or_saturated():
    g = gains(rate_i=(1.0, 1.0, 1.0))
    _, landed = rate_control(ZERO3, (1.0, 1.0, 1.0), ZERO3, 0.01, True, g, NO, NO, ZERO3)
    assert landed == ZERO3
    pos, neg = (True, False, False), (False, True, False)
    _, held = rate_control(ZERO3, (1.0, -1.0, 1.0), ZERO3, 0.01, False, g, pos, neg, ZERO3)
    assert held[0] == 0.0 and held[1] == 0.0 and held[2] > 0.0  # no growth into a saturated direction
    _, back = rate_control(ZERO3, (-1.0, 1.0, 0.0), ZERO3, 0.01, False, g, pos, neg, ZERO3)
    assert back[0] < 0.0 and back[1] > 0.0  # out of saturation it may


def test_rate_pid_terms_and_i_factor():
    """tau = K P e + i - K D w' + FF w_sp; the integral's gain falls as 1 - (e / 400 deg/s)^2."""
    p = Px4Parameters.defaults().with_values(MC_ROLLRATE_K=2.0, MC_ROLLRATE_FF=0.1)
    g = px4_gains(p)
    rate, rate_sp, accel = (0.1, 0.0, 0.0), (0.5, 0.0, 0.0), (3.0, 0.0, 0.0)
    torque, integ = rate_control(rate, rate_sp, accel, 0.004, False, g, NO, NO, (0.02, 0.0, 0.0))
    assert torque[0] == pytest.approx(2 * 0.15 * 0.4 + 0.02 - 2 * 0.003 * 3.0 + 0.1 * 0.5)
    f = 1 - (0.4 / math.radians(400)) ** 2
    assert integ[0] == pytest.approx(0.02 + f * 2 * 0.2 * 0.4 * 0.004)
    _, big = rate_control(ZERO3, (math.radians(400), 0.0, 0.0), ZERO3, 0.004, False, g, NO, NO, ZERO3)
    assert big[0] == 0.0  # at 400 deg/s of error the integral does not grow


# --- AttitudeControlTest.cpp ------------------------------------------------------------------


def att_gains(p, yaw_w, rmax):
    return gains(att_p=p, yaw_w=yaw_w, rate_max=rmax)


def test_attitude_all_zero_case():
    assert attitude_control((1.0, 0.0, 0.0, 0.0), (1.0, 0.0, 0.0, 0.0), 0.0, gains()) == ZERO3


QUATS = [
    (1.0, 0.0, 0.0, 0.0),
    (0.0, 1.0, 0.0, 0.0),
    (0.0, 0.0, 1.0, 0.0),
    (0.0, 0.0, 0.0, 1.0),
    (0.698, 0.024, -0.681, -0.220),
    (-0.820, -0.313, 0.225, -0.423),
    (0.599, -0.172, 0.755, -0.204),
    (0.216, -0.662, 0.290, -0.656),
]


def axis_angle_quat(v):
    angle = math.sqrt(v[0] ** 2 + v[1] ** 2 + v[2] ** 2)
    if angle < 1e-12:
        return (1.0, 0.0, 0.0, 0.0)
    s = math.sin(angle / 2) / angle
    return (math.cos(angle / 2), v[0] * s, v[1] * s, v[2] * s)


@pytest.mark.parametrize("start", range(8))
@pytest.mark.parametrize("goal", range(8))
def test_attitude_converges_from_every_pair(start, goal):
    """PX4's AttitudeControlConvergence: gains (.5, .6, .3), yaw weight .4, rate limit 100;
    the state turned by the rate setpoint each step (and negated, against unwinding) must
    reach the goal, the output shrinking every step, within 100 steps."""
    g = att_gains((0.5, 0.6, 0.3), 0.4, (100.0, 100.0, 100.0))
    q = qnormalize(QUATS[start])
    goal_q = qnormalize(QUATS[goal])
    last = 1000.0 * math.sqrt(3)
    i = 100
    while i > 0:
        rate = attitude_control(q, goal_q, 0.0, g)
        q = qmul(q, axis_angle_quat(rate))
        q = (-q[0], -q[1], -q[2], -q[3])
        norm = math.sqrt(sum(r * r for r in rate))
        if norm >= last:
            break
        last = norm
        i -= 1
    assert np.allclose(qcanonical(q), qcanonical(goal_q), atol=1e-4)
    assert i > 0


def test_attitude_yaw_weight_scaling():
    """PX4's YawWeightScaling: a pure 0.1 rad yaw error with yaw gain 2.8 and weight .4 gives
    0.28 rad/s of yaw rate and none in roll and pitch; weight 0 gives nothing (and no NaN)."""
    yaw = 0.1
    qd = (math.cos(yaw / 2), 0.0, 0.0, math.sin(yaw / 2))
    rate = attitude_control((1.0, 0.0, 0.0, 0.0), qd, 0.0, att_gains((6.5, 6.5, 2.8), 0.4, (1000.0,) * 3))
    assert rate[0] == 0.0 and rate[1] == 0.0
    assert rate[2] == pytest.approx(yaw * 2.8, abs=1e-4)
    rate = attitude_control((1.0, 0.0, 0.0, 0.0), qd, 0.0, att_gains((6.5, 6.5, 2.8), 0.0, (1000.0,) * 3))
    assert rate == ZERO3


def test_attitude_yaw_feedforward_and_rate_limits():
    """The yaw rate feed-forward is about the world z axis, in body axes; outputs are limited."""
    q = tuple(Rotation.from_euler("ZYX", [0.3, 0.0, 0.5]).as_quat(scalar_first=True))
    rate = attitude_control(q, q, 1.0, gains())
    assert np.allclose(rate, np.array(dcm_from_quat(q))[2], atol=1e-12)  # R^T e_z
    qd = tuple(Rotation.from_euler("ZYX", [0.0, 0.0, 1.0]).as_quat(scalar_first=True))
    rate = attitude_control((1.0, 0.0, 0.0, 0.0), qd, math.nan, gains())
    assert rate[0] == pytest.approx(math.radians(220.0))  # 6.5 x 2 sin(0.5) = 6.2 rad/s, limited


# --- ControlMathTest.cpp ----------------------------------------------------------------------


def unit(v):
    v = np.asarray(v, float)
    return tuple(v / np.linalg.norm(v))


UP = (0.0, 0.0, 1.0)


def test_limit_tilt_unchanged():
    for body in [unit((0, 0, 1)), unit((0, 0.1, 1))]:
        assert np.allclose(limit_tilt(body, UP, math.radians(45)), body, atol=1e-6)


@pytest.mark.parametrize("body", [(0.0, 0.0, -1.0), unit((0.001, 0.0, -1.0))], ids=["opposite", "almost"])
def test_limit_tilt_opposite(body):
    out = limit_tilt(body, UP, math.radians(45))
    assert math.degrees(math.acos(np.dot(out, UP))) == pytest.approx(45.0, abs=1e-4)
    assert np.linalg.norm(out) == pytest.approx(1.0)


def test_limit_tilt_45_and_10_degrees():
    s = math.sqrt(0.5)
    assert np.allclose(limit_tilt((1.0, 0.0, 0.0), UP, math.radians(45)), (s, 0, s), atol=1e-6)
    assert np.allclose(limit_tilt((0.0, 1.0, 0.0), UP, math.radians(45)), (0, s, s), atol=1e-6)
    out = limit_tilt(unit((1, 1, 0.1)), UP, math.radians(10))
    assert math.degrees(math.acos(np.dot(out, UP))) == pytest.approx(10.0, abs=1e-4)
    assert np.linalg.norm(out) == pytest.approx(1.0) and out[0] == pytest.approx(out[1])
    out = limit_tilt((1.0, 2.0, 0.2), UP, math.radians(10))  # not a unit vector, as PX4's test
    assert math.degrees(math.acos(np.dot(out, UP))) == pytest.approx(10.0, abs=1e-4)
    assert np.linalg.norm(out) == pytest.approx(1.0) and 2 * out[0] == pytest.approx(out[1])


def thrust_to_attitude(thr, yaw):
    q = body_z_to_attitude((-thr[0], -thr[1], -thr[2]), yaw)
    return q, euler_from_dcm(dcm_from_quat(q)), -math.sqrt(sum(t * t for t in thr))


def angle_equal(a, b):
    return abs(math.remainder(a - b, 2 * math.pi)) < 1e-6


def test_throttle_attitude_mapping():
    """Thrust straight up: level at any yaw; straight down: rolled by 180 deg (roll, pitch, yaw order)."""
    _, euler, tz = thrust_to_attitude((0.0, 0.0, -1.0), 0.0)
    assert np.allclose(euler, (0, 0, 0), atol=1e-7) and tz == -1.0
    _, euler, tz = thrust_to_attitude((0.0, 0.0, -1.0), math.pi / 2)
    assert np.allclose(euler, (0, 0, math.pi / 2), atol=1e-7) and tz == -1.0
    _, euler, tz = thrust_to_attitude((0.0, 0.0, 1.0), math.pi / 2)
    assert angle_equal(euler[0], -math.pi) and abs(euler[1]) < 1e-7 and angle_equal(euler[2], math.pi / 2)
    assert tz == -1.0


def test_constrain_xy_priorities():
    vmax = 5.0
    v0, v1 = (vmax, 0.0), (0.0, -vmax)
    assert np.allclose(constrain_xy(v0, v1, vmax), (vmax, 0.0))  # v0 already at max
    assert np.allclose(constrain_xy((0.0, 0.0), v1, vmax), (0.0, -vmax))  # v0 zero, v1 too long
    assert np.allclose(constrain_xy((0.5, 0.5), (0.5, -0.5), vmax), (1.0, 0.0))  # within the limit
    out = constrain_xy((4.0, 0.0), (0.0, -4.0), vmax)  # perpendicular, together too long
    assert out[0] == pytest.approx(4.0) and out[1] == pytest.approx(-math.sqrt(vmax**2 - 16.0))


# --- PositionControlTest.cpp ------------------------------------------------------------------

MAX_THRUST, MARGIN = 0.9, 0.3


def basic_gains():
    """PositionControlBasicTest's set-up (tilt and hover thrust are run()'s arguments)."""
    return gains(
        pos_p=(1.0, 1.0, 1.0),
        vel_p=(20.0,) * 3,
        vel_i=(20.0,) * 3,
        vel_d=(20.0,) * 3,
        vmax_xy=1.0,
        vmax_up=1.0,
        vmax_dn=1.0,
        thr_min=0.1,
        thr_max=MAX_THRUST,
        thr_xy_marg=MARGIN,
    )


def run(pos_sp=NAN3, vel_sp=NAN3, acc_sp=NAN3, tilt=1.0, hover=0.5, state=(ZERO3, ZERO3, ZERO3), vel_int=ZERO3):
    """PositionControlBasicTest::runController: dt 0.1 s, zero state unless given."""
    pos, vel, vel_dot = state
    return position_control(pos, vel, vel_dot, pos_sp, vel_sp, acc_sp, 0.1, basic_gains(), hover, tilt, vel_int)


def body_z_of(thr):
    return dcm_z(body_z_to_attitude((-thr[0], -thr[1], -thr[2]), 0.0))


@pytest.mark.parametrize("which", ["position", "velocity"])
def test_position_direction(which):
    sp = (0.1, 0.1, -0.1)
    _, _, thr, _, valid = run(pos_sp=sp) if which == "position" else run(vel_sp=sp)
    assert valid
    assert thr[0] > 0 and thr[1] > 0 and thr[2] < 0
    bz = body_z_of(thr)
    assert bz[0] < 0 and bz[1] < 0 and bz[2] > 0


def test_position_tilt_limit():
    for tilt in (1.0, 0.5):
        _, _, thr, _, valid = run(pos_sp=(10.0, 10.0, 0.0), tilt=tilt)
        angle = math.acos(np.dot(body_z_of(thr), UP))
        assert valid and 0.0 < angle <= tilt + 1e-5


def test_position_velocity_limit():
    vel, _, _, _, valid = run(pos_sp=(10.0, 10.0, -10.0))
    assert valid and math.hypot(vel[0], vel[1]) <= 1.0 + 1e-12 and abs(vel[2]) <= 1.0


def test_position_max_thrust_limit():
    """Vertical and horizontal saturation: |thrust| = 0.9, the horizontal part the 0.3 margin
    (0.3/sqrt 2 on each axis), the vertical sqrt(0.9^2 - 0.3^2); roll asin((0.3/sqrt 2)/0.9)."""
    _, _, thr, _, _ = run(pos_sp=(10.0, 10.0, -10.0))
    assert np.linalg.norm(thr) == pytest.approx(MAX_THRUST)
    assert thr[0] == pytest.approx(MARGIN / math.sqrt(2)) and thr[1] == pytest.approx(MARGIN / math.sqrt(2))
    assert thr[2] == pytest.approx(-math.sqrt(MAX_THRUST**2 - MARGIN**2))
    q, euler, tz = thrust_to_attitude(thr, 0.0)
    assert tz == pytest.approx(-MAX_THRUST)
    assert euler[0] == pytest.approx(math.asin((MARGIN / math.sqrt(2)) / MAX_THRUST))


def test_position_min_thrust_limit():
    _, _, thr, _, _ = run(pos_sp=(10.0, 0.0, 10.0))
    assert np.linalg.norm(thr) == pytest.approx(0.1)
    _, euler, tz = thrust_to_attitude(thr, 0.0)
    assert tz == pytest.approx(-0.1)
    assert euler[0] == pytest.approx(0.0, abs=1e-7) and euler[1] == pytest.approx(-1.0)


def test_position_failsafe_input():
    _, _, thr, _, valid = run(vel_sp=(math.nan, math.nan, 0.1), acc_sp=(0.0, 0.0, math.nan))
    assert valid
    assert thr[0] == pytest.approx(0.0, abs=1e-7) and thr[1] == pytest.approx(0.0, abs=1e-7)
    assert -0.5 < thr[2] < -0.1


def test_position_idle_thrust_input():
    _, _, thr, _, valid = run(acc_sp=(0.0, 0.0, 100.0))
    assert valid and thr == pytest.approx((0.0, 0.0, -0.1))


def test_position_input_combinations():
    vel, _, thr, _, valid = run(pos_sp=(0.1, 0.2, 0.3))
    assert valid and all(math.isfinite(v) for v in vel + thr)
    vel, _, thr, _, valid = run(pos_sp=(math.nan, math.nan, 0.3), vel_sp=(0.1, 0.2, math.nan))
    assert valid and vel[0] == pytest.approx(0.1) and vel[1] == pytest.approx(0.2)
    assert all(math.isfinite(v) for v in vel + thr)


def test_position_setpoint_validity_simple():
    assert not run()[4]
    assert not run(pos_sp=(0.1, math.nan, math.nan))[4]
    assert not run(pos_sp=(0.1, 0.2, math.nan))[4]
    assert run(pos_sp=(0.1, 0.2, math.nan), acc_sp=(math.nan, math.nan, 0.3))[4]


def test_position_setpoint_validity_all_combinations():
    """Each of 512 combinations of given and NaN setpoints: valid exactly when every axis has
    one and north and east come in pairs."""
    for combination in range(512):
        sp = [math.nan] * 9  # x, vx, ax, y, vy, ay, z, vz, az
        for j in range(9):
            if combination & (1 << j):
                sp[j] = combination / (j + 1)
        has = [(combination >> (3 * a)) & 7 != 0 for a in range(3)]
        expected = all(has) and (combination & 7) == ((combination >> 3) & 7)
        valid = run(pos_sp=(sp[0], sp[3], sp[6]), vel_sp=(sp[1], sp[4], sp[7]), acc_sp=(sp[2], sp[5], sp[8]))[4]
        assert valid == expected, combination


def test_position_invalid_state():
    sp = (0.1, 0.2, 0.3)
    nan = math.nan
    assert not run(pos_sp=sp, state=((nan, 0.0, 0.0), ZERO3, ZERO3))[4]
    assert not run(pos_sp=sp, state=((nan, 0.0, 0.0), (nan, 0.0, 0.0), ZERO3))[4]
    assert not run(pos_sp=sp, state=(ZERO3, (nan, 0.0, 0.0), ZERO3))[4]
    assert not run(pos_sp=sp, state=(ZERO3, ZERO3, (0.0, nan, 0.0)))[4]


def test_position_update_hover_thrust():
    """Zero velocity setpoint: the thrust is the hover thrust (0.6); a new hover thrust (0.7)
    moved into the integral leaves the output the same (PositionControlTest's case); and while
    accelerating (a climb's velocity error), PX4's
    ``(a - g) h_old / h_new + g - a`` still leaves it the same, the simpler ``(h_new - h_old)
    g / h_new`` would not."""
    _, acc, thr, vel_int, valid = run(vel_sp=ZERO3, hover=0.6)
    assert valid and thr[2] == pytest.approx(-0.6)
    vel_int = (vel_int[0], vel_int[1], hover_thrust_integral(vel_int[2], 0.6, 0.7, acc[2]))
    _, _, thr, _, valid = run(vel_sp=ZERO3, hover=0.7, vel_int=vel_int)
    assert valid and thr[2] == pytest.approx(-0.6)
    climb = (0.0, 0.0, -0.1)
    _, acc, thr0, _, valid = run(vel_sp=climb, hover=0.6)  # the integral 0 going in
    assert valid and acc[2] < -0.5 and -0.85 < thr0[2] < -0.6  # accelerating, not saturated
    moved = hover_thrust_integral(0.0, 0.6, 0.7, acc[2])
    _, _, thr, _, _ = run(vel_sp=climb, hover=0.7, vel_int=(0.0, 0.0, moved))
    assert thr[2] == pytest.approx(thr0[2], abs=1e-6)
    simple = (0.7 - 0.6) * 9.80665 / 0.7
    _, _, thr, _, _ = run(vel_sp=climb, hover=0.7, vel_int=(0.0, 0.0, simple))
    assert abs(thr[2] - thr0[2]) > 1e-3


def test_position_integrator_does_not_wind_up_on_invalid_setpoint():
    _, _, _, vel_int, valid = run(pos_sp=(0.1, 0.2, math.nan))
    assert not valid and vel_int == ZERO3
    _, _, thr, _, valid = run(vel_sp=ZERO3, vel_int=vel_int)
    _, euler, _ = thrust_to_attitude(thr, 0.0)
    assert valid and abs(euler[0]) < 1e-7 and abs(euler[1]) < 1e-7
