"""Each packed row (a controller's gains and memory, a disturbance's parameters and memory) is
declared once, as a :class:`quadcruise.layout.Row`: the constants the compiled code reads are
unpacked from its offsets under the names of its fields, in its order."""

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
