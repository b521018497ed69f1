"""Flattening a generated module: helpers inlined, code that never runs or is never read
dropped, parameters loaded once; the flattened source computes what the source as written
computes (both run by the interpreter here, the values checked by hand)."""

from __future__ import annotations

import ast

import numpy as np

from dirac.codegen.flatten import flatten_source, specialise_solves
from dirac.codegen.numba_backend import interpret_source
from dirac.codegen.small_solves import lu_source

_SOURCE = '''"""tidy -- generated for a test"""
import math
import numpy as np
import numba


@numba.njit(cache=True, inline="always")
def scaled(q, c, out):
    """out = c0 * q + c1 (c2 read and never used)."""
    c0_ = c[0]
    c1_ = c[1]
    c2_ = c[2]
    for i in range(2):
        out[i] = c0_ * q[i] + c1_


@numba.njit(cache=True)
def run(q, c, n_steps, out):
    """n_steps of q <- c0 q + c1, twice per step through the helper; a constraint loop of
    zero length and a branch on 0 > 0 (a system without constraints) never run."""
    spare = np.empty(0)
    tmp = np.empty(2)
    for step in range(n_steps):
        scaled(q, c, tmp)
        scaled(tmp, c, q)
        for a in range(0):
            q[0] += spare[a]
        if 0 > 0:
            q[1] = -1.0
        else:
            q[1] += 0.0
    out[0] = q[0]
    out[1] = q[1]
'''


def _function(source: str, name: str) -> ast.FunctionDef:
    return next(node for node in ast.parse(source).body if isinstance(node, ast.FunctionDef) and node.name == name)


def test_dead_code_unused_loads_and_repeated_parameter_loads_are_gone() -> None:
    """In the flattened ``run``: no ``range(0)`` loop, no ``if 0 > 0``, no allocation or load
    nobody reads, and each parameter ``c[k]`` read once, at the top (two inlined copies of
    the helper read ``c[0]`` and ``c[1]`` twice each and ``c[2]`` for nothing)."""
    flat = flatten_source(_SOURCE)
    run = _function(flat, "run")
    body = run.body[1:]  # after the docstring
    text = "\n".join(ast.unparse(statement) for statement in body)
    assert "range(0)" not in text and "0 > 0" not in text and "spare" not in text
    loads = [node for node in ast.walk(run) if isinstance(node, ast.Subscript)
             and isinstance(node.value, ast.Name) and node.value.id == "c"]
    assert sorted(ast.unparse(node) for node in loads) == ["c[0]", "c[1]"]
    assert [ast.unparse(s) for s in body[:2]] == ["_c0_ = c[0]", "_c1_ = c[1]"]
    assert "scaled(" not in text  # both calls inlined


def test_the_flattened_source_computes_the_hand_iteration() -> None:
    """Each step applies q <- 2 q + 1 twice to q[0] (and to q[1]): from q = (1, 0) after
    one step q = (2 (2 + 1) + 1, 2 (0 + 1) + 1) = (7, 3), after two (31, 15)."""
    c = np.array([2.0, 1.0, 99.0])
    for source in (_SOURCE, flatten_source(_SOURCE)):
        module = interpret_source(source)
        q, out = np.array([1.0, 0.0]), np.empty(2)
        module.run(q, c, 1, out)
        assert out.tolist() == [7.0, 3.0]
        q = np.array([1.0, 0.0])
        module.run(q, c, 2, out)
        assert out.tolist() == [31.0, 15.0]


_SOLVES = '''"""solves -- generated for a test"""
import math
import numpy as np
import numba
''' + lu_source() + '''

@numba.njit(cache=True)
def fixed(b):
    """A literal 3 x 3 matrix: its solves are specialised."""
    A = np.empty((3, 3))
    piv = np.empty(3, dtype=np.int64)
    for i in range(3):
        for j in range(3):
            A[i, j] = 1.0 / (i + j + 1) + (4.0 if i == j else 0.0)
    lu_factor(A, piv)
    lu_solve(A, piv, b)


@numba.njit(cache=True)
def sized_at_run_time(z, b):
    """A matrix whose size is known only at run time: left to the loops."""
    n = z.shape[0]
    A = np.empty((n, n))
    piv = np.empty(n, dtype=np.int64)
    for i in range(n):
        for j in range(n):
            A[i, j] = 1.0 / (i + j + 1) + (4.0 if i == j else 0.0)
    lu_factor(A, piv)
    lu_solve(A, piv, b)
'''


def test_solves_of_a_literal_size_are_unrolled_and_the_others_left_to_the_loops() -> None:
    """specialise_solves renames the calls on the 3 x 3 matrix only and appends their
    unrolled forms; both functions still solve (4 I + H) x = b, H the 3 x 3 Hilbert matrix,
    which numpy.linalg.solve gives too."""
    specialised = specialise_solves(_SOLVES)
    tree = ast.parse(specialised)
    calls = {name: sorted({n.func.id for n in ast.walk(f) if isinstance(n, ast.Call) and isinstance(n.func, ast.Name)
                           and n.func.id.startswith("lu_")})
             for f in tree.body if isinstance(f, ast.FunctionDef) for name in [f.name]}
    assert calls["fixed"] == ["lu_factor_3", "lu_solve_3"]
    assert calls["sized_at_run_time"] == ["lu_factor", "lu_solve"]
    assert {"lu_factor_3", "lu_solve_3"} <= set(calls)  # appended to the module
    module = interpret_source(specialised)
    matrix = np.array([[1.0 / (i + j + 1) + (4.0 if i == j else 0.0) for j in range(3)] for i in range(3)])
    b = np.array([1.0, 2.0, 3.0])
    x1, x2 = b.copy(), b.copy()
    module.fixed(x1)
    module.sized_at_run_time(np.zeros(3), x2)
    assert x1.tobytes() == x2.tobytes()
    np.testing.assert_allclose(x1, np.linalg.solve(matrix, b), rtol=1e-14)
    assert specialise_solves(_SOURCE) == _SOURCE  # nothing to specialise: unchanged


def test_one_function_is_specialised_alone_when_the_interpreter_first_runs_it() -> None:
    """specialised_function parses only the function asked for: ``fixed`` comes back with
    its unrolled solves, put into the interpreted module it solves (4 I + H) x = b as the
    loops do, bit for bit; ``sized_at_run_time`` (no literal size) and a function that is
    not there give None."""
    from dirac.codegen.flatten import specialised_function

    text = specialised_function(_SOLVES, "fixed")
    assert text is not None and "lu_factor_3(A, piv)" in text and "def lu_solve_3(" in text
    assert "def lu_factor(" not in text
    assert specialised_function(_SOLVES, "sized_at_run_time") is None
    assert specialised_function(_SOLVES, "absent") is None
    module = interpret_source(_SOLVES)
    b = np.array([1.0, 2.0, 3.0])
    looped, unrolled = b.copy(), b.copy()
    module.fixed(looped)
    exec(compile(text, "<specialised fixed>", "exec"), module.__dict__)
    module.fixed(unrolled)
    assert looped.tobytes() == unrolled.tobytes()


_BLOCKS = '''"""blocks -- generated for a test"""
import math
import numpy as np
import numba
''' + lu_source() + '''

@numba.njit(cache=True)
def blocks(b, c):
    """Two 2 x 2 matrices stacked in one (4, 2) allocation, factored as the blocks J[:2] and J[2:]."""
    J = np.empty((2 * 2, 2))
    piv = np.empty(2 * 2, dtype=np.int64)
    J[0, 0] = 1.0
    J[0, 1] = 2.0
    J[1, 0] = 3.0
    J[1, 1] = 4.0
    J[2, 0] = 0.5
    J[2, 1] = -1.0
    J[3, 0] = 2.0
    J[3, 1] = 0.25
    lu_factor(J[:2], piv[:2])
    lu_factor(J[2:], piv[2:])
    lu_solve(J[:2], piv[:2], b)
    lu_solve(J[2:], piv[2:], c)
'''


def test_the_square_blocks_of_one_allocation_are_unrolled_too() -> None:
    """``lu_factor(J[:2], ...)`` and ``lu_factor(J[2:], ...)`` of a ``(2 * 2, 2)`` allocation (the
    two Newton matrices of the unconstrained RATTLE loop) call the unrolled 2 x 2 forms; the
    solutions are the loops' bit for bit and Cramer's rule's: [[1, 2], [3, 4]] x = (1, 1) gives
    x = (-1, 1), [[0.5, -1], [2, 0.25]] y = (1, 2) gives y = (18 / 17, -8 / 17) (determinants -2
    and 2.125)."""
    specialised = specialise_solves(_BLOCKS)
    assert "lu_factor_2(J[:2], piv[:2])" in specialised and "lu_factor_2(J[2:], piv[2:])" in specialised
    assert "lu_solve_2(J[2:], piv[2:], c)" in specialised
    results = []
    for source in (_BLOCKS, specialised):
        b, c = np.array([1.0, 1.0]), np.array([1.0, 2.0])
        interpret_source(source).blocks(b, c)
        results.append(b.tobytes() + c.tobytes())
        np.testing.assert_allclose(b, [-1.0, 1.0], rtol=1e-15)
        np.testing.assert_allclose(c, [18.0 / 17.0, -8.0 / 17.0], rtol=1e-15)
    assert results[0] == results[1]


_CHOICE = '''"""choice -- generated for a test"""
import numpy as np
import numba


@numba.njit(cache=True, inline="always")
def note(info, flag, value):
    """info = [1 if flag else 0, value]."""
    info[0] = 1.0 if flag else 0.0
    info[1] = value


@numba.njit(cache=True)
def run(x, info):
    """Notes failure (True) when x < 0, else success (False)."""
    if x < 0.0:
        note(info, True, x)
        return
    note(info, False, 2.0 * x)
'''


def test_a_choice_on_a_literal_argument_is_folded_to_its_value() -> None:
    """The helper's ``1.0 if flag else 0.0``, inlined with ``flag`` a literal ``True`` or
    ``False``, becomes ``1.0`` or ``0.0`` (numba would make three blocks of each choice), and
    the flattened ``run`` still computes by hand: x = -3 gives info = (1, -3), x = 2.5 gives
    (0, 5)."""
    flat = flatten_source(_CHOICE)
    run = _function(flat, "run")
    assert not any(isinstance(node, ast.IfExp) for node in ast.walk(run))
    for source in (_CHOICE, flat):
        module = interpret_source(source)
        info = np.zeros(2)
        module.run(-3.0, info)
        assert info.tolist() == [1.0, -3.0]
        module.run(2.5, info)
        assert info.tolist() == [0.0, 5.0]


_WORKED = '''"""worked -- generated for a test"""
import numpy as np
import numba


@numba.njit(cache=True)
def halve_work():
    """Work arrays of halve."""
    return (np.empty(2), np.empty((2, 2)))


@numba.njit(cache=True)
def halve(z, tol, work):
    """Halve z until its largest entry is at most tol, at most 5 times (a return in the loop)."""
    y, M = work
    for _it in range(5):
        size = 0.0
        for i in range(2):
            size = max(size, abs(z[i]))
        if size <= tol:
            return
        for i in range(2):
            M[i, i] = 0.5
            y[i] = M[i, i] * z[i]
            z[i] = y[i]


@numba.njit(cache=True)
def run(z, tol, n_steps, out):
    w = halve_work()
    for step in range(n_steps):
        z[0] += 3.0
        halve(z, tol, w)
        out[step] = z[0]


@numba.njit(cache=True)
def big(z, tol):
    J = np.empty((9, 9))
    piv = np.empty(9, dtype=np.int64)
    w = halve_work()
    lu_factor(J, piv)
    halve(z, tol, w)


@numba.njit(cache=True)
def leaks(z, tol):
    w = halve_work()
    halve(z, tol, w)
    return w
'''


def test_a_helper_handed_a_work_tuple_is_inlined_with_one_array_per_entry() -> None:
    """``w = halve_work()`` becomes one allocation per array, ``halve`` is inlined with its
    ``return`` made a ``break`` of its last loop; the loop then computes what the source as
    written computes, and the hand iteration (z = (0, 40), tol = 1): step 0, z0 = 3, five
    halvings (the cap: |z1| = 1.25 still > 1) give 0.09375; step 1, z0 = 3.09375, two halvings
    (|z| <= 1 after the second: the early exit) give 0.7734375; step 2, z0 = 3.7734375, two
    halvings give 0.943359375. A tuple that leaves the function is left alone, and so is a
    loop whose own solve stays looped (9 x 9, over the unrolled sizes: its integer pivots keep
    it off the tape anyway)."""
    from dirac.codegen.flatten import function_text, inline_worked_helpers

    text = inline_worked_helpers(_WORKED, function_text(_WORKED, "run") or "")
    assert text is not None and "halve(" not in text and "halve_work" not in text and "break" in text
    assert "w_y = np.empty(2)" in text and "w_M = np.empty((2, 2))" in text
    written = interpret_source(_WORKED)
    inlined = interpret_source(_WORKED)
    exec(compile(text, "<inlined>", "exec"), inlined.__dict__)
    results = []
    for module in (written, inlined):
        z, out = np.array([0.0, 40.0]), np.zeros(3)
        module.run(z, 1.0, 3, out)
        results.append((z.tolist(), out.tolist()))
    assert results[0] == results[1]
    assert results[1][1] == [0.09375, 0.7734375, 0.943359375]
    assert inline_worked_helpers(_WORKED, function_text(_WORKED, "leaks") or "") is None
    assert inline_worked_helpers(_WORKED, function_text(_WORKED, "big") or "") is None
    small = _WORKED.replace("(9, 9)", "(2, 2)")
    assert inline_worked_helpers(small, function_text(small, "big") or "") is not None
