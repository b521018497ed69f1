"""Every rigid-body method reproduces the paper's closed forms (165), (183) and the
elliptic solution (Sect. IX; the standard test case of docs/conventions.md), through ``integrate``.

The expected values are derived by hand from the Euler–Poisson equations (250)–(251):

* (165): ``m = (0, 0, m3)``: ``M`` stays ``(0, 0, m3)`` and ``R(t)`` is the rotation about
  ``z`` by ``w t``, ``w = m3 / I3``.
* (183), ``I1 = I2``: ``Omega = M / I2 + (1/I3 - 1/I2) M3 e3`` and ``R hat(M) R^T = hat(m)``
  give ``dR/dt = hat(m) R / I2 + (1/I3 - 1/I2) m3 R hat(e3)``, so
  ``R(t) = exp(t hat(m) / I2) exp(phi t hat(e3))`` with ``phi = (I2 - I3) m3 / (I2 I3)``:
  a rotation by ``k t``, ``k = |m| / I2``, about ``m / |m|``, times a rotation about z.
* The standard body's ``M(10)`` to 17 digits (docs/conventions.md).
"""

from __future__ import annotations

import numpy as np
import pytest

from dirac.flows import RigidBodyProblem, integrate
from dirac.flows.methods.registry import METHODS


def _rotation(axis: np.ndarray, angle: float) -> np.ndarray:
    """Rodrigues: exp(angle hat(axis)) for a unit axis."""
    K = np.array([[0.0, -axis[2], axis[1]], [axis[2], 0.0, -axis[0]], [-axis[1], axis[0], 0.0]])
    return np.eye(3) + np.sin(angle) * K + (1.0 - np.cos(angle)) * K @ K


def _rigid_body_methods() -> list[str]:
    return ["auto"] + sorted(n for n, m in METHODS.items() if m.accepts("rigid_body"))


#: (dt, allowed error) per method family: the closed forms (165) and the symmetric
#: top are exactly representable by some splittings, not by midpoint or RK.
def _settings(name: str) -> tuple[float, float]:
    if name in ("exact", "auto"):
        return 0.1, 1e-12
    if name.startswith("scipy"):
        return 0.1, 1e-7
    if name == "midpoint":
        return 0.001, 2e-6
    order = METHODS[name].order
    return {2: (0.001, 1e-5), 4: (0.01, 1e-7), 6: (0.02, 1e-9), 8: (0.05, 1e-10)}[order]


@pytest.mark.parametrize("name", _rigid_body_methods())
def test_closed_form_165_rotation_about_the_third_axis(name):
    inertia = np.array([1.0, 2.0, 3.0])
    m3 = 1.7
    dt, allowed = _settings(name)
    T = 5.0
    solution = integrate(RigidBodyProblem(inertia, [0.0, 0.0, m3]), name, t_end=T, dt=dt, samples=6,
                         outputs=["M", "R"], tolerance=1e-10)
    w = m3 / inertia[2]
    for t, M, R in zip(solution.t, solution["M"], solution["R"]):
        expected = np.array([[np.cos(w * t), -np.sin(w * t), 0.0], [np.sin(w * t), np.cos(w * t), 0.0], [0, 0, 1.0]])
        assert np.abs(R - expected).max() < allowed, (name, t)
        assert np.abs(M - [0.0, 0.0, m3]).max() < allowed


@pytest.mark.parametrize("name", _rigid_body_methods())
def test_closed_form_183_free_symmetric_top(name):
    I2, I3 = 2.0, 0.8
    inertia = np.array([I2, I2, I3])
    m = np.array([0.0, 0.6, 1.1])  # R(0) = 1, so M(0) = m
    dt, allowed = _settings(name)
    solution = integrate(RigidBodyProblem(inertia, m), name, t_end=4.0, dt=dt, samples=5, outputs=["M", "R"],
                         tolerance=1e-10)
    norm = np.linalg.norm(m)
    k = norm / I2
    phi = (I2 - I3) * m[2] / (I2 * I3)
    for t, M, R in zip(solution.t, solution["M"], solution["R"]):
        expected = _rotation(m / norm, k * t) @ _rotation(np.array([0.0, 0.0, 1.0]), phi * t)
        assert np.abs(R - expected).max() < allowed, (name, t)
        assert np.abs(M - expected.T @ m).max() < allowed, (name, t)


@pytest.mark.parametrize("name", _rigid_body_methods())
def test_elliptic_solution_of_the_standard_body(name, standard_problem):
    """Standard test case (docs/conventions.md): M(10) = (0.40706613658804081, 0.28300742681284408, 0.86844916766156164)."""
    reference = np.array([0.40706613658804081, 0.28300742681284408, 0.86844916766156164])
    dt, allowed = _settings(name)
    solution = integrate(standard_problem, name, t_end=10.0, dt=dt, samples=2, outputs=["M", "energy"],
                         tolerance=1e-10)
    assert np.abs(solution["M"][-1] - reference).max() < 10 * allowed, name
    assert abs(solution["energy"][0] - 0.64712527931383642713) < 1e-15
