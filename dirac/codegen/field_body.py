"""The body of one Dirac vector field as straight-line source, shared by every emitter.

The Hamiltonian vector field over second-class constraints ``Phi_a`` with generalized
forces ``Q`` and an explicit time ``t`` (the Dirac bracket, the paper's (240); Dirac,
*Lectures on Quantum Mechanics*; Henneaux & Teitelboim, Ch. 1; Gitman & Tyutin for the
rheonomic term)

    z_dot = f - J D^T x,    C x = D f + d_t Phi,    f = J g + (0, Q),
    g = grad H,   D = grad Phi  (k, N),   C_ab = {Phi_a, Phi_b} = D_a^T J D_b,

with ``J = [[0, 1], [-1, 0]]`` on ``z = (q, p)``, is written by :func:`dirac_field_body`
as the lines of a function body that fill ``out``: ``g``, ``D`` and ``d_t Phi`` from
sympy with common sub-expressions shared (:func:`dirac.codegen.printer.straight_line`),
then ``C`` and the right side from the named entries of ``D`` and ``g`` (terms of
structurally zero entries left out), then Gaussian elimination with partial pivoting on
``C`` unrolled on local scalars (:func:`_elimination`): no array is allocated, no LAPACK
is called. Row exchanges of the pivoting are conditional swaps of local names; a column
whose diagonal entry is structurally zero takes its first structurally non-zero row
before the comparisons. When the unrolled elimination would exceed ``unroll_limit``
lines (a large ``C`` with much fill-in), ``[C | b]`` is written into a scratch array
instead and solved there by the looped elimination ``solve_scratch``
(:data:`SCRATCH_SOLVER`), which compiles in a fraction of the time.

Both the public vector field (:mod:`dirac.codegen.field_source`) and the step kernels of
analysed systems (:mod:`dirac.codegen.kernel_source`) print their field with this one
function; they differ only in where the inputs and the scratch space come from.
"""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from dataclasses import dataclass

import sympy

from dirac.codegen.printer import straight_line

__all__ = ["FieldBody", "dirac_field_body", "BANDED_SOLVER", "SCRATCH_SOLVER", "UNROLL_LIMIT"]


def _product(a: str | None, b: str | None) -> str | None:
    return None if a is None or b is None else f"{a} * {b}"


def _sum(terms: Sequence[tuple[str, str | None]]) -> str | None:
    """``+ t1 - t2 ...`` of the non-None terms (sign, code); None when none is left."""
    parts = [(sign, code) for sign, code in terms if code is not None]
    if not parts:
        return None
    text = ("-" if parts[0][0] == "-" else "") + parts[0][1]
    for sign, code in parts[1:]:
        text += f" {sign} {code}"
    return text


class _TooLong(Exception):
    """The unrolled elimination passed its line limit (the looped solve takes over)."""


class _Lines:
    """Source lines of the function body (at most ``limit`` of them, else :class:`_TooLong`)."""

    def __init__(self, limit: int | None = None) -> None:
        self.lines: list[str] = []
        self.limit = limit

    def add(self, text: str) -> None:
        self.lines.append("    " + text)
        if self.limit is not None and len(self.lines) > self.limit:
            raise _TooLong


def _elimination(lines: _Lines, matrix: list[list[str | None]], rhs: list[str | None]) -> list[str | None]:
    """Unrolled Gaussian elimination with partial pivoting of ``matrix x = rhs``.

    Entries are local names or ``None`` (structurally zero). Returns the names of ``x``
    (``None`` where ``x`` is structurally zero). Every intermediate value gets a fresh
    local name, so the code is straight-line (except the conditional row swaps).
    """
    k = len(matrix)
    rows = [list(row) + [value] for row, value in zip(matrix, rhs)]  # augmented, k x (k + 1)
    counter = [0]

    def fresh(prefix: str) -> str:
        counter[0] += 1
        return f"{prefix}{counter[0]}_"

    for c in range(k):
        candidates = [r for r in range(c, k) if rows[r][c] is not None]
        if not candidates:
            # structurally singular: numerically so as well; divide by zero below
            zero = fresh("z")
            lines.add(f"{zero} = 0.0")
            rows[c][c] = zero
            candidates = [c]
        if candidates[0] != c:  # static exchange: the diagonal is structurally zero
            rows[c], rows[candidates[0]] = rows[candidates[0]], rows[c]
        for r in candidates[1:]:
            # swap rows c and r when row r has the larger pivot; both rows may then be either
            width = range(c, k + 1)
            union = [rows[c][j] is not None or rows[r][j] is not None for j in width]
            new_c = [fresh("s") if u else None for u in union]
            new_r = [fresh("s") if u else None for u in union]
            for j, name in zip(width, new_c):
                if name is not None:
                    lines.add(f"{name} = {rows[c][j] or '0.0'}")
            for j, name in zip(width, new_r):
                if name is not None:
                    lines.add(f"{name} = {rows[r][j] or '0.0'}")
            lines.add(f"if abs({rows[r][c]}) > abs({rows[c][c]}):")
            for a, b in zip(new_c, new_r):
                if a is not None and b is not None:
                    lines.add(f"    {a}, {b} = {b}, {a}")
            for j, a, b in zip(width, new_c, new_r):
                rows[c][j], rows[r][j] = a, b
        pivot = rows[c][c]
        for r in range(c + 1, k):
            below = rows[r][c]
            if below is None:
                continue
            factor = fresh("f")
            lines.add(f"{factor} = {below} / {pivot}")
            rows[r][c] = None
            for j in range(c + 1, k + 1):
                top = rows[c][j]
                if top is None:
                    continue
                name = fresh("e")
                lines.add(f"{name} = {rows[r][j]} - {factor} * {top}" if rows[r][j] is not None
                          else f"{name} = -{factor} * {top}")
                rows[r][j] = name
    x: list[str | None] = [None] * k
    for c in range(k - 1, -1, -1):
        code = _sum([("+", rows[c][k])] + [("-", _product(rows[c][j], x[j])) for j in range(c + 1, k)])
        if code is None:
            continue
        name = f"x{c}_"
        lines.add(f"{name} = ({code}) / {rows[c][c]}")
        x[c] = name
    return x


#: largest unrolled elimination (source lines) before the looped solve takes over
UNROLL_LIMIT = 1200

SCRATCH_SOLVER = '''@numba.njit("void(float64[::1], int64, int64)", cache=True, error_model="numpy")
def solve_scratch(w, start, k):
    """Solve [C | b] (k x (k + 1), row-major in w[start:]) in place by Gaussian
    elimination with partial pivoting; the solution ends up in column k."""
    m = k + 1
    for c in range(k):
        pivot = c
        best = abs(w[start + c * m + c])
        for r in range(c + 1, k):
            size = abs(w[start + r * m + c])
            if size > best:
                best = size
                pivot = r
        if pivot != c:
            for j in range(c, m):
                swap = w[start + c * m + j]
                w[start + c * m + j] = w[start + pivot * m + j]
                w[start + pivot * m + j] = swap
        d = w[start + c * m + c]
        for r in range(c + 1, k):
            factor = w[start + r * m + c] / d
            if factor != 0.0:
                for j in range(c + 1, m):
                    w[start + r * m + j] -= factor * w[start + c * m + j]
    for c in range(k - 1, -1, -1):
        acc = w[start + c * m + k]
        for j in range(c + 1, k):
            acc -= w[start + c * m + j] * w[start + j * m + k]
        w[start + c * m + k] = acc / w[start + c * m + c]


'''


#: the looped solve of a banded ``C`` (after a symmetric reordering): LAPACK's ``gbsv``
#: scheme (Golub & Van Loan, *Matrix Computations*, 4th ed., Sect. 4.3.5): partial pivoting
#: within the ``lower`` rows below the diagonal, so the upper band widens to ``lower + upper``
BANDED_SOLVER = '''@numba.njit("void(float64[::1], int64, int64, int64, int64)", cache=True, error_model="numpy")
def solve_banded(w, start, k, lower, upper):
    """Solve C x = b in place by Gaussian elimination with partial pivoting on band storage:
    row r of C holds columns r - lower .. r + lower + upper at w[start + r * W + (j - r + lower)]
    (W = 2 lower + upper + 1), then b at w[start + k * W:]; x replaces b."""
    W = 2 * lower + upper + 1
    rhs = start + k * W
    for c in range(k):
        last = min(k - 1, c + lower)
        high = min(k - 1, c + lower + upper)
        pivot = c
        best = abs(w[start + c * W + lower])
        for r in range(c + 1, last + 1):
            size = abs(w[start + r * W + (c - r + lower)])
            if size > best:
                best = size
                pivot = r
        if pivot != c:
            for j in range(c, high + 1):
                a = start + c * W + (j - c + lower)
                b = start + pivot * W + (j - pivot + lower)
                swap = w[a]
                w[a] = w[b]
                w[b] = swap
            swap = w[rhs + c]
            w[rhs + c] = w[rhs + pivot]
            w[rhs + pivot] = swap
        d = w[start + c * W + lower]
        for r in range(c + 1, last + 1):
            factor = w[start + r * W + (c - r + lower)] / d
            if factor != 0.0:
                for j in range(c + 1, high + 1):
                    w[start + r * W + (j - r + lower)] -= factor * w[start + c * W + (j - c + lower)]
                w[rhs + r] -= factor * w[rhs + c]
    for c in range(k - 1, -1, -1):
        acc = w[rhs + c]
        for j in range(c + 1, min(k - 1, c + lower + upper) + 1):
            acc -= w[start + c * W + (j - c + lower)] * w[rhs + j]
        w[rhs + c] = acc / w[start + c * W + lower]


'''


def _band_order(matrix: list[list[str | None]]) -> tuple[list[int], int, int]:
    """A symmetric reordering of ``matrix`` that makes it banded (reverse Cuthill-McKee on
    its structure; Cuthill & McKee 1969, George & Liu 1981) and the lower and upper
    bandwidths after it: ``order[p]`` is the row (and column) moved to position ``p``."""
    import numpy as np
    from scipy.sparse import csr_matrix
    from scipy.sparse.csgraph import reverse_cuthill_mckee

    k = len(matrix)
    rows, cols = zip(*[(a, b) for a in range(k) for b in range(k) if matrix[a][b] is not None]) or ((), ())
    pattern = csr_matrix((np.ones(len(rows)), (np.array(rows, dtype=np.int64), np.array(cols, dtype=np.int64))),
                         shape=(k, k))
    order = [int(a) for a in reverse_cuthill_mckee(pattern, symmetric_mode=True)]
    position = {a: p for p, a in enumerate(order)}
    lower = upper = 0
    for a, b in zip(rows, cols):
        lower = max(lower, position[a] - position[b])
        upper = max(upper, position[b] - position[a])
    return order, lower, upper


def _banded_pays(k: int, lower: int, upper: int) -> bool:
    """Whether the banded solve beats the dense one: fewer products, ``k lower (lower + upper)``
    against ``k^3 / 3`` (Golub & Van Loan, *Matrix Computations*, Sect. 4.3).

    Its source is also shorter: one line per structurally non-zero entry of ``C`` against
    one per entry of the dense ``k (k + 1)`` scratch, every one of them compiled (numba's
    and LLVM's time grows faster than the length of the function: the dense scratch of the
    16-link chain, ``k = 64``, made a 6400-line field that took minutes to compile).
    """
    return 3 * lower * (lower + upper) < k * k


def _banded_solve(lines: _Lines, matrix: list[list[str | None]], rhs: list[str | None], scratch: str, start: int,
                  order: list[int], lower: int, upper: int) -> list[str | None]:
    """``matrix x = rhs`` by the looped banded solve ``solve_banded`` on ``scratch[start:]``.

    The band of the reordered matrix is zeroed by one loop and its structurally non-zero
    entries written (one line each: the source grows with the entries, not with ``k^2``),
    solved in place, and ``x`` read back in the original order.
    """
    k = len(matrix)
    width = 2 * lower + upper + 1
    lines.add(f"for i_ in range({start}, {start + k * width}):")
    lines.add(f"    {scratch}[i_] = 0.0")
    for p, a in enumerate(order):
        for q, b in enumerate(order):
            if matrix[a][b] is not None:
                lines.add(f"{scratch}[{start + p * width + q - p + lower}] = {matrix[a][b]}")
        lines.add(f"{scratch}[{start + k * width + p}] = {rhs[a] or '0.0'}")
    lines.add(f"solve_banded({scratch}, {start}, {k}, {lower}, {upper})")
    x: list[str | None] = [None] * k
    for p, a in enumerate(order):
        lines.add(f"x{a}_ = {scratch}[{start + k * width + p}]")
        x[a] = f"x{a}_"
    return x


def _scratch_solve(lines: _Lines, matrix: list[list[str | None]], rhs: list[str | None], scratch: str,
                   start: int) -> list[str | None]:
    """``matrix x = rhs`` by the looped solve ``solve_scratch`` on ``scratch[start:]``.

    The augmented matrix is written row by row into the scratch space (structurally
    zero entries as 0.0), solved in place, and ``x`` read back into local names.
    """
    k = len(matrix)
    m = k + 1
    for r in range(k):
        for j, value in enumerate([*matrix[r], rhs[r]]):
            lines.add(f"{scratch}[{start + r * m + j}] = {value or '0.0'}")
    lines.add(f"solve_scratch({scratch}, {start}, {k})")
    x: list[str | None] = []
    for a in range(k):
        lines.add(f"x{a}_ = {scratch}[{start + a * m + k}]")
        x.append(f"x{a}_")
    return x


#: with this many second-class constraints the whole field is one closed form (``C^{-1}`` of a
#: 2 x 2 antisymmetric ``C`` written out), simplified by sympy and printed as one straight-line
#: block, so constant entries fold away and one division remains
CLOSED_FORM_SIZES = (0, 2)


def _closed_form_body(z: list[sympy.Symbol], inputs: Mapping[sympy.Symbol, str], gradient: list[sympy.Expr],
                      second_class: list[sympy.Expr], title: str, time: sympy.Symbol | None) -> FieldBody:
    """The field (240) with ``k`` in ``(0, 2)`` as sympy expressions: ``f = J g``, and for ``k = 2``

        z_dot = f - J D^T C^{-1} (D f + d_t Phi),   C^{-1} = [[0, -1/C_01], [1/C_01, 0]]."""
    N = len(z)
    n = N // 2
    flow = sympy.Matrix([*gradient[n:], *[-e for e in gradient[:n]]])  # J g
    k = len(second_class)
    if k:
        D = sympy.Matrix([[sympy.diff(phi, s) for s in z] for phi in second_class])
        J = sympy.zeros(N, N)
        for i in range(n):
            J[i, n + i], J[n + i, i] = 1, -1
        phi_t = sympy.Matrix([sympy.diff(phi, time) if time is not None else sympy.S.Zero for phi in second_class])
        C = D * J * D.T
        inverse = sympy.Matrix([[0, -1 / C[0, 1]], [1 / C[0, 1], 0]])
        flow = flow - J * D.T * inverse * (D * flow + phi_t)
    code = straight_line(dict(inputs), list(flow), "math", "cse", title)
    lines = list(code.body()) + [f"    out[{i}] = {value}" for i, value in enumerate(code.outputs)]
    return FieldBody(lines, 0, "")


@dataclass(frozen=True)
class FieldBody:
    """The lines of a field body (indented by four spaces) and what they need around them.

    ``scratch_size`` entries of the scratch array are used (0: the solve is unrolled, no
    scratch); ``solver`` is then the source of ``solve_scratch`` to put into the module.
    """

    lines: list[str]
    scratch_size: int
    solver: str


def dirac_field_body(
    variables: Sequence[sympy.Symbol],
    inputs: Mapping[sympy.Symbol, str],
    hamiltonian: sympy.Expr,
    second_class: Sequence[sympy.Expr],
    title: str,
    time: sympy.Symbol | None = None,
    forces: Sequence[sympy.Expr] = (),
    unroll_limit: int = UNROLL_LIMIT,
    scratch: tuple[str, int] = ("params", 0),
    banded: bool | None = None,
) -> FieldBody:
    """Lines filling ``out[0:N]`` with the Dirac vector field (see the module docstring).

    Parameters
    ----------
    variables
        The phase-space variables ``z = (q, p)``: ``n`` coordinates then their ``n``
        momenta, so ``{z_i, z_{n+i}} = 1``.
    inputs
        Every symbol the expressions may use -> the local name that holds its value (the
        caller's lines load them before these).
    hamiltonian, second_class
        ``H`` and the second-class constraints ``Phi_a`` (``C`` invertible on the surface).
    title
        A name for the generated code (comments of the printer).
    time
        The explicit time of a rheonomic system (``d_t Phi`` joins the right side of the
        solve), or None.
    forces
        Generalized forces ``Q_i`` on the first ``len(forces)`` coordinates: ``p_dot_i =
        -dH/dq_i + Q_i`` before the projection.
    unroll_limit
        Largest number of lines of the unrolled elimination before the looped solve.
    scratch
        The array name and the first entry of the scratch space of the looped solve.
    banded
        The looped solve on band storage after a bandwidth-reducing reordering (True), or
        the dense one (False); None: the banded one where it is cheaper.
    """
    z = list(variables)
    N = len(z)
    n = N // 2
    k = len(second_class)
    gradient = [sympy.diff(hamiltonian, s) for s in z]
    for i, Q in enumerate(forces):  # (J g)_{n+i} = -g_i: p_dot_i = -dH/dq_i + Q_i
        gradient[i] = gradient[i] - Q
    if k in CLOSED_FORM_SIZES:
        return _closed_form_body(z, inputs, gradient, list(second_class), title, time)
    wanted: list[sympy.Expr] = []
    slots: list[tuple[str, int, int]] = []
    for i, g in enumerate(gradient):
        if g != 0:
            wanted.append(g)
            slots.append(("g", i, 0))
    for a, phi in enumerate(second_class):
        for i, s in enumerate(z):
            d = sympy.diff(phi, s)
            if d != 0:
                wanted.append(d)
                slots.append(("d", a, i))
    if time is not None:  # d_t Phi_a of a rheonomic constraint
        for a, phi in enumerate(second_class):
            derivative = sympy.diff(phi, time)
            if derivative != 0:
                wanted.append(derivative)
                slots.append(("t", a, 0))
    code = straight_line(dict(inputs), wanted, "math", "cse", title)
    lines = _Lines()
    lines.lines.extend(code.body())
    g_name: list[str | None] = [None] * N
    d_name: list[list[str | None]] = [[None] * N for _ in range(k)]
    t_name: list[str | None] = [None] * k
    for (kind, a, i), value in zip(slots, code.outputs):
        name = {"g": f"g{a}_", "d": f"d{a}_{i}_", "t": f"e{a}_"}[kind]
        lines.add(f"{name} = {value}")
        if kind == "g":
            g_name[a] = name
        elif kind == "d":
            d_name[a][i] = name
        else:
            t_name[a] = name
    # J g: (J g)_i = g_{n+i}, (J g)_{n+i} = -g_i
    correction: list[str | None] = [None] * N
    scratch_size = 0
    solver = ""
    if k:
        # C_ab = sum_i D_a,i D_b,n+i - D_a,n+i D_b,i  (antisymmetric), b_a = (D J g)_a + d_t Phi_a
        C: list[list[str | None]] = [[None] * k for _ in range(k)]
        having: list[set[int]] = [set() for _ in range(N)]  # column -> the constraints whose gradient has it
        for a in range(k):
            for i in range(N):
                if d_name[a][i] is not None:
                    having[i].add(a)
        for a in range(k):
            partners = {b for i in range(N) if d_name[a][i] is not None for b in having[(i + n) % N] if b > a}
            for b in sorted(partners):
                entry = _sum([term for i in range(n) for term in (
                    ("+", _product(d_name[a][i], d_name[b][n + i])), ("-", _product(d_name[a][n + i], d_name[b][i])))])
                if entry is not None:
                    lines.add(f"C{a}_{b}_ = {entry}")
                    lines.add(f"C{b}_{a}_ = -C{a}_{b}_")
                    C[a][b], C[b][a] = f"C{a}_{b}_", f"C{b}_{a}_"
        rhs: list[str | None] = []
        for a in range(k):
            entry = _sum([term for i in range(n) for term in (
                ("+", _product(d_name[a][i], g_name[n + i])), ("-", _product(d_name[a][n + i], g_name[i])))]
                + [("+", t_name[a])])
            if entry is not None:
                lines.add(f"b{a}_ = {entry}")
            rhs.append(f"b{a}_" if entry is not None else None)
        unrolled = _Lines(unroll_limit)
        try:
            x = _elimination(unrolled, C, rhs)
            lines.lines.extend(unrolled.lines)
        except _TooLong:
            order, lower, upper = _band_order(C)
            if _banded_pays(k, lower, upper) if banded is None else banded:
                x = _banded_solve(lines, C, rhs, scratch[0], scratch[1], order, lower, upper)
                scratch_size = k * (2 * lower + upper + 2)
                solver = BANDED_SOLVER
            else:
                x = _scratch_solve(lines, C, rhs, scratch[0], scratch[1])
                scratch_size = k * (k + 1)
                solver = SCRATCH_SOLVER
        # w = D^T x
        for j in range(N):
            total = _sum([("+", _product(d_name[a][j], x[a])) for a in range(k)])
            correction[j] = None if total is None else f"({total})"
    for i in range(n):
        lines.add(f"out[{i}] = {_sum([('+', g_name[n + i]), ('-', correction[n + i])]) or '0.0'}")
    for i in range(n):
        lines.add(f"out[{n + i}] = {_sum([('-', g_name[i]), ('+', correction[i])]) or '0.0'}")
    return FieldBody(lines.lines, scratch_size, solver)
