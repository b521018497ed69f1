"""Divisors proven nonzero by sign, and the ones left open said so
(:func:`dirac.analysis.core.divisors.pfaffian`, :func:`~dirac.analysis.core.divisors.sum_of_squares_on_surface`,
:func:`~dirac.analysis.core.divisors.singular_loci`).

Hand derivations:

* ``det A = Pf(A)^2`` for antisymmetric ``A`` of even size (Cayley); for ``4 x 4``,
  ``Pf = a12 a34 - a13 a24 + a14 a23``.
* The pendulum ``L = m/2 (x'^2 + y'^2) - m g y`` with ``x^2 + y^2 = l^2`` has the second-class
  constraints ``p_lambda``, ``phi = x^2 + y^2 - l^2``, ``chi = 2 (x p_x + y p_y)/m`` and
  ``psi`` (linear in ``lambda`` with coefficient ``4 (x^2 + y^2)/m``). Their bracket matrix
  has ``C_12 = C_13 = 0``, ``C_14 = -4 (x^2 + y^2)/m``, ``C_23 = 4 (x^2 + y^2)/m``, so
  ``Pf(C) = C_14 C_23 = -16 (x^2 + y^2)^2/m^2 = -16 l^4/m^2`` on the surface: ``det C`` never
  vanishes there.
* A sum of even powers with positive coefficients is at least each of its terms; one term
  that is a nonzero constant on the surface makes it positive there.
"""

import signal

import sympy

import dirac
from dirac.analysis.core.divisors import Division, pfaffian, singular_loci, sum_of_squares_on_surface
from dirac.analysis.core.numeric import Numerics
from dirac.analysis.core.phase_space import PhaseSpace

x, y, z, m, l = sympy.symbols("x y z m l")


def test_the_pfaffian_squares_to_the_determinant():
    """``Pf(A)^2 = det A`` on generic antisymmetric matrices of sizes 2, 4 and 6, and the 4 x 4 expansion."""
    for size in (2, 4, 6):
        entries = {(i, j): sympy.Symbol(f"a{i}{j}") for i in range(size) for j in range(i + 1, size)}
        A = sympy.Matrix(size, size, [entries.get((i, j), 0) - entries.get((j, i), 0)
                                      for i in range(size) for j in range(size)])
        assert sympy.expand(pfaffian(A) ** 2 - A.det(method="berkowitz")) == 0
    a = sympy.Matrix(4, 4, lambda i, j: (sympy.Symbol(f"a{i + 1}{j + 1}") if i < j else
                                         -sympy.Symbol(f"a{j + 1}{i + 1}") if i > j else 0))
    a12, a13, a14, a23, a24, a34 = (sympy.Symbol(s) for s in ("a12", "a13", "a14", "a23", "a24", "a34"))
    assert sympy.expand(pfaffian(a) - (a12 * a34 - a13 * a24 + a14 * a23)) == 0


def test_sums_of_squares_with_a_constant_square_are_proven_nonzero():
    circle = [x**2 + y**2 - l**2]
    assert sum_of_squares_on_surface(-16 * (x**2 + y**2) ** 2 / m**2, circle, [x, y])
    assert sum_of_squares_on_surface((x**2 + y**2) ** 2 + (x * y) ** 2 + 3 * z**4, circle, [x, y, z])
    assert sum_of_squares_on_surface(z**2 + 1, circle, [x, y, z])
    # no proof where the sum can vanish on the surface, or a term can be negative
    assert not sum_of_squares_on_surface(x**2 + z**2, circle, [x, y, z])  # zero at x = z = 0, y = l
    assert not sum_of_squares_on_surface(x**2 - 1, circle, [x, y])
    assert not sum_of_squares_on_surface(x**2 + y**2 - 2 * x * y, circle, [x, y])  # (x - y)^2, zero at x = y


def test_a_short_divisor_not_found_on_the_surface_is_said_not_ruled_out():
    """``x^2 + y^2 - 2 x y = (x - y)^2`` vanishes on the circle at ``x = y = l/sqrt(2)`` (found);
    ``x^4 + y^4 + x^2 y^2 + 1`` never does and is proven; ``2 - x^2 y^2`` on the unit circle
    (``|x y| <= 1/2``) never vanishes either but has no proof here: the analysis says it is not
    ruled out instead of passing it over."""
    space = PhaseSpace((x, y), (sympy.Symbol("p_x"), sympy.Symbol("p_y")), ())
    surface = [x**2 + y**2 - 1]
    numerics = Numerics(space, {}, seed=3)
    found = [Division(sympy.expand((x - y) ** 2), 1, "the test divides by zero"),
             Division(x**4 + y**4 + x**2 * y**2 + 1, 1, "the test divides by zero"),
             Division(2 - x**2 * y**2, 1, "the test divides by zero")]
    undecided: list = []
    loci = singular_loci(found, surface, numerics, space.variables, undecided=undecided)
    assert [locus.expression for locus in loci] == [sympy.expand((x - y) ** 2)]
    assert [u.divisor for u in undecided] == [2 - x**2 * y**2]
    assert "a factor of a denominator" in str(undecided[0]) and "no proof" in str(undecided[0])


def test_the_pendulum_bracket_matrix_is_proven_regular_by_its_pfaffian():
    """No locus and nothing left open: ``Pf(C) = -16 l^4/m^2`` on the surface (module docstring)."""
    L = dirac.Lagrangian.from_strings("pendulum", ["x", "y"], "m/2*(x_dot**2 + y_dot**2) - m*g*y",
                                      ["x**2 + y**2 - l**2"], parameters={"m": 1.0, "g": 9.81, "l": 1.0})
    analysis = dirac.analyze(L)
    assert analysis.singular_loci == ()
    assert analysis.singular_loci_unsearched == ()


def test_the_bracket_divisor_is_read_off_the_pfaffian_not_a_determinant_of_expressions():
    """A random Lagrangian the long stress run drew: ``L = q3 q2'^2 + 3 q1 q2' q3'/2 + 3 q1 q3'^2/2
    - q2 q1' - 2 q1 q2 q3'``, two second-class constraints (``p1 + q2`` and its rate). Its
    report's search for the zeros of ``det C`` ran sympy's determinant of the 2 x 2 bracket
    matrix, which cancels the product of two sums of rational functions as expressions, for
    minutes. ``det C = Pf(C)^2 = C_12^2``: the locus is where the numerator of ``C_12`` in
    lowest terms vanishes, read here with the bracket written out by hand,
    ``C_12 = sum_i (d phi_1/dq_i d phi_2/dp_i - d phi_1/dp_i d phi_2/dq_i)``; no determinant of
    expressions is taken (the analysis and its loci take well under a second; the alarm turns the
    minutes the determinant took into a failure instead of a hung run)."""
    def hung(*args):
        raise AssertionError("the analysis and its singular loci took more than 120 s")

    previous = signal.signal(signal.SIGALRM, hung)
    signal.alarm(120)
    try:
        _check_the_drawn_bracket_locus()
    finally:
        signal.alarm(0)
        signal.signal(signal.SIGALRM, previous)


def _check_the_drawn_bracket_locus() -> None:
    L = dirac.Lagrangian.from_strings(
        "drawn", ["q1", "q2", "q3"],
        "(2)*q3*q2_dot*q2_dot/2 + (3)*q1*q2_dot*q3_dot/2 + (3)*q1*q3_dot*q3_dot/2 + (-1)*q2*q1_dot + (-2)*q2*q1*q3_dot", [],
    )
    analysis = dirac.analyze(L)
    assert (len(analysis.first_class), len(analysis.second_class), analysis.physical_degrees_of_freedom) == (0, 2, 2)
    q = [analysis.symbols[f"q{k}"] for k in (1, 2, 3)]
    p = [analysis.symbols[f"p_q{k}"] for k in (1, 2, 3)]
    phi1, phi2 = analysis.second_class
    assert sympy.expand(phi1 - (p[0] + q[1])) == 0
    c12 = sum(sympy.diff(phi1, a) * sympy.diff(phi2, b) - sympy.diff(phi1, b) * sympy.diff(phi2, a) for a, b in zip(q, p))
    numerator = sympy.fraction(sympy.together(c12))[0]
    bracket = [locus for locus in analysis.singular_loci if "the Dirac bracket divides by zero" in locus.what]
    multipliers = [locus for locus in analysis.singular_loci if "multiplier" in locus.what]
    # the bracket's locus is the multipliers' (u_1 = -{phi_1, H_c}/C_12): one locus, a factor of C_12's numerator
    loci = bracket or multipliers
    assert len(loci) == 1
    assert sympy.rem(sympy.expand(numerator), loci[0].expression, *q, *p) == 0
