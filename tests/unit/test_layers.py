"""The package's layers: every import (lazy ones inside functions included) runs downward, no
import cycle, no private name imported from another module.

The ranks below are the architecture; docs/architecture.md explains them. A module may import
from a lower rank, and from its own subpackage as long as the graph stays acyclic.
"""

from __future__ import annotations

import ast
from pathlib import Path

import pytest

import quadcruise

PACKAGE = Path(quadcruise.__file__).parent

#: bottom (0) to top: a module may import only from a lower rank or from its own subpackage
RANKS = {
    "quadcruise._version": 0,
    "quadcruise.errors": 0,
    "quadcruise.layout": 0,
    "quadcruise._cache": 0,
    "quadcruise.protocols": 0,
    "quadcruise.numeric": 0,
    "quadcruise.fields": 1,
    "quadcruise.checks": 1,
    "quadcruise.io": 1,
    "quadcruise.model": 2,
    "quadcruise.metrics": 3,
    "quadcruise.plots": 4,
    "quadcruise.sim": 5,
    "quadcruise.missions": 6,
    "quadcruise.control": 7,
    "quadcruise.disturbances": 8,
    "quadcruise.sensors": 8,
    "quadcruise.estimation": 8.5,
    "quadcruise.workflows": 9,
    "quadcruise.sysid": 9,
    "quadcruise.montecarlo": 10,
    "quadcruise.tune": 11,
    "quadcruise.gym": 11,
    "quadcruise.report": 12,
    "quadcruise.cli": 13,
    "quadcruise": 14,
    "quadcruise.__main__": 14,
}


def module_name(path: Path) -> str:
    parts = ("quadcruise",) + path.relative_to(PACKAGE).with_suffix("").parts
    return ".".join(parts[:-1] if parts[-1] == "__init__" else parts)


MODULES = {module_name(p): p for p in sorted(PACKAGE.rglob("*.py"))}


def group(module: str) -> str:
    """The layer a module belongs to: its subpackage, or itself for a top-level module."""
    parts = module.split(".")
    for k in range(len(parts), 0, -1):
        if ".".join(parts[:k]) in RANKS:
            return ".".join(parts[:k])
    raise KeyError(module)


def imports(module: str) -> list[tuple[str, list[str], int]]:
    """(imported module, names, line) of every import statement in the module, at any depth."""
    path = MODULES[module]
    package = module if path.name == "__init__.py" else module.rpartition(".")[0]
    out = []
    for node in ast.walk(ast.parse(path.read_text(), str(path))):
        if isinstance(node, ast.Import):
            out += [(a.name, [], node.lineno) for a in node.names if a.name.startswith("quadcruise")]
        elif isinstance(node, ast.ImportFrom):
            if node.level:
                base = package.split(".")[: len(package.split(".")) - node.level + 1]
                target = ".".join(base + ([node.module] if node.module else []))
            else:
                target = node.module or ""
            if not target.startswith("quadcruise"):
                continue
            names = [a.name for a in node.names]
            subs = [f"{target}.{n}" for n in names if f"{target}.{n}" in MODULES]
            out += [(s, [], node.lineno) for s in subs]
            rest = [n for n in names if f"{target}.{n}" not in MODULES]
            if rest or not subs:
                out.append((target, rest, node.lineno))
    return out


def edges() -> dict[str, set[str]]:
    graph: dict[str, set[str]] = {m: set() for m in MODULES}
    for m in MODULES:
        for target, _, _ in imports(m):
            assert target in MODULES, f"{m} imports {target}, which does not exist"
            if target != m:
                graph[m].add(target)
    return graph


def test_every_module_has_a_layer():
    missing = [m for m in MODULES if not any(m == g or m.startswith(g + ".") for g in RANKS)]
    assert not missing


def test_imports_run_downward():
    upward = []
    for m in MODULES:
        for target, _, line in imports(m):
            gm, gt = group(m), group(target)
            if gm != gt and RANKS[gt] >= RANKS[gm]:
                upward.append(f"{MODULES[m].relative_to(PACKAGE)}:{line} {m} ({gm}) imports {target} ({gt})")
    assert not upward, "\n".join(upward)


def test_no_import_cycle():
    graph, state, cycles = edges(), {}, []

    def visit(node, stack):
        state[node] = "open"
        for nxt in sorted(graph[node]):
            if state.get(nxt) == "open":
                cycles.append(" -> ".join(stack[stack.index(nxt) :] + [nxt]))
            elif nxt not in state:
                visit(nxt, stack + [nxt])
        state[node] = "done"

    for m in sorted(graph):
        if m not in state:
            visit(m, [m])
    assert not cycles, "\n".join(cycles)


def test_no_private_name_crosses_modules():
    crossing = [
        f"{MODULES[m].relative_to(PACKAGE)}:{line} imports {n} from {target}"
        for m in MODULES
        for target, names, line in imports(m)
        for n in names
        if n.startswith("_") and not n.startswith("__")
    ]
    assert not crossing, "\n".join(crossing)


@pytest.mark.parametrize(
    "low,high", [("quadcruise.sim.engine", "quadcruise.report"), ("quadcruise.model.plant", "quadcruise.sim")]
)
def test_the_check_sees_an_upward_import(low, high):
    """The rule itself: a low module importing a high one is upward (the check can fail)."""
    assert RANKS[group(high)] > RANKS[group(low)]


MAX_MODULE_LINES = 650
"""No grab-bag modules: each one idea, readable in one sitting (docs/architecture.md)."""


def long_modules(limit: int = MAX_MODULE_LINES) -> dict[str, int]:
    """The modules of the package over ``limit`` lines, with their line counts."""
    counts = {m: len(p.read_text().splitlines()) for m, p in MODULES.items()}
    return {m: n for m, n in counts.items() if n > limit}


def test_no_module_is_over_the_line_limit():
    assert not long_modules(), long_modules()


def test_the_line_limit_sees_a_long_module():
    """The rule itself: lowered below the engine's length, the check names the engine, and at its
    length it does not."""
    length = len(MODULES["quadcruise.sim.engine"].read_text().splitlines())
    assert "quadcruise.sim.engine" in long_modules(limit=length - 1)
    assert "quadcruise.sim.engine" not in long_modules(limit=length)
