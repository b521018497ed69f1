"""The square-root relativistic particle held on a conic: counts by hand, and the refusal.

``L = -m sqrt(t_dot^2 - x_dot^2 - y_dot^2)`` with the holonomic constraint
``chi = x^2 + y^2/4 - 1 = 0`` (an ellipse, a regular curve: its gradient ``(2x, y/2)``
never vanishes on it) or ``chi = x^2 - y^2/4 - 1`` (a hyperbola), its multiplier
``lambda_1`` a coordinate (``L_ext = L - lambda_1 chi``). By hand:

* the Hessian of ``L_ext`` in the velocities ``(t_dot, x_dot, y_dot, lambda_1_dot)`` has
  rank 2 (``L`` is homogeneous of degree one in ``(t_dot, x_dot, y_dot)``, so its Hessian
  annihilates them; ``lambda_1_dot`` does not occur): 4 - 2 = 2 primary constraints,
  ``p_lambda_1 = 0`` and the mass shell ``m^2 - p_t^2 + p_x^2 + p_y^2 = 0``;
* Euler's theorem gives ``p q_dot - L = 0``, so ``H_c = lambda_1 chi``;
* stage 2: ``{p_lambda_1, H_T} = -chi`` gives ``chi = 0``, and
  ``{m^2 - p_t^2 + p_x^2 + p_y^2, lambda_1 chi} = -2 lambda_1 (p_x d_x chi + p_y d_y chi)``
  gives ``lambda_1 (4 x p_x + y p_y) = 0`` for the ellipse (``lambda_1 (4 x p_x - y p_y)``
  for the hyperbola): the union of the branch ``lambda_1 = 0`` (no constraint force) and
  the branch ``4 x p_x + y p_y = 0`` (momentum tangent to the curve), which meet where
  both vanish. There is no single regular constraint surface, so the engine must
  refuse (never analyse one branch silently) and name both branches.

The same holds for any holonomic constraint on this homogeneous Lagrangian: the mass
shell's consistency condition is always ``lambda_1`` times ``p . grad chi``.
"""

from __future__ import annotations

import pytest

import dirac
from dirac.errors import AnalysisError


def _particle_on(chi: str) -> dirac.Lagrangian:
    return dirac.Lagrangian.from_strings(
        "relativistic_conic", ["t", "x", "y"], "-m*sqrt(t_dot**2 - x_dot**2 - y_dot**2)",
        constraints=[chi], parameters={"m": 1.0},
    )


@pytest.mark.parametrize(
    ("chi", "tangent"),
    [("x**2 + y**2/4 - 1", "4*p_x*x + p_y*y"), ("x**2 - y**2/4 - 1", "4*p_x*x - p_y*y")],
)
def test_conic_refused_at_stage_two_with_both_branches(chi: str, tangent: str) -> None:
    lines: list[str] = []
    with pytest.raises(AnalysisError) as refused:
        dirac.analyze(_particle_on(chi), progress=lines.append)
    # the Legendre transform finished with the hand counts before the chain refused
    assert len(lines) == 1 and "Hessian rank 2, 2 primary constraints" in lines[0]
    message = " ".join(str(refused.value).split())
    assert "stage-2 constraint" in message
    assert f"branches lambda_1 = 0 and {tangent} = 0" in message


def test_free_particle_counts() -> None:
    """Without the conic: one primary constraint (the mass shell), first class, H_c = 0,
    (6 - 2*1)/2 = 2 degrees of freedom (docs/classic_examples.md derives them)."""
    free = dirac.Lagrangian.from_strings(
        "relativistic_sqrt", ["t", "x", "y"], "-m*sqrt(t_dot**2 - x_dot**2 - y_dot**2)", parameters={"m": 1.0}
    )
    analysis = dirac.analyze(free)
    assert analysis.hessian_rank == 2 and analysis.canonical_hamiltonian == 0
    assert [len(stage) for stage in analysis.stages] == [1]
    p_t, p_x, p_y = (analysis.symbols[n] for n in ("p_t", "p_x", "p_y"))
    m = next(iter(analysis.parameters))
    shell = m**2 - p_t**2 + p_x**2 + p_y**2
    assert (analysis.constraints[0] - shell).expand() == 0 or (analysis.constraints[0] + shell).expand() == 0
    assert len(analysis.first_class) == 1 and not analysis.second_class
    assert analysis.physical_degrees_of_freedom == 2
