"""The forced-systems table of dirac bench: its rows and its target."""

from __future__ import annotations

from dirac.bench.forced import forced_rows, forced_target, format_forced_rows


def test_forced_rows_converge_and_the_target_compares_equal_error():
    rows = forced_rows(quick=True, repeats=1, say=lambda message: None)
    by_method: dict[str, list[dict]] = {}
    for row in rows:
        by_method.setdefault(row["method"], []).append(row)
    assert set(by_method) == {"forced-rattle-2", "forced-rattle-4", "conformal-2", "conformal-4", "scipy-DOP853"}
    for method, subset in by_method.items():
        errors = [r["error"] for r in sorted(subset, key=lambda r: -r["value"])]
        assert errors[-1] < errors[0], (method, errors)  # smaller step or tolerance, smaller error
    target = forced_target(rows)
    assert target.value is not None
    reached = [r for r in rows if r["error"] <= 1e-8]
    ours = min(r["cpu_s"] for r in reached if not r["method"].startswith("scipy-"))
    dop = min(r["cpu_s"] for r in reached if r["method"] == "scipy-DOP853")
    assert target.value == dop / ours
    assert "damped pendulum" in format_forced_rows(rows)


def test_forced_target_is_unmeasured_when_nothing_reaches_the_threshold():
    rows = [{"problem": "damped pendulum", "method": "conformal-4", "value": 0.1, "cpu_s": 1e-3, "error": 1e-3}]
    assert forced_target(rows).value is None
