"""Systems with gauge freedom: first-class constraints, two stages, free multipliers.

gauge_system, L = 1/2[(x_dot - z y)^2 + (y_dot + z x)^2] - k/2 (x^2 + y^2) (hand):
  p_x = x_dot - z y, p_y = y_dot + z x, p_z = 0 (primary);
  H_c = (p_x^2 + p_y^2)/2 + z (y p_x - x p_y) + k/2 (x^2 + y^2);
  {p_z, H_c} = -(y p_x - x p_y)  => stage 2: J = x p_y - y p_x = 0;
  {J, H_c} = 0 (rotation invariance), {J, p_z} = 0: nothing new, u_1 undetermined.
  Both first class: (6 - 2*2)/2 = 1 degree of freedom.
relativistic_particle, L = eta(x_dot, x_dot)/(2e) - e m^2/2 (hand):
  p_mu = eta x_dot/e, p_e = 0; H_c = e/2 (eta^{-1}(p, p) + m^2);
  {p_e, H_c} = -(p^2 + m^2)/2 => stage 2: -p_t^2 + p_x^2 + p_y^2 + p_z^2 + m^2 = 0;
  {p^2 + m^2, H_T} = 0: done. Both first class: (10 - 4)/2 = 3 degrees of freedom.
"""

from __future__ import annotations

import pytest
import sympy

import dirac


@pytest.fixture(scope="module")
def gauge():
    return dirac.analyze(dirac.load_system("gauge_system"))


@pytest.fixture(scope="module")
def particle():
    return dirac.analyze(dirac.load_system("relativistic_particle"))


def _proportional(a, b):
    ratio = sympy.cancel(a / b)
    return ratio.is_number and ratio != 0


def test_gauge_system_chain(gauge):
    s = gauge.symbols
    assert [len(st) for st in gauge.stages] == [1, 1]
    assert gauge.stages[0] == [s["p_z"]]
    assert _proportional(gauge.stages[1][0], s["x"] * s["p_y"] - s["y"] * s["p_x"])
    assert len(gauge.first_class) == 2 and gauge.second_class == []
    assert gauge.physical_degrees_of_freedom == 1
    assert gauge.multipliers == {}
    assert [u.name for u in gauge.undetermined_multipliers] == ["u_1"]
    assert gauge.hessian_rank == 2
    # the Dirac bracket is the Poisson bracket: no second-class constraints
    assert gauge.dirac_bracket(s["x"], s["p_x"]) == 1


def test_gauge_equations_keep_the_free_multiplier(gauge):
    eom = gauge.equations_of_motion()
    s = gauge.symbols
    u = gauge.primary_multipliers[0]
    assert sympy.simplify(eom[s["z"]] - u) == 0  # z_dot = u: pure gauge
    assert sympy.simplify(eom[s["x"]] - (s["p_x"] + s["z"] * s["y"])) == 0


def test_relativistic_particle_chain(particle):
    s = particle.symbols
    m = sympy.Symbol("m", real=True)
    assert [len(st) for st in particle.stages] == [1, 1]
    assert particle.stages[0] == [s["p_e"]]
    mass_shell = -s["p_t"] ** 2 + s["p_x"] ** 2 + s["p_y"] ** 2 + s["p_z"] ** 2 + m**2
    assert _proportional(particle.stages[1][0], mass_shell)
    assert len(particle.first_class) == 2 and particle.second_class == []
    assert particle.physical_degrees_of_freedom == 3
    assert particle.multipliers == {}
    assert len(particle.phase_space) == 10
    e = s["e"]
    assert sympy.simplify(particle.canonical_hamiltonian - e / 2 * mass_shell) == 0


def test_inconsistent_lagrangian_is_reported():
    L = dirac.Lagrangian.from_strings("bad", ["x", "y"], "x_dot**2/2 + y")
    with pytest.raises(dirac.InconsistentSystemError, match="1 = 0|cannot hold"):
        dirac.analyze(L)


def test_non_quadratic_lagrangian_is_refused():
    """A Lagrangian not algebraic in the velocities (a square root, -m sqrt(1 - x_dot^2), is
    now transformed: tests/analysis/legendre/test_nonquadratic_legendre.py)."""
    L = dirac.Lagrangian.from_strings("relativistic", ["x"], "-m*exp(x_dot)", parameters={"m": 1.0})
    with pytest.raises(dirac.AnalysisError, match="not quadratic in the velocities"):
        dirac.analyze(L)


def test_redundant_holonomic_constraint_is_dropped():
    L = dirac.Lagrangian.from_strings(
        "twice", ["x", "y"], "(x_dot**2 + y_dot**2)/2", constraints=["x**2 + y**2 - 1", "2*x**2 + 2*y**2 - 2"]
    )
    analysis = dirac.analyze(L)
    # p_lambda_1, p_lambda_2 primary; only one independent circle constraint follows
    assert [len(st) for st in analysis.stages][:2] == [2, 1]
    # lambda_1 and lambda_2 only enter through lambda_1 + 2 lambda_2: one combination is gauge
    assert len(analysis.first_class) >= 1
    assert analysis.physical_degrees_of_freedom == 1
