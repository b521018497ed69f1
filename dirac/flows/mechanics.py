"""A Lagrangian with holonomic constraints, compiled to numbers for RATTLE and friends.

For ``L = 1/2 q_dot^T M(q) q_dot - V(q)`` with constraints ``chi(q) = 0`` the
Hamiltonian is ``H = 1/2 p^T M(q)^{-1} p + V(q)`` and the constrained equations are
(Hairer, Lubich & Wanner, Geometric Numerical Integration, Sect. VII.1)

    q_dot = M^{-1} p,   p_dot = -grad H_q - G(q)^T lambda,   chi(q) = 0,

``G = d chi / dq``; the hidden constraint ``G(q) M^{-1} p = 0`` is the paper's third
stage (Sect. X). The multipliers ``lambda`` are those of the extended Lagrangian (1).

:class:`MechanicalSystem` extracts ``M(q)``, ``V(q)`` and ``chi(q)`` from a
:class:`dirac.Lagrangian` (sympy, once), and generates numba functions for them
(:mod:`dirac.codegen.numba_backend`). Lagrangians that are not of this form (terms linear in the
velocities, non-quadratic kinetic energy, a singular mass matrix) are refused with an
:class:`InputError` saying why.
"""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import dataclass, field
from typing import TYPE_CHECKING

import numpy as np
import sympy

from dirac.errors import InputError
from dirac.model.lagrangian import Lagrangian
from dirac.validate import unknown_name_error, validate_finite

if TYPE_CHECKING:
    from dirac.analysis.constraint_analysis import ConstraintAnalysis

__all__ = ["MechanicalSystem", "NotMechanicalError", "TimeDependentSystemError", "refuse_time_dependent", "resolve_parameters"]


class NotMechanicalError(InputError):
    """The Lagrangian is not ``1/2 q_dot^T M(q) q_dot - V(q)`` (terms linear in the
    velocities, a kinetic energy that is not quadratic): RATTLE cannot take it, the Dirac
    flow of its analysis (:class:`dirac.flows.analysed.AnalysedSystem`) may."""


class TimeDependentSystemError(InputError):
    """The Lagrangian or a constraint depends explicitly on the time ``t``: the compiled
    flows integrate autonomous systems only, so they refuse it instead of freezing ``t``."""


def refuse_time_dependent(lagrangian: Lagrangian, analysis: object | None = None) -> None:
    """Raise :class:`TimeDependentSystemError` when ``lagrangian`` depends explicitly on ``t``,
    or when ``analysis`` of it does (a time-dependent gauge such as ``x0 - t``)."""
    if analysis is not None and getattr(analysis, "time", None) is not None and not lagrangian.is_time_dependent:
        raise TimeDependentSystemError(
            f"the gauge conditions {', '.join(getattr(analysis, 'gauge_conditions', ()))} of {lagrangian.name!r} "
            "depend explicitly on the time t: the numerical flows integrate only systems without explicit time "
            "dependence; use a gauge without t for a flow, or equations_of_motion of the analysis"
        )
    if lagrangian.is_time_dependent:
        raise TimeDependentSystemError(
            f"system {lagrangian.name!r} depends explicitly on the time t (a rheonomic system): the "
            "numerical flows integrate only systems without explicit time dependence; analyse it with "
            "dirac analyze (or dirac.analyze), which includes the partial time derivatives"
        )


def resolve_parameters(lagrangian: Lagrangian, parameters: Mapping[str, float] | None = None) -> dict[str, float]:
    """The value of every parameter of ``lagrangian``: its default, overridden by ``parameters``.

    Raises
    ------
    InputError
        A name that is not a parameter, a value that is not a finite number, or a
        parameter with neither a default nor a value given.
    """
    values = dict(lagrangian.parameter_values)
    for key, value in (parameters or {}).items():
        if key not in values:
            raise unknown_name_error("parameter", key, values, source=f"system {lagrangian.name!r}")
        values[key] = validate_finite(value, f"parameter {key!r}")
    missing = sorted(k for k, v in values.items() if v is None)
    if missing:
        raise InputError(
            f"system {lagrangian.name!r}: parameters {', '.join(missing)} have no value; give them "
            "(in a scene: under [system] parameters)"
        )
    return {k: float(v) for k, v in values.items() if v is not None}


@dataclass
class MechanicalSystem:
    """Numerical pieces of a natural mechanical system with holonomic constraints.

    Build it with :meth:`from_lagrangian`. Generated numba functions (``f(q, params, out)``
    with a flat ``out``, coordinates in :attr:`coordinate_names` order): ``mass`` (n, n),
    ``grad_potential`` (n,), ``potential`` (1,), ``constraints`` (m,),
    ``constraint_jacobian`` (m, n), ``mass_derivative`` (n, n, n) with
    ``[k, i, j] = dM_ij/dq_k``, ``constraint_hessian`` (m, n, n); :attr:`functions` is the
    tuple handed to the kernels of :mod:`dirac.flows.constrained_kernels`.

    Attributes
    ----------
    name : str
    coordinate_names : tuple of str
    dimension : int
        Number of coordinates ``n``.
    n_constraints : int
        Number of holonomic constraints ``m``.
    parameter_values : dict
        Parameter name -> value used.
    constant_mass : numpy.ndarray or None
        The mass matrix when it does not depend on ``q`` (fast RATTLE path).
    """

    name: str
    coordinate_names: tuple[str, ...]
    dimension: int
    n_constraints: int
    parameter_values: dict[str, float]
    params: np.ndarray
    constant_mass: np.ndarray | None
    module: object
    functions: tuple = field(repr=False, default=())
    symbolic: dict[str, object] = field(repr=False, default_factory=dict)

    # ------------------------------------------------------------------ building
    @classmethod
    def from_analysis(
        cls, analysis: ConstraintAnalysis, parameters: Mapping[str, float] | None = None, extra_source: str = ""
    ) -> MechanicalSystem:
        """The mechanical system of an analysed Lagrangian (the road ``Lagrangian ->
        analyze -> compiled flow``, as :meth:`AnalysedSystem.from_analysis`).

        RATTLE needs only ``M(q)``, ``V(q)`` and ``chi(q)``, which come from the Lagrangian
        the analysis keeps (``analysis.lagrangian``); its stages 3 and 4 (the hidden
        constraint ``G M^{-1} p = 0`` and the multiplier) are what the integrator enforces.
        Parameters fixed before the analysis stay fixed; the others are given at run
        time, as in :meth:`from_lagrangian`.

        Parameters
        ----------
        analysis : ConstraintAnalysis
            The result of :func:`dirac.analyze`.
        parameters, extra_source
            As for :meth:`from_lagrangian`.

        Raises
        ------
        InputError
            ``analysis`` is not an analysis, or as for :meth:`from_lagrangian`.
        """
        lagrangian = getattr(analysis, "lagrangian", None)
        if not isinstance(lagrangian, Lagrangian):
            raise InputError(f"from_analysis needs the result of dirac.analyze(system), not {type(analysis).__name__}")
        return cls.from_lagrangian(lagrangian, parameters, extra_source)

    @classmethod
    def from_lagrangian(
        cls, lagrangian: Lagrangian, parameters: Mapping[str, float] | None = None, extra_source: str = ""
    ) -> MechanicalSystem:
        """Split ``L`` into ``1/2 q_dot^T M(q) q_dot - V(q)`` and generate its functions.

        Parameters
        ----------
        lagrangian
            The system (parameters without a value must be given in ``parameters``).
        parameters
            Overrides of parameter values, by name.
        extra_source
            Numba source appended to the generated module (step loops).

        Raises
        ------
        InputError
            Unknown or missing parameter values, velocity-linear terms, a kinetic energy
            that is not quadratic in the velocities, a mass matrix that is singular, or
            (:class:`TimeDependentSystemError`) an explicit dependence on the time ``t``.
        """
        refuse_time_dependent(lagrangian)
        values = resolve_parameters(lagrangian, parameters)
        q = list(lagrangian.coordinates)
        v = list(lagrangian.velocities)
        L = sympy.expand(lagrangian.expression)
        zero_velocity = {s: 0 for s in v}
        hessian = sympy.hessian(L, v)
        if any(entry.free_symbols & set(v) for entry in hessian):
            raise NotMechanicalError(
                f"the Lagrangian of {lagrangian.name!r} is not quadratic in the velocities: RATTLE and the "
                "flows here need L = 1/2 q_dot^T M(q) q_dot - V(q)"
            )
        linear = [sympy.simplify(sympy.diff(L, s).subs(zero_velocity)) for s in v]
        offending = [s.name for s, term in zip(v, linear) if term != 0]
        if offending:
            raise NotMechanicalError(
                f"the Lagrangian of {lagrangian.name!r} has terms linear in the velocities "
                f"({', '.join(offending)}, e.g. magnetic or gyroscopic terms): RATTLE needs "
                "L = 1/2 q_dot^T M(q) q_dot - V(q); use method = \"midpoint\" on the Dirac flow instead"
            )
        potential = sympy.expand(-L.subs(zero_velocity))
        mass = sympy.Matrix(hessian)
        chis = sympy.Matrix(list(lagrangian.constraints))
        parameter_symbols = list(lagrangian.parameters)
        param_array = np.array([float(values[p.name]) for p in parameter_symbols], dtype=float)
        n, m = len(q), len(lagrangian.constraints)
        jacobian = chis.jacobian(q) if m else sympy.zeros(0, n)
        grad_v = sympy.Matrix([sympy.diff(potential, s) for s in q])
        dmass = [mass.diff(s) for s in q]
        hessians = [e for chi in chis for e in sympy.hessian(chi, q)]
        constant = all(not (entry.free_symbols & set(q)) for entry in mass)
        from dirac.codegen import GeneratedFunction, generate_module

        args = tuple(q)
        functions = [
            GeneratedFunction("mass", args, mass, "mass matrix M(q), (n, n)"),
            GeneratedFunction("potential", args, [potential], "potential V(q), (1,)"),
            GeneratedFunction("grad_potential", args, grad_v, "dV/dq, (n,)"),
            GeneratedFunction("constraints", args, list(chis), "holonomic constraints chi(q), (m,)"),
            GeneratedFunction("constraint_jacobian", args, jacobian, "G = dchi/dq, (m, n)"),
            GeneratedFunction(
                "mass_derivative", args, [e for d in dmass for e in d], "dM_ij/dq_k as [k, i, j], (n, n, n)"
            ),
            GeneratedFunction("constraint_hessian", args, hessians, "d2 chi_a/dq_k dq_j as [a, k, j], (m, n, n)"),
        ]
        from dirac.flows import constrained_kernels

        module = generate_module(functions, parameter_symbols, extra_source, title=f"system {lagrangian.name}")
        functions_tuple = tuple(getattr(module, name) for name in constrained_kernels.FUNCTION_NAMES)
        constant_mass = None
        if constant:
            constant_mass = constrained_kernels.call(module.mass, np.zeros(n), param_array, n * n).reshape(n, n)
        system = cls(
            name=lagrangian.name,
            coordinate_names=tuple(s.name for s in q),
            dimension=n,
            n_constraints=m,
            parameter_values={k: float(v) for k, v in values.items()},
            params=param_array,
            constant_mass=constant_mass,
            module=module,
            functions=functions_tuple,
            symbolic={"mass": mass, "potential": potential, "constraints": chis, "coordinates": q,
                      "parameters": parameter_symbols},
        )
        return system

    # ------------------------------------------------------------------ numerics (numpy side)
    def _call(self, name: str, q: np.ndarray, size: int) -> np.ndarray:
        from dirac.flows.constrained_kernels import call

        return call(getattr(self.module, name), q, self.params, size)

    def mass_matrix(self, q: np.ndarray) -> np.ndarray:
        """``M(q)``, checked to be symmetric positive definite."""
        if self.constant_mass is not None:
            matrix = self.constant_mass.copy()
        else:
            matrix = self._call("mass", q, self.dimension * self.dimension).reshape(self.dimension, self.dimension)
        eigenvalues = np.linalg.eigvalsh(matrix)
        if not np.all(np.isfinite(eigenvalues)) or eigenvalues.min() <= 1e-14 * max(1.0, eigenvalues.max()):
            raise InputError(
                f"the mass matrix of {self.name!r} is singular or not positive at q = {np.asarray(q).tolist()}: "
                "RATTLE needs a regular Lagrangian (positive kinetic energy in every velocity)"
            )
        return matrix

    def energy(self, q: np.ndarray, p: np.ndarray) -> float:
        """``H = 1/2 p^T M(q)^{-1} p + V(q)``."""
        potential = self._call("potential", q, 1)[0]
        return float(0.5 * p @ np.linalg.solve(self.mass_matrix(q), p) + potential)

    def residuals(self, q: np.ndarray, p: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """Position residuals ``chi(q)`` and velocity residuals ``G(q) M(q)^{-1} p``."""
        m = self.n_constraints
        if m == 0:
            return np.zeros(0), np.zeros(0)
        chi = self._call("constraints", q, m)
        G = self._call("constraint_jacobian", q, m * self.dimension).reshape(m, self.dimension)
        return chi, G @ np.linalg.solve(self.mass_matrix(q), p)

    def constraint_residual(self, q: np.ndarray, p: np.ndarray) -> float:
        """``max(|chi(q)|, |G M^{-1} p|)``: distance from the constraint surface."""
        chi, velocity = self.residuals(q, p)
        if chi.size == 0:
            return 0.0
        return float(max(np.max(np.abs(chi)), np.max(np.abs(velocity))))

    def project(self, q: np.ndarray, p: np.ndarray, tol: float = 1e-14, max_iter: int = 50) -> tuple[np.ndarray, np.ndarray]:
        """Project ``(q, p)`` onto the constraint surface (closest point in the metric ``M``).

        ``q <- q - M^{-1} G^T (G M^{-1} G^T)^{-1} chi(q)`` (Newton, until ``|chi|`` stops
        decreasing), then ``p <- p - G^T (G M^{-1} G^T)^{-1} G M^{-1} p``.

        Raises
        ------
        InputError
            When the projection does not converge (q too far from the surface).
        """
        q = np.array(q, dtype=float)
        p = np.array(p, dtype=float)
        m = self.n_constraints
        if m == 0:
            return q, p
        shape = (m, self.dimension)
        for _ in range(max_iter):
            chi = self._call("constraints", q, m)
            if np.max(np.abs(chi)) <= tol * (1.0 + q @ q):
                break
            G = self._call("constraint_jacobian", q, m * self.dimension).reshape(shape)
            A = np.linalg.solve(self.mass_matrix(q), G.T)
            q = q - A @ np.linalg.solve(G @ A, chi)
        else:
            raise InputError(
                f"could not project the initial q onto the constraints of {self.name!r} "
                f"(residual {np.max(np.abs(chi)):.3g}): give q closer to the surface"
            )
        G = self._call("constraint_jacobian", q, m * self.dimension).reshape(shape)
        mass = self.mass_matrix(q)
        A = np.linalg.solve(mass, G.T)
        p = p - G.T @ np.linalg.solve(G @ A, G @ np.linalg.solve(mass, p))
        return q, p
