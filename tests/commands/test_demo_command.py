"""``dirac demo``: the flagship scene (the standard test case, docs/conventions.md) with a summary."""

from __future__ import annotations

import json
import re

import numpy as np


def _value(stdout: str, label: str) -> float:
    match = re.search(rf"{re.escape(label)}\s+([0-9.e+-]+)", stdout)
    assert match, (label, stdout)
    return float(match.group(1))


def test_demo_prints_method_steps_time_and_conservation(run_cli):
    status, stdout, stderr = run_cli("demo", "--no-progress")
    assert status == 0
    assert "warning: " in stderr and "triangle inequality" in stderr  # I = (2, 1, 2/3) is not physical
    assert "method         exact" in stdout
    assert "H_0 = 0.647125279313836" in stdout  # reference H_0 = 0.64712527931383642713 (docs/conventions.md)
    assert "t = 0 .. 1000" in stdout
    for label in ("energy H_0", "Casimir |M|^2", "lab momentum m = R M", "|R^T R - 1|"):
        assert _value(stdout, label) < 1e-12
    assert re.search(r"CPU time\s+[0-9.e+-]+ s", stdout)


def test_demo_with_a_splitting_method_and_output_file(run_cli, tmp_path):
    out = tmp_path / "demo.npz"
    status, stdout, _ = run_cli("demo", "--method", "lie-poisson-6", "--t-end", "50", "--dt", "0.05",
                                "--out", str(out), "--no-progress")
    assert status == 0
    assert "lie-poisson-6 (order 6), dt = 0.05" in stdout
    assert "steps          1000" in stdout
    assert _value(stdout, "Casimir |M|^2") < 1e-12
    assert _value(stdout, "energy H_0") < 1e-6
    with np.load(out) as data:
        meta = json.loads(str(data["meta"]))
        M = data["M"]
        t = data["t"]
    assert meta["method"] == "lie-poisson-6" and meta["complete"] is True
    # M(10) of the standard test case (docs/conventions.md)
    ten = int(np.argmin(np.abs(t - 10.0)))
    assert t[ten] == 10.0
    assert np.abs(M[ten] - [0.40706613658804081, 0.28300742681284408, 0.86844916766156164]).max() < 1e-7
