"""Problems: a system with validated numbers and initial states, ready to integrate.

A problem holds everything about *what* is integrated (equations, parameters, initial
states); *how* (method, step, sampling, outputs) is given to :func:`dirac.flows.integrate`.
Initial states may carry a leading batch axis: many bodies or initial conditions are
integrated with the same method in one call.

* :class:`RigidBodyProblem` -- the free rigid body, Euler–Poisson equations (250)–(251).
* :class:`HeavyTopProblem` -- the rigid body in a uniform gravity field,
  ``H = H_0(M) + m g <chi, R^T e_z>``.
* :class:`ConstrainedProblem` -- a mechanical system ``L = 1/2 q_dot^T M(q) q_dot - V(q)``
  with holonomic constraints (a :class:`dirac.flows.mechanics.MechanicalSystem`).

Each declares its ``kind`` (``"rigid_body"``, ``"heavy_top"``, ``"constrained"``; the
analysed systems of :mod:`dirac.flows.analysed` have ``"analysed"``): the methods choose
their stepper by it. :class:`Problem` is what :func:`dirac.flows.integrate` needs of any
problem.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import TYPE_CHECKING, ClassVar, Protocol, runtime_checkable

import numpy as np

from dirac.errors import InputError
from dirac.validate import validate_array, validate_non_negative

if TYPE_CHECKING:
    from dirac.flows.impulses import AngularImpulse
    from dirac.flows.mechanics import MechanicalSystem
    from dirac.flows.torques import Torque
    from dirac.model.lagrangian import Lagrangian

__all__ = ["RigidBodyProblem", "HeavyTopProblem", "ConstrainedProblem", "ForcedProblem", "Impulse", "Problem",
           "OffSurfaceError"]

#: the way out a Python user is shown for a Lagrangian with terms linear in the velocities
PYTHON_DIRAC_FLOW_ROAD = (
    "run the Dirac flow of its analysis instead: from dirac.flows.analysed import AnalysedProblem, "
    "AnalysedSystem; system = AnalysedSystem.from_lagrangian(lagrangian); "
    "dirac.integrate(AnalysedProblem(system, system.initial_state({'x': ...}, q_dot={'x': ...})), "
    "\"midpoint\", ...) (or a scipy method; a scene takes this road by itself)"
)


class OffSurfaceError(InputError):
    """Initial data of a :class:`ConstrainedProblem` off the constraint surface.

    ``detail`` says what is off; the message adds the advice for Python
    (``project=True``); a scene re-raises it with its own (``project = true``).
    """

    def __init__(self, detail: str, advice: str) -> None:
        super().__init__(f"{detail}; {advice}")
        self.detail = detail


@runtime_checkable
class Problem(Protocol):
    """What :func:`dirac.flows.integrate` needs of a problem.

    Attributes
    ----------
    kind : str
        ``"rigid_body"``, ``"heavy_top"``, ``"constrained"`` or ``"analysed"``: which
        steppers of a method apply (:attr:`dirac.flows.methods.base.Method.factories`).
    outputs : tuple of str
        The outputs that can be requested.
    batched : bool
        Whether the initial states were given with a leading batch axis.
    """

    kind: ClassVar[str]
    outputs: ClassVar[tuple[str, ...]]
    batched: bool

    @property
    def system(self) -> str:
        """Name of the system, for the result file's ``meta``."""
        ...

    @property
    def batch(self) -> int:
        """Number of initial states."""
        ...

    def parameters(self) -> dict[str, object]:
        """Numerical parameters, for the result file's ``meta``."""
        ...


def _batched(array: np.ndarray, single_ndim: int, name: str) -> tuple[np.ndarray, bool]:
    """Return ``(array with a leading batch axis, whether the input had one)``."""
    if array.ndim == single_ndim:
        return array[None, ...].copy(), False
    if array.ndim == single_ndim + 1:
        if array.shape[0] == 0:
            raise InputError(f"{name} has an empty batch axis: give at least one state")
        return array.copy(), True
    raise InputError(f"{name} has {array.ndim} axes; give one state or a batch of states (one more leading axis)")


@dataclass
class RigidBodyProblem:
    """The free rigid body: ``dM/dt = M x Omega``, ``dR/dt = R hat(Omega)`` (250)–(251).

    Parameters
    ----------
    inertia : array_like, shape (3,)
        Principal moments ``I_i`` (validated; triangle-inequality violations warn).
    M0 : array_like, shape (3,) or (B, 3)
        Initial body angular momentum.
    R0 : array_like, shape (3, 3) or (B, 3, 3), optional
        Initial attitude (body to lab), default the identity (43).
    torque : dirac.flows.torques.Torque or sequence of 3 str, optional (keyword)
        External torque ``N`` in the body frame: ``dM/dt = M x Omega + N`` (Euler's
        equations with a torque), expressions in ``M_i``, ``Omega_i``, ``R_ij`` and ``t``.
    impulses : sequence of (t, [a, b, c]) or AngularImpulse, optional (keyword)
        Angular impulses (body frame): ``M`` jumps by ``[a, b, c]`` at time ``t >= 0``.

    Examples
    --------
    >>> problem = RigidBodyProblem([2.0, 1.0, 2 / 3], [0.4536, 0.0, 0.8912])  # doctest: +SKIP
    """

    inertia: np.ndarray
    M0: np.ndarray
    R0: np.ndarray | None = None
    torque: Torque | None = field(default=None, kw_only=True)
    impulses: tuple[AngularImpulse, ...] = field(default=(), kw_only=True)
    batched: bool = field(init=False, default=False)

    kind: ClassVar[str] = "rigid_body"
    system: ClassVar[str] = "rigid_body"
    outputs: ClassVar[tuple[str, ...]] = ("M", "R", "energy", "casimir", "lab_momentum", "work")

    def __post_init__(self) -> None:
        from dirac.flows.impulses import validate_impulses
        from dirac.rigidbody.inertia import validate_inertia, validate_momentum, validate_rotation

        if self.torque is not None:
            from dirac.flows.torques import Torque  # the expression parser: only for a torque

            if not isinstance(self.torque, Torque):
                self.torque = Torque(self.torque)
        self.impulses = validate_impulses(self.impulses)

        self.inertia = validate_inertia(self.inertia)
        moments = validate_array(self.M0, "M0", finite=False)  # finiteness: validate_momentum, per body
        self.M0, self.batched = _batched(moments, 1, "M0")
        for body in self.M0:
            validate_momentum(body)
        batch = self.M0.shape[0]
        if self.R0 is None:
            self.R0 = np.repeat(np.eye(3)[None], batch, axis=0)
        else:
            rotations = validate_array(self.R0, "R0", finite=False)  # finiteness: validate_rotation
            rotations, _ = _batched(rotations, 2, "R0")
            if rotations.shape[0] == 1 and batch > 1:
                rotations = np.repeat(rotations, batch, axis=0)
            if rotations.shape[0] != batch:
                raise InputError(f"R0 has {rotations.shape[0]} states but M0 has {batch}: give one R0 per M0")
            self.R0 = np.stack([validate_rotation(r) for r in rotations])

    @property
    def batch(self) -> int:
        """Number of initial states."""
        return int(self.M0.shape[0])

    @property
    def driven(self) -> bool:
        """Whether an external torque or an angular impulse acts (not a free flow)."""
        return self.torque is not None or bool(self.impulses)

    def parameters(self) -> dict[str, object]:
        """Numerical parameters for the result file's ``meta``."""
        return {"inertia": self.inertia.tolist(), **self._driving()}

    def _driving(self) -> dict[str, object]:
        """The torque and impulses for ``meta`` (nothing when there are none)."""
        driving: dict[str, object] = {}
        if self.torque is not None:
            driving["torque"] = list(self.torque.texts)
        if self.impulses:
            driving["impulses"] = [{"t": i.t, "angular_impulse": i.vector.tolist()} for i in self.impulses]
        return driving


@dataclass
class HeavyTopProblem(RigidBodyProblem):
    """A rigid body with a fixed point in a uniform gravity field (heavy top).

    ``H = sum_i M_i^2 / (2 I_i) + m g <chi, gamma>``, ``gamma = R^T e_z`` (the lab vertical
    seen from the body), ``chi`` the centre of mass in body coordinates relative to the
    fixed point. With the bracket (248)–(249) the equations are
    ``dM/dt = M x Omega + m g gamma x chi``, ``dR/dt = R hat(Omega)``.
    The Lagrange top has ``I_1 = I_2`` and ``chi`` on the third axis.

    Parameters
    ----------
    inertia, M0, R0
        As for :class:`RigidBodyProblem` (moments about the fixed point).
    mass_gravity : float
        ``m g`` (>= 0).
    center_of_mass : array_like, shape (3,)
        ``chi`` in body coordinates.
    """

    mass_gravity: float = 1.0
    center_of_mass: np.ndarray = field(default_factory=lambda: np.array([0.0, 0.0, 1.0]))

    kind: ClassVar[str] = "heavy_top"
    system: ClassVar[str] = "heavy_top"
    outputs: ClassVar[tuple[str, ...]] = ("M", "R", "energy", "lab_momentum_z", "work")

    def __post_init__(self) -> None:
        super().__post_init__()
        self.mass_gravity = validate_non_negative(self.mass_gravity, "mass_gravity", hint="the product m g")
        self.center_of_mass = validate_array(self.center_of_mass, "center_of_mass", (3,))

    @property
    def weight_vector(self) -> np.ndarray:
        """``m g chi`` (body frame)."""
        return self.mass_gravity * self.center_of_mass

    def parameters(self) -> dict[str, object]:
        return {
            "inertia": self.inertia.tolist(),
            "mass_gravity": self.mass_gravity,
            "center_of_mass": self.center_of_mass.tolist(),
            **self._driving(),
        }


@dataclass
class ConstrainedProblem:
    """A holonomically constrained mechanical system with initial positions and momenta (or velocities).

    A system with generalized forces (``Lagrangian(..., forces=...)``) gives a
    :class:`ForcedProblem` (without impulses): ``rattle-2/4`` then run as
    ``forced-rattle-2/4``, ``midpoint`` and the scipy methods on the forced Dirac field.

    Parameters
    ----------
    mechanics : dirac.Lagrangian or dirac.flows.mechanics.MechanicalSystem
        The system: a :class:`~dirac.model.lagrangian.Lagrangian` (compiled here with its
        default parameter values) or an already compiled ``MechanicalSystem``.
    q0 : array_like, shape (n,) or (B, n)
        Initial coordinates, on the constraint surface ``chi(q, 0) = 0``.
    p0 : array_like, shape (n,) or (B, n)
        Initial momenta, tangent: ``G(q) M(q)^{-1} p + d_t chi = 0`` (the third-stage
        constraints). Give ``p0`` or ``qdot0``.
    surface_tolerance : float
        Largest accepted constraint residual of the initial data (absolute, scaled by
        ``1 + |q|^2``).
    qdot0 : array_like, shape (n,) or (B, n), optional
        Initial velocities instead of ``p0`` (as ``q_dot`` in a scene): ``p0 = M(q0, 0) qdot0``.
    project : bool
        Put the initial data on the constraint surface first (as ``project = true`` in a
        scene): the closest point in the metric ``M`` (:meth:`MechanicalSystem.project`).

    Raises
    ------
    InputError
        Wrong shapes, non-finite values, neither or both of ``p0`` and ``qdot0``, or
        initial data off the constraint surface (:class:`OffSurfaceError`) without
        ``project=True``.
    """

    mechanics: MechanicalSystem | Lagrangian  # a MechanicalSystem once constructed
    q0: np.ndarray
    p0: np.ndarray | None = None
    surface_tolerance: float = 1e-9
    qdot0: np.ndarray | None = None
    project: bool = False
    batched: bool = field(init=False, default=False)

    kind: ClassVar[str] = "constrained"
    outputs: ClassVar[tuple[str, ...]] = ("q", "p", "q_dot", "energy", "constraint_residual")

    def __new__(cls, *args: object, **kwargs: object) -> ConstrainedProblem:
        """A system with generalized forces (a Lagrangian built with ``forces=``, or a forced
        ``MechanicalSystem``) gives a :class:`ForcedProblem`: the same problem, whose methods
        take the forces (``rattle-2/4``, ``midpoint``, ``auto``, the scipy methods, ...)."""
        if cls is ConstrainedProblem:
            system = args[0] if args else kwargs.get("mechanics")
            if bool(getattr(system, "is_forced", False)) or bool(getattr(system, "forced", False)):
                return super().__new__(ForcedProblem)
        return super().__new__(cls)

    def __post_init__(self) -> None:
        from dirac.model.lagrangian import Lagrangian

        mechanics = self.mechanics
        if isinstance(mechanics, Lagrangian):
            from dirac.flows.mechanics import MechanicalSystem, NotMechanicalError

            try:
                mechanics = MechanicalSystem.from_lagrangian(mechanics, with_forces=self.kind == "forced")
            except NotMechanicalError as exc:
                if not exc.road:
                    raise
                if self.kind == "forced":
                    raise NotMechanicalError(
                        f"{exc.reason}; forces and impulses are integrated for that form only") from None
                raise NotMechanicalError(exc.reason, road=PYTHON_DIRAC_FLOW_ROAD) from None
        if self.kind == "forced" and not getattr(mechanics, "forced", False):
            raise InputError(
                f"a ForcedProblem needs the forced kernels of {mechanics.name!r}: give the Lagrangian, or "
                "MechanicalSystem.from_lagrangian(lagrangian, with_forces=True)"
            )
        self.mechanics = mechanics
        n = mechanics.dimension
        if (self.p0 is None) == (self.qdot0 is None):
            raise InputError("give the initial momenta p0 or the initial velocities qdot0 (one of them), e.g. "
                             "ConstrainedProblem(system, q0=[0.6, -0.8], qdot0=[0.0, 0.0])")
        q0, self.batched = _batched(validate_array(self.q0, "initial q", finite=False), 1, "q")
        given, what = (self.p0, "p") if self.p0 is not None else (self.qdot0, "qdot")
        rates, _ = _batched(validate_array(given, f"initial {what}", finite=False), 1, what)
        for name, value in (("q", q0), (what, rates)):
            if value.shape[1] != n:
                raise InputError(f"initial {name} has {value.shape[1]} entries; the system has {n} coordinates")
            if not np.all(np.isfinite(value)):
                raise InputError(f"initial {name} has non-finite entries; give finite numbers")
        if q0.shape[0] != rates.shape[0]:
            raise InputError(f"{q0.shape[0]} initial q but {rates.shape[0]} initial {what}: give one {what} per q")
        p0 = rates if what == "p" else np.array([mechanics.mass_matrix(a) @ v for a, v in zip(q0, rates)])
        if self.project:
            pairs = [mechanics.project(a, b) for a, b in zip(q0, p0)]
            q0, p0 = np.array([a for a, _ in pairs]), np.array([b for _, b in pairs])
        names = mechanics.coordinate_names
        advice = "or pass project=True to put the data on the surface (the closest point in the metric M)"
        for b in range(q0.shape[0]):
            position, velocity = mechanics.residuals(q0[b], p0[b])
            scale = 1.0 + float(q0[b] @ q0[b])
            if np.any(np.abs(position) > self.surface_tolerance * scale):
                worst = int(np.argmax(np.abs(position)))
                raise OffSurfaceError(
                    f"initial q {dict(zip(names, q0[b].tolist()))} is off the constraint surface: constraint "
                    f"{worst + 1} = {position[worst]:.3g}",
                    f"give q with chi(q, 0) = 0, {advice}",
                )
            pscale = scale * (1.0 + float(p0[b] @ p0[b]))
            if np.any(np.abs(velocity) > self.surface_tolerance * np.sqrt(pscale)):
                worst = int(np.argmax(np.abs(velocity)))
                raise OffSurfaceError(
                    f"initial velocity is not tangent to the constraint surface: d(constraint {worst + 1})/dt = "
                    f"{velocity[worst]:.3g}",
                    f"give qdot0 (or p0) with d chi/dt = 0, {advice}",
                )
        self.q0, self.p0 = q0, p0
        self.qdot0 = None  # the state is (q0, p0) from here on

    @property
    def system(self) -> str:
        """Name of the mechanical system."""
        return self.mechanics.name

    @property
    def batch(self) -> int:
        """Number of initial states."""
        return int(self.q0.shape[0])

    def parameters(self) -> dict[str, object]:
        """Parameter values of the mechanical system, for the result file's ``meta``."""
        return dict(self.mechanics.parameter_values)



@dataclass(frozen=True)
class Impulse:
    """A generalized impulse ``J`` (Lamb's ``Q_r'``, the time integral of ``Q_r`` over a
    blow of vanishing duration) at time ``t``: ``p`` jumps by ``J`` projected so that the
    constraints' velocity stage still holds
    (:meth:`dirac.flows.mechanics.MechanicalSystem.apply_impulse`)."""

    t: float
    vector: np.ndarray


@dataclass
class ForcedProblem(ConstrainedProblem):
    """A constrained mechanical system with generalized forces ``Q(q, q_dot, t)`` and impulses.

    The forces come with the system (``Lagrangian.forces``); Lagrange's equations are
    ``d/dt dL/dq_dot - dL/dq = Q + G^T lambda``. Parameters as for
    :class:`ConstrainedProblem`, and

    Parameters
    ----------
    impulses : sequence of (t, {coordinate: value}) or Impulse
        Generalized impulses at times ``t > 0``; coordinates not named get 0. The methods
        land a step on each impulse time.

    Raises
    ------
    InputError
        As for :class:`ConstrainedProblem`; an impulse at ``t <= 0``, on an unknown
        coordinate or with a non-finite value.
    """

    impulses: tuple = ()

    kind: ClassVar[str] = "forced"
    outputs: ClassVar[tuple[str, ...]] = ("q", "p", "q_dot", "energy", "work", "constraint_residual")

    def __post_init__(self) -> None:
        super().__post_init__()
        self.impulses = tuple(sorted((self._impulse(item) for item in self.impulses), key=lambda i: i.t))

    def _impulse(self, item: object) -> Impulse:
        from dirac.flows.mechanics import MechanicalSystem
        from dirac.validate import did_you_mean

        mechanics = self.mechanics
        assert isinstance(mechanics, MechanicalSystem)  # converted by ConstrainedProblem.__post_init__

        if isinstance(item, Impulse):
            time, vector = item.t, item.vector
        else:
            if not isinstance(item, tuple) or len(item) != 2:
                raise InputError(f"an impulse must be (t, {{coordinate: value}}), not {item!r}")
            time, values = item
            names = mechanics.coordinate_names
            if not isinstance(values, dict):
                raise InputError(f"the impulse at t = {time} must be a table {{ {names[0]} = ... }}")
            for key in values:
                if key not in names:
                    raise InputError(
                        f"the impulse at t = {time} names {key!r}, which is not a coordinate"
                        f"{did_you_mean(str(key), names)}; coordinates: {', '.join(names)}"
                    )
            vector = np.array([values.get(n, 0.0) for n in names], dtype=float)
        from dirac.validate import validate_finite

        time = validate_finite(time, "impulse time")
        if not time > 0.0:
            raise InputError(f"an impulse at t = {time} is not after the start t = 0: give t > 0 "
                             "(a blow at the start is an initial velocity)")
        vector = np.asarray(vector, dtype=float)
        if vector.shape != (mechanics.dimension,) or not np.all(np.isfinite(vector)):
            raise InputError(f"the impulse at t = {time} must have {mechanics.dimension} finite entries")
        return Impulse(float(time), vector)
