"""Read the code blocks of a Markdown page and run them (used by test_docs_examples.py).

Conventions of the pages (README.md and docs/*.md), all visible in the source:

* ```` ```python ```` blocks run in page order in one namespace; a ```` ```text ````
  block right after one is its expected output (doctest matching: ``...`` stands for
  anything, whitespace is normalised, and numbers below ``1e-13`` written as
  ``d.ddde-NN`` match any such number: round-off differs between machines).
* ```` ```console ```` / ```` ```bash ```` blocks: every line ``$ dirac …`` (or
  ``$ python -m dirac …``) runs through the command line; the lines after it, up to the
  next ``$``, are its expected output (``error:`` / ``warning:`` lines are matched
  against stderr, the rest against stdout). Other ``$`` lines (pip, pytest) are not run.
* An HTML comment on the line(s) before a block sets options:
  ``<!-- file: NAME -->`` writes the block to the file ``NAME`` before it is used,
  ``<!-- status: 2 -->`` is the exit status the commands of a console block must return,
  ``<!-- raises: InputError -->`` is a Python block illustrating an error: it must raise
  that exception, ``<!-- warns: why -->`` a Python block meant to warn (a block that
  warns without it fails, and so does a command whose page shows no ``warning:`` line
  but which prints one). Nothing is ever skipped silently.
"""

from __future__ import annotations

import contextlib
import doctest
import io
import re
import shlex
import traceback
import warnings
from dataclasses import dataclass, field
from pathlib import Path

from dirac.errors import DiracWarning

FENCE = re.compile(r"^(?P<fence>`{3,}|~{3,})\s*(?P<info>[^\s`]*)(?P<rest>.*)$")
MARKER = re.compile(r"^<!--\s*(?P<key>[a-z-]+)\s*:\s*(?P<value>.*?)\s*-->\s*$")
RUNNABLE_CONSOLE = ("console", "bash", "shell", "sh")
CHECKER = doctest.OutputChecker()
FLAGS = doctest.ELLIPSIS | doctest.NORMALIZE_WHITESPACE


@dataclass
class Block:
    """One fenced code block of a page."""

    language: str
    text: str
    line: int
    options: dict[str, str] = field(default_factory=dict)
    expected: str | None = None  # for python blocks: the text block that follows


def parse_blocks(path: Path) -> list[Block]:
    """The fenced blocks of a Markdown file, in order, with their marker options."""
    lines = path.read_text(encoding="utf-8").splitlines()
    blocks: list[Block] = []
    pending: dict[str, str] = {}
    i = 0
    while i < len(lines):
        line = lines[i]
        marker = MARKER.match(line.strip())
        if marker:
            pending[marker.group("key")] = marker.group("value")
            i += 1
            continue
        match = FENCE.match(line.strip()) if not line.startswith("    ") else None
        if match:
            fence = match.group("fence")
            start = i + 1
            j = start
            while j < len(lines) and not (
                lines[j].strip().startswith(fence[0] * len(fence)) and set(lines[j].strip()) <= {fence[0]}
            ):
                j += 1
            blocks.append(Block(match.group("info").lower(), "\n".join(lines[start:j]) + "\n", start, pending))
            pending = {}
            i = j + 1
            continue
        if line.strip():
            pending = {}
        i += 1
    # a text block right after a python block is its expected output
    merged: list[Block] = []
    for block in blocks:
        if block.language in ("text", "output") and merged and merged[-1].language == "python" \
                and merged[-1].expected is None and not block.options:
            merged[-1].expected = block.text
            continue
        merged.append(block)
    return merged


ROUND_OFF = re.compile(r"(?<![\w.])[-+]?\d+(?:\.\d+)?e-(\d+)\b")


def _round_off_as_word(text: str) -> str:
    """Numbers below 1e-13 written as ``d.ddde-NN`` become the word ``<round-off>``.

    Round-off-level figures (an error of 4.4e-16 here is 6.7e-16 on another machine)
    differ between machines and library versions; every larger number must match.
    """
    return ROUND_OFF.sub(lambda m: "<round-off>" if int(m.group(1)) >= 14 else m.group(0), text)


def matches(expected: str, got: str) -> bool:
    """doctest comparison with ELLIPSIS and NORMALIZE_WHITESPACE, round-off figures alike."""
    return CHECKER.check_output(
        _round_off_as_word(expected.strip()) + "\n", _round_off_as_word(got.strip()) + "\n", FLAGS
    )


def is_placeholder(expected: str) -> bool:
    """An expected output that is only ``...`` would match anything: not allowed."""
    return expected.strip().replace(".", "").strip() == "" and expected.strip() != ""


@dataclass
class Command:
    """One ``$ dirac …`` line of a console block with the output printed under it."""

    argv: list[str]
    expected: str
    line: int


def console_commands(block: Block) -> list[Command]:
    """The runnable commands of a console block (``$ dirac …``, ``$ python -m dirac …``)."""
    commands: list[Command] = []
    current: Command | None = None
    for offset, raw in enumerate(block.text.splitlines()):
        if raw.startswith("$ "):
            words = shlex.split(raw[2:], comments=True)
            if words[:1] == ["dirac"]:
                current = Command(words[1:], "", block.line + offset + 1)
                commands.append(current)
            elif words[:3] == ["python", "-m", "dirac"]:
                current = Command(words[3:], "", block.line + offset + 1)
                commands.append(current)
            else:
                current = None
            continue
        if current is not None:
            current.expected += raw + "\n"
    return commands


def run_cli(argv: list[str]) -> tuple[int, str, str]:
    """Run the command line in-process; return (status, stdout, stderr)."""
    from dirac.cli import main

    out, err = io.StringIO(), io.StringIO()
    with contextlib.redirect_stdout(out), contextlib.redirect_stderr(err):
        try:
            status = main(argv)
        except SystemExit as exc:
            status = int(exc.code or 0)
    return status, out.getvalue(), err.getvalue()


def check_command(page: str, command: Command, status_expected: int) -> list[str]:
    """Run one command; return the list of problems (empty when it behaves as the page says)."""
    where = f"{page}:{command.line}: $ dirac {shlex.join(command.argv)}"
    status, out, err = run_cli(command.argv)
    problems = []
    if status != status_expected:
        problems.append(f"{where}\n  exit status {status}, the page expects {status_expected}\n  stderr: {err.strip()[-2000:]}")
        return problems
    expected_err = "".join(
        line + "\n" for line in command.expected.splitlines() if line.startswith(("error:", "warning:"))
    )
    expected_out = "".join(
        line + "\n" for line in command.expected.splitlines() if not line.startswith(("error:", "warning:"))
    )
    if is_placeholder(expected_out) or is_placeholder(expected_err):
        problems.append(f"{where}\n  the page shows only '...' as its output: show the real output")
    elif expected_out.strip() and not matches(expected_out, out):
        problems.append(f"{where}\n  stdout differs from the page.\n--- page:\n{expected_out}--- real:\n{out}")
    real_err = "".join(line + "\n" for line in err.splitlines() if line.startswith(("error:", "warning:")))
    if not expected_err.strip() and real_err:
        problems.append(f"{where}\n  prints a warning or error the page does not show:\n{real_err}")
    elif expected_err.strip():
        if not matches(expected_err, real_err):
            problems.append(f"{where}\n  stderr differs from the page.\n--- page:\n{expected_err}--- real:\n{real_err}")
    return problems


def run_python(page: str, block: Block, namespace: dict) -> list[str]:
    """Execute one python block in ``namespace``; return the problems found."""
    where = f"{page}:{block.line}: python block"
    code = compile(block.text, f"{page}:{block.line}", "exec")
    out = io.StringIO()
    wanted = block.options.get("raises")
    try:
        with contextlib.redirect_stdout(out), warnings.catch_warnings(record=True) as caught:
            warnings.simplefilter("always", DiracWarning)
            exec(code, namespace)
    except Exception as exc:
        names = {cls.__name__ for cls in type(exc).__mro__} | {
            f"{cls.__module__}.{cls.__name__}" for cls in type(exc).__mro__
        }
        if wanted and wanted in names:
            return []
        return [f"{where} raised {type(exc).__name__}: {exc}\n{traceback.format_exc()[-3000:]}"]
    if wanted:
        return [f"{where} is marked 'raises: {wanted}' but ran without an error"]
    warned = [str(w.message) for w in caught if issubclass(w.category, DiracWarning)]
    if warned and "warns" not in block.options:
        return [f"{where} warns, and the page does not say so (give the block the option 'warns' if it is meant):\n"
                + "\n".join(warned)]
    if block.expected is not None and is_placeholder(block.expected):
        return [f"{where}: the page shows only '...' as its output: show the real output"]
    if block.expected is not None and not matches(block.expected, out.getvalue()):
        return [f"{where}: printed output differs from the page.\n--- page:\n{block.expected}--- real:\n{out.getvalue()}"]
    return []


def run_page(path: Path, label: str) -> tuple[list[str], int]:
    """Run every block of one page in order (in the current directory).

    Returns the problems found and the number of things executed (python blocks,
    commands, files written).
    """
    namespace: dict = {"__name__": "__doc_example__"}
    problems: list[str] = []
    executed = 0
    for block in parse_blocks(path):
        if problems:  # later blocks build on earlier ones: stop at the first problem
            break
        if "file" in block.options:
            target = Path(block.options["file"])
            target.parent.mkdir(parents=True, exist_ok=True)
            target.write_text(block.text, encoding="utf-8")
            executed += 1
        elif block.language == "python":
            problems += run_python(label, block, namespace)
            executed += 1
        elif block.language in RUNNABLE_CONSOLE:
            status = int(block.options.get("status", "0"))
            for command in console_commands(block):
                problems += check_command(label, command, status)
                executed += 1
    return problems, executed
