"""Shared test configuration.

``@pytest.mark.slow`` marks long stress runs. CI runs them too, in a bounded form: a slow
test reads ``stress_scaling.stress_scale()`` and shortens itself unless
``DIRAC_FULL_STRESS=1``.

The suite runs on every core with pytest-xdist (``-n auto --dist loadfile`` in
pyproject.toml; ``pytest -n 0`` runs it in one process): the tests of one file go to one
worker, so a module-scoped fixture (an analysis, compiled kernels) is still built once and
the kernels a file's tests share are compiled once. The workers share the cache of
generated code (``$DIRAC_CACHE_DIR``, else ``~/.cache/dirac/generated``) as a user's
parallel runs do: every writer of it uses file names of its own before an atomic rename.
xdist hands the files to the workers largest first by their number of tests; a file of few
but long tests (``LONG_FILES``: each compiles kernels of its own for a minute or more) would
then start last and keep one worker busy after the other has finished, so
``pytest_xdist_make_scheduler`` starts those files first (``xdist_order.py``).

Property tests (hypothesis) draw the same examples in every bounded run (``derandomize``,
no example database): a run of the suite is reproducible, and a rare draw that is slow or
fails cannot appear in one CI run and not in the next. The full stress runs
(``DIRAC_FULL_STRESS=1``) draw new examples each time, which is where the search for
failures goes on.
"""

from __future__ import annotations

import os

import pytest
from hypothesis import settings

settings.register_profile("bounded", derandomize=True, database=None)
settings.register_profile("exploring")
settings.load_profile("exploring" if os.environ.get("DIRAC_FULL_STRESS") == "1" else "bounded")

@pytest.hookimpl(optionalhook=True)
def pytest_xdist_make_scheduler(config, log):
    """``--dist loadfile`` with the long files handed out first (:mod:`xdist_order`)."""
    from xdist_order import long_files_first_scheduler

    return long_files_first_scheduler(config, log)


@pytest.fixture
def run_cli(capsys):
    """Run the ``dirac`` command line in-process; return (status, stdout, stderr)."""
    from dirac.cli import main

    def run(*argv: str) -> tuple[int, str, str]:
        try:
            status = main(list(argv))
        except SystemExit as exc:  # argparse errors and --help
            status = int(exc.code or 0)
        captured = capsys.readouterr()
        return status, captured.out, captured.err

    return run
