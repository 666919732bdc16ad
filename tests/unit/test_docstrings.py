"""Every public function, method and class of the package has a numpydoc docstring.

The rules, checked on each module's source with :mod:`ast` (a numba-compiled function
counts by its Python source):

- public means a name that does not start with ``_``, defined in the module (not
  imported); methods of public classes count, nested functions do not;
- every public function, method, property and class has a docstring;
- a function or method that takes arguments (besides ``self``/``cls``) has a
  ``Parameters`` section (``Other Parameters`` counts too) naming exactly its arguments:
  no argument left out, no name that the signature lacks; ``a, b : float`` documents
  both, and ``*args``/``**kwargs`` are written with or without their stars;
- a function that returns a value (a ``return <value>`` other than ``return None``, or,
  for a stub whose body only raises, a return annotation other than None) has a
  ``Returns`` section, and a generator a ``Yields`` section (either one satisfies both);
- a class documents its constructor's arguments in a ``Parameters`` section of the class
  docstring (for a dataclass: its ``__init__`` fields); properties need only a docstring.

Each module is one test. The modules that are not documented yet are listed in
``NOT_YET`` and expected to fail (strictly: once a module passes, its xfail turns into
an error, and its name must leave the list). Run this file as a script for the coverage
table, per module and per subpackage::

    python tests/unit/test_docstrings.py
"""

from __future__ import annotations

import ast
import dataclasses
import importlib
import inspect
import re
import sys
from collections import defaultdict
from functools import cache
from pathlib import Path

import pytest

PACKAGE = Path(__file__).resolve().parents[2] / "src" / "quadcruise"

# Modules whose public names are not documented to the standard yet; a later pass covers
# them. Strict xfail: when a module passes, remove it from this list.
NOT_YET: set[str] = set()          # every module is documented; a new one must be too

# Public names that cannot carry the sections ("module.qualname" -> the reason). Keep it
# short: an entry here is a name nobody is asked to document. None is needed so far:
# - a click command's docstring is its --help text, but click cuts the help at a line
#   holding only "\f", so the numpydoc sections go after such a line;
# - a compiled (numba) function with many arguments documents them like any other, grouped
#   where they share a meaning ("sphi, cphi : float").
ALLOWED: dict[str, str] = {
}

_HEADER = re.compile(r"^[A-Z][A-Za-z ]*$")
_RULE = re.compile(r"^-{3,}$")
_NAMES = re.compile(r"^(\*{0,2}[A-Za-z_]\w*(\s*,\s*\*{0,2}[A-Za-z_]\w*)*)\s*(:.*)?$")  # "a, b : float"


@dataclasses.dataclass
class Item:
    """One public name and what is wrong with its docstring (nothing: documented)."""

    module: str
    qualname: str
    kind: str
    line: int
    problems: list[str]


def module_names() -> list[str]:
    """Dotted names of every module of the package, from its source files."""
    names = []
    for path in sorted(PACKAGE.rglob("*.py")):
        parts = path.relative_to(PACKAGE.parent).with_suffix("").parts
        names.append(".".join(parts[:-1] if parts[-1] == "__init__" else parts))
    return names


def module_path(module: str) -> Path:
    """The source file of a dotted module name."""
    rel = Path(*module.split(".")[1:])
    package_init = PACKAGE / rel / "__init__.py"
    return package_init if package_init.exists() else (PACKAGE / rel).with_suffix(".py")


def sections(doc: str) -> dict[str, list[str]]:
    """The numpydoc sections of a (cleaned) docstring: title -> its lines."""
    lines = doc.splitlines()
    heads = [i for i in range(len(lines) - 1)
             if _HEADER.match(lines[i].strip()) and _RULE.match(lines[i + 1].strip())]
    out = {}
    for k, i in enumerate(heads):
        end = heads[k + 1] if k + 1 < len(heads) else len(lines)
        out[lines[i].strip()] = lines[i + 2:end]
    return out


def documented_names(doc: str) -> list[str]:
    """The names listed in the Parameters (and Other Parameters) sections."""
    found = sections(doc)
    names = []
    for title in ("Parameters", "Other Parameters"):
        for line in found.get(title, []):
            match = _NAMES.match(line)           # an entry; an indented line is its description
            if match:
                names += [name.strip().lstrip("*") for name in match.group(1).split(",")]
    return names


def _own_nodes(node):
    """The nodes of a function's body, not descending into nested functions or classes."""
    todo = list(node.body)
    while todo:
        child = todo.pop()
        yield child
        if not isinstance(child, ast.FunctionDef | ast.AsyncFunctionDef | ast.ClassDef | ast.Lambda):
            todo.extend(ast.iter_child_nodes(child))


def _is_stub(node) -> bool:
    body = node.body[1:] if ast.get_docstring(node) is not None else node.body
    return all(isinstance(s, ast.Pass | ast.Raise) or (isinstance(s, ast.Expr) and isinstance(s.value, ast.Constant))
               for s in body)


def _returns_value(node) -> bool:
    for child in _own_nodes(node):
        if isinstance(child, ast.Return) and child.value is not None:
            if not (isinstance(child.value, ast.Constant) and child.value.value is None):
                return True
    annotation = node.returns
    return (_is_stub(node) and annotation is not None
            and not (isinstance(annotation, ast.Constant) and annotation.value in (None, "None")))


def _yields(node) -> bool:
    return any(isinstance(child, ast.Yield | ast.YieldFrom) for child in _own_nodes(node))


def _decorators(node) -> set[str]:
    names = set()
    for dec in node.decorator_list:
        target = dec.func if isinstance(dec, ast.Call) else dec
        names.add(ast.unparse(target).split(".")[-1])
    return names


def _argument_names(node, method: bool) -> list[str]:
    args = node.args
    names = [a.arg for a in args.posonlyargs + args.args]
    if method and "staticmethod" not in _decorators(node):
        names = names[1:]
    names += [a.arg for a in args.kwonlyargs]
    names += [a.arg for a in (args.vararg, args.kwarg) if a is not None]
    return names


def _compare_names(expected: list[str], doc: str) -> list[str]:
    problems = []
    if not expected:
        return problems
    found = sections(doc)
    if "Parameters" not in found and "Other Parameters" not in found:
        return [f"no Parameters section (arguments: {', '.join(expected)})"]
    documented = documented_names(doc)
    missing = [name for name in expected if name not in documented]
    extra = [name for name in documented if name not in expected]
    if missing:
        problems.append(f"arguments not documented: {', '.join(missing)}")
    if extra:
        problems.append(f"documented but not arguments: {', '.join(extra)}")
    return problems


def _check_function(node, method: bool) -> tuple[str, list[str]]:
    decorators = _decorators(node)
    doc = ast.get_docstring(node)
    if {"property", "cached_property"} & decorators:
        return "property", [] if doc else ["no docstring"]
    if doc is None:
        return ("method" if method else "function"), ["no docstring"]
    problems = _compare_names(_argument_names(node, method), doc)
    found = sections(doc)
    if (_returns_value(node) or _yields(node)) and not {"Returns", "Yields"} & set(found):
        problems.append("returns a value but has no Returns (or Yields) section")
    return ("method" if method else "function"), problems


def _constructor_arguments(node, module: str, qualname: str) -> list[str]:
    """The arguments of a class's constructor, if a class of this package defines it."""
    init = next((n for n in node.body if isinstance(n, ast.FunctionDef) and n.name == "__init__"), None)
    if init is not None and not node.decorator_list:
        return _argument_names(init, method=True)
    if not node.bases and not node.decorator_list:
        return []                        # object's constructor
    obj = importlib.import_module(module)  # a dataclass, or a constructor it may inherit
    for part in qualname.split("."):
        obj = getattr(obj, part)
    for klass in obj.__mro__:
        if "__init__" in vars(klass):
            init = vars(klass)["__init__"]
            if not getattr(init, "__module__", klass.__module__).startswith("quadcruise"):
                return []                # e.g. typing.Protocol's own placeholder
            params = list(inspect.signature(init).parameters.values())[1:]
            return [p.name for p in params]
    return []


def _walk(body, module: str, prefix: str, in_class: bool, items: list[Item]) -> None:
    for node in body:
        if isinstance(node, ast.If | ast.Try) and not in_class:
            _walk(node.body + node.orelse + getattr(node, "finalbody", []), module, prefix, in_class, items)
            continue
        if not isinstance(node, ast.FunctionDef | ast.AsyncFunctionDef | ast.ClassDef):
            continue
        if node.name.startswith("_"):
            continue
        qualname = f"{prefix}{node.name}"
        if f"{module}.{qualname}" in ALLOWED:
            continue
        if isinstance(node, ast.ClassDef):
            doc = ast.get_docstring(node)
            if doc is None:
                problems = ["no docstring"]
            else:
                problems = _compare_names(_constructor_arguments(node, module, qualname), doc)
            items.append(Item(module, qualname, "class", node.lineno, problems))
            _walk(node.body, module, f"{qualname}.", True, items)
        else:
            if in_class and _decorators(node) & {"setter", "deleter", "overload"}:
                continue
            if "overload" in _decorators(node):
                continue
            kind, problems = _check_function(node, in_class)
            items.append(Item(module, qualname, kind, node.lineno, problems))


def check_source(source: str, module: str) -> list[Item]:
    """Every public name defined in ``source`` (the text of ``module``) with its problems."""
    items: list[Item] = []
    _walk(ast.parse(source).body, module, "", False, items)
    return items


@cache
def check_module(module: str) -> tuple[Item, ...]:
    """Every public name of a module with its problems."""
    return tuple(check_source(module_path(module).read_text(), module))


def subpackage(module: str) -> str:
    """``quadcruise.metrics.flight`` -> ``metrics``; a top-level module -> ``(top level)``."""
    parts = module.split(".")
    if len(parts) > 2 or module_path(module).name == "__init__.py" and len(parts) == 2:
        return parts[1]
    return "(top level)"


def coverage(modules) -> tuple[int, int]:
    """(documented, total) public names of the given modules."""
    items = [item for m in modules for item in check_module(m)]
    return sum(not item.problems for item in items), len(items)


def _percent(done: int, total: int) -> str:
    return f"{100.0 * done / total:.1f} % ({done}/{total})" if total else "n/a (0 public names)"


def coverage_table() -> str:
    """Coverage by subpackage and overall, as text."""
    groups = defaultdict(list)
    for m in module_names():
        groups[subpackage(m)].append(m)
    lines = [f"{name:<14} {_percent(*coverage(mods))}" for name, mods in sorted(groups.items())]
    lines.append(f"{'overall':<14} {_percent(*coverage(module_names()))}")
    return "\n".join(lines)


def _param(module: str):
    if module in NOT_YET:
        return pytest.param(module, marks=pytest.mark.xfail(strict=True, reason="not documented yet (NOT_YET)"))
    return module


_SAMPLE = '''
def good(a, b, *args, c=1, **kwargs):
    """Sum.

    Parameters
    ----------
    a, b : float
        Two numbers [m].
    *args : float
        More.
    c : int
        A count.
    **kwargs
        Ignored.

    Returns
    -------
    float
        The sum [m].
    """
    return a + b


def stale(a, b):
    """Sum.

    Parameters
    ----------
    a : float
        A number.
    old : float
        Gone from the signature.
    """


def counts(n):
    """Count.

    Parameters
    ----------
    n : int
        How far.

    Yields
    ------
    int
        0 .. n - 1.
    """
    yield from range(n)


def no_returns():
    """One."""
    def inner():
        return 2
    return 1


def returns_none(x):
    """Nothing.

    Parameters
    ----------
    x : int
        Ignored.
    """
    return None


def _private(x):
    return x


class Box:
    """A box."""

    @property
    def size(self):
        """Its size [m]."""
        return 1.0

    def fill(self, what):
        return what
'''


def test_the_checker_reads_numpydoc():
    found = {item.qualname: item.problems for item in check_source(_SAMPLE, "sample")}
    assert found == {
        "good": [],
        "stale": ["arguments not documented: b", "documented but not arguments: old"],
        "counts": [],
        "no_returns": ["returns a value but has no Returns (or Yields) section"],
        "returns_none": [],
        "Box": [],
        "Box.size": [],
        "Box.fill": ["no docstring"],
    }


def test_not_yet_names_modules():
    unknown = NOT_YET - set(module_names())
    assert not unknown, f"NOT_YET names modules that do not exist: {sorted(unknown)}"


def test_allowed_names_exist():
    missing = []
    for name in ALLOWED:
        module, _, qualname = name.rpartition(".")
        while module and module not in module_names():
            module, _, head = module.rpartition(".")
            qualname = f"{head}.{qualname}"
        if not module or qualname.split(".")[0] not in module_path(module).read_text():
            missing.append(name)
    assert not missing, f"ALLOWED names things that do not exist: {missing}"


@pytest.mark.parametrize("module", [_param(m) for m in module_names()])
def test_public_names_documented(module):
    bad = [item for item in check_module(module) if item.problems]
    report = "\n".join(f"  {module_path(module).relative_to(PACKAGE.parent)}:{item.line} {item.kind} "
                       f"{item.qualname}: {'; '.join(item.problems)}" for item in bad)
    assert not bad, (f"{len(bad)} public names of {module} lack numpydoc sections "
                     f"(module {_percent(*coverage([module]))}, package {_percent(*coverage(module_names()))}):\n"
                     f"{report}")


if __name__ == "__main__":
    sys.path.insert(0, str(PACKAGE.parent))
    for m in module_names():
        bad = [item for item in check_module(m) if item.problems]
        print(f"{m:<40} {_percent(*coverage([m]))}{'  NOT_YET' if m in NOT_YET else ''}")
        if "-v" in sys.argv:
            for item in bad:
                print(f"    :{item.line} {item.kind} {item.qualname}: {'; '.join(item.problems)}")
    print()
    print(coverage_table())
