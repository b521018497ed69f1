"""The unconstrained RATTLE step of the generated kernels (``rattle_general`` with no
constraints, :mod:`dirac.codegen.kernel_templates`), against hand derivations.

Without constraints RATTLE is the generalized Stoermer-Verlet scheme (Hairer, Lubich &
Wanner, *Geometric Numerical Integration*, VI.3.4, eq. (3.4)) of ``H = 1/2 p^T M(q)^{-1} p
+ V(q)``:

    p_half = p - h/2 H_q(q, p_half),
    q1 = q + h/2 (H_p(q, p_half) + H_p(q1, p_half)),
    p1 = p_half - h/2 H_q(q1, p_half),

with ``H_p = M^{-1} p = v`` and ``H_q_k = dV/dq_k - 1/2 v^T (dM/dq_k) v``. The kernel solves
the first two equations one after the other (two Newton iterations of size n); here the
same equations are solved by plain fixed-point iteration in numpy from ``M``, ``dM/dq`` and
``dV/dq`` derived by hand, and the kernel's step must agree to the Newton tolerance.
"""

from __future__ import annotations

import math
import warnings
from collections.abc import Callable

import numpy as np
import pytest

import dirac
from dirac.flows.mechanics import MechanicalSystem
from dirac.model.lagrangian import Lagrangian

G = 9.81


def _double_pendulum() -> tuple[Lagrangian, Callable, Callable, Callable]:
    """Unit masses and rods in the angles (a, b) (Landau & Lifshitz Sect. 5):
    M = [[2, cos(a - b)], [cos(a - b), 1]], V = -2 g cos a - g cos b."""
    system = Lagrangian.from_strings(
        "double_pendulum_angles", ["a", "b"],
        "a_dot**2 + b_dot**2/2 + a_dot*b_dot*cos(a - b) + 2*g*cos(a) + g*cos(b)", parameters={"g": G})

    def mass(q: np.ndarray) -> np.ndarray:
        c = math.cos(q[0] - q[1])
        return np.array([[2.0, c], [c, 1.0]])

    def dmass(q: np.ndarray) -> list[np.ndarray]:
        s = math.sin(q[0] - q[1])
        return [np.array([[0.0, -s], [-s, 0.0]]), np.array([[0.0, s], [s, 0.0]])]

    def grad_v(q: np.ndarray) -> np.ndarray:
        return np.array([2.0 * G * math.sin(q[0]), G * math.sin(q[1])])

    return system, mass, dmass, grad_v


def _symmetric_top() -> tuple[Lagrangian, Callable, Callable, Callable]:
    """Heavy symmetric top in Euler angles (ph, th, ps) (Goldstein eq. 5.59), I1 = 1,
    I3 = 1/2, M g l = g: M = [[I1 sin^2 th + I3 cos^2 th, 0, I3 cos th], [0, I1, 0],
    [I3 cos th, 0, I3]], V = M g l cos th. Its mass matrix is 3 x 3 and not diagonal: the
    kernel eliminates v = M^{-1} p."""
    i1, i3 = 1.0, 0.5
    system = Lagrangian.from_strings(
        "symmetric_top", ["ph", "th", "ps"],
        "I1/2*(th_dot**2 + ph_dot**2*sin(th)**2) + I3/2*(ps_dot + ph_dot*cos(th))**2 - g*cos(th)",
        parameters={"I1": i1, "I3": i3, "g": G})

    def mass(q: np.ndarray) -> np.ndarray:
        s, c = math.sin(q[1]), math.cos(q[1])
        return np.array([[i1 * s * s + i3 * c * c, 0.0, i3 * c], [0.0, i1, 0.0], [i3 * c, 0.0, i3]])

    def dmass(q: np.ndarray) -> list[np.ndarray]:
        s, c = math.sin(q[1]), math.cos(q[1])
        zero = np.zeros((3, 3))
        return [zero, np.array([[2.0 * (i1 - i3) * s * c, 0.0, -i3 * s], [0.0, 0.0, 0.0], [-i3 * s, 0.0, 0.0]]), zero]

    def grad_v(q: np.ndarray) -> np.ndarray:
        return np.array([0.0, -G * math.sin(q[1]), 0.0])

    return system, mass, dmass, grad_v


def _stoermer_verlet(q: np.ndarray, p: np.ndarray, h: float, mass: Callable, dmass: Callable,
                     grad_v: Callable) -> tuple[np.ndarray, np.ndarray]:
    """One step of the scheme of the module docstring, each implicit equation by fixed-point
    iteration to the last bits (a contraction for small h)."""

    def h_q(x: np.ndarray, momentum: np.ndarray) -> np.ndarray:
        v = np.linalg.solve(mass(x), momentum)
        return grad_v(x) - 0.5 * np.array([v @ d @ v for d in dmass(x)])

    half = p.copy()
    for _ in range(200):
        half = p - 0.5 * h * h_q(q, half)
    v0 = np.linalg.solve(mass(q), half)
    q1 = q.copy()
    for _ in range(200):
        q1 = q + 0.5 * h * (v0 + np.linalg.solve(mass(q1), half))
    return q1, half - 0.5 * h * h_q(q1, half)


@pytest.mark.parametrize("build, q0, p0", [
    (_double_pendulum, [1.2, -0.7], [0.9, -1.3]),
    (_symmetric_top, [0.3, 0.8, -0.4], [0.6, -0.5, 1.7]),
])
def test_one_step_solves_the_stoermer_verlet_equations(build, q0, p0) -> None:
    """Each of 20 steps of h = 0.05 from a state with large momenta (several Newton
    iterations per block), redone by the hand-derived scheme from the kernel's state before
    it, agrees with the kernel's state after it to the Newton tolerance: residuals within
    tol (1 + |p_half|^2 + |q1|^2) with tol = 1e-12 (a factor 10 for the Jacobians and M^-1 that
    carry a residual to the state); a wrong term would be off by about h^3 = 1e-4."""
    _steps_solve_stoermer_verlet(*build(), q0, p0)


def _steps_solve_stoermer_verlet(system, mass, dmass, grad_v, q0, p0) -> None:
    """20 steps of h = 0.05 of the kernel, each against the hand-derived scheme redone from
    the kernel's state before it (the bound of the test above)."""
    h = 0.05
    with warnings.catch_warnings():
        # steps this long on purpose (several Newton iterations per block): the energy changes by 3-3.8 % of the
        # kinetic energy, and the run says so (dirac.flows.energy_watch); the steps are what this test checks
        warnings.filterwarnings("ignore", "the energy of", dirac.DiracWarning)
        solution = dirac.integrate(dirac.ConstrainedProblem(system, q0=q0, p0=p0), "rattle-2", t_end=20 * h, dt=h,
                                   samples=21, outputs=["q", "p"], newton_tolerance=1e-12)
    qs, ps = solution.outputs["q"], solution.outputs["p"]
    for k in range(20):
        q1, p1 = _stoermer_verlet(qs[k], ps[k], h, mass, dmass, grad_v)
        bound = 10 * 1e-12 * (1.0 + np.sum(ps[k + 1] ** 2) + np.sum(p1 ** 2) + np.sum(q1 ** 2))
        assert np.max(np.abs(qs[k + 1] - q1)) < bound
        assert np.max(np.abs(ps[k + 1] - p1)) < bound


def _polar_error(method: str, dt: float) -> float:
    """A free particle in polar coordinates, L = (r_dot^2 + r^2 th_dot^2)/2 (M = diag(1, r^2)):
    from r = 1, th = 0 with velocity (0.3, 0.8) it moves on the straight line
    (1 + 0.3 t, 0.8 t); the error in (x, y) at t = 2."""
    system = Lagrangian.from_strings("free_polar", ["r", "th"], "(r_dot**2 + r**2*th_dot**2)/2")
    solution = dirac.integrate(dirac.ConstrainedProblem(system, q0=[1.0, 0.0], p0=[0.3, 0.8]), method, t_end=2.0,
                               dt=dt, samples=2, outputs=["q"])
    r, th = solution.outputs["q"][-1]
    return float(math.hypot(r * math.cos(th) - 1.6, r * math.sin(th) - 1.6))


@pytest.mark.parametrize("method, order", [("rattle-2", 2), ("rattle-4", 4)])
def test_order_on_a_straight_line_in_polar_coordinates(method: str, order: int) -> None:
    """The observed order log2(err(dt) / err(dt/2)) is the method's order (closed form: the
    straight line of a free particle, in coordinates where its mass depends on r)."""
    errors = [_polar_error(method, dt) for dt in (0.1, 0.05)]
    assert abs(math.log2(errors[0] / errors[1]) - order) < 0.15


def test_a_step_that_does_not_converge_is_reported_and_undone() -> None:
    """With no Newton iteration allowed (max_iter = 0) no step converges: info says
    failed after 0 steps and (q, p) are the state before the step."""
    system, *_ = _double_pendulum()
    mechanics = MechanicalSystem.from_lagrangian(system)
    q, p = np.array([1.2, -0.7]), np.array([0.9, -1.3])
    info = np.zeros(4)
    mechanics.module.rattle_general(q, p, 0.0, mechanics.params, np.ones(1), 0.05, 3, 1e-12, 0, info)
    assert info[0] == 0 and info[1] == 1.0
    assert q.tolist() == [1.2, -0.7] and p.tolist() == [0.9, -1.3]


def test_each_expression_is_evaluated_at_one_place_in_the_loop() -> None:
    """The generated loop of the double pendulum evaluates each expression of the system at
    one place (numba compiles every inlined copy anew). By hand, for M = [[2, cos(a - b)],
    [cos(a - b), 1]] and V = -2 g cos a - g cos b: the force dV/dq - 1/2 v^T (dM/dq_k) v
    holds sin(a - b), sin a and sin b, (dM/dq_k) u holds sin(a - b), M and M^-1 p each
    cos(a - b). The transcendental functions of q are evaluated once per configuration
    (``transcendentals``) and read by every expression: 3 sines (sin(a - b), sin a, sin b)
    and 1 cosine (cos(a - b)) in rattle_general; one copy of each expression with its own
    functions (the loop before) gave 4 sines and 2 cosines, two copies of the force 7 sines."""
    import ast

    system, *_ = _double_pendulum()
    source = MechanicalSystem.from_lagrangian(system).module.source
    tree = ast.parse(source)
    loop = next(node for node in tree.body if isinstance(node, ast.FunctionDef) and node.name == "rattle_general")
    calls = [ast.unparse(node.func) for node in ast.walk(loop) if isinstance(node, ast.Call)]
    assert calls.count("math.sin") == 3
    assert calls.count("math.cos") == 1


@pytest.mark.parametrize("n, velocity_by_elimination", [(2, False), (3, True), (5, True)])
def test_the_template_calls_each_expression_once(n: int, velocity_by_elimination: bool) -> None:
    """In the unconstrained template (before any inlining) force, mass, mass_dq_v and
    velocity are each called at one place at most, for both roads to v = M^-1 p."""
    import ast

    from dirac.codegen.kernel_templates import mechanical_templates

    tree = ast.parse(mechanical_templates(n, 0, velocity_by_elimination))
    loop = next(node for node in tree.body if isinstance(node, ast.FunctionDef) and node.name == "rattle_general")
    calls = [ast.unparse(node.func) for node in ast.walk(loop) if isinstance(node, ast.Call)]
    for name in ("force", "mass", "mass_dq_v", "velocity"):
        assert calls.count(name) <= 1, name
    assert calls.count("force") == 1 and calls.count("mass_dq_v") == 1


@pytest.mark.parametrize("build, q0, p0", [
    (_double_pendulum, [2.9, -2.5], [0.0, 0.0]),
    (_double_pendulum, [1.2, -0.7], [4.0, -6.0]),
    (_symmetric_top, [0.3, 0.8, -0.4], [0.6, -0.5, 1.7]),
])
def test_a_step_is_within_the_tolerance_of_the_exactly_solved_step(build, q0, p0) -> None:
    """Each of 200 steps (dt = 2e-3, the flip map's step) from the state of the run, solved
    with tol = 1e-12 and again with tol = 1e-15 (solved to rounding), differ by at most
    10 tol (1 + |p|^2 + |q|^2): the stopping test does not accept an iterate farther from
    the solution of the step's equations than its tolerance says."""
    system, *_ = build()
    mechanics = MechanicalSystem.from_lagrangian(system)
    q, p = np.array(q0, dtype=float), np.array(p0, dtype=float)
    info = np.zeros(4)
    for _ in range(200):
        q12, p12 = q.copy(), p.copy()
        mechanics.module.rattle_general(q12, p12, 0.0, mechanics.params, np.ones(1), 2e-3, 1, 1e-12, 50, info)
        assert info[1] == 0.0
        q15, p15 = q.copy(), p.copy()
        mechanics.module.rattle_general(q15, p15, 0.0, mechanics.params, np.ones(1), 2e-3, 1, 1e-15, 50, info)
        assert info[1] == 0.0
        bound = 10 * 1e-12 * (1.0 + np.sum(p15 ** 2) + np.sum(q15 ** 2))
        assert np.max(np.abs(q12 - q15)) <= bound
        assert np.max(np.abs(p12 - p15)) <= bound
        q, p = q15, p15


def _triple_pendulum() -> tuple[Lagrangian, Callable, Callable, Callable]:
    """Triple pendulum of unit masses and rods in its angles (bob k at
    sum_{j<=k} (sin q_j, -cos q_j)): M_ij = (3 - max(i, j)) cos(q_i - q_j),
    dM_ij/dq_k = -(3 - max(i, j)) sin(q_i - q_j) (delta_ik - delta_jk),
    V = -g (3 cos q_0 + 2 cos q_1 + cos q_2). A full 3 x 3 mass: the kernel writes
    v = M^-1 p by Cramer's rule and shares nine sines and cosines of q among M, M^-1 p, the
    force and (dM/dq_k) u."""
    kinetic = ("3/2*a_dot**2 + b_dot**2 + 1/2*c_dot**2 + 2*a_dot*b_dot*cos(a-b) + a_dot*c_dot*cos(a-c)"
               " + b_dot*c_dot*cos(b-c)")
    system = Lagrangian.from_strings("triple_pendulum", ["a", "b", "c"],
                                     f"{kinetic} + g*(3*cos(a) + 2*cos(b) + cos(c))", parameters={"g": G})

    def weight(i: int, j: int) -> float:
        return float(3 - max(i, j))

    def mass(q: np.ndarray) -> np.ndarray:
        return np.array([[weight(i, j) * math.cos(q[i] - q[j]) for j in range(3)] for i in range(3)])

    def dmass(q: np.ndarray) -> list[np.ndarray]:
        return [np.array([[-weight(i, j) * math.sin(q[i] - q[j]) * ((i == k) - (j == k)) for j in range(3)]
                          for i in range(3)]) for k in range(3)]

    def grad_v(q: np.ndarray) -> np.ndarray:
        return np.array([G * (3 - k) * math.sin(q[k]) for k in range(3)])

    return system, mass, dmass, grad_v


def test_a_full_three_by_three_mass_solves_the_stoermer_verlet_equations() -> None:
    """As the test above, for the triple pendulum (a full 3 x 3 mass whose M^-1 p the kernel
    writes by Cramer's rule, its sines and cosines evaluated once per configuration): each of
    20 steps of h = 0.05 agrees with the hand-derived scheme to the Newton tolerance."""
    _steps_solve_stoermer_verlet(*_triple_pendulum(), [1.0, -0.6, 2.2], [0.7, -1.1, 0.9])


def test_a_time_dependent_force_is_taken_at_the_end_of_the_step() -> None:
    """L = (2 + cos q) q_dot^2 / 2 + (1 + sin t / 2) cos q: M = 2 + cos q, dM/dq = -sin q,
    V = -(1 + sin t / 2) cos q, so H_q(q, p, t) = (1 + sin t / 2) sin q + sin q v^2 / 2 with
    v = p / (2 + cos q). The generalized Stoermer-Verlet step (Hairer, Lubich & Wanner
    VI.3.4) takes H_q at (q, t) for p_half and at (q1, t + h) for p1; the kernel evaluates
    the sines of (q, t) once per configuration and reads them at the end of the step at
    (q1, t + h): 20 steps of h = 0.1 from t = 0 agree with the scheme solved by fixed-point
    iteration to the Newton tolerance (a force taken at the wrong time or place would be off
    by about h^2 = 1e-2 in p)."""
    system = Lagrangian.from_strings("driven_variable_mass", ["q"], "(2 + cos(q))*q_dot**2/2 + (1 + sin(t)/2)*cos(q)")
    h = 0.1

    def h_q(x: float, momentum: float, time: float) -> float:
        v = momentum / (2.0 + math.cos(x))
        return (1.0 + math.sin(time) / 2.0) * math.sin(x) + math.sin(x) * v * v / 2.0

    solution = dirac.integrate(dirac.ConstrainedProblem(system, q0=[1.1], p0=[0.8]), "rattle-2",
                               t_end=20 * h, dt=h, samples=21, outputs=["q", "p"], newton_tolerance=1e-12)
    qs, ps = solution.outputs["q"][:, 0], solution.outputs["p"][:, 0]
    for k in range(20):
        q, p, t = float(qs[k]), float(ps[k]), k * h
        half = p
        for _ in range(200):
            half = p - 0.5 * h * h_q(q, half, t)
        v0 = half / (2.0 + math.cos(q))
        q1 = q
        for _ in range(200):
            q1 = q + 0.5 * h * (v0 + half / (2.0 + math.cos(q1)))
        p1 = half - 0.5 * h * h_q(q1, half, t + h)
        bound = 10 * 1e-12 * (1.0 + p1 * p1 + half * half + q1 * q1)
        assert abs(qs[k + 1] - q1) < bound
        assert abs(ps[k + 1] - p1) < bound
