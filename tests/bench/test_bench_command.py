"""``dirac bench``: structure of its output on a tiny suite (no timing assertions)."""

from __future__ import annotations

import json
import math

import pytest

import dirac.bench.reference as reference
import dirac.bench.suite as suite
from dirac.bench.suite import ConstrainedCase, MethodGrid, RigidBodyCase
from dirac.bench.targets import Target, work_precision_targets


@pytest.fixture
def tiny_suite(monkeypatch, tmp_path):
    """A suite of one short rigid-body run per method kind and one pendulum period."""
    monkeypatch.setattr(reference, "cache_directory", lambda: tmp_path)
    body = RigidBodyCase(
        "standard", "tiny", (2.0, 1.0, 2.0 / 3.0), (math.cos(1.1), 0.0, math.sin(1.1)), 2.0,
        (
            MethodGrid("lie-poisson-4", (0.1, 0.05), "dt"),
            MethodGrid("exact", (None,), ""),
            MethodGrid("scipy-DOP853", (1e-10,), "tolerance"),
        ),
    )
    pendulum = ConstrainedCase("pendulum", "tiny", "pendulum", (1.0,), 1.0,
                               (MethodGrid("rattle-2", (0.01,), "dt"),))
    monkeypatch.setattr(suite, "rigid_body_cases", lambda quick: [body])
    monkeypatch.setattr(suite, "constrained_cases", lambda quick: [pendulum])
    return tmp_path


def test_bench_writes_one_json_row_per_run_and_a_plot(tiny_suite, capsys):
    from dirac.bench.run import run_benchmark

    json_path = tiny_suite / "bench.json"
    plot_path = tiny_suite / "bench.png"
    run_benchmark(quick=True, json_path=str(json_path), plot_path=str(plot_path), progress=False, targets=False)
    out = capsys.readouterr().out
    assert "machine:" in out and "== standard" in out and "== pendulum" in out and "targets" in out
    document = json.loads(json_path.read_text())
    runs = document["runs"]
    assert [(r["problem"], r["method"], r["value"]) for r in runs] == [
        ("standard", "lie-poisson-4", 0.1), ("standard", "lie-poisson-4", 0.05), ("standard", "exact", None),
        ("standard", "scipy-DOP853", 1e-10), ("pendulum", "rattle-2", 0.01),
    ]
    for row in runs:
        assert "failed" not in row, row
        assert row["cpu_s"] > 0 and row["repeats"] >= 1 and row["steps"] >= 0 and row["evaluations"] >= 1
        assert math.isfinite(row["error"])
    rigid = {(r["method"], r["value"]): r for r in runs if r["problem"] == "standard"}
    # the exact flow agrees with the independent Taylor reference to round-off
    assert rigid[("exact", None)]["error"] < 1e-12
    # a 4th-order method: halving dt divides the error by about 16
    ratio = rigid[("lie-poisson-4", 0.1)]["error"] / rigid[("lie-poisson-4", 0.05)]["error"]
    assert 10 < ratio < 24
    # splitting keeps |M|^2 and R^T R = 1 to round-off; DOP853 does not try to
    assert rigid[("lie-poisson-4", 0.05)]["casimir_error"] < 1e-13
    assert rigid[("lie-poisson-4", 0.05)]["orthogonality_error"] < 1e-13
    pendulum = runs[-1]
    assert pendulum["constraint_residual"] < 1e-10 and pendulum["error_p"] is not None
    assert plot_path.stat().st_size > 1000 and plot_path.read_bytes()[:4] == b"\x89PNG"
    assert {t["name"] for t in document["targets"]} >= {
        "work-precision: fastest non-exact method, error <= 1e-9 (ms CPU)",
        "work-precision: DOP853 CPU / fastest (same error)",
    }


def _row(method, value, cpu, error):
    return {"problem": "standard", "method": method, "value": value, "cpu_s": cpu, "call_cpu_s": cpu,
            "error": error, "steps": 10, "evaluations": 100}


def test_work_precision_targets_pick_the_cheapest_run_reaching_the_error():
    rows = [
        _row("lie-poisson-8", 0.5, 0.4e-3, 2e-7),  # too inaccurate
        _row("lie-poisson-8", 0.25, 0.9e-3, 5e-10),
        _row("lie-poisson-sym-8", 0.35, 0.5e-3, 1e-10),
        _row("exact", None, 0.05e-3, 1e-14),  # excluded: not a time stepper
        _row("scipy-DOP853", 1e-8, 30e-3, 3e-9),  # too inaccurate
        _row("scipy-DOP853", 1e-10, 50e-3, 4e-10),
        _row("scipy-DOP853", 1e-12, 80e-3, 3e-11),
    ]
    fastest, ratio = work_precision_targets(rows)
    assert fastest.value == pytest.approx(0.5) and fastest.met
    assert "lie-poisson-sym-8" in fastest.detail and "lie-poisson-8 dt = 0.25" in fastest.detail
    assert ratio.value == pytest.approx(100.0) and ratio.met


def test_missed_targets_are_reported_with_the_factor():
    from dirac.bench.report import format_targets

    text = format_targets([
        Target("a", 2.6, "ms", 1.0, "<="), Target("b", 25.0, "x", 50.0, ">="), Target("c", None, "s", 1.0, "<="),
    ])
    assert "MISSED by 2.60x" in text and "MISSED by 2.00x" in text and "not measured" in text
    # what a missed target means for the user is said, once, and the lines say which way it is missed
    assert "slower than planned" in text and "Results are as accurate either way" in text
    assert "MISSED by 2.60x (over the target" in text and "MISSED by 2.00x (under the target" in text
    assert text.rstrip().endswith("0 of 3 targets met, 2 missed, 1 not measured")


@pytest.mark.parametrize("flag,module", [("--stress", "dirac.commands.bench_stress"), ("--ensemble", "dirac.commands.bench_ensemble")])
def test_stress_and_ensemble_flags_delegate_to_their_module(run_cli, monkeypatch, flag, module):
    import sys
    import types

    seen = []
    fake = types.ModuleType(module)
    fake.main = lambda args: seen.append(args) or 0
    monkeypatch.setitem(sys.modules, module, fake)
    status, _, _ = run_cli("bench", flag)
    assert status == 0 and len(seen) == 1
    assert getattr(seen[0], flag.lstrip("-")) is True


@pytest.mark.parametrize("flag,module", [("--stress", "dirac.commands.bench_stress"), ("--ensemble", "dirac.commands.bench_ensemble")])
def test_stress_and_ensemble_flags_say_when_unavailable(run_cli, monkeypatch, flag, module):
    import sys

    monkeypatch.setitem(sys.modules, module, None)  # importing it now raises ModuleNotFoundError
    status, _, err = run_cli("bench", flag)
    assert status == 2
    assert err.startswith("error:") and f"dirac bench {flag} is not available in this version yet" in err


def test_bad_plot_name_is_an_input_error(run_cli):
    status, _, err = run_cli("bench", "--quick", "--plot", "figure.pdf")
    assert status == 2 and err.startswith("error:") and ".png" in err


def test_output_into_a_missing_folder_is_an_input_error(run_cli, tmp_path):
    status, _, err = run_cli("bench", "--quick", "--json", str(tmp_path / "no" / "such" / "bench.json"))
    assert status == 2 and err.startswith("error:") and "does not exist" in err
