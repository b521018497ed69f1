"""LaTeX of the generated names (docs/conventions.md): velocities as dots, multipliers as
lambda with an index, momenta as p with the coordinate as subscript; names and str() unchanged."""

from __future__ import annotations

import pytest
import sympy

import dirac
from dirac.model.lagrangian import Lagrangian, latex_name


@pytest.mark.parametrize("name, latex", [
    ("x_dot", r"\dot{x}"),
    ("theta_dot", r"\dot{\theta}"),
    ("p_x", "p_{x}"),
    ("lambda_1", r"\lambda_{1}"),
    ("p_lambda_1", r"p_{\lambda_{1}}"),
    ("p_theta", r"p_{\theta}"),
    ("m", "m"),
])
def test_latex_name(name, latex):
    assert latex_name(name) == latex


def test_lagrangian_renders_velocities_with_dots_and_keeps_its_names():
    pendulum = Lagrangian.from_strings("pendulum", ["x", "y"], "m/2*(x_dot**2 + y_dot**2) - m*g*y",
                                       constraints=["x**2 + y**2 - l**2"], parameters={"m": 1.0, "g": 9.81, "l": 1.0})
    latex = pendulum._repr_latex_()
    assert latex.startswith("$$") and latex.endswith("$$")
    assert r"\dot{x}^{2}" in latex and r"\dot{y}^{2}" in latex and "x_{dot}" not in latex
    assert r"\chi_{1} &= - l^{2} + x^{2} + y^{2} = 0" in latex
    assert [str(v) for v in pendulum.velocities] == ["x_dot", "y_dot"]
    assert sympy.latex(pendulum.velocities[0]) == "x_{dot}"  # the symbol itself is untouched


def test_analysis_latex_names_multipliers_and_their_momenta():
    analysis = dirac.analyze(dirac.load_system("pendulum"))
    latex = analysis._repr_latex_()
    assert r"&p_{\lambda_{1}} = 0" in latex  # the primary constraint
    assert r"\lambda_{1} x^{2}" in latex and r"\dot{x}" in latex
    assert r"\lambda 1" not in latex and "{dot}" not in latex
    assert "p_lambda_1" in analysis.to_text()  # text keeps the names
