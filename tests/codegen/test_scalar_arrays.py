"""The interpreted tier's rewriting of a step loop (:mod:`dirac.codegen.scalar_arrays`):
loops of literal length unrolled, small work arrays as locals, element reads as Python
numbers; the same floating-point operations in the same order, so the same bits."""

from __future__ import annotations

import ast
import math

import numpy as np

from dirac.codegen.scalar_arrays import UNROLL_MAX, scalar_function

_LOOP = '''
def run(q, p, c, dt, n_steps, out):
    """n_steps of q <- q + dt M p, p <- p - dt sin(q) with M = [[c0, c1], [c1, c2]] (loops of
    literal length over work arrays allocated once)."""
    M = np.empty((2, 2))
    v = np.zeros(2)
    M[0, 0] = c[0]
    M[0, 1] = c[1]
    M[1, 0] = c[1]
    M[1, 1] = c[2]
    for step in range(n_steps):
        for i in range(2):
            acc = 0.0
            for j in range(2):
                acc += M[i, j] * p[j]
            v[i] = acc
        for i in range(2):
            q[i] = q[i] + dt * v[i]
            p[i] = p[i] - dt * math.sin(q[i])
    out[0] = v[0] + v[1]
'''


def _run(text: str, *args):
    namespace = {"np": np, "math": math}
    exec(text, namespace)
    return namespace["run"](*args)


def _hand(q: list[float], p: list[float], c: list[float], dt: float, steps: int) -> tuple[list[float], list[float], float]:
    """The loop written out by hand on Python floats."""
    v0 = v1 = 0.0
    for _ in range(steps):
        v0 = 0.0 + c[0] * p[0] + c[1] * p[1]
        v1 = 0.0 + c[1] * p[0] + c[2] * p[1]
        q[0] = q[0] + dt * v0
        p[0] = p[0] - dt * math.sin(q[0])
        q[1] = q[1] + dt * v1
        p[1] = p[1] - dt * math.sin(q[1])
    return q, p, v0 + v1


def test_the_rewritten_loop_gives_the_hand_loop_bit_for_bit_and_keeps_no_small_loop_or_work_array() -> None:
    """Loops unrolled (no ``range(2)`` left), ``M`` and ``v`` made locals, the iterates equal to
    the original loop's and to the hand-written one's to the last bit."""
    text = scalar_function(_LOOP, "run")
    assert text is not None
    tree = ast.parse(text)
    assert "range(2)" not in text and "range(n_steps)" in text
    assert not any(isinstance(node, ast.Subscript) and isinstance(node.value, ast.Name) and node.value.id in ("M", "v")
                   for node in ast.walk(tree))
    c, dt, steps = [1.3, 0.2, 0.7], 0.01, 50
    results = []
    for source in (_LOOP, text):
        q, p, out = np.array([0.3, -0.2]), np.array([0.1, 0.4]), np.zeros(1)
        _run(source, q, p, np.array(c), dt, steps, out)
        results.append((q.tolist(), p.tolist(), out[0]))
    assert results[0] == results[1] == _hand([0.3, -0.2], [0.1, 0.4], c, dt, steps)


def test_reads_become_python_numbers_and_writes_stay_in_the_arrays() -> None:
    """``q[i]`` read as ``q.item(i)`` (a Python float: the arithmetic runs on floats), written
    back in place (the caller's state)."""
    text = scalar_function(_LOOP, "run")
    assert text is not None and "q.item(0)" in text and "q[0] = " in text and "out[0] = " in text


_KEPT = '''
def run(x, piv, n):
    """A loop that leaves early, and an array indexed by a variable: both kept."""
    w = np.empty(3)
    for i in range(3):
        w[i] = x[i]
        if x[i] < 0.0:
            break
    k = piv[0]
    w[k] = 2.0 * w[k]
    x[0] = w[0] + w[1] + w[2]
    for j in range(UNROLL):
        x[1] += 1.0
'''.replace("UNROLL", str(UNROLL_MAX + 1))


def test_a_loop_that_breaks_a_variable_index_and_a_long_loop_are_kept() -> None:
    """``break`` (the iterations that run depend on the data), ``w[k]`` (an address known only
    at run time) and a loop longer than :data:`UNROLL_MAX`: left as they are; the results are
    the original's (x0 = 1 + 2 * 2 + 3 = 8 when piv[0] = 1, x1 = UNROLL_MAX + 1)."""
    text = scalar_function(_KEPT, "run")
    assert text is not None  # the element reads still become .item
    assert "break" in text and "w[k]" in text and f"range({UNROLL_MAX + 1})" in text
    for source in (_KEPT, text):
        x = np.array([1.0, 2.0, 3.0])
        _run(source, x, np.array([1]), 3)
        assert x.tolist() == [8.0, 2.0 + UNROLL_MAX + 1, 3.0]


def test_a_function_with_nothing_to_rewrite_is_left_alone() -> None:
    assert scalar_function("def run(a, b):\n    return a + b\n", "run") is None
    assert scalar_function("def other(a):\n    return a\n", "run") is None


def test_a_nest_that_would_grow_past_the_statement_limit_stays_a_loop() -> None:
    """Three nested loops of 8 (512 iterations of a two-statement body, 1024 statements and
    more): the innermost two are unrolled (64 iterations), the outer one is kept; the sum
    is the hand count, 8 * 8 * 8 = 512, on both forms."""
    text = '''
def run(out):
    total = 0.0
    for i in range(8):
        for j in range(8):
            for k in range(8):
                total += 1.0
                out[1] = total
    out[0] = total
'''
    rewritten = scalar_function(text, "run")
    assert rewritten is not None and rewritten.count("for i in range(8)") == 1 and "for k in" not in rewritten
    for source in (text, rewritten):
        out = np.zeros(2)
        _run(source, out)
        assert out.tolist() == [512.0, 512.0]
