"""Each packed row (the engine's state, reference, command, vehicle parameters and external
inputs, a controller's gains and memory, a disturbance's parameters and memory) is declared once,
as a :class:`quadcruise.layout.Row`: the constants the compiled code reads are unpacked from its
offsets under the names of its fields, in its order."""

from __future__ import annotations

import ast
import importlib
from pathlib import Path

import numpy as np
import pytest

import quadcruise
from quadcruise.layout import Row

PACKAGE = Path(quadcruise.__file__).parent


def offset_unpackings():
    """(module, row variable, the names assigned, line) of every ``A, B = ROW.offsets``."""
    out = []
    for path in sorted(PACKAGE.rglob("*.py")):
        module = ".".join(("quadcruise",) + path.relative_to(PACKAGE).with_suffix("").parts)
        for node in ast.parse(path.read_text()).body:
            value = getattr(node, "value", None)
            if (
                isinstance(node, ast.Assign)
                and isinstance(value, ast.Attribute)
                and value.attr == "offsets"
                and isinstance(value.value, ast.Name)
            ):
                target = node.targets[0]
                names = [e.id for e in target.elts] if isinstance(target, ast.Tuple) else [target.id]
                out.append((module.removesuffix(".__init__"), value.value.id, names, node.lineno))
    return out


UNPACKINGS = offset_unpackings()


def test_the_rows_are_found():
    rows = {(m, r) for m, r, _, _ in UNPACKINGS}
    assert len(rows) >= 10, rows  # the controllers' gains and memories, the environment's rows
    assert ("quadcruise.control.position", "NLPD_GAINS") in rows
    assert ("quadcruise.disturbances.environment", "ENVIRONMENT_PARAMS") in rows


@pytest.mark.parametrize("module, row, names, line", UNPACKINGS, ids=[f"{m}:{r}" for m, r, _, _ in UNPACKINGS])
def test_constants_are_named_after_the_fields_in_order(module, row, names, line):
    declared = getattr(importlib.import_module(module), row)
    assert isinstance(declared, Row)
    assert names == [declared.prefix + field.upper() for field, _ in declared.fields], f"{module}:{line}"


def test_no_two_rows_give_one_constant_two_offsets():
    """The complaint this layout answers: ``KP_Z`` meant two offsets in two controllers."""
    seen: dict[str, tuple[int, str]] = {}
    for module, _, names, _ in UNPACKINGS:
        mod = importlib.import_module(module)
        for name in names:
            value = getattr(mod, name)
            assert seen.setdefault(name, (value, module))[0] == value, (name, seen[name], module)


def test_pack_puts_each_field_at_its_offset_and_refuses_what_does_not_fit():
    base = Row.of("base", "a", ("v", 3))
    row = Row.of("row", "b", "c", parent=base, prefix="R_")
    assert row.offsets == (4, 5) and row.size == 6 and row.names == ("a", "v[0]", "v[1]", "v[2]", "b", "c")
    packed = row.pack({"a": 1.0, "v": (2.0, 3.0, 4.0), "b": 5.0, "c": 6.0})
    assert packed.tolist() == [1.0, 2.0, 3.0, 4.0, 5.0, 6.0]
    batch = row.pack({"v": np.arange(6.0).reshape(2, 3), "c": [7.0, 8.0]}, n=2, default=0.0)
    np.testing.assert_array_equal(batch, [[0, 0, 1, 2, 0, 7], [0, 3, 4, 5, 0, 8]])
    with pytest.raises(ValueError, match="missing"):
        row.pack({"a": 1.0})
    with pytest.raises(ValueError, match="unknown"):
        row.pack({"a": 1.0, "q": 2.0}, default=0.0)
    with pytest.raises(ValueError, match="'v' takes 3 values, got 2"):
        row.pack({"v": (1.0, 2.0)}, default=0.0)
    with pytest.raises(ValueError, match="unique"):
        Row.of("twice", "a", parent=base)


@pytest.mark.parametrize("name", ["nlpd", "gonzalez", "se3", "cascade"])
def test_each_controller_packs_its_declared_row(name):
    from quadcruise.control import controller_from_name

    controller = controller_from_name(name)
    module = importlib.import_module(type(controller).__module__)
    row = getattr(module, f"{name.upper()}_GAINS")
    assert controller.gains().shape == (row.size,) == (len(row.names),)
    assert np.all(np.isfinite(controller.gains()))


def test_the_kernel_takes_its_declared_arguments_flat_and_in_order():
    """KernelArgs declares the kernel's arguments once; the kernel stays a flat list (faster
    than tuples: docs/performance.md), and its parameters are those fields, in order."""
    import inspect

    from quadcruise.sim import engine
    from quadcruise.sim.kernel_args import KERNEL_SIG, KernelArgs

    parameters = tuple(inspect.signature(engine._kernel.py_func).parameters)
    assert parameters == ("first", "stop") + KernelArgs._fields
    assert len(KERNEL_SIG.args) == len(parameters) and engine._kernel.signatures == [KERNEL_SIG.args]


#: The engine's vectors as the documentation gives them: (row, constants in column order,
#: names in tables), written out here independently of quadcruise.layout.
ENGINE_LAYOUTS = {
    "STATE": (
        "X Y Z VX VY VZ PHI THETA PSI P Q R F1 F2 F3 F4",
        "x y z vx vy vz phi theta psi p q r F1 F2 F3 F4",
    ),
    "REFERENCE": (
        "REF_X REF_Y REF_Z REF_VX REF_VY REF_VZ REF_AX REF_AY REF_AZ REF_PSI REF_PSI_DOT",
        "x_ref y_ref z_ref vx_ref vy_ref vz_ref ax_ref ay_ref az_ref psi_ref psi_dot_ref",
    ),
    "COMMAND": (
        "CMD_U1 CMD_U2 CMD_U3 CMD_U4 CMD_THRUST CMD_TAU_PHI CMD_TAU_THETA CMD_TAU_PSI CMD_PHI_D CMD_THETA_D"
        " CMD_PSI_D CMD_FLAGS",
        "u1 u2 u3 u4 U1_d U2_d U3_d U4_d phi_d theta_d psi_d flags",
    ),
    "PARAMS": (
        "P_M P_JXX P_JYY P_JZZ P_L P_K P_OMEGA P_D P_G P_K1 P_K2 P_K3 P_K4 P_K5 P_K6 P_CD1 P_CD2 P_INV_M"
        " P_INV_JXX P_INV_JYY P_INV_JZZ",
        None,
    ),
    "EXTERNAL": (
        "EXT_FX EXT_FY EXT_FZ EXT_TX EXT_TY EXT_TZ EXT_WX EXT_WY EXT_WZ EXT_E1 EXT_E2 EXT_E3 EXT_E4",
        None,
    ),
}
SIZES = {"STATE": "STATE_SIZE", "REFERENCE": "REF_SIZE", "COMMAND": "CMD_SIZE", "PARAMS": "PARAM_SIZE"}
NAMES = {"STATE": "STATE_NAMES", "REFERENCE": "REF_NAMES", "COMMAND": "CMD_NAMES"}


@pytest.mark.parametrize("row", ENGINE_LAYOUTS)
def test_each_engine_layout_is_one_row_and_its_constants_are_its_columns(row):
    """The state, reference, command, vehicle parameter and external-input layouts are each one
    Row; its constants, size and names are that row's, and they are the documented columns, both
    ways: each constant is its column's offset, each offset's field gives that constant."""
    from quadcruise import layout

    declared = getattr(layout, row)
    constants, names = (s.split() for s in (ENGINE_LAYOUTS[row][0], ENGINE_LAYOUTS[row][1] or ""))
    assert isinstance(declared, Row) and declared.parent is None
    assert declared.size == len(constants) == getattr(layout, SIZES.get(row, "EXT_SIZE"))
    for column, constant in enumerate(constants):
        value = getattr(layout, constant)
        assert type(value) is int and value == column, (constant, value, column)  # constant -> column
    fields = [field for field, _ in declared.fields]
    assert [declared.prefix + field.upper() for field in fields] == constants  # column -> constant
    assert all(width == 1 for _, width in declared.fields)
    if names:
        assert getattr(layout, NAMES[row]) == tuple(names)


def test_the_state_units_are_those_of_its_columns():
    from quadcruise.layout import F1, PSI, STATE, STATE_UNITS, VZ, P, R, X, Z

    assert len(STATE_UNITS) == STATE.size
    assert STATE_UNITS[X] == STATE_UNITS[Z] == "m" and STATE_UNITS[VZ] == "m/s"
    assert STATE_UNITS[PSI] == "rad" and STATE_UNITS[P] == STATE_UNITS[R] == "rad/s" and STATE_UNITS[F1] == "N"
    assert STATE_UNITS == ("m",) * 3 + ("m/s",) * 3 + ("rad",) * 3 + ("rad/s",) * 3 + ("N",) * 4
