"""Named common sub-expressions: the texts and definitions read back to the expressions."""

from __future__ import annotations

import json
import random
import re
from pathlib import Path

import pytest
import sympy

import dirac
import dirac.analysis.report as report
from dirac.analysis.core.common_subexpressions import named_subexpressions
from dirac.analysis.core.phase_space import free_symbols_of
from dirac.model.lagrangian import Lagrangian

x, y, z, a = sympy.symbols("x y z a", real=True)


def read_back(texts: list[str], definitions: dict[str, str], symbols) -> list[sympy.Expr]:
    """The expressions of ``texts``: each definition in order (earlier names only), then the texts."""
    names = {s.name: s for s in symbols}
    known: dict[str, sympy.Expr] = {}
    for name, text in definitions.items():
        known[name] = sympy.sympify(text, locals={**names, **known})
    return [sympy.sympify(t, locals={**names, **known}) for t in texts]


def test_a_shared_sum_is_named_once_and_used_where_it_stands():
    s = x + y + z
    e1 = a * s**2 + s * x
    e2 = sympy.sin(s) + 3 * s
    texts, definitions = named_subexpressions([e1, e2], "cse_", str)
    assert definitions == {"cse_0": str(s)}
    assert "cse_0" in texts[0] and "cse_0" in texts[1]
    assert "x + y + z" not in texts[0] + texts[1]
    back = read_back(texts, definitions, [x, y, z, a])
    assert sympy.expand(back[0] - e1) == 0 and sympy.expand(back[1] - e2) == 0


def test_definitions_use_only_earlier_names():
    inner = x * y + z  # shared inside the shared outer sum
    outer = inner**2 + a
    exprs = [outer * x + inner * y, outer * y + inner * z]
    texts, definitions = named_subexpressions(exprs, "cse_", str)
    order = list(definitions)
    assert len(order) == 2
    for k, text in enumerate(definitions.values()):
        assert set(re.findall(r"cse_[0-9]+", text)) <= set(order[:k])
    back = read_back(texts, definitions, [x, y, z, a])
    assert all(sympy.expand(b - e) == 0 for b, e in zip(back, exprs))


def test_a_small_repeated_sub_tree_is_not_named():
    exprs = [2 * x + sympy.sin(2 * x), sympy.cos(2 * x) * y]  # 2*x: three tree nodes, printed where it stands
    texts, definitions = named_subexpressions(exprs, "cse_", str)
    assert definitions == {}
    assert texts == [str(e) for e in exprs]


def test_names_skip_the_symbols_of_the_expressions():
    taken = sympy.Symbol("cse_0", real=True)
    s = x + y + taken
    texts, definitions = named_subexpressions([s * x + s**2, s * y], "cse_", str)
    assert "cse_0" not in definitions and list(definitions) == ["cse_1"]
    back = read_back(texts, definitions, [x, y, taken])
    assert sympy.expand(back[0] - (s * x + s**2)) == 0 and sympy.expand(back[1] - s * y) == 0


def test_a_deep_graph_of_huge_tree_size_prints_in_linear_size():
    # u_{k+1} = u_k^2 + x u_k: as a tree 2^k copies of u_1, as a graph k nodes
    u = x + y
    for _ in range(40):
        u = sympy.Add(sympy.Mul(u, u, evaluate=False), sympy.Mul(x, u, evaluate=False), evaluate=False)
    texts, definitions = named_subexpressions([u], "cse_", str)
    # u_1 ... u_39 are named (u_0 = x + y is small, u_40 the expression itself)
    assert len(definitions) == 39 and sum(map(len, definitions.values())) < 40 * 40
    names = {s.name: s for s in (x, y)}
    point = {x: 0.3, y: -0.25}
    values: dict[str, float] = {}
    for name, text in definitions.items():
        values[name] = float(sympy.sympify(text, locals=names).subs({**point, **values}))
    expected = point[x] + point[y]
    for _ in range(40):
        expected = expected**2 + point[x] * expected
    value = float(sympy.sympify(texts[0], locals=names).subs({**point, **values}))
    assert value == pytest.approx(expected, rel=1e-12)


@pytest.fixture
def small_tree_limit(monkeypatch):
    """Every multiplier of more than 40 tree nodes goes through the shared form."""
    monkeypatch.setattr(report, "TREE_LIMIT", 40)


def test_json_multipliers_read_back_to_the_analysis_multipliers(small_tree_limit):
    # a double pendulum in Cartesian coordinates: the multipliers share the block solve's sub-expressions
    L = Lagrangian.from_strings(
        "double_pendulum_xy",
        ["x1", "y1", "x2", "y2"],
        "m1*(x1_dot**2 + y1_dot**2)/2 + m2*(x2_dot**2 + y2_dot**2)/2 - m1*g*y1 - m2*g*y2",
        ["x1**2 + y1**2 - l1**2", "(x2 - x1)**2 + (y2 - y1)**2 - l2**2"],
        parameters={"m1": 1.0, "m2": 2.0, "g": 9.81, "l1": 1.0, "l2": 0.7},
    )
    analysis = dirac.analyze(L)
    data = json.loads(json.dumps(analysis.to_json()))
    definitions = data["multiplier_subexpressions"]
    assert definitions
    solved = dict(analysis.multipliers)
    symbols = free_symbols_of(solved.values())
    names = [k for k in data["multipliers"] if data["multipliers"][k] != "undetermined"]
    back = dict(zip(names, read_back([data["multipliers"][k] for k in names], definitions, symbols)))
    rng = random.Random(3)
    for _ in range(3):
        point = {s: sympy.Rational(rng.randint(1, 40), rng.randint(1, 40)) for s in symbols}
        for k in names:
            assert back[k].xreplace(point) == solved[k].xreplace(point)


def test_the_documented_tree_limit_is_the_reports():
    text = (Path(__file__).resolve().parents[3] / "docs" / "file_formats.md").read_text()
    assert f"more than {report.TREE_LIMIT:,} nodes" in text.replace("\n", " ")
