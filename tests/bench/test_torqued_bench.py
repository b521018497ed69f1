"""The torqued-body rows of ``dirac bench`` (dirac/bench/torqued.py) and their target."""

from __future__ import annotations

import numpy as np

from dirac.bench.targets import torqued_target
from dirac.bench.torqued import TORQUED_BODY, torqued_rhs
from dirac.flows.torques import Torque


def test_the_baseline_right_hand_side_is_euler_s_equations_with_the_same_torque():
    """The hand-written float RHS of DOP853 against M x Omega + N with N from the parsed torque."""
    rng = np.random.default_rng(3)
    inertia = np.array([3.0, 2.0, 1.0])
    torque = Torque(TORQUED_BODY)
    for _ in range(5):
        M = rng.normal(size=3)
        R, _ = np.linalg.qr(rng.normal(size=(3, 3)))
        t = float(rng.uniform(0, 10))
        omega = M / inertia
        N = torque.evaluate(M, R, t, inertia)
        hat = np.array([[0, -omega[2], omega[1]], [omega[2], 0, -omega[0]], [-omega[1], omega[0], 0]])
        expected = np.concatenate([np.cross(M, omega) + N, (R @ hat).ravel(), [N @ omega]])
        assert np.allclose(torqued_rhs(t, np.concatenate([M, R.ravel(), [0.0]])), expected, rtol=1e-14, atol=1e-15)


def test_the_target_compares_the_fastest_runs_that_reach_the_error():
    rows = [
        {"problem": "torqued body", "method": "exact-kick-6", "value": 0.2, "cpu_s": 1e-3, "error": 5e-10},
        {"problem": "torqued body", "method": "lie-poisson-4", "value": 0.1, "cpu_s": 1e-4, "error": 1e-6},
        {"problem": "torqued body", "method": "scipy-DOP853", "value": 1e-9, "cpu_s": 4e-3, "error": 7e-9,
         "evaluations": 400},
        {"problem": "torqued body", "method": "scipy-DOP853", "value": 1e-7, "cpu_s": 2e-3, "error": 3e-7,
         "evaluations": 300},
    ]
    target = torqued_target(rows)
    assert target.value == 4.0 and target.met
    assert torqued_target(rows[1:2]).value is None
