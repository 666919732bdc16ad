"""Docstrings, checked by numpydoc's own validator (``numpydoc.validate``).

- Every public function, method, property and class defined in the package has a docstring
  (public: its name and its module's do not start with ``_``).
- The public API, what users call, carries the numpydoc sections: every argument under
  Parameters and no other name (PR01, PR02), a Returns or Yields section when it returns a
  value (RT01, YD01). The public API is
  (1) the names that ``quadcruise/__init__.py`` and each subpackage's ``__init__.py`` export
  in ``__all__``; (2) the names the README and docs/ show users calling (``from quadcruise.x
  import y`` or a dotted ``quadcruise.x.y`` in their text); (3) the classes these return, by
  their return annotations; and the public methods of all these classes. A module's own
  ``__all__`` (what its siblings import) does not make a name public.
- Anything else, a helper, may be one line. Once it has sections, they are checked the same way.

Run it as a script to list every problem: ``python tests/unit/test_docstrings.py``.
"""

from __future__ import annotations

import importlib
import inspect
import pkgutil
import re
import sys
from functools import cache
from pathlib import Path

import pytest
from numpydoc.docscrape import NumpyDocString
from numpydoc.validate import validate

import quadcruise

CHECKED = {"GL08", "PR01", "PR02", "RT01", "YD01"}
"""numpydoc's codes we hold every sectioned docstring to (numpydoc.validate.ERROR_MSGS)."""


def modules() -> list[str]:
    """Every module of the package, by dotted name."""
    names = [quadcruise.__name__]
    for info in pkgutil.walk_packages(quadcruise.__path__, prefix="quadcruise."):
        if not any(part.startswith("_") for part in info.name.split(".")[1:]):
            names.append(info.name)
    return names


def _home(obj) -> str | None:
    obj = getattr(obj, "py_func", obj)  # a numba dispatcher: its Python function
    return getattr(obj, "__module__", None)


def public_names(module: str) -> list[str]:
    """``module.qualname`` of every public function, class, and public method of its classes defined there."""
    mod = importlib.import_module(module)
    out = []
    for name, obj in vars(mod).items():
        if name.startswith("_") or _home(obj) != module:
            continue
        if inspect.isclass(obj):
            out.append(f"{module}.{name}")
            for attr, member in vars(obj).items():
                if attr.startswith("_") or isinstance(member, (int, float, str, tuple, frozenset)):
                    continue
                if callable(member) or isinstance(member, (property, classmethod, staticmethod)):
                    out.append(f"{module}.{name}.{attr}")
        elif inspect.isfunction(getattr(obj, "py_func", obj)) and getattr(obj, "__name__", name) == name:
            out.append(f"{module}.{name}")  # a function defined under this name (not a constant made by one)
    return out


ROOT = Path(__file__).resolve().parents[2]
DOCS = (ROOT / "README.md", *sorted((ROOT / "docs").glob("*.md")))
"""The pages whose ``quadcruise`` names are public API."""


def _dotted(obj, name: str) -> str | None:
    """``module.qualname`` of a function or class defined in the package, else None."""
    home = _home(obj)
    if home and home.startswith("quadcruise") and (inspect.isclass(obj) or callable(obj)):
        return f"{home}.{getattr(obj, '__qualname__', name)}"
    return None


def package_exports() -> set[str]:
    """The names ``quadcruise`` and its subpackages export in their ``__init__``'s ``__all__``."""
    out = set()
    for module in modules():
        mod = importlib.import_module(module)
        if hasattr(mod, "__path__"):  # a package, not a module
            out.update(filter(None, (_dotted(getattr(mod, n, None), n) for n in getattr(mod, "__all__", ()))))
    return out


def shown_in_docs(pages=DOCS) -> set[str]:
    """The functions and classes the pages name: ``from quadcruise.x import y`` or ``quadcruise.x.y``."""
    found = set()
    for page in pages:
        text = Path(page).read_text()
        for module, names in re.findall(r"from (quadcruise[\w.]*) import ([\w, ]+)", text):
            found.update(f"{module}.{n.strip()}" for n in names.split(",") if n.strip())
        found.update(re.findall(r"\bquadcruise(?:\.\w+)+", text))
    out = set()
    for name in found:
        try:
            obj = _resolve(name)
        except AttributeError:
            continue  # a word after a module's name (``quadcruise.cli.main``'s ``.py``)
        if not inspect.ismodule(obj):
            out.update(filter(None, [_dotted(obj, name.rsplit(".", 1)[1])]))
    return out


def returned_classes(name: str) -> set[str]:
    """The package's classes that a function's return annotation names, looked up in its module."""
    func = getattr(_resolve(name), "py_func", _resolve(name))
    if inspect.isclass(func) or not callable(func):
        return set()
    annotation = inspect.signature(func).return_annotation
    if annotation is inspect.Signature.empty:
        return set()
    scope = vars(importlib.import_module(func.__module__))
    words = re.findall(r"[A-Za-z_]\w*", annotation if isinstance(annotation, str) else repr(annotation))
    return {d for w in words if inspect.isclass(scope.get(w)) and (d := _dotted(scope[w], w))}


def _callables(name: str) -> list[str]:
    """A function's name, or a class's public methods."""
    obj = _resolve(name)
    if not inspect.isclass(obj):
        return [name]
    return [method for method in public_names(_home(obj)) if method.startswith(f"{name}.")]


@cache
def exported() -> frozenset[str]:
    """The public API: package exports, names the docs show, and the classes these return."""
    public = package_exports() | shown_in_docs()
    new = set(public)
    while new:  # what their functions and methods return, until nothing new
        calls = [call for name in new for call in _callables(name)]
        new = set().union(*map(returned_classes, calls)) - public
        public |= new
    return frozenset(public)


def problems(name: str, required: bool) -> list[str]:
    """What numpydoc finds wrong with one name's docstring, by our rules."""
    result = validate(name)
    if result["docstring"].strip() == "":
        return ["GL08 no docstring"]
    has_sections = any(NumpyDocString(result["docstring"])[s] for s in ("Parameters", "Returns", "Yields"))
    if not (required or has_sections):
        return []
    obj = result["file"] and _resolve(name)
    if inspect.isclass(obj) and _home(_own_init(obj)) != _home(obj):
        return []  # an Enum's or a Protocol's constructor is not ours
    found = [f"{code} {message}" for code, message in result["errors"] if code in CHECKED]
    return [p for p in found if not (p.startswith("PR02") and message_names(p) <= {"self", "cls"})]


def message_names(message: str) -> set[str]:
    """The parameter names a PR01/PR02 message lists."""
    inside = message[message.find("{") + 1 : message.find("}")]
    return {part.strip().strip("'\"") for part in inside.split(",")}


def _resolve(name: str):
    module, _, rest = name.partition(".")
    obj = importlib.import_module(module)
    parts = name.split(".")
    for i in range(len(parts), 0, -1):
        try:
            obj = importlib.import_module(".".join(parts[:i]))
        except ImportError:
            continue
        for attr in parts[i:]:
            obj = getattr(obj, attr)
        return obj
    return None


def _own_init(cls):
    for klass in cls.__mro__:
        if "__init__" in vars(klass):
            return vars(klass)["__init__"]
    return None


def all_problems() -> dict[str, list[str]]:
    """Every public name with problems: name -> its problems."""
    required = exported()
    out = {}
    for module in modules():
        for name in public_names(module):
            owner = name.rsplit(".", 1)[0]
            found = problems(name, name in required or owner in required)
            if found:
                out[name] = found
    return out


SAMPLE = '''
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
    """


def stale(a, b):
    """Old.

    Parameters
    ----------
    a, old : float
        Gone.
    """


def no_returns(x):
    """Twice.

    Parameters
    ----------
    x : float
        A number.
    """
    return 2 * x


def one_line(x):
    """Twice x."""
    return 2 * x


def bare(x):
    return x
'''


def test_the_validator_reads_numpydoc(tmp_path, monkeypatch):
    (tmp_path / "qc_docstring_sample.py").write_text(SAMPLE)
    monkeypatch.syspath_prepend(str(tmp_path))
    found = {
        name: [p[:4] for p in problems(f"qc_docstring_sample.{name}", required)]
        for name, required in (
            ("good", True),
            ("stale", False),
            ("no_returns", False),
            ("one_line", False),
            ("one_line", True),
            ("bare", False),
        )
    }
    assert found == {
        "good": [],
        "stale": ["PR01", "PR02"],
        "no_returns": ["RT01"],
        "one_line": ["PR01", "RT01"],
        "bare": ["GL08"],
    }
    assert problems("qc_docstring_sample.one_line", False) == []  # a helper may be one line


def test_public_api_is_what_users_call(tmp_path):
    public = exported()
    assert "quadcruise.workflows.fly.fly" in public  # qc.fly: the package's __all__
    assert "quadcruise.control.position.NLPD" in public  # quadcruise.control's __all__
    assert "quadcruise.control.design.pd_from_poles" in public  # the README imports it
    assert "quadcruise.workflows.linearization.Linearization" in public  # what linearize (docs/paper.md) returns
    assert "quadcruise.checks.number" not in public  # a helper, in its own module's __all__ only
    assert "quadcruise.control.design.pid_from_poles" not in public
    page = tmp_path / "page.md"
    page.write_text(
        "```python\nfrom quadcruise.control.design import pid_from_poles, PDGains\n```\n"
        "`quadcruise.checks.number(...)`, the module `quadcruise.io.files`, `quadcruise.cli.main.py`\n"
    )
    assert shown_in_docs([page]) == {
        "quadcruise.control.design.pid_from_poles",
        "quadcruise.control.design.PDGains",
        "quadcruise.checks.number",
    }
    assert returned_classes("quadcruise.workflows.analysis.linearize") == {
        "quadcruise.workflows.linearization.Linearization"
    }


def test_the_validator_holds_our_rules():
    assert problems("quadcruise.workflows.fly.fly", True) == []
    assert problems("quadcruise.numeric.wrap_angle", True) == []


@pytest.mark.parametrize("module", modules())
def test_public_names_documented(module):
    required = exported()
    bad = {}
    for name in public_names(module):
        owner = name.rsplit(".", 1)[0]
        found = problems(name, name in required or owner in required)
        if found:
            bad[name] = found
    assert not bad, "\n".join(f"{name}: {'; '.join(found)}" for name, found in bad.items())


if __name__ == "__main__":
    found = all_problems()
    for name, items in found.items():
        print(f"{name}: {'; '.join(items)}")
    print(f"{len(found)} names with problems", file=sys.stderr)
