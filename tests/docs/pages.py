"""The pages whose examples run (README.md and docs/*.md) and the test module that runs each.

The examples of a page run in page order in one test (:func:`check_page`). With
pytest-xdist's ``--dist loadfile`` (pyproject.toml) the tests of one module run on one
worker, one after another, so a module holding every page would run all of them on one
worker while the others sit idle. A page whose examples take long (its commands compile
member loops and kernels of their own) therefore runs in a module of its own,
``test_page_<name>.py`` (:data:`OWN_MODULES`), and ``test_docs_examples.py`` runs the
others: the long pages run side by side on different workers.
``test_docs_examples.py`` checks that every page runs in exactly one module.
"""

from __future__ import annotations

from pathlib import Path

import pytest
from doc_blocks import run_page

ROOT = Path(__file__).resolve().parents[2]
PAGES = [ROOT / "README.md", *sorted((ROOT / "docs").glob("*.md"))]

#: The pages that run in a module of their own (page label -> module name in tests/docs).
OWN_MODULES = {
    "docs/ensembles_general.md": "test_page_ensembles_general",
    "docs/field_theories.md": "test_page_field_theories",
}


def label(path: Path) -> str:
    """The page's path relative to the repository (its test id)."""
    return str(path.relative_to(ROOT))


def page(name: str) -> Path:
    """The page of label ``name`` (``"docs/ensembles_general.md"``)."""
    return ROOT / name


def check_page(page: Path, tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    """Run every example of ``page`` and assert it behaves as the page shows.

    The page runs in a fresh temporary directory in which ``docs/`` points at the
    repository's docs, as for a reader who works in a clone of the repository.
    """
    (tmp_path / "docs").symlink_to(ROOT / "docs", target_is_directory=True)
    monkeypatch.chdir(tmp_path)
    problems, _ = run_page(page, label(page))
    assert not problems, "\n\n".join(problems)
