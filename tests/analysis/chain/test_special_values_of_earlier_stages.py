"""Special parameter values where the rank of an earlier stage's consistency block drops.

``L = x_dot^2/2 + y_dot^2/2 - u x - a u^2/2 - w y``, by hand: ``p = x_dot``, ``p_y = y_dot``,
``p_u = p_w = 0`` (stage 1), ``H_c = p^2/2 + p_y^2/2 + u x + a u^2/2 + w y``.

* ``a != 0``: ``{p_u, H_c} = -(x + a u)``, ``{p_w, H_c} = -y``: stage 2 is ``a u + x, y``.
  The consistency block of stage 2, ``{Phi_a, phi_k}`` over ``p_u, p_w, a u + x, y`` and
  the multipliers of ``p_u, p_w``, has the single non-zero entry ``{a u + x, p_u} = a``:
  rank 1, the row of ``a u + x`` fixes the multiplier of ``p_u`` (``p + a v_u = 0``). The row
  of ``y`` is zero and ``{y, H_c} = p_y``: stage 3 is ``p_y``; ``{p_y, H_c} = -w``: stage 4
  is ``w``, ``{w, p_w} = 1`` fixes the multiplier of ``p_w``. Stages ``[2, 2, 1, 1]``, the six
  constraints pair up (``{p_u, a u + x} = -a``, ``{p_w, w} = -1``, ``{y, p_y} = 1``): 6 second
  class, ``(8 - 6)/2 = 1`` degree of freedom.
* ``a = 0``: the stage-2 block is zero (its rank drops from 1 to 0, before the last
  stage): ``{x, H_c} = p`` and ``{y, H_c} = p_y`` are stage 3, ``{p, H_c} = -u`` and
  ``{p_y, H_c} = -w`` stage 4, which fixes both multipliers (``{u, p_u} = {w, p_w} = 1``).
  Stages ``[2, 2, 2, 2]``, 8 second class (the pairs ``x, p``; ``y, p_y``; ``u, p_u``;
  ``w, p_w``), 0 degrees of freedom.
"""

from __future__ import annotations

import dirac
from dirac.model.lagrangian import Lagrangian

STAGE_TWO = Lagrangian.from_strings(
    "stage_two", ["x", "y", "u", "w"], "x_dot**2/2 + y_dot**2/2 - u*x - a*u**2/2 - w*y", parameters={"a": 1.0}
)


def _counts(analysis) -> tuple:
    return ([len(s) for s in analysis.stages], len(analysis.first_class), len(analysis.second_class),
            analysis.physical_degrees_of_freedom)


def test_the_rank_drop_of_the_stage_two_block_is_found():
    """Hand derivation in the module docstring: a = 0 drops the rank of stage 2's block from 1 to 0."""
    a = dirac.analyze(STAGE_TWO)
    assert _counts(a) == ([2, 2, 1, 1], 0, 6, 1)
    (special,) = a.special_parameter_values
    assert (special.parameter, special.value) == ("a", 0)
    assert "rank of the consistency matrix {Phi_a, phi_k} of stage 2 drops from 1 to 0" in special.where


def test_the_case_a_zero_has_the_hand_counts():
    """Hand derivation in the module docstring: at a = 0 the chain is [2, 2, 2, 2], 8 second class, 0 dof."""
    cases = {c.condition: _counts(c.analysis) for c in dirac.analyze(STAGE_TWO, cases=True).parameter_cases}
    assert cases == {"a != 0": ([2, 2, 1, 1], 0, 6, 1), "a = 0": ([2, 2, 2, 2], 0, 8, 0)}
