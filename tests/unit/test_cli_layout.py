"""The command line's layout: cli/ is the only place that prints or uses click, one module per
command, each short; the library returns values and text.
"""

from __future__ import annotations

import ast
from pathlib import Path

import pytest

import quadcruise
from quadcruise.cli.main import main

PACKAGE = Path(quadcruise.__file__).parent
CLI = PACKAGE / "cli"
LIBRARY = sorted(p for p in PACKAGE.rglob("*.py") if CLI not in p.parents)
MAX_LINES = 280  # as ruff formats them


def printing(source: str, name: str = "<source>") -> list[str]:
    """Where ``source`` calls print, calls click.echo (or an echo imported from click) or
    imports click: ``line: what`` for each."""
    found = []
    for node in ast.walk(ast.parse(source, name)):
        if isinstance(node, ast.Import):
            found += [f"{node.lineno}: import {a.name}" for a in node.names if a.name.split(".")[0] == "click"]
        elif isinstance(node, ast.ImportFrom) and not node.level and (node.module or "").split(".")[0] == "click":
            found.append(f"{node.lineno}: from {node.module} import ...")
        elif isinstance(node, ast.Call):
            func = node.func
            if isinstance(func, ast.Name) and func.id == "print":
                found.append(f"{node.lineno}: print(")
            elif (
                isinstance(func, ast.Attribute)
                and func.attr in ("echo", "secho")
                and isinstance(func.value, ast.Name)
                and func.value.id == "click"
            ):
                found.append(f"{node.lineno}: click.{func.attr}(")
    return found


def test_the_check_sees_printing():
    source = "import click\nfrom click import echo\ndef f():\n    print('x')\n    click.echo('y')\n"
    assert printing(source) == ["1: import click", "2: from click import ...", "4: print(", "5: click.echo("]
    assert printing('def f():\n    """>>> print(1)"""\n    return "print(2)"\n') == []  # text is not a call


def test_only_the_cli_prints_or_imports_click():
    assert LIBRARY and all(p.suffix == ".py" for p in LIBRARY)
    found = [f"{p.relative_to(PACKAGE)}:{hit}" for p in LIBRARY for hit in printing(p.read_text(), str(p))]
    assert not found, "\n".join(found)


@pytest.mark.parametrize("path", sorted(CLI.glob("*.py")), ids=lambda p: p.name)
def test_every_cli_module_is_short(path):
    lines = len(path.read_text().splitlines())
    assert lines <= MAX_LINES, f"{path.name}: {lines} lines; split it or move the work into the library"


@pytest.mark.parametrize("name", sorted(main.commands))
def test_each_command_has_its_own_module(name):
    """Command ``name`` is defined in ``quadcruise.cli.<name>`` (a hyphen as an underscore), which
    defines no other."""
    module = main.commands[name].callback.__module__
    assert module == f"quadcruise.cli.{name.replace('-', '_')}"
    assert [n for n, c in main.commands.items() if c.callback.__module__ == module] == [name]


def test_the_entry_points_stay():
    """``quadcruise = quadcruise.cli.main:run``; ``quadcruise.cli`` exports main and run."""
    import importlib

    import quadcruise.cli

    module = importlib.import_module("quadcruise.cli.main")
    assert module.main is main and quadcruise.cli.main is main and quadcruise.cli.run is module.run
    assert set(main.commands) == {
        "analyze",
        "compare",
        "estimate",
        "fly",
        "identify",
        "montecarlo",
        "px4-check",
        "replay",
        "reproduce",
        "tune",
        "vehicles",
    }
