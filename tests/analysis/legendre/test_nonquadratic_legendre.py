"""Legendre transform of Lagrangians that are not quadratic in the velocities.

Hand derivations (momenta ``p = dL/dq_dot``, ``{q, p} = 1``, ``H_c = v.p - L``):

- Square-root relativistic particle ``L = -m sqrt(t_dot^2 - x_dot^2 - y_dot^2)``, ``s`` the
  root: ``p_t = -m t_dot/s``, ``p_x = m x_dot/s``, ``p_y = m y_dot/s``, so
  ``p_t^2 - p_x^2 - p_y^2 = m^2 (t_dot^2 - x_dot^2 - y_dot^2)/s^2 = m^2``: one primary
  constraint (the mass shell). ``L`` is homogeneous of degree one, so ``W q_dot = 0``
  (rank 2 of 3) and ``v.p - L = -m s^2/s + m s = 0`` (Euler): ``H_c = 0``,
  ``H_T = u phi``. ``{phi, phi} = 0``: no secondary constraint, ``phi`` first class, ``u``
  undetermined (reparametrisations are gauge), ``(6 - 2*1 - 0)/2 = 2`` degrees of freedom.
- Regular relativistic particle ``L = -m sqrt(1 - x_dot^2)``: ``p = m v/sqrt(1 - v^2)``,
  ``v = p/sqrt(p^2 + m^2)`` (``m > 0``), ``H = p v + m sqrt(1 - v^2) = sqrt(p^2 + m^2)``;
  for ``m = -1`` (``L = +sqrt(1 - v^2)``) the branch is ``v = -p/sqrt(p^2 + 1)`` and
  ``H = -sqrt(p^2 + 1)``.
- ``L = sqrt(x_dot^2 + y_dot^2) - (x^2 + y^2)/2``: ``p = v/|v|``, primary
  ``phi = p_x^2 + p_y^2 - 1``; ``L + V`` is homogeneous of degree one, so ``H_c = V``.
  ``{phi, V} = -2 (x p_x + y p_y)``: secondary ``chi = x p_x + y p_y``;
  ``{chi, H_T} = -(x^2 + y^2) + u {chi, phi} = -(x^2 + y^2) + 2 u (p_x^2 + p_y^2)`` fixes
  ``u = (x^2 + y^2)/2`` on the surface; ``{phi, chi} = -2 != 0``: both second class,
  ``(4 - 2)/2 = 1`` degree of freedom.
- ``L = -sqrt(1 - (x_dot - y_dot)^2) - x^2/2``, ``s = x_dot - y_dot``: ``p_x = s/sqrt(1 - s^2)
  = -p_y``, primary ``p_x + p_y = 0``; the velocity part is not homogeneous:
  ``v.p - L_v = s^2/sqrt(1 - s^2) + sqrt(1 - s^2) = 1/sqrt(1 - s^2) = sqrt(1 + p_x^2)``, so
  ``H_c = sqrt(1 + p_x^2) + x^2/2`` on the surface. ``{p_x + p_y, H_c} = -x``: secondary
  ``x = 0``; ``{x, H_T} = u`` fixes ``u = 0``; ``{p_x + p_y, x} = -1``: both second class,
  ``(4 - 2)/2 = 1`` degree of freedom.
"""

from __future__ import annotations

import signal

import numpy as np
import pytest
import sympy

import dirac
from dirac.analysis.legendre.velocity_elimination import eliminate_velocities
from dirac.model.lagrangian import Lagrangian


def _symbols(analysis, *names):
    return [analysis.symbols[n] if n in analysis.symbols else analysis.lagrangian.parameter_symbols[n] for n in names]


def test_square_root_relativistic_particle():
    particle = Lagrangian.from_strings(
        "relativistic_sqrt", ["t", "x", "y"], "-m*sqrt(t_dot**2 - x_dot**2 - y_dot**2)", parameters={"m": 1.0}
    )
    a = dirac.analyze(particle)
    p_t, p_x, p_y, m = _symbols(a, "p_t", "p_x", "p_y", "m")
    assert a.hessian_rank == 2
    assert a.canonical_hamiltonian == 0
    assert [len(stage) for stage in a.stages] == [1]
    (phi,) = a.primary_constraints
    ratio = sympy.simplify(phi / (p_t**2 - p_x**2 - p_y**2 - m**2))
    assert ratio.is_number and ratio != 0
    assert len(a.first_class) == 1 and a.second_class == []
    assert [u.name for u in a.undetermined_multipliers] == ["u_1"]
    assert a.physical_degrees_of_freedom == 2
    assert "homogeneous of degree one" in " ".join(a.notes)


def test_mass_shell_holds_at_the_momenta_of_a_physical_velocity():
    """Sign convention p = dL/dq_dot: t_dot = 2, x_dot = 1, y_dot = 1/2, m = 3 gives
    s = sqrt(11)/2, p_t = -12/sqrt(11), p_x = 6/sqrt(11), p_y = 3/sqrt(11), and
    p_t^2 - p_x^2 - p_y^2 = (144 - 36 - 9)/11 = 9 = m^2."""
    particle = Lagrangian.from_strings(
        "relativistic_sqrt", ["t", "x", "y"], "-m*sqrt(t_dot**2 - x_dot**2 - y_dot**2)", parameters={"m": 3.0}
    ).with_defaults()
    a = dirac.analyze(particle)
    p_t, p_x, p_y = _symbols(a, "p_t", "p_x", "p_y")
    r = sympy.sqrt(11)
    at = {p_t: -12 / r, p_x: 6 / r, p_y: 3 / r}
    assert sympy.simplify(a.primary_constraints[0].subs(at)) == 0
    assert sympy.simplify(a.primary_constraints[0].subs({**at, p_t: 12 / r})) == 0  # the other sheet too


def test_regular_relativistic_particle_has_h_sqrt_p2_m2():
    free = Lagrangian.from_strings("relativistic_1d", ["x"], "-m*sqrt(1 - x_dot**2)", parameters={"m": 1.0})
    a = dirac.analyze(free)
    p, m = _symbols(a, "p_x", "m")
    assert a.hessian_rank == 1 and a.stages == []
    assert sympy.simplify(a.canonical_hamiltonian - sympy.sqrt(p**2 + m**2)) == 0
    assert a.physical_degrees_of_freedom == 1
    v = a._legendre.velocity_solution[free.velocities[0]]
    assert sympy.simplify(v - p / sympy.sqrt(p**2 + m**2)) == 0


def test_regular_branch_follows_the_sign_of_a_fixed_parameter():
    flipped = Lagrangian.from_strings("flipped", ["x"], "-m*sqrt(1 - x_dot**2)", parameters={"m": -1.0}).with_defaults()
    a = dirac.analyze(flipped)
    (p,) = _symbols(a, "p_x")
    assert sympy.simplify(a.canonical_hamiltonian + sympy.sqrt(p**2 + 1)) == 0


def test_regular_relativistic_particle_on_a_ring():
    """With x^2 + y^2 = 1 (multiplier lambda_1) the chain is the pendulum's: p_lambda_1, the
    circle, its velocity x p_x + y p_y = 0 (over sqrt(p^2 + m^2)), and the equation fixing
    lambda_1; all four are second class, one degree of freedom."""
    ring = Lagrangian.from_strings(
        "ring", ["x", "y"], "-m*sqrt(1 - x_dot**2 - y_dot**2)", ["x**2 + y**2 - 1"], parameters={"m": 1.0}
    )
    a = dirac.analyze(ring)
    x, y, p_x, p_y, lam, m = _symbols(a, "x", "y", "p_x", "p_y", "lambda_1", "m")
    assert sympy.simplify(a.canonical_hamiltonian - sympy.sqrt(m**2 + p_x**2 + p_y**2) - lam * (x**2 + y**2 - 1)) == 0
    assert [len(stage) for stage in a.stages] == [1, 1, 1, 1]
    (third,) = a.stages[2]
    assert sympy.simplify(third * sympy.sqrt(m**2 + p_x**2 + p_y**2) / (x * p_x + y * p_y)).is_number
    assert len(a.second_class) == 4 and a.physical_degrees_of_freedom == 1


def test_singular_not_homogeneous_energy_on_the_primary_surface():
    L = Lagrangian.from_strings("sqrt_speed", ["x", "y"], "sqrt(x_dot**2 + y_dot**2) - (x**2 + y**2)/2")
    a = dirac.analyze(L)
    x, y, p_x, p_y = _symbols(a, "x", "y", "p_x", "p_y")
    assert a.hessian_rank == 1
    assert sympy.simplify(a.canonical_hamiltonian - (x**2 + y**2) / 2) == 0
    assert [len(stage) for stage in a.stages] == [1, 1]
    assert sympy.simplify(a.stages[0][0] / (p_x**2 + p_y**2 - 1)).is_number
    assert sympy.simplify(a.stages[1][0] / (x * p_x + y * p_y)).is_number
    (u,) = a.multipliers.values()
    on_surface = u.subs(p_y**2, 1 - p_x**2)
    assert sympy.simplify(on_surface - (x**2 + y**2) / 2) == 0
    assert len(a.second_class) == 2 and a.physical_degrees_of_freedom == 1


def test_singular_energy_from_a_root_of_its_eliminant():
    L = Lagrangian.from_strings("boosted", ["x", "y"], "-sqrt(1 - (x_dot - y_dot)**2) - x**2/2")
    a = dirac.analyze(L)
    x, p_x, p_y = _symbols(a, "x", "p_x", "p_y")
    assert a.hessian_rank == 1
    assert sympy.simplify(a.stages[0][0] / (p_x + p_y)).is_number
    kinetic = a.canonical_hamiltonian - x**2 / 2
    assert sympy.simplify((kinetic**2 - 1 - p_x**2).subs(p_y, -p_x)) == 0
    assert sympy.simplify(kinetic.subs({p_y: -sympy.Rational(3, 4), p_x: sympy.Rational(3, 4)}) - sympy.Rational(5, 4)) == 0
    assert [len(stage) for stage in a.stages] == [1, 1] and a.stages[1][0] in (x, -x)
    assert a.multipliers == {"u_1": 0}
    assert len(a.second_class) == 2 and a.physical_degrees_of_freedom == 1


@pytest.mark.parametrize(
    "lagrangian, message",
    [
        ("-m*exp(x_dot)", r"the velocities occur in exp\(x_dot\), which is not algebraic"),
        ("x_dot**7/7 + x_dot**2/2", "the inverse velocity map for x_dot has no solution in radicals"),
    ],
)
def test_lagrangians_the_elimination_cannot_take_are_refused(lagrangian, message):
    L = Lagrangian.from_strings("refused", ["x"], lagrangian, parameters={"m": 1.0} if "m" in lagrangian else None)
    with pytest.raises(dirac.AnalysisError, match=message) as info:
        dirac.analyze(L)
    assert "L must be algebraic in the velocities" in str(info.value)


def test_elimination_over_its_time_budget_is_refused():
    particle = Lagrangian.from_strings(
        "relativistic_sqrt", ["t", "x", "y"], "-m*sqrt(t_dot**2 - x_dot**2 - y_dot**2)", parameters={"m": 1.0}
    )
    momenta = [sympy.Symbol(f"p_{c}", real=True) for c in "txy"]
    m = particle.parameter_symbols["m"]
    with pytest.raises(dirac.AnalysisError, match=r"Gröbner basis .* took more than 0\.001 s"):
        eliminate_velocities(particle, momenta, np.random.default_rng(1), {m: 1.3}, seconds=0.001)


def test_quadratic_lagrangians_keep_the_quadratic_path():
    a = dirac.analyze(dirac.load_system("pendulum"))
    assert "not quadratic" not in a.notes[0]


@pytest.mark.skipif(not hasattr(signal, "setitimer"), reason="interval timers are POSIX only")
def test_time_budget_restores_an_outer_timer():
    """An alarm set by the caller (e.g. a test's watchdog) keeps running, with its remaining time."""
    particle = Lagrangian.from_strings("rel", ["t", "x"], "-m*sqrt(t_dot**2 - x_dot**2)", parameters={"m": 1.0})
    momenta = [sympy.Symbol("p_t", real=True), sympy.Symbol("p_x", real=True)]
    fired: list[int] = []

    def watchdog(signum, frame):
        fired.append(signum)

    previous = signal.signal(signal.SIGALRM, watchdog)
    signal.setitimer(signal.ITIMER_REAL, 100.0)
    try:
        with pytest.raises(dirac.AnalysisError, match="took more than"):
            eliminate_velocities(particle, momenta, np.random.default_rng(2), {particle.parameter_symbols["m"]: 1.1}, seconds=0.001)
        remaining, _ = signal.getitimer(signal.ITIMER_REAL)
        assert 90.0 < remaining <= 100.0 and not fired
        assert signal.getsignal(signal.SIGALRM) is watchdog
    finally:
        signal.setitimer(signal.ITIMER_REAL, 0)
        signal.signal(signal.SIGALRM, previous)
