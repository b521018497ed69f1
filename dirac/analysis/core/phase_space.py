"""The canonical phase space of the extended Lagrangian and its Poisson bracket.

The multipliers of the holonomic constraints are coordinates (the paper's extended
Lagrangian (1)), so the phase space is ``(q, lambda; p_q, p_lambda)`` with the canonical
bracket ``{q_i, p_j} = delta_ij`` used throughout Sect. X ((207)-(209)).
"""

from __future__ import annotations

from collections.abc import Iterable, Mapping, Sequence
from dataclasses import dataclass, field

import sympy

from dirac.analysis.core.fast_partials import PolynomialPartials

__all__ = ["PhaseSpace", "derivative", "free_symbols_of"]


def _free_symbols_memo(expr: sympy.Expr, memo: dict[sympy.Basic, frozenset] | None = None) -> dict[sympy.Basic, frozenset]:
    """Free symbols of every node of ``expr``, each shared sub-tree computed once.

    ``memo`` (filled in place and returned) may already hold other expressions' nodes:
    the sub-trees they share with ``expr`` are not walked again.
    """
    memo = {} if memo is None else memo

    def walk(node: sympy.Basic) -> frozenset:
        hit = memo.get(node)
        if hit is None:
            if node.is_Symbol:
                hit = frozenset((node,))
            elif not node.args:
                hit = frozenset(node.free_symbols)
            else:
                hit = frozenset().union(*(walk(a) for a in node.args))
            memo[node] = hit
        return hit

    walk(expr)
    return memo


def free_symbols_of(exprs: Iterable[sympy.Basic], memo: dict[sympy.Basic, frozenset] | None = None) -> frozenset:
    """The free symbols of all of ``exprs`` (expressions, or the entries of a matrix), each shared sub-tree walked once.

    sympy's ``free_symbols`` walks the expression as a tree: on the unexpanded
    consistency conditions of the rigid body ((228), stage 3), whose entries share
    sub-trees of millions of tree nodes, one ``Matrix.free_symbols`` took tens of seconds.
    Here every node is visited once (:func:`_free_symbols_memo`); pass the same ``memo``
    to several calls over expressions that share sub-trees.
    """
    memo = {} if memo is None else memo
    if isinstance(exprs, sympy.MatrixBase):
        # the non-zero entries only: iterating a matrix reads every entry, one by one (a Hessian of
        # 768 velocities, 590,000 reads of mostly zeros, took 1-3 s of the 16 x 16 torus's analysis)
        exprs = exprs.values()
    found: frozenset = frozenset()
    for expr in exprs:
        found |= _free_symbols_memo(expr, memo)[expr]
    return found


def derivative(
    expr: sympy.Expr,
    x: sympy.Symbol,
    free: dict[sympy.Basic, frozenset] | None = None,
    cache: dict[sympy.Basic, sympy.Expr] | None = None,
) -> sympy.Expr:
    """``d expr / d x`` by the sum, product and power rules on the expression tree.

    The same rules as sympy's ``_eval_derivative`` of ``Add``, ``Mul`` and ``Pow``, so
    the same expression as ``sympy.diff(expr, x)``, but each shared sub-tree is differentiated once and sub-trees free of ``x`` are
    skipped without a walk: on the large unexpanded consistency conditions of the rigid
    body ((228), stage 3) this is several times faster than ``sympy.diff``, which spends
    its time on assumptions and repeated free-symbol walks. Nodes other than sums,
    products, numeric powers and symbols (functions such as ``sin``) go to ``sympy.diff``
    after the chain rule has reached them.

    Parameters
    ----------
    expr
        The expression.
    x
        The symbol.
    free
        Free symbols per node of ``expr`` (from one walk; computed when not given).
    cache
        Derivatives by ``x`` of nodes met before (filled in place): sub-trees shared with
        expressions differentiated earlier (the pieces of ``H_c`` in every consistency
        condition) are differentiated once. The derivative of a node is a function of the
        node alone, so the result is the same with or without it.
    """
    free = _free_symbols_memo(expr) if free is None else free
    cache = {} if cache is None else cache

    def symbols_of(node: sympy.Basic) -> frozenset:
        hit = free.get(node)
        if hit is None:
            hit = frozenset(node.free_symbols)
            free[node] = hit
        return hit

    def d(node: sympy.Basic) -> sympy.Expr:
        if x not in symbols_of(node):
            return sympy.S.Zero
        hit = cache.get(node)
        if hit is not None:
            return hit
        if node is x or node == x:
            out: sympy.Expr = sympy.S.One
        elif node.is_Add:
            out = sympy.Add(*[d(a) for a in node.args])
        elif node.is_Mul:
            args = node.args
            terms = []
            for i, a in enumerate(args):
                da = d(a)
                if da != 0:
                    terms.append(sympy.Mul(*args[:i], da, *args[i + 1 :]))
            out = sympy.Add(*terms)
        elif node.is_Pow and node.exp.is_Number:
            out = node * (d(node.base) * node.exp / node.base)  # sympy's Pow._eval_derivative, d exp = 0
        else:
            out = sympy.diff(node, x)
        cache[node] = out
        return out

    return d(expr)


@dataclass
class PhaseSpace:
    """Canonical coordinates and momenta, with a cached canonical Poisson bracket.

    Parameters
    ----------
    coordinates
        Configuration coordinates: the Lagrangian's ``q`` then the multipliers
        ``lambda_1, ...``.
    momenta
        Their conjugate momenta ``p_q``, ``p_lambda_1``, ... in the same order.
    parameters
        Parameter symbols that are still symbolic (constants under the bracket).
    """

    coordinates: tuple[sympy.Symbol, ...]
    momenta: tuple[sympy.Symbol, ...]
    parameters: tuple[sympy.Symbol, ...] = ()
    _gradients: dict[sympy.Expr, tuple[dict, dict]] = field(default_factory=dict, repr=False)
    _polynomials: PolynomialPartials | None = field(default=None, repr=False)
    #: free symbols of every node met, and derivatives of nodes by each variable (shared by
    #: all expressions differentiated by the tree rules: :func:`derivative`)
    _free: dict[sympy.Basic, frozenset] = field(default_factory=dict, repr=False)
    _derivatives: dict[sympy.Symbol, dict[sympy.Basic, sympy.Expr]] = field(default_factory=dict, repr=False)

    @property
    def variables(self) -> tuple[sympy.Symbol, ...]:
        """``coordinates + momenta``: the order of every numeric phase-space vector (the same tuple each time)."""
        cached = self.__dict__.get("_variables")
        if cached is None or cached[0] is not self.coordinates or cached[1] is not self.momenta:
            cached = (self.coordinates, self.momenta, self.coordinates + self.momenta)
            self.__dict__["_variables"] = cached
        return cached[2]

    @property
    def dimension(self) -> int:
        """Dimension ``2n`` of the phase space."""
        return 2 * len(self.coordinates)

    @property
    def symbols(self) -> dict[str, sympy.Symbol]:
        """Name -> symbol of every phase-space variable (names: docs/conventions.md)."""
        return {s.name: s for s in self.variables}

    def partials(self, expr: sympy.Expr) -> tuple[dict, dict]:
        """Non-zero partial derivatives of ``expr``: ``({q_i: df/dq_i}, {q_i: df/dp_i})``.

        Both dictionaries are keyed by the coordinate, so the bracket pairs them up.
        Results are cached (constraints are differentiated many times). Polynomials in
        the variables are differentiated in the sparse polynomial ring
        (:mod:`dirac.analysis.core.fast_partials`, the same derivatives, expanded), other
        expressions by ``sympy.diff``.
        """
        expr = sympy.sympify(expr)
        cached = self._gradients.get(expr)
        if cached is not None:
            return cached
        if self._polynomials is None:
            self._polynomials = PolynomialPartials(self.variables, self.parameters)
        found = self._polynomials.partials(expr, self._polynomials.variables)
        if found is not None:
            coordinate_of = self._coordinate_of()  # (coordinate, whether the variable is a momentum)
            fast = ({coordinate_of[s][0]: d for s, d in found.items() if not coordinate_of[s][1]},  # ordered as the variables
                    {coordinate_of[s][0]: d for s, d in found.items() if coordinate_of[s][1]})
            self._gradients[expr] = fast
            return fast
        free = _free_symbols_memo(expr, self._free)
        dq: dict = {}
        dp: dict = {}
        for q, p in zip(self.coordinates, self.momenta):
            if q in free[expr]:
                d = derivative(expr, q, free, self._derivatives.setdefault(q, {}))
                if d != 0:
                    dq[q] = d
            if p in free[expr]:
                d = derivative(expr, p, free, self._derivatives.setdefault(p, {}))
                if d != 0:
                    dp[q] = d
        self._gradients[expr] = (dq, dp)
        return dq, dp

    def _coordinate_of(self) -> dict[sympy.Symbol, tuple[sympy.Symbol, bool]]:
        """Each variable -> its coordinate and whether it is a momentum (``q -> (q, False)``, ``p_q -> (q, True)``)."""
        found = self.__dict__.get("_coordinates_of")
        if found is None:
            found = {**{p: (q, True) for q, p in zip(self.coordinates, self.momenta)}, **{q: (q, False) for q in self.coordinates}}
            self.__dict__["_coordinates_of"] = found
        return found

    def poisson_bracket(self, f: sympy.Expr, g: sympy.Expr) -> sympy.Expr:
        """Canonical Poisson bracket ``{f, g} = sum_i df/dq_i dg/dp_i - df/dp_i dg/dq_i``.

        The sign convention is the paper's: ``{q_i, p_j} = delta_ij`` and
        ``z_dot = {z, H}`` (Sect. X, below (207)). The result is not simplified.
        """
        fq, fp = self.partials(f)
        gq, gp = self.partials(g)
        terms = [fq[q] * gp[q] for q in fq if q in gp]
        terms += [-fp[q] * gq[q] for q in fp if q in gq]
        return sympy.Add(*terms)

    def gradient(self, expr: sympy.Expr) -> list[sympy.Expr]:
        """Full gradient of ``expr`` in the order of :attr:`variables`."""
        dq, dp = self.partials(expr)
        return [dq.get(q, sympy.S.Zero) for q in self.coordinates] + [dp.get(q, sympy.S.Zero) for q in self.coordinates]

    def gradient_entries(self, exprs: Sequence[sympy.Expr]) -> tuple[list[int], list[int], list[sympy.Expr]]:
        """The non-zero entries of the gradients of ``exprs``: ``(rows, columns, derivatives)``.

        Row ``i`` is ``exprs[i]``, columns are positions in :attr:`variables` (a coordinate's
        derivative, then its momentum's); only the partial derivatives that
        :meth:`partials` finds are listed, ``O(non-zeros)`` for the constraints of a local
        system.
        """
        position = self._positions()
        rows: list[int] = []
        cols: list[int] = []
        entries: list[sympy.Expr] = []
        for i, e in enumerate(exprs):
            dq, dp = self.partials(e)
            for q, d in dq.items():
                rows.append(i)
                cols.append(position[q])
                entries.append(d)
            for q, d in dp.items():
                rows.append(i)
                cols.append(self.pair_positions(q)[1])  # dp is keyed by q
                entries.append(d)
        return rows, cols, entries

    def pair_positions(self, coordinate: sympy.Symbol) -> tuple[int, int]:
        """Positions in :attr:`variables` of ``coordinate`` and of its momentum (``len(coordinates)`` further on)."""
        k = self._positions()[coordinate]
        return k, k + len(self.coordinates)

    def _positions(self) -> dict[sympy.Symbol, int]:
        """Variable -> its position in :attr:`variables` (built once per tuple of variables)."""
        variables = self.variables
        held = self.__dict__.get("_position_index")
        if held is None or held[0] is not variables:
            held = (variables, {v: k for k, v in enumerate(variables)})
            self.__dict__["_position_index"] = held
        return held[1]

    def check_names(self, values: Mapping[str, float] | Iterable[str], what: str) -> None:
        """Raise :class:`~dirac.errors.InputError` for a name that is not a variable or parameter."""
        from dirac.errors import InputError

        known = set(self.symbols) | {p.name for p in self.parameters}
        unknown = sorted(set(values) - known)
        if unknown:
            raise InputError(
                f"{what}: unknown name(s) {', '.join(unknown)}; the phase-space variables are "
                f"{', '.join(self.symbols)}"
            )
