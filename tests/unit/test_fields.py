"""The one validation of fields with units (quadcruise.fields): each check accepts good values and
refuses bad ones with one line naming the owner, the field, its meaning and unit; every parameter
class of the package is declared and checked through it; and the one KEY=VALUE parser."""

from __future__ import annotations

import dataclasses
import importlib
import inspect
import math
import pkgutil
from dataclasses import dataclass
from typing import Any

import numpy as np
import pytest

import quadcruise
from quadcruise.cli.assignments import parse_assignments, parse_numbers
from quadcruise.errors import InputError
from quadcruise.fields import (
    CHECKS,
    Check,
    Validated,
    between,
    check_value,
    instance_of,
    one_of,
    unit_field,
    validate,
    vector,
)


def probe(check, value, batch=False, optional=None, default: Any = 0.0):
    """An object of a one-field class checked by ``check``: its stored value (or InputError)."""

    @dataclass(frozen=True)
    class Probe(Validated):
        name = "probe"
        knob: Any = unit_field(default, "N m", "the knob", check, batch=batch, optional=optional)

    return Probe(knob=value).knob


def refused(check, value, **kw) -> str:
    """The message for a refused value, checked to be one line naming owner, field, meaning, unit."""
    with pytest.raises(InputError) as err:
        probe(check, value, **kw)
    text = str(err.value)
    assert "\n" not in text
    assert text.startswith("probe field 'knob' (the knob, N m) must be "), text
    return text


# --- each check -------------------------------------------------------------------------------
@pytest.mark.parametrize(
    "check, good, bad",
    [
        ("real", [0, -3.5, 1e300, np.float32(2.0), np.int64(4)], [math.nan, math.inf, "1", True, None, [1.0]]),
        ("pos", [1e-300, 2, 5.5], [0.0, -1.0, -math.inf, math.nan]),
        ("nonneg", [0.0, 0, 3.0], [-1e-300, -2, math.nan]),
        ("frac", [0.0, 0.5, 1.0], [-0.01, 1.01, math.inf]),
        ("sign", [1, -1, 1.0], [0, 2, -0.5]),
        ("whole", [0, 3, 7.0], [-1, 2.5, math.nan]),
        ("flag", [True, False, np.bool_(True), 0, 1], [2, "yes", None, 0.5]),
        ("pair", [(1, 2), [0.5, -1.0], np.array([1.0, 2.0])], [(1,), (1, 2, 3), "ab", 3.0, (1, math.nan), [[1, 2]]]),
        ("vec", [(1, 2, 3)], [(1, 2), (1, 2, "3")]),
        (between(0.0, 1.0, "[)"), [0.0, 0.999], [1.0, -0.1]),
        (between(0.0, 1.0, "(]"), [1.0, 1e-9], [0.0, 1.1]),
        (between(0.0, math.pi / 2, "()", text="(0, pi/2)"), [0.1, 1.5], [0.0, math.pi / 2, 2.0]),
        (between(1, 4, whole=True), [1, 4, 2.0], [0, 5, 1.5]),
        (one_of("light", "moderate"), ["light", np.str_("moderate")], ["Light", 1, None]),
        (vector(4, "pos"), [(1, 2, 3, 4)], [(1, 2, 3, 0), (1, 2, 3)]),
        (instance_of(tuple), [(1,), ()], [[1], None, "x"]),
        (Check("even", "an even number", lambda v: isinstance(v, int) and v % 2 == 0), [2, 0], [1, "2"]),
    ],
)
def test_each_check_accepts_good_and_refuses_bad_in_one_line(check, good, bad):
    for value in good:
        probe(check, value)
    for value in bad:
        refused(check, value)


def test_stored_forms():
    assert probe("pos", 2) == 2.0 and type(probe("pos", np.float32(2.5))) is float
    assert probe("sign", -1.0) == -1 and type(probe("sign", -1.0)) is int
    assert probe("whole", 3.0) == 3 and type(probe("whole", 3.0)) is int
    assert probe("flag", 1) is True
    assert probe("pair", np.array([1, 2])) == (1.0, 2.0)
    assert probe(one_of("x", "y"), np.str_("x")) == "x" and type(probe(one_of("x", "y"), np.str_("x"))) is str
    assert probe("real", np.array(2.0)) == 2.0  # a 0-d array is a number


def test_messages_say_what_was_wrong():
    assert refused("pos", 0.0).endswith("must be > 0, got 0.0")
    assert refused("pos", math.nan).endswith("must be finite, got nan")
    assert refused("real", "1").endswith("must be a number, got '1'")
    assert refused(between(0.0, 1.0, "[)"), 1.0).endswith("must be in [0, 1), got 1.0")
    assert refused("frac", 2.0, optional=True).endswith("must be in [0, 1] or None, got 2.0")
    assert refused(instance_of(tuple), [1]).endswith("must be a tuple, got [1]")
    assert "must be a number or a 1-D array of numbers" in refused("pos", np.ones((40, 40)), batch=True)
    assert len(refused("pos", np.ones((40, 40)), batch=True)) < 250  # a long value is cut short


def test_batched_fields_hold_one_value_per_vehicle():
    arr = probe("pos", [1, 2, 3], batch=True)
    assert isinstance(arr, np.ndarray) and arr.dtype == float and arr.tolist() == [1.0, 2.0, 3.0]
    assert not arr.flags.writeable
    source = np.array([1.0, 2.0])
    stored = probe("pos", source, batch=True)
    source[0] = -5.0
    assert stored[0] == 1.0  # a copy
    assert refused("pos", [1.0, -2.0, 3.0], batch=True).endswith("got -2.0 (entry 1 of 3)")
    assert refused("pos", [1.0, math.nan], batch=True).endswith("must be finite, got nan (entry 1 of 2)")
    for bad in ([], [[1.0]], ["a"], [True, False]):
        refused("pos", bad, batch=True)
    refused("pos", [1.0, 2.0])  # not batched: one number
    x, y, z = probe("vec", np.ones((4, 3)), batch=True, default=(0.0, 0.0, 0.0))  # (N, 3) -> columns
    assert x.shape == (4,) and isinstance(y, np.ndarray)
    assert probe("vec", ([1.0, 2.0], 0.0, 0), batch=True, default=(0.0, 0.0, 0.0))[1] == 0.0


def test_batch_lengths_must_agree():
    @dataclass(frozen=True)
    class Two(Validated):
        name = "two"
        a: Any = unit_field(1.0, "m", "a", "real", batch=True)
        b: Any = unit_field((0.0, 0.0), "m", "b", "pair", batch=True)

    assert validate(Two(a=[1.0, 2.0], b=([1.0, 2.0], 0.0))) == 2
    assert validate(Two()) is None
    with pytest.raises(InputError, match=r"two fields have different batch lengths \[2, 3\]"):
        Two(a=[1.0, 2.0], b=(0.0, [1.0, 2.0, 3.0]))


def test_optional_fields_and_required_fields():
    assert probe("pos", None, default=None) is None  # default None: optional
    refused("pos", None)  # otherwise not

    @dataclass(frozen=True)
    class Gains(Validated):
        name = "G"
        field_noun = "gain"
        kp: float = unit_field(unit="1/s^2", doc="proportional gain", check="pos")

    assert Gains(2).kp == 2.0 and Gains.units() == {"kp": "1/s^2"}
    with pytest.raises(InputError, match=r"^G gain 'kp' \(proportional gain, 1/s\^2\) must be > 0, got -1.0$"):
        Gains(-1)


def test_declaration_errors_are_programming_errors():
    with pytest.raises(TypeError):
        unit_field(1.0, "", "no unit")
    with pytest.raises(TypeError):
        unit_field(1.0, "m", "")
    with pytest.raises(TypeError):
        unit_field(1.0, "m", "length", "positive")
    with pytest.raises(ValueError):
        between(0, 1, "[[")

    @dataclass(frozen=True)
    class Bare(Validated):
        x: float = 1.0

    with pytest.raises(TypeError, match="Bare.x is not declared"):
        Bare()


def test_check_value_for_function_arguments():
    assert check_value("f argument 'w' (bandwidth, rad/s)", 15, "pos") == 15.0
    with pytest.raises(InputError, match=r"^f argument 'w' \(bandwidth, rad/s\) must be > 0, got -1.0$"):
        check_value("f argument 'w' (bandwidth, rad/s)", -1, "pos")
    assert set(CHECKS) >= {"real", "pos", "nonneg", "frac", "sign", "whole", "flag", "pair", "vec"}


# --- every parameter class of the package goes through the one mechanism ----------------------
#: dataclasses of the parameter layers that are not parameter objects with units (a table checked
#: row by row and column by column, reported with its file's lines)
NOT_PARAMETERS = {"quadcruise.missions.waypoints.WaypointTable"}
PARAMETER_PACKAGES = ("quadcruise.model", "quadcruise.missions", "quadcruise.control", "quadcruise.disturbances")


def package_dataclasses():
    found = {}
    for info in pkgutil.walk_packages(quadcruise.__path__, "quadcruise."):
        if not info.name.startswith(PARAMETER_PACKAGES):
            continue
        module = importlib.import_module(info.name)
        for obj in vars(module).values():
            if inspect.isclass(obj) and dataclasses.is_dataclass(obj) and obj.__module__ == info.name:
                found[f"{obj.__module__}.{obj.__qualname__}"] = obj
    return found


def test_every_parameter_class_is_validated_and_every_field_has_unit_doc_and_check():
    classes = package_dataclasses()
    expected = {
        "Vehicle",
        "Mission",
        "Hover",
        "Step",
        "Circle",
        "Square",
        "Waypoints",
        "MinimumSnap",
        "ConstantWind",
        "Gust",
        "Turbulence",
        "RotorLoss",
        "ExternalForce",
        "SensorNoise",
        "Environment",
        "CustomDisturbance",
        "Controller",
        "NLPD",
        "Gonzalez",
        "SE3",
        "Cascade",
        "PDGains",
        "PIDGains",
        "RateGains",
    }
    assert expected <= {c.__name__ for c in classes.values()}
    missing = []
    for qualname, cls in sorted(classes.items()):
        if qualname in NOT_PARAMETERS:
            continue
        if not issubclass(cls, Validated):
            missing.append(f"{qualname} does not derive from quadcruise.fields.Validated")
        for f in dataclasses.fields(cls):
            meta = f.metadata
            if not (meta.get("unit") and meta.get("doc") and isinstance(meta.get("check"), Check)):
                missing.append(f"{qualname}.{f.name} has no unit, doc or check: declare it with unit_field")
    assert not missing, "\n".join(missing)


def test_units_of_parameter_classes():
    from quadcruise.control import NLPD, Cascade
    from quadcruise.disturbances import Environment, SensorNoise
    from quadcruise.missions import Circle

    assert quadcruise.Vehicle.units()["omega"] == "rad/s" and Circle.units()["period"] == "s"
    units = NLPD.units()
    assert units["position.kp"] == "1/s^2" and units["attitude.ki"] == "1/s^3" and units["max_tilt"] == "rad"
    assert "position" not in units
    assert Cascade.units()["rate.kd"] == "-" and Cascade.units()["vel_d_cutoff"] == "Hz"
    assert Environment.units()["turbulence.altitude"] == "m" and SensorNoise.units()["delay"] == "s"


@pytest.mark.parametrize(
    "make, words",
    [
        (lambda: quadcruise.Vehicle(m=0.0), "vehicle field 'm' (mass, kg) must be > 0, got 0.0"),
        (
            lambda: __import__("quadcruise.missions", fromlist=["Circle"]).Circle(center=(1.0,)),
            "circle field 'center' (centre (x, y), m) must be a pair of numbers",
        ),
        (
            lambda: __import__("quadcruise.disturbances", fromlist=["Gust"]).Gust(duration=-1.0),
            "gust field 'duration' (gust duration, s) must be > 0, got -1.0",
        ),
        (
            lambda: __import__("quadcruise.disturbances", fromlist=["RotorLoss"]).RotorLoss(rotor=5),
            "loss field 'rotor' (rotor number, -) must be a whole number in [1, 4], got 5.0",
        ),
        (
            lambda: __import__("quadcruise.control", fromlist=["SE3"]).SE3(max_tilt=2.0),
            "se3 parameter 'max_tilt' (largest tilt of b3_d from the vertical, rad) must be in (0, pi/2), got 2.0",
        ),
        (
            lambda: __import__("quadcruise.control", fromlist=["Cascade"]).Cascade(rate=None),
            "cascade parameter 'rate' (roll and pitch rate PID, -) must be a RateGains, got None",
        ),
        (
            lambda: __import__("quadcruise.control.design", fromlist=["PIDGains"]).PIDGains(1.0, -1.0, 0.0),
            "PID gain 'ki' (integral gain, 1/s^3) must be >= 0, got -1.0",
        ),
    ],
)
def test_package_messages_name_owner_field_meaning_unit(make, words):
    with pytest.raises(InputError) as err:
        make()
    assert str(err.value).startswith(words) and "\n" not in str(err.value)


# --- KEY=VALUE -------------------------------------------------------------------------------
def test_parse_assignments_values():
    got = parse_assignments(["radius=3", "center=1,2.5", "axis=x", "ff=True", "scale=-2e-3", "path=a,b.csv"], "-m")
    assert got == {"radius": 3, "center": (1, 2.5), "axis": "x", "ff": True, "scale": -0.002, "path": "a,b.csv"}
    assert type(got["radius"]) is int
    assert parse_assignments("a=1, b = 2 ,c=3", "-m") == {"a": 1, "b": 2, "c": 3}
    assert parse_assignments([], "-m") == {}
    assert parse_assignments("Position=0.1", "noise", keys={"position": "position_std"}) == {"position_std": 0.1}


@pytest.mark.parametrize(
    "items, kw, words",
    [
        (["radius"], {}, "-m 'radius': expected KEY=VALUE"),
        (("a=1", "a=2"), {}, "-m 'a=2': 'a' is given twice; give each key once"),
        ("Position=0.1,position=0.2", {"keys": {"position": "position_std"}}, "'position_std' is given twice"),
        (["=3"], {}, "-m '=3': expected KEY=VALUE"),
        (["radius="], {}, "-m 'radius=': expected KEY=VALUE"),
        ("jitter=1", {"keys": ["position", "rate"]}, "-m 'jitter=1': unknown key 'jitter'; keys: position, rate"),
        ("postion=1", {"keys": ["position", "rate"]}, "unknown key 'postion' (did you mean 'position'?)"),
        ("rate=fast", {"numbers": True}, "-m 'rate=fast': the value must be a number, got 'fast'"),
        ("center=1,x", {"numbers": True}, "-m 'center=1,x': the value must be a number, got '1,x'"),
    ],
)
def test_parse_assignments_refuses_bad_items_in_one_line(items, kw, words):
    with pytest.raises(InputError) as err:
        parse_assignments(items, "-m", **kw)
    assert words in str(err.value) and "\n" not in str(err.value)


def test_parse_numbers():
    assert parse_numbers("1, 2,3", "X,Y,Z", 3) == [1.0, 2.0, 3.0] and parse_numbers("4", "T") == [4.0]
    with pytest.raises(InputError, match=r"^needs 3 values X,Y,Z, got '1,2'$"):
        parse_numbers("1,2", "X,Y,Z", 3)
    with pytest.raises(InputError, match=r"^needs 1 value T, got '1,2'$"):
        parse_numbers("1,2", "T", 1)
    with pytest.raises(InputError, match=r"^X,Y must be numbers, got 'a,b'$"):
        parse_numbers("a,b", "X,Y")
