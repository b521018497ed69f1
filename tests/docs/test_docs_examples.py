"""Every code example of README.md and docs/*.md runs, and prints what the page shows.

The conventions (expected output, ``<!-- file: … -->``, ``<!-- status: … -->``,
``<!-- raises: … -->``) are described in ``doc_blocks.py``. Each page runs in a fresh
temporary directory in which ``docs/`` points at the repository's docs, as for a reader
who works in a clone of the repository. The pages whose examples take long run in modules
of their own (``pages.OWN_MODULES``), so that pytest-xdist runs them on other workers;
this module runs the others.
"""

from __future__ import annotations

import importlib
import inspect
from pathlib import Path

import pytest
from doc_blocks import parse_blocks
from pages import OWN_MODULES, PAGES, ROOT, check_page, label


@pytest.mark.parametrize("page", [p for p in PAGES if label(p) not in OWN_MODULES], ids=label)
def test_page_examples_run_as_shown(page: Path, tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    check_page(page, tmp_path, monkeypatch)


def test_every_page_runs_in_exactly_one_module() -> None:
    """A page listed in OWN_MODULES runs in that module's test (and not here); a page renamed
    or removed from the list would otherwise run nowhere, or twice."""
    labels = {label(p) for p in PAGES}
    assert set(OWN_MODULES) <= labels, set(OWN_MODULES) - labels
    here = Path(__file__).parent
    for name, module_name in OWN_MODULES.items():
        assert (here / f"{module_name}.py").is_file(), module_name
        module = importlib.import_module(module_name)
        assert label(module.PAGE) == name, (module_name, label(module.PAGE))
        test = module.test_page_examples_run_as_shown
        assert "check_page(page" in inspect.getsource(test), module_name
        marks = [m for m in getattr(test, "pytestmark", []) if m.name == "parametrize"]
        assert [label(p) for m in marks for p in m.args[1]] == [name], module_name


def test_readme_has_the_contract_commands_and_a_runnable_example() -> None:
    text = (ROOT / "README.md").read_text(encoding="utf-8")
    # the two set-up commands of the quick start, verbatim (install + demo, install + tests)
    assert "pip install . && dirac demo" in text
    assert "pip install '.[test]' && pytest" in text
    python_blocks = [b for b in parse_blocks(ROOT / "README.md") if b.language == "python"]
    assert python_blocks, "README.md must show a Python example"
    assert len(python_blocks[0].text.strip().splitlines()) <= 12, "the README example should stay about 10 lines"


def _table_rows(text: str, heading: str) -> list[str]:
    """The table rows of the README section under ``## heading``."""
    section = text.split(f"## {heading}", 1)[1].split("\n## ", 1)[0]
    return [line for line in section.splitlines() if line.startswith("| `")]


def test_readme_systems_table_lists_exactly_the_built_in_systems() -> None:
    import re

    import dirac

    rows = _table_rows((ROOT / "README.md").read_text(encoding="utf-8"), "Built-in systems")
    listed = {re.match(r"\| `([^`]+)`", row).group(1) for row in rows}
    assert listed == set(dirac.builtin_systems())


def test_readme_integrators_table_names_only_real_methods() -> None:
    import re

    from dirac.flows import method_names

    rows = _table_rows((ROOT / "README.md").read_text(encoding="utf-8"), "Integrators")
    names = {token for row in rows for token in re.findall(r"`([a-z][a-z0-9-]*)`", row)}
    assert names, "the integrators table is empty"
    assert names <= set(method_names()), names - set(method_names())


def test_readme_links_point_at_files_that_exist() -> None:
    import re

    text = (ROOT / "README.md").read_text(encoding="utf-8")
    targets = [t.split("#")[0] for t in re.findall(r"\]\(([^)\s]+)\)", text) if "://" not in t]
    assert targets
    missing = [t for t in targets if not (ROOT / t).exists()]
    assert not missing, f"README.md links to missing files: {missing}"


def test_readme_names_the_paper_in_its_introduction() -> None:
    intro = (ROOT / "README.md").read_text(encoding="utf-8").split("## ")[0]
    assert "A. A. Deriglazov" in intro
    assert "Lagrangian and\nHamiltonian formulations of asymmetric rigid body, considered as a constrained system" in intro
    assert "(2024)" in intro


def test_every_option_of_analyze_is_in_the_cli_page(run_cli) -> None:
    import re

    status, help_text, _ = run_cli("analyze", "--help")
    assert status == 0
    # the help of --compare gives its syntax, not a vague "e.g. the paper's equations"
    assert "dirac,chetaev" in help_text and "paper's equations" not in help_text
    page = (ROOT / "docs" / "cli.md").read_text(encoding="utf-8")
    options = set(re.findall(r"(--[a-z][a-z-]+)", help_text)) - {"--help"}
    assert "--compare" in options
    for option in options:
        assert f"`{option}" in page, option
    assert "dirac analyze rigid_body_momentum --compare dirac,chetaev" in page


def test_no_page_writes_into_the_repository() -> None:
    import re

    for page in PAGES:
        text = page.read_text(encoding="utf-8")
        for line in text.splitlines():
            if line.startswith(("$ ", "dirac ", "python ")):  # commands a reader types
                assert not re.search(r"(--out|--json|--plot)\s+docs/", line), (page.name, line)
