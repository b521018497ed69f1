"""The dispatcher: help, exit statuses, one error line (docs/cli.md)."""

from __future__ import annotations

import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest
from cli_output import one_error_line

from dirac.cli import COMMANDS


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


def test_version_prints_the_installed_version_on_stdout(run_cli):
    from importlib.metadata import version

    status, out, err = run_cli("--version")
    assert (status, out, err) == (0, f"dirac {version('dirac-mechanics')}\n", "")


def test_the_version_is_looked_up_only_when_asked(monkeypatch, run_cli):
    import dirac.cli

    def fail() -> str:
        raise AssertionError("the installed version was looked up")

    monkeypatch.setattr(dirac.cli, "_version", fail)
    dirac.cli.build_parser()
    status, out, _ = run_cli("systems")
    assert status == 0 and "pendulum" in out


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


@pytest.mark.parametrize("command", sorted(COMMANDS))
def test_every_command_takes_quiet_and_verbose(command, run_cli):
    status, out, _ = run_cli(command, "--help")
    assert status == 0
    assert "-q, --quiet" in out and "-v, --verbose" in out


def test_quiet_and_verbose_go_before_or_after_the_command():
    from dirac.cli import build_parser, verbosity

    parser = build_parser()
    assert verbosity(parser.parse_args(["systems"])) == 0
    for argv in (["-q", "systems"], ["systems", "-q"], ["systems", "--quiet"], ["-q", "systems", "-v"]):
        assert verbosity(parser.parse_args(argv)) == -1, argv  # -q wins over -v
    for argv in (["-v", "systems"], ["systems", "-v"], ["systems", "--verbose"]):
        assert verbosity(parser.parse_args(argv)) == 1, argv


def test_systems_output_is_the_same_at_every_level(run_cli):
    default = run_cli("systems")
    assert run_cli("systems", "-q") == default
    assert run_cli("-v", "systems") == default


def test_analyze_reports_its_stages_only_with_verbose(run_cli):
    # the pendulum (the paper's Sect. XI example): rank-2 Hessian in (x, y, lambda), one
    # primary constraint p_lambda = 0, then the chain p_lambda, phi, phi_dot, phi_ddot:
    # four stages of one constraint each, all four second-class
    default = run_cli("analyze", "pendulum")
    assert default[0] == 0 and default[2] == ""  # not a terminal: nothing on stderr
    quiet = run_cli("analyze", "pendulum", "-q")
    assert quiet == default  # the analysis itself is the output, not a summary of a file
    status, out, err = run_cli("analyze", "pendulum", "-v")
    assert (status, out) == default[:2]
    lines = err.splitlines()
    assert len(lines) == 4 and all(line.startswith("analyze: ") and line.endswith(" s)") for line in lines)
    assert lines[0].startswith("analyze: Legendre transform: Hessian rank 2, 1 primary constraint (")
    assert lines[1].startswith("analyze: constraint chain: 4 stages (sizes 1, 1, 1, 1), 4 constraints (")
    assert lines[2].startswith("analyze: classification: 0 first-class, 4 second-class (")
    assert lines[3].startswith("analyze: Dirac bracket set up (")


def test_analyze_compare_reports_its_phases_with_verbose(run_cli):
    default = run_cli("analyze", "pendulum", "--compare", "dirac,dirac:3")
    assert default[0] == 0 and default[2] == ""
    status, out, err = run_cli("analyze", "pendulum", "--compare", "dirac,dirac:3", "-v")
    assert (status, out) == default[:2]
    phases = [line.split(" (")[0] for line in err.splitlines()[4:]]
    assert phases == [
        "analyze: compare: brackets dirac and dirac built",
        "analyze: compare: 3 point(s) of the constraint surface sampled",
        "analyze: compare: brackets compared at the points",
        "analyze: compare: Jacobi identity of dirac checked",
        "analyze: compare: Jacobi identity of dirac checked",
    ]


def test_run_quiet_writes_the_file_and_prints_nothing(tmp_path, run_cli):
    scene = Path(__file__).resolve().parents[2] / "docs" / "scenes" / "pendulum.toml"
    status, out, err = run_cli("run", str(scene), "--out", str(tmp_path / "q.npz"), "-q")
    assert (status, out, err) == (0, "", "")
    assert (tmp_path / "q.npz").is_file()
    status, out, err = run_cli("run", str(scene), "--out", str(tmp_path / "v.npz"), "-v")
    assert status == 0 and "written to" in out
    assert err.startswith("run: integration ") and "s CPU" in err
    with np.load(tmp_path / "q.npz") as q, np.load(tmp_path / "v.npz") as v:
        assert np.array_equal(q["t"], v["t"])
