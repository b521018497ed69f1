"""Sphinx configuration of the dirac documentation (Markdown pages through MyST).

Build (warnings are errors, as in the test suite, tests/docs/test_docs_build.py)::

    sphinx-build -W --keep-going -b html docs docs/_build/html
"""

from __future__ import annotations

import sys
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent
# the source tree first, so that autodoc documents this checkout even when not installed
sys.path.insert(0, str(ROOT))

project = "dirac"
author = "The dirac developers"
copyright = "2026, The dirac developers"  # Sphinx's name for the notice, shadowing a builtin
try:
    from importlib.metadata import PackageNotFoundError
    from importlib.metadata import version as _installed_version  # `version` is a Sphinx setting

    release = _installed_version("dirac-mechanics")
except PackageNotFoundError:  # not installed: the docs still build
    release = "0.1.0"

extensions = [
    "myst_parser",
    "sphinx.ext.autodoc",
    "sphinx.ext.napoleon",
    "sphinx.ext.mathjax",
]

source_suffix = {".md": "markdown"}
root_doc = "index"
exclude_patterns = ["_build", "scenes", "images", "Thumbs.db", ".DS_Store"]

# MyST: $...$ and $$...$$ maths, ::: fences, anchors for links to sections
myst_enable_extensions = ["dollarmath", "amsmath", "colon_fence", "deflist"]
myst_heading_anchors = 3

# autodoc: numpy-style docstrings; the heavy modules are importable (no mocking), so the
# API page documents what is really there
autodoc_default_options = {"members": True, "show-inheritance": True}
autodoc_member_order = "bysource"
autodoc_typehints = "description"
napoleon_google_docstring = False
napoleon_numpy_docstring = True
napoleon_use_rtype = False

html_theme = "alabaster"
html_title = "dirac: constrained Hamiltonian mechanics"
html_theme_options = {
    "description": "Dirac brackets and structure-preserving flows; flagship: the free rigid body",
    "fixed_sidebar": True,
}


def _markdown_fences_to_rst(app, what, name, obj, options, lines):
    """Let docstrings use Markdown code fences: turn them into ``code-block`` directives."""
    import re

    out: list[str] = []
    i = 0
    while i < len(lines):
        opening = re.match(r"^(\s*)```+\s*([\w+-]*)\s*$", lines[i])
        if not opening:
            out.append(lines[i])
            i += 1
            continue
        indent, language = opening.group(1), opening.group(2) or "text"
        body = []
        i += 1
        while i < len(lines) and not re.match(r"^\s*```+\s*$", lines[i]):
            body.append(lines[i][len(indent):] if lines[i].startswith(indent) else lines[i].lstrip())
            i += 1
        i += 1  # the closing fence
        out += [f"{indent}.. code-block:: {language}", ""] + [f"{indent}   {line}" if line else "" for line in body] + [""]
    lines[:] = out


def setup(app):
    app.connect("autodoc-process-docstring", _markdown_fences_to_rst)
