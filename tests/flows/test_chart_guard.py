"""A run that comes near a coordinate singularity of its chart stops and says so.

The asymmetric heavy top in Euler angles ``(phi, theta, psi)``: body moments ``A = 1``,
``B = 0.8``, ``C = 0.5`` about the principal axes, ``m g l = 1``, with
``omega = (phi' sin(theta) sin(psi) + theta' cos(psi), phi' sin(theta) cos(psi) - theta' sin(psi),
phi' cos(theta) + psi')`` (Goldstein, "Classical Mechanics", Sect. 4.9, (4.87)) and
``L = (A omega_1^2 + B omega_2^2 + C omega_3^2)/2 - m g l cos(theta)`` (Sect. 5.7). Its mass
matrix has ``det W = A B C sin(theta)^2`` (by hand: the columns of ``d omega / d q_dot`` are
``(sin(theta) sin(psi), sin(theta) cos(psi), cos(theta))``, ``(cos(psi), -sin(psi), 0)``,
``(0, 0, 1)``, whose determinant is ``-sin(theta)``): the chart is singular at
``sin(theta) = 0``. Released at ``theta = 0.4`` spinning about its axis at 2 rad/s, the top
passes ``theta ~ 4e-4`` near ``t = 62.1``; before that its smallest ``theta`` is about 0.05
(near ``t = 31``).
"""

from __future__ import annotations

import numpy as np
import pytest

import dirac
from dirac.errors import CoordinateSingularityError
from dirac.flows import ConstrainedProblem, integrate
from dirac.flows.chart_guard import chart_guard

OMEGA = (
    "(phi_dot*sin(theta)*sin(psi) + theta_dot*cos(psi))",
    "(phi_dot*sin(theta)*cos(psi) - theta_dot*sin(psi))",
    "(phi_dot*cos(theta) + psi_dot)",
)


def _euler_top() -> ConstrainedProblem:
    w1, w2, w3 = OMEGA
    L = dirac.Lagrangian.from_strings(
        "euler_top", ["phi", "theta", "psi"], f"(A*{w1}**2 + B*{w2}**2 + C*{w3}**2)/2 - mgl*cos(theta)", [],
        parameters={"A": 1.0, "B": 0.8, "C": 0.5, "mgl": 1.0},
    )
    return ConstrainedProblem(L, q0=[0.0, 0.4, 0.0], qdot0=[0.0, 0.0, 2.0])


def test_the_guard_measures_the_distance_to_sin_theta_zero():
    """``det W = A B C sin(theta)^2`` (module docstring): the locus is ``sin(theta) = 0`` and the
    first-order distance to it is ``|sin(theta)| / |cos(theta)| = |tan(theta)|`` (radians),
    whatever ``phi`` and ``psi``."""
    guard = chart_guard(_euler_top().mechanics)
    assert guard is not None and guard.locus == "sin(theta) = 0"
    for theta in (0.4, 1e-3, -0.2):
        q = np.array([[0.3, theta, 1.1], [2.0, 0.7, -0.5]])
        assert guard.distance(q) == pytest.approx(min(abs(np.tan(theta)), np.tan(0.7)), rel=1e-12)


@pytest.mark.parametrize("method, dt", [("auto", None), ("rattle-2", 0.01)])
def test_a_run_through_the_singularity_stops_and_names_it(method, dt):
    """The default run used to fail with "Newton iteration did not converge ... reduce dt" at
    ``t = 62.11``, and ``rattle-2`` passed ``theta = 4e-4`` with a 1 % energy error and no word.
    Both stop just before (``|tan(theta)|`` below ``1e-2``), naming the locus, the time and
    another chart."""
    options = {} if dt is None else {"dt": dt}
    with pytest.raises(CoordinateSingularityError, match=r"sin\(theta\) = 0") as caught:
        integrate(_euler_top(), method, t_end=70.0, samples=701, **options)
    text = str(caught.value)
    assert "rotation matrix" in text and "Cartesian coordinates" in text
    t_reached = caught.value.partial.extra["t_reached"]
    assert 61.5 < t_reached < 62.2
    theta = caught.value.partial.outputs["q"][:, 1]
    assert np.min(np.abs(np.sin(theta))) > 5e-3  # every stored sample is before the singular pass


def test_a_run_kept_away_from_the_singularity_is_unchanged():
    """Up to ``t = 50`` the top keeps ``theta >= 0.05``: the run completes and conserves the
    energy (a property of the flow, checked against its initial value ``E_0 = C omega_3^2/2 +
    m g l cos(0.4)``)."""
    solution = integrate(_euler_top(), "rattle-2", t_end=50.0, dt=0.002, samples=251)
    energy = solution.outputs["energy"]
    assert solution.complete
    assert energy[0] == pytest.approx(0.5 * 2.0**2 / 2 + np.cos(0.4), rel=1e-12)
    assert np.max(np.abs(energy - energy[0])) < 1e-3


def test_a_chart_without_a_singularity_has_no_guard():
    """The pendulum in Cartesian coordinates has a constant ``W = m 1``: no guard, the run is as before."""
    problem = ConstrainedProblem(dirac.load_system("pendulum"), q0=[0.6, -0.8], qdot0=[0.0, 0.0])
    assert chart_guard(problem.mechanics) is None


def test_the_polynomial_road_finds_the_gimbal_lock(monkeypatch):
    """Without ``trigsimp``: sines and cosines as symbols, Pythagoras for ``psi``
    (``sin(psi)^2 + cos(psi)^2 = 1``), and the factor left of ``A B C sin(theta)^2`` is
    ``sin(theta)``, as by hand (module docstring); the distance near the gimbal lock
    ``theta = 0`` is ``|tan(theta)|``, and trigsimp is never called."""
    import sympy

    calls = []
    original = sympy.trigsimp
    monkeypatch.setattr(sympy, "trigsimp", lambda *a, **k: calls.append(a) or original(*a, **k))
    guard = chart_guard(_euler_top().mechanics)
    assert not calls
    assert guard is not None and guard.locus == "sin(theta) = 0"
    for theta in (1e-3, -0.02):
        assert guard.distance(np.array([0.3, theta, 1.1])) == pytest.approx(abs(np.tan(theta)), rel=1e-12)


def test_three_angles_keep_every_locus():
    """``L = (a'^2 + sin(a)^2 b'^2 + (2 + cos b + cos c) c'^2)/2``: ``W`` is diagonal with
    ``det W = sin(a)^2 (2 + cos b + cos c)`` (three angles). Both loci
    are kept: ``sin(a) = 0`` (distance ``|tan a|``) and ``cos b + cos c + 2 = 0``, reached only
    at ``b = c = pi``, where at ``b = c = pi - e`` the first-order distance
    ``|f| / |grad f| = (2 - 2 cos e) / (sqrt(2) sin e) = sqrt(2) tan(e/2)`` (by hand)."""
    L = dirac.Lagrangian.from_strings(
        "three_angles", ["a", "b", "c"], "(a_dot**2 + sin(a)**2*b_dot**2 + (2 + cos(b) + cos(c))*c_dot**2)/2", [],
        parameters={})
    guard = chart_guard(ConstrainedProblem(L, q0=[1.0, 0.5, 0.2], qdot0=[0.0, 0.0, 0.1]).mechanics)
    assert guard is not None and guard.locus == "sin(a) = 0 and cos(b) + cos(c) + 2 = 0"
    assert guard.distance(np.array([2e-3, 0.5, 0.2])) == pytest.approx(np.tan(2e-3), rel=1e-12)
    e = 1e-3
    assert guard.distance(np.array([1.0, np.pi - e, np.pi - e])) == pytest.approx(np.sqrt(2) * np.tan(e / 2), rel=1e-9)


def test_the_triple_pendulum_keeps_its_determinant_as_the_locus():
    """Unit masses and rods: ``W = [[3, 2 cos(a-b), cos(a-c)], [2 cos(a-b), 2, cos(b-c)],
    [cos(a-c), cos(b-c), 1]]``, by cofactors ``det W = 6 - 4 cos^2(a-b) - 2 cos^2(a-c)
    - 3 cos^2(b-c) + 4 cos(a-b) cos(a-c) cos(b-c)``: the one factor kept is that polynomial
    (up to its sign), at random angles."""
    kinetic = ("3/2*a_dot**2 + b_dot**2 + 1/2*c_dot**2 + 2*a_dot*b_dot*cos(a-b) + a_dot*c_dot*cos(a-c)"
               " + b_dot*c_dot*cos(b-c)")
    L = dirac.Lagrangian.from_strings("triple", ["a", "b", "c"], f"{kinetic} + 3*cos(a) + 2*cos(b) + cos(c)", [],
                                      parameters={})
    guard = chart_guard(ConstrainedProblem(L, q0=[1.0, 0.5, 0.2], qdot0=[0.0, 0.0, 0.0]).mechanics)
    assert guard is not None and " and " not in guard.locus
    import sympy

    a, b, c = sympy.symbols("a b c", real=True)
    factor = sympy.sympify(guard.locus.removesuffix(" = 0"), locals={"a": a, "b": b, "c": c})
    rng = np.random.default_rng(3)
    for angles in rng.uniform(-np.pi, np.pi, size=(5, 3)):
        x, y, z = np.cos(angles[0] - angles[1]), np.cos(angles[0] - angles[2]), np.cos(angles[1] - angles[2])
        det = 6 - 4 * x**2 - 2 * y**2 - 3 * z**2 + 4 * x * y * z
        value = float(factor.subs({a: angles[0], b: angles[1], c: angles[2]}))
        assert abs(value) == pytest.approx(abs(det), rel=1e-12)


def test_a_det_w_too_long_to_factor_still_guards_its_zero_set(monkeypatch):
    """With the factoring limit set below the length of ``det W = A B C sin(theta)^2`` (module
    docstring), no factor is named, and the guard used to be dropped without a word. It now
    guards ``det W`` itself: the same zero set, distance ``|det W| / |grad det W|`` to first
    order; by hand ``sin(theta)^2 / |2 sin(theta) cos(theta)| = |tan(theta)| / 2``."""
    from dirac.analysis.core import divisors

    monkeypatch.setattr(divisors, "DIVISOR_TEXT_LIMIT", 2)
    guard = chart_guard(_euler_top().mechanics)
    assert guard is not None and guard.locus.startswith("det W = 0")
    for theta in (0.4, 1e-3, -0.2):
        q = np.array([[0.3, theta, 1.1]])
        assert guard.distance(q) == pytest.approx(abs(np.tan(theta)) / 2, rel=1e-12)


def _double_pendulum(m1: float) -> ConstrainedProblem:
    """The double pendulum in its angles (Landau & Lifshitz Sect. 5), unit rods:
    ``W = [[m1 + m2, m2 cos(a - b)], [m2 cos(a - b), m2]]``, ``det W = m2 (m1 + m2 sin(a - b)^2)``."""
    L = dirac.Lagrangian.from_strings(
        "double_pendulum", ["a", "b"],
        "(m1+m2)/2*a_dot**2 + m2/2*b_dot**2 + m2*a_dot*b_dot*cos(a-b) + (m1+m2)*g*cos(a) + m2*g*cos(b)", [],
        parameters={"m1": m1, "m2": 1.0, "g": 9.81})
    return ConstrainedProblem(L, q0=[1.0, 0.5], qdot0=[0.0, 0.0])


def test_never_zero_encloses_the_factor_over_the_sines_and_cosines():
    """Interval enclosures by hand over ``|s|, |c| <= 1`` (each monomial in ``[0, 1]`` with even
    exponents, else ``[-1, 1]``): ``m1 + m2 - m2 c^2`` is in ``[m1, m1 + m2]``, never zero for
    ``m1 > 0`` (``m1 = 0.1``: a double that is not a short binary fraction, taken exactly), and
    reaches 0 at ``c = 1`` for ``m1 = 0``; ``-(1 + c^2)`` is in ``[-2, -1]``. Not proved (and
    each does vanish, or may): ``s`` (``sin(theta) = 0``), ``c_1 + c_2 + 2`` in ``[0, 4]`` (zero
    at ``b = c = pi``), the triple pendulum's ``6 - 4x^2 - 2y^2 - 3z^2 + 4xyz`` in ``[-7, 10]``,
    and a factor in a coordinate outside the sines and cosines."""
    import sympy

    from dirac.flows.chart_guard import never_zero

    s, c, c1, c2, x, y, z, r = sympy.symbols("s c c1 c2 x y z r", real=True)
    m1, m2 = sympy.symbols("m1 m2", positive=True)
    pendulum = m1 + m2 - m2 * c**2
    assert never_zero(pendulum, [s, c], {m1: 1.0, m2: 1.0})
    assert never_zero(pendulum, [s, c], {m1: 0.1, m2: 3.0})
    assert not never_zero(pendulum, [s, c], {m1: 0.0, m2: 1.0})
    assert never_zero(-(1 + c**2), [s, c], {})
    assert not never_zero(s, [s, c], {})
    assert not never_zero(c1 + c2 + 2, [c1, c2], {})
    assert not never_zero(6 - 4 * x**2 - 2 * y**2 - 3 * z**2 + 4 * x * y * z, [x, y, z], {})
    assert not never_zero(r**2 + 1 + c, [c], {})


def test_a_double_pendulum_whose_det_w_never_vanishes_has_no_guard_and_the_same_numbers(monkeypatch):
    """``det W = m2 (m1 + m2 sin(a - b)^2) >= m1 m2 > 0`` for ``m1 = m2 = 1``: no configuration
    is singular, and the guard is left out (it was read between calls of the step loop, two
    calls per output sample of the default run to t = 100 where one does, and its distance
    ``|f| / |grad f| = (1 + sin^2 u) / (sqrt(2) |sin 2u|)``, ``u = a - b``, never fell below
    ``1 / sqrt(2)``). The system has no explicit
    time, so its steps do not depend on those cuts: ``q`` and ``p`` are the same, bit for bit,
    as with the guard kept. With ``m1 = 0`` (a massless upper bob) ``det W = sin(a - b)^2``
    vanishes at ``a = b``, and the guard is there."""
    from dirac.flows import chart_guard as module

    assert chart_guard(_double_pendulum(1.0).mechanics) is None
    massless = chart_guard(_double_pendulum(0.0).mechanics)
    assert massless is not None and "cos(a - b)" in massless.locus
    plain = integrate(_double_pendulum(1.0), "rattle-4", t_end=3.0, dt=0.01, samples=31)
    kept = _double_pendulum(1.0)
    monkeypatch.setattr(module, "never_zero", lambda *args: False)
    assert chart_guard(kept.mechanics) is not None
    guarded = integrate(kept, "rattle-4", t_end=3.0, dt=0.01, samples=31)
    assert plain.outputs["q"].tobytes() == guarded.outputs["q"].tobytes()
    assert plain.outputs["p"].tobytes() == guarded.outputs["p"].tobytes()
