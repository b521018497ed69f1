"""Source of one compiled Dirac vector field: grad H, grad Phi, C and its solve inlined.

The Hamiltonian vector field over second-class constraints ``Phi_a`` (the Dirac
bracket (240); Dirac, *Lectures on Quantum Mechanics*; Henneaux & Teitelboim, Ch. 1)

    z_dot = {z, H}_D = J g - J D^T x,    C x = D J g,
    g = grad H,   D = grad Phi  (k, N),   C_ab = {Phi_a, Phi_b} = D_a^T J D_b,

with ``J = [[0, 1], [-1, 0]]`` on ``z = (q, p)``, is printed by :func:`vector_field_source`
as one straight-line numba function: ``g`` and ``D`` from sympy with common
sub-expressions shared (:func:`dirac.codegen.printer.straight_line`), then ``C`` and
``D J g`` from the named entries of ``D`` and ``g`` (terms of structurally zero entries
left out), then Gaussian elimination with partial pivoting on ``C``, unrolled on local
scalars: no array is allocated besides the output, no LAPACK is called. Row exchanges
of the pivoting are conditional swaps of local names; a column whose diagonal entry is
structurally zero takes its first structurally non-zero row before the comparisons.
When the unrolled elimination would exceed ``UNROLL_LIMIT`` lines (a large ``C`` with
much fill-in: the 24 second-class constraints of a rigid body), ``[C | D J g]`` is
written into scratch space at the end of ``params`` instead and solved there by one
looped elimination with partial pivoting (``solve_scratch``), which compiles in a
fraction of the time; still nothing is allocated. ``params`` therefore holds
``PARAMS`` entries: the parameter values, then the scratch space (none when unrolled).
The generated functions hold the GIL, so callers on several threads never share the
scratch space at the same time.

:func:`compile_vector_field` writes the source into the cache directory under the hash
of its text and imports it (as :func:`dirac.codegen.numba_backend.generate_module`), so
numba's on-disk cache keeps the machine code between runs. The module defines

* ``field(t, z, params) -> ndarray``: ``z_dot`` at ``z`` (a fresh array of ``N``); for a
  field with an explicit time (``time=``) it first writes ``t`` into ``params[TIME]``;
* ``field_into(z, params, out)``: the same into ``out``;
* ``field_batch(Z, params, OUT)``: rows of ``Z`` (B, N) into rows of ``OUT``;
* ``residual(z, params, out)`` and ``residual_batch(Z, params, OUT)``: the values of the
  constraints given as ``residual_expressions``.

With an explicit time ``t`` (a rheonomic system: ``H`` and ``Phi`` depend on ``t``), ``t`` is
one of the parameters, read from ``params[TIME]`` like the others, and the right side of
the solve gets the partial time derivative of the constraints, so that the motion stays on
the moving surface (Gitman–Tyutin; Dirac, *Lectures*):

    z_dot = J g - J D^T x,    C x = D J g + d_t Phi.

A singular ``C`` (off the constraint surface, or at a point where the constraints are
not second class) gives ``inf`` or ``NaN`` entries (numba's ``error_model="numpy"``),
never an exception.
"""

from __future__ import annotations

from collections.abc import Sequence
from types import ModuleType

import sympy

from dirac.codegen.numba_backend import import_source
from dirac.codegen.printer import straight_line

__all__ = ["vector_field_source", "compile_vector_field"]

_DECORATOR = '@numba.njit({signature!r}, cache=True, error_model="numpy")'
_SIGNATURES = {
    "field_into": "void(float64[::1], float64[::1], float64[::1])",
    "field": "float64[::1](float64, float64[::1], float64[::1])",
    "field_batch": "void(float64[:, ::1], float64[::1], float64[:, ::1])",
    "residual": "void(float64[::1], float64[::1], float64[::1])",
    "residual_batch": "void(float64[:, ::1], float64[::1], float64[:, ::1])",
}


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


class _Lines:
    """Source lines of the function body and fresh local names."""

    def __init__(self) -> None:
        self.lines: list[str] = []

    def add(self, text: str) -> None:
        self.lines.append("    " + text)


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

_SCRATCH_SOLVER = '''@numba.njit("void(float64[::1], int64, int64)", cache=True, error_model="numpy")
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


def _scratch_solve(lines: _Lines, matrix: list[list[str | None]], rhs: list[str | None], start: int) -> list[str | None]:
    """``matrix x = rhs`` by the looped solve ``solve_scratch`` on ``params[start:]``.

    The augmented matrix is written row by row into the scratch space (structurally
    zero entries as 0.0), solved in place, and ``x`` read back into local names.
    """
    k = len(matrix)
    m = k + 1
    for r in range(k):
        for j, value in enumerate([*matrix[r], rhs[r]]):
            lines.add(f"params[{start + r * m + j}] = {value or '0.0'}")
    lines.add(f"solve_scratch(params, {start}, {k})")
    x: list[str | None] = []
    for a in range(k):
        lines.add(f"x{a}_ = params[{start + a * m + k}]")
        x.append(f"x{a}_")
    return x


def vector_field_source(
    variables: Sequence[sympy.Symbol],
    parameters: Sequence[sympy.Symbol],
    hamiltonian: sympy.Expr,
    second_class: Sequence[sympy.Expr],
    residual_expressions: Sequence[sympy.Expr] = (),
    title: str = "Dirac vector field",
    unroll_limit: int = UNROLL_LIMIT,
    time: sympy.Symbol | None = None,
    forces: Sequence[sympy.Expr] = (),
) -> str:
    """Python source of the compiled Dirac vector field (see the module docstring).

    Parameters
    ----------
    variables
        The phase-space variables ``z = (q, p)``: ``n`` coordinates then their ``n``
        momenta, so ``{z_i, z_{n+i}} = 1``.
    parameters
        Symbols read from ``params`` in this order (parameters of the system, free
        multipliers of first-class constraints, ...).
    hamiltonian
        ``H`` (for a system with first-class primary constraints: ``H_c`` plus the free
        multipliers times them, the paper's (234) with the multipliers given).
    second_class
        The second-class constraints ``Phi_a``; ``C`` must be invertible on the surface.
    residual_expressions
        The expressions ``residual`` evaluates (typically every constraint).
    title
        First docstring line of the module.
    forces
        Generalized forces ``Q_i`` on the first ``len(forces)`` coordinates (functions of
        ``z``): the unprojected field becomes ``J grad H + (0, Q)`` (``p_dot = -dH/dq +
        Q``) before the Dirac projection, so that on the surface it is the forced motion
        with the multipliers solved with the forces.
    unroll_limit
        Largest number of source lines of the unrolled elimination; a larger one (large
        ``C`` with much fill-in, e.g. the 24 second-class constraints of a rigid body)
        is replaced by the looped solve, which compiles in a fraction of the time.
    time
        The explicit time ``t`` of a rheonomic system, one of ``parameters`` (its slot in
        ``params`` is ``TIME``, which ``field(t, z, params)`` fills): the solve gets
        ``d_t Phi`` on its right side. ``None`` (an autonomous field): ``TIME = -1``.

    Returns
    -------
    str
        The module source; its hash names the cached file.
    """
    z = list(variables)
    N = len(z)
    scratch = len(parameters)  # where the scratch space of the looped solve starts in params
    if N % 2:
        raise ValueError(f"a canonical phase space has an even dimension, not {N}")
    if time is not None and time not in parameters:
        raise ValueError(f"the time {time} must be one of the parameters")
    time_slot = -1 if time is None else list(parameters).index(time)
    n = N // 2
    k = len(second_class)
    gradient = [sympy.diff(hamiltonian, s) for s in z]
    for i, Q in enumerate(forces):  # (J g)_{n+i} = -g_i: p_dot_i = -dH/dq_i + Q_i
        gradient[i] = gradient[i] - Q
    jacobian = [[sympy.diff(phi, s) for s in z] for phi in second_class]
    inputs = {symbol: f"a{i}_" for i, symbol in enumerate(z)}
    inputs.update({symbol: f"c{i}_" for i, symbol in enumerate(parameters)})
    wanted: list[sympy.Expr] = []
    slots: list[tuple[str, int, int]] = []
    for i, g in enumerate(gradient):
        if g != 0:
            wanted.append(g)
            slots.append(("g", i, 0))
    for a, row in enumerate(jacobian):
        for i, d in enumerate(row):
            if d != 0:
                wanted.append(d)
                slots.append(("d", a, i))
    if time is not None:  # d_t Phi_a of a rheonomic constraint
        for a, phi in enumerate(second_class):
            derivative = sympy.diff(phi, time)
            if derivative != 0:
                wanted.append(derivative)
                slots.append(("t", a, 0))
    code = straight_line(inputs, wanted, "math", "cse", title)
    lines = _Lines()
    lines.add(f"if z.shape[0] != {N} or out.shape[0] != {N}:")
    lines.add(f'    raise ValueError("the state must have {N} entries")')
    lines.add("if params.shape[0] != PARAMS:")
    lines.add('    raise ValueError("params must have PARAMS entries")')
    for i in range(N):
        lines.add(f"a{i}_ = z[{i}]")
    for i in range(len(parameters)):
        lines.add(f"c{i}_ = params[{i}]")
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
    scratch_size = [0]
    solver_source: list[str] = []
    if k:
        # C_ab = sum_i D_a,i D_b,n+i - D_a,n+i D_b,i  (antisymmetric), b_a = (D J g)_a
        C: list[list[str | None]] = [[None] * k for _ in range(k)]
        for a in range(k):
            for b in range(a + 1, k):
                entry = _sum([term for i in range(n) for term in (
                    ("+", _product(d_name[a][i], d_name[b][n + i])), ("-", _product(d_name[a][n + i], d_name[b][i])))])
                if entry is not None:
                    lines.add(f"C{a}_{b}_ = {entry}")
                    lines.add(f"C{b}_{a}_ = -C{a}_{b}_")
                    C[a][b], C[b][a] = f"C{a}_{b}_", f"C{b}_{a}_"
        rhs: list[str | None] = []
        for a in range(k):  # b_a = (D J g)_a + d_t Phi_a
            entry = _sum([term for i in range(n) for term in (
                ("+", _product(d_name[a][i], g_name[n + i])), ("-", _product(d_name[a][n + i], g_name[i])))]
                + [("+", t_name[a])])
            if entry is not None:
                lines.add(f"b{a}_ = {entry}")
            rhs.append(f"b{a}_" if entry is not None else None)
        unrolled = _Lines()
        x = _elimination(unrolled, C, rhs)
        if len(unrolled.lines) <= unroll_limit:
            lines.lines.extend(unrolled.lines)
        else:
            x = _scratch_solve(lines, C, rhs, scratch)
            scratch_size[0] = k * (k + 1)
            solver_source = _SCRATCH_SOLVER.splitlines()
        # w = D^T x
        for j in range(N):
            total = _sum([("+", _product(d_name[a][j], x[a])) for a in range(k)])
            correction[j] = None if total is None else f"({total})"
    for i in range(n):
        lines.add(f"out[{i}] = {_sum([('+', g_name[n + i]), ('-', correction[n + i])]) or '0.0'}")
    for i in range(n):
        lines.add(f"out[{n + i}] = {_sum([('-', g_name[i]), ('+', correction[i])]) or '0.0'}")

    residual_inputs = straight_line(inputs, list(residual_expressions), "math", "cse", f"{title}: residual")
    residual_lines = [f"    if z.shape[0] != {N}:", f'        raise ValueError("the state must have {N} entries")']
    residual_lines += [f"    a{i}_ = z[{i}]" for i in range(N)]
    residual_lines += [f"    c{i}_ = params[{i}]" for i in range(len(parameters))]
    residual_lines += residual_inputs.body()
    residual_lines += [f"    out[{r}] = {value}" for r, value in enumerate(residual_inputs.outputs)]
    residual_lines += ["    return"]

    def decorated(name: str) -> str:
        return _DECORATOR.format(signature=_SIGNATURES[name])

    source = [
        f'"""{title} -- generated by dirac.codegen.field_source; do not edit."""',
        "import math",
        "import numpy as np",
        "import numba",
        "",
        f"N = {N}",
        f"K = {len(residual_expressions)}",
        f"#: entries of params: {len(parameters)} values, then {scratch_size[0]} of scratch space for the solve",
        f"PARAMS = {len(parameters) + scratch_size[0]}",
        "#: the entry of params that holds the time t (-1: the field does not depend on t)",
        f"TIME = {time_slot}",
        "",
        "",
        *solver_source,
        decorated("field_into"),
        "def field_into(z, params, out):",
        '    """z_dot = J grad H - J grad Phi^T C^{-1} (grad Phi J grad H) at z, into out (240)."""',
        *lines.lines,
        "",
        "",
        decorated("field"),
        "def field(t, z, params):",
        ('    """z_dot at z as a new array (t is not used: the field is autonomous)."""' if time is None else
         '    """z_dot at z and the time t (written into params[TIME]) as a new array."""'),
        *([] if time is None else ["    params[TIME] = t"]),
        "    out = np.empty(N)",
        "    field_into(z, params, out)",
        "    return out",
        "",
        "",
        decorated("field_batch"),
        "def field_batch(Z, params, OUT):",
        '    """field_into on every row of Z (B, N) into the rows of OUT."""',
        "    if Z.shape[1] != N or OUT.shape[0] != Z.shape[0] or OUT.shape[1] != N:",
        f'        raise ValueError("the states must have shape (B, {N})")',
        "    for b in range(Z.shape[0]):",
        "        field_into(Z[b], params, OUT[b])",
        "",
        "",
        decorated("residual"),
        "def residual(z, params, out):",
        '    """The constraint values at z, into out."""',
        *residual_lines,
        "",
        "",
        decorated("residual_batch"),
        "def residual_batch(Z, params, OUT):",
        '    """residual on every row of Z (B, N) into the rows of OUT (B, K)."""',
        "    for b in range(Z.shape[0]):",
        "        residual(Z[b], params, OUT[b])",
        "",
    ]
    return "\n".join(source)


def compile_vector_field(source: str) -> ModuleType:
    """Write ``source`` to the cache directory under the hash of its text and import it
    (:func:`dirac.codegen.numba_backend.import_source`, the one disk cache of generated code).

    The functions compile at import for their one signature each; numba caches the
    machine code on disk next to the file, so a later run with the same source loads it.
    """
    return import_source(source)
