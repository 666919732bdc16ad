"""Tests of the mission references: derivatives, geometry, timing, compiled use, bad input."""

import math
import subprocess
import sys

import numpy as np
import pytest
from numba import njit, types

from quadcruise.errors import InputError
from quadcruise.layout import (
    REF_AX,
    REF_AY,
    REF_AZ,
    REF_PSI,
    REF_PSI_DOT,
    REF_SIZE,
    REF_VX,
    REF_VY,
    REF_VZ,
    REF_X,
    REF_Y,
    REF_Z,
    MissionType,
)
from quadcruise.missions import Circle, Hover, Square, Step, mission_from_dict, mission_from_name, stack_params

POS = [REF_X, REF_Y, REF_Z]
VEL = [REF_VX, REF_VY, REF_VZ]
ACC = [REF_AX, REF_AY, REF_AZ]


def central(mission, t, cols, h=1e-4):
    """Central difference of the given reference columns at times t."""
    return (mission.reference(t + h)[:, cols] - mission.reference(t - h)[:, cols]) / (2 * h)


# --- circle -------------------------------------------------------------------------------
@pytest.mark.parametrize(
    "mission",
    [
        Circle(),
        Circle(radius=1.5, period=7.0, direction=-1, start_angle=0.7, center=(1.0, -2.0)),
        Circle(ramp_time=5.0),
        Circle(radius=3.0, period=12.0, ramp_time=2.5, direction=-1),
    ],
)
def test_circle_derivatives(mission):
    t = np.linspace(0.01, 40.0, 997)
    ref = mission.reference(t)
    np.testing.assert_allclose(central(mission, t, POS), ref[:, VEL], atol=1e-6)
    np.testing.assert_allclose(central(mission, t, VEL), ref[:, ACC], atol=1e-6)


def test_circle_radius_period_speed_and_start():
    c = Circle(radius=2.5, period=16.0, altitude=1.7, center=(0.5, -1.0))
    t = np.linspace(0.0, 50.0, 1001)
    ref = c.reference(t)
    dist = np.hypot(ref[:, REF_X] - 0.5, ref[:, REF_Y] + 1.0)
    np.testing.assert_allclose(dist, 2.5, rtol=0, atol=1e-12)
    np.testing.assert_allclose(ref[:, REF_Z], 1.7)
    np.testing.assert_allclose(c.reference(t + 16.0), ref, atol=1e-11)
    np.testing.assert_allclose(np.hypot(ref[:, REF_VX], ref[:, REF_VY]), 2 * math.pi * 2.5 / 16.0)
    np.testing.assert_allclose(np.hypot(ref[:, REF_AX], ref[:, REF_AY]), 2.5 * (2 * math.pi / 16.0) ** 2)
    np.testing.assert_allclose(ref[0, :2], [3.0, -1.0])  # starts at centre + (R, 0)
    quarter = c.reference(4.0)[0]  # counter-clockwise
    np.testing.assert_allclose(quarter[:2], [0.5, 1.5], atol=1e-12)
    assert Circle().speed == pytest.approx(0.6283, abs=1e-4)


def test_circle_direction():
    for direction in (1, -1):
        ref = Circle(direction=direction).reference(np.linspace(0, 20, 50))
        spin = ref[:, REF_X] * ref[:, REF_VY] - ref[:, REF_Y] * ref[:, REF_VX]
        assert np.all(np.sign(spin) == direction)


def test_circle_ramp_starts_at_rest_and_reaches_cruise():
    c = Circle(ramp_time=4.0)
    ref = c.reference([-1.0, 0.0, 2.0, 4.0, 10.0])
    np.testing.assert_allclose(ref[:2, VEL + ACC], 0.0)
    np.testing.assert_allclose(ref[0, :2], [2.0, 0.0])
    speed = np.hypot(ref[:, REF_VX], ref[:, REF_VY])
    assert 0 < speed[2] < c.speed
    np.testing.assert_allclose(speed[3:], c.speed)
    # acceleration continuous across the end of the ramp; after it the phase lags by w T / 2
    a = c.reference([4.0 - 1e-7, 4.0 + 1e-7])[:, ACC]
    np.testing.assert_allclose(a[0], a[1], atol=1e-6)
    np.testing.assert_allclose(c.reference(30.0), Circle().reference(28.0), atol=1e-12)


# --- square -------------------------------------------------------------------------------
def test_square_corners_at_the_right_times():
    s = Square(side=4.0, speed=0.5, altitude=1.2)
    assert s.lap_time == 32.0
    corners = s.reference([0.0, 8.0, 16.0, 24.0, 32.0, 40.0, 64.0])
    np.testing.assert_allclose(
        corners[:, :3],
        [[0, 0, 1.2], [4, 0, 1.2], [4, 4, 1.2], [0, 4, 1.2], [0, 0, 1.2], [4, 0, 1.2], [0, 0, 1.2]],
        atol=1e-12,
    )


def test_square_legs_constant_speed_and_derivatives():
    s = Square(side=3.0, speed=0.75, corner=(-1.0, 2.0), direction=-1)
    leg = 3.0 / 0.75
    t = np.linspace(0.0, 3 * s.lap_time, 3001)
    t = t[np.abs(t / leg - np.round(t / leg)) > 1e-3]  # off the corners
    ref = s.reference(t)
    np.testing.assert_allclose(np.hypot(ref[:, REF_VX], ref[:, REF_VY]), 0.75)
    np.testing.assert_allclose(ref[:, ACC + [REF_VZ, REF_PSI_DOT]], 0.0)
    np.testing.assert_allclose(central(s, t, POS, h=1e-5), ref[:, VEL], atol=1e-8)
    x, y = ref[:, REF_X], ref[:, REF_Y]  # stays on the square's edges
    assert x.min() >= -1.0 - 1e-12 and x.max() <= 2.0 + 1e-12
    assert y.min() >= -1.0 - 1e-12 and y.max() <= 2.0 + 1e-12  # clockwise: y goes down first
    on_edge = np.minimum.reduce([np.abs(x + 1), np.abs(x - 2), np.abs(y - 2), np.abs(y + 1)])
    assert on_edge.max() < 1e-9
    np.testing.assert_allclose(s.reference(leg + 1.0)[0, [REF_VX, REF_VY]], [0.0, -0.75])


def test_square_leg_directions_and_velocity_jump():
    s = Square()
    v = s.reference([4.0, 12.0, 20.0, 28.0])[:, [REF_VX, REF_VY]]
    np.testing.assert_allclose(v, [[0.5, 0], [0, 0.5], [-0.5, 0], [0, -0.5]])
    before, after = s.reference([8.0 - 1e-9, 8.0])[:, [REF_VX, REF_VY]]
    np.testing.assert_allclose(before, [0.5, 0.0])
    np.testing.assert_allclose(after, [0.0, 0.5])


def test_square_dwell():
    s = Square(side=2.0, speed=1.0, dwell=1.5)
    assert s.lap_time == 4 * 3.5
    ref = s.reference([0.0, 1.0, 1.49, 2.5, 3.5, 4.0])
    np.testing.assert_allclose(ref[:3, [REF_X, REF_Y, REF_VX, REF_VY]], 0.0)
    np.testing.assert_allclose(ref[3, [REF_X, REF_VX]], [1.0, 1.0])
    np.testing.assert_allclose(ref[4:, [REF_X, REF_Y, REF_VX, REF_VY]], [[2, 0, 0, 0], [2, 0, 0, 0]])


# --- hover and step -----------------------------------------------------------------------
def test_hover_constant():
    ref = Hover(x=1.0, y=-2.0, z=3.0, yaw=0.4).reference(np.linspace(0, 100, 11))
    expected = np.zeros(REF_SIZE)
    expected[[REF_X, REF_Y, REF_Z, REF_PSI]] = [1.0, -2.0, 3.0, 0.4]
    np.testing.assert_array_equal(ref, np.tile(expected, (11, 1)))


@pytest.mark.parametrize("axis,col", [("x", REF_X), ("y", REF_Y), ("z", REF_Z), ("yaw", REF_PSI)])
def test_step_at_the_right_time(axis, col):
    m = Step(axis=axis, size=0.8, time=2.5, x=0.1, y=0.2, z=1.3, yaw=0.05)
    ref = m.reference([0.0, 2.4999, 2.5, 10.0])
    base = {REF_X: 0.1, REF_Y: 0.2, REF_Z: 1.3, REF_PSI: 0.05}
    for c, v in base.items():
        np.testing.assert_allclose(ref[:2, c], v)
        np.testing.assert_allclose(ref[2:, c], v + (0.8 if c == col else 0.0))
    np.testing.assert_array_equal(ref[:, VEL + ACC + [REF_PSI_DOT]], 0.0)


# --- compiled use -------------------------------------------------------------------------
@njit(types.void(MissionType, types.float64[::1], types.float64[::1]))
def _call_at_one(fn, mp, ref):
    fn(1.0, mp, ref)


@njit(types.void(MissionType, types.float64[:, ::1], types.float64[:, ::1]))
def _call_batch(fn, mps, refs):
    for i in range(mps.shape[0]):
        fn(3.0, mps[i], refs[i])


@pytest.mark.parametrize("mission", [Hover(z=2.0), Step(time=0.5), Circle(radius=1.2), Square(dwell=0.2)])
def test_called_from_compiled_code(mission):
    ref = np.full(REF_SIZE, np.nan)
    _call_at_one(mission.function, mission.params(), ref)
    np.testing.assert_array_equal(ref, mission.reference(1.0)[0])


def test_per_vehicle_rows():
    missions = [Circle(radius=r, period=p) for r, p in ((1.0, 10.0), (2.0, 20.0), (3.0, 8.0))]
    mps = stack_params(missions)
    assert mps.shape == (3, 8) and mps.flags.c_contiguous
    refs = np.empty((3, REF_SIZE))
    _call_batch(Circle.function, mps, refs)
    for m, row in zip(missions, refs, strict=False):
        np.testing.assert_array_equal(row, m.reference(3.0)[0])
    assert stack_params(Square(), n=4).shape == (4, 8)


def test_cache_hits_in_a_new_process():
    """The references compile on first use, not at import, and then load from the cache."""
    code = (
        "import quadcruise.missions as m; "
        "fs = (m.hover_ref, m.step_ref, m.circle_ref, m.square_ref); "
        "lazy = all(not f.signatures for f in fs); "
        "[M().reference(1.0) for M in (m.Hover, m.Step, m.Circle, m.Square)]; "
        "print(lazy and all(sum(f.stats.cache_hits.values()) > 0 and not f.stats.cache_misses "
        "for f in fs))"
    )
    # the first process may be the one that compiles them (a fresh clone, or a worker whose other
    # tests flew no mission yet); the next one loads them from the cache
    subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, check=True)
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, check=True)
    assert out.stdout.strip() == "True"


# --- python side --------------------------------------------------------------------------
def test_params_layout_and_dict_round_trip():
    for m in (Hover(), Step(axis="yaw"), Circle(direction=-1, center=(1, 2)), Square(corner=[1, 2])):
        p = m.params()
        assert p.dtype == np.float64 and p.flags.c_contiguous and p.shape == (len(m.columns),)
        assert mission_from_dict(m.to_dict()) == m
        assert m.name == m.to_dict()["kind"]
    assert Circle(period=10.0, direction=-1).params()[1] == pytest.approx(-2 * math.pi / 10)
    assert Step(axis="yaw").params()[4] == REF_PSI
    assert Circle.units()["period"] == "s"
    assert mission_from_name("Circle", radius=1.0) == Circle(radius=1.0)
    assert Circle().replace(radius=5.0).radius == 5.0


@pytest.mark.parametrize(
    "cls,field,value",
    [
        (Circle, "radius", 0.0),
        (Circle, "radius", -1.0),
        (Circle, "period", 0.0),
        (Circle, "altitude", float("nan")),
        (Circle, "ramp_time", -1.0),
        (Circle, "direction", 2),
        (Circle, "center", (1.0,)),
        (Circle, "center", (0.0, float("inf"))),
        (Circle, "yaw", "0"),
        (Square, "side", -4.0),
        (Square, "speed", 0.0),
        (Square, "dwell", -0.1),
        (Square, "corner", "ab"),
        (Square, "altitude", True),
        (Step, "axis", "w"),
        (Step, "time", -1.0),
        (Step, "size", float("nan")),
        (Hover, "z", float("inf")),
    ],
)
def test_bad_input_names_the_field(cls, field, value):
    with pytest.raises(InputError, match=f"'{field}'") as err:
        cls(**{field: value})
    assert "\n" not in str(err.value)


def test_factory_and_stack_errors():
    with pytest.raises(InputError, match="hover, step, circle, square"):
        mission_from_name("figure8")
    with pytest.raises(InputError, match="unknown circle field.*side"):
        mission_from_name("circle", side=3.0)
    with pytest.raises(InputError, match="one mission kind"):
        stack_params([Circle(), Square()])
    with pytest.raises(InputError, match="non-empty"):
        stack_params([])
    with pytest.raises(InputError, match="2 missions given but 3"):
        stack_params([Hover(), Hover()], n=3)
    with pytest.raises(InputError, match="times"):
        Circle().reference([0.0, float("nan")])
