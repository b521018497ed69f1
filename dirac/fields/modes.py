"""Fourier modes of a linear field theory, and the way back to position space.

A density quadratic in the fields and their first derivatives with constant coefficients,
``L = (1/2) X^T C X`` with ``X = (phi_a, d_t phi_a, d_j phi_a)``, is diagonal in the Fourier
modes ``phi_a(x) = sum_k a_a(k) e^{i k.x}``, ``a_a(-k) = conj(a_a(k))`` (real fields). With
``d_j -> i k_j`` the modes ``k`` and ``-k`` together contribute (volume ``V``)

    L_k + L_{-k} = 2 V [ Q(Re X_k) + Q(Im X_k) ],        X_k = (a, a_dot, i k_j a),

(``C`` real symmetric, so the cross terms ``Re X C Im X`` cancel). The engine is handed
the **pair Lagrangian** ``Q(Re X_k) + Q(Im X_k)`` (the constant ``2V`` dropped: it scales
every momentum and bracket alike and changes no constraint) in the real coordinates
``<field>_re = Re a`` and ``<field>_im = Im a``, with the wave vector ``k_x, k_y, ...`` as
symbolic parameters: ``Re X_k = (u, u_dot, -k_j v)`` and ``Im X_k = (v, v_dot, k_j u)``.

Counting. ``N`` lattice points carry ``N`` Fourier modes, which pair into ``N/2`` pairs
``(k, -k)``; each pair is one pair Lagrangian. So every count of the pair analysis
(constraints of each stage, first and second class, degrees of freedom) is **twice** the
count per spatial point, and the counts per point are the pair's divided by 2. They are
even: space translations act on the pair as the rotations ``a -> e^{i theta} a``, which map
each real constraint ``Re F`` to its partner ``Im F``. The zero mode ``k = 0`` is real
(``a(0) = conj(a(0))``): its Lagrangian is ``Q(a, a_dot, 0)`` in one real variable per field,
and its counts are per mode, not halved.

Back to position space. A real linear function ``c`` of the pair's phase space is the real
part ``Re F`` of ``F = sum_a alpha_a(k) a_a + beta_a(k) pi_a`` with ``alpha_a = dc/du_a - i
dc/dv_a`` (and the momenta alike): ``F`` is the Fourier transform of a local expression
``sum_a alpha_a(-i d) phi_a + beta_a(-i d) pi_a``, read with ``i k_j -> d_j``. Printed with
``d_x(...)`` for the spatial derivative along ``x`` (``d_x(d_y(A0))`` for a second one).
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np
import sympy

from dirac.errors import InputError
from dirac.fields.theory import TIME_DIRECTION, FieldTheory
from dirac.model.lagrangian import Lagrangian, momentum_name, velocity_name

__all__ = [
    "ModeMap",
    "check_linear",
    "pair_lagrangian",
    "zero_mode_lagrangian",
    "wave_vector",
    "operator_symbol",
]

#: relative singular-value threshold of the numeric rank tests (independence over C)
RANK_TOLERANCE = 1e-9

LATTICE_ROAD = (
    "the mode-by-mode analysis takes densities quadratic in the fields and their first derivatives with "
    "constant coefficients; analyse a nonlinear theory on a lattice instead: dirac.lattice(theory, sites=N, "
    "spacing=a) in Python, or dirac analyze FILE --lattice N"
)


def wave_vector(theory: FieldTheory) -> tuple[sympy.Symbol, ...]:
    """``(k_x, k_y, ...)``: one real symbol per spatial direction."""
    return tuple(sympy.Symbol(f"k_{d}", real=True) for d in theory.space)


def check_linear(theory: FieldTheory) -> None:
    """Refuse a density that is not quadratic with constant coefficients (or has constraints).

    Raises
    ------
    InputError
        Naming the offending term and the lattice road.
    """
    if theory.constraints:
        raise InputError(f"{theory.name!r} has holonomic constraints at every point, which make it nonlinear: "
                         + LATTICE_ROAD)
    variables = list(theory.variables.values())
    density = sympy.expand(theory.density)
    try:
        poly = sympy.Poly(density, *variables)
    except sympy.PolynomialError:
        raise InputError(f"the density of {theory.name!r} is not a polynomial in the fields and their "
                         f"derivatives: {LATTICE_ROAD}") from None
    for monomial, coefficient in poly.terms():
        degree = sum(monomial)
        if coefficient.free_symbols & set(variables):  # pragma: no cover - Poly keeps them apart
            raise InputError(f"the density of {theory.name!r} has a coefficient {coefficient} depending on the fields")
        term = coefficient * sympy.Mul(*(v**e for v, e in zip(variables, monomial)))
        if degree > 2:
            raise InputError(f"the density of {theory.name!r} is not quadratic (the term {term} has degree "
                             f"{degree}): {LATTICE_ROAD}")
        if degree == 1:
            raise InputError(f"the density of {theory.name!r} has the linear term {term} (a source): the mode "
                             "analysis takes homogeneous quadratic densities; shift the field to remove the source, "
                             "or use the lattice (dirac.lattice(theory, sites=N, spacing=a))")


def _mode_symbols(theory: FieldTheory, suffix: str) -> tuple[tuple[sympy.Symbol, ...], tuple[sympy.Symbol, ...]]:
    q = tuple(sympy.Symbol(f"{f}{suffix}", real=True) for f in theory.field_names)
    v = tuple(sympy.Symbol(velocity_name(s.name), real=True) for s in q)
    return q, v


def _substitution(theory: FieldTheory, q, v, spatial) -> dict:
    out = {}
    for f, qa, va, sa in zip(theory.fields, q, v, spatial):
        out[f] = qa
        out[theory.derivative(f, TIME_DIRECTION)] = va
        for d, s in zip(theory.space, sa):
            out[theory.derivative(f, d)] = s
    return out


def pair_lagrangian(theory: FieldTheory) -> Lagrangian:
    """The Lagrangian of the pair ``(k, -k)``: ``Q(Re X_k) + Q(Im X_k)`` (module docstring)."""
    ks = wave_vector(theory)
    u, ud = _mode_symbols(theory, "_re")
    w, wd = _mode_symbols(theory, "_im")
    real = _substitution(theory, u, ud, [[-k * wa for k in ks] for wa in w])
    imag = _substitution(theory, w, wd, [[k * ua for k in ks] for ua in u])
    expression = sympy.expand(theory.density.xreplace(real) + theory.density.xreplace(imag))
    expression = _without_constant(expression, [*u, *w, *ud, *wd])
    parameters = {**theory.parameters, **{k: None for k in ks}}
    return Lagrangian(f"{theory.name} (mode pair k, -k)", (*u, *w), (*ud, *wd), expression, (), parameters,
                      f"Fourier modes k and -k of {theory.name}")


def zero_mode_lagrangian(theory: FieldTheory) -> Lagrangian:
    """The Lagrangian of the real zero mode ``k = 0``: ``Q(a, a_dot, 0)``."""
    q, v = _mode_symbols(theory, "")
    expression = theory.density.xreplace(_substitution(theory, q, v, [[0] * len(theory.space) for _ in q]))
    expression = _without_constant(sympy.expand(expression), [*q, *v])
    if expression == 0:
        raise InputError(f"the zero mode of {theory.name!r} has a vanishing Lagrangian (every term has a spatial "
                         "derivative): nothing to analyse at k = 0")
    return Lagrangian(f"{theory.name} (zero mode k = 0)", q, v, expression, (), dict(theory.parameters),
                      f"zero mode of {theory.name}")


def _without_constant(expression: sympy.Expr, variables: Sequence[sympy.Symbol]) -> sympy.Expr:
    constant = expression.subs({s: 0 for s in variables})
    return sympy.expand(expression - constant)


def operator_symbol(monomial: dict[str, int], label: str) -> sympy.Symbol:
    """``{"x": 1, "y": 1}``, ``"p_A1"`` -> the symbol printed ``d_x(d_y(p_A1))``."""
    text = label
    for direction in sorted(monomial, reverse=True):
        for _ in range(monomial[direction]):
            text = f"d_{direction}({text})"
    return sympy.Symbol(text)


def latex_of_operator(name: str) -> str:
    """LaTeX of an operator symbol name: ``d_x(d_y(p_A1))`` -> ``\\partial_{x} \\partial_{y} p_{A1}``."""
    parts = []
    while name.startswith("d_") and name.endswith(")") and "(" in name:
        head, _, rest = name.partition("(")
        parts.append(rf"\partial_{{{head[2:]}}}")
        name = rest[:-1]
    from dirac.model.lagrangian import latex_name

    base = _latex_epsilon(name) if name.startswith("epsilon") else latex_name(name)
    return " ".join([*parts, base])


def _latex_epsilon(name: str) -> str:
    """``epsilon_2_tt`` -> ``\\ddot{\\epsilon}_{2}``: a gauge parameter and its time derivatives."""
    pieces = name.split("_")[1:]
    dots = len(pieces.pop()) if pieces and set(pieces[-1]) == {"t"} else 0
    base = r"\epsilon"
    if dots:
        base = {1: r"\dot", 2: r"\ddot", 3: r"\dddot"}.get(dots, rf"\partial_t^{{{dots}}}") + "{" + base + "}"
    return base + (f"_{{{pieces[0]}}}" if pieces else "")


@dataclass
class ModeMap:
    """Real linear functions of a mode's phase space <-> local expressions in position space.

    ``pair`` is True for the pair Lagrangian (``<f>_re``, ``<f>_im``), False for a real
    mode (the zero mode, or a theory without spatial directions), whose variables carry
    the field names themselves.
    """

    theory: FieldTheory
    pair: bool

    def __post_init__(self) -> None:
        names = self.theory.field_names
        suffixes = ("_re", "_im") if self.pair else ("", None)
        self.labels = [*names, *(momentum_name(f) for f in names)]
        self.real = [sympy.Symbol(f"{f}{suffixes[0]}", real=True) for f in names]
        self.real += [sympy.Symbol(momentum_name(f"{f}{suffixes[0]}"), real=True) for f in names]
        self.imag = ([sympy.Symbol(f"{f}{suffixes[1]}", real=True) for f in names]
                     + [sympy.Symbol(momentum_name(f"{f}{suffixes[1]}"), real=True) for f in names]
                     if self.pair else [])
        self.ks = wave_vector(self.theory)
        self.ds = {k: sympy.Symbol(f"d_{d}") for k, d in zip(self.ks, self.theory.space)}
        self.variables = [*self.real, *self.imag]

    # ------------------------------------------------------------------ complex coefficients
    def complex_vector(self, c: sympy.Expr) -> list[sympy.Expr] | None:
        """``F`` with ``c = Re F`` (module docstring), or None when ``c`` is not linear homogeneous."""
        c = sympy.expand(c)
        if self.pair:
            vec = [sympy.diff(c, r) - sympy.I * sympy.diff(c, i) for r, i in zip(self.real, self.imag)]
        else:
            vec = [sympy.diff(c, r) for r in self.real]
        if any(e.free_symbols & set(self.variables) for e in vec):
            return None
        rebuilt = sum((sympy.re(e) * r - sympy.im(e) * i for e, r, i in zip(vec, self.real, self.imag)), sympy.Integer(0)) \
            if self.pair else sum((e * r for e, r in zip(vec, self.real)), sympy.Integer(0))
        if sympy.expand(rebuilt - c) != 0:
            return None
        return vec

    def numeric(self, vec: Sequence[sympy.Expr], point: dict) -> np.ndarray:
        return np.array([complex(sympy.N(e.xreplace(point))) for e in vec], dtype=complex)

    def normalised(self, vec: Sequence[sympy.Expr], lead_first: Sequence[int] | None = None) -> list[sympy.Expr]:
        """``vec`` times one factor: polynomial (denominators cleared, common factors free of the
        wave vector removed: a factor ``k_x`` is kept, it is the derivative ``d_x``), in the
        derivative symbols ``d_j = i k_j``, with real coefficients where possible and its leading
        coefficient 1 (a number) or positive. ``lead_first``: the order in which entries are
        searched for the leading one (default: momenta first, then fields)."""
        entries = [sympy.cancel(sympy.together(e)) for e in vec]
        common = sympy.Integer(1)
        for e in entries:
            common = sympy.lcm(common, sympy.denom(e))
        entries = [sympy.expand(sympy.cancel(e * common)) for e in entries]
        nonzero = [e for e in entries if e != 0]
        if not nonzero:
            return entries
        g = nonzero[0]
        for e in nonzero[1:]:
            g = sympy.gcd(g, e)
        ks = set(self.ds)
        _, factors = sympy.factor_list(g)
        removable = sympy.Mul(*(f**n for f, n in factors if not (f.free_symbols & ks)))
        if removable.free_symbols:
            entries = [sympy.expand(sympy.cancel(e / removable)) for e in entries]
        to_d = {k: -sympy.I * d for k, d in self.ds.items()}
        entries = [sympy.expand(e.xreplace(to_d)) for e in entries]
        if lead_first is None:
            half = len(entries) // 2
            lead_first = [*range(half, len(entries)), *range(half)] if len(entries) == len(self.labels) else range(len(entries))
        lead = self.leading(entries, lead_first)
        if sympy.expand(sympy.im(lead)) == 0:
            factor = sympy.Integer(1)
        elif sympy.expand(sympy.re(lead)) == 0:
            factor = sympy.I
        else:
            factor = lead
        lead = sympy.expand(lead / factor)
        if lead.is_number:
            factor *= lead
        elif lead.could_extract_minus_sign():
            factor = -factor
        return [sympy.expand(e / factor) for e in entries]

    def leading(self, entries: Sequence[sympy.Expr], order: Sequence[int]) -> sympy.Expr:
        """The leading coefficient (in the derivative symbols) of the first nonzero entry in ``order``."""
        gens = list(self.ds.values())
        first = next(entries[i] for i in order if entries[i] != 0)
        return sympy.Poly(first, *gens).coeffs()[0] if gens else first

    def expression(self, entries: Sequence[sympy.Expr], labels: Sequence[str]) -> sympy.Expr:
        """``sum_a entries[a](d) label_a`` written with operator symbols ``d_x(label)``."""
        gens = list(self.ds.values())
        directions = list(self.theory.space)
        total = sympy.Integer(0)
        for e, label in zip(entries, labels):
            if e == 0:
                continue
            if not gens:
                total += e * sympy.Symbol(label)
                continue
            for monomial, coefficient in sympy.Poly(e, *gens).terms():
                powers = {d: n for d, n in zip(directions, monomial) if n}
                total += coefficient * operator_symbol(powers, label)
        return total

    def position(self, c: sympy.Expr) -> sympy.Expr:
        """A real linear function of the mode's phase space as a local expression (or ``c``
        unchanged when it is not linear)."""
        vec = self.complex_vector(c)
        if vec is None:
            return c
        return self.expression(self.normalised(vec), self.labels)

    def independent(self, vectors: Sequence[Sequence[sympy.Expr]], before: Sequence[Sequence[sympy.Expr]] = (),
                    seed: int = 7) -> list[int]:
        """Indices of ``vectors`` independent over C of each other and of ``before`` (numerically, at a
        random wave vector and random parameter values)."""
        rng = np.random.default_rng(seed)
        symbols = set().union(*(e.free_symbols for v in [*vectors, *before] for e in v)) - set(self.variables)
        point = {s: sympy.Float(rng.uniform(0.5, 1.5) * rng.choice([-1, 1])) for s in symbols}
        rows = [self.numeric(v, point) for v in before]
        kept: list[int] = []
        for index, v in enumerate(vectors):
            row = self.numeric(v, point)
            trial = np.array([*rows, row])
            scale = max(1.0, float(np.abs(trial).max()))
            rank = int(np.sum(np.linalg.svd(trial, compute_uv=False) > RANK_TOLERANCE * scale)) if len(trial) else 0
            if rank == len(trial):
                rows.append(row)
                kept.append(index)
        return kept
