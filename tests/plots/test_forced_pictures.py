"""Pictures of forced runs: the error of energy - work, and the energy labelled not conserved."""

from __future__ import annotations

import numpy as np

from dirac.plots.constrained import constrained_errors


def test_forced_errors_are_the_balance_and_the_energy_itself():
    energy = np.array([2.0, 1.5, 1.0])
    work = np.array([0.0, -0.5, -1.0 + 1e-6])  # E - W = 2, 2, 2 - 1e-6
    errors = constrained_errors(energy, None, None, work=work)
    balance = next(v for k, v in errors.items() if "work" in k)
    assert "(conserved)" in next(k for k in errors if "work" in k)
    np.testing.assert_allclose(balance, [0.0, 0.0, 0.5e-6], rtol=1e-9, atol=1e-15)
    changed = next(v for k, v in errors.items() if "not conserved" in k)
    np.testing.assert_allclose(changed, [0.0, 0.25, 0.5])


def test_unforced_errors_keep_the_energy_error():
    errors = constrained_errors(np.array([2.0, 2.0 + 2e-9]), None)
    assert list(errors) == [r"energy $|E-E_0|/|E_0|$"]
