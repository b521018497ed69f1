"""Source of the small dense linear solves that generated step kernels inline.

A step of RATTLE or of the midpoint rule solves a few small systems (``m x m`` for the
multipliers, ``n x n`` for the mass matrix, ``(2n + m)`` for a Newton step). Calling
LAPACK from numba costs more than these solves themselves and allocates, so each
generated module carries its own solves as source, specialised to the sizes that occur:

* size 1 and 2: closed forms (Cramer's rule);
* any size: Gaussian elimination with partial pivoting in place (Golub & Van Loan,
  Algorithm 3.4.1), factor once and solve many right-hand sides (the simplified Newton
  iterations keep their matrix over a step).

None of them allocates. A zero pivot or a zero determinant divides by zero, which numba
raises as ``ZeroDivisionError`` (the steppers turn it into a step failure that names
the singular Newton matrix).

For the interpreted tier (:mod:`dirac.codegen.tiers`), where each loop iteration and each
array access costs interpreter time, :func:`unrolled_lu_source` writes the same
elimination for one fixed size as straight-line code on Python floats
(``lu_factor_<k>``, ``lu_solve_<k>``): the same pivot choices, the same floating-point
operations in the same order, hence bit for bit the same factors and solutions, in a
fifth of the time at ``k = 6`` (a third at ``k = 3``). Numba compiles the looped form
faster (the unrolled 6 x 6 took 3-4 times as long), so the compiled tier keeps it
(:func:`dirac.codegen.flatten.specialise_solves` makes the interpreted variant).
"""

from __future__ import annotations

__all__ = ["solve_source", "lu_source", "unrolled_lu_source", "offset_lu_source", "UNROLLED_MAX_SIZE"]

#: largest matrix size whose LU is unrolled (for the interpreted tier; the factors and solve
#: of :func:`offset_lu_source` for both tiers); the source grows like k^3 (k^2 for a solve)
UNROLLED_MAX_SIZE = 8


_CLOSED_FORMS = {
    1: '''
@numba.njit(cache=True, inline="always")
def solve_1(A, b, x, piv):
    """x = A^{-1} b for a 1 x 1 matrix."""
    x[0] = b[0] / A[0, 0]
''',
    2: '''
@numba.njit(cache=True, inline="always")
def solve_2(A, b, x, piv):
    """x = A^{-1} b for a 2 x 2 matrix (Cramer's rule)."""
    det = A[0, 0] * A[1, 1] - A[0, 1] * A[1, 0]
    inv = 1.0 / det
    x0 = (A[1, 1] * b[0] - A[0, 1] * b[1]) * inv
    x1 = (A[0, 0] * b[1] - A[1, 0] * b[0]) * inv
    x[0] = x0
    x[1] = x1
''',
}

_LU = '''
@numba.njit(cache=True, inline="always")
def lu_factor(A, piv):
    """A <- its LU factors with partial pivoting (row exchanges in piv), in place."""
    k = A.shape[0]
    for c in range(k):
        best = abs(A[c, c])
        r_best = c
        for r in range(c + 1, k):
            if abs(A[r, c]) > best:
                best = abs(A[r, c])
                r_best = r
        piv[c] = r_best
        if r_best != c:  # columns from c on: the multipliers left of c stay with their step
            for j in range(c, k):
                tmp = A[c, j]
                A[c, j] = A[r_best, j]
                A[r_best, j] = tmp
        d = A[c, c]
        for r in range(c + 1, k):
            f = A[r, c] / d
            A[r, c] = f
            if f != 0.0:
                for j in range(c + 1, k):
                    A[r, j] -= f * A[c, j]


@numba.njit(cache=True, inline="always")
def lu_solve(A, piv, b):
    """b <- A^{-1} b with the factors of lu_factor, in place (the row exchanges and the
    eliminations applied to b in the order lu_factor made them)."""
    k = A.shape[0]
    for c in range(k):
        r = piv[c]
        if r != c:
            tmp = b[c]
            b[c] = b[r]
            b[r] = tmp
        for r in range(c + 1, k):
            b[r] -= A[r, c] * b[c]
    for c in range(k - 1, -1, -1):
        acc = b[c]
        for r in range(c + 1, k):
            acc -= A[c, r] * b[r]
        b[c] = acc / A[c, c]
'''

_BY_ELIMINATION = '''
@numba.njit(cache=True, inline="always")
def solve_{k}(A, b, x, piv):
    """x = A^{{-1}} b for a {k} x {k} matrix by elimination with partial pivoting; A is overwritten."""
    lu_factor(A, piv)
    for i in range({k}):
        x[i] = b[i]
    lu_solve(A, piv, x)
'''


def lu_source() -> str:
    """Source of ``lu_factor(A, piv)`` and ``lu_solve(A, piv, b)`` (in place)."""
    return _LU


def solve_source(size: int) -> str:
    """Source of ``solve_<size>(A, b, x, piv)``: ``x = A^{-1} b`` (``A`` may be overwritten;
    ``piv`` is an int64 work array of ``size`` entries).

    Closed forms for sizes 1 and 2; elimination with partial pivoting (needs
    :func:`lu_source` in the same module) otherwise. Size 0 gives a function that does
    nothing.
    """
    if size == 0:
        return '''
@numba.njit(cache=True, inline="always")
def solve_0(A, b, x, piv):
    """Nothing to solve (no constraints)."""
    return
'''
    if size in _CLOSED_FORMS:
        return _CLOSED_FORMS[size]
    return _BY_ELIMINATION.format(k=size)


def unrolled_lu_source(size: int) -> str:
    """Source of ``lu_factor_<size>(A, piv)`` and ``lu_solve_<size>(A, piv, b)``: the
    elimination of :func:`lu_source` for a ``size x size`` matrix written out as
    straight-line code on local floats (Golub & Van Loan, Algorithm 3.4.1, partial pivoting).

    Every operation of the loops is kept, in their order: the pivot of column ``c`` is the
    first row of largest ``|A[r, c]|`` (strict ``>``), the rows exchange their entries from
    column ``c`` on (the multipliers left of ``c`` stay with their step), each multiplier
    ``A[r, c] / A[c, c]`` is stored and, when not zero, ``A[r, j] - f A[c, j]`` formed; the
    solve applies the exchanges and eliminations in that order, then substitutes backwards
    with ``(b_c - A[c, c+1] b_{c+1} - ...) / A[c, c]``. So both give bit for bit what the
    loops give (a test checks this), and ``piv`` is interchangeable between the two forms.
    The loads go through ``float``: in the interpreter, arithmetic on Python floats costs a
    third of numpy's scalars (the values are the same doubles).
    """
    if size < 1:
        raise ValueError(f"an unrolled LU needs a size of at least 1, not {size}")
    k = size

    def a(i: int, j: int) -> str:
        return f"a{i}_{j}"

    lines = ["", "", "@numba.njit(cache=True)", f"def lu_factor_{k}(A, piv):",
             f'    """A <- its LU factors with partial pivoting, in place: lu_factor unrolled for {k} x {k}."""']
    lines += [f"    {a(i, j)} = float(A[{i}, {j}])" for i in range(k) for j in range(k)]
    for c in range(k - 1):
        lines += [f"    best = abs({a(c, c)})", f"    r_best = {c}"]
        for r in range(c + 1, k):
            lines += [f"    if abs({a(r, c)}) > best:", f"        best = abs({a(r, c)})", f"        r_best = {r}"]
        lines.append(f"    piv[{c}] = r_best")
        for r in range(c + 1, k):
            lines.append(f"    {'if' if r == c + 1 else 'elif'} r_best == {r}:")
            lines += [f"        {a(c, j)}, {a(r, j)} = {a(r, j)}, {a(c, j)}" for j in range(c, k)]
        for r in range(c + 1, k):
            lines += [f"    {a(r, c)} = {a(r, c)} / {a(c, c)}", f"    if {a(r, c)} != 0.0:"]
            lines += [f"        {a(r, j)} = {a(r, j)} - {a(r, c)} * {a(c, j)}" for j in range(c + 1, k)]
    lines.append(f"    piv[{k - 1}] = {k - 1}")
    lines += [f"    A[{i}, {j}] = {a(i, j)}" for i in range(k) for j in range(k)]
    lines += ["", "", "@numba.njit(cache=True)", f"def lu_solve_{k}(A, piv, b):",
              f'    """b <- A^{{-1}} b with the factors of lu_factor(_{k}), in place: lu_solve unrolled for {k} x {k}."""']
    lines += [f"    b{i} = float(b[{i}])" for i in range(k)]
    for c in range(k - 1):
        lines.append(f"    r_piv = piv[{c}]")
        for r in range(c + 1, k):
            lines += [f"    {'if' if r == c + 1 else 'elif'} r_piv == {r}:", f"        b{c}, b{r} = b{r}, b{c}"]
        lines += [f"    b{r} = b{r} - float(A[{r}, {c}]) * b{c}" for r in range(c + 1, k)]
    for c in range(k - 1, -1, -1):
        terms = "".join(f" - float(A[{c}, {r}]) * b{r}" for r in range(c + 1, k))
        lines.append(f"    b{c} = (b{c}{terms}) / float(A[{c}, {c}])")
    lines += [f"    b[{i}] = b{i}" for i in range(k)]
    return "\n".join(lines) + "\n"


def offset_lu_source(n: int) -> str:
    """Source of ``lu_factor_n(A, piv, dinv, o)`` and ``lu_solve_n(A, piv, dinv, b, o)``: the
    LU factors (partial pivoting, Golub & Van Loan, Algorithm 3.4.1) of an ``n x n`` matrix
    kept in rows ``o .. o + n - 1`` of ``A`` (row exchanges in ``piv[o:]``, the reciprocals
    of the pivots in ``dinv[o:]``), in loops of literal length, and the solve with them,
    written out for this ``n`` on local floats, inlined where they are called (the unconstrained RATTLE loop of
    :mod:`dirac.codegen.kernel_templates`, a few Newton matrices per sub-step, several
    solves each).

    Against the looped :func:`lu_source` on a slice ``A[o:o + n]``: no array views (each
    slice took and dropped a reference, two atomic operations per slice), no loads and
    stores of ``b`` through a row exchange's computed index inside the elimination, and the
    backward substitution multiplies by ``dinv`` (``1 / A[c, c]`` formed once per
    factorization) instead of dividing in every solve, taking the divisions off the chain
    of dependent operations of a Newton iteration (they were most of its latency). The pivot
    choices are those of the loops (the first row of largest ``|A[r, c]|``); the results
    differ from the loops' by rounding only. A zero pivot divides by zero
    (``ZeroDivisionError``, a singular Newton matrix) in both tiers: the reciprocal is formed
    from ``float(pivot)``, a Python float when interpreted (numpy's scalar division would
    return inf), a no-op when compiled.
    """
    if not 1 <= n <= UNROLLED_MAX_SIZE:
        raise ValueError(f"an unrolled offset LU needs 1 <= n <= {UNROLLED_MAX_SIZE}, not {n}")

    lines = ["", "", '@numba.njit(cache=True, inline="always")', "def lu_factor_n(A, piv, dinv, o):",
             f'    """Rows o .. o + {n} - 1 of A <- the LU factors of the ({n}, {n}) matrix there (row exchanges',
             '    in piv[o:], reciprocal pivots in dinv[o:]), in place."""',
             f"    for c in range({n}):",
             "        best = abs(A[o + c, c])",
             "        r_best = c",
             f"        for r in range(c + 1, {n}):",
             "            if abs(A[o + r, c]) > best:",
             "                best = abs(A[o + r, c])",
             "                r_best = r",
             "        piv[o + c] = r_best",
             "        if r_best != c:",
             f"            for j in range(c, {n}):",
             "                tmp = A[o + c, j]",
             "                A[o + c, j] = A[o + r_best, j]",
             "                A[o + r_best, j] = tmp",
             "        d = 1.0 / float(A[o + c, c])",  # a Python float in the interpreter: 1 / 0 raises there too
             "        dinv[o + c] = d",
             f"        for r in range(c + 1, {n}):",
             "            f = A[o + r, c] * d",
             "            A[o + r, c] = f",
             f"            for j in range(c + 1, {n}):",
             "                A[o + r, j] -= f * A[o + c, j]"]
    lines += ["", "", '@numba.njit(cache=True, inline="always")', "def lu_solve_n(A, piv, dinv, b, o):",
              f'    """b <- A^{{-1}} b for the factors of lu_factor_n of the ({n}, {n}) matrix in rows o .. o + {n} - 1',
              '    of A, in place."""']
    lines += [f"    b{i} = b[{i}]" for i in range(n)]
    for c in range(n - 1):
        lines.append(f"    r = piv[o + {c}]")
        for r in range(c + 1, n):
            lines += [f"    {'if' if r == c + 1 else 'elif'} r == {r}:", f"        b{c}, b{r} = b{r}, b{c}"]
        lines += [f"    b{r} = b{r} - A[o + {r}, {c}] * b{c}" for r in range(c + 1, n)]
    for c in range(n - 1, -1, -1):
        terms = "".join(f" - A[o + {c}, {r}] * b{r}" for r in range(c + 1, n))
        lines.append(f"    b{c} = (b{c}{terms}) * dinv[o + {c}]" if terms else f"    b{c} = b{c} * dinv[o + {c}]")
    lines += [f"    b[{i}] = b{i}" for i in range(n)]
    return "\n".join(lines) + "\n"
