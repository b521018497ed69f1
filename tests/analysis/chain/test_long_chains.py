"""Long Dirac–Bergmann chains: a first-order system with 4 stages and one with 6 stages.

First-order chain (Hessian rank 0), ``L = y x_dot + b a_dot - y^2/2 - (a^2 + b^2)/2 - z (x - a)``
(by hand; ``(x, y)`` and ``(a, b)`` are canonical pairs of the first-order Lagrangian, ``z``
enforces ``x = a``):
  stage 1: ``phi_1 = p_x - y``, ``phi_2 = p_y``, ``phi_3 = p_a - b``, ``phi_4 = p_b``, ``phi_5 = p_z``;
  ``H_c = y^2/2 + (a^2 + b^2)/2 + z (x - a)``; ``{phi_1, phi_2} = {phi_3, phi_4} = -1``, so
  ``phi_1..4`` fix ``u_1 = y``, ``u_2 = -z``, ``u_3 = b``, ``u_4 = z - a`` and
  ``{p_z, H_c} = -(x - a)`` gives
  stage 2: ``x - a``;  ``{x - a, H_T} = u_1 - u_3 = y - b`` gives
  stage 3: ``y - b``;  ``{y - b, H_T} = u_2 - u_4 = a - 2 z`` gives
  stage 4: ``a - 2 z``; ``{a - 2z, H_T} = u_3 - 2 u_5 = 0`` fixes ``u_5 = b/2``: the chain ends.
  8 constraints; no combination ``c . Phi`` commutes with all of them (solving
  ``sum_i c_i {Phi_i, Phi_j} = 0`` column by column forces ``c = 0``), so all are second
  class and ``(10 - 8)/2 = 1`` degree of freedom remains. On the surface ``x = a``,
  ``y = b``, ``z = a/2``, and the Euler–Lagrange equations give ``a_ddot = -a/2``; the
  reduced Lagrangian ``2 b a_dot - b^2 - a^2/2`` gives ``{a, b}_D = 1/2`` (and
  ``{x, y}_D = 1/2``).
Six stages (Hessian rank 3 of 4), ``L = u_dot w_dot/2 + y_dot^2/2 - y^2/2 - k u^2/2 - g u y - z w``
(by hand; ``u, w`` are light-cone-like coordinates with a null kinetic term):
  ``p_u = w_dot/2``, ``p_w = u_dot/2``, ``p_y = y_dot``, stage 1 ``p_z = 0``;
  ``H_c = 2 p_u p_w + p_y^2/2 + y^2/2 + k u^2/2 + g u y + z w``. Each consistency condition
  is the time derivative of the last constraint and is free of the multiplier until the end:
  stage 2 ``w`` (from ``p_z_dot = -w``), stage 3 ``p_u`` (``w_dot = 2 p_u``), stage 4
  ``k u + g y`` (``p_u_dot = -(k u + g y)``), stage 5 ``2 k p_w + g p_y``, stage 6
  ``2 k z + g y + g^2 u`` (from ``2 k p_w_dot + g p_y_dot = -2 k z - g (y + g u)``); its time
  derivative ``2 k u_1 + g p_y + 2 g^2 p_w = 0`` fixes ``u_1 = -(g p_y + 2 g^2 p_w)/(2k)``.
  ``C``: ``p_z`` pairs only with stage 6 (``-2k``), ``w`` only with stage 5 (``2k``), leaving
  ``{p_u, k u + g y} = -k``: the Pfaffian is ``±4 k^3 ≠ 0``, all 6 are second class and
  ``(8 - 6)/2 = 1`` degree of freedom remains: on the surface ``u = -g y/k``, and ``y``
  oscillates with ``y_ddot = -(1 - g^2/k) y``.
"""

from __future__ import annotations

import numpy as np
import pytest
import sympy

import dirac

FIRST_ORDER = "y*x_dot + b*a_dot - y**2/2 - (a**2 + b**2)/2 - z*(x - a)"
SIX_STAGES = "u_dot*w_dot/2 + y_dot**2/2 - y**2/2 - k*u**2/2 - g*u*y - z*w"


def _proportional(a, b) -> bool:
    ratio = sympy.cancel(sympy.sympify(a) / sympy.sympify(b))
    return bool(ratio.is_number and ratio != 0)


def _weakly_equal(analysis, a, b, seeds=(1, 2, 3)) -> bool:
    """``a = b`` at several points of the constraint surface (parameters at their defaults)."""
    variables = list(analysis.phase_space)
    values = {p: analysis.lagrangian.parameters[p] for p in analysis.parameters}
    difference = sympy.lambdify(variables, (sympy.sympify(a) - sympy.sympify(b)).subs(values))
    for seed in seeds:
        point = analysis.surface_point(seed=seed)
        if abs(float(difference(*[point[x.name] for x in variables]))) > 1e-9:
            return False
    return True


@pytest.fixture(scope="module")
def first_order():
    return dirac.analyze(dirac.Lagrangian.from_strings("first_order_chain", ["x", "y", "a", "b", "z"], FIRST_ORDER))


@pytest.fixture(scope="module")
def six():
    lagrangian = dirac.Lagrangian.from_strings(
        "six_stages", ["u", "w", "y", "z"], SIX_STAGES, parameters={"k": 2.0, "g": 0.6}
    )
    return dirac.analyze(lagrangian)


def test_first_order_chain_has_four_stages(first_order):
    s = first_order.symbols
    assert first_order.hessian_rank == 0
    assert [len(stage) for stage in first_order.stages] == [5, 1, 1, 1]
    expected = [s["x"] - s["a"], s["y"] - s["b"], s["a"] - 2 * s["z"]]
    for stage, constraint in zip(first_order.stages[1:], expected):
        assert _proportional(stage[0], constraint)
    assert first_order.first_class == [] and len(first_order.second_class) == 8
    assert first_order.physical_degrees_of_freedom == 1
    assert first_order.undetermined_multipliers == []
    p_z = first_order.primary_constraints.index(s["p_z"])
    assert _weakly_equal(first_order, first_order.multipliers[f"u_{p_z + 1}"], s["b"] / 2)


def test_first_order_chain_reduced_bracket(first_order):
    s = first_order.symbols
    assert sympy.simplify(first_order.dirac_bracket(s["a"], s["b"]) - sympy.Rational(1, 2)) == 0
    assert sympy.simplify(first_order.dirac_bracket(s["x"], s["y"]) - sympy.Rational(1, 2)) == 0
    flow = first_order.equations_of_motion([s["a"], s["b"]])
    assert _weakly_equal(first_order, flow[s["a"]], s["b"])
    assert _weakly_equal(first_order, flow[s["b"]], -s["a"] / 2)


def test_six_stages(six):
    s = six.symbols
    k, g = sympy.symbols("k g", real=True)
    assert six.hessian_rank == 3
    assert [len(stage) for stage in six.stages] == [1, 1, 1, 1, 1, 1]
    expected = [
        s["p_z"],
        s["w"],
        s["p_u"],
        k * s["u"] + g * s["y"],
        2 * k * s["p_w"] + g * s["p_y"],
        2 * k * s["z"] + g * s["y"] + g**2 * s["u"],
    ]
    for stage, constraint in zip(six.stages, expected):
        assert _proportional(stage[0], constraint)
    assert six.first_class == [] and len(six.second_class) == 6
    assert six.physical_degrees_of_freedom == 1
    u_by_hand = -(g * s["p_y"] + 2 * g**2 * s["p_w"]) / (2 * k)
    assert _weakly_equal(six, six.multipliers["u_1"], u_by_hand)


def test_six_stage_reduced_motion(six):
    s = six.symbols
    k, g = 2.0, 0.6
    flow = six.equations_of_motion([s["y"], s["p_y"]])
    assert _weakly_equal(six, flow[s["y"]], s["p_y"])
    assert _weakly_equal(six, flow[s["p_y"]], -(1 - g**2 / k) * s["y"])
    point = six.surface_point(seed=5)
    assert np.isclose(point["u"], -g * point["y"] / k)


def test_sparse_normal_components_equal_the_dense_projection():
    """|(1 - P) row| of the sparse projection per connected block against the dense QR projection."""
    import numpy as np
    import scipy.sparse as sp

    from dirac.analysis.chain.chain_regularity import _normal_norms
    from dirac.analysis.legendre.regularity import normal_components

    for trial in range(6):
        base = (sp.random(40, 90, density=0.03, random_state=trial) + sp.eye(40, 90)).tocsr()
        if trial % 2:  # a dependent base row (a reducible constraint)
            base = sp.vstack([base, base.getrow(0) + 2.0 * base.getrow(3)]).tocsr()
        rows = sp.random(12, 90, density=0.05, random_state=50 + trial).tocsr()
        rows = sp.vstack([rows, base.getrow(5) - base.getrow(7)]).tocsr()  # in the span: normal part 0
        found = _normal_norms(base, rows)
        assert found is not None
        expected = normal_components(rows.toarray(), base.toarray(), np.ones(rows.shape[0]))
        assert np.allclose(found, expected, atol=1e-12)
        assert found[-1] < 1e-12
