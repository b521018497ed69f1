"""`Solution` shows its fields and the shapes of its arrays, never the arrays."""

from __future__ import annotations

import dirac


def solution():
    return dirac.integrate(dirac.RigidBodyProblem(inertia=(1.0, 2.0, 3.0), M0=(1.0, 0.5, 0.2)), "exact", t_end=10.0)


def test_repr_is_short_and_shows_shapes():
    run = solution()
    text = repr(run)
    assert len(text) < 400
    assert "system='rigid_body'" in text and "method='exact'" in text
    assert "t[101]" in text and "M[101, 3]" in text and "R[101, 3, 3]" in text and "energy[101]" in text


def test_html_table():
    html = solution()._repr_html_()
    assert html.startswith("<table>") and html.endswith("</table>")
    for cell in ("<td>rigid_body</td>", "<td>exact (order 0)</td>", "output R", "101 × 3 × 3", "CPU"):
        assert cell in html
