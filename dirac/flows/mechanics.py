"""A Lagrangian with holonomic constraints, compiled to numbers for RATTLE and friends.

For ``L = 1/2 q_dot^T M(q) q_dot - V(q)`` with constraints ``chi(q) = 0`` the
Hamiltonian is ``H = 1/2 p^T M(q)^{-1} p + V(q)`` and the constrained equations are
(Hairer, Lubich & Wanner, Geometric Numerical Integration, Sect. VII.1)

    q_dot = M^{-1} p,   p_dot = -grad H_q - G(q)^T lambda,   chi(q) = 0,

``G = d chi / dq``; the hidden constraint ``G(q) M^{-1} p = 0`` is the paper's third
stage (Sect. X). The multipliers ``lambda`` are those of the extended Lagrangian (1).

:class:`MechanicalSystem` extracts ``M(q)``, ``V(q)`` and ``chi(q)`` from a
:class:`dirac.Lagrangian` (sympy, once), and generates one numba module of step kernels
for them (:mod:`dirac.codegen.kernel_source`: RATTLE, the Dirac vector field, the
midpoint rule, energies and residuals with every expression inlined). A Lagrangian with
a time symbol (``Lagrangian.time``) gives ``M(q, t)``, ``V(q, t)``, ``chi(q, t)``; the
hidden constraint is then ``G M^{-1} p + d chi/dt = 0``. Lagrangians that are not of this form (terms linear in the
velocities, non-quadratic kinetic energy, a singular mass matrix) are refused with an
:class:`InputError` saying why.
"""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from dataclasses import dataclass, field
from typing import TYPE_CHECKING, Any

import numpy as np
import sympy

from dirac.errors import InputError
from dirac.model.lagrangian import Lagrangian
from dirac.validate import unknown_name_error, validate_finite

if TYPE_CHECKING:
    from dirac.analysis.constraint_analysis import ConstraintAnalysis

__all__ = ["DIRAC_FLOW_ROAD", "MechanicalSystem", "NotMechanicalError", "resolve_parameters"]

#: the way out named by :class:`NotMechanicalError` for terms linear in the velocities (a scene takes it by itself)
DIRAC_FLOW_ROAD = 'use method = "midpoint" on the Dirac flow instead'


class NotMechanicalError(InputError):
    """The Lagrangian is not ``1/2 q_dot^T M(q) q_dot - V(q)`` (terms linear in the
    velocities, a kinetic energy that is not quadratic): RATTLE cannot take it, the Dirac
    flow of its analysis (:class:`dirac.flows.analysed.AnalysedSystem`) may.

    ``reason`` says what the Lagrangian is; ``road`` the way out when the Dirac flow takes it
    (:data:`DIRAC_FLOW_ROAD`, empty otherwise). The message is ``reason; road``: a caller with
    another way out (Python, a scene) puts its own after ``reason``.
    """

    def __init__(self, reason: str, road: str = "") -> None:
        super().__init__(f"{reason}; {road}" if road else reason)
        self.reason = reason
        self.road = road


def _conformal_rate(forces: Sequence[sympy.Expr], velocities: Sequence[sympy.Symbol], mass: sympy.Matrix,
                    values: Mapping[sympy.Symbol, float], coordinates: Sequence[sympy.Symbol],
                    time: sympy.Symbol | None) -> float | None:
    """``gamma`` if ``Q = -gamma M q_dot`` for a constant ``gamma`` at these parameter values, else None.

    Then ``p_dot = -dH/dq - gamma p``: a conformal Hamiltonian system (McLachlan &
    Perlmutter 2001). ``Q`` must be linear in the velocities, without ``q`` or ``t``, with
    damping matrix ``D = -dQ/dq_dot`` equal to ``gamma M`` (e.g. ``Q = -c q_dot`` with
    ``M = m 1``: ``gamma = c / m``).
    """
    numeric = {k: sympy.Float(v) for k, v in values.items()}
    Q = sympy.Matrix([sympy.sympify(e).xreplace(numeric) for e in forces])
    D = -Q.jacobian(list(velocities))
    moving = set(coordinates) | set(velocities) | ({time} if time is not None else set())
    if any(entry.free_symbols & moving for entry in D):
        return None
    if any(sympy.simplify(e) != 0 for e in Q.xreplace({s: 0 for s in velocities})):
        return None
    M = sympy.Matrix(mass).xreplace(numeric)
    if any(entry.free_symbols for entry in (*D, *M)):
        return None
    Dn = np.array(D.tolist(), dtype=float)
    Mn = np.array(M.tolist(), dtype=float)
    gamma = float(np.trace(Dn) / np.trace(Mn))
    if not np.allclose(Dn, gamma * Mn, rtol=1e-13, atol=1e-15 * max(1.0, float(np.abs(Mn).max()))):
        return None
    return gamma


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


def _rotation(lagrangian: Lagrangian, values: Mapping[str, float]) -> tuple[int, int, float, str] | None:
    """``(i, j, w, "H - w (...)")`` of uniformly turning constraints at these parameter values, else None."""
    from dirac.model.rotating_frame import uniform_rotation

    found = uniform_rotation(lagrangian)
    if found is None:
        return None
    rate = found.rate.subs({s: values[s.name] for s in found.rate.free_symbols if s.name in values})
    if rate.free_symbols:
        return None
    names = tuple(q.name for q in lagrangian.coordinates)
    return found.first, found.second, float(rate), found.label(names, f"{float(rate):g}")


def _split_by_velocities(L: sympy.Expr, v: list[sympy.Symbol]) -> tuple[sympy.Matrix, list[sympy.Expr], sympy.Expr]:
    """``(d^2 L/dv_i dv_j, dL/dv_i, L - (terms with a velocity))`` of an expanded ``L``.

    The same as ``sympy.hessian(L, v)`` and ``diff(L, v_i)``, term by term: each term of the
    sum is differentiated only by the velocities it contains, so a system of ``n``
    coordinates costs ``O(terms)`` derivatives of small terms instead of ``n^2``
    derivatives of the whole ``L`` (minutes for a chain of 128 links).
    """
    index = {s: i for i, s in enumerate(v)}
    n = len(v)
    hessian: dict[tuple[int, int], list[sympy.Expr]] = {}
    gradient: list[list[sympy.Expr]] = [[] for _ in range(n)]
    rest: list[sympy.Expr] = []
    for term in sympy.Add.make_args(L):
        present = sorted(index[s] for s in term.free_symbols if s in index)
        if not present:
            rest.append(term)
            continue
        for i in present:
            first = sympy.diff(term, v[i])
            gradient[i].append(first)
            for j in present:
                if j >= i:
                    second = sympy.diff(first, v[j])
                    if second != 0:
                        hessian.setdefault((i, j), []).append(second)
    matrix = sympy.zeros(n, n)
    for (i, j), parts in hessian.items():
        matrix[i, j] = matrix[j, i] = sympy.Add(*parts)
    return matrix, [sympy.Add(*parts) for parts in gradient], sympy.Add(*rest)


@dataclass
class MechanicalSystem:
    """Numerical pieces of a natural mechanical system with holonomic constraints.

    Build it with :meth:`from_lagrangian`. :attr:`module` is the generated kernel module
    of :func:`dirac.codegen.kernel_source.mechanical_kernel_source`, interpreted or
    compiled as pays (:class:`dirac.codegen.tiers.TieredModule`; ``module.name`` is the
    compiled function, ``module.function(name)`` the tiered one) (functions
    ``f(q, t, c, out)`` of the coordinates in :attr:`coordinate_names` order, the time and
    the parameter values :attr:`params`; step loops ``rattle_constant_mass``,
    ``rattle_general``, ``midpoint_run``; ``field``, ``energy``, ``residuals``).

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
        The mass matrix when it depends on neither ``q`` nor ``t`` (fast RATTLE path).
    time_symbol : sympy.Symbol or None
        The time of a time-dependent system, else None.
    rotation : tuple or None
        ``(i, j, w, text)`` when the constraints turn uniformly at the rate ``w`` in the
        plane of coordinates ``i, j`` (:func:`dirac.model.rotating_frame.uniform_rotation`):
        the energy is not conserved, the Jacobi integral ``H - w (q_i p_j - q_j p_i)``
        (``text``) is; else None.
    forced : bool
        Whether generalized forces ``Q(q, q_dot, t)`` act (``Lagrangian.forces``); the
        module's ``force`` is then ``dH/dq - Q`` and it has the forced step loops of
        :mod:`dirac.codegen.forced_source` (``forced_rattle_run``, ``conformal_run``).
    conformal_rate : float or None
        ``gamma`` when the forces are ``Q = -gamma M q_dot`` (``p_dot = ... - gamma p``)
        with a constant mass: a conformal Hamiltonian system (McLachlan & Perlmutter 2001).
    """

    name: str
    coordinate_names: tuple[str, ...]
    dimension: int
    n_constraints: int
    parameter_values: dict[str, float]
    params: np.ndarray
    constant_mass: np.ndarray | None
    module: Any = field(repr=False, default=None)
    time_symbol: sympy.Symbol | None = field(repr=False, default=None)
    symbolic: dict[str, object] = field(repr=False, default_factory=dict)
    rotation: tuple[int, int, float, str] | None = field(repr=False, default=None)
    forced: bool = False
    conformal_rate: float | None = None
    # the constant mass last found positive definite (a copy): checked when it changes, not at every sample (a
    # 400-site lattice's eigvalsh took 60 ms of CPU a sample, and seconds of wall with BLAS threads under load)
    _positive_mass: np.ndarray | None = field(init=False, repr=False, compare=False, default=None)

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
        cls, lagrangian: Lagrangian, parameters: Mapping[str, float] | None = None, extra_source: str = "",
        with_forces: bool = False,
    ) -> MechanicalSystem:
        """Split ``L`` into ``1/2 q_dot^T M(q) q_dot - V(q)`` and generate its functions.

        Parameters
        ----------
        lagrangian
            The system (parameters without a value must be given in ``parameters``).
        parameters
            Overrides of parameter values, by name.
        extra_source
            Numba source appended to the generated kernel module.
        with_forces
            Generate the forced kernels (:mod:`dirac.codegen.forced_source`) even when the
            Lagrangian has no forces (a system that only receives impulses). A Lagrangian
            with forces always gets them.

        Raises
        ------
        InputError
            Unknown or missing parameter values, velocity-linear terms, a kinetic energy
            that is not quadratic in the velocities, or a mass matrix that is singular.
            An explicit time ``t`` (``lagrangian.time``) is taken: ``M(q, t)``, ``V(q, t)``,
            ``chi(q, t)``.
        """
        values = resolve_parameters(lagrangian, parameters)
        q = list(lagrangian.coordinates)
        v = list(lagrangian.velocities)
        L = sympy.expand(lagrangian.expression)
        hessian, gradient_at_rest, potential_terms = _split_by_velocities(L, v)
        velocity_symbols = set(v)
        if any(entry.free_symbols & velocity_symbols for entry in hessian.todok().values()):
            raise NotMechanicalError(
                f"the Lagrangian of {lagrangian.name!r} is not quadratic in the velocities: RATTLE and the "
                "flows here need L = 1/2 q_dot^T M(q) q_dot - V(q)"
            )
        # each term at rest by its own velocities: a substitution of all n of them in each of the n terms
        # is n^2 (31 s of a 200-site lattice's 40 s under cProfile)
        linear = [sympy.simplify(term.subs({s: 0 for s in term.free_symbols & velocity_symbols})) if term != 0
                  else term for term in gradient_at_rest]
        offending = [s.name for s, term in zip(v, linear) if term != 0]
        if offending:
            raise NotMechanicalError(
                f"the Lagrangian of {lagrangian.name!r} has terms linear in the velocities "
                f"({', '.join(offending)}, e.g. magnetic or gyroscopic terms): RATTLE needs "
                "L = 1/2 q_dot^T M(q) q_dot - V(q)", road=DIRAC_FLOW_ROAD,
            )
        potential = sympy.expand(-potential_terms)
        mass = sympy.Matrix(hessian)
        chis = sympy.Matrix(list(lagrangian.constraints))
        parameter_symbols = list(lagrangian.parameters)
        param_array = np.array([float(values[p.name]) for p in parameter_symbols], dtype=float)
        n, m = len(q), len(lagrangian.constraints)
        forces = lagrangian.force_vector if (lagrangian.is_forced or with_forces) else None
        forced_in_time = forces is not None and lagrangian.time is not None and any(
            lagrangian.time in e.free_symbols for e in forces)
        time = lagrangian.time if (lagrangian.is_time_dependent or forced_in_time) else None
        moving = {*q, *([time] if time is not None else [])}
        constant = all(not (entry.free_symbols & moving) for entry in mass.todok().values())
        from dirac.codegen import mechanical_kernel_source
        from dirac.codegen.tiers import tiered_module

        source = mechanical_kernel_source(q, parameter_symbols, mass, potential, list(chis), time,
                                          title=f"system {lagrangian.name}", forces=forces, velocities=v)
        rate = None
        if forces is not None:
            from dirac.codegen.forced_source import forced_kernel_source

            source += forced_kernel_source(q, v, parameter_symbols, forces, time, m, constant)
            if constant:
                rate = _conformal_rate(forces, v, mass, {p: values[p.name] for p in parameter_symbols}, q, time)
        module = tiered_module(source + extra_source, f"system {lagrangian.name!r}")
        constant_mass = None
        if constant:
            constant_mass = np.empty((n, n))
            module.function("mass")(np.zeros(n), 0.0, param_array, constant_mass)
        system = cls(
            name=lagrangian.name,
            coordinate_names=tuple(s.name for s in q),
            dimension=n,
            n_constraints=m,
            parameter_values={k: float(v) for k, v in values.items()},
            params=param_array,
            constant_mass=constant_mass,
            module=module,
            time_symbol=time,
            symbolic={"mass": mass, "potential": potential, "constraints": chis, "coordinates": q,
                      "parameters": parameter_symbols, "forces": forces, "velocities": v},
            rotation=_rotation(lagrangian, values),
            forced=forces is not None,
            conformal_rate=rate,
        )
        return system

    # ------------------------------------------------------------------ forces
    def applied_force(self, q: np.ndarray, q_dot: np.ndarray, time: float = 0.0) -> np.ndarray:
        """``Q(q, q_dot, t)`` (generated kernel ``applied_force``; zero for an unforced system)."""
        if not self.forced:
            return np.zeros(self.dimension)
        out = np.empty(self.dimension)
        self.module.function("applied_force")(np.ascontiguousarray(q, dtype=float), np.ascontiguousarray(q_dot, dtype=float),
                                  float(time), self.params, out)
        return out

    def apply_impulse(self, q: np.ndarray, p: np.ndarray, impulse: np.ndarray,
                      time: float = 0.0) -> tuple[np.ndarray, float]:
        """The momentum after a generalized impulse ``J`` (Lamb's ``Q_r'``) at the configuration ``q``.

        Integrating Lagrange's equations over an impulse of vanishing duration gives
        ``Delta p = J + G^T nu`` (the constraints' own impulse ``G^T nu``), and the
        velocity stage ``G M^{-1} p + d chi/dt = 0`` must hold after it, so

            Delta p = J - G^T (G M^{-1} G^T)^{-1} G M^{-1} J,   Delta q_dot = M^{-1} Delta p

        (with the velocity stage holding before). Returns the new ``p`` and the work of
        the impulse, ``J . (q_dot_before + q_dot_after) / 2`` (the change of the kinetic
        energy when the constraints do not move; Lamb, *Higher Mechanics*, Sect. 27),
        computed by :func:`dirac.flows.impulse_kick.impulse_kick`.
        """
        from dirac.flows.impulse_kick import impulse_kick

        q = np.asarray(q, dtype=float)
        impulse = np.array(impulse, dtype=float)
        mass = self.mass_matrix(q, time)
        m = self.n_constraints
        G = self._evaluate("jacobian", q, time, (m, self.dimension)) if m else np.zeros((0, self.dimension))
        after = np.array(p, dtype=float)
        # plain loops (dirac.flows.impulse_kick): an ensemble's member loop runs the same text compiled
        work = impulse_kick(mass, G, after, impulse)
        return after, float(work)

    def require_field(self, what: str) -> None:
        """Refuse ``what`` (a method needing the Dirac vector field) on a system whose
        generated module holds RATTLE only (:mod:`dirac.codegen.sparse_rattle`: a constant
        diagonal mass and many constraints, or many coordinates and no constraint).

        Raises
        ------
        InputError
            When the module has no vector field.
        """
        from dirac.codegen.sparse_rattle import RATTLE_ONLY

        if RATTLE_ONLY in getattr(self.module, "source", ""):
            raise InputError(
                f"{what} needs the Dirac vector field of {self.name!r}, which is not generated for a system of "
                f"{self.dimension} coordinates and {self.n_constraints} constraints with a constant diagonal mass (its "
                "kernel module holds the looped RATTLE only, so that it is built in seconds); use rattle-2 (or "
                "rattle-4/6/8)"
            )

    # ------------------------------------------------------------------ numerics (numpy side)
    def _evaluate(self, name: str, q: np.ndarray, time: float, shape: tuple[int, ...]) -> np.ndarray:
        """The generated function ``name(q, t, c, out)`` of the kernel module at one point."""
        out = np.empty(shape)
        self.module.function(name)(np.ascontiguousarray(q, dtype=float), float(time), self.params, out)
        return out

    def mass_matrix(self, q: np.ndarray, time: float = 0.0) -> np.ndarray:
        """``M(q, t)``, checked to be symmetric positive definite."""
        if self.constant_mass is not None:
            matrix = self.constant_mass.copy()
            if self._positive_mass is not None and np.array_equal(matrix, self._positive_mass):
                return matrix
        else:
            matrix = self._evaluate("mass", q, time, (self.dimension, self.dimension))
        eigenvalues = np.linalg.eigvalsh(matrix)
        if not np.all(np.isfinite(eigenvalues)) or eigenvalues.min() <= 1e-14 * max(1.0, eigenvalues.max()):
            raise InputError(
                f"the mass matrix of {self.name!r} is singular or not positive at q = {np.asarray(q).tolist()}: "
                "RATTLE needs a regular Lagrangian (positive kinetic energy in every velocity)"
            )
        if self.constant_mass is not None:
            self._positive_mass = matrix.copy()
        return matrix

    def energy(self, q: np.ndarray, p: np.ndarray, time: float = 0.0) -> float:
        """``H = 1/2 p^T M(q, t)^{-1} p + V(q, t)`` (generated kernel ``energy``)."""
        self.mass_matrix(q, time)  # refuses a singular mass matrix
        q = np.ascontiguousarray(q, dtype=float)
        return float(self.module.function("energy")(q, np.ascontiguousarray(p, dtype=float), float(time), self.params))

    def residuals(self, q: np.ndarray, p: np.ndarray, time: float = 0.0) -> tuple[np.ndarray, np.ndarray]:
        """Position residuals ``chi(q, t)`` and velocity residuals ``G(q, t) M(q, t)^{-1} p + d chi/dt``
        (generated kernel ``residuals``)."""
        m = self.n_constraints
        if m == 0:
            return np.zeros(0), np.zeros(0)
        self.mass_matrix(q, time)  # refuses a singular mass matrix
        out = np.empty(2 * m)
        self.module.function("residuals")(np.ascontiguousarray(q, dtype=float), np.ascontiguousarray(p, dtype=float),
                                          float(time), self.params, out)
        return out[:m], out[m:]

    def constraint_residual(self, q: np.ndarray, p: np.ndarray, time: float = 0.0) -> float:
        """``max(|chi|, |G M^{-1} p + d chi/dt|)``: distance from the constraint surface."""
        chi, velocity = self.residuals(q, p, time)
        if chi.size == 0:
            return 0.0
        return float(max(np.max(np.abs(chi)), np.max(np.abs(velocity))))

    def project(self, q: np.ndarray, p: np.ndarray, tol: float = 1e-14, max_iter: int = 50,
                time: float = 0.0) -> tuple[np.ndarray, np.ndarray]:
        """Project ``(q, p)`` onto the constraint surface (closest point in the metric ``M``).

        ``q <- q - M^{-1} G^T (G M^{-1} G^T)^{-1} chi(q, t)`` (Newton, until ``|chi|`` stops
        decreasing), then ``p <- p - G^T (G M^{-1} G^T)^{-1} (G M^{-1} p + d chi/dt)``.

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
            chi = self._evaluate("constraints", q, time, (m,))
            if np.max(np.abs(chi)) <= tol * (1.0 + q @ q):
                break
            G = self._evaluate("jacobian", q, time, shape)
            A = np.linalg.solve(self.mass_matrix(q, time), G.T)
            q = q - A @ np.linalg.solve(G @ A, chi)
        else:
            raise InputError(
                f"could not project the initial q onto the constraints of {self.name!r} "
                f"(residual {np.max(np.abs(chi)):.3g}): give q closer to the surface"
            )
        G = self._evaluate("jacobian", q, time, shape)
        mass = self.mass_matrix(q, time)
        A = np.linalg.solve(mass, G.T)
        hidden = G @ np.linalg.solve(mass, p) + self._evaluate("constraints_dt", q, time, (m,))
        p = p - G.T @ np.linalg.solve(G @ A, hidden)
        return q, p
