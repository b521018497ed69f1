"""Linear field theories mode by mode: counts per spatial point, classes, gauge generators, k = 0.

Every count is derived by hand in the test's docstring (canonical analysis per point:
momenta, the Hamiltonian density, the consistency conditions). Counts per point: the
pair (k, -k) counts twice (dirac.fields.modes); the zero mode k = 0 is one real mode,
counted per mode.
"""

from __future__ import annotations

import sympy

import dirac
from dirac.fields.catalog import (
    chern_simons,
    fierz_pauli,
    klein_gordon,
    maxwell,
    maxwell_1p1,
    maxwell_chern_simons,
    proca,
)


def _counts(analysis):
    return (analysis.constraints_per_stage, analysis.first_class_count, analysis.second_class_count,
            analysis.physical_degrees_of_freedom)


def _case(analysis, condition):
    (case,) = [c for c in analysis.parameter_cases if c.condition == condition]
    d = case.to_json()
    return d["constraints_per_stage"], d["first_class_count"], d["second_class_count"], d["physical_degrees_of_freedom"]


def test_maxwell_3p1_two_first_class_and_two_photon_polarisations():
    """Hand count (the textbook example of first-class constraints in a field theory):
    pi^0 = dL/d(d_t A0) = 0 (1 primary); H = pi^2/2 + B^2/2 - A0 d_i pi_i (after an integration
    by parts), so d_t pi^0 = d_i pi_i: the Gauss law (1 secondary), which commutes with H:
    the chain stops. {pi^0, d_i pi_i} = 0: 2 first class per point, dof = (8 - 2*2)/2 = 2.
    Castellani's generator G = int (eps_dot pi^0 - eps d_i pi_i): delta A0 = d_t eps, delta A_i = d_i eps.
    k = 0: A0 drops out (it enters only through d_i A0), L_0 = a_dot_i^2/2: one primary p_A0,
    first class, no secondary (k . pi = 0 identically): dof per mode (8 - 2)/2 = 3."""
    a = dirac.analyze(maxwell())
    assert _counts(a) == ([1, 1], 2, 0, 2)
    assert [str(c) for c in a.stages[0]] == ["p_A0"]
    assert [str(c) for c in a.stages[1]] == ["d_x(p_A1) + d_y(p_A2) + d_z(p_A3)"]  # the Gauss law
    (gauge,) = a.gauge_generators
    assert {k: str(v) for k, v in gauge.delta.items()} == {
        "A0": "epsilon_t", "A1": "d_x(epsilon)", "A2": "d_y(epsilon)", "A3": "d_z(epsilon)"}
    assert _case(a, "k_x = k_y = k_z = 0") == ([1], 1, 0, 3)


def test_maxwell_1p1_has_no_propagating_photon():
    """Hand count: in 1+1, L = (d_t A1 - d_x A0)^2/2; pi^0 = 0 (primary), Gauss law d_x pi^1 = 0
    (secondary), both first class: dof = (4 - 2*2)/2 = 0 (no transverse direction).
    k = 0: L_0 = a_dot_1^2/2, p_A0 = 0 only (first class): dof per mode (4 - 2)/2 = 1 (the
    zero mode of A1, a free particle: the electric field's constant part)."""
    a = dirac.analyze(maxwell_1p1())
    assert _counts(a) == ([1, 1], 2, 0, 0)
    assert [str(c) for c in a.stages[1]] == ["d_x(p_A1)"]
    (gauge,) = a.gauge_generators  # delta A0 = d_t eps, delta A1 = d_x eps, as in 3+1
    assert {k: str(v) for k, v in gauge.delta.items()} == {"A0": "epsilon_t", "A1": "d_x(epsilon)"}
    assert _case(a, "k_x = 0") == ([1], 1, 0, 1)


def test_proca_three_polarisations_all_second_class():
    """Hand count: L = Maxwell + m^2 (A0^2 - A_i A_i)/2; pi^0 = 0 (primary), d_t pi^0 =
    d_i pi_i + m^2 A0 (secondary); {pi^0(x), d_i pi_i + m^2 A0 (y)} = -m^2 delta != 0: one
    second-class pair, the multiplier of pi^0 fixed, the chain stops. dof = (8 - 2)/2 = 3.
    k = 0: L_0 = a_dot_i^2/2 + m^2 (a0^2 - a_i^2)/2: p_A0 = 0, then m^2 a0 = 0: second class,
    dof per mode 3. m = 0 (special parameter value) is Maxwell: 2 first class, 2 per point."""
    a = dirac.analyze(proca())
    assert _counts(a) == ([1, 1], 0, 2, 3)
    assert a.gauge_generators == []
    assert _case(a, "k_x = k_y = k_z = 0") == ([1, 1], 0, 2, 3)
    assert _case(a, "m = 0") == ([1, 1], 2, 0, 2)


def test_real_klein_gordon_one_degree_of_freedom_no_constraints():
    """Hand count: L = (phi_t^2 - |grad phi|^2 - m^2 phi^2)/2 is regular (Hessian 1): no
    constraint, dof 1 per point; the zero mode (a harmonic oscillator of frequency m) likewise."""
    a = dirac.analyze(klein_gordon())
    assert _counts(a) == ([], 0, 0, 1)
    assert _case(a, "k_x = k_y = k_z = 0") == ([], 0, 0, 1)


def test_maxwell_chern_simons_one_massive_photon():
    """Hand count (Deser-Jackiw-Templeton, Ann. Phys. 140 (1982) 372: one massive mode):
    pi^0 = 0 (primary); d_t pi^0 = d_i pi_i + (kappa/2) eps_ij d_i A_j (secondary, the
    modified Gauss law); its bracket with itself is kappa eps_ij d_i d_j delta = 0, so both are
    first class: dof = (6 - 2*2)/2 = 1. k = 0: A0 drops out (it enters only through d_i A0 and
    A0 B), L_0 = (a_dot_1^2 + a_dot_2^2)/2 + (kappa/2)(a2 a_dot_1 - a1 a_dot_2), regular in a_1,
    a_2 (a charge in a magnetic field): p_A0 = 0 alone, first class, dof per mode (6 - 2)/2 = 2."""
    a = dirac.analyze(maxwell_chern_simons())
    assert _counts(a) == ([1, 1], 2, 0, 1)
    (gauge,) = a.gauge_generators
    assert str(gauge.delta["A0"]) == "epsilon_t" and str(gauge.delta["A1"]) == "d_x(epsilon)"
    assert _case(a, "k_x = k_y = 0") == ([1], 1, 0, 2)


def test_pure_chern_simons_has_no_local_degree_of_freedom():
    """Hand count: L = (kappa/2) eps^{mu nu rho} A_mu d_nu A_rho is first order in time:
    pi^0 = 0, pi^1 - (kappa/2) A2 = 0, pi^2 + (kappa/2) A1 = 0 (3 primary); H = -kappa A0 B, so
    d_t pi^0 gives B = d_x A2 - d_y A1 = 0 (1 secondary). {phi_1, phi_2} = -kappa: that pair is
    second class; pi^0 and the Gauss law d_i phi_i + kappa B... are first class: 2 first, 2 second
    class, dof = (6 - 2*2 - 2)/2 = 0 (a topological theory). k = 0: B = 0 identically and A0 drops
    out: the 3 primaries only, p_A0 first class and the other two second class: dof per mode
    (6 - 2 - 2)/2 = 1 (the zero modes of A1 and A2 are canonically conjugate: the holonomies)."""
    a = dirac.analyze(chern_simons())
    assert _counts(a) == ([3, 1], 2, 2, 0)
    (gauge,) = a.gauge_generators  # G = int (eps_dot pi^0 - eps (d_i phi_i + kappa B)): delta A_mu = d_mu eps
    assert [str(gauge.delta[f]) for f in ("A0", "A1", "A2")] == ["epsilon_t", "d_x(epsilon)", "d_y(epsilon)"]
    assert _case(a, "k_x = k_y = 0") == ([3], 1, 2, 1)
    (vanishing,) = [c for c in a.parameter_cases if c.condition == "kappa = 0"]
    assert vanishing.error is not None and "vanishes" in vanishing.error


def test_fierz_pauli_five_polarisations():
    """Hinterbichler, Rev. Mod. Phys. 84 (2012) 671, sect. II: the massive graviton has 5
    degrees of freedom, all constraints second class. Hand count of the chain: h00 and h0i enter
    without their own time derivatives once the terms d_t h_0mu d_i h_ij are read as momenta, so
    p_h0mu - (spatial derivatives of h) = 0 (4 primary); their preservation gives 4 secondary
    (h00 appears linearly: its secondary is the Hamiltonian-type constraint; h0i quadratically in the
    mass term: theirs fix h0i); the secondary of h00 commutes with the primaries, so its
    preservation is a tertiary constraint (1), and that one's a quaternary (1) which fixes the
    multiplier of p_h00. 10 second class, 0 first class: dof = (20 - 10)/2 = 5.
    k = 0: the same chain with the spatial derivatives dropped ([4, 4, 1, 1]: p_h0mu = 0; h0i = 0
    and the trace h_ii = 0; then p_ii = 0; then h00 fixed): 10 second class, dof per mode 5 (the
    traceless h_ij: spin 2 at rest)."""
    a = dirac.analyze(fierz_pauli())
    assert _counts(a) == ([4, 4, 1, 1], 0, 10, 5)
    assert _case(a, "k_x = k_y = k_z = 0") == ([4, 4, 1, 1], 0, 10, 5)


def test_linearised_einstein_two_graviton_polarisations_and_diffeomorphisms():
    """Hand count (the massless limit of Hinterbichler's (2.1), m = 0): p_h0mu - (spatial
    derivatives of h) = 0 (4 primary); their preservation gives the 4 linearised Hamiltonian and
    momentum constraints (secondary), which commute with H: the chain stops. All 8 are first class
    (the linearised diffeomorphisms): dof = (20 - 2*8)/2 = 2. Castellani's generators are the four
    transformations delta h_mu nu = d_mu xi_nu + d_nu xi_mu: with xi_0 = eps_1/2, delta h00 = d_t eps_1
    and delta h0i = d_i eps_1 / 2. k = 0: h0mu drop out (they enter only with spatial derivatives
    or through d_t h_0mu d_i h_ij), L_0 = (h_dot_ij h_dot_ij - h_dot_ii^2)/2 is regular in the six
    h_ij: 4 primary p_h0mu = 0, first class, no secondary: dof per mode (20 - 8)/2 = 6."""
    a = dirac.analyze(fierz_pauli(mass=False))
    assert _counts(a) == ([4, 4], 8, 0, 2)
    assert len(a.gauge_generators) == 4
    time_gauge = [g for g in a.gauge_generators if str(g.delta.get("h00")) == "epsilon_1_t"]
    assert len(time_gauge) == 1
    delta = time_gauge[0].delta
    assert [str(delta[f"h0{i}"]) for i in (1, 2, 3)] == ["d_x(epsilon_1)/2", "d_y(epsilon_1)/2", "d_z(epsilon_1)/2"]
    assert _case(a, "k_x = k_y = k_z = 0") == ([4], 4, 0, 6)


def test_fierz_pauli_massless_case_is_linearised_einstein():
    """At m = 0 Hinterbichler's (2.1) is linearised Einstein: the hand count of
    test_linearised_einstein_two_graviton_polarisations_and_diffeomorphisms above (4 primary,
    4 secondary that commute with H, all 8 first class, dof (20 - 2*8)/2 = 2). The structure
    changes at stage 2: for m != 0 the mass term gives the h0i secondaries a non-zero bracket
    with the primaries (the consistency block of stage 2 fixes their multipliers), at m = 0
    that block vanishes and the chain stops there. So m = 0 must be a special parameter value
    of Fierz-Pauli, found in the stage-2 block, with the linearised-Einstein counts."""
    a = dirac.analyze(fierz_pauli())
    assert _case(a, "m = 0") == ([4, 4], 8, 0, 2)
    (special,) = [s for s in a.mode.special_parameter_values if s.equation == "m = 0"]
    assert "consistency matrix {Phi_a, phi_k} of stage 2 drops" in special.where


def test_coulomb_gauge_bracket_is_the_transverse_delta():
    """In Coulomb gauge (A0 = 0, d_i A_i = 0) the Dirac bracket of Maxwell is
    {A_i(x), pi_j(y)}_D = (delta_ij - d_i d_j / laplacian) delta(x - y): its Fourier coefficient is
    delta_ij - k_i k_j / k^2 (Dirac, Lectures on Quantum Mechanics; the transverse delta). Hand
    derivation per mode: the constraints k.pi = 0 and k.A = 0 have C = {k.A, k.pi} = k^2, so
    {A_i, pi_j}_D = delta_ij - k_i (1/k^2) k_j."""
    a = dirac.analyze(maxwell())
    coulomb = a.fix_gauge(["A0", "A1_x + A2_y + A3_z"])
    k = sympy.symbols("k_x k_y k_z", real=True)
    k2 = sum(c**2 for c in k)
    for i in range(3):
        for j in range(3):
            value = coulomb.dirac_bracket(f"A{i + 1}", f"p_A{j + 1}")
            expected = (1 if i == j else 0) - k[i] * k[j] / k2
            assert sympy.simplify(value - expected) == 0, (i, j, value)
    assert coulomb.first_class == []
    assert coulomb.dirac_bracket("A1", "A2") == 0 and coulomb.dirac_bracket("p_A1", "p_A2") == 0
    assert coulomb.dirac_bracket("A0", "p_A0") == 0  # A0 = 0 and p_A0 = 0 are a second-class pair


def test_poisson_bracket_per_mode_is_the_canonical_delta():
    """{A_i(x), pi_j(y)} = delta_ij delta(x - y): the Fourier coefficient is delta_ij (no k)."""
    a = dirac.analyze(maxwell())
    assert a.poisson_bracket("A1", "p_A1") == 1 and a.poisson_bracket("A1", "p_A2") == 0


def test_chern_simons_bracket_of_the_two_spatial_components():
    """By hand: up to a total time derivative L = kappa A2 d_t A1 - kappa A0 B, so A1 and kappa A2 are
    canonically conjugate: {A1(x), A2(y)}_D = (1/kappa) delta(x - y), a constant Fourier coefficient
    1/kappa; the second-class pair p_A1 - kappa A2/2, p_A2 + kappa A1/2 halves {A1, p_A1}_D to 1/2."""
    a = dirac.analyze(chern_simons())
    kappa = sympy.Symbol("kappa", real=True)
    assert sympy.simplify(a.dirac_bracket("A1", "A2") - 1 / kappa) == 0
    assert a.dirac_bracket("A1", "p_A1") == sympy.Rational(1, 2)
