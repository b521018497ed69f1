"""The compile-cost table of the generated step loops (dirac.bench.compile_cost)."""

from __future__ import annotations

import sympy

from dirac.bench.compile_cost import format_compile_cost, measure_compile_cost, n_link_pendulum_text


def _parse(names: list[str], text: str) -> sympy.Expr:
    symbols = {name: sympy.Symbol(name) for name in names} | {f"{name}_dot": sympy.Symbol(f"{name}_dot") for name in names}
    return sympy.sympify(text, locals=symbols | {"g": sympy.Symbol("g")})


def test_the_n_link_pendulum_is_the_hand_derived_double_and_triple_pendulum() -> None:
    """Unit masses and rods, bob k at sum_{j<=k} (sin q_j, -cos q_j): the double pendulum's
    T = q0'^2 + q0' q1' cos(q0 - q1) + q1'^2 / 2, V = -g (2 cos q0 + cos q1); the triple
    pendulum's T = 3/2 a' ^2 + b'^2 + c'^2 / 2 + 2 a' b' cos(a - b) + a' c' cos(a - c)
    + b' c' cos(b - c), V = -g (3 cos a + 2 cos b + cos c) (the kernel tests' hand form)."""
    names, text = n_link_pendulum_text(2)
    a, b, ad, bd, g = sympy.symbols("a0 a1 a0_dot a1_dot g")
    hand = ad**2 + ad * bd * sympy.cos(a - b) + bd**2 / 2 + g * (2 * sympy.cos(a) + sympy.cos(b))
    assert sympy.simplify(_parse(names, text) - hand) == 0
    names, text = n_link_pendulum_text(3)
    a, b, c, ad, bd, cd = sympy.symbols("a0 a1 a2 a0_dot a1_dot a2_dot")
    hand = (sympy.Rational(3, 2) * ad**2 + bd**2 + cd**2 / 2 + 2 * ad * bd * sympy.cos(a - b)
            + ad * cd * sympy.cos(a - c) + bd * cd * sympy.cos(b - c) + g * (3 * sympy.cos(a) + 2 * sympy.cos(b) + sympy.cos(c)))
    assert sympy.simplify(_parse(names, text) - hand) == 0


def test_the_table_gives_the_loop_its_own_seconds_per_statement() -> None:
    """A loop of 900 IR statements compiled in 2.0 s, 0.2 s of which numba spent on library
    code (np.empty, min): (2.0 - 0.2) / 900 = 2.00 ms per statement; the passes' shares of
    6 + 3 + 1 s are 60 %, 30 % and 10 %."""
    row = {"system": "made_up", "n": 3, "kernel": "rattle_general", "chars": 10000, "statements": 900, "blocks": 100,
           "import_numba": 0.3, "first_compile": 0.45, "kernel_compile": 2.0, "nested": [["ol_np_empty", 0.15],
                                                                                       ["ol_min", 0.05]],
           "pass_seconds": {"native_lowering": 6.0, "nopython_type_inference": 3.0, "reconstruct_ssa": 1.0}}
    line = format_compile_cost([row]).splitlines()[1]
    assert line.split()[:11] == ["made_up", "3", "rattle_general", "10000", "900", "100", "0.30", "0.45", "2.00",
                                 "2.00", "0.20"]
    assert line.endswith("native_lowering 60%, nopython_type_inference 30%, reconstruct_ssa 10%")


def test_a_fresh_process_times_the_loop_of_a_constant_mass() -> None:
    """The Cartesian pendulum (one rod: a constant mass, so the loop is ``rattle_constant_mass``
    over its two coordinates) compiled cold in a child: its parts are measured, the library code
    numba compiled for it is a part of the loop's seconds, and numba's IR of it has statements
    and blocks."""
    (row,) = measure_compile_cost(["pendulum_cartesian"])
    assert (row["n"], row["kernel"]) == (2, "rattle_constant_mass")
    assert row["statements"] > row["blocks"] > 1
    assert row["kernel_compile"] > sum(seconds for _, seconds in row["nested"]) >= 0.0
    assert row["import_numba"] > 0.0 and row["first_compile"] > 0.0
