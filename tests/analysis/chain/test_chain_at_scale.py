"""The constraint chain of a local system touches only the entries that can be non-zero.

Checked against the definitions on the planar chain (systems/scale_models.py): the rows
``A_ak = {Phi_a, phi_k}`` built only for primaries that share a variable with ``Phi_a``
equal the full list of brackets, and gradients evaluated over their non-zero entries equal
the dense gradients; the hand counts hold on the large-system path (4 stages of ``n``, ``4 n``
second class, ``n`` degrees of freedom, every ``u_k`` fixed alone) without the exact
multiplier solve having run.
"""

from __future__ import annotations

import numpy as np
import pytest

import dirac
from dirac.analysis.chain.chain_regularity import gradient_values
from dirac_systems.scale_models import chain


@pytest.fixture(scope="module")
def three():
    return dirac.analyze(chain(3))


def test_consistency_rows_equal_every_bracket_with_the_primaries(three):
    ch = three._chain
    pb = ch.phase_space.poisson_bracket
    for c in three.constraints:
        _, row = ch._rows(c)
        assert row == [pb(c, phi) for phi in ch.primary]


def test_gradients_over_non_zero_entries_equal_the_dense_gradients(three):
    space, numerics, points = three._space, three._numerics, three._points
    cs = three.constraints
    dense = numerics.evaluate([g for c in cs for g in space.gradient(c)], points).reshape(len(points), len(cs), -1)
    assert np.array_equal(gradient_values(space, numerics, cs, points), dense)


def test_chain_hand_counts_on_the_large_system_path():
    n = 21  # 126 phase-space variables: sparse surface points and one-pass ranks
    analysis = dirac.analyze(chain(n))
    assert [len(stage) for stage in analysis.stages] == [n] * 4
    assert len(analysis.second_class) == 4 * n and analysis.first_class == []
    assert analysis.physical_degrees_of_freedom == n and analysis.reducible_constraints == []
    assert analysis.undetermined_multipliers == [] and sorted(analysis.multipliers) == sorted(f"u_{k}" for k in range(1, n + 1))
    assert not analysis.multiplier_solution.solved  # counts and names need no exact solve
    assert any(note.startswith("large system (126 phase-space variables)") and "first time" in note for note in analysis.notes)
