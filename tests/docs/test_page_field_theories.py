"""Every code example of docs/field_theories.md runs, and prints what the page shows.

A module of its own (see pages.py): its examples take long, and pytest-xdist's
``--dist loadfile`` runs them on a worker of their own, beside the other pages.
"""

from __future__ import annotations

from pathlib import Path

import pytest
from pages import check_page, label, page

PAGE = page("docs/field_theories.md")


@pytest.mark.parametrize("page", [PAGE], ids=label)
def test_page_examples_run_as_shown(page: Path, tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    check_page(page, tmp_path, monkeypatch)
