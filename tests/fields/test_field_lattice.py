"""dirac.lattice: a density on a periodic lattice (forward differences), and the O(3) sigma model with RATTLE."""

from __future__ import annotations

import numpy as np
import pytest
import sympy
from stress_scaling import stress_scale

import dirac
from dirac.errors import InputError

#: sites of the slow ring tests: 64 in the full stress runs, 16 in CI's bounded form
RING = 64 if stress_scale() == 1.0 else 16

SIGMA_DENSITY = "(n1_t**2 + n2_t**2 + n3_t**2)/2 - (n1_x**2 + n2_x**2 + n3_x**2)/2"


def sigma_model() -> dirac.FieldTheory:
    """The O(3) sigma model: L = (|d_t n|^2 - |d_x n|^2)/2 with n . n = 1 at every point."""
    return dirac.FieldTheory.from_strings("sigma", ["x"], ["n1", "n2", "n3"], SIGMA_DENSITY,
                                          constraints=["n1**2 + n2**2 + n3**2 - 1"])


def test_forward_differences_periodic_and_the_volume_factor():
    """By hand: 3 sites, a = 1/2: L = a sum_i [phi_dot_i^2/2 - ((phi_{i+1} - phi_i)/a)^2/2] with phi_3 = phi_0."""
    kg = dirac.FieldTheory.from_strings("kg", ["x"], ["phi"], "phi_t**2/2 - phi_x**2/2")
    lagrangian = dirac.lattice(kg, sites=3, spacing=0.5)
    phi = sympy.symbols("phi_0 phi_1 phi_2", real=True)
    dots = sympy.symbols("phi_0_dot phi_1_dot phi_2_dot", real=True)
    a = sympy.Rational(1, 2)
    expected = a * sum(dots[i] ** 2 / 2 - ((phi[(i + 1) % 3] - phi[i]) / a) ** 2 / 2 for i in range(3))
    assert sympy.expand(lagrangian.expression - expected) == 0
    assert [c.name for c in lagrangian.coordinates] == ["phi_0", "phi_1", "phi_2"]


def test_two_dimensional_names_and_constraints_at_every_site():
    theory = dirac.FieldTheory.from_strings("s", ["x", "y"], ["n1", "n2"], "(n1_t**2 + n2_t**2 - n1_x**2 - n2_y**2)/2",
                                            constraints=["n1**2 + n2**2 - 1"])
    lagrangian = dirac.lattice(theory, sites=[2, 3])
    assert [c.name for c in lagrangian.coordinates][:4] == ["n1_0_0", "n2_0_0", "n1_0_1", "n2_0_1"]
    assert len(lagrangian.constraints) == 6
    assert str(lagrangian.constraints[5]) == "n1_1_2**2 + n2_1_2**2 - 1"


def test_bad_lattice_arguments():
    kg = dirac.FieldTheory.from_strings("kg", ["x"], ["phi"], "phi_t**2/2 - phi_x**2/2")
    with pytest.raises(InputError, match="sites must be a positive integer"):
        dirac.lattice(kg, sites=0)
    with pytest.raises(InputError, match="one value per spatial direction"):
        dirac.lattice(kg, sites=[4, 4])
    with pytest.raises(InputError, match="spacing must be a positive"):
        dirac.lattice(kg, sites=4, spacing=-1.0)


def _sigma_counts(sites: int) -> tuple:
    a = dirac.analyze(dirac.lattice(sigma_model(), sites=sites, spacing=1.0))
    return [len(s) for s in a.stages], len(a.first_class), len(a.second_class), a.physical_degrees_of_freedom


def test_sigma_model_counts_on_a_small_ring():
    """Hand count per site (the engine's extended phase space: n and the multiplier lambda, 8
    dimensions per site): p_lambda = 0 (primary), n.n - 1 = 0, n.p = 0, and the one that fixes
    lambda (|p|^2 - n.(force)... - 2 lambda n.n...): 4 second class per site, and
    dof = (8 - 4)/2 = 2 per site (the two angles of the sphere)."""
    assert _sigma_counts(4) == ([4, 4, 4, 4], 0, 16, 8)


@pytest.mark.slow
def test_sigma_model_counts_on_a_large_ring():
    """The same hand count on N = 64 sites (16 in the bounded run): 4 stages of N, 4 N second class, 2 N dof."""
    assert _sigma_counts(RING) == ([RING] * 4, 0, 4 * RING, 2 * RING)


@pytest.mark.slow
def test_sigma_model_with_rattle_keeps_the_sphere_and_the_energy_to_second_order():
    """RATTLE (Andersen, J. Comput. Phys. 52 (1983) 24; Hairer-Lubich-Wanner, Geometric Numerical Integration, ch. VII)
    keeps the holonomic constraints to the Newton tolerance at every step and the energy to
    O(dt^2): halving dt divides the energy error by 4 (a fit of log error against log dt has slope 2)."""
    sites = RING
    lagrangian = dirac.lattice(sigma_model(), sites=sites, spacing=1.0)
    x = np.arange(sites)
    theta = 1.0 + 0.3 * np.sin(2 * np.pi * x / sites)
    phi = 0.5 * np.cos(2 * np.pi * x / sites)
    n = np.stack([np.sin(theta) * np.cos(phi), np.sin(theta) * np.sin(phi), np.cos(theta)], axis=1)
    omega = np.array([0.1, 0.2, 0.4])[None, :] * (1 + 0.2 * np.sin(2 * np.pi * x / sites))[:, None]
    problem = dirac.ConstrainedProblem(lagrangian, q0=n.ravel(), qdot0=np.cross(omega, n).ravel())
    t_end = 10.0  # a few hundred steps of the ring: the first compilation dominates the time
    errors = []
    steps = (0.02, 0.01, 0.005)  # dt = 0.04 is not yet in the asymptotic range (ratio 2.8)
    for dt in steps:
        solution = dirac.integrate(problem, "rattle-2", t_end=t_end, dt=dt, samples=101, outputs=["q", "energy"],
                                   newton_tolerance=1e-14)
        q = solution["q"].reshape(-1, sites, 3)
        assert np.abs(np.linalg.norm(q, axis=2) - 1).max() < 1e-12
        energy = solution["energy"]
        errors.append(np.abs(energy - energy[0]).max())
    slope = np.polyfit(np.log(steps), np.log(errors), 1)[0]
    assert 1.8 < slope < 2.2, (errors, slope)


def test_maxwell_on_a_lattice_keeps_its_gauge_invariance():
    """Non-compact abelian fields on sites with forward differences keep a lattice gauge
    invariance. Hand count, 1+1 on N = 4 sites: L = a sum_n (A1_dot_n - (A0_{n+1} - A0_n)/a)^2/2;
    p_A0_n = 0 (N primary); their preservation gives the lattice Gauss laws p_A1_{n-1} - p_A1_n = 0,
    whose sum over the ring vanishes identically: N - 1 = 3 independent secondaries. All 2N - 1 = 7
    are first class; dof = (4N - 2(2N - 1))/2 = 1 (the zero mode of A1, as in the continuum's k = 0
    case); one gauge parameter per site: delta A0_n = eps_dot_n, delta A1_n = (eps_{n+1} - eps_n)/a."""
    from dirac.fields.catalog import maxwell_1p1

    a = dirac.analyze(dirac.lattice(maxwell_1p1(), sites=4, spacing=0.5))
    assert ([len(s) for s in a.stages], len(a.first_class), len(a.second_class)) == ([4, 3], 7, 0)
    assert a.physical_degrees_of_freedom == 1
    assert len(a.gauge_generators) == 4
