"""Divisors whose square is a constant on the constraint surface
(:func:`dirac.analysis.core.divisors.square_on_surface`, :func:`~dirac.analysis.core.divisors.determinant_grid`).

Hand derivation: ``det(M)^2 = det(M^T) det(M) = det(M^T M)``. On ``M^T M = 1`` (the
orthogonality constraints of Lagrangians (78) and (228)) this is ``det 1 = 1``, so
``det R = +-1`` at every point of the surface and no singular locus of ``det R`` exists;
where only some Gram entries are fixed (two orthonormal columns, the third free) the
third column can lie in the plane of the first two and ``det R`` vanishes there.
"""

import sympy

from dirac.analysis.core.divisors import Division, determinant_grid, singular_loci, square_on_surface
from dirac.analysis.core.numeric import Numerics
from dirac.analysis.core.phase_space import PhaseSpace

R = sympy.Matrix(3, 3, lambda i, j: sympy.Symbol(f"R_{i + 1}{j + 1}"))
VARIABLES = list(R)
HALF = sympy.Rational(1, 2)
GRAM = R.T * R - sympy.eye(3)
#: R^T R = 1 as Lagrangian (78) writes it: halves on the diagonal
ORTHOGONAL = [sympy.expand(GRAM[i, j] * (HALF if i == j else 1)) for i in range(3) for j in range(i, 3)]
DET = sympy.expand(R.det())


def test_det_r_squared_is_one_on_the_orthogonality_surface():
    """``det(R)^2 = det(R^T R) = 1`` on ``R^T R = 1``, for ``det R`` and for ``-det R``."""
    assert square_on_surface(DET, ORTHOGONAL, VARIABLES) == 1
    assert square_on_surface(-DET, ORTHOGONAL, VARIABLES) == 1


def test_det_r_squared_on_orthonormal_rows():
    """``R R^T = 1`` fixes ``det(R R^T) = det(R)^2 = 1`` as well (the Gram matrix of the rows)."""
    rows = R * R.T - sympy.eye(3)
    assert square_on_surface(DET, [sympy.expand(rows[i, j]) for i in range(3) for j in range(i, 3)], VARIABLES) == 1


def test_scaled_columns_give_the_product_of_the_squared_lengths():
    """Columns orthogonal of squared lengths ``1, 4, 9``: ``det(R)^2 = det diag(1, 4, 9) = 36``."""
    lengths = sympy.diag(1, 4, 9)
    scaled = [sympy.expand((R.T * R - lengths)[i, j]) for i in range(3) for j in range(i, 3)]
    assert square_on_surface(DET, scaled, VARIABLES) == 36
    assert square_on_surface(5 * DET, scaled, VARIABLES) == 25 * 36


def test_a_two_by_two_rotation():
    """``a e - b c`` with ``(a, c)``, ``(b, e)`` orthonormal columns: its square is 1."""
    a, b, c, e = sympy.symbols("a b c e")
    assert determinant_grid(a * e - b * c, [a, b, c, e]) is not None
    assert square_on_surface(a * e - b * c, [a**2 + c**2 - 1, b**2 + e**2 - 1, a * b + c * e], [a, b, c, e]) == 1


def test_no_certificate_when_a_column_is_free():
    """Only the first two columns orthonormal: ``det R`` varies (0 when the third column lies in their plane)."""
    two_columns = [ORTHOGONAL[0], ORTHOGONAL[1], ORTHOGONAL[3]]
    assert square_on_surface(DET, two_columns, VARIABLES) is None


def test_not_a_determinant_is_refused():
    """A permanent (all signs +) and a sum with too few terms are no determinants of distinct variables."""
    permanent = sympy.expand(sympy.Matrix(R).per())
    assert determinant_grid(permanent, VARIABLES) is None
    assert determinant_grid(R[0, 0] * R[1, 1] * R[2, 2], VARIABLES) is None
    assert square_on_surface(permanent, ORTHOGONAL, VARIABLES) is None


def _loci(divisor, surface):
    q = VARIABLES
    space = PhaseSpace(tuple(q), tuple(sympy.Symbol(f"p_{s.name}") for s in q), ())
    numerics = Numerics(space, {}, seed=7)
    return singular_loci([Division(divisor, 1, "test division")], surface, numerics, space.variables)


def test_the_locus_of_det_r_is_kept_where_it_exists():
    """On two orthonormal columns ``det R = 0`` has points (third column in their plane): the search reports it."""
    loci = _loci(DET, [ORTHOGONAL[0], ORTHOGONAL[1], ORTHOGONAL[3]])
    assert len(loci) == 1 and loci[0].expression == DET


class _NoSearch:
    """Numerics that must not be asked: the certificate decides without sampling."""

    def surface_points(self, *args, **kwargs):
        raise AssertionError("the divisor was searched although a certificate proves it nonzero")


def test_no_locus_of_det_r_on_so3_and_no_search():
    """On ``R^T R = 1`` the certificate holds: no locus (``det R = +-1``), decided without sampling."""
    assert _loci(DET, ORTHOGONAL) == ()
    assert singular_loci([Division(DET, 1, "test division")], ORTHOGONAL, _NoSearch(), VARIABLES) == ()


def test_denominators_proven_nonzero_are_not_factored():
    """``x / (R_11^2 + R_21^2 + R_31^2)`` on unit columns: the denominator is 1 there (no factor to test);
    ``x / (R_11 det R)`` keeps ``R_11`` (it vanishes on SO(3), at a rotation about the first axis) but
    ``det R`` is settled; off the surface of the proof both are factors."""
    from dirac.analysis.core.divisors import denominator_factors, nonvanishing_on

    x = sympy.Symbol("x")
    settled = nonvanishing_on(ORTHOGONAL, VARIABLES)
    norm = R[0, 0] ** 2 + R[1, 0] ** 2 + R[2, 0] ** 2
    assert denominator_factors(x / norm, [*VARIABLES, x], settled) == []
    assert denominator_factors(x / norm, [*VARIABLES, x]) == [norm]
    assert settled(DET) and not settled(R[0, 0])
    assert denominator_factors(x / DET + x / R[0, 0], [*VARIABLES, x], settled) == [R[0, 0]]
    assert set(denominator_factors(x / DET + x / R[0, 0], [*VARIABLES, x])) == {R[0, 0], DET}
