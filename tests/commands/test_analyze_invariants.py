"""Invariants of every accepted analysis of a random small polynomial Lagrangian.

The Lagrangians are those of ``test_analyze_never_traceback.py``. Where the analysis is
accepted, at its sample points of the constraint surface (Henneaux & Teitelboim,
*Quantization of Gauge Systems*, 1992, ch. 1; Dirac, *Lectures on Quantum Mechanics*, 1964):

* the second-class block ``C_ab = {Phi_a, Phi_b}`` is invertible (its smallest singular
  value is not round-off relative to its largest entry);
* first-class constraints commute weakly with every constraint: ``{F, Phi_a} ~ 0``;
* the total Hamiltonian with the solved multipliers, ``H' = H_c + U_k phi_k`` (free
  ``v_a = 0``, and also with each null vector added), keeps the motion on the surface:
  ``{Phi_a, H'} + d_t Phi_a ~ 0``;
* the Dirac bracket kills the second-class constraints: ``{Phi_a, z}_D ~ 0`` for every
  phase-space variable ``z``;
* the Dirac bracket satisfies the Jacobi identity on the first three phase-space variables
  (for systems without first-class constraints and at most 4 second-class ones, whose
  exact brackets are simplified modulo second-class constraints only).

* the chain adds no spurious constraint and loses no branch (:func:`chain_violations`): at a
  regular point of the surface of stages ``1..s`` (the consistency matrix ``{Phi_a, phi_k}``
  has its generic rank there) where the consistency conditions ``b + A u = 0`` can be solved,
  every constraint of stage ``s + 1`` vanishes. Points are sampled on the surface of stages
  ``1..s`` and on the zero sets there of every divisor the analysis recorded (where a
  division may have lost a branch: ``z (1 - 2 y) = 0`` reported as ``z = 0``).

"~ 0" is ``|value| <= 1e-7 (1 + sum of |terms|)`` at the point: a value that is not
round-off of the terms that cancelled is a violation.
"""

from __future__ import annotations

import warnings

import numpy as np
import pytest
import sympy
from hypothesis import HealthCheck, event, given, settings
from stress_scaling import stress_scale
from test_analyze_never_traceback import systems

import dirac
from dirac.errors import DiracError

WEAK = 1e-7


def _weakly_zero(analysis, exprs, points) -> list[tuple[str, float]]:
    """``(expression, value)`` of every expression that is not weakly zero at some point."""
    exprs = [sympy.sympify(e) for e in exprs]
    if not exprs:
        return []
    numerics = analysis._numerics
    values = numerics.evaluate(exprs, points)
    scales = numerics.term_scale(exprs, points)
    bad = []
    for v, s in zip(values, scales):
        for e, x, sc in zip(exprs, v, s):
            if np.isfinite(x) and abs(x) > WEAK * sc:
                bad.append((str(e), float(x)))
    return bad


def check_invariants(analysis) -> list[str]:
    """Violations of the invariants (module docstring) at the analysis's sample points."""
    space = analysis._space
    points = list(analysis._points)
    time = analysis.time
    problems: list[str] = []
    constraints = list(analysis.constraints)
    second = list(analysis.second_class)
    if second:
        C = sympy.Matrix([[space.poisson_bracket(a, b) for b in second] for a in second])
        values = analysis._numerics.evaluate(list(C), points).reshape(len(points), len(second), len(second))
        for v in values:
            sv = np.linalg.svd(v, compute_uv=False)
            if sv[-1] <= 1e-9 * (1.0 + np.max(np.abs(v))):
                problems.append(f"C on the second class is singular at a surface point (singular values {sv})")
    for f in analysis.first_class:
        for bad in _weakly_zero(analysis, [space.poisson_bracket(f, c) for c in constraints], points):
            problems.append(f"first-class {f} does not commute weakly with a constraint: {bad}")
    solution = analysis.multiplier_solution
    hamiltonians = [solution.first_class_hamiltonian]
    for vec in solution.null_vectors:
        hamiltonians.append(hamiltonians[0] + sum((vec[u.name] * phi for u, phi in zip(solution.multipliers, solution.primary)), sympy.S.Zero))
    for H in hamiltonians:
        rates = [space.poisson_bracket(c, H) + (sympy.diff(c, time) if time is not None else 0) for c in constraints]
        for bad in _weakly_zero(analysis, rates, points):
            problems.append(f"H_T with the solved multipliers is not tangent to the surface: {bad}")
    if second:
        for z in points[:2]:
            at = {s.name: float(x) for s, x in zip(space.variables, z)}
            if time is not None:
                continue  # the numeric bracket needs t; skipped for time-dependent systems
            for a in second:
                for var in space.variables:
                    value = analysis.dirac_bracket(a, var, at=at)
                    if abs(value) > 1e-6 * (1.0 + max(abs(x) for x in z)):
                        problems.append(f"{{{a}, {var}}}_D = {value} at a surface point, not 0")
    if second and not analysis.first_class and len(second) <= 4 and time is None and len(space.variables) >= 3:
        # Jacobi identity of the Dirac bracket on three phase-space variables. Without first-class
        # constraints the exact brackets are simplified modulo second-class constraints only, which
        # the Dirac bracket kills, so the nested brackets are weakly those of the unsimplified ones.
        x, y, z = space.variables[:3]
        db = analysis.dirac_bracket
        jacobi = db(x, db(y, z)) + db(y, db(z, x)) + db(z, db(x, y))
        for bad in _weakly_zero(analysis, [jacobi], points):
            problems.append(f"the Dirac bracket violates the Jacobi identity on {x}, {y}, {z}: {bad}")
    return problems


#: points sampled per surface (the generic one and each divisor's zero set) by the chain invariant
CHAIN_POINTS = 3


def _solvable(b: np.ndarray, A: np.ndarray) -> bool:
    """``rank [A | b] == rank A`` relative to the size of the entries."""
    from dirac.analysis.core.numeric import numeric_rank

    augmented = np.hstack([A, b[:, None]])
    scale = np.max(np.abs(augmented)) or 1.0  # one scale for both: round-off in A is no rank
    return numeric_rank(augmented / scale) == numeric_rank(A / scale, scale=1.0)


def _off_poles(numerics, poles, points) -> list:
    """The points where no divisor in ``poles`` is round-off of its terms (``|f| > 1e-8 * term scale``)."""
    if not poles or not points:
        return list(points)
    values = np.abs(numerics.evaluate(poles, points))
    scales = numerics.term_scale(poles, points)
    return [z for z, v, sc in zip(points, values, scales) if np.all(v > 1e-8 * sc)]


def chain_violations(analysis) -> list[str]:
    """Stage ``s + 1`` constraints that do not vanish at a regular solvable point of stages ``1..s`` (module docstring)."""
    from dirac.analysis.core.numeric import numeric_rank

    chain = analysis._chain
    if analysis.reducible_constraints or chain.imposed or len(analysis.stages) < 1:
        return []  # reducible sets: a stage's surface is not its kept constraints alone
    from dirac.analysis.core.divisors import LEGENDRE_SINGULAR

    numerics = analysis._numerics
    # On a locus where the Legendre map is singular H_c has a pole: the consistency conditions
    # b + A u = 0 are not defined there (the analysis reports the locus and holds off it), and
    # their value at a sampled point is the round-off of cancelling 1/divisor terms. Those zero
    # sets are not sampled, and points of the other zero sets lying on them are no regular points.
    poles = [locus.expression for locus in analysis.singular_loci if locus.what == LEGENDRE_SINGULAR]
    divisors = [d.divisor for d in chain.divisions] + [
        locus.expression for locus in analysis.singular_loci if locus.what != LEGENDRE_SINGULAR
    ]
    problems = []
    stages = list(analysis.stages)
    for s in range(1, len(stages) + 1):
        surface = [c for stage in stages[:s] for c in stage]
        following = stages[s] if s < len(stages) else []
        try:
            generic = _off_poles(numerics, poles, numerics.surface_points(surface, CHAIN_POINTS, regular=len(surface)))
        except DiracError:
            continue
        generic_rows = [A for A in chain._numeric_rows(surface, generic)[1] if np.all(np.isfinite(A))]
        if not generic_rows:
            continue
        rank = max(numeric_rank(A, scale=float(np.max(np.abs(A), initial=0.0))) for A in generic_rows)
        points = list(generic)
        for f in dict.fromkeys(divisors):
            try:
                points += _off_poles(
                    numerics, poles, numerics.surface_points([*surface, f], CHAIN_POINTS, regular=len(surface), attempts=12)
                )
            except DiracError:
                continue
        b_num, A_num = chain._numeric_rows(surface, points)
        sizes = [max(np.max(np.abs(A), initial=0.0), np.max(np.abs(b), initial=0.0)) for b, A in zip(b_num, A_num)]
        typical = float(np.median(sizes[: len(generic)])) or 1.0
        for z, b, A, size in zip(points, b_num, A_num, sizes):
            if not (np.all(np.isfinite(A)) and np.all(np.isfinite(b))) or size > 1e6 * typical:
                continue  # on (or next to) the zero set of a divisor of H_c or of the constraints: no regular point
            if numeric_rank(A / size if size else A, scale=1.0) != rank or not _solvable(b, A):
                continue
            if not following:
                continue
            values = numerics.evaluate(list(following), [z])[0]
            scales = numerics.term_scale(list(following), [z])[0]
            for c, v, sc in zip(following, values, scales):
                if np.isfinite(v) and abs(v) > 1e-6 * sc:
                    problems.append(f"at a regular point of stages 1..{s} where the consistency conditions can be "
                                    f"solved, the stage-{s + 1} constraint {c} = {v:.3g}, not 0 (a spurious constraint or a lost branch)")
    return problems


def _analyse(text: str, tmp_path_factory):
    path = tmp_path_factory.mktemp("random") / "system.toml"
    path.write_text(text)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        try:
            analysis = dirac.analyze(dirac.load_system(str(path)))
        except DiracError as error:
            event(f"refused: {type(error).__name__}")
            return None
    event("components" if analysis.components else "analysed")
    return analysis


def _check(text: str, tmp_path_factory) -> None:
    analysis = _analyse(text, tmp_path_factory)
    if analysis is None:
        return
    for part in analysis.components or [None]:
        target = analysis if part is None else part.analysis
        if target is None:
            continue
        problems = check_invariants(target) + chain_violations(target)
        assert problems == [], text + "\n" + "\n".join(problems)


@settings(max_examples=10, deadline=None, suppress_health_check=[HealthCheck.function_scoped_fixture, HealthCheck.too_slow])
@given(text=systems())
def test_random_lagrangians_keep_the_invariants(text, tmp_path_factory):
    _check(text, tmp_path_factory)


@pytest.mark.slow
@settings(max_examples=max(5, int(1000 * stress_scale())), deadline=None, suppress_health_check=[HealthCheck.function_scoped_fixture, HealthCheck.too_slow])
@given(text=systems())
def test_random_lagrangians_keep_the_invariants_long(text, tmp_path_factory):
    _check(text, tmp_path_factory)


def test_the_chain_invariant_sees_a_lost_branch():
    """The check can fail: ``L = x x' z + x z - 2 x' z^2/3 + 2 y y' z + y z'`` (hand derivation in
    tests/analysis/chain/test_divisions.py) analysed with stage 2 cut to ``z = 0``, as the chain
    gave it when it divided by ``1 - 2 y``: at points with ``y = 1/2`` and ``z != 0`` the
    consistency conditions can be solved (``F_yz = 1 - 2 y`` vanishes there) but ``z != 0``."""
    L = dirac.Lagrangian.from_strings("lost", ["x", "y", "z"], "x*x_dot*z + x*z - 2*x_dot*z**2/3 + 2*y*y_dot*z + y*z_dot", [])
    a = dirac.analyze(L, assume=["1 - 2*y != 0"])
    assert chain_violations(a) == []
    a._numerics.avoid = []  # the branch y = 1/2 is no longer set aside
    from dirac.analysis.core.divisors import Division

    y = a.symbols["y"]
    a._chain.divisions.append(Division(1 - 2 * y, 2, "the elimination of multipliers divides by zero"))
    assert any("stage-2 constraint z" in p for p in chain_violations(a))


def test_the_invariant_check_sees_a_wrong_class():
    """The check can fail: a pendulum whose first class is claimed for a second-class constraint."""
    a = dirac.analyze(dirac.load_system("pendulum", m=1.0, g=9.81, l=1.0))
    a.first_class = [a.second_class[1]]
    assert any("does not commute weakly" in p for p in check_invariants(a))


def test_the_chain_invariant_keeps_off_the_poles_of_the_canonical_hamiltonian():
    """A random Lagrangian the long run drew: ``L = q2 q1' q2'/2 - q2 q2' q3'/2 - 2 q2 q3 q1' - q3^2 q2'``.

    By hand: ``p1 = q2 q2'/2 - 2 q2 q3``, ``p2 = q2 (q1' - q3')/2 - q3^2``, ``p3 = -q2 q2'/2``, so
    ``phi = p1 + p3 + 2 q2 q3 = 0`` is primary and, where ``q2 != 0``, ``q2' = -2 p3/q2``,
    ``q1' - q3' = 2 (p2 + q3^2)/q2`` and ``H_c = 2 (p1 + 2 q2 q3)(p2 + q3^2)/q2`` (the quadratic part
    ``q2 q2' (q1' - q3')/2`` in momenta, ``p3 = -p1 - 2 q2 q3`` on the surface). Then
    ``{phi, H_c} = 2 q3 dH/dp2 - dH/dq3 = -4 (p2 + q3^2)`` exactly (the ``4 q3 (p1 + 2 q2 q3)/q2`` terms
    cancel), the secondary constraint. On ``q2 = 0`` (the rank of the Hessian drops from 2 to 0, which
    the analysis reports as a singular locus) ``H_c`` has a pole, and a point sampled there gave
    ``b = 0`` from cancelling round-off while ``p2 + q3^2 != 0``: the chain invariant must not count it.
    """
    L = dirac.Lagrangian.from_strings(
        "drawn", ["q1", "q2", "q3"], "q2*q1_dot*q2_dot/2 - q2*q2_dot*q3_dot/2 - 2*q2*q3*q1_dot - q3**2*q2_dot", []
    )
    a = dirac.analyze(L)
    q1, q2, q3, p1, p2, p3 = a._space.variables
    (primary,), (secondary,) = a.stages
    assert sympy.simplify(primary - (p1 + p3 + 2 * q2 * q3)) == 0
    assert sympy.simplify(secondary / (p2 + q3**2)).is_constant()
    assert [locus.expression for locus in a.singular_loci] == [q2]
    assert chain_violations(a) == []
    assert check_invariants(a) == []
