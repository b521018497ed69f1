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

"~ 0" is ``|value| <= 1e-7 (1 + sum of |terms|)`` at the point: a value that is not
round-off of the terms that cancelled is a violation.
"""

from __future__ import annotations

import warnings

import numpy as np
import pytest
import sympy
from hypothesis import HealthCheck, given, settings
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


def _analyse(text: str, tmp_path_factory):
    path = tmp_path_factory.mktemp("random") / "system.toml"
    path.write_text(text)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        try:
            return dirac.analyze(dirac.load_system(str(path)))
        except DiracError:
            return None


def _check(text: str, tmp_path_factory) -> None:
    analysis = _analyse(text, tmp_path_factory)
    if analysis is None:
        return
    for part in analysis.components or [None]:
        target = analysis if part is None else part.analysis
        if target is None:
            continue
        problems = check_invariants(target)
        assert problems == [], text + "\n" + "\n".join(problems)


@settings(max_examples=10, deadline=None, suppress_health_check=[HealthCheck.function_scoped_fixture, HealthCheck.too_slow])
@given(text=systems())
def test_random_lagrangians_keep_the_invariants(text, tmp_path_factory):
    _check(text, tmp_path_factory)


@pytest.mark.slow
@settings(max_examples=max(5, int(500 * stress_scale())), deadline=None, suppress_health_check=[HealthCheck.function_scoped_fixture, HealthCheck.too_slow])
@given(text=systems())
def test_random_lagrangians_keep_the_invariants_long(text, tmp_path_factory):
    _check(text, tmp_path_factory)


def test_the_invariant_check_sees_a_wrong_class():
    """The check can fail: a pendulum whose first class is claimed for a second-class constraint."""
    a = dirac.analyze(dirac.load_system("pendulum", m=1.0, g=9.81, l=1.0))
    a.first_class = [a.second_class[1]]
    assert any("does not commute weakly" in p for p in check_invariants(a))
