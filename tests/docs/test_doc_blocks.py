"""The documentation-example runner itself: it must report every kind of failure."""

from __future__ import annotations

from pathlib import Path

import pytest
from doc_blocks import console_commands, parse_blocks, run_page

PAGE = '''# Page

<!-- file: data.txt -->
```text
hello
```

```python
x = 2 + 3
print(x)
```

```text
5
```

<!-- raises: ZeroDivisionError -->
```python
1 / 0
```

```console
$ pip install something-not-run
$ dirac --version
dirac ...
```
'''


def _write(tmp_path: Path, text: str) -> Path:
    page = tmp_path / "page.md"
    page.write_text(text, encoding="utf-8")
    return page


@pytest.fixture
def run_text(tmp_path: Path, monkeypatch):
    """Run a page text as ``page.md`` in ``tmp_path``, which is made the working directory."""
    monkeypatch.chdir(tmp_path)

    def run(text: str) -> tuple[list[str], int]:
        return run_page(_write(tmp_path, text), "page.md")

    return run


def test_a_correct_page_runs_every_block(tmp_path: Path, run_text) -> None:
    problems, executed = run_text(PAGE)
    assert problems == []
    assert executed == 4  # the file, two python blocks, one dirac command
    assert (tmp_path / "data.txt").read_text() == "hello\n"


def test_parse_attaches_output_and_markers(tmp_path: Path) -> None:
    blocks = parse_blocks(_write(tmp_path, PAGE))
    assert [b.language for b in blocks] == ["text", "python", "python", "console"]
    assert blocks[0].options == {"file": "data.txt"}
    assert blocks[1].expected == "5\n"
    assert blocks[2].options == {"raises": "ZeroDivisionError"}
    commands = console_commands(blocks[3])
    assert [c.argv for c in commands] == [["--version"]]
    assert commands[0].expected == "dirac ...\n"


def test_wrong_output_is_reported(run_text) -> None:
    problems, _ = run_text(PAGE.replace("\n5\n", "\n6\n"))
    assert len(problems) == 1 and "printed output differs" in problems[0]


def test_an_error_is_reported(run_text) -> None:
    problems, _ = run_text(PAGE.replace("x = 2 + 3", "x = undefined_name"))
    assert len(problems) == 1 and "NameError" in problems[0]


def test_a_raises_block_that_does_not_raise_is_reported(run_text) -> None:
    problems, _ = run_text(PAGE.replace("1 / 0", "1 / 1"))
    assert len(problems) == 1 and "ran without an error" in problems[0]


def test_a_failing_command_is_reported(run_text) -> None:
    problems, _ = run_text(PAGE.replace("$ dirac --version", "$ dirac no-such-command"))
    assert len(problems) == 1 and "exit status 2" in problems[0]


def test_expected_status_and_error_line_are_checked(run_text) -> None:
    page = "<!-- status: 2 -->\n```console\n$ dirac systems --no-such-option\nerror: ...--no-such-option...\n```\n"
    problems, executed = run_text(page)
    assert executed == 1 and problems == []
    problems, _ = run_text(page.replace("status: 2", "status: 0"))
    assert len(problems) == 1 and "exit status 2" in problems[0]


def test_a_placeholder_output_is_reported(run_text) -> None:
    problems, _ = run_text(PAGE.replace("\n5\n", "\n...\n"))
    assert len(problems) == 1 and "only '...'" in problems[0]
    problems, _ = run_text(PAGE.replace("dirac ...\n", "...\n"))
    assert len(problems) == 1 and "only '...'" in problems[0]


def test_round_off_figures_match_each_other_but_larger_numbers_must_agree() -> None:
    from doc_blocks import matches

    assert matches("error 4.441e-16, E = 0.647", "error 6.661e-16, E = 0.647")
    assert matches("drift 1.2e-14", "drift 3e-15")
    assert not matches("drift 1.2e-13", "drift 3.0e-13")  # 1e-13 and up must agree
    assert not matches("error 4.4e-16, E = 0.647", "error 4.4e-16, E = 0.648")
    assert not matches("error 4.4e-16", "error 4.4e-06")
