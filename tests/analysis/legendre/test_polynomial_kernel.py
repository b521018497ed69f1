"""Polynomial null vectors and scaled right inverses of a velocity map, by ansatz."""

from __future__ import annotations

import numpy as np
import sympy

from dirac.analysis.core.numeric import Numerics
from dirac.analysis.core.phase_space import PhaseSpace
from dirac.analysis.legendre.polynomial_kernel import polynomial_kernel

R = sympy.Matrix(3, 3, lambda i, j: sympy.Symbol(f"R_{i + 1}{j + 1}", real=True))


def numerics_on(coordinates, parameter_values=None) -> Numerics:
    """The engine's evaluator on the phase space of ``coordinates`` (momenta p_<name>)."""
    momenta = tuple(sympy.Symbol(f"p_{c.name}", real=True) for c in coordinates)
    parameters = tuple(parameter_values or {})
    return Numerics(PhaseSpace(tuple(coordinates), momenta, parameters), dict(parameter_values or {}), seed=0)


def body_velocity_map() -> sympy.Matrix:
    """Omega_k = -1/2 eps_knm (R^T R_dot)_nm (227) as a 3 x 9 matrix acting on R_dot."""
    return sympy.Matrix(
        3, 9, lambda k, c: -sympy.Rational(1, 2) * sum(sympy.LeviCivita(k, n, c % 3) * R[c // 3, n] for n in range(3))
    )


def test_rigid_body_null_vectors_and_det_R_right_inverse():
    A = body_velocity_map()
    T = R.T * R - sympy.eye(3)
    holonomic = [T[i, j] for i in range(3) for j in range(i, 3)]
    kernel = polynomial_kernel(A, numerics_on(list(R)), 3, holonomic)
    assert kernel is not None and kernel.unit_denominator
    assert len(kernel.null_basis) == 6
    N = sympy.Matrix(kernel.null_basis).T
    assert (A * N).applyfunc(sympy.expand) == sympy.zeros(3, 6)  # exact null vectors
    assert kernel.degree[0] == 1  # sym(p R^T): no higher degree needed
    (B, d), = kernel.right_inverses
    assert (A * B - d * sympy.eye(3)).applyfunc(sympy.expand) == sympy.zeros(3, 3)
    ratio = sympy.cancel(d / R.det())
    assert ratio.is_Rational and ratio != 0  # d is a multiple of det(R): never zero on O(3)
    # the columns of B are tangent to R^T R = 1 at rotations
    J = sympy.Matrix(holonomic).jacobian(list(R))
    rng = np.random.default_rng(1)
    for _ in range(3):
        q, _r = np.linalg.qr(rng.normal(size=(3, 3)))
        values = dict(zip(R, q.ravel()))
        assert np.max(np.abs(np.array((J * B).subs(values), dtype=float))) < 1e-12


def test_without_holonomic_constraints_the_cofactors_are_combined():
    A = body_velocity_map()
    kernel = polynomial_kernel(A, numerics_on(list(R)), 3)
    assert kernel is not None and not kernel.unit_denominator
    p = sympy.Matrix(9, 1, lambda i, _: sympy.Symbol(f"p{i}"))
    m, den = kernel.momentum_solution(p)
    assert sympy.expand(den - sum(d**2 for _, d in kernel.right_inverses)) == 0
    for B, d in kernel.right_inverses:
        assert (A * B - d * sympy.eye(3)).applyfunc(sympy.expand) == sympy.zeros(3, 3)


def test_non_polynomial_map_is_declined():
    x, y = sympy.symbols("x y", real=True)
    A = sympy.Matrix([[sympy.sin(x), y]])
    assert polynomial_kernel(A, numerics_on([x, y]), 1) is None


def test_parameters_stay_in_the_coefficient_field():
    x, y = sympy.symbols("x y", real=True)
    a = sympy.Symbol("a", positive=True)
    A = sympy.Matrix([[a * x, y]])  # null vector (y, -a x)
    kernel = polynomial_kernel(A, numerics_on([x, y], {a: 2.0}), 1)
    assert kernel is not None
    (n,) = kernel.null_basis
    assert sympy.expand(A[0, 0] * n[0] + A[0, 1] * n[1]) == 0


def test_the_first_columns_in_the_ring_are_the_sympy_entries_converted():
    """The ring elements ``_first_diagonal`` multiplies are ``B``'s first column, exactly (QQ and a parameter field)."""
    from sympy.polys.rings import PolyRing

    from dirac.analysis.legendre.polynomial_kernel import _ansatz

    q = list(R)
    a = sympy.Symbol("a", positive=True)
    # degree 2 gives (228)'s first candidates with d != 0; over the parameter field degree 1 (its exact nullspace is slow)
    for A, domain, degree in ((body_velocity_map(), sympy.QQ, 2), (a * body_velocity_map(), sympy.QQ.frac_field(a), 1)):
        ring = PolyRing(q, domain)
        entries = [[ring(A[i, j]) for j in range(A.shape[1])] for i in range(A.shape[0])]
        columns: list = []
        matrices = _ansatz(entries, q, domain, degree, A.shape[0], scaled_identity=True, first_columns=columns)
        assert matrices and len(columns) == len(matrices)
        for B, column in zip(matrices, columns):
            assert [ring(B[j, 0]) for j in range(B.shape[0])] == [ring.from_dict(terms) for terms in column]
        assert sum(1 for column in columns if any(column)) > 1  # not a comparison of zeros only
