"""Docstring lines per line of code, per module and in all (issue 26, item 4).

Docstring lines: the lines spanned by a string statement (a module's, class's or function's
docstring, or an attribute's under its assignment). Code lines: the other lines that hold
anything but a comment. The same count runs on any tree of Python files, so the package can be
set beside another (RotorPy, python-control)::

    python benchmarks/docstring_weight.py                 # src/quadcruise, worst modules first
    python benchmarks/docstring_weight.py PATH [--top N]  # any folder or file
    python benchmarks/docstring_weight.py --only FILE...  # just these files, and their total
"""

from __future__ import annotations

import argparse
import ast
import io
import tokenize
from pathlib import Path


def count(source: str) -> tuple[int, int]:
    """(docstring lines, code lines) of one module's source."""
    tree = ast.parse(source)
    doc: set[int] = set()
    for node in ast.walk(tree):
        if isinstance(node, ast.Expr) and isinstance(node.value, ast.Constant) and isinstance(node.value.value, str):
            doc.update(range(node.lineno, node.end_lineno + 1))
    code: set[int] = set()
    skip = {tokenize.COMMENT, tokenize.NL, tokenize.NEWLINE, tokenize.INDENT, tokenize.DEDENT, tokenize.ENCODING}
    for tok in tokenize.generate_tokens(io.StringIO(source).readline):
        if tok.type not in skip and tok.type != tokenize.ENDMARKER:
            code.update(range(tok.start[0], tok.end[0] + 1))
    return len(doc), len(code - doc)


def main() -> None:
    """Print the table."""
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("paths", nargs="*", default=[str(Path(__file__).parents[1] / "src" / "quadcruise")])
    parser.add_argument("--top", type=int, default=25, help="modules listed, heaviest docstrings first")
    parser.add_argument("--only", action="store_true", help="list every file given, in the order given")
    args = parser.parse_args()
    files = []
    for p in map(Path, args.paths):
        files += sorted(p.rglob("*.py")) if p.is_dir() else [p]
    rows = [(str(f), *count(f.read_text())) for f in files]
    doc, code = sum(r[1] for r in rows), sum(r[2] for r in rows)
    shown = rows if args.only else sorted(rows, key=lambda r: r[1] - r[2], reverse=True)[: args.top]
    for name, d, c in shown:
        print(f"{d:6d} {c:6d} {d / max(c, 1):6.2f}  {name}")
    ratio = doc / max(code, 1)
    print(f"{doc:6d} {code:6d} {ratio:6.2f}  total: docstring lines, code lines, their ratio ({len(rows)} files)")


if __name__ == "__main__":
    main()
