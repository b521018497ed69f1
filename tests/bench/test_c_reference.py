"""The benchmark's C reference step: same mathematics as the numba kernel."""

from __future__ import annotations

import math

import numpy as np

import dirac.bench.c_reference as c_reference
from dirac.rigidbody.splitting import advance


def test_c_reference_computes_the_same_strang_step_as_the_package():
    reference, note = c_reference.compile_reference()
    if c_reference.find_compiler() is None:  # machines without cc: the bench says so
        assert reference is None and "no C compiler" in note
        return
    assert reference is not None, note
    inv = 1.0 / np.array([2.0, 1.0, 2.0 / 3.0])
    M0 = np.array([math.cos(1.1), 0.0, math.sin(1.1)])
    for with_R in (True, False):
        M_c, R_c = M0.copy(), np.eye(3)
        reference.advance(M_c, R_c, inv, 0.01, 5000, with_R)
        M_n, R_n = M0.copy(), np.eye(3)
        advance(M_n, R_n, inv, 0.01, 5000, (1.0,), with_R)
        np.testing.assert_allclose(M_c, M_n, rtol=0, atol=1e-14)
        np.testing.assert_allclose(R_c, R_n, rtol=0, atol=1e-14)
    # and it is a rotation of the state: |M| and m = R M conserved
    assert abs(np.linalg.norm(M_c) - 1.0) < 1e-14


def test_missing_compiler_is_reported_not_fatal(monkeypatch):
    monkeypatch.setattr(c_reference, "find_compiler", lambda: None)
    reference, note = c_reference.compile_reference()
    assert reference is None
    assert "no C compiler" in note and "skipped" in note


def test_failed_compilation_is_reported(monkeypatch, tmp_path):
    fake = tmp_path / "cc"
    fake.write_text("#!/bin/sh\necho broken >&2\nexit 1\n")
    fake.chmod(0o755)
    monkeypatch.setattr(c_reference, "find_compiler", lambda: str(fake))
    reference, note = c_reference.compile_reference()
    assert reference is None
    assert "failed" in note and "broken" in note
