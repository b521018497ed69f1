"""`dirac analyze FILE --json` on random small polynomial Lagrangians: a result or one error line.

Lagrangians quadratic in the velocities (coefficients constants or linear in a
coordinate; none at all in some draws, so that the Hessian has rank 0), with linear-in-velocity terms, a polynomial potential and up to one
polynomial holonomic constraint, in 1-3 coordinates. Whatever the algorithm meets
(singular Hessians, irregular or crossing constraints, inconsistencies, special
structure) the command must either print a JSON result with exit status 0, or exactly
one ``error:`` line with exit status 2: never a traceback (an uncaught exception fails
the test).
"""

from __future__ import annotations

import contextlib
import io
import json

import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st
from stress_scaling import stress_scale

from dirac.cli import main

COEFFICIENTS = st.sampled_from([-2, -1, 1, 2, 3])


@st.composite
def monomials(draw, names: list[str], max_degree: int) -> str:
    degree = draw(st.integers(0, max_degree))
    factors = [draw(st.sampled_from(names)) for _ in range(degree)]
    return "*".join(factors) if factors else "1"


@st.composite
def polynomials(draw, names: list[str], max_degree: int, terms: int) -> str:
    count = draw(st.integers(1, terms))
    return " + ".join(f"({draw(COEFFICIENTS)})*{draw(monomials(names, max_degree))}" for _ in range(count))


@st.composite
def systems(draw) -> str:
    n = draw(st.integers(1, 3))
    q = [f"q{i}" for i in range(1, n + 1)]
    v = [f"{c}_dot" for c in q]
    parts = []
    for i in range(n):
        for j in range(i, n):
            if draw(st.booleans()):
                coefficient = draw(st.sampled_from(["1", *q]))
                parts.append(f"({draw(COEFFICIENTS)})*{coefficient}*{v[i]}*{v[j]}/2")
    if not parts and draw(st.booleans()):  # else the Hessian has rank 0 (first-order Lagrangians)
        parts.append(f"{v[0]}**2/2")
    for i in range(n):
        if draw(st.integers(0, 3)) == 0:
            parts.append(f"({draw(COEFFICIENTS)})*{draw(monomials(q, 2))}*{v[i]}")
    if draw(st.booleans()):
        parts.append(f"-({draw(polynomials(q, 3, 3))})")
    constraints = []
    if draw(st.integers(0, 2)) == 0:
        shape = draw(st.sampled_from(["plain", "square", "product"]))
        base = draw(polynomials(q, 2, 3))
        if shape == "square":
            base = f"({base})**2"
        elif shape == "product":
            base = f"({base})*({draw(polynomials(q, 1, 2))})"
        constraints.append(base)
    if not parts:
        parts.append("0")
    listed = ", ".join(f'"{c}"' for c in constraints)
    names = ", ".join(f'"{c}"' for c in q)
    return f'[system]\nname = "random"\ncoordinates = [{names}]\nlagrangian = "{" + ".join(parts)}"\nconstraints = [{listed}]\n'


def _run(path: str) -> tuple[int, str, str]:
    out, err = io.StringIO(), io.StringIO()
    with contextlib.redirect_stdout(out), contextlib.redirect_stderr(err):
        status = main(["analyze", path, "--json"])
    return status, out.getvalue(), err.getvalue()


def _check(text: str, tmp_path_factory) -> None:
    path = tmp_path_factory.mktemp("random") / "system.toml"
    path.write_text(text)
    status, out, err = _run(str(path))
    errors = [line for line in err.splitlines() if line.startswith("error:")]
    others = [line for line in err.splitlines() if line.strip() and not line.startswith(("error:", "warning:"))]
    assert others == [], text + err
    if status == 0:
        assert errors == [], text + err
        data = json.loads(out)
        assert data["physical_degrees_of_freedom"] >= 0, text
    else:
        assert status == 2 and len(errors) == 1 and out == "", text + err


@settings(max_examples=40, deadline=None, suppress_health_check=[HealthCheck.function_scoped_fixture, HealthCheck.too_slow])
@given(text=systems())
def test_random_polynomial_lagrangians_never_trace_back(text, tmp_path_factory):
    _check(text, tmp_path_factory)


@pytest.mark.slow
@settings(max_examples=max(5, int(300 * stress_scale())), deadline=None, suppress_health_check=[HealthCheck.function_scoped_fixture, HealthCheck.too_slow])
@given(text=systems())
def test_random_polynomial_lagrangians_never_trace_back_long(text, tmp_path_factory):
    _check(text, tmp_path_factory)
