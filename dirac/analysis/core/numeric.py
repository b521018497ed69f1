"""Numerical decisions of the symbolic engine: points on constraint surfaces, weak zeros, ranks.

The Dirac–Bergmann algorithm keeps its expressions exact, but deciding whether an
expression vanishes *weakly* (on the surface of the constraints found so far), whether
constraints are independent, and what rank a bracket matrix has on the surface is done
numerically at several random points of that surface (probabilistic identity testing):
an expression that vanishes at independent random points of an irreducible surface
vanishes on it, up to an event of probability zero. Points are found by Gauss–Newton
projection (minimum-norm steps) of random points, with compiled residuals and
Jacobians; with ``regular=k`` only regular points are kept (the first ``k``
constraints' gradients independent there), so that no rank is read at a crossing or
another singular point. Parameters that are still symbolic take generic random values
for these decisions, so the answers hold for generic parameters (the values where
they do not are found by :mod:`dirac.analysis.chain.special_values`).
"""

from __future__ import annotations

from collections.abc import Callable, Mapping, Sequence
from functools import partial
from typing import TYPE_CHECKING, Any, Protocol

import numpy as np
import sympy

from dirac.analysis.core.budget import cpu_clock
from dirac.analysis.core.graphs import issparse
from dirac.analysis.core.phase_space import PhaseSpace, free_symbols_of
from dirac.analysis.core.scaled_function import BOTH, ScaledFunction, scaled_function, terms_of
from dirac.analysis.core.sparse_numeric import independent_rows_eliminated, independent_rows_one_pass
from dirac.analysis.core.sparse_surface import LARGE_SYSTEM, SparseJacobian
from dirac.codegen import UnsupportedExpression, array_function
from dirac.errors import AnalysisError

if TYPE_CHECKING:  # scipy.sparse is imported where it is used (large systems)
    import scipy.sparse as sp

__all__ = ["Numerics", "RankTest", "SingularSurface", "numeric_rank", "independent_rows"]

#: values of scaled batches kept from their term-size calls (:meth:`Numerics._call`), at most this many numbers
KEPT_VALUES = 100_000
#: relative size below which a value counts as zero
ZERO_TOLERANCE = 1e-8
#: residual (relative to the constraint's own term sizes) of a converged surface point
SURFACE_TOLERANCE = 1e-11
#: smallest singular value of the row-normalised constraint Jacobian at a regular point
REGULAR_TOLERANCE = 1e-6
#: a gradient smaller than this, relative to the size of its terms (``1 + sum |term|``), is
#: vanishing: the point is on a singular locus (a crossing ``x^2 - y^2 = 0`` at the origin),
#: however independent the row-normalised gradients look there (at a converged point next
#: to such a locus the gradient is of the order of the square root of the residual, ~1e-6)
SINGULAR_GRADIENT = 1e-4
#: rows (candidates and base together) from which independence is decided in one pass
LARGE_ROWS = 64


class RankTest(Protocol):
    """A matrix whose rank is read at surface points (:mod:`dirac.analysis.core.rank_loci`)."""

    def near_rank_drop(self, z: np.ndarray) -> tuple[float, str] | None:
        """How close ``z`` is to a locus where the rank drops (a singular value and the matrix's name), or ``None``."""


class SingularSurface(AnalysisError):
    """Points of a constraint surface were found, but none is regular (irregular constraints)."""


def numeric_rank(matrix: np.ndarray, tol: float = 1e-8, scale: float | None = None) -> int:
    """Rank of ``matrix`` by SVD: the number of singular values ``s_i > tol * max(s_1, scale)``.

    Parameters
    ----------
    matrix
        The values.
    tol
        Relative cut.
    scale
        Size of the terms the entries were computed from (e.g. ``max`` of
        :meth:`Numerics.term_scale` over the entries), before they cancelled. Without it
        the cut is relative to the largest singular value ``s_1`` alone, so a matrix of
        pure round-off (``1e-16`` left where exact terms cancelled) would count as rank
        ``>= 1``; with it, such a matrix has rank 0 (Golub & Van Loan, *Matrix
        Computations*, Sect. 5.4.1: numerical rank relative to the size of the data's errors).
    """
    if matrix.size == 0:
        return 0
    if not np.all(np.isfinite(matrix)):
        raise AnalysisError(
            "a rank was needed where the expressions are not finite (a denominator vanishes at a sample "
            "point of the constraint surface): the analysis cannot decide it there"
        )
    s = np.linalg.svd(matrix, compute_uv=False)
    if s[0] == 0 or not np.isfinite(s[0]):
        return 0
    return int(np.sum(s > tol * max(s[0], scale or 0.0)))


#: at most this many column sets are tried by :func:`columns_invertible_everywhere`
COLUMN_SETS = 5000
#: ... and only among at most this many columns (a search, not a method for large systems)
COLUMN_SEARCH = 24


def columns_invertible_everywhere(matrices: Sequence[np.ndarray], rows: Sequence[int], order: Sequence[int] | None = None) -> list[int]:
    """Columns ``Q`` with ``m[rows, Q]`` square and invertible at every point, or ``[]``.

    :func:`independent_rows` keeps a column when it raises the rank at a majority of the
    points. When the rows have full rank at every point but the columns that carry it differ
    from point to point (half the points need one column, half another), the majority
    choice finds too few. Here the column sets of the right size are tried in
    lexicographic order of ``order`` (the preference; all columns by default; at most
    ``COLUMN_SETS`` sets, among at most ``COLUMN_SEARCH`` columns) and the first one of full
    rank at every point is returned, so that the multipliers are solved from the same
    columns everywhere.
    """
    from itertools import combinations, islice

    rows = list(rows)
    if not rows or not len(matrices):
        return []
    blocks = [np.asarray(m)[rows] for m in matrices]
    scales = [(np.max(np.abs(b)) or 1.0) for b in blocks]
    preference = list(order) if order is not None else list(range(blocks[0].shape[1]))
    if len(preference) > COLUMN_SEARCH:
        return []
    for columns in islice(combinations(preference, len(rows)), COLUMN_SETS):
        if all(numeric_rank(b[:, list(columns)] / s) == len(rows) for b, s in zip(blocks, scales)):
            return list(columns)
    return []


def unit_rows(rows: np.ndarray) -> np.ndarray:
    """``rows`` each divided by its length (a zero or non-finite row is left as it is).

    Rows already kept as independent enter a rank decision at unit length: the numerical
    rank is relative to the largest singular value, and a kept row far shorter than the row
    being tested counted as nearly zero. Whether a constraint is new must not depend on the
    constant factors the constraints carry (``chi`` and ``10^6 chi`` are one surface): a
    stage-4 gradient ``5e5 dq1 - 0.5 dlambda`` (near a pole of its coefficients) beside the
    kept ``dq1`` made the stack's smallest singular value ``2e-12`` of its largest, and the
    condition ``lambda = 0`` was dropped as dependent (Golub & Van Loan, *Matrix
    Computations*, Sect. 3.5.2: row equilibration).
    """
    norms = np.linalg.norm(rows, axis=1, keepdims=True)
    safe = np.where((norms > 0.0) & np.isfinite(norms), norms, 1.0)
    return rows / safe


def independent_rows(
    matrices: Sequence[Any], order: Sequence[int], base: Sequence[Any] | None = None, notes: list[str] | None = None,
    equilibrate: bool = False,
) -> list[int]:
    """Greedy choice of rows that raise the rank, in the given order of preference.

    Parameters
    ----------
    matrices
        The same symbolic matrix evaluated at several surface points.
    order
        Row indices in order of preference.
    base
        Rows already chosen (one block per point) that every candidate must be
        independent of.

    notes
        Where a note is added when sparse rows could not be decided by elimination.
    equilibrate
        Rows of gradients of constraints: the rows already kept enter each decision at unit
        length (:func:`unit_rows`), so that the constant factors the constraints carry do
        not decide whether a new one is independent (dense path).

    Returns
    -------
    list of int
        Chosen row indices; a row is kept when it raises the rank at a majority of points.

    Sparse matrices (``scipy.sparse``, rows of a local system) are decided by sparse
    elimination (:func:`~dirac.analysis.core.sparse_numeric.independent_rows_eliminated`);
    where a reduced row is neither clearly zero nor clearly not at some point, by the dense
    pass below, with a note. Large dense matrices (rows from ``LARGE_ROWS`` or columns from ``LARGE_SYSTEM``) are decided
    in one orthogonalisation pass per point
    (:func:`~dirac.analysis.core.sparse_numeric.independent_rows_one_pass`), not one SVD per row.
    """
    if len(matrices) and issparse(matrices[0]):
        eliminated = independent_rows_eliminated(matrices, order, base)
        if eliminated is not None:
            return eliminated
        if notes is not None:
            notes.append(
                "independence of rows: sparse elimination met a row neither clearly dependent nor clearly "
                "independent at a sample point, so that choice was made on the dense path (orthogonalisation)"
            )
        matrices = [m.toarray() for m in matrices]
        base = [b.toarray() if issparse(b) else b for b in base] if base is not None else None
    if len(matrices) and matrices[0].ndim == 2 and (
        len(order) + (len(base[0]) if base is not None else 0) >= LARGE_ROWS or matrices[0].shape[1] >= LARGE_SYSTEM
    ):
        return independent_rows_one_pass(matrices, order, base)
    chosen: list[int] = []
    for row in order:
        votes = 0
        for k, m in enumerate(matrices):
            stack = [m[chosen]] if chosen else []
            if base is not None and len(base[k]):
                stack.insert(0, base[k])
            current = np.vstack(stack) if stack else np.zeros((0, m.shape[1]))
            scale = (np.max(np.abs(m)) if m.size else 0.0) or 1.0  # an all-zero matrix has rank 0, not NaN
            if equilibrate:  # the kept rows at unit length, the new one relative to its matrix (round-off stays small)
                current = unit_rows(current)
                before = numeric_rank(current) if len(current) else 0
                after = numeric_rank(np.vstack([current, m[row : row + 1] / scale]))
            else:
                before = numeric_rank(current / scale) if len(current) else 0
                after = numeric_rank(np.vstack([current, m[row : row + 1]]) / scale)
            votes += after > before
        if 2 * votes > len(matrices):
            chosen.append(row)
    return chosen


#: evaluation plans (and term splits) a :class:`Numerics` keeps (:meth:`Numerics.function`); past it, plans are made anew
PLAN_CACHE = 4096

#: relative size below which an expression assumed nonzero counts as vanishing at a point
AVOID_TOLERANCE = 1e-6


class Numerics:
    """Lambdified evaluation, surface points and weak-zero tests for one phase space.

    Parameters
    ----------
    phase_space
        The canonical phase space (its :attr:`~PhaseSpace.variables` order the vectors).
    parameter_values
        Numbers for the parameters that are still symbolic.
    seed
        Seed of the random points (results are reproducible).
    time
        The time ``t`` of an explicitly time-dependent system (``None`` otherwise). It is
        sampled like a variable: every point carries its own random ``t`` as one extra
        last component (after :attr:`~PhaseSpace.variables`), which surface projections
        hold fixed (a point of the surface at that time).
    """

    def __init__(
        self,
        phase_space: PhaseSpace,
        parameter_values: Mapping[sympy.Symbol, float],
        seed: int = 20240607,
        time: sympy.Symbol | None = None,
    ):
        self.phase_space = phase_space
        self.time = time
        self.parameters = tuple(phase_space.parameters)
        self.parameter_vector = np.array([float(parameter_values[p]) for p in self.parameters], dtype=float)
        self.rng = np.random.default_rng(seed)
        self._index: dict[sympy.Expr, tuple[int, int]] = {}
        self._batches: list[Callable] = []
        #: batch -> positions in ``(z, parameters)`` of the arguments it takes, when not all of them
        self._picks: dict[int, np.ndarray] = {}
        #: batches compiled by :func:`scaled_function`: they also give their expressions' term sizes
        self._scaled: dict[int, ScaledFunction] = {}
        #: evaluation plans of expression lists met before (:meth:`function`), and their split into terms (:meth:`term_scale`)
        self._plans: dict[tuple, Callable[[np.ndarray], np.ndarray]] = {}
        self._terms: dict[tuple, tuple[list[sympy.Expr], np.ndarray]] = {}
        self._scale_plans: dict[tuple, tuple[list[int], list[tuple[int, np.ndarray, np.ndarray]]]] = {}
        self._jacobians: dict[tuple, _DenseJacobian] = {}
        #: (batch, arguments) -> values of a scaled batch computed together with its term sizes
        #: (:meth:`_call`): the values asked next at the same point are not computed again
        self._values_with_sizes: dict[tuple, Any] = {}
        self._kept = 0  # numbers held in it
        self._args = (*phase_space.variables, *([time] if time is not None else []), *self.parameters)
        self._arg_set = frozenset(self._args)
        #: expressions assumed nonzero (``--assume "EXPR != 0"``): surface points near their zeros are rejected
        self.avoid: list[sympy.Expr] = []
        #: indices of variables that projections hold two of at their start values (:meth:`_held_variables`)
        self.hold: tuple[int, ...] = ()
        #: what the analysis should tell the user about its sample points (points kept next to a rank-drop locus)
        self.notes: list[str] = []

    def sharing_compiled(self, parameter_values: Mapping[sympy.Symbol, float], seed: int) -> Numerics:
        """A new instance at other parameter values that shares this one's compiled functions.

        The parameters are arguments of the compiled functions, so the expressions this
        instance compiled are not compiled again (the special-value scan evaluates the
        analysis' own matrices at other parameter values). Everything else starts as in a
        new instance: the random points from ``seed``, no expressions to avoid, no held
        variables, no notes.
        """
        other = Numerics(self.phase_space, parameter_values, seed=seed, time=self.time)
        other._index, other._batches, other._scaled, other._picks = self._index, self._batches, self._scaled, self._picks
        return other

    # ------------------------------------------------------------------ compiled functions
    def function(self, exprs: Sequence[sympy.Expr], key: object | None = None) -> Callable[[np.ndarray], np.ndarray]:
        """Compile ``exprs`` into ``f(z) -> array`` (expressions compiled once, in batches).

        The evaluation plan of a list of expressions met before (the same expressions in
        the same order, as the projections onto one surface ask again and again) is
        reused: only the values are computed again.
        """
        exprs = [e if isinstance(e, sympy.Basic) else sympy.sympify(e) for e in exprs]
        plan_key = tuple(exprs)
        fn = self._plans.get(plan_key)
        if fn is None:
            fn = self._plan(exprs)
            if len(self._plans) < PLAN_CACHE:
                self._plans[plan_key] = fn
        return fn

    def _plan(self, exprs: list[sympy.Expr]) -> Callable[[np.ndarray], np.ndarray]:
        """``f(z) -> array`` of ``exprs``: the compiled batches' values gathered by index arrays."""
        zero = sympy.S.Zero  # most entries of a large gradient or bracket matrix: no conversion
        self._compile([e for e in exprs if e is not zero])
        # (batch, index in it) of a compiled expression, (None, value) of a number; every
        # expression that is not a number is in the index after ``_compile`` (``is_number``
        # walks the whole tree, so it is asked only of what the index does not hold)
        index = self._index
        plan: list[tuple[int | None, Any]] = [
            (None, 0.0) if e is zero else (index.get(e) or (None, float(e))) for e in exprs
        ]
        constant = np.array([0.0 if b is not None else i for b, i in plan], dtype=float)
        gathers = [
            (b, np.array([k for k, (c, _) in enumerate(plan) if c == b], dtype=np.intp),
             np.array([i for c, i in plan if c == b], dtype=np.intp))
            for b in sorted({b for b, _ in plan if b is not None})
        ]

        def fn(z: np.ndarray) -> np.ndarray:
            out = constant.copy()
            for b, where, picks in gathers:
                out[where] = self._call(b, z)[picks]
            return out

        return fn

    def _compile(self, exprs: Sequence[sympy.Expr]) -> None:
        index = self._index
        missing = list(dict.fromkeys(e for e in exprs if e not in index and not e.is_number))
        if not missing:
            return
        raw: Callable
        batch = len(self._batches)
        arguments = self._args
        # a batch takes the arguments its expressions hold: one Gauss law of a 256-site lattice held all
        # 1,024 phase-space variables as arguments, and each of its thousands of calls passed them all
        # (work quadratic in the size); a symbol that is no argument keeps them all (the error as before)
        used = free_symbols_of(missing, self.phase_space._free)  # the phase space's memo: nodes walked once
        if used <= self._arg_set and len(used) < len(arguments):
            positions = [k for k, a in enumerate(arguments) if a in used]
            arguments = tuple(arguments[k] for k in positions)
            self._picks[batch] = np.asarray(positions, dtype=np.intp)
        try:
            scaled = scaled_function(arguments, missing)
            raw = partial(scaled, False)
            self._scaled[batch] = scaled
        except UnsupportedExpression:  # an unusual function: evaluate with numpy instead
            raw = array_function(arguments, missing)
        self._batches.append(raw)
        for i, e in enumerate(missing):
            self._index[e] = (batch, i)

    def _call(self, batch: int, z: np.ndarray, sizes: bool = False) -> np.ndarray:
        """The values of one compiled batch at ``z`` (real parts of complex values), or with ``sizes`` its term sizes.

        Term sizes are computed together with the values (one pass through the batch's
        body, :data:`~dirac.analysis.core.scaled_function.BOTH`); the values are kept for
        the last few points, so that a caller asking for the sizes and then the values at
        the same points (:meth:`term_scale`, then :meth:`evaluate`) pays for the body once.
        The values are the same numbers either way (the same code).
        """
        z = np.asarray(z, dtype=float)
        pick = self._picks.get(batch)
        if pick is None:
            args = [*z.tolist(), *self.parameter_vector.tolist()]
        else:
            args = np.concatenate((z, self.parameter_vector))[pick].tolist()
        if batch in self._scaled:  # Python floats through math: nothing for numpy to warn about
            key = (batch, z.tobytes(), self.parameter_vector.tobytes())  # bit-exact (0.0 and -0.0 differ)
            if sizes:
                values, out = self._scaled[batch](BOTH, *args)
                kept = self._values_with_sizes
                if self._kept + len(values) > KEPT_VALUES:
                    kept.clear()
                    self._kept = 0
                kept[key] = values
                self._kept += len(values)
            else:
                out = self._values_with_sizes.get(key)
                if out is None:
                    out = self._batches[batch](*args)
            try:
                return np.array(out, dtype=float)
            except TypeError:  # a complex value: its real part, below
                pass
        else:
            with np.errstate(all="ignore"):
                out = self._batches[batch](*args)
        try:
            values = np.asarray(out)
            if values.dtype.kind == "c":  # a complex value (a root of a negative number): its real part
                values = values.real
            return values.astype(float)
        except (TypeError, ValueError):
            return np.array([complex(v).real if isinstance(v, complex) else float(v) for v in out], dtype=float)

    def evaluate(self, exprs: Sequence[sympy.Expr], points: Sequence[np.ndarray] | np.ndarray) -> np.ndarray:
        """Values of ``exprs`` at each point: array of shape ``(len(points), len(exprs))``."""
        fn = self.function(exprs)
        return np.array([fn(z) for z in points], dtype=float).reshape(len(points), len(exprs))

    def sparse_gradients(self, exprs: Sequence[sympy.Expr], points: Sequence[np.ndarray]) -> list[sp.csr_matrix]:
        """The gradients of ``exprs`` (rows, in the order of the phase-space variables) at each point, as sparse matrices.

        Only the non-zero partial derivatives are compiled and evaluated: ``O(non-zeros)``
        for the constraints of a local system, instead of ``len(exprs)`` times the dimension.
        """
        jacobian = SparseJacobian(self, [sympy.sympify(e) for e in exprs], REGULAR_TOLERANCE, SINGULAR_GRADIENT)
        return [jacobian(z) for z in points]

    def term_scale(self, exprs: Sequence[sympy.Expr], points: Sequence[np.ndarray]) -> np.ndarray:
        """Size of each expression's terms at each point: ``1 + sum |term|`` (for relative zero tests).

        The terms are added in their order (``((1 + |t_1|) + |t_2|) + ...``). An expression
        compiled by :func:`~dirac.analysis.core.scaled_function.scaled_function` gives its
        term sizes from the same compiled function as its value; only the others' terms are
        compiled on their own.
        """
        exprs = [e if isinstance(e, sympy.Basic) else sympy.sympify(e) for e in exprs]
        plan = self._scale_plans.get(tuple(exprs))
        if plan is None:
            plan = self._scale_plan(exprs)
            if len(self._scale_plans) < PLAN_CACHE:
                self._scale_plans[tuple(exprs)] = plan
        rest, gathers = plan
        if not gathers:
            return self._term_scale(exprs, points)
        scale = np.ones((len(points), len(exprs)))
        if rest:
            scale[:, rest] = self._term_scale([exprs[k] for k in rest], points)
        for row, z in enumerate(points):
            for b, where, picks in gathers:
                scale[row, where] = self._call(b, z, sizes=True)[picks]
        return scale

    def _scale_plan(self, exprs: list[sympy.Expr]) -> tuple[list[int], list[tuple[int, np.ndarray, np.ndarray]]]:
        """How :meth:`term_scale` gathers the sizes of ``exprs``: ``(rest, gathers)``, built once per list of expressions.

        ``gathers`` holds ``(batch, positions, indices in the batch)`` of the expressions
        compiled by :func:`~dirac.analysis.core.scaled_function.scaled_function` (empty when
        none is), ``rest`` the positions of the others. Both depend only on where each
        expression was compiled, which never changes once it is; the Newton steps of
        :meth:`surface_points` ask for the sizes of the same constraints at every converged
        point (779 times in the 400-point walk of (228)'s Legendre transform), and the plan
        is no longer rebuilt each time.
        """
        zero = sympy.S.Zero
        self._compile([e for e in exprs if e is not zero])
        index, scaled = self._index, self._scaled
        fused: dict[int, tuple[int, int]] = {}  # position -> (batch, index in it) of a scaled batch
        for k, e in enumerate(exprs):
            at = index.get(e)
            if at is not None and at[0] in scaled:
                fused[k] = at
        rest = [k for k in range(len(exprs)) if k not in fused]
        gathers = [
            (b, np.array([k for k, (c, _) in fused.items() if c == b], dtype=np.intp),
             np.array([i for c, i in fused.values() if c == b], dtype=np.intp))
            for b in sorted({c for c, _ in fused.values()})
        ]
        return rest, gathers

    def _term_scale(self, exprs: list[sympy.Expr], points: Sequence[np.ndarray]) -> np.ndarray:
        """:meth:`term_scale` from the terms compiled as expressions of their own."""
        split = self._terms.get(tuple(exprs))
        if split is None:
            terms: list[sympy.Expr] = []
            owner: list[int] = []
            for k, e in enumerate(exprs):
                parts = terms_of(e)
                terms.extend(parts)
                owner.extend([k] * len(parts))
            split = (terms, np.asarray(owner, dtype=np.intp))
            if len(self._terms) < PLAN_CACHE:
                self._terms[tuple(exprs)] = split
        terms, owners = split
        values = np.abs(self.evaluate(terms, points)) if terms else np.zeros((len(points), 0))
        scale = np.ones((len(points), len(exprs)))
        # unbuffered, in the order of the terms: the same sums as adding them one by one
        np.add.at(scale.T, owners, values.T)
        return scale

    def weakly_zero(self, exprs: Sequence[sympy.Expr], points: Sequence[np.ndarray]) -> np.ndarray:
        """Boolean mask: which expressions vanish at every given (surface) point.

        A value counts as zero when it is below ``ZERO_TOLERANCE`` times the size of the
        expression's terms there; values above ``1e-6`` count as non-zero at once.
        """
        exprs = [sympy.sympify(e) for e in exprs]
        mask = np.array([e == 0 for e in exprs], dtype=bool)
        rest = [k for k, e in enumerate(exprs) if e != 0]
        if rest and len(points):
            values = self.evaluate([exprs[k] for k in rest], points)
            finite = np.all(np.isfinite(values), axis=0)
            big = np.any(np.abs(values) > 1e-6, axis=0) | ~finite
            unclear = [j for j in range(len(rest)) if not big[j]]
            if unclear:
                sub = [exprs[rest[j]] for j in unclear]
                scale = self.term_scale(sub, points)
                small = np.all(np.abs(values[:, unclear]) <= ZERO_TOLERANCE * scale, axis=0)
                for j, flag in zip(unclear, small):
                    mask[rest[j]] = bool(flag)
        return mask

    # ------------------------------------------------------------------ surface points
    @staticmethod
    def _regular_point(jacobian: np.ndarray) -> bool:
        """Whether the rows of ``jacobian`` (constraint gradients at a point) are independent.

        Each row is scaled to unit length (constraints may be multiplied by any non-zero
        function), then the smallest singular value must exceed ``REGULAR_TOLERANCE``.
        """
        if not np.all(np.isfinite(jacobian)):
            return False
        norms = np.linalg.norm(jacobian, axis=1)
        if np.any(norms == 0):
            return False
        s = np.linalg.svd(jacobian / norms[:, None], compute_uv=False)
        return bool(s[-1] > REGULAR_TOLERANCE) if len(s) == jacobian.shape[0] else False

    def _vanishing_gradient(self, gradients: Sequence[sympy.Expr], jacobian: np.ndarray, z: np.ndarray) -> bool:
        """Whether a constraint's gradient (a row of ``jacobian``) is vanishing at ``z`` relative to its terms.

        Row normalisation in :meth:`_regular_point` hides a gradient that is small only
        because the point lies next to where it vanishes; here each row's length is
        compared with ``1 + sum |term|`` of its entries (``gradients``, flattened row by
        row), below ``SINGULAR_GRADIENT`` the point is singular (Henneaux–Teitelboim,
        Sect. 1.1.2: regular points have non-vanishing independent gradients).
        """
        k, n = jacobian.shape
        scales = self.term_scale(gradients, [z])[0].reshape(k, n)
        sizes = np.linalg.norm(jacobian, axis=1) / (1.0 + np.sum(scales - 1.0, axis=1))
        return bool(np.any(sizes < SINGULAR_GRADIENT))

    def random_point(self) -> np.ndarray:
        """A random phase-space point with components of size 0.5-1.5 and random signs (and a time ``t``)."""
        n = len(self.phase_space.variables) + (self.time is not None)
        return self.rng.uniform(0.5, 1.5, n) * self.rng.choice([-1.0, 1.0], n)

    def _near_avoided(self, z: np.ndarray) -> bool:
        """Whether an expression assumed nonzero (:attr:`avoid`) vanishes at ``z``.

        ``|e(z)| <= AVOID_TOLERANCE * (1 + sum of |terms of e| at z)``: a point on (or next to)
        the excluded set ``e = 0``, where the ranks are not those of the part assumed.
        """
        scales = self.term_scale(self.avoid, [z])[0]  # first: the values below come with the sizes
        values = self.evaluate(self.avoid, [z])[0]
        return bool(np.any(np.abs(values) <= AVOID_TOLERANCE * scales))

    def _held_variables(self, free: np.ndarray) -> np.ndarray:
        """Variables held at their random start values in this projection (none unless :attr:`hold`).

        Gauss–Newton steps on homogeneous conditions (``A_2 x (A_1 x A_2) = 0``) shrink the
        point towards the origin of their variables, where such conditions are singular. With
        :attr:`hold` (indices of those variables, set by the chain once its points fell on
        such a locus) each projection holds two of them, chosen at random, at their start
        values, so that the point lands on the regular part of the surface; it passes the
        same tests as any other point.
        """
        if len(self.hold) < 3:
            return np.empty(0, dtype=int)
        choices = np.intersect1d(np.asarray(self.hold, dtype=int), free)
        if choices.size < 3:
            return np.empty(0, dtype=int)
        return self.rng.choice(choices, size=2, replace=False)

    def surface_points(
        self,
        constraints: Sequence[sympy.Expr],
        count: int,
        fixed: Mapping[int, float] | None = None,
        attempts: int = 40,
        start: np.ndarray | None = None,
        regular: int = 0,
        minors: Sequence[RankTest] = (),
        deadline: float | None = None,
    ) -> list[np.ndarray]:
        """``count`` points on the surface ``constraints = 0`` (Gauss–Newton projection).

        Parameters
        ----------
        constraints
            Expressions in the phase-space variables (and symbolic parameters).
        count
            Number of points wanted.
        fixed
            Variable index -> value held fixed; the other variables are solved for.
        attempts
            Random restarts allowed in total before giving up.
        start
            First starting point (random ones follow).
        regular
            The first ``regular`` constraints must have independent gradients at each point
            returned (a full-rank Jacobian, the regularity condition of Henneaux–Teitelboim,
            Sect. 1.1.2): points where they do not (crossings, singular points) are dropped
            and others sampled, so that no decision is taken at a singular point.
        minors
            Matrices whose rank is read at the points: points next to a locus where one
            of their ranks drops (:mod:`dirac.analysis.core.rank_loci`) are set aside and others
            sampled. Gauss–Newton steps onto conditions such as ``p_2 (p_1 - 2) + 4 q_2^2 = 0``
            are drawn towards such loci (there, ``q_2 = 0``), so that half the points can
            fall within ``1e-3`` of one. Only when ``attempts`` run out are the set-aside
            points used, those farthest from the locus first, and a note in :attr:`notes`
            says so.
        deadline
            :func:`~dirac.analysis.core.budget.cpu_clock` past which no further random start is tried (the first
            always is): a search with a CPU-time budget (:func:`~dirac.analysis.core.divisors.singular_loci`).

        Raises
        ------
        AnalysisError
            If no point is found: the surface may be empty (no real solution), or it has
            no regular point (its constraints are irregular).
        """
        constraints = [sympy.sympify(c) for c in constraints]
        residual = self.function(constraints)
        n = len(self.phase_space.variables)
        m = len(constraints)
        jacobian: _DenseJacobian | SparseJacobian | None = None
        if m:  # a large system: sparse Jacobian, steps and rank tests; the same rules otherwise
            if n >= LARGE_SYSTEM:
                jacobian = SparseJacobian(self, constraints, REGULAR_TOLERANCE, SINGULAR_GRADIENT)
            else:  # the same surface is projected onto again and again: its Jacobian is built once
                jacobian = self._jacobians.get(tuple(constraints))
                if jacobian is None:
                    jacobian = _DenseJacobian(self, constraints)
                    if len(self._jacobians) < PLAN_CACHE:
                        self._jacobians[tuple(constraints)] = jacobian
        fixed = dict(fixed or {})
        free = np.array([i for i in range(n) if i not in fixed], dtype=int)
        points: list[np.ndarray] = []
        near: list[tuple[float, np.ndarray, str]] = []  # (smallest singular value, point, matrix) set aside
        tries = 0
        singular = 0
        while len(points) < count and tries < attempts:
            if tries and deadline is not None and cpu_clock() > deadline:
                break
            tries += 1
            z = start.copy() if (start is not None and tries == 1) else self.random_point()
            for i, v in fixed.items():
                z[i] = v
            held = self._held_variables(free)
            step_free = np.setdiff1d(free, held) if held.size else free  # free: sorted and distinct already
            if jacobian is None:
                points.append(z)
                continue
            ok = False
            for _ in range(60):
                r = residual(z)
                if not np.all(np.isfinite(r)):
                    break
                size = self.term_scale(constraints, [z])[0] if np.max(np.abs(r)) < 1e-6 else None
                if size is not None and np.all(np.abs(r) <= SURFACE_TOLERANCE * size):
                    ok = True
                    break
                J = jacobian(z)
                if not jacobian.finite(J):
                    break
                step = jacobian.step(J[:, step_free], r)
                norm = np.linalg.norm(step)
                if norm > 10.0:  # keep steps bounded far from the surface
                    step *= 10.0 / norm
                z = z.copy()
                z[step_free] += step
            if ok and regular and jacobian.singular(z, regular):
                singular += 1
                continue
            if ok and self.avoid and self._near_avoided(z):
                continue
            drop = self.near_rank_drop(minors, z) if ok else None
            if drop is not None:
                near.append((drop[0], z, drop[1]))
                continue
            if ok:
                points.append(z)
        if len(points) < count and near:
            near.sort(key=lambda item: -item[0])
            used = near[: count - len(points)]
            points.extend(z for _, z, _ in used)
            self.notes.append(
                f"{len(used)} of {len(points)} sample points on a surface of {m} constraint(s) lie next to a locus where "
                f"the rank of {used[-1][2]} drops (a singular value {used[-1][0]:.1e} relative to the size of its terms): "
                f"no point away from it was found in {attempts} tries; ranks read there are right while that value is "
                "well above round-off, but quantities built on the inverse of that block are ill-conditioned at those points"
            )
        if len(points) < count:
            raise _no_surface_point(constraints, singular)
        return points

    @staticmethod
    def near_rank_drop(minors: Sequence[RankTest], z: np.ndarray) -> tuple[float, str] | None:
        """The smallest ``near_rank_drop`` value of ``minors`` at ``z`` and its matrix's name, or ``None``."""
        found = [drop for m in minors if (drop := m.near_rank_drop(z)) is not None]
        return min(found) if found else None


class _DenseJacobian:
    """The Jacobian of constraints as a dense array, with the dense step and regularity tests
    of :meth:`Numerics.surface_points` (the sparse counterpart: :class:`SparseJacobian`)."""

    def __init__(self, numerics: Numerics, constraints: Sequence[sympy.Expr]) -> None:
        self._numerics = numerics
        self.shape = (len(constraints), len(numerics.phase_space.variables))
        self._flat = [g for c in constraints for g in numerics.phase_space.gradient(c)]
        self._values = numerics.function(self._flat)

    def __call__(self, z: np.ndarray) -> np.ndarray:
        return self._values(z).reshape(self.shape)

    @staticmethod
    def finite(jacobian: np.ndarray) -> bool:
        """Whether every entry is finite."""
        return bool(np.all(np.isfinite(jacobian)))

    @staticmethod
    def step(jacobian: np.ndarray, residual: np.ndarray) -> np.ndarray:
        """The minimum-norm Gauss–Newton step ``dz`` of ``J dz = -r`` (``lstsq``)."""
        return np.linalg.lstsq(jacobian, -residual, rcond=1e-12)[0]

    def singular(self, z: np.ndarray, regular: int) -> bool:
        """Whether the first ``regular`` gradients are dependent, or one of them vanishing, at ``z``."""
        rows = self(z)[:regular]
        return not Numerics._regular_point(rows) or self._numerics._vanishing_gradient(
            self._flat[: regular * self.shape[1]], rows, z)


def _no_surface_point(constraints: list[sympy.Expr], singular: int) -> AnalysisError:
    """The error when too few points were found: none regular among ``singular`` found, or none at all."""
    m = len(constraints)
    names = "; ".join(str(c) for c in constraints[:6])
    if singular:
        return SingularSurface(
            f"the constraint surface ({names}{' ...' if m > 6 else ''}) has no regular point among "
            f"{singular} points found: the gradients of its constraints are dependent wherever they hold "
            "(irregular constraints); write the surface with constraints whose gradients are independent on it"
        )
    return AnalysisError(
        f"could not find points on the constraint surface ({names}{' ...' if m > 6 else ''}) "
        "after many random starts: the constraints may have no real solution for these parameters"
    )

