"""Flows on the full phase space of a Dirac–Bergmann analysis (any analysed system).

From a :class:`dirac.analysis.constraint_analysis.ConstraintAnalysis` (phase space ``z``: the
coordinates and multipliers, then their momenta), the numerical Hamiltonian vector field

    z_dot = {z, H}_D - {z, Phi_a} (C^{-1})^{ab} d_t Phi_b
          = J grad H - J grad Phi^T C^{-1} (grad Phi J grad H + d_t Phi),
    C_ab = {Phi_a, Phi_b}  (240; the d_t term for explicitly time-dependent constraints,
    Gitman–Tyutin),

over the second-class constraints ``Phi`` is compiled once: ``grad H``, ``Phi`` and
``grad Phi`` are generated from sympy into one kernel module with the field and the
midpoint step loop (:func:`dirac.codegen.kernel_source.analysed_kernel_source`); ``C`` is
evaluated and solved numerically at each point.
``H`` is the canonical Hamiltonian; with first-class constraints the free multipliers of
``H_T`` take the values the user chooses (``multipliers=``, constants or phase-space
functions; default ``u = 0``): ``H = H_c + v_f phi_f``. Gauge-invariant quantities do not
depend on that choice; a gauge-fixed analysis (``analysis.fix_gauge``) has no free
multiplier left. This path takes every Lagrangian the
engine can analyse, also those that :class:`MechanicalSystem` refuses (terms linear in the
velocities, singular Lagrangians such as the rigid body's (228)).
"""

from __future__ import annotations

from collections.abc import Callable, Mapping
from dataclasses import dataclass, field
from typing import TYPE_CHECKING, Any

import numpy as np
import sympy

from dirac.errors import InputError
from dirac.model.lagrangian import Lagrangian

if TYPE_CHECKING:
    from dirac.analysis.constraint_analysis import ConstraintAnalysis

__all__ = ["AnalysedSystem", "AnalysedProblem"]


@dataclass
class AnalysedSystem:
    """Compiled Dirac vector field of an analysed Lagrangian.

    Build it from an analysis with :meth:`from_analysis` (the road
    ``Lagrangian -> analyze -> compiled flow``), or from a Lagrangian with
    :meth:`from_lagrangian`, which fixes the parameters, analyses and then does the same.
    """

    name: str
    variable_names: tuple[str, ...]
    dimension: int
    n_constraints: int
    parameter_values: dict[str, float]
    params: np.ndarray
    module: Any
    analysis: ConstraintAnalysis = field(repr=False)
    momenta: Callable[..., np.ndarray] = field(repr=False)
    gauge_multipliers: dict[str, str] = field(default_factory=dict)
    #: the Hamiltonian of the flow (``H_c`` plus the chosen free multipliers times their constraints), sympy
    hamiltonian: Any = field(default=sympy.S.Zero, repr=False)
    #: the parameters that take the values ``params`` at run time, in that order (sympy symbols)
    parameter_symbols: tuple[Any, ...] = field(default=(), repr=False)

    @classmethod
    def from_lagrangian(cls, lagrangian: Lagrangian, parameters: Mapping[str, float] | None = None) -> AnalysedSystem:
        """Fix every parameter (its default, overridden by ``parameters``), analyse, compile.

        The same as ``from_analysis(analyze(lagrangian.fix(...)))``: the analysis then
        decides the constraint structure at exactly these values.

        Raises
        ------
        InputError
            Unknown parameters, values that are not finite numbers, or parameters
            without a value.
        """
        from dirac.analysis.constraint_analysis import analyze
        from dirac.flows.mechanics import resolve_parameters

        values = resolve_parameters(lagrangian, parameters)
        return cls.from_analysis(analyze(lagrangian.fix(**values)))

    @classmethod
    def from_analysis(
        cls, analysis: ConstraintAnalysis, multipliers: Mapping[str, float | str] | None = None
    ) -> AnalysedSystem:
        """Compile the Dirac vector field of an existing analysis (nothing is analysed again).

        ``grad H_c``, the second-class constraints ``Phi`` and ``grad Phi`` are generated
        once from the analysis (:mod:`dirac.codegen`). Parameters the analysed Lagrangian
        still has as symbols take their default values at run time; the analysis decided
        the constraint structure at generic values of them, which holds at the defaults
        unless these are special. To analyse at exactly the values used, fix them first
        (:meth:`Lagrangian.fix`, or :meth:`from_lagrangian`).

        Parameters
        ----------
        analysis : ConstraintAnalysis
            The result of :func:`dirac.analyze`.
        multipliers : mapping, optional
            Values of free multipliers (names out of ``analysis.undetermined_multipliers``):
            numbers, or expressions in the phase-space variables; the flow is that of
            ``H_c + v_f phi_f`` (the total Hamiltonian; Henneaux–Teitelboim, ch. 1). Those not given are 0.

        Raises
        ------
        InputError
            ``analysis`` is not an analysis, a parameter still symbolic in it has no
            default value, or a multiplier name is not a free multiplier.
        """
        from dirac.codegen import analysed_kernel_source, array_function
        from dirac.codegen.tiers import tiered_module

        lagrangian = getattr(analysis, "lagrangian", None)
        if not isinstance(lagrangian, Lagrangian) or not hasattr(analysis, "second_class"):
            raise InputError(f"from_analysis needs the result of dirac.analyze(system), not {type(analysis).__name__}")
        if lagrangian.is_forced:
            raise InputError(
                f"system {lagrangian.name!r} has generalized forces, which the flows of the full phase space do not "
                "take: integrate it as a ForcedProblem (L = 1/2 q_dot^T M(q) q_dot - V(q)), or use "
                "analysis.vector_field() with scipy"
            )
        defaults = {p: float(v) for p, v in lagrangian.parameters.items() if v is not None}
        missing = [p.name for p in lagrangian.parameters if p not in defaults]
        if missing:
            raise InputError(
                f"system {lagrangian.name!r}: parameters {', '.join(missing)} have no value; fix them before "
                "the analysis (Lagrangian.fix) or use AnalysedSystem.from_lagrangian(lagrangian, {name: value})"
            )
        z = tuple(analysis.phase_space)
        H = analysis.canonical_hamiltonian
        constraints = list(analysis.second_class)
        chosen = _free_multipliers(analysis, multipliers or {})
        H_flow = H + sum((v * phi for v, phi in chosen.values()), sympy.S.Zero)
        time = getattr(analysis, "time", None)  # a time-dependent system, or a gauge such as x0 - t
        module = tiered_module(analysed_kernel_source(z, list(defaults), H_flow, constraints, time,
                                                     title=f"analysed system {lagrangian.name}", energy=H),
                              f"analysed system {lagrangian.name!r}")
        velocities = list(lagrangian.velocities)
        expression = lagrangian.expression.subs(defaults)
        momenta = array_function([list(lagrangian.coordinates), velocities],
                                 [sympy.diff(expression, v) for v in velocities], cse=False)
        return cls(
            name=lagrangian.name,
            variable_names=tuple(s.name for s in z),
            dimension=len(z),
            n_constraints=len(constraints),
            parameter_values={**lagrangian.fixed_values, **{p.name: v for p, v in defaults.items()}},
            params=np.array(list(defaults.values()), dtype=float),
            module=module,
            analysis=analysis,
            momenta=momenta,
            gauge_multipliers={name: str(v) for name, (v, _) in chosen.items()},
            hamiltonian=H_flow,
            parameter_symbols=tuple(defaults),
        )

    def energy(self, z: np.ndarray, time: float = 0.0) -> float:
        """``H_c(z, t)`` (generated kernel ``energy``)."""
        return float(self.module.function("energy")(np.ascontiguousarray(z, dtype=float), float(time), self.params))

    def constraint_residual(self, z: np.ndarray, time: float = 0.0) -> float:
        """``max |Phi(z, t)|`` over the second-class constraints (generated kernel ``residuals``)."""
        if self.n_constraints == 0:
            return 0.0
        out = np.empty(self.n_constraints)
        self.module.function("residuals")(np.ascontiguousarray(z, dtype=float), float(time), self.params, out)
        return float(np.max(np.abs(out)))

    def field(self, z: np.ndarray, time: float = 0.0) -> np.ndarray:
        """``z_dot`` at ``z`` and ``time`` (generated kernel ``field``)."""
        out = np.empty(self.dimension)
        self.module.function("field")(np.ascontiguousarray(z, dtype=float), float(time), self.params, out)
        return out

    def initial_state(self, q: dict[str, float], q_dot: dict[str, float] | None = None,
                      p: dict[str, float] | None = None, seed: int | None = 0) -> np.ndarray:
        """A point of the constraint surface with the given coordinates and velocities
        (``p = dL/dq_dot``) or momenta; the multipliers and the rest are completed by
        :meth:`ConstraintAnalysis.surface_point` (Gauss–Newton from a pseudo-random start
        drawn with ``seed``: the same seed gives the same last bits of the completed values
        in every process; ``None`` draws a fresh start).

        Raises
        ------
        InputError
            If no point of the surface has these values.
        """
        lagrangian = self.analysis.lagrangian
        names = [s.name for s in lagrangian.coordinates]
        values = {k: float(v) for k, v in q.items()}
        if q_dot is not None:
            qv = [values.get(n, 0.0) for n in names]
            vv = [float(q_dot.get(n, 0.0)) for n in names]
            momenta = np.broadcast_to(np.asarray(self.momenta(qv, vv), dtype=float), (len(names),))
            values.update({f"p_{n}": float(m) for n, m in zip(names, momenta)})
        elif p is not None:
            values.update({f"p_{n}": float(v) for n, v in p.items()})
        point = self.analysis.surface_point(values, seed=seed)
        return np.array([point[n] for n in self.variable_names])


def _free_multipliers(analysis: ConstraintAnalysis, values: Mapping[str, float | str]) -> dict[str, tuple]:
    """Name -> ``(value, phi)`` of the chosen free multipliers (values parsed in the phase-space names).

    Raises
    ------
    InputError
        A name that is not a free multiplier of the analysis, or a value that is not a
        number or an expression in the phase-space variables and parameters.
    """
    from dirac.model.expressions import parse_expression
    from dirac.validate import unknown_name_error

    free = {u.name: phi for u, phi in zip(analysis.primary_multipliers, analysis.primary_constraints)
            if u in set(analysis.undetermined_multipliers)}
    names = {**analysis.symbols, **{p.name: p for p in analysis.parameters}}
    chosen: dict[str, tuple] = {}
    for name, value in values.items():
        if name not in free:
            raise unknown_name_error(
                "free multiplier", name, free,
                hint="only the multipliers the analysis leaves undetermined can be chosen" if free
                else f"{analysis.name!r} has no free multiplier (no gauge freedom, or the gauge is fixed)",
            )
        if isinstance(value, bool) or not isinstance(value, (int, float, str)):
            raise InputError(f"free multiplier {name}: give a number or an expression, not {value!r}")
        if isinstance(value, str):
            expr = parse_expression(value, names, what=f"free multiplier {name}")
        elif not np.isfinite(value):
            raise InputError(f"free multiplier {name}: the value must be a finite number, not {value}")
        else:
            expr = sympy.Rational(repr(float(value)))
        chosen[name] = (expr, free[name])
    return chosen


@dataclass
class AnalysedProblem:
    """An analysed system with initial states ``z0`` (shape (N,) or (B, N)) on its surface."""

    analysed: AnalysedSystem
    z0: np.ndarray
    surface_tolerance: float = 1e-8
    batched: bool = field(init=False, default=False)

    kind = "analysed"
    outputs = ("z", "q", "p", "energy", "constraint_residual")

    def __post_init__(self) -> None:
        z0 = np.asarray(self.z0, dtype=float)
        self.batched = z0.ndim == 2
        z0 = np.atleast_2d(z0).copy()
        if z0.shape[1] != self.analysed.dimension:
            raise InputError(f"initial state has {z0.shape[1]} entries; the phase space has {self.analysed.dimension}: "
                             f"{', '.join(self.analysed.variable_names)}")
        for z in z0:
            residual = self.analysed.constraint_residual(z)
            if not residual <= self.surface_tolerance * (1.0 + float(z @ z)):
                raise InputError(f"initial state is off the constraint surface (residual {residual:.3g}); "
                                 "complete it with AnalysedSystem.initial_state")
        self.z0 = z0

    @property
    def system(self) -> str:
        return self.analysed.name

    @property
    def batch(self) -> int:
        return int(self.z0.shape[0])

    def parameters(self) -> dict[str, object]:
        return dict(self.analysed.parameter_values)


def analysed_outputs(analysed: AnalysedSystem, names: tuple[str, ...], z: np.ndarray,
                     time: float = 0.0) -> dict[str, np.ndarray]:
    """Outputs of an analysed system from batched ``z`` (B, N): the state ``z``, its
    coordinate half ``q`` (coordinates and multipliers), momentum half ``p``, ``energy``
    (``H_c``) and ``constraint_residual`` (``max |Phi|``)."""
    half = analysed.dimension // 2
    result: dict[str, np.ndarray] = {}
    for name in names:
        if name == "z":
            result[name] = z.copy()
        elif name == "q":
            result[name] = z[:, :half].copy()
        elif name == "p":
            result[name] = z[:, half:].copy()
        elif name == "energy":
            result[name] = np.array([analysed.energy(x, time) for x in z])
        elif name == "constraint_residual":
            result[name] = np.array([analysed.constraint_residual(x, time) for x in z])
    return result
