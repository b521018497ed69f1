"""Gram-type divisors proven nonzero by the Cauchy–Binet formula, and the ones that are not
(:class:`dirac.analysis.core.gram_proof.GramProver`).

Hand derivations:

* Cartesian double pendulum, ``r1 = (x1, y1)``, ``d = r2 - r1``, constraints
  ``chi_1 = |r1|^2 - l1^2``, ``chi_2 = |d|^2 - l2^2``, ``W = diag(1/m1, 1/m1, 1/m2, 1/m2)``:
  ``J = [[2 x1, 2 y1, 0, 0], [-2 dx, -2 dy, 2 dx, 2 dy]]`` and ``G = J W J^T`` has
  ``G11 = 4 |r1|^2/m1``, ``G12 = -4 (r1 . d)/m1``, ``G22 = 4 |d|^2 (1/m1 + 1/m2)``. The
  multiplier solution divides by the Schur complement ``G22 - G12^2/G11``, whose numerator
  is ``det G = 16/m1^2 (|r1|^2 |d|^2 - (r1 . d)^2) + 16 |r1|^2 |d|^2/(m1 m2)``
  ``= 16/m1^2 (x1 dy - y1 dx)^2 + 16 l1^2 l2^2/(m1 m2)`` on the surface (Lagrange's identity):
  positive for positive masses. For masses of unknown sign ``m1 m2 < 0`` lets it vanish:
  at ``m1 = 1, m2 = -1`` with ``r1`` perpendicular to ``d``, ``(x1 dy - y1 dx)^2 = l1^2 l2^2`` and
  ``det G = 16 l1^2 l2^2 (1 - 1) = 0``; so no proof may be claimed. With one mass ``m`` for both
  bobs (``m1 = m2 = m``) ``det G = 16/m^2 ((x1 dy - y1 dx)^2 + |r1|^2 |d|^2) >= 16 l1^2 l2^2/m^2``
  whatever the sign of ``m``: all weights are ``1/m^2``.
* Viviani's curve, a particle of mass ``m`` on the sphere ``x^2 + y^2 + z^2 = 1`` and the
  cylinder ``x^2 + y^2 = x``, ``W = 1/m``: ``det G = |grad chi_1 x grad chi_2|^2 / m^2`` with
  ``grad chi_1 x grad chi_2 = (-4 y z, 2 z (2 x - 1), 2 y)``, zero at ``(1, 0, 0)``, a point of
  both surfaces where the curve crosses itself: the Gram determinant vanishes there and must
  not be proven nonzero.
* A bead of mass ``m`` on a hoop of radius ``R`` turning as ``-x sin(w t) + y cos(w t) = 0``:
  the one-row minor of the sphere ``x^2 + y^2 + z^2 = R^2`` is ``|grad chi_1|^2/m = 4 (x^2 + y^2 + z^2)/m``,
  ``= 4 R^2/m`` on the surface whatever the turning constraint (which holds ``sin(w t)``).
"""

import sympy

import dirac
from dirac.analysis.core.divisors import Division, singular_loci
from dirac.analysis.core.gram_proof import GramProver
from dirac.analysis.core.numeric import Numerics
from dirac.analysis.core.phase_space import PhaseSpace

x1, y1, x2, y2, x, y, z = sympy.symbols("x1 y1 x2 y2 x y z", real=True)
px1, py1, px2, py2, px, py, pz = sympy.symbols("p_x1 p_y1 p_x2 p_y2 p_x p_y p_z", real=True)
l1, l2 = sympy.symbols("l1 l2", real=True)


def _double_pendulum(m1: sympy.Symbol, m2: sympy.Symbol):
    """``(prover, Schur complement, surface)`` of the double pendulum with masses ``m1``, ``m2`` (module docstring)."""
    chi = [x1**2 + y1**2 - l1**2, (x2 - x1) ** 2 + (y2 - y1) ** 2 - l2**2]
    H = (px1**2 + py1**2) / (2 * m1) + (px2**2 + py2**2) / (2 * m2)
    variables = (x1, y1, x2, y2, px1, py1, px2, py2)
    prover = GramProver.from_hamiltonian(H, (x1, y1, x2, y2), (px1, py1, px2, py2), chi, variables)
    dx, dy = x2 - x1, y2 - y1
    g11 = 4 * (x1**2 + y1**2) / m1
    g12 = -4 * (x1 * dx + y1 * dy) / m1
    g22 = 4 * (dx**2 + dy**2) * (1 / m1 + 1 / m2)
    return prover, sympy.expand(g22) - sympy.expand(g12) ** 2 / sympy.expand(g11), chi


def test_the_double_pendulum_schur_complement_is_proven_for_positive_masses():
    """``det G >= 16 l1^2 l2^2/(m1 m2) > 0`` on the surface (module docstring)."""
    m1, m2 = sympy.symbols("m1 m2", positive=True)
    prover, schur, _ = _double_pendulum(m1, m2)
    assert prover is not None
    verdict = prover(schur)
    assert verdict is not None and verdict.proven


def test_masses_of_unknown_sign_prove_nothing():
    """With ``m1 m2 < 0`` the Gram determinant can vanish on the surface (module docstring): no proof, and the
    reason names the weights whose sign is unknown."""
    m1, m2 = sympy.symbols("m1 m2", real=True)
    prover, schur, _ = _double_pendulum(m1, m2)
    assert prover is not None
    verdict = prover(schur)
    assert verdict is not None and not verdict.proven
    assert "not known to have one sign" in verdict.reason and "1/(m1*m2)" in verdict.reason
    # numbers of opposite signs: the weight 1/(m1 m2) = -1 is negative, and no proof either
    prover, schur, _ = _double_pendulum(sympy.Integer(1), sympy.Integer(-1))
    assert prover is not None
    verdict = prover(schur)
    assert verdict is not None and not verdict.proven


def test_one_mass_of_unknown_sign_is_one_weight_and_proves():
    """``m1 = m2 = m`` real: one weight ``1/m^2``, whose sign does not matter (module docstring)."""
    m = sympy.Symbol("m", real=True)
    prover, schur, _ = _double_pendulum(m, m)
    assert prover is not None
    verdict = prover(schur)
    assert verdict is not None and verdict.proven


def test_the_built_in_double_pendulum_leaves_no_division_open():
    """Its masses are declared positive: the Schur complement is proven, so nothing is said not ruled out."""
    analysis = dirac.analyze(dirac.load_system("double_pendulum"))
    assert analysis.singular_loci == ()
    assert analysis.singular_loci_unsearched == ()


def test_the_double_pendulum_with_masses_of_unknown_sign_stays_not_ruled_out():
    L = dirac.Lagrangian.from_strings(
        "double_pendulum", ["x1", "y1", "x2", "y2"],
        "m1/2*(x1_dot**2 + y1_dot**2) + m2/2*(x2_dot**2 + y2_dot**2) - g*(m1*y1 + m2*y2)",
        ["x1**2 + y1**2 - l1**2", "(x2 - x1)**2 + (y2 - y1)**2 - l2**2"],
        parameters={"m1": 1.0, "m2": 1.0, "g": 9.81, "l1": 1.0, "l2": 1.0})
    analysis = dirac.analyze(L)
    [open_] = analysis.singular_loci_unsearched
    assert "not ruled out" in str(open_) and "not known to have one sign" in str(open_)


def test_a_gram_determinant_that_vanishes_on_the_surface_is_never_proven():
    """Viviani's curve: ``det(J W J^T)`` vanishes at ``(1, 0, 0)`` (module docstring): the rule finds no
    group constant on the surface, and the search finds the locus or says it is not ruled out."""
    m = sympy.Symbol("m", positive=True)
    chi = [x**2 + y**2 + z**2 - 1, x**2 + y**2 - x]
    H = (px**2 + py**2 + pz**2) / (2 * m)
    space = PhaseSpace((x, y, z), (px, py, pz), (m,))
    prover = GramProver.from_hamiltonian(H, space.coordinates, space.momenta, chi, space.variables)
    assert prover is not None
    J = sympy.Matrix([[sympy.diff(c, v) for v in (x, y, z)] for c in chi])
    G = J * J.T / m
    det = sympy.expand(G.det())
    cross = sympy.Matrix([-4 * y * z, 2 * z * (2 * x - 1), 2 * y])
    assert sympy.expand(det - (cross.T * cross)[0] / m**2) == 0  # Lagrange's identity, by hand
    assert det.subs({x: 1, y: 0, z: 0}) == 0 and all(c.subs({x: 1, y: 0, z: 0}) == 0 for c in chi)
    for divisor in (det, sympy.expand(G[1, 1]) - sympy.expand(G[0, 1]) ** 2 / sympy.expand(G[0, 0])):
        verdict = prover(divisor)
        assert verdict is not None and not verdict.proven
    undecided: list = []
    loci = singular_loci([Division(det, 4, "the test divides by zero")], chi, Numerics(space, {m: 1.3}, seed=5),
                         space.variables, undecided=undecided, gram=prover)
    assert len(loci) + len(undecided) == 1  # a locus, or not ruled out: never passed over as proven


def test_a_divisor_that_is_no_gram_minor_is_not_recognised_and_the_budget_is_kept():
    m1, m2 = sympy.symbols("m1 m2", positive=True)
    prover, schur, chi = _double_pendulum(m1, m2)
    assert prover is not None and prover(x1**2 - 2 * y1) is None  # no constant multiple of a principal minor
    spent = GramProver.from_hamiltonian(
        (px1**2 + py1**2) / (2 * m1) + (px2**2 + py2**2) / (2 * m2), (x1, y1, x2, y2), (px1, py1, px2, py2), chi,
        (x1, y1, x2, y2, px1, py1, px2, py2), budget=0.0)
    assert spent is not None
    verdict = spent(schur)
    assert verdict is not None and not verdict.proven and "budget" in verdict.reason


def test_a_one_row_minor_beside_a_turning_constraint_is_proven():
    """The bead on the turning hoop (module docstring): the divisor ``x^2 + y^2 + z^2`` is ``R^2`` on the surface."""
    m, R, w, t = sympy.symbols("m R w t", real=True)
    chi = [x**2 + y**2 + z**2 - R**2, -x * sympy.sin(w * t) + y * sympy.cos(w * t)]
    H = (px**2 + py**2 + pz**2) / (2 * m) + m * 9 * z
    prover = GramProver.from_hamiltonian(H, (x, y, z), (px, py, pz), chi, (x, y, z, px, py, pz))
    assert prover is not None
    verdict = prover(x**2 + y**2 + z**2)
    assert verdict is not None and verdict.proven
    verdict = prover(x**2 + y**2)  # the cylinder's |grad|^2 is no principal minor here: not recognised
    assert verdict is None


def test_the_momentum_hessian_is_the_hand_one_from_sympy_and_from_the_cached_partials():
    """``H = p1^2/(2 m) + p1 p2/k + q^2 p2^2/2 + g q`` (``p3`` absent): by hand ``W = [[1/m, 1/k], [1/k, q^2]]``
    over the momenta ``H`` holds (``p1``, ``p2``), whether the derivatives come from ``sympy.diff`` or from a
    phase space's cache (``PhaseSpace.partials``, keyed by the coordinate)."""
    from dirac.analysis.core.gram_proof import _momentum_hessian

    q1, q2, q3, p1, p2, p3, m, k, g = sympy.symbols("q1 q2 q3 p1 p2 p3 m k g")
    H = p1**2 / (2 * m) + p1 * p2 / k + q1**2 * p2**2 / 2 + g * q1
    by_hand = sympy.Matrix([[1 / m, 1 / k], [1 / k, q1**2]])
    space = PhaseSpace((q1, q2, q3), (p1, p2, p3), (m, k, g))
    for partials in (None, space.partials):
        used, W = _momentum_hessian(H, (q1, q2, q3), (p1, p2, p3), partials)
        assert used == [0, 1]
        assert (W - by_hand).applyfunc(sympy.simplify) == sympy.zeros(2, 2)


def test_the_prover_built_from_the_cached_partials_proves_the_same():
    """The double pendulum's Schur complement (module docstring) with the derivatives read from a phase space."""
    m1, m2 = sympy.symbols("m1 m2", positive=True)
    _, schur, chi = _double_pendulum(m1, m2)
    space = PhaseSpace((x1, y1, x2, y2), (px1, py1, px2, py2), (m1, m2, l1, l2))
    H = (px1**2 + py1**2) / (2 * m1) + (px2**2 + py2**2) / (2 * m2)
    prover = GramProver.from_hamiltonian(H, space.coordinates, space.momenta, chi, space.variables,
                                         partials=space.partials)
    assert prover is not None
    verdict = prover(schur)
    assert verdict is not None and verdict.proven
    assert prover(x1**2 - 2 * y1) is None


def test_building_the_prover_counts_in_its_budget():
    """A prover whose budget is spent before it is built says so for every divisor (it never proves)."""
    m1, m2 = sympy.symbols("m1 m2", positive=True)
    _, schur, chi = _double_pendulum(m1, m2)
    H = (px1**2 + py1**2) / (2 * m1) + (px2**2 + py2**2) / (2 * m2)
    prove = GramProver.on_first_use(H, (x1, y1, x2, y2), (px1, py1, px2, py2), chi,
                                    (x1, y1, x2, y2, px1, py1, px2, py2), budget=0.0)
    for _ in range(2):
        verdict = prove(schur)
        assert verdict is not None and not verdict.proven and "budget" in verdict.reason
