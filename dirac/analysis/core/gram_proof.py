"""Proofs that Gram-type divisors never vanish on the constraint surface (Cauchy–Binet).

With holonomic constraints ``chi_a(q) = 0`` and a kinetic energy quadratic in the
momenta, ``H_c = 1/2 p^T W p + V(q)`` with a constant ``W`` (the inverse mass matrix), the
consistency conditions of the fourth stage fix the multipliers through the Gram matrix

    G = J W J^T,      J_ai = d chi_a / d q_i

(Sect. X, (210)-(215): ``{Phi_a, p_lambda_b} = d Phi_a/d lambda_b`` is ``G``). Eliminating
the multipliers divides by its pivots, ratios ``D_k / D_(k-1)`` of its principal minors:
the Cartesian double pendulum's multiplier solution divides by the Schur complement
``G_22 - G_12^2 / G_11``, whose numerator is ``det G``. The principal minor of the rows
``K`` is a sum of squares by the Cauchy–Binet formula (e.g. Horn & Johnson, *Matrix
Analysis*, 2nd ed., Sect. 0.8.7; for ``k = 2`` and ``W = 1`` Lagrange's identity):

    det(J_K W J_K^T) = sum_{|S| = k} det(J_KS)^2 prod_{s in S} w_s

for a diagonal ``W = diag(w)``; a constant symmetric ``W = L D L^T`` is brought to that
form with ``J L`` and ``D``. When the weight products ``prod w_S`` all have one sign
(each one's ratio to the first is positive: numbers, or parameters declared
``positive=True``; a single mass ``m`` for all coordinates gives one weight, whose sign does
not matter) the terms that share a weight product are grouped, ``det = w_0 sum_g r_g S_g``
with ``r_g > 0`` and sums of squares ``S_g >= 0`` (also a finer grouping: by the weights and the rows of
``J_K`` that the columns enter, so that the terms of a chain of equal masses that take one column of each
bob form a group of their own), and when one group's ``S_g`` is a nonzero constant on
the surface (each factor of it an exact identity ``c + sum a_i phi_i``,
:func:`~dirac.analysis.core.divisors.constant_on_surface`), the minor is at least that
group times its weight: it never vanishes on the surface. The double pendulum's
``det G = 16/m1^2 (r1 x d)^2 + 16 (x1^2 + y1^2)(dx^2 + dy^2)/(m1 m2)`` (``d = r2 - r1``) is
at least ``16 l1^2 l2^2/(m1 m2)`` there.

The rule is a proof or nothing: a divisor whose numerator is no constant multiple of such
a minor, a weight of unknown sign (a mass not declared positive), or no group constant on
the surface leave the divisor to the other proofs and the search, with the reason
(:class:`GramVerdict`). It runs inside a CPU-time budget (:data:`GRAM_BUDGET`).
"""

from __future__ import annotations

import itertools
import random
from collections.abc import Callable, Sequence

import sympy
from sympy.polys.matrices import DomainMatrix

from dirac.analysis.core.budget import CpuBudget, OverBudget
from dirac.analysis.core.divisors import GramVerdict, constant_on_surface, sum_of_squares_on_surface

__all__ = ["GramProver", "GramVerdict", "GRAM_BUDGET"]

#: ``expr -> ({q: d expr/dq}, {q: d expr/dp_q})``, the non-zero partial derivatives keyed by the coordinate
Partials = Callable[[sympy.Expr], tuple[dict, dict]]

#: CPU seconds that the Gram proofs of one analysis may take in all (past it, divisors stay not ruled out)
GRAM_BUDGET = 2.0
#: largest number of rows of a principal minor tried (``k`` of ``det(J_K W J_K^T)``)
GRAM_ROWS = 4
#: largest number of row sets ``K`` compared with one divisor
GRAM_SUBSETS = 64
#: largest number of Cauchy–Binet terms (column sets ``S``) expanded for one minor
GRAM_TERMS = 2000
#: largest number of terms of a group's expanded sum of squares that is factored (larger groups are not tried)
GROUP_TERMS = 400


def _momentum_hessian(
    hamiltonian: sympy.Expr, coordinates: Sequence[sympy.Symbol], momenta: Sequence[sympy.Symbol],
    partials: Partials | None = None,
) -> tuple[list[int], sympy.Matrix]:
    """``(used, W)``: the momenta ``H`` contains (indices) and ``W_ij = d^2 H / dp_i dp_j`` over them.

    Each first derivative is taken once and differentiated again only by the momenta it contains
    (``sympy.hessian`` differentiates ``H`` itself for each of the ``n^2`` entries: 6.9 s for the 48
    momenta of a 24-link chain). With ``partials`` (:meth:`~dirac.analysis.core.phase_space.PhaseSpace.partials`,
    ``expr -> ({q: d/dq}, {q: d/dp_q})``) the derivatives the analysis has taken already are read from its cache.
    """
    if partials is not None:
        by_coordinate = partials(hamiltonian)[1]
        used = [k for k, q in enumerate(coordinates) if q in by_coordinate]
        first = {k: by_coordinate[coordinates[k]] for k in used}
    else:
        used = [k for k, p in enumerate(momenta) if hamiltonian.has(p)]
        first = {k: sympy.diff(hamiltonian, momenta[k]) for k in used}
    position = {k: i for i, k in enumerate(used)}
    entries: dict[tuple[int, int], sympy.Expr] = {}
    for k in used:
        d = first[k]
        if partials is not None:
            seconds = partials(d)[1]
            found = {position[j]: seconds[coordinates[j]] for j in used if coordinates[j] in seconds}
        else:
            present = d.free_symbols
            found = {position[j]: sympy.diff(d, momenta[j]) for j in used if momenta[j] in present}
        entries.update({(position[k], j): value for j, value in found.items() if value != 0})
    n = len(used)
    return used, sympy.Matrix(n, n, lambda i, j: entries.get((i, j), sympy.S.Zero))


class GramProver:
    """``divisor -> GramVerdict``: whether the divisor's numerator is a principal minor of ``J W J^T``
    proven nonzero on the surface by the Cauchy–Binet formula (module docstring).

    Parameters
    ----------
    holonomic
        The constraints of the surface that depend on the ``coordinates`` alone (the rows of ``J``).
    coordinates
        The coordinates conjugate to the momenta of ``W`` (the columns of ``J``).
    weights
        ``W`` (``n x n``, constant on phase space, symmetric): ``d^2 H_c / dp^2``.
    surface, variables
        All constraints of the surface, and the phase-space variables.
    budget
        CPU seconds for all calls together (:data:`GRAM_BUDGET`), or the running budget they share.
    partials
        The analysis' cached partial derivatives (``expr -> ({q: d/dq}, {q: d/dp_q})``), or None
        (``sympy.diff``).
    """

    def __init__(
        self, holonomic: Sequence[sympy.Expr], coordinates: Sequence[sympy.Symbol], weights: sympy.Matrix,
        surface: Sequence[sympy.Expr], variables: Sequence[sympy.Symbol], budget: float | CpuBudget = GRAM_BUDGET,
        partials: Partials | None = None,
    ) -> None:
        self.holonomic = list(holonomic)
        self.coordinates = list(coordinates)
        self.surface = list(surface)
        self.variables = list(variables)
        self.budget = budget if isinstance(budget, CpuBudget) else CpuBudget(budget)
        self._partials = partials
        self._memo: dict = {}
        self._jacobian: sympy.Matrix | None = None
        self._diagonal: list[sympy.Expr] | None = None
        self._weights = weights
        self._answers: dict[sympy.Expr, GramVerdict | None] = {}
        self._minors: dict[tuple[int, ...], tuple[sympy.Matrix, sympy.Expr, set, int]] = {}  # per row set K
        self._verdicts: dict[tuple[int, ...], GramVerdict] = {}  # Cauchy-Binet per row set K

    @classmethod
    def from_hamiltonian(
        cls, hamiltonian: sympy.Expr, coordinates: Sequence[sympy.Symbol], momenta: Sequence[sympy.Symbol],
        surface: Sequence[sympy.Expr], variables: Sequence[sympy.Symbol], budget: float | CpuBudget = GRAM_BUDGET,
        partials: Partials | None = None,
    ) -> GramProver | None:
        """The prover for ``H_c`` and the surface, or None when there is no Gram structure to use: no
        constraint in the coordinates alone, or ``d^2 H_c / dp^2`` not constant on phase space. ``partials``
        (the analysis' cached derivatives, ``expr -> ({q: d/dq}, {q: d/dp_q})``) spares taking them again."""
        names = set(variables)
        own = set(coordinates)
        holonomic = [c for c in surface if (c.free_symbols & names) and (c.free_symbols & names) <= own]
        if not holonomic or not momenta:
            return None
        try:
            used, W = _momentum_hessian(hamiltonian, coordinates, momenta, partials)
        except (TypeError, ValueError):
            return None
        if not used:
            return None
        if any(entry.free_symbols & names for entry in W) or W != W.T:
            return None
        return cls(holonomic, [coordinates[k] for k in used], W, surface, variables, budget, partials)

    @classmethod
    def on_first_use(
        cls, hamiltonian: sympy.Expr, coordinates: Sequence[sympy.Symbol], momenta: Sequence[sympy.Symbol],
        surface: Sequence[sympy.Expr], variables: Sequence[sympy.Symbol], budget: float = GRAM_BUDGET,
        partials: Partials | None = None,
    ) -> Callable[[sympy.Expr], GramVerdict | None]:
        """``divisor -> verdict`` that builds the prover (:meth:`from_hamiltonian`) on its first call: an analysis
        whose divisors are all decided otherwise never takes the Hessian of ``H_c``. Building it counts in the
        budget (a step past it leaves every divisor to the other proofs, with the reason)."""
        built: list[GramProver | None] = []
        clocks: list[CpuBudget] = []  # started at the first use, not at the analysis' end
        spent = GramVerdict(False, f"the Cauchy-Binet proof for Gram determinants was not tried: its budget "
                                   f"({float(budget):g} s of CPU time) ran out")

        def prove(divisor: sympy.Expr) -> GramVerdict | None:
            if not built:
                if not clocks:
                    clocks.append(CpuBudget(budget))
                clock = clocks[0]
                try:
                    with clock.interrupting():
                        built.append(cls.from_hamiltonian(hamiltonian, coordinates, momenta, surface, variables, clock,
                                                          partials))
                except OverBudget:
                    return spent  # tried again on the next divisor: the clock says at once that it ran out
            prover = built[0]
            return None if prover is None else prover(divisor)

        return prove

    # ------------------------------------------------------------------ the structure
    def _factors(self) -> tuple[sympy.Matrix, list[sympy.Expr]] | None:
        """``(J L, diag D)`` with ``W = L D L^T`` (``L = 1`` for a diagonal ``W``); None when ``W`` has no such form."""
        if self._jacobian is None:
            W = self._weights
            if self._partials is not None:  # the constraints' gradients, from the analysis' cache
                rows = [self._partials(c)[0] for c in self.holonomic]
                J = sympy.Matrix([[row.get(q, sympy.S.Zero) for q in self.coordinates] for row in rows])
            else:
                J = sympy.Matrix([[sympy.diff(c, q) for q in self.coordinates] for c in self.holonomic])
            if W.is_diagonal():
                self._jacobian, self._diagonal = J, [W[i, i] for i in range(W.shape[0])]
            else:
                try:
                    L, D = W.LDLdecomposition(hermitian=False)
                except (ValueError, ZeroDivisionError):  # not positive definite in the order given: no such form
                    return None
                self._jacobian, self._diagonal = (J * L).applyfunc(sympy.expand), [sympy.cancel(D[i, i]) for i in range(D.shape[0])]
        assert self._diagonal is not None
        return self._jacobian, self._diagonal

    def __call__(self, divisor: sympy.Expr) -> GramVerdict | None:
        """The verdict on ``divisor`` (remembered), or None when it is not recognised as a Gram minor."""
        if divisor not in self._answers:
            if self.budget.left() <= 0:
                return GramVerdict(False, self._out_of_budget())
            try:
                with self.budget.interrupting():
                    self._answers[divisor] = self._decide(divisor)
            except OverBudget:
                return GramVerdict(False, self._out_of_budget())
            except (sympy.PolynomialError, sympy.CoercionFailed, NotImplementedError, ValueError, TypeError,
                    ZeroDivisionError):
                self._answers[divisor] = None  # sympy could not take a step of the proof: no proof, nothing claimed
        return self._answers[divisor]

    def _out_of_budget(self) -> str:
        return (f"the Cauchy-Binet proof for Gram determinants was not tried: its budget ({self.budget.seconds:g} s "
                "of CPU time) ran out")

    def _decide(self, divisor: sympy.Expr) -> GramVerdict | None:
        names = set(self.variables)
        numerator, _ = sympy.fraction(sympy.together(divisor))
        numerator = sympy.expand(numerator)
        if not (numerator.free_symbols & names) or not (numerator.free_symbols & names) <= set(self.coordinates):
            return None  # a Gram minor depends on the coordinates alone
        factors = self._factors()
        if factors is None:
            return None
        J, w = factors
        own = sorted(numerator.free_symbols & names, key=lambda s: s.name)
        try:
            degree = sympy.Poly(numerator, *own).total_degree()
        except sympy.PolynomialError:
            return None
        m = J.shape[0]
        tried = 0
        for k in range(1, min(m, GRAM_ROWS) + 1):
            for K in itertools.combinations(range(m), k):
                tried += 1
                if tried > GRAM_SUBSETS:
                    return None
                rows, det, variables, det_degree = self._gram_minor(K)
                if det == 0 or variables != set(own) or det_degree != degree or not self._same_ratio(numerator, det):
                    continue  # the random point already tells them apart: no cancel of two long polynomials
                ratio = sympy.cancel(numerator / det)
                if ratio != 0 and not ratio.free_symbols & names:
                    if K not in self._verdicts:
                        self._verdicts[K] = self._certify(rows, w)
                    return self._verdicts[K]
        return None

    def _gram_minor(self, K: tuple[int, ...]) -> tuple[sympy.Matrix, sympy.Expr, set, int]:
        """``(J_K, det(J_K W J_K^T) expanded, its variables, its total degree)``, computed once per row set ``K``."""
        if K not in self._minors:
            factors = self._factors()
            assert factors is not None
            J, w = factors
            rows = J.extract(list(K), list(range(J.shape[1])))
            # J_K W J_K^T with W diagonal: the columns of J_K scaled by their weights (no n x n matrix W)
            weighted = sympy.Matrix(rows.shape[0], rows.shape[1], lambda i, s: rows[i, s] * w[s])
            gram = (weighted * rows.T).applyfunc(sympy.expand)
            try:  # in the polynomial ring: a tenth of the time of sympy's Berkowitz on expressions
                matrix = DomainMatrix.from_Matrix(gram)
                det = sympy.expand(matrix.domain.to_sympy(matrix.det()))
            except (sympy.polys.polyerrors.PolynomialError, NotImplementedError, ValueError):
                det = sympy.expand(gram.det(method="berkowitz"))
            names = set(self.variables)
            variables = det.free_symbols & names
            try:
                degree = sympy.Poly(det, *sorted(variables, key=lambda v: v.name)).total_degree() if variables else 0
            except sympy.PolynomialError:
                degree = -1
            self._minors[K] = (rows, det, variables, degree)
        return self._minors[K]

    def _same_ratio(self, a: sympy.Expr, b: sympy.Expr) -> bool:
        """Whether ``a/b`` takes one value at two random rational points of phase space (the parameters at one
        random value): a necessary condition for a ratio free of the variables."""
        names = set(self.variables)
        symbols = sorted(a.free_symbols | b.free_symbols, key=lambda v: v.name)
        rng = random.Random(len(symbols))
        fixed = {v: sympy.Rational(rng.randint(2, 97), rng.randint(2, 97)) for v in symbols if v not in names}
        ratios = []
        for _ in range(2):
            point = {**fixed, **{v: sympy.Rational(rng.randint(-97, 97), rng.randint(2, 97)) for v in symbols if v in names}}
            den = b.xreplace(point)
            if den == 0:
                return True  # undecided here: the exact test decides
            ratios.append(a.xreplace(point) / den)
        return ratios[0] == ratios[1]

    def _certify(self, rows: sympy.Matrix, w: list[sympy.Expr]) -> GramVerdict:
        """Cauchy–Binet on ``det(J_K W J_K^T)``: positive weights and one group constant nonzero on the surface."""
        k, n = rows.shape
        if not all(symbol.is_real for symbol in rows.free_symbols):
            return GramVerdict(False, "it is a Gram determinant det(J W J^T) whose Jacobian J has entries not known "
                                      "to be real (the squares det(J_KS)^2 need real entries)")
        columns = [s for s in range(n) if w[s] != 0]
        if len(columns) < k:
            return GramVerdict(False, "it is a Gram determinant det(J W J^T) with fewer positive weights than rows")
        count = 1
        for i in range(k):
            count = count * (len(columns) - i) // (i + 1)
        if count > GRAM_TERMS:
            return GramVerdict(False, f"it is a Gram determinant det(J W J^T) of {count} Cauchy-Binet terms, more than "
                                      f"the {GRAM_TERMS} the proof expands")
        # a column's class: its weight and the rows of J_K it enters (the bobs of a chain of equal masses share
        # a weight, but the terms taking one column of each bob add up to |r1|^2 |d|^2, constant on the surface)
        kind = {s: (w[s], tuple(r for r in range(k) if rows[r, s] != 0)) for s in columns}
        groups: dict[sympy.Expr, sympy.Expr] = {}  # weight product -> sum of its squares
        classes: dict[tuple, sympy.Expr] = {}  # column classes -> sum of their squares (a finer grouping)
        for S in itertools.combinations(columns, k):
            minor = sympy.expand(rows.extract(list(range(k)), list(S)).det(method="berkowitz"))
            if minor == 0:
                continue
            if minor.has(sympy.I):
                return GramVerdict(False, "it is a Gram determinant det(J W J^T) whose Jacobian J is not real")
            weight = sympy.Mul(*(w[s] for s in S))
            square = sympy.expand(minor**2)
            groups[weight] = groups.get(weight, sympy.S.Zero) + square
            key = tuple(sorted((kind[s] for s in S), key=str))
            classes[key] = classes.get(key, sympy.S.Zero) + square
        if not groups:
            return GramVerdict(False, "it is a Gram determinant det(J W J^T) with no nonzero Cauchy-Binet term")
        reference = next(iter(groups))
        unknown = [weight for weight in groups if not _positive(sympy.cancel(weight / reference))]
        if unknown:
            shown = ", ".join(str(u) for u in [reference, *unknown][:4])
            return GramVerdict(False, (
                f"its numerator is a Gram determinant det(J W J^T), by Cauchy-Binet a sum of squares with weights, but "
                f"the weights {shown} are not known to have one sign (declare the parameters positive, "
                "sympy.Symbol(name, positive=True), or fix their values, --param NAME=VALUE, to have it proven)"))
        # every group is a sum of squares >= 0 times a weight of one sign: one group nonzero on the surface suffices
        candidates = dict.fromkeys(sorted([*classes.values(), *groups.values()], key=_size))  # small first
        for total in candidates:
            if _size(total) > GROUP_TERMS:
                break  # factoring a long sum costs more than it promises
            if self._constant_nonzero(total):
                return GramVerdict(True)
        return GramVerdict(False, (
            "its numerator is a Gram determinant det(J W J^T), by Cauchy-Binet a sum of squares with weights of one "
            "sign, but no group of its terms is proven a nonzero constant on the surface"))

    def _polynomial_surface(self) -> list[sympy.Expr]:
        """The constraints without functions such as ``sin(w t)``: the identities ``c + sum a_i phi_i`` are sought
        modulo these (fewer constraints, the same surface or a larger one: still a proof)."""
        key = ("polynomial surface",)
        if key not in self._memo:
            self._memo[key] = [c for c in self.surface if not c.atoms(sympy.Function)]
        return self._memo[key]

    def _constant_nonzero(self, total: sympy.Expr) -> bool:
        """Whether a sum of squares is a nonzero constant on the surface, factor by factor."""
        names = set(self.variables)
        try:
            coefficient, listed = sympy.factor_list(sympy.expand(total))
        except (sympy.PolynomialError, sympy.CoercionFailed, NotImplementedError):
            return False
        if coefficient == 0:
            return False
        for factor, _ in listed:
            if not factor.free_symbols & names:
                if factor == 0:
                    return False
                continue
            surface = self._polynomial_surface()
            value = constant_on_surface(factor, surface, self.variables, self._memo)
            if value is not None and value != 0:
                continue
            if sum_of_squares_on_surface(factor, surface, self.variables, self._memo):
                continue
            return False
        return True


def _positive(expr: sympy.Expr) -> bool:
    """Whether ``expr`` (numbers and parameters) is positive, each parameter nonzero (as the analysis reads
    them: at generic values; a weight of ``W = d^2 H_c/dp^2`` holds it in a denominator, ``1/m``)."""
    if expr.is_positive:
        return True
    nonzero = {s: sympy.Dummy(s.name, real=True, nonzero=True) for s in expr.free_symbols
               if s.is_real and s.is_zero is None}
    return bool(nonzero) and expr.xreplace(nonzero).is_positive is True


def _size(expr: sympy.Expr) -> int:
    """The number of terms of ``expr``, a sum of expanded squares (so itself expanded)."""
    return len(sympy.Add.make_args(expr))
