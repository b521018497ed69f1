"""Source of one compiled Dirac vector field: grad H, grad Phi, C and its solve inlined.

The Hamiltonian vector field over second-class constraints ``Phi_a`` (the Dirac
bracket (240); Dirac, *Lectures on Quantum Mechanics*; Henneaux & Teitelboim, Ch. 1)

    z_dot = {z, H}_D = J g - J D^T x,    C x = D J g,
    g = grad H,   D = grad Phi  (k, N),   C_ab = {Phi_a, Phi_b} = D_a^T J D_b,

with ``J = [[0, 1], [-1, 0]]`` on ``z = (q, p)``, is printed by :func:`vector_field_source`
as one straight-line numba function whose body comes from the one field emitter :func:`dirac.codegen.field_body.dirac_field_body` (shared
with the step kernels of analysed systems): ``g`` and ``D`` with common sub-expressions
shared, ``C`` and ``D J g`` from their named entries, then Gaussian elimination with
partial pivoting unrolled on local scalars, or, past ``UNROLL_LIMIT`` lines, the looped
elimination ``solve_scratch`` on scratch space at the end of ``params``. ``params``
therefore holds ``PARAMS`` entries: the parameter values, then the scratch space (none
when unrolled). The generated functions hold the GIL, so callers on several threads never share the
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

from dirac.codegen.field_body import UNROLL_LIMIT, dirac_field_body
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
    banded: bool | None = None,
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
    banded
        For a looped solve (past ``unroll_limit``): on band storage after a
        bandwidth-reducing reordering of ``C`` (True; its cost and source grow linearly
        with ``k`` at a fixed bandwidth) or dense (False); None: banded where cheaper.

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
    inputs = {symbol: f"a{i}_" for i, symbol in enumerate(z)}
    inputs.update({symbol: f"c{i}_" for i, symbol in enumerate(parameters)})
    body = dirac_field_body(z, inputs, hamiltonian, second_class, title, time, forces, unroll_limit,
                            ("params", scratch), banded)
    lines = [f"    if z.shape[0] != {N} or out.shape[0] != {N}:",
             f'        raise ValueError("the state must have {N} entries")',
             "    if params.shape[0] != PARAMS:",
             '        raise ValueError("params must have PARAMS entries")']
    lines += [f"    a{i}_ = z[{i}]" for i in range(N)]
    lines += [f"    c{i}_ = params[{i}]" for i in range(len(parameters))]
    lines += body.lines

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
        f"#: entries of params: {len(parameters)} values, then {body.scratch_size} of scratch space for the solve",
        f"PARAMS = {len(parameters) + body.scratch_size}",
        "#: the entry of params that holds the time t (-1: the field does not depend on t)",
        f"TIME = {time_slot}",
        "",
        "",
        *body.solver.splitlines(),
        decorated("field_into"),
        "def field_into(z, params, out):",
        '    """z_dot = J grad H - J grad Phi^T C^{-1} (grad Phi J grad H) at z, into out (240)."""',
        *lines,
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
