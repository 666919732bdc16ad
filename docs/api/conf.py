"""Sphinx configuration of the API reference, generated from the numpydoc docstrings.

Build it (warnings are errors, as .ci/run builds it):

    pip install -e '.[docs]'
    sphinx-build -W --keep-going -b html docs/api docs/api/_build/html
"""

import re

from quadcruise import __version__

project = "quadcruise"
author = "quadcruise"
copyright = "quadcruise authors, MIT licence"
release = version = __version__

extensions = ["sphinx.ext.autodoc", "sphinx.ext.viewcode", "numpydoc"]
exclude_patterns = ["_build"]
html_theme = "alabaster"
html_static_path: list[str] = []

autodoc_default_options = {"members": True, "member-order": "bysource"}
autodoc_typehints = "none"  # the numpydoc sections say the types, with their units
numpydoc_show_class_members = False  # no autosummary table of every method: the class's own entries follow
numpydoc_validation_checks: set[str] = set()  # tests/unit/test_docstrings.py checks the docstrings
suppress_warnings = ["autodoc.import_object"]

# A docstring writes a norm or an absolute value as |x| (plain text for help() and the
# terminal); reStructuredText would read it as a substitution. Escaped here, outside literals
# and examples, so that the docstrings stay as a reader of the source sees them.
_BARS = re.compile(r"(?<![\\|])\|(?=[^\s|])([^|\n]*?[^\s|\\])\|(?!\|)")


def _escape_bars(app, what, name, obj, options, lines):
    example = False
    for i, line in enumerate(lines):
        stripped = line.strip()
        example = stripped.startswith(">>>") or (example and stripped != "")
        if example or "|" not in line:
            continue
        parts = line.split("``")
        parts[::2] = [_BARS.sub(r"\\|\1\\|", part) for part in parts[::2]]
        lines[i] = "``".join(parts)


def setup(app):
    app.connect("autodoc-process-docstring", _escape_bars, priority=400)
