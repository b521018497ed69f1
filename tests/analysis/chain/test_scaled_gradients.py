"""A new constraint whose gradient is large near a pole of its coefficients is still new.

By hand: ``L = q1_dot^2 + 3/2 q1 q1_dot q3_dot - 1/2 q2_dot^2 + 3/2 q2 q2_dot q3_dot`` with the
holonomic constraint ``q1 = 0`` and its multiplier ``lambda`` as a variable. Lagrange's equation
of ``q1`` is ``d/dt (2 q1_dot + 3/2 q1 q3_dot) - 3/2 q1_dot q3_dot = lambda``; on ``q1 = 0``
for all times its left side is zero, so ``lambda = 0``: the multiplier is determined, not a
gauge freedom. In the Dirac-Bergmann chain: ``p_lambda = 0``, then ``q1 = 0``, then
``q1_dot = 0`` (on ``q1 = 0``: ``p_q1 / 2 = 0``), then ``lambda = 0`` at stage 4
(``{chi_3, H_c} = -lambda / 2`` on the surface), which fixes ``u``: four second-class
constraints, none first class, ``(8 - 4) / 2 = 2`` degrees of freedom.

The stage-4 gradient is about ``5e5 dq1 - 0.5 dlambda`` at sample points near ``q2 = 0``,
where the coefficients have a pole; the rank decision measured the kept ``dq1`` against it
and dropped ``lambda = 0`` as dependent, reporting ``p_lambda`` first class and ``u``
undetermined: a wrong classification, said without a warning.
"""

from __future__ import annotations

import warnings

import numpy as np

import dirac
from dirac.analysis.core.numeric import independent_rows, unit_rows

L = "q1_dot**2 + 3*q1*q1_dot*q3_dot/2 - q2_dot**2/2 + 3*q2*q2_dot*q3_dot/2"


def test_lambda_is_fixed_at_the_fourth_stage():
    system = dirac.Lagrangian.from_strings("pole", ["q1", "q2", "q3"], L, constraints=["q1"])
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        analysis = dirac.analyze(system)
    assert [len(stage) for stage in analysis.stages] == [1, 1, 1, 1]
    assert len(analysis.first_class) == 0 and len(analysis.second_class) == 4
    assert analysis.physical_degrees_of_freedom == 2
    assert not analysis.undetermined_multipliers
    lam = next(s for s in analysis.phase_space if s.name == "lambda_1")
    assert lam in analysis.stages[3][0].free_symbols


def test_a_kept_row_short_beside_the_new_one_still_counts():
    """The numbers of the failing point: kept ``dp_lambda``, ``dq1`` and ``516 dq1 + 0.5 dp_q1``,
    new ``5.3e5 dq1 - 0.5 dlambda`` (variables q1, lambda, p_q1, p_lambda): independent, as
    its ``dlambda`` part shows, and so by the rank of the equilibrated rows."""
    kept = np.array([[0.0, 0.0, 0.0, 1.0], [1.0, 0.0, 0.0, 0.0], [516.0, 0.0, 0.5, 0.0]])
    new = np.array([[5.3e5, -0.5, 0.0, 0.0]])
    assert independent_rows([new], [0], base=[kept], equilibrate=True) == [0]
    assert independent_rows([new], [0], base=[kept * 1e6], equilibrate=True) == [0]  # the constant factors do not matter
    dependent = np.array([[5.3e5, 0.0, 0.0, 0.0]])
    assert independent_rows([dependent], [0], base=[kept], equilibrate=True) == []
    assert independent_rows([new], [0], base=[kept]) == []  # unscaled: the short kept rows look like zero
    assert np.allclose(np.linalg.norm(unit_rows(kept), axis=1), 1.0)
