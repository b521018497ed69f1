"""Shared test configuration.

``@pytest.mark.slow`` marks long stress runs. CI runs them too, in a bounded form: a slow
test reads ``stress_scaling.stress_scale()`` and shortens itself unless
``DIRAC_FULL_STRESS=1``.
"""

from __future__ import annotations

import pytest


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
