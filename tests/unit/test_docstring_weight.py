"""`benchmarks/docstring_weight.py` counts docstring lines and code lines as its docstring says."""

import importlib.util
import subprocess
import sys
from pathlib import Path

SCRIPT = Path(__file__).resolve().parents[2] / "benchmarks" / "docstring_weight.py"
_spec = importlib.util.spec_from_file_location("docstring_weight", SCRIPT)
weight = importlib.util.module_from_spec(_spec)
_spec.loader.exec_module(weight)

SOURCE = '''"""A module.

Two more lines.
"""

# a comment: neither

X = 1
"""X's docstring."""


def f(a):
    """One line."""
    text = """not a docstring:
    an assigned string is code"""
    return a, text  # code with a comment
'''


def test_counts_string_statements_as_docstrings_and_the_rest_as_code():
    # docstrings: the module's 4 lines, X's 1, f's 1; code: X = 1, def, the 2-line assignment, return
    assert weight.count(SOURCE) == (6, 5)


def test_a_file_without_docstrings_or_code():
    assert weight.count("# only a comment\n\n") == (0, 0)
    assert weight.count("x = 1\n") == (0, 1)


def test_prints_the_total_of_the_files_given(tmp_path):
    (tmp_path / "a.py").write_text(SOURCE)
    (tmp_path / "b.py").write_text("y = 2\n")
    out = subprocess.run(
        [sys.executable, str(SCRIPT), "--only", str(tmp_path / "a.py"), str(tmp_path / "b.py")],
        capture_output=True,
        text=True,
        check=True,
    ).stdout.splitlines()
    assert out[-1].split()[:3] == ["6", "6", "1.00"] and "(2 files)" in out[-1]
