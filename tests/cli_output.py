"""Checks of what a ``dirac`` command printed on stderr, shared by the command-line tests.

Importable as ``from cli_output import one_error_line`` because pytest (rootdir/conftest
mode, no ``__init__.py``) puts ``tests/`` on ``sys.path``, as for ``stress_scaling``.
"""

from __future__ import annotations


def one_error_line(status: int, err: str) -> str:
    """Assert exit status 2 and stderr of exactly one non-blank line, an ``error:`` line; return it.

    Stricter than ``assert_one_error_line`` of ``tests/stress/test_bad_input.py``, which
    also lets ``warning:`` lines precede the error. The one ``dirac: compiling ...`` notice
    of a first compilation (a cold cache of generated code) is not counted.
    """
    # the one notice of a first compilation in a process (docs/getting_started.md) is not an error line
    lines = [line for line in err.splitlines() if line.strip() and not line.startswith("dirac: compiling ")]
    assert status == 2, err
    assert len(lines) == 1 and lines[0].startswith("error:"), err
    return lines[0]
