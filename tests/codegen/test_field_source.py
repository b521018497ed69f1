"""The generated Dirac vector field: grad H, grad Phi, C and the unrolled pivoted solve."""

from __future__ import annotations

import numpy as np
import pytest
import sympy

from dirac.codegen.field_source import compile_vector_field, vector_field_source

n, k = 4, 4
q = sympy.symbols(f"q1:{n + 1}", real=True)
p = sympy.symbols(f"p1:{n + 1}", real=True)
z = (*q, *p)
A = sympy.Matrix(k, 2 * n, lambda a, i: sympy.Symbol(f"A_{a}_{i}", real=True))
S = sympy.Matrix(2 * n, 2 * n, lambda i, j: sympy.Symbol(f"S_{min(i, j)}_{max(i, j)}", real=True))
c = sympy.Matrix(2 * n, 1, lambda i, _: sympy.Symbol(f"c_{i}", real=True))
Z = sympy.Matrix(z)
PARAMETERS = sorted((A.free_symbols | S.free_symbols | c.free_symbols), key=lambda s: s.name)
J = np.block([[np.zeros((n, n)), np.eye(n)], [-np.eye(n), np.zeros((n, n))]])


@pytest.fixture(scope="module", params=["unrolled", "looped"])
def linear_module(request):
    """Quadratic ``H = 1/2 z^T S z + c^T z`` and linear constraints ``Phi = A z``, all
    coefficients parameters: ``C = A J A^T`` is a dense antisymmetric matrix, so every
    column's diagonal is structurally zero and the pivoting decides at run time. Both
    solves: unrolled, and looped in the scratch space (``unroll_limit=0``)."""
    H = (Z.T * S * Z)[0, 0] / 2 + (c.T * Z)[0, 0]
    constraints = list(A * Z)
    limit = {"unrolled": 10_000, "looped": 0}[request.param]
    source = vector_field_source(z, PARAMETERS, H, constraints, constraints, title="linear test field",
                                 unroll_limit=limit)
    module = compile_vector_field(source)
    assert module.PARAMS == len(PARAMETERS) + (k * (k + 1) if request.param == "looped" else 0)
    return module


def _values(rng: np.random.Generator, module) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
    a = rng.normal(size=(k, 2 * n))
    s = rng.normal(size=(2 * n, 2 * n))
    s = s + s.T
    cc = rng.normal(size=2 * n)
    values = {}
    for (i, j), symbol in np.ndenumerate(np.array(A, dtype=object)):
        values[symbol] = a[i, j]
    for i in range(2 * n):
        for j in range(i, 2 * n):
            values[S[i, j]] = s[i, j]
        values[c[i, 0]] = cc[i]
    params = np.zeros(len(PARAMETERS) + k * (k + 1))  # the values, then the scratch space if looped
    params[:len(PARAMETERS)] = [values[symbol] for symbol in PARAMETERS]
    return a, s, cc, params[:module.PARAMS].copy()


def test_linear_field_against_the_dense_formula(linear_module):
    """z_dot = J g - J A^T C^{-1} (A J g), g = S z + c, C = A J A^T (the Dirac bracket (240)
    of linear constraints), solved by numpy; 200 random systems, so both outcomes of
    every pivot comparison occur."""
    rng = np.random.default_rng(7)
    for _ in range(200):
        a, s, cc, params = _values(rng, linear_module)
        point = rng.normal(size=2 * n)
        g = s @ point + cc
        C = a @ J @ a.T
        expected = J @ g - J @ a.T @ np.linalg.solve(C, a @ J @ g)
        got = linear_module.field(0.0, point, params)
        scale = 1.0 + np.abs(expected).max()
        assert np.max(np.abs(got - expected)) <= 1e-10 * scale * np.linalg.cond(C)
        # the field is tangent to the constraint surface: A z_dot = 0 (round-off)
        assert np.max(np.abs(a @ got)) <= 1e-10 * scale * np.linalg.cond(C)
        residual = np.empty(k)
        linear_module.residual(point, params, residual)
        assert np.allclose(residual, a @ point, rtol=1e-13, atol=1e-13)


def test_a_small_first_pivot_is_exchanged():
    """Phi = (q1, q2, p2 + eps p1, p1), eps = 1e-17: by hand C_13 = eps, C_14 = 1,
    C_23 = 1, the rest zero, so column 1 of C holds -eps and -1 below the diagonal.
    As many constraints as dimensions: D = grad Phi is invertible and
    J D^T (D J D^T)^{-1} D J = J, so the Dirac field vanishes at every point (z_dot = 0).
    Eliminating with the pivot -eps instead of -1 gives z_dot = (0, -0.7, 0, 0) here."""
    q1, q2, p1, p2 = sympy.symbols("q1 q2 p1 p2", real=True)
    eps = sympy.Float(1e-17)
    constraints = [q1, q2, p2 + eps * p1, p1]
    H = p1**2 / 2 + q2 * p2
    module = compile_vector_field(vector_field_source((q1, q2, p1, p2), (), H, constraints, constraints,
                                                      title="pivot test field"))
    point = np.array([0.3, -0.7, 1.1, 0.4])
    got = module.field(0.0, point, np.empty(0))
    assert np.max(np.abs(got)) <= 1e-15


def test_batch_rows_equal_single_calls(linear_module):
    rng = np.random.default_rng(3)
    *_, params = _values(rng, linear_module)
    states = rng.normal(size=(5, 2 * n))
    out = np.empty_like(states)
    linear_module.field_batch(states, params, out)
    for row, state in zip(out, states):
        assert np.array_equal(row, linear_module.field(0.0, state, params))


def test_a_state_of_the_wrong_length_is_refused(linear_module):
    *_, params = _values(np.random.default_rng(1), linear_module)
    with pytest.raises(ValueError, match="8 entries"):
        linear_module.field(0.0, np.zeros(7), params)


def test_the_module_is_cached_on_disk_by_the_hash_of_its_source(linear_module):
    import hashlib

    from dirac.codegen import cache_directory

    path = cache_directory() / f"{linear_module.__name__}.py"
    source = path.read_text(encoding="utf-8")
    assert linear_module.__name__ == f"dirac_gen_{hashlib.sha256(source.encode()).hexdigest()[:20]}"
    assert compile_vector_field(source) is linear_module


def test_explicit_time_puts_the_partial_time_derivative_into_the_solve():
    """A particle driven along q1 = c t^2/2 (the chain's Phi = (q1 - c t^2/2, p1 - c t)),
    free along q2, with H = (p1^2 + p2^2)/2 + k q2: by hand q1_ddot = c (the driving), which
    only the term d_t Phi in C x = {Phi, H} + d_t Phi gives ({Phi, H} alone gives p1_dot = 0);
    q2 moves freely, p2_dot = -k. The time is the last parameter, written by field(t, ...)."""
    q1, q2, p1, p2, cc, kk, tt = sympy.symbols("q1 q2 p1 p2 c k t", real=True)
    H = (p1**2 + p2**2) / 2 + kk * q2
    phi = [q1 - cc * tt**2 / 2, p1 - cc * tt]
    module = compile_vector_field(vector_field_source((q1, q2, p1, p2), [cc, kk, tt], H, phi, phi,
                                                      title="driven test field", time=tt))
    assert module.TIME == 2
    params = np.array([0.7, 0.3, 0.0])
    for time in (0.0, 1.3, -2.0):
        state = np.array([0.7 * time**2 / 2, 0.4, 0.7 * time, -1.1])  # on the surface at this time
        rate = module.field(time, state, params)
        assert params[2] == time  # field wrote the time into its slot
        assert rate == pytest.approx([0.7 * time, -1.1, 0.7, -0.3], abs=1e-15)
        residual = np.empty(2)
        module.residual(state, params, residual)
        assert residual == pytest.approx([0.0, 0.0], abs=1e-15)
    autonomous = compile_vector_field(vector_field_source((q1, q2, p1, p2), [cc, kk], H.subs(tt, 0), [q1, p1],
                                                          title="autonomous test field"))
    assert autonomous.TIME == -1
