"""The reducibility note of a large stage says the relation briefly.

By hand (systems/scale_models.py): the Gauss laws of the ring, p_A1_i - p_A1_{i-1}, sum to
zero (telescoping), and no smaller set of them does (any n - 1 are independent): one
relation, a signed sum of all n with coefficients +1 or -1. The torus's L^2 Gauss laws
likewise: each p_Ax and p_Ay enters two neighbouring sites' laws with opposite signs.
A note listing every constraint twice would grow with n (~45 KB at n = 1024).
"""

from __future__ import annotations

import pytest

import dirac
from dirac_systems.scale_models import maxwell_ring, maxwell_torus


def _reducible_notes(analysis):
    return [note for note in analysis.notes if "reducible" in note]


@pytest.mark.parametrize(("lagrangian", "count"), [(maxwell_ring(64), 64), (maxwell_torus(6), 36)])
def test_a_long_reducibility_note_states_the_relation_briefly(lagrangian, count):
    analysis = dirac.analyze(lagrangian)
    [note] = _reducible_notes(analysis)
    assert note.startswith(f"stage 2: the {count} constraints ")
    assert f"one relation, proved exactly: a signed sum (coefficients +1 or -1) of all {count} vanishes identically" in note
    assert f"1 of them ({analysis.reducible_constraints[0]}) depend(s) on the {count - 1} others" in note
    assert len(note) < 800
    assert len(analysis.reducible_constraints) == 1


def test_a_short_reducibility_note_lists_every_constraint():
    analysis = dirac.analyze(maxwell_ring(4))
    [note] = _reducible_notes(analysis)
    for c in analysis.stages[1] + analysis.reducible_constraints:
        assert str(c) in note
    assert "independent set kept" in note
