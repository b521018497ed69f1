"""scipy's explicit Runge–Kutta pairs (``RK45``, ``DOP853``) as baselines.

They integrate the same vector fields as the geometric methods: the Euler–Poisson
equations (250)–(251) (the 3-component Euler equations alone when no output needs
``R``), the heavy-top equations, and the constrained flow of a general system (the Dirac
vector field, :mod:`dirac.flows.dirac_field`). Step control is scipy's, with
``rtol = atol = tolerance``; output times are met by scipy's dense output, so sampling
does not shorten the steps. Neither method preserves any invariant.
"""

from __future__ import annotations

from collections.abc import Callable
from typing import Protocol

import numpy as np

from dirac.flows.dirac_field import ConstrainedField
from dirac.flows.methods.base import Method, StepFailure, Stepper
from dirac.flows.methods.rigid_body_stepper import gravity_weight, needs_attitude, rigid_body_outputs
from dirac.rigidbody.euler_poisson import lean_rhs_full, lean_rhs_M


class _OdeSolver(Protocol):
    """What is used of a ``scipy.integrate.OdeSolver`` (scipy ships no type information)."""

    t: float
    y: np.ndarray
    status: str
    nfev: int

    def step(self) -> str | None: ...

    def dense_output(self) -> Callable[[float], np.ndarray]: ...

__all__ = ["ScipyStepper", "METHODS"]


class ScipyStepper(Stepper):
    """One scipy ``OdeSolver`` per initial state, stepped to each output time."""

    kind = "adaptive"

    def __init__(self, method: Method, problem, outputs: tuple[str, ...], options: dict) -> None:
        super().__init__()
        self.method = method
        self.problem = problem
        self.outputs = outputs
        # scipy refuses rtol below 100 machine epsilons (it warns and clamps): clamp here
        self.tolerance = max(float(options.get("tolerance", 1e-8)), 2.3e-14)
        self.t_end = float(options["t_end"])
        self.t = 0.0
        kind = problem.kind
        self.driven = False
        if kind in ("rigid_body", "heavy_top"):
            torque = problem.torque
            self.driven = problem.driven
            self.with_R = (needs_attitude(outputs) or kind == "heavy_top"
                           or (torque is not None and torque.depends_on_attitude))
            self._fun, self._args = _rigid_body_rhs(problem, self.with_R)
            states = [np.concatenate([M, R.ravel()]) if self.with_R else M.copy() for M, R in zip(problem.M0, problem.R0)]
            if self.driven:  # the work W is the last component: dW/dt = N.Omega
                self._fun = _driven_rhs(self._fun, problem, self.with_R)
                states = [np.concatenate([y, [0.0]]) for y in states]
            self.impulses = tuple(problem.impulses)
            self._next = 0
        elif kind == "analysed":
            self.analysed = problem.analysed
            self._fun, self._args = (lambda t, y: self.analysed.field(y, t)), ()
            states = [z.copy() for z in problem.z0]
        else:
            self.field = ConstrainedField(problem.mechanics)
            self._fun, self._args = self.field.scipy_rhs, ()
            states = [np.concatenate([q, p]) for q, p in zip(problem.q0, problem.p0)]
        self.y = np.array(states)
        self._solvers: list[_OdeSolver] | None = None
        if self.driven:
            self._apply_impulses_at(0.0)

    def _apply_impulses_at(self, t: float) -> None:
        """Angular impulses at time ``t``: ``M`` jumps, the work by the jump of the energy."""
        inverse = 1.0 / np.asarray(self.problem.inertia, dtype=float)
        while self._next < len(self.impulses) and self.impulses[self._next].t <= t:
            before = 0.5 * np.sum(self.y[:, :3] ** 2 * inverse, axis=-1)
            self.y[:, :3] += self.impulses[self._next].vector
            self.y[:, -1] += 0.5 * np.sum(self.y[:, :3] ** 2 * inverse, axis=-1) - before
            self._next += 1

    def _make_solvers(self) -> list[_OdeSolver]:
        from scipy import integrate

        solver_class = {"scipy-RK45": integrate.RK45, "scipy-DOP853": integrate.DOP853}[self.method.name]
        args = self._args

        def fun(t, y):
            return self._fun(t, y, *args)

        self._counted = 0
        return [
            solver_class(fun, self.t, y.copy(), self.t_end, rtol=self.tolerance, atol=self.tolerance)
            for y in self.y
        ]

    def warm_up(self) -> None:
        self._fun(0.0, self.y[0].copy(), *self._args)
        self._solvers = self._make_solvers()  # imports scipy and picks the first step outside the timing

    def advance_to(self, t: float) -> None:
        if self.driven:  # stop at each impulse, jump, restart the solvers there
            while self._next < len(self.impulses) and self.impulses[self._next].t <= t:
                t_impulse = self.impulses[self._next].t
                if t_impulse > self.t:
                    self._advance_solvers(t_impulse)
                self._apply_impulses_at(t_impulse)
                self._solvers = self._make_solvers() if t_impulse < self.t_end else None
        if t > self.t:
            self._advance_solvers(t)

    def _advance_solvers(self, t: float) -> None:
        if self._solvers is None:
            self._solvers = self._make_solvers()
        for b, solver in enumerate(self._solvers):
            while solver.t < t and solver.status == "running":
                message = solver.step()
                self.steps += 1
                if solver.status == "failed":
                    raise StepFailure(f"scipy {self.method.name} failed: {message}")
            if solver.t == t:
                self.y[b] = solver.y
            else:
                self.y[b] = solver.dense_output()(t)
        self.evaluations += sum(s.nfev for s in self._solvers) - self._counted
        self._counted = sum(s.nfev for s in self._solvers)
        self.t = t

    def finite(self) -> bool:
        return bool(np.all(np.isfinite(self.y)))

    def observe(self) -> dict[str, np.ndarray]:
        if hasattr(self, "analysed"):
            from dirac.flows.analysed import analysed_outputs

            return analysed_outputs(self.analysed, self.outputs, self.y, self.t)
        if hasattr(self, "field"):
            n = self.problem.mechanics.dimension
            return self.field.outputs(self.outputs, self.y[:, :n], self.y[:, n:], self.t)

        M = self.y[:, :3]
        R = self.y[:, 3:12].reshape(-1, 3, 3) if self.with_R else None
        work = self.y[:, -1] if self.driven else None
        return rigid_body_outputs(self.outputs, M, R, np.asarray(self.problem.inertia), gravity_weight(self.problem),
                                  work)

    def drift(self) -> float:
        if hasattr(self, "analysed"):
            return max(self.analysed.constraint_residual(y, self.t) for y in self.y)
        if hasattr(self, "field"):
            n = self.problem.mechanics.dimension
            return max(self.problem.mechanics.constraint_residual(y[:n], y[n:], self.t) for y in self.y)
        return 0.0  # RK methods do not preserve R^T R = 1; that is what the baseline shows


def _rigid_body_rhs(problem, with_R: bool):
    i1, i2, i3 = (float(x) for x in problem.inertia)
    if problem.kind == "heavy_top":
        w = problem.weight_vector

        def heavy(t, y, i1, i2, i3):
            dy = lean_rhs_full(t, y, i1, i2, i3)
            g0, g1, g2 = y[9], y[10], y[11]  # gamma = R^T e_z = third row of R
            dy[0] += g1 * w[2] - g2 * w[1]
            dy[1] += g2 * w[0] - g0 * w[2]
            dy[2] += g0 * w[1] - g1 * w[0]
            return dy

        return heavy, (i1, i2, i3)
    return (lean_rhs_full if with_R else lean_rhs_M), (i1, i2, i3)


def _driven_rhs(free, problem, with_R: bool):
    """The right-hand side ``free`` plus the external torque ``N`` (body frame, on ``dM/dt``)
    and the rate of work ``dW/dt = N·Omega`` (the last component of ``y``)."""
    inertia = np.asarray(problem.inertia, dtype=float)
    torque = problem.torque
    identity = np.eye(3)

    def driven(t, y, *args):
        dy = np.empty_like(y)
        dy[:-1] = free(t, y[:-1], *args)
        if torque is None:
            dy[-1] = 0.0
            return dy
        R = y[3:12].reshape(3, 3) if with_R else identity
        N = torque.evaluate(y[:3], R, t, inertia)
        dy[:3] += N
        dy[-1] = float(N @ (y[:3] / inertia))
        return dy

    return driven


def _factory(method: Method, problem, outputs, options) -> Stepper:
    return ScipyStepper(method, problem, outputs, options)


#: scipy's ``RK45`` and ``DOP853``, for every problem kind.
METHODS: tuple[Method, ...] = tuple(
    Method(
        name=name,
        order=order,
        kind="adaptive",
        symplectic=False,
        preserves_casimirs=False,
        description=f"baseline: scipy {name[6:]} with rtol = atol = tolerance (adaptive steps)",
        reference=reference,
        factories={kind: _factory for kind in ("rigid_body", "heavy_top", "constrained", "analysed")},
    )
    for name, order, reference in (
        ("scipy-RK45", 5, "Dormand & Prince (1980), scipy.integrate.RK45"),
        ("scipy-DOP853", 8, "Hairer, Norsett & Wanner, DOP853; scipy.integrate.DOP853"),
    )
)
