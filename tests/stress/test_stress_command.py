"""``dirac bench --stress``: the command runs the suite, prints the tables, writes JSON.

The sizes are shrunk here (``plan`` replaced); the full sizes run in the slow tests of
this folder and for docs/stress.md.
"""

from __future__ import annotations

import json

import dirac.bench.stress as stress
from dirac.bench.hard_bodies import HARD_BODY_METHODS


def _tiny_plan(quick: bool) -> stress.StressPlan:
    needle = next(body for body in stress.HARD_BODIES if body.name == "needle")
    return stress.StressPlan(long_runs=[("lie-poisson-4", 2_000, 0.05)],
                             constrained=[("pendulum", "rattle-2", 2_000, 0.01)],
                             bodies=(needle,), samples=11)


def test_stress_command_prints_the_tables_and_writes_json(tmp_path, run_cli, monkeypatch):
    monkeypatch.setattr(stress, "plan", _tiny_plan)
    target = tmp_path / "stress.json"
    status, out, _ = run_cli("bench", "--stress", "--quick", "--json", str(target), "--no-progress")
    assert status == 0, out
    assert out.startswith("machine: ")
    assert "| lie-poisson-4 | 2e+03 |" in out
    assert "| needle | exact |" in out and "| pendulum | rattle-2 |" in out
    assert "all passed: yes" in out
    document = json.loads(target.read_text())
    assert document["passed"] is True
    assert {row["method"] for row in document["hard_bodies"]} == set(HARD_BODY_METHODS)
    exact = next(row for row in document["hard_bodies"] if row["method"] == "exact")
    assert exact["error_M"] <= exact["bound"] and exact["error_R"] <= exact["bound"]


def test_a_failed_row_makes_the_command_fail(tmp_path, run_cli, monkeypatch):
    """Exit status 1 when a criterion is missed: here a drift limit no splitting can meet."""
    monkeypatch.setattr(stress, "plan", lambda quick: stress.StressPlan(
        long_runs=[("lie-poisson-2", 2_000, 0.05)], constrained=[], bodies=(), samples=11))
    real = stress.long_run

    def strict(method, steps, dt, samples=1001):
        row = real(method, steps, dt, samples)
        row["passed"] = row["passed"] and row["energy_error_last_tenth"] == 0.0  # impossible
        return row

    monkeypatch.setattr(stress, "long_run", strict)
    status, out, _ = run_cli("bench", "--stress", "--no-progress")
    assert status == 1
    assert "| NO |" in out and "all passed: NO" in out
