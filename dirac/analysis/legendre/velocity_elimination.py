"""Legendre transform of a Lagrangian that is not quadratic in the velocities.

For ``L(q, q_dot, t)`` with momenta ``p = dL/dq_dot`` ((205)) and Hessian
``W = d^2 L/dq_dot dq_dot``, two cases are treated (Dirac, "Lectures on quantum
mechanics", Lecture 1; Henneaux–Teitelboim, Sect. 1.1; Gitman–Tyutin, Sect. 2.1):

- ``W`` regular (generic rank ``n``): the velocity map ``q_dot -> p`` is inverted,
  ``q_dot = v(q, p)``, on the branch through the physical velocities, and
  ``H = p . v(q, p) - L(q, v(q, p))`` (e.g. ``L = -m sqrt(1 - x_dot^2)`` gives
  ``H = sqrt(p^2 + m^2)``); each velocity's relation to the momenta comes from a
  lexicographic Gröbner basis, unless exchanging two axes (coordinate, velocity and
  momentum) maps the relations onto themselves: then it is an earlier velocity's relation
  with the axes exchanged (:func:`_mirrored`; a relativistic particle in 3-D needs one
  basis instead of three);
- ``W`` singular (rank ``r < n``): ``n - r`` primary constraints ``phi(q, p) = 0`` are the
  relations among the momenta left when the velocities are eliminated from
  ``p = dL/dq_dot``. The elimination is algebraic: every root ``b^(k/s)`` is named by a
  new variable ``rho`` with ``rho^s = b``, the equations are cleared of denominators
  (kept non-zero by ``w * denominators = 1``, Rabinowitsch), and a lexicographic Gröbner
  basis eliminates ``w``, the ``rho`` and the velocities (Cox–Little–O'Shea, "Ideals,
  Varieties, and Algorithms", Ch. 3, elimination theorem). Of the eliminants, the
  irreducible factors that vanish at the physical momenta are kept. The canonical
  Hamiltonian is the energy ``E = q_dot . p - L``, which on the primary surface is a
  function of ``(q, p)`` alone ((207)); for ``L`` homogeneous of degree one in the
  velocities ``E = 0`` by Euler's theorem (the reparametrisation-invariant relativistic
  particle ``L = -m sqrt(t_dot^2 - x_dot^2 - y_dot^2)``, primary constraint
  ``p_t^2 - p_x^2 - p_y^2 - m^2 = 0``, ``H_c = 0``), and ``H_c = -L_0`` when only the
  velocity-free terms ``L_0`` break the homogeneity; otherwise ``h = E`` is eliminated the
  same way and ``H_c`` is the root of an eliminant that equals ``E`` at the physical points.

Every step runs under a time budget; a step that fails or exceeds it is refused with an
:class:`~dirac.errors.AnalysisError` naming the step and the form ``L`` must take. The
branch of every root is decided numerically at random physical points (velocities where
``L`` is real), with symbolic parameters at their generic positive values: the result is
checked there and holds on the branch through those points.
"""

from __future__ import annotations

import signal
import threading
import time
from collections.abc import Callable, Iterator, Mapping, Sequence
from contextlib import contextmanager
from dataclasses import dataclass
from functools import partial

import numpy as np
import sympy

from dirac.analysis.core.numeric import independent_rows
from dirac.analysis.core.phase_space import derivative
from dirac.codegen import array_function
from dirac.errors import AnalysisError
from dirac.model.lagrangian import Lagrangian

__all__ = ["VelocityElimination", "eliminate_velocities", "ELIMINATION_SECONDS"]

#: seconds allowed for each algebraic step (Gröbner basis, roots, simplification)
ELIMINATION_SECONDS = 30.0

#: random physical points (velocities where L is real and finite) for ranks and branches
PHYSICAL_SAMPLES = 6

#: relative tolerance of the numerical checks at the physical points
CHECK_TOLERANCE = 1e-7

_FORM = (
    "L must be algebraic in the velocities (polynomials, quotients and roots such as "
    "sqrt(t_dot**2 - x_dot**2)), with a velocity map p = dL/dq_dot that can be inverted in radicals "
    "(regular Hessian) or whose velocities can be eliminated (singular Hessian)"
)


@dataclass
class VelocityElimination:
    """The Legendre transform of ``L`` itself (the multipliers' part is added by the caller).

    Attributes
    ----------
    hessian
        ``W(q, q_dot) = d^2 L/dq_dot dq_dot``.
    rank
        Generic rank of ``W`` (decided at random physical points).
    primary
        Primary constraints ``phi(q, p) = 0`` (empty when ``W`` is regular).
    energy
        ``E = q_dot . p - L`` as a function of ``(q, p)`` on the primary surface: the
        canonical Hamiltonian without the constraint terms ``lambda_a chi_a``.
    velocity_solution
        Velocity -> ``v(q, p)`` when ``W`` is regular, else empty.
    method
        What was done (for the analysis notes).
    """

    hessian: sympy.Matrix
    rank: int
    primary: list[sympy.Expr]
    energy: sympy.Expr
    velocity_solution: dict[sympy.Symbol, sympy.Expr]
    method: str


class _OverBudget(Exception):
    """Raised inside an algebraic step that ran over its time budget."""


@contextmanager
def _budget(seconds: float) -> Iterator[None]:
    """Interrupt the enclosed (pure Python) computation after ``seconds`` (POSIX main thread).

    Uses the real-time interval timer; a timer already running (an outer alarm) is
    restored afterwards with its remaining time, and when it would fire first it is left
    alone. Elsewhere (another thread, no ``SIGALRM``) the step runs without a limit.
    """
    usable = hasattr(signal, "setitimer") and threading.current_thread() is threading.main_thread()
    if not usable:
        yield
        return
    outer_remaining, outer_interval = signal.getitimer(signal.ITIMER_REAL)
    if outer_remaining and outer_remaining <= seconds:
        yield
        return

    def over(signum: int, frame: object) -> None:
        raise _OverBudget

    previous = signal.signal(signal.SIGALRM, over)
    start = time.monotonic()
    signal.setitimer(signal.ITIMER_REAL, seconds)
    try:
        yield
    finally:
        signal.setitimer(signal.ITIMER_REAL, 0)
        signal.signal(signal.SIGALRM, previous)
        if outer_remaining:
            left = max(outer_remaining - (time.monotonic() - start), 1e-3)
            signal.setitimer(signal.ITIMER_REAL, left, outer_interval)


def _step(name: str, lagrangian: Lagrangian, seconds: float, work: Callable[[], object]) -> object:
    """Run one algebraic step under the budget; refuse with the step's name when it fails."""
    try:
        with _budget(seconds):
            return work()
    except _OverBudget:
        raise AnalysisError(
            f"the Legendre transform of {lagrangian.name!r} (not quadratic in the velocities) was refused: "
            f"{name} took more than {seconds:g} s; {_FORM}"
        ) from None
    except (sympy.PolynomialError, sympy.CoercionFailed, NotImplementedError, ValueError, ZeroDivisionError) as exc:
        raise AnalysisError(
            f"the Legendre transform of {lagrangian.name!r} (not quadratic in the velocities) was refused: "
            f"{name} failed ({type(exc).__name__}: {exc}); {_FORM}"
        ) from None


def _refuse(lagrangian: Lagrangian, what: str) -> AnalysisError:
    return AnalysisError(
        f"the Legendre transform of {lagrangian.name!r} (not quadratic in the velocities) was refused: {what}; {_FORM}"
    )


# ---------------------------------------------------------------------- algebraic form
class _Algebraic:
    """Expressions rewritten as polynomials: roots of velocity expressions named ``rho_k``
    (``rho_k^s = base``), velocity-free non-polynomial pieces named ``c_k`` (coefficients)."""

    def __init__(self, velocities: Sequence[sympy.Symbol], lagrangian: Lagrangian) -> None:
        self.velocities = set(velocities)
        self.lagrangian = lagrangian
        self.roots: dict[tuple[sympy.Expr, int], sympy.Symbol] = {}
        self.relations: list[sympy.Expr] = []
        self.coefficients: dict[sympy.Expr, sympy.Symbol] = {}

    def convert(self, e: sympy.Expr) -> sympy.Expr:
        if e.is_Symbol or e.is_Number:
            return e
        if not (e.free_symbols & self.velocities):
            if e.is_polynomial():
                return e
            if e not in self.coefficients:
                self.coefficients[e] = sympy.Symbol(f"_c{len(self.coefficients)}")
            return self.coefficients[e]
        if isinstance(e, (sympy.Add, sympy.Mul)):
            return e.func(*[self.convert(a) for a in e.args])
        if isinstance(e, sympy.Pow):
            base, exponent = self.convert(e.base), e.exp
            if exponent.is_Integer:
                return base**exponent
            if exponent.is_Rational:
                return self._root(base, int(exponent.q)) ** int(exponent.p)
        if isinstance(e, sympy.Abs):  # |a| = sqrt(a^2)
            return self._root(self.convert(e.args[0]) ** 2, 2)
        raise _refuse(self.lagrangian, f"the velocities occur in {e}, which is not algebraic")

    def _root(self, base: sympy.Expr, s: int) -> sympy.Symbol:
        key = (base, s)
        if key not in self.roots:
            rho = sympy.Symbol(f"_rho{len(self.roots)}")
            self.roots[key] = rho
            self.relations.append(rho**s - base)
        return self.roots[key]

    def back(self, e: sympy.Expr) -> sympy.Expr:
        """Coefficient names back to their expressions."""
        return e.xreplace({c: original for original, c in self.coefficients.items()})


def _cleared(e: sympy.Expr) -> tuple[sympy.Expr, sympy.Expr]:
    """``(numerator, denominator)`` of ``e`` over one denominator."""
    num, den = sympy.fraction(sympy.together(e))
    return sympy.expand(num), den


# ---------------------------------------------------------------------- physical points
@dataclass
class _Samples:
    """Random physical points: arguments ``(q, q_dot, t, parameters)`` and the values there."""

    arguments: tuple[sympy.Symbol, ...]
    points: list[np.ndarray]
    momenta: list[np.ndarray]
    hessians: list[np.ndarray]


def _physical_samples(
    lagrangian: Lagrangian, momenta_exprs: list[sympy.Expr], W: sympy.Matrix, rng: np.random.Generator, parameter_values: Mapping
) -> _Samples:
    """Points where ``L``, ``p`` and ``W`` are real and finite (velocities of several scales)."""
    q, v = lagrangian.coordinates, lagrangian.velocities
    n = len(q)
    time_symbols = [lagrangian.time] if lagrangian.is_time_dependent and lagrangian.time is not None else []
    params = list(lagrangian.parameters)
    arguments = (*q, *v, *time_symbols, *params)
    fn = array_function(arguments, [lagrangian.expression, *momenta_exprs, *W], cse=True)
    pvals = [float(parameter_values[s]) for s in params]
    points, momenta, hessians = [], [], []
    for _ in range(4000):
        z = rng.uniform(0.5, 1.5, n + len(time_symbols)) * rng.choice([-1.0, 1.0], n + len(time_symbols))
        scale = rng.choice([0.1, 0.3, 1.0, 3.0])
        vel = rng.normal(size=n) * scale
        point = np.concatenate([z[:n], vel, z[n:], pvals])
        with np.errstate(all="ignore"):
            values = np.asarray(fn(*point), dtype=complex)
        if not np.all(np.isfinite(values)) or np.any(np.abs(values.imag) > 1e-12 * (1 + np.abs(values.real))):
            continue
        values = values.real
        points.append(point)
        momenta.append(values[1 : 1 + n])
        hessians.append(values[1 + n :].reshape(n, n))
        if len(points) == PHYSICAL_SAMPLES:
            break
    if len(points) < PHYSICAL_SAMPLES:
        raise _refuse(lagrangian, "no random velocities were found where L and its momenta are real and finite")
    return _Samples(arguments, points, momenta, hessians)


def _values(samples: _Samples, exprs: Sequence[sympy.Expr], extra: Sequence[sympy.Symbol] = (), extra_values: Sequence[np.ndarray] = ()) -> np.ndarray:
    """``exprs`` at the physical points (``extra`` symbols, e.g. momenta, take ``extra_values``)."""
    fn = array_function((*samples.arguments, *extra), list(exprs), cse=True)
    out = []
    for k, point in enumerate(samples.points):
        more = list(extra_values[k]) if extra else []
        with np.errstate(all="ignore"):
            out.append(np.asarray(fn(*point, *more), dtype=complex))
    return np.array(out).reshape(len(samples.points), len(exprs))


def _vanishes(values: np.ndarray, scale: np.ndarray) -> np.ndarray:
    """Which columns vanish at every point, relative to ``1 + scale``."""
    finite = np.all(np.isfinite(values), axis=0)
    return finite & np.all(np.abs(values) <= CHECK_TOLERANCE * (1 + scale), axis=0)


def _split(lagrangian: Lagrangian) -> tuple[sympy.Expr, sympy.Expr]:
    """``L = L_v + L_0``: the terms with velocities and the velocity-free terms (e.g. ``-V(q, t)``)."""
    velocities = set(lagrangian.velocities)
    terms = sympy.Add.make_args(lagrangian.expression)
    rest = sympy.Add(*[term for term in terms if not (term.free_symbols & velocities)])
    return lagrangian.expression - rest, rest


# ---------------------------------------------------------------------- the transform
def eliminate_velocities(
    lagrangian: Lagrangian,
    momenta: Sequence[sympy.Symbol],
    rng: np.random.Generator,
    parameter_values: Mapping,
    seconds: float = ELIMINATION_SECONDS,
) -> VelocityElimination:
    """Legendre transform of a Lagrangian that is not quadratic in the velocities.

    Parameters
    ----------
    lagrangian
        ``L(q, q_dot, t)`` (the multipliers of its constraints are the caller's).
    momenta
        The momentum symbols ``p`` of the coordinates, in order.
    rng, parameter_values
        Random generator and generic (positive) parameter values for the numerical
        decisions: the Hessian rank and the branches of the roots.
    seconds
        Time budget of each algebraic step.

    Returns
    -------
    VelocityElimination

    Raises
    ------
    AnalysisError
        When ``L`` is not algebraic in the velocities, no physical point is found, the
        inverse velocity map or the elimination fails or exceeds ``seconds``, or the
        result does not check at the physical points; the message names the step.
    """
    q, v = lagrangian.coordinates, lagrangian.velocities
    n = len(q)
    L = lagrangian.expression
    P = [derivative(L, vi) for vi in v]  # sympy.diff's expressions, each shared sub-tree once
    W = sympy.Matrix(n, n, lambda i, j: derivative(P[i], v[j]))
    samples = _physical_samples(lagrangian, P, W, rng, parameter_values)
    rank = len(independent_rows(samples.hessians, list(range(n))))
    if rank == n:
        solution, energy, method = _regular(lagrangian, P, list(momenta), samples, parameter_values, seconds)
        return VelocityElimination(W, rank, [], energy, solution, method)
    primary, energy, method = _singular(lagrangian, P, list(momenta), rank, samples, parameter_values, seconds)
    return VelocityElimination(W, rank, primary, energy, {}, method)


def _positive(expr: sympy.Expr, lagrangian: Lagrangian, seconds: float, name: str) -> sympy.Expr:
    """``simplify`` with the symbolic parameters taken positive (as at the generic points)."""
    positive = {p: sympy.Symbol(p.name, positive=True) for p in lagrangian.parameters}
    back = {s: p for p, s in positive.items()}
    simplified = _step(name, lagrangian, seconds, lambda: sympy.simplify(expr.xreplace(positive)))
    assert isinstance(simplified, sympy.Expr)
    return simplified.xreplace(back)


def _momentum_relations(
    lagrangian: Lagrangian, P: list[sympy.Expr], p: list[sympy.Symbol]
) -> tuple[_Algebraic, list[sympy.Expr], list[sympy.Symbol], sympy.Symbol]:
    """The polynomial relations of ``p = dL/dq_dot``: each equation with its denominator
    cleared, the defining relations of the named roots, and ``w * prod(denominators) = 1``
    (denominators non-zero); returns the root naming, the relations, the root symbols and ``w``."""
    alg = _Algebraic(lagrangian.velocities, lagrangian)
    equations, denominators = [], []
    for pi, Pi in zip(p, P):
        num, den = _cleared(pi - alg.convert(Pi))
        equations.append(num)
        denominators.append(den)
    w = sympy.Symbol("_w")
    relations = [*equations, *alg.relations, sympy.expand(w * sympy.Mul(*denominators) - 1)]
    return alg, relations, list(alg.roots.values()), w


def _signed(e: sympy.Expr) -> sympy.Expr:
    """``e`` expanded, of the one sign of ``+-e`` that sympy writes without a leading minus."""
    e = sympy.expand(e)
    return -e if e.could_extract_minus_sign() else e


def _mirrored(
    relations: Sequence[sympy.Expr],
    signed: set[sympy.Expr],
    q: Sequence[sympy.Symbol],
    v: Sequence[sympy.Symbol],
    p: Sequence[sympy.Symbol],
    found: Sequence[sympy.Expr],
    i: int,
) -> sympy.Expr | None:
    """The relation of velocity ``i`` read off an earlier one's by a symmetry of the momentum relations, or ``None``.

    The swap ``sigma`` of ``(q_i, v_i, p_i)`` with ``(q_j, v_j, p_j)`` is a ring automorphism;
    when it maps the set of relations (the equations ``p = dL/dq_dot`` cleared of
    denominators, the roots' defining relations, the Rabinowitsch relation; each up to its
    sign) onto itself, it maps the ideal ``I`` they generate onto itself, so that
    ``sigma(g)`` lies in ``I`` and in ``Q[v_i, p]`` for the relation ``g`` of ``v_j`` found by
    elimination (Cox, Little, O'Shea, Ch. 3): a relation between ``v_i`` and the momenta
    without another Gröbner basis. An isotropic Lagrangian (a relativistic particle in 3-D,
    ``-m c^2 sqrt(1 - v^2/c^2)``) needs one basis instead of three. The root symbols are not
    swapped: a symmetry that exchanges two roots is not used. ``signed`` is the set of the
    relations up to their signs (:func:`_signed`), taken once by the caller.
    """
    for j in range(i):
        swap = {q[i]: q[j], q[j]: q[i], v[i]: v[j], v[j]: v[i], p[i]: p[j], p[j]: p[i]}
        if {_signed(r.xreplace(swap)) for r in relations} == signed:
            return found[j].xreplace(swap)
    return None


def _regular(
    lagrangian: Lagrangian, P: list[sympy.Expr], p: list[sympy.Symbol], samples: _Samples, parameter_values: Mapping, seconds: float
) -> tuple[dict[sympy.Symbol, sympy.Expr], sympy.Expr, str]:
    """Invert ``p = dL/dq_dot`` on the physical branch; ``H = p . v - L`` there."""
    v = lagrangian.velocities
    n = len(v)
    alg, relations, roots, w = _momentum_relations(lagrangian, P, p)
    candidates: list[list[sympy.Expr]] = []
    relations_of: list[sympy.Expr] = []  # the relation between each velocity and the momenta, in the named roots
    signed = {_signed(r) for r in relations} if n > 1 else set()  # the relations up to their signs, for _mirrored
    for i, vi in enumerate(v):
        mirrored = _mirrored(relations, signed, lagrangian.coordinates, v, p, relations_of, i)
        if mirrored is not None:
            poly = mirrored
        else:
            others = [vj for j, vj in enumerate(v) if j != i]
            gens = [w, *roots, *others, vi, *p]
            basis = _step(
                f"the Gröbner basis eliminating the roots and the other velocities (for {vi.name})",
                lagrangian, seconds, partial(sympy.groebner, relations, *gens, order="lex"),
            )
            assert isinstance(basis, sympy.GroebnerBasis)
            eliminated = set(gens) - {vi, *p}
            univariate = [g for g in basis.exprs if not (g.free_symbols & eliminated) and vi in g.free_symbols]
            if not univariate:
                raise _refuse(lagrangian, f"no relation between {vi.name} and the momenta was found")
            poly = min(univariate, key=lambda g: sympy.degree(g, vi))
        relations_of.append(poly)
        found = _step(
            f"the roots of the inverse velocity map for {vi.name}",
            lagrangian, seconds, partial(sympy.roots, alg.back(poly), vi),
        )
        assert isinstance(found, dict)
        if sum(found.values()) != sympy.degree(poly, vi):
            raise _refuse(lagrangian, f"the inverse velocity map for {vi.name} has no solution in radicals")
        candidates.append(list(found))
    # the branch: the combination of roots that gives back the sampled velocities
    velocity_values = [point[n : 2 * n] for point in samples.points]
    chosen: list[sympy.Expr] = []
    for i, vi in enumerate(v):
        values = _values(samples, candidates[i], p, samples.momenta)
        target = np.array([vel[i] for vel in velocity_values])[:, None]
        ok = _vanishes(values - target, np.abs(target))
        good = [c for c, flag in zip(candidates[i], ok) if flag]
        if not good:
            raise _refuse(
                lagrangian,
                f"no root of the inverse velocity map for {vi.name} gives back the velocities at the random "
                "physical points (the branch changes between them)",
            )
        chosen.append(good[0])
    solution = dict(zip(v, chosen))
    moving, rest = _split(lagrangian)
    energy_v = sum((pi * vi for pi, vi in zip(p, v)), sympy.S.Zero) - moving
    energy = _positive(energy_v.xreplace(solution), lagrangian, seconds, "the simplification of H = p.v - L") - rest
    # check: H(q, p(q, v)) equals the energy v.dL/dv - L at the physical points
    direct = sum((Pi * vi for Pi, vi in zip(P, v)), sympy.S.Zero) - lagrangian.expression
    h_values = _values(samples, [energy, direct], p, samples.momenta)
    if not _vanishes((h_values[:, 0] - h_values[:, 1])[:, None], np.abs(h_values[:, 1:2]))[0]:
        raise _refuse(lagrangian, "the Hamiltonian p.v(q, p) - L does not match the energy at the physical points")
    method = (
        f"regular Hessian, L not quadratic in the velocities: the velocity map p = dL/dq_dot inverted in radicals "
        f"(eliminating {len(roots)} root(s) by a Gröbner basis), on the branch through random physical velocities "
        "(symbolic parameters at generic positive values), H = p.v - L there"
    )
    return solution, energy, method


def _singular(
    lagrangian: Lagrangian,
    P: list[sympy.Expr],
    p: list[sympy.Symbol],
    rank: int,
    samples: _Samples,
    parameter_values: Mapping,
    seconds: float,
) -> tuple[list[sympy.Expr], sympy.Expr, str]:
    """Primary constraints by eliminating the velocities; ``H_c`` = the energy on the surface."""
    v = lagrangian.velocities
    n = len(v)
    alg, relations, roots, w = _momentum_relations(lagrangian, P, p)
    gens = [w, *roots, *v, *p]
    basis = _step(
        "the Gröbner basis eliminating the velocities from p = dL/dq_dot",
        lagrangian, seconds, lambda: sympy.groebner(relations, *gens, order="lex"),
    )
    assert isinstance(basis, sympy.GroebnerBasis)
    eliminated = {w, *roots, *v}
    eliminants = [alg.back(g) for g in basis.exprs if not (g.free_symbols & eliminated)]
    factors: list[sympy.Expr] = []
    for g in eliminants:
        listed = _step("the factorisation of the eliminants", lagrangian, seconds, partial(sympy.factor_list, g))
        assert isinstance(listed, tuple)
        for factor, _ in listed[1]:
            if factor.free_symbols & set(p) and factor not in factors:
                factors.append(factor)
    if not factors:
        raise _refuse(lagrangian, f"eliminating the velocities gave no relation among the momenta (Hessian rank {rank} of {n})")
    # keep the factors that vanish at the physical momenta, simplest first
    factors.sort(key=sympy.count_ops)
    values = _values(samples, factors, p, samples.momenta)
    scale = np.array([[float(np.sum(np.abs(m))) for _ in factors] for m in samples.momenta])
    physical = [f for f, ok in zip(factors, _vanishes(values, scale)) if ok]
    variables = [*lagrangian.coordinates, *p]
    gradients = _values(samples, [sympy.diff(f, s) for f in physical for s in variables], p, samples.momenta)
    matrices = [g.real.reshape(len(physical), 2 * n) for g in gradients]
    chosen = independent_rows(matrices, list(range(len(physical)))) if physical else []
    if len(chosen) != n - rank:
        raise _refuse(
            lagrangian,
            f"eliminating the velocities gave {len(chosen)} independent relation(s) among the momenta at the "
            f"physical points, but the Hessian has rank {rank} of {n} (so {n - rank} were expected)",
        )
    primary = [sympy.expand(physical[k]) for k in chosen]
    # the canonical Hamiltonian: the energy v.p - L on the primary surface
    moving, rest = _split(lagrangian)
    euler = sum((Pi * vi for Pi, vi in zip(P, v)), sympy.S.Zero) - moving
    homogeneous = _step("the Euler test sum v dL/dv - L = 0", lagrangian, seconds, lambda: sympy.simplify(euler) == 0)
    if homogeneous and rest == 0:
        energy: sympy.Expr = sympy.S.Zero
        how = "L is homogeneous of degree one in the velocities (Euler: v.dL/dv - L = 0), so H_c = 0"
    elif homogeneous:
        energy = -rest
        how = (
            "L is homogeneous of degree one in the velocities up to velocity-free terms L_0 "
            "(Euler: v.dL/dv - (L - L_0) = 0), so H_c = -L_0"
        )
    else:
        energy = _energy(lagrangian, alg, euler, relations, gens, p, samples, seconds) - rest
        how = (
            "H_c = v.p - L on the primary surface, from an eliminant of h = v.p - L (the root equal to "
            "it at the physical points)"
        )
    method = (
        f"singular Hessian of rank {rank}, L not quadratic in the velocities: primary constraints by eliminating "
        f"the velocities and {len(roots)} root(s) from p = dL/dq_dot (lexicographic Gröbner basis), keeping the "
        f"factors that vanish at random physical momenta; {how}"
    )
    return primary, energy, method


def _energy(
    lagrangian: Lagrangian,
    alg: _Algebraic,
    energy_v: sympy.Expr,
    relations: list[sympy.Expr],
    gens: list[sympy.Symbol],
    p: list[sympy.Symbol],
    samples: _Samples,
    seconds: float,
) -> sympy.Expr:
    """``E = v.p - L`` as a function of ``(q, p)``: eliminate the velocities from ``h = E``.

    The eliminants in ``h`` and ``p`` are tried lowest degree in ``h`` first; a root that
    equals ``E`` at the physical points is the branch taken (linear: the quotient).
    """
    h = sympy.Symbol("_h")
    num, den = _cleared(h - alg.convert(energy_v))
    w2 = sympy.Symbol("_w2")
    system = [*relations, num, sympy.expand(w2 * den - 1)]
    order = [w2, *gens[: len(gens) - len(p)], h, *p]
    basis = _step(
        "the Gröbner basis eliminating the velocities from H_c = v.p - L",
        lagrangian, seconds, partial(sympy.groebner, system, *order, order="lex"),
    )
    assert isinstance(basis, sympy.GroebnerBasis)
    eliminated = set(order) - {h, *p}
    eliminants = [g for g in basis.exprs if not (g.free_symbols & eliminated) and h in g.free_symbols]
    for g in sorted(eliminants, key=lambda g: sympy.degree(g, h)):
        if sympy.degree(g, h) == 1:
            a, b = sympy.Poly(g, h).all_coeffs()
            candidates = [sympy.cancel(-b / a)]
        else:
            found = _step("the roots of the eliminant of H_c", lagrangian, seconds, partial(sympy.roots, g, h))
            assert isinstance(found, dict)
            candidates = list(found)
        for candidate in candidates:
            candidate = alg.back(candidate)
            values = _values(samples, [candidate, energy_v], p, samples.momenta)
            if _vanishes((values[:, 0] - values[:, 1])[:, None], np.abs(values[:, 1:2]))[0]:
                if sympy.degree(g, h) == 1:
                    return candidate
                return _positive(candidate, lagrangian, seconds, "the simplification of H_c")
    raise _refuse(lagrangian, "the energy v.p - L could not be written as a single function of q and p on the primary surface")
