"""Textbook linear field theories, ready to analyse (docs/field_theories.md).

Each builder returns a :class:`~dirac.fields.theory.FieldTheory`; the densities are the
textbook ones (references in each docstring). Metric ``eta = diag(-1, 1, 1, 1)`` where one
is needed. ``CATALOG`` maps a name to its builder (``dirac bench`` times each analysis).
"""

from __future__ import annotations

import itertools

import sympy

from dirac.fields.theory import FieldTheory

#: Maxwell in 3+1: L = (E^2 - B^2)/2, E_i = d_t A_i - d_i A0 (Henneaux-Teitelboim, eq. (19.1))
MAXWELL_DENSITY = (
    "((A1_t - A0_x)**2 + (A2_t - A0_y)**2 + (A3_t - A0_z)**2)/2"
    " - ((A2_x - A1_y)**2 + (A3_y - A2_z)**2 + (A1_z - A3_x)**2)/2"
)


def maxwell() -> FieldTheory:
    return FieldTheory.from_strings("maxwell", ["x", "y", "z"], ["A0", "A1", "A2", "A3"], MAXWELL_DENSITY)


def maxwell_1p1() -> FieldTheory:
    """Maxwell in 1+1: L = E^2/2 with E = d_t A1 - d_x A0 (no magnetic field in one space dimension)."""
    return FieldTheory.from_strings("maxwell_1p1", ["x"], ["A0", "A1"], "(A1_t - A0_x)**2/2")


def proca() -> FieldTheory:
    """Proca: L = -F^2/4 - m^2 A_mu A^mu / 2 with eta = diag(-1, 1, 1, 1): Maxwell + m^2 (A0^2 - A_i A_i)/2."""
    return FieldTheory.from_strings(
        "proca", ["x", "y", "z"], ["A0", "A1", "A2", "A3"],
        MAXWELL_DENSITY + " + m**2*(A0**2 - A1**2 - A2**2 - A3**2)/2", parameters={"m": 1.0})


#: the Chern-Simons term (kappa/2) eps^{mu nu rho} A_mu d_nu A_rho in 2+1, eps^{012} = 1
CHERN_SIMONS_TERM = "kappa/2*(A0*(A2_x - A1_y) + A1*(A0_y - A2_t) + A2*(A1_t - A0_x))"


def maxwell_chern_simons() -> FieldTheory:
    """Maxwell-Chern-Simons in 2+1 (Deser-Jackiw-Templeton): (E1^2 + E2^2 - B^2)/2 + CS term."""
    return FieldTheory.from_strings(
        "maxwell_chern_simons", ["x", "y"], ["A0", "A1", "A2"],
        "((A1_t - A0_x)**2 + (A2_t - A0_y)**2)/2 - (A2_x - A1_y)**2/2 + " + CHERN_SIMONS_TERM,
        parameters={"kappa": 1.0})


def chern_simons() -> FieldTheory:
    """Pure Chern-Simons in 2+1."""
    return FieldTheory.from_strings("chern_simons", ["x", "y"], ["A0", "A1", "A2"], CHERN_SIMONS_TERM,
                                          parameters={"kappa": 1.0})


def klein_gordon() -> FieldTheory:
    """Real Klein-Gordon in 3+1: L = (phi_t^2 - |grad phi|^2 - m^2 phi^2)/2."""
    return FieldTheory.from_strings(
        "klein_gordon", ["x", "y", "z"], ["phi"], "(phi_t**2 - phi_x**2 - phi_y**2 - phi_z**2 - m**2*phi**2)/2",
        parameters={"m": 1.0})


#: the ten components of a symmetric tensor h_{mu nu}, mu <= nu
TENSOR_FIELDS = [f"h{m}{n}" for m in range(4) for n in range(m, 4)]


def fierz_pauli(mass: bool = True) -> FieldTheory:
    """Fierz-Pauli (``mass=False``: linearised Einstein), Hinterbichler, Rev. Mod. Phys. 84 (2012) 671, eq. (2.1):

    L = -1/2 d_l h_mn d^l h^mn + d_m h^ml d^n h_nl - d_m h^mn d_n h + 1/2 d_l h d^l h - m^2/2 (h_mn h^mn - h^2),

    eta = diag(-1, 1, 1, 1), written out in the ten components ``h00, h01, ..., h33``.
    """
    eta = sympy.diag(-1, 1, 1, 1)
    directions = ["t", "x", "y", "z"]
    comp = {}
    for m, n in itertools.product(range(4), repeat=2):
        a, b = sorted((m, n))
        comp[m, n] = f"h{a}{b}"

    def d(m: int, n: int, l: int) -> sympy.Symbol:  # d_l h_mn
        return sympy.Symbol(f"{comp[m, n]}_{directions[l]}")

    def h(m: int, n: int) -> sympy.Symbol:
        return sympy.Symbol(comp[m, n])

    r4 = range(4)
    trace = sum(eta[m, m] * h(m, m) for m in r4)
    d_trace = [sum(eta[m, m] * d(m, m, l) for m in r4) for l in r4]
    # eta is diagonal: raising an index multiplies by eta[i, i]
    L = sympy.Integer(0)
    L += -sympy.Rational(1, 2) * sum(eta[l, l] * eta[m, m] * eta[n, n] * d(m, n, l) ** 2
                                    for l in r4 for m in r4 for n in r4)
    div = [sum(eta[m, m] * d(m, l, m) for m in r4) for l in r4]  # d^m h_ml (lower l)
    L += sum(eta[l, l] * div[l] ** 2 for l in r4)
    L += -sum(div[n] * eta[n, n] * d_trace[n] for n in r4)
    L += sympy.Rational(1, 2) * sum(eta[l, l] * d_trace[l] ** 2 for l in r4)
    if mass:
        msym = sympy.Symbol("m")
        L += -msym**2 / 2 * (sum(eta[m, m] * eta[n, n] * h(m, n) ** 2 for m in r4 for n in r4) - trace**2)
    name = "fierz_pauli" if mass else "linearised_einstein"
    return FieldTheory.from_sympy(name, ["x", "y", "z"], TENSOR_FIELDS, sympy.expand(L),
                                        parameters={"m": 1.0} if mass else {})


def linearised_einstein() -> FieldTheory:
    """Linearised Einstein gravity: :func:`fierz_pauli` without the mass term."""
    return fierz_pauli(mass=False)


#: name -> builder of every theory above
CATALOG = {
    "maxwell": maxwell,
    "maxwell_1p1": maxwell_1p1,
    "proca": proca,
    "maxwell_chern_simons": maxwell_chern_simons,
    "chern_simons": chern_simons,
    "klein_gordon": klein_gordon,
    "fierz_pauli": fierz_pauli,
    "linearised_einstein": linearised_einstein,
}
