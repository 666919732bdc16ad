"""Every file the docs cite exists: a path in backticks (``sim/engine.py``,
``tests/support/compiled_code.py``, ``benchmarks/ab.py``), a bare module name of the package
(``chunk.py``), and every relative link. A file moved without its docs fails here."""

import re
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[2]
PACKAGE = ROOT / "src" / "quadcruise"
PAGES = sorted((ROOT / "docs").glob("*.md")) + [ROOT / "README.md", ROOT / "benchmarks" / "README.md"]
TOP = {"src", "tests", "benchmarks", "docs", "examples", ".ci", "quadcruise"} | {
    p.name for p in PACKAGE.iterdir() if p.is_dir()
}
CITED = re.compile(r"`([A-Za-z0-9_.][A-Za-z0-9_./-]*\.(?:py|md|js|toml|csv|npz))(?::[^`]*)?`")
LINK = re.compile(r"\]\(([^)#\s]+)(?:#[^)]*)?\)")
OURS = {
    p.name for where in ("src", "tests", "benchmarks", "examples") for p in (ROOT / where).rglob("*") if p.is_file()
}


def citations():
    for page in PAGES:
        text = page.read_text()
        for m in CITED.finditer(text):
            yield page, m.group(1), "path"
        for m in LINK.finditer(text):
            if not m.group(1).startswith(("http://", "https://", "mailto:")):
                yield page, m.group(1), "link"


def found(page: Path, cited: str, how: str) -> bool:
    if how == "link":
        return (page.parent / cited).exists()
    if "/" in cited:
        if cited.split("/")[0] not in TOP:  # another project's path (rotorpy/...) or an output's (ident/...)
            return True
        return any(c.exists() for c in (ROOT / cited, PACKAGE / cited, ROOT / "src" / cited, page.parent / cited))
    if cited.endswith((".py", ".js")):  # a bare module name: one of ours somewhere
        return cited in OURS
    return True  # a bare data or output file name (scenario.toml, report.md) names what a command writes


@pytest.mark.parametrize("page", PAGES, ids=lambda p: p.name)
def test_cited_files_exist(page):
    missing = sorted({f"{cited} ({how})" for p, cited, how in citations() if p == page and not found(p, cited, how)})
    assert not missing, f"{page.relative_to(ROOT)} cites files that do not exist: {', '.join(missing)}"


def test_the_check_finds_a_moved_file(tmp_path):
    page = tmp_path / "page.md"
    assert not found(page, "tests/test_layers.py", "path")  # not where it is
    assert found(page, "tests/unit/test_layers.py", "path")
    assert not found(page, "control/no_such_module.py", "path") and found(page, "control/registry.py", "path")
    assert not found(page, "no_such_module.py", "path") and found(page, "chunk.py", "path")
    assert not found(ROOT / "docs" / "x.md", "nowhere.md", "link") and found(ROOT / "docs" / "x.md", "gym.md", "link")


DOTTED = re.compile(r"`(quadcruise(?:\.[A-Za-z_][A-Za-z0-9_]*)+)")
NOT_NAMES = {"quadcruise.json", "quadcruise.x.y", "quadcruise.controllers"}  # a file, a pattern, an entry-point group


def resolves(dotted: str) -> bool:
    """Whether ``quadcruise.a.b.c`` names a module or an attribute of one."""
    import importlib

    parts = dotted.split(".")
    for k in range(len(parts), 0, -1):
        try:
            obj = importlib.import_module(".".join(parts[:k]))
        except ImportError:
            continue
        for attr in parts[k:]:
            if not hasattr(obj, attr):
                return False
            obj = getattr(obj, attr)
        return True
    return False


@pytest.mark.parametrize("page", PAGES, ids=lambda p: p.name)
def test_cited_names_exist(page):
    pytest.importorskip("gymnasium")  # docs/gym.md names quadcruise.gym's
    names = {m.group(1) for m in DOTTED.finditer(page.read_text())} - NOT_NAMES
    missing = sorted(n for n in names if not resolves(n))
    assert not missing, f"{page.relative_to(ROOT)} names what does not exist: {', '.join(missing)}"
    assert not resolves("quadcruise.control.no_such_name") and resolves("quadcruise.control.registry.declared")
