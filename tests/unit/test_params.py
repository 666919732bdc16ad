import math

import numpy as np
import pytest

from quadcruise import InputError, Vehicle
from quadcruise.layout import P_INV_JXX, P_INV_JYY, P_INV_JZZ, P_INV_M, P_K1, P_K2, P_K5, P_K6, PARAM_SIZE


def test_paper_preset_is_table_one():
    v = Vehicle.paper()
    assert (v.m, v.Jxx, v.Jyy, v.Jzz, v.l, v.K, v.omega) == (3.499, 0.03, 0.03, 0.04, 0.2, 120.0, 15.0)
    assert v.d == pytest.approx(4 / 120)
    assert v.hover_duty == pytest.approx(3.499 * 9.81 / 480)
    assert set(Vehicle.units()) == {
        "m",
        "Jxx",
        "Jyy",
        "Jzz",
        "l",
        "K",
        "omega",
        "d",
        "g",
        "drag_linear",
        "drag_quadratic",
    }
    assert v.drag_linear == 0.0 and v.drag_quadratic == 0.0  # the paper's model has no drag


def test_rows_carry_k_coefficients_of_section_three():
    v = Vehicle(Jxx=0.02, Jyy=0.03, Jzz=0.045)
    row = v.rows()[0]
    assert row.shape == (PARAM_SIZE,)
    assert row[P_K1] == pytest.approx((0.03 - 0.045) / 0.02)
    assert row[P_K2] == pytest.approx(0.2 / 0.02)
    assert row[P_K5] == pytest.approx((0.02 - 0.03) / 0.045)
    assert row[P_K6] == pytest.approx(1 / 0.045)
    assert (row[P_INV_M], row[P_INV_JXX], row[P_INV_JYY], row[P_INV_JZZ]) == (1 / v.m, 1 / 0.02, 1 / 0.03, 1 / 0.045)


def test_frozen():
    with pytest.raises(AttributeError):
        Vehicle().m = 2.0


@pytest.mark.parametrize(
    "field, value, words",
    [
        ("m", 0.0, "'m' (mass, kg) must be > 0"),
        ("Jxx", -0.01, "'Jxx'"),
        ("K", math.nan, "'K' (thrust per unit PWM duty"),
        ("omega", math.inf, "must be finite"),
        ("g", -1.0, "'g'"),
    ],
)
def test_bad_values_name_the_field(field, value, words):
    with pytest.raises(InputError, match=words.replace("(", r"\(").replace(")", r"\)")):
        Vehicle.paper().replace(**{field: value})


def test_unknown_field():
    with pytest.raises(InputError, match="unknown vehicle field"):
        Vehicle.paper().replace(mass=1.0)


def test_batch_axis():
    v = Vehicle(m=np.array([3.0, 3.5]), Jzz=np.array([0.04, 0.05]))
    rows = v.rows()
    assert v.batch_size == 2 and rows.shape == (2, PARAM_SIZE)
    assert rows[:, 0].tolist() == [3.0, 3.5]
    assert np.all(rows[:, 1] == 0.03)
    with pytest.raises(InputError, match="batch"):
        Vehicle(m=np.array([3.0, 3.5]), Jzz=np.array([0.04, 0.05, 0.06]))
    with pytest.raises(InputError, match="batch has 2"):
        v.rows(3)
    assert Vehicle().rows(4).shape == (4, PARAM_SIZE)
    with pytest.raises(ValueError):
        v.m[0] = 1.0  # stored arrays are read-only


def test_stack():
    a, b = Vehicle(m=3.0), Vehicle(m=np.array([4.0, 5.0]))
    s = Vehicle.stack([a, b])
    assert s.batch_size == 3 and s.m.tolist() == [3.0, 4.0, 5.0]


def test_default_objects_are_built_once_shared_and_frozen():
    """fly() with names and no parameters reuses one validated, frozen default of each."""
    import dataclasses

    from quadcruise.control import controller_from_name
    from quadcruise.missions import mission_from_name

    assert Vehicle.paper() is Vehicle.paper() and Vehicle.paper() == Vehicle()
    assert controller_from_name("nlpd") is controller_from_name("nlpd")
    assert controller_from_name("nlpd", max_tilt=0.5) is not controller_from_name("nlpd")
    assert controller_from_name("nlpd", max_tilt=0.5).max_tilt == 0.5
    assert mission_from_name("circle") is mission_from_name("circle")
    assert mission_from_name("circle", radius=3.0).radius == 3.0
    with pytest.raises(dataclasses.FrozenInstanceError):
        Vehicle.paper().m = 1.0
