"""The general solution of the consistency conditions for the multipliers of ``H_T``.

At the end of the Dirac–Bergmann chain the time derivatives of all constraints vanish
weakly when the multipliers ``u_k`` of the primary constraints ``phi_k`` satisfy

    b_a + A_ak u_k ≈ 0,      b_a = {Phi_a, H_c},  A_ak = {Phi_a, phi_k}      ((214)-(215)).

Their general solution is (Dirac, "Lectures on quantum mechanics", Lecture 1;
Henneaux–Teitelboim Sect. 1.2.2)

    u_k = U_k + v_a V_ak,

``U`` one particular solution, ``V_a`` a basis of the null space of ``A`` on the
surface and ``v_a`` arbitrary: the total Hamiltonian is

    H_T = H' + v_a phi_a,      H' = H_c + U_k phi_k,      phi_a = V_ak phi_k,

with ``phi_a`` the first-class combinations of the primary constraints. A single
``u_k`` is *fixed alone* exactly when every ``V_a`` has a zero ``k`` component; when two
primary constraints coincide only their sum of multipliers is fixed and neither alone.

The rank of ``A`` is decided numerically at the chain's surface points; a set ``Q`` of
columns with ``A_PQ`` invertible on the surface (``P`` the independent rows) is chosen,
preferring multipliers that are fixed alone. Then ``U_Q = -A_PQ^{-1} b_P`` and
``U_k = 0`` off ``Q``; for each ``j`` not in ``Q``, ``V_j = e_j - A_PQ^{-1} A_Pj`` (the ``j``
component is 1). Both are exact expressions, solved weakly on the surface by
:func:`~dirac.analysis.core.linear_solve.weak_solve`.
"""

from __future__ import annotations

from collections.abc import Callable, Iterator, Mapping, Sequence

import numpy as np
import sympy

from dirac.analysis.core.algebra import prints_shorter, tidy
from dirac.analysis.core.linear_solve import TIDY_LIMIT, weak_solve, weakly_solvable
from dirac.analysis.core.numeric import columns_invertible_everywhere, independent_rows
from dirac.errors import AnalysisError

__all__ = ["MultiplierSolution", "FixedMultipliers", "general_multiplier_solution", "unsolved_multipliers"]


class MultiplierSolution:
    """``u = U + v_a V_a``: the general solution of ``b + A u ≈ 0`` (Henneaux–Teitelboim (1.32)).

    The exact ``U`` and ``V_a`` may be computed on first use: :func:`general_multiplier_solution`
    decides everything numeric at once (which rows and columns are independent, that the
    system is solvable at every sample point) and passes the exact solve as ``solve``, run
    the first time :attr:`particular` or :attr:`null_vectors` is read (for a long chain it
    is a symbolic elimination whose result nothing in the analysis itself needs).

    Attributes
    ----------
    multipliers
        The multipliers ``u_k`` of the primary constraints, in order.
    primary
        The primary constraints ``phi_k`` they multiply.
    canonical_hamiltonian
        ``H_c``.
    free
        The free parameters ``v_1, v_2, ...`` (one per null vector).

    The exact ``U`` (:attr:`particular`, ``0`` for the multipliers set to zero) and ``V_a``
    (:attr:`null_vectors`) are properties, solved on first read.
    """

    def __init__(
        self,
        multipliers: tuple[sympy.Symbol, ...],
        primary: list[sympy.Expr],
        canonical_hamiltonian: sympy.Expr,
        particular: dict[str, sympy.Expr] | None,
        null_vectors: list[dict[str, sympy.Expr]] | None,
        free: tuple[sympy.Symbol, ...] = (),
        solve: Callable[[], tuple[dict[str, sympy.Expr], list[dict[str, sympy.Expr]]]] | None = None,
        matrix: sympy.Matrix | None = None,
    ) -> None:
        if (particular is None or null_vectors is None) and solve is None:
            raise ValueError("a multiplier solution needs its particular solution and null vectors, or a solve that gives them")
        self.multipliers = multipliers
        self.primary = primary
        self.canonical_hamiltonian = canonical_hamiltonian
        self.free = tuple(free)
        self._particular = particular
        self._null_vectors = null_vectors
        self._solve = solve if (particular is None or null_vectors is None) else None
        #: the square block ``A_PQ`` of the consistency conditions that the exact solve inverts (``None`` when
        #: not known): where it is regular the multipliers are finite, whatever the solved expressions divide by
        self.matrix = matrix

    def __repr__(self) -> str:
        state = "solved" if self.solved else "exact solve on first use"
        return f"MultiplierSolution({len(self.multipliers)} multipliers, {len(self.free)} free, {state})"

    @property
    def solved(self) -> bool:
        """Whether the exact ``U`` and ``V_a`` have been computed (they are on first use)."""
        return self._solve is None

    def _exact(self) -> tuple[dict[str, sympy.Expr], list[dict[str, sympy.Expr]]]:
        if self._solve is not None:
            self._particular, self._null_vectors = self._solve()
            self._solve = None
        assert self._particular is not None and self._null_vectors is not None
        return self._particular, self._null_vectors

    @property
    def particular(self) -> dict[str, sympy.Expr]:
        """``U``: multiplier name -> exact expression, weakly simplified on the surface."""
        return self._exact()[0]

    @property
    def null_vectors(self) -> list[dict[str, sympy.Expr]]:
        """The ``V_a`` (one dict multiplier name -> exact component per free parameter)."""
        return self._exact()[1]

    @property
    def first_class_primary(self) -> list[sympy.Expr]:
        """``phi_a = V_ak phi_k``: the first-class combinations of the primary constraints."""
        return [
            sympy.expand(sum((vec[u.name] * phi for u, phi in zip(self.multipliers, self.primary)), sympy.S.Zero))
            for vec in self.null_vectors
        ]

    @property
    def general(self) -> dict[str, sympy.Expr]:
        """``u_k = U_k + v_a V_ak`` for every multiplier (name -> expression in the ``v_a``)."""
        return {
            u.name: self.particular[u.name] + sum((v * vec[u.name] for v, vec in zip(self.free, self.null_vectors)), sympy.S.Zero)
            for u in self.multipliers
        }

    @property
    def first_class_hamiltonian(self) -> sympy.Expr:
        """``H' = H_c + U_k phi_k``, first class on the surface."""
        return self.canonical_hamiltonian + sum(
            (self.particular[u.name] * phi for u, phi in zip(self.multipliers, self.primary)), sympy.S.Zero
        )

    @property
    def total_hamiltonian(self) -> sympy.Expr:
        """``H_T = H' + v_a phi_a``: the total Hamiltonian that keeps the motion on the surface."""
        return self.first_class_hamiltonian + sum(
            (v * phi for v, phi in zip(self.free, self.first_class_primary)), sympy.S.Zero
        )

    @property
    def fixed_alone(self) -> list[sympy.Symbol]:
        """The ``u_k`` with a zero component in every null vector (determined by themselves)."""
        return [u for u in self.multipliers if all(vec[u.name] == 0 for vec in self.null_vectors)]

    @property
    def each_fixed_or_free(self) -> bool:
        """True when every ``u_k`` is either fixed alone or entirely free (``V_a = e_k``, ``U_k = 0``).

        Then ``H_T = H_c + u_k phi_k`` with the fixed ``u_k`` substituted and the others
        arbitrary is already the general form.
        """
        units = 0
        for vec in self.null_vectors:
            nonzero = [name for name, value in vec.items() if value != 0]
            if len(nonzero) != 1 or vec[nonzero[0]] != 1 or self.particular[nonzero[0]] != 0:
                return False
            units += 1
        return units == len(self.null_vectors)


class FixedMultipliers(Mapping[str, sympy.Expr]):
    """Name -> exact ``U_k`` of each multiplier fixed alone (``analysis.multipliers``).

    Which multipliers are fixed alone is decided numerically during the analysis, so the
    names (``in``, ``len``, iteration) are known at once; a value is read from
    :attr:`MultiplierSolution.particular`, which runs the exact solve the first time.
    """

    def __init__(self, names: Sequence[str], solution: MultiplierSolution) -> None:
        self._names = list(names)
        self._known = set(names)
        self._solution = solution

    def __getitem__(self, name: str) -> sympy.Expr:
        if name not in self._known:
            raise KeyError(name)
        return self._solution.particular[name]

    def __contains__(self, name: object) -> bool:
        return name in self._known

    def __iter__(self) -> Iterator[str]:
        return iter(self._names)

    def __len__(self) -> int:
        return len(self._names)

    def __repr__(self) -> str:
        return repr(dict(self))  # printing asks for the values: solved here if not yet


def free_parameters(count: int, taken: Sequence[str]) -> tuple[sympy.Symbol, ...]:
    """``v_1, ..., v_count`` (``v_free_1, ...`` when a variable or parameter is already named ``v_k``)."""
    base = "v"
    while any(f"{base}_{a + 1}" in taken for a in range(count)):
        base += "_free"
    return tuple(sympy.Symbol(f"{base}_{a + 1}", real=True) for a in range(count))


def unsolved_multipliers(
    multipliers: tuple[sympy.Symbol, ...], primary: list[sympy.Expr], canonical_hamiltonian: sympy.Expr, taken: Sequence[str]
) -> MultiplierSolution:
    """The solution when no consistency condition involves a multiplier: ``U = 0``, ``V_a = e_a``."""
    names = [u.name for u in multipliers]
    return MultiplierSolution(
        multipliers,
        list(primary),
        canonical_hamiltonian,
        {name: sympy.S.Zero for name in names},
        [{other: (sympy.S.One if other == name else sympy.S.Zero) for other in names} for name in names],
        free_parameters(len(names), taken),
    )


def general_multiplier_solution(
    multipliers: tuple[sympy.Symbol, ...],
    primary: list[sympy.Expr],
    canonical_hamiltonian: sympy.Expr,
    a_rows: sympy.Matrix,
    b_rows: sympy.Matrix,
    a_num: Sequence[np.ndarray],
    b_num: Sequence[np.ndarray],
    order: Sequence[int],
    variables: Sequence[sympy.Symbol],
    taken: Sequence[str],
) -> MultiplierSolution:
    """Solve ``b_P + A_P u ≈ 0`` in general form ``u = U + v_a V_a``.

    The numeric decisions (the columns ``Q``, that ``A_PQ`` is invertible at every sample
    point) are taken now, and a system that fails them is refused now; the exact
    ``U`` and ``V_a`` are computed on first use (:class:`MultiplierSolution`).

    Parameters
    ----------
    multipliers, primary, canonical_hamiltonian
        The ``u_k``, the ``phi_k`` and ``H_c``.
    a_rows, b_rows
        ``A_P`` (``|P| x K``) and ``b_P`` (``|P| x 1``): the rows of the consistency
        conditions that are independent on the surface.
    a_num, b_num
        The same at the surface points (one ``|P| x K`` and one ``|P|`` array per point).
    order
        Multiplier indices in order of preference for the pivot columns ``Q`` (those
        fixed alone first, so that their ``U_k`` is their unique value).
    variables
        Phase-space variables (for readable normal forms).
    taken
        Names already in use (variables, parameters): the free ``v_a`` avoid them.
    """
    K = len(multipliers)
    names = [u.name for u in multipliers]
    A_num = [np.asarray(A, dtype=float).reshape(-1, K) for A in a_num]
    B_num = [np.asarray(b, dtype=float).reshape(-1, 1) for b in b_num]
    Q = independent_rows([A.T for A in A_num], list(order))
    if len(Q) < a_rows.shape[0]:  # the columns that carry the rank differ between points
        Q = columns_invertible_everywhere(A_num, list(range(a_rows.shape[0])), list(order)) or Q
    F = [k for k in range(K) if k not in Q]
    if len(Q) != a_rows.shape[0]:  # rows independent on the surface, columns not: ranks decided inconsistently
        raise AnalysisError(
            f"the consistency conditions have {a_rows.shape[0]} rows independent on the surface but only {len(Q)} "
            "independent multiplier columns at its points: the rank of {Phi_a, phi_k} is not the same everywhere "
            "on the surface (parts of different structure); analyse each part as a system of its own"
        )
    A_num_Q = [A[:, Q] for A in A_num]
    weakly_solvable(A_num_Q, B_num)  # a system singular at a sample point is refused now, not on first use

    def solve() -> tuple[dict[str, sympy.Expr], list[dict[str, sympy.Expr]]]:
        """The exact ``U`` and ``V_a`` (run on first use)."""
        A_PQ = a_rows[:, Q]
        particular = {name: sympy.S.Zero for name in names}
        sol = weak_solve(A_PQ, -b_rows, A_num_Q, [-b for b in B_num], variables=variables)
        for r, k in enumerate(Q):
            particular[names[k]] = sol[r, 0]
        null_vectors: list[dict[str, sympy.Expr]] = []
        if F:
            N = weak_solve(A_PQ, -a_rows[:, F], A_num_Q, [-A[:, F] for A in A_num], variables=variables)
            for c, j in enumerate(F):
                vec = {name: sympy.S.Zero for name in names}
                vec[names[j]] = sympy.S.One
                for r, k in enumerate(Q):
                    entry = N[r, c]
                    vec[names[k]] = tidy(entry, variables, rational=prints_shorter(entry, TIDY_LIMIT // 4)) if entry != 0 else sympy.S.Zero
                null_vectors.append(vec)
        return particular, null_vectors

    return MultiplierSolution(
        multipliers, list(primary), canonical_hamiltonian, None, None, free_parameters(len(F), taken), solve=solve,
        matrix=a_rows[:, Q],
    )
