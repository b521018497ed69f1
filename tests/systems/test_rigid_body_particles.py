"""The rigid body as n >= 4 point masses, constraints (17)–(18), Lagrangian (19):
body data (24), (66), (67), refusal of planar bodies, and the engine's count of six
degrees of freedom.  Expected numbers are computed by hand in the comments."""

from __future__ import annotations

import numpy as np
import pytest
import sympy
from rigid_body_analyses import cached_analysis

import dirac
from dirac.errors import InputError
from dirac_systems import rigid_body_particles

UNIT_TETRAHEDRON = [(0.0, 0.0, 0.0), (1.0, 0.0, 0.0), (0.0, 1.0, 0.0), (0.0, 0.0, 1.0)]


def test_body_data_of_the_unit_tetrahedron():
    # centre (1/4, 1/4, 1/4); x_N = y_N - centre; g_11 = 3 (1/4)^2 + (3/4)^2 = 3/4,
    # g_12 = 1/16 - 3/16 - 3/16 + 1/16 = -1/4; I = tr(g) 1 - g with tr g = 9/4.
    data = rigid_body_particles.body_data([1.0] * 4, UNIT_TETRAHEDRON)
    np.testing.assert_allclose(data.centre_of_mass, [0.25, 0.25, 0.25])
    g = np.full((3, 3), -0.25) + np.eye(3)
    np.testing.assert_allclose(data.mass_matrix, g, atol=1e-15)
    np.testing.assert_allclose(data.inertia_tensor, 2.25 * np.eye(3) - g, atol=1e-15)
    # eigenvalues of g: 1/4 along (1,1,1), 1 twice -> I: 2, 5/4, 5/4 (72)
    np.testing.assert_allclose(data.principal_moments, [1.25, 1.25, 2.0])
    np.testing.assert_allclose(data.relative_positions.T @ np.ones(4), 0.0, atol=1e-15)  # (29)


def test_body_data_weights_by_mass():
    masses = [1.0, 2.0, 3.0, 4.0]
    data = rigid_body_particles.body_data(masses, UNIT_TETRAHEDRON)
    # centre = (2 e_x + 3 e_y + 4 e_z)/10
    np.testing.assert_allclose(data.centre_of_mass, [0.2, 0.3, 0.4])
    # g_11 = sum m x^2: 1*0.04 + 2*0.64 + 3*0.04 + 4*0.04 = 1.6; g_12 = sum m x y:
    # 1*(0.06) + 2*(0.8*-0.3) + 3*(-0.2*0.7) + 4*(-0.2*-0.3) = 0.06 - 0.48 - 0.42 + 0.24 = -0.6
    assert data.mass_matrix[0, 0] == pytest.approx(1.6)
    assert data.mass_matrix[0, 1] == pytest.approx(-0.6)
    moments = data.principal_moments
    assert moments[0] + moments[1] > moments[2]  # triangle inequality of a real body


@pytest.mark.parametrize(
    "positions, shape",
    [
        ([(0, 0, 0), (1, 0, 0), (0, 1, 0), (1, 1, 0)], "planar"),
        ([(0, 0, 0), (1, 1, 1), (2, 2, 2), (3, 3, 3)], "collinear"),
        ([(1, 2, 3)] * 4, "single point"),
    ],
)
def test_planar_and_collinear_bodies_are_refused(positions, shape):
    with pytest.raises(InputError, match=shape):
        rigid_body_particles.system(masses=[1.0] * 4, positions=positions)


def test_bad_particle_input_is_refused():
    with pytest.raises(InputError, match="n >= 4"):
        rigid_body_particles.system(masses=[1.0] * 3, positions=UNIT_TETRAHEDRON[:3])
    with pytest.raises(InputError, match="positive"):
        rigid_body_particles.system(masses=[1.0, -1.0, 1.0, 1.0], positions=UNIT_TETRAHEDRON)
    with pytest.raises(InputError, match="shape"):
        rigid_body_particles.system(masses=[1.0] * 4, positions=UNIT_TETRAHEDRON[:3])
    # non-planar body whose first four particles are coplanar: (17) would be degenerate
    coplanar_first = [(0, 0, 0), (1, 0, 0), (0, 1, 0), (1, 1, 0), (0, 0, 1)]
    with pytest.raises(InputError, match="particles 1-4"):
        rigid_body_particles.system(masses=[1.0] * 5, positions=coplanar_first)


def test_default_constraints_are_17_with_hand_computed_constants():
    L = rigid_body_particles.system()
    assert len(L.coordinates) == 12 and len(L.constraints) == 6  # 3n - 6
    y = [sympy.Matrix([sympy.Symbol(f"{a}_{N}", real=True) for a in "xyz"]) for N in (1, 2, 3, 4)]
    z = [y[A] - y[0] for A in (1, 2, 3)]
    # default body: z_2 = (1,0,0), z_3 = (0,2,0), z_4 = (1/2, 1/2, 3/2)
    a = {(0, 0): 1, (0, 1): 0, (0, 2): sympy.Rational(1, 2), (1, 1): 4, (1, 2): 1, (2, 2): sympy.Rational(11, 4)}
    expected = [z[A].dot(z[B]) - a[(A, B)] for A in range(3) for B in range(3) if A <= B]
    assert [sympy.expand(c - e) for c, e in zip(L.constraints, expected)] == [0] * 6
    # kinetic term (19) with masses 1, 2, 3, 4
    v = [sympy.Matrix([sympy.Symbol(f"{a}_{N}_dot", real=True) for a in "xyz"]) for N in (1, 2, 3, 4)]
    kinetic = sum(m * v[N].dot(v[N]) for N, m in enumerate([1, 2, 3, 4])) / 2
    assert sympy.expand(L.expression - kinetic) == 0


def test_constraints_18_of_a_five_particle_body_hold_under_rigid_motions():
    positions = [(0, 0, 0), (1, 0, 0), (0, 1, 0), (0, 0, 1), (0.3, -0.7, 1.1)]
    L = rigid_body_particles.system(masses=[1.0, 1.0, 2.0, 1.0, 0.5], positions=positions)
    assert len(L.constraints) == 9  # 6 of (17) and 3 (n - 4) = 3 of (18)
    rng = np.random.default_rng(0)
    q, r = np.linalg.qr(rng.normal(size=(3, 3)))
    moved = np.array(positions) @ q.T + rng.normal(size=3)
    deformed = np.array(positions, dtype=float)
    deformed[4] += [0.0, 0.0, 0.1]
    f = sympy.lambdify(L.coordinates, list(L.constraints), "numpy")
    assert np.max(np.abs(f(*moved.ravel()))) < 1e-12
    values = np.array(f(*deformed.ravel()), dtype=float)
    assert np.all(np.abs(values[:6]) < 1e-12) and np.max(np.abs(values[6:])) > 1e-3


def test_factory_options_pass_through_load_system():
    L = dirac.load_system("rigid_body_particles", masses=[1.0] * 4, positions=UNIT_TETRAHEDRON)
    assert L.name == "rigid_body_particles" and len(L.constraints) == 6
    assert "4 point masses" in L.description


@pytest.mark.slow
def test_engine_finds_six_degrees_of_freedom(request):
    """Lagrangian (19): 3n coordinates and 3n - 6 multipliers; the chain (17)-(18) then
    velocities, then the multipliers: 4 stages of 3n - 6, all second class, so
    (2 (6n - 6) - 4 (3n - 6)) / 2 = 6 degrees of freedom (n = 4: 36-dim phase space)."""
    analysis = cached_analysis(request.config, "rigid_body_particles")
    assert len(analysis.phase_space) == 36
    assert [len(s) for s in analysis.stages] == [6, 6, 6, 6]
    assert len(analysis.second_class) == 24 and not analysis.first_class
    assert analysis.physical_degrees_of_freedom == 6
