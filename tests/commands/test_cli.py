"""The dispatcher: help, exit statuses, one error line (docs/cli.md)."""

from __future__ import annotations

import subprocess
import sys

from cli_output import one_error_line


def test_help_lists_every_contract_command(run_cli):
    status, out, _ = run_cli("--help")
    assert status == 0
    for command in ("demo", "systems", "analyze", "run", "bench"):
        assert command in out


def test_unknown_command_is_bad_input_with_one_error_line(run_cli):
    status, _, err = run_cli("frobnicate")
    assert status == 2
    lines = err.strip().splitlines()
    assert len(lines) == 1 and lines[0].startswith("error:")


def test_systems_lists_builtins_with_descriptions(run_cli):
    status, out, _ = run_cli("systems")
    assert status == 0
    line = next(l for l in out.splitlines() if l.strip().startswith("pendulum"))
    assert "pendulum" in line and len(line.split()) > 2


def test_python_dash_m_runs_the_same_cli():
    result = subprocess.run([sys.executable, "-m", "dirac", "systems"], capture_output=True, text=True, timeout=120)
    assert result.returncode == 0, result.stderr
    assert "pendulum" in result.stdout


def test_help_does_not_import_sympy_or_numba():
    code = "import sys; from dirac.cli import build_parser; build_parser(); print(sorted(m for m in ('sympy', 'numba', 'scipy') if m in sys.modules))"
    result = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, timeout=120)
    assert result.returncode == 0, result.stderr
    assert result.stdout.strip() == "[]"


def test_bare_dirac_prints_help_and_one_error_line(run_cli):
    # regression: bare `dirac` exited with status 2 but printed no error: line
    status, out, err = run_cli()
    assert status == 2
    assert "COMMAND" in out
    lines = err.strip().splitlines()
    assert len(lines) == 1 and lines[0].startswith("error: no command given")


def test_python_system_file_whose_system_fails_is_one_error_line(tmp_path, run_cli):
    # regression: the call of system() in a .py system file was not guarded (traceback, not one error line)
    for source in ('def system():\n    raise RuntimeError("boom")\n', "def system(a):\n    return a\n"):
        path = tmp_path / "broken.py"
        path.write_text(source)
        status, _, err = run_cli("analyze", str(path))
        assert one_error_line(status, err).startswith("error: system() in"), err
