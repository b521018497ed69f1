"""RATTLE with a constant mass matrix as fully unrolled scalar numba source.

The step of :func:`dirac.codegen.kernel_templates.mechanical_templates` keeps its
vectors in small arrays; numba cannot keep those in registers, and a hand-written kernel
beats it by the loads and stores. Here the same algorithm is written out per system with
every vector entry a local scalar (``q_0``, ``ph_1``, ``A_2_0`` ...), every loop over the
``n`` coordinates and ``m`` constraints unrolled at generation time, and the expressions
(``grad V``, ``chi``, ``G``, ``M^{-1} G^T``, ``M^{-1} x``, ``d chi/dt``) inlined as
straight-line code with shared sub-expressions (:func:`dirac.codegen.printer.straight_line`).
The multiplier solves are closed forms for ``m <= 2`` and an in-place elimination
(:mod:`dirac.codegen.small_solves`) otherwise.

The algorithm (Andersen 1983; Hairer, Lubich & Wanner VII.1.4), one sub-step of size
``h = dt * fractions[s]`` from ``(q, p)`` at time ``tau``:

    p_half = p - h/2 (grad V(q, tau) + G(q, tau)^T lam),   q1 = q + h M^{-1} p_half,
    chi(q1, tau + h) = 0  (Newton on lam, matrix -h^2/2 G(q1) M^{-1} G(q)^T),
    p1 = p_half - h/2 (grad V(q1, tau + h) + G(q1, tau + h)^T mu),
    G(q1) M^{-1} p1 + d chi/dt = 0  (an m x m solve for mu).
"""

from __future__ import annotations

import re
from collections.abc import Mapping, Sequence

import sympy

from dirac.codegen.printer import straight_line

__all__ = ["constant_mass_rattle_source"]


class _Writer:
    """Indented source lines, and inlined expression blocks with their own temporaries."""

    def __init__(self) -> None:
        self.lines: list[str] = []
        self.blocks = 0

    def __call__(self, depth: int, text: str) -> None:
        self.lines.append("    " * depth + text)

    def block(self, depth: int, inputs: Mapping[sympy.Symbol, str], expressions: Sequence[sympy.Expr],
              targets: Sequence[str]) -> None:
        """``targets[k] = expressions[k]`` as straight-line code (temporaries renamed per block)."""
        self.blocks += 1
        prefix = f"e{self.blocks}_"
        code = straight_line(inputs, list(expressions), "math", "cse", f"block {self.blocks}")

        def rename(text: str) -> str:
            return re.sub(r"\bt(\d+)\b", prefix + r"t\1", text)

        for name, value in code.assignments:
            self(depth, f"{rename(name)} = {rename(value)}")
        for target, value in zip(targets, code.outputs):
            self(depth, f"{target} = {rename(value)}")


def _names(stem: str, *sizes: int) -> list[str]:
    if len(sizes) == 1:
        return [f"{stem}_{i}" for i in range(sizes[0])]
    return [f"{stem}_{i}_{j}" for i in range(sizes[0]) for j in range(sizes[1])]


def constant_mass_rattle_source(
    coordinates: Sequence[sympy.Symbol],
    parameters: Sequence[sympy.Symbol],
    inverse_mass: sympy.Matrix,
    potential: sympy.Expr,
    constraints: Sequence[sympy.Expr],
    time: sympy.Symbol | None,
) -> str:
    """Source of ``rattle_constant_mass(q, p, t, c, fractions, dt, n_steps, tol, max_iter, info)``.

    Needs ``report`` and, for ``m > 2``, ``solve_<m>`` of the same module. ``info``
    reports ``[steps_done, failed, evaluations, last_residual]``; a sub-step whose Newton
    iteration does not converge restores the state of the last completed step.
    """
    q = list(coordinates)
    n, m = len(q), len(constraints)
    chi = sympy.Matrix(list(constraints))
    G = chi.jacobian(q) if m else sympy.zeros(0, n)
    grad_v = [sympy.diff(potential, s) for s in q]
    A = inverse_mass * G.T if m else sympy.zeros(n, 0)
    chi_t = [sympy.diff(e, time) if time is not None else sympy.S.Zero for e in chi]
    x = [sympy.Symbol(f"_x{i}", real=True) for i in range(n)]
    minv_x = list(inverse_mass * sympy.Matrix(x))
    c_names = {s: f"c_{k}" for k, s in enumerate(parameters)}

    def at(names: Sequence[str], when: str) -> dict[sympy.Symbol, str]:
        inputs = dict(zip(q, names))
        inputs.update(c_names)
        if time is not None:
            inputs[time] = when
        return inputs

    def vector(names: Sequence[str]) -> dict[sympy.Symbol, str]:
        inputs = dict(zip(x, names))
        inputs.update(c_names)
        return inputs

    qn, pn, phn, q1n, un, gvn = (_names(s, n) for s in ("q", "p", "ph", "q1", "u", "gv"))
    chin, ctn = _names("chi", m), _names("ct", m)
    G0, G1 = _names("G0", m, n), _names("G1", m, n)
    A0, A1 = _names("A0", n, m), _names("A1", n, m)
    w = _Writer()
    w(0, "@numba.njit(cache=True)")
    w(0, "def rattle_constant_mass(q, p, t, c, fractions, dt, n_steps, tol, max_iter, info):")
    w(1, '"""RATTLE, constant mass, unrolled scalar code (see dirac.codegen.rattle_scalar)."""')
    for k in range(len(parameters)):
        w(1, f"c_{k} = c[{k}]")
    for i in range(n):
        w(1, f"q_{i} = q[{i}]")
        w(1, f"p_{i} = p[{i}]")
    if m > 2:
        w(1, f"Jm = np.empty(({m}, {m}))")
        w(1, f"bm = np.empty({m})")
        w(1, f"xm = np.empty({m})")
        w(1, f"pivm = np.empty({m}, dtype=np.int64)")
    w(1, "evals = 0.0")
    w(1, "residual = 0.0")
    w(1, "for step in range(n_steps):")
    for i in range(n):
        w(2, f"qs_{i} = q_{i}")
        w(2, f"ps_{i} = p_{i}")
    w(2, "tau = t + step * dt")
    w(2, "for s in range(fractions.shape[0]):")
    d = 3
    w(d, "h = dt * fractions[s]")
    w(d, "tau1 = tau + h")
    w.block(d, at(qn, "tau"), grad_v, gvn)
    w(d, "evals += 1.0")
    for i in range(n):
        w(d, f"ph_{i} = p_{i} - 0.5 * h * gv_{i}")
    w.block(d, vector(phn), minv_x, un)
    for i in range(n):
        w(d, f"qp_{i} = q_{i} + h * u_{i}")
    if m:
        w.block(d, at(qn, "tau"), [*G, *A], [*G0, *A0])
        for a in range(m):
            w(d, f"lam_{a} = 0.0")
        for i in range(n):
            w(d, f"q1_{i} = qp_{i}")
        w(d, "converged = False")
        w(d, "for _it in range(max_iter):")
        e = d + 1
        w.block(e, at(q1n, "tau1"), list(chi), chin)
        w(e, "evals += 1.0")
        w(e, "residual = " + (f"max({', '.join(f'abs(chi_{a})' for a in range(m))})" if m > 1 else "abs(chi_0)"))
        w(e, "if residual <= tol * (1.0 + " + " + ".join(f"q1_{i} * q1_{i}" for i in range(n)) + "):")
        w(e + 1, "converged = True")
        w(e + 1, "break")
        w(e, "if residual != residual:")
        w(e + 1, "break")
        w.block(e, at(q1n, "tau1"), list(G), G1)
        for a in range(m):
            for b in range(m):
                terms = " + ".join(f"G1_{a}_{i} * A0_{i}_{b}" for i in range(n))
                w(e, f"J_{a}_{b} = -0.5 * h * h * ({terms})")
        _solve(w, e, m, "J", "chi", "d")
        for a in range(m):
            w(e, f"lam_{a} -= d_{a}")
        for i in range(n):
            terms = " + ".join(f"A0_{i}_{a} * lam_{a}" for a in range(m))
            w(e, f"q1_{i} = qp_{i} - 0.5 * h * h * ({terms})")
        w(d, "if not converged:")
        for i in range(n):
            w(d + 1, f"q[{i}] = qs_{i}")
            w(d + 1, f"p[{i}] = ps_{i}")
        w(d + 1, "report(info, step, True, evals, residual)")
        w(d + 1, "return")
        for i in range(n):
            terms = " + ".join(f"G0_{a}_{i} * lam_{a}" for a in range(m))
            w(d, f"ph_{i} -= 0.5 * h * ({terms})")
            w(d, f"q_{i} = q1_{i}")
    else:
        for i in range(n):
            w(d, f"q_{i} = qp_{i}")
    w.block(d, at(qn, "tau1"), grad_v, gvn)
    w(d, "evals += 1.0")
    for i in range(n):
        w(d, f"p_{i} = ph_{i} - 0.5 * h * gv_{i}")
    if m:
        w.block(d, at(qn, "tau1"), [*G, *A, *chi_t], [*G1, *A1, *ctn])
        w.block(d, vector(pn), minv_x, un)
        for a in range(m):
            w(d, f"rhs_{a} = ct_{a} + " + " + ".join(f"G1_{a}_{i} * u_{i}" for i in range(n)))
            for b in range(m):
                terms = " + ".join(f"G1_{a}_{i} * A1_{i}_{b}" for i in range(n))
                w(d, f"J_{a}_{b} = 0.5 * h * ({terms})")
        _solve(w, d, m, "J", "rhs", "mu")
        for i in range(n):
            terms = " + ".join(f"G1_{a}_{i} * mu_{a}" for a in range(m))
            w(d, f"p_{i} -= 0.5 * h * ({terms})")
    w(d, "tau = tau1")
    for i in range(n):
        w(1, f"q[{i}] = q_{i}")
        w(1, f"p[{i}] = p_{i}")
    w(1, "report(info, n_steps, False, evals, residual)")
    return "\n".join(w.lines) + "\n"


def _solve(w: _Writer, depth: int, m: int, matrix: str, rhs: str, out: str) -> None:
    """``out = matrix^{-1} rhs`` on scalars ``matrix_a_b``, ``rhs_a``: Cramer's rule for
    ``m <= 2``, else through the arrays ``Jm``, ``bm``, ``xm`` and ``solve_<m>``."""
    if m == 1:
        w(depth, f"{out}_0 = {rhs}_0 / {matrix}_0_0")
    elif m == 2:
        w(depth, f"det = 1.0 / ({matrix}_0_0 * {matrix}_1_1 - {matrix}_0_1 * {matrix}_1_0)")
        w(depth, f"{out}_0 = ({matrix}_1_1 * {rhs}_0 - {matrix}_0_1 * {rhs}_1) * det")
        w(depth, f"{out}_1 = ({matrix}_0_0 * {rhs}_1 - {matrix}_1_0 * {rhs}_0) * det")
    else:
        for a in range(m):
            w(depth, f"bm[{a}] = {rhs}_{a}")
            for b in range(m):
                w(depth, f"Jm[{a}, {b}] = {matrix}_{a}_{b}")
        w(depth, f"solve_{m}(Jm, bm, xm, pivm)")
        for a in range(m):
            w(depth, f"{out}_{a} = xm[{a}]")
