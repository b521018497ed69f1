"""Integration methods as small objects, and the registry of their names (CONTRACTS §7a).

A :class:`Method` is data plus one factory: its name, order, flags (``symplectic``,
``preserves_casimirs``), the problems it accepts, and :meth:`Method.start`, which
returns a :class:`Stepper` bound to one problem. Steppers hold the state and do the
mathematics of a step (or of a direct evaluation); they never loop over output times,
count CPU time or draw progress: :func:`dirac.flows.integrate` does that, once, for all.

Three kinds of stepper:

``fixed``
    ``step(n_steps, dt)`` advances by ``n_steps`` steps of size ``dt`` (the loop over
    the steps may run in compiled code).
``adaptive``
    ``advance_to(t)`` advances to time ``t`` with the method's own step control.
``exact``
    ``evaluate(times)`` returns the outputs at the given times, without time stepping.
"""

from __future__ import annotations

from collections.abc import Callable, Sequence
from dataclasses import dataclass, field

import numpy as np

from dirac.errors import InputError

__all__ = ["Method", "Stepper", "StepFailure", "METHODS", "register_method", "get_method", "method_names"]


class StepFailure(Exception):
    """Raised by a stepper when a step cannot be completed (e.g. Newton non-convergence).

    ``steps_done`` counts the steps completed in the current call before the failure; the
    stepper's state is that after those steps.
    """

    def __init__(self, message: str, steps_done: int = 0) -> None:
        super().__init__(message)
        self.steps_done = steps_done


class Stepper:
    """State and mathematics of one method on one problem (base class).

    Attributes
    ----------
    kind : {"fixed", "adaptive", "exact"}
    evaluations : int
        Vector-field (or sub-flow) evaluations so far.
    steps : int
        Steps taken so far (adaptive steppers count their accepted steps).
    """

    kind = "fixed"

    def __init__(self) -> None:
        self.evaluations = 0
        self.steps = 0

    def warm_up(self) -> None:
        """Compile the kernels (on a scratch copy of the state): nothing compiles later."""

    def step(self, n_steps: int, dt: float) -> None:  # pragma: no cover - interface
        raise NotImplementedError

    def advance_to(self, t: float) -> None:  # pragma: no cover - interface
        raise NotImplementedError

    def evaluate(self, times: np.ndarray) -> dict[str, np.ndarray]:  # pragma: no cover - interface
        raise NotImplementedError

    def observe(self) -> dict[str, np.ndarray]:  # pragma: no cover - interface
        """The requested outputs at the current state, each with a leading batch axis."""
        raise NotImplementedError

    def drift(self) -> float:
        """Largest violation of a structural constraint of the current state (0 if none)."""
        return 0.0

    def finite(self) -> bool:  # pragma: no cover - interface
        """Whether the current state is finite."""
        raise NotImplementedError


@dataclass(frozen=True)
class Method:
    """An integration method: data and a factory of steppers.

    Attributes
    ----------
    name : str
        Registry name (CONTRACTS §7a), e.g. ``"lie-poisson-4"``.
    order : int
        Classical order (0 for ``exact``: no discretisation error).
    kind : {"fixed", "adaptive", "exact"}
    problems : tuple of str
        Problem kinds accepted: ``"rigid_body"``, ``"heavy_top"``, ``"constrained"``.
    symplectic : bool
        Symplectic (for constrained systems: on the constraint manifold), or Poisson for a
        Lie–Poisson system.
    preserves_casimirs : bool
        Keeps ``|M|^2`` (and ``R^T R = 1``) to round-off.
    description : str
        One line for ``dirac run --help``.
    reference : str
        Where the method comes from.
    factory : callable
        ``factory(method, problem, outputs, options) -> Stepper``.
    """

    name: str
    order: int
    kind: str
    problems: tuple[str, ...]
    symplectic: bool
    preserves_casimirs: bool
    description: str
    reference: str
    factory: Callable[..., Stepper] = field(repr=False, compare=False)
    data: object = field(default=None, repr=False, compare=False)

    def accepts(self, problem_kind: str) -> bool:
        """Whether this method integrates problems of the given kind."""
        return problem_kind in self.problems

    def start(self, problem: object, outputs: Sequence[str], options: dict[str, object]) -> Stepper:
        """A stepper of this method bound to ``problem`` (initial state copied)."""
        return self.factory(self, problem, tuple(outputs), dict(options))


#: name -> Method; filled by the method modules (see :func:`_load_all`).
METHODS: dict[str, Method] = {}


def register_method(method: Method) -> Method:
    """Add ``method`` to :data:`METHODS` (names are unique)."""
    if method.name in METHODS:
        raise ValueError(f"method {method.name!r} registered twice")
    METHODS[method.name] = method
    return method


_LOADED = False


def _load_all() -> None:
    global _LOADED
    if _LOADED:
        return
    _LOADED = True
    import dirac.flows.methods.exact  # noqa: F401
    import dirac.flows.methods.heavy_top  # noqa: F401
    import dirac.flows.methods.lie_poisson  # noqa: F401
    import dirac.flows.methods.midpoint  # noqa: F401
    import dirac.flows.methods.rattle  # noqa: F401
    import dirac.flows.methods.scipy_rk  # noqa: F401


#: The names every user sees first (CONTRACTS §7a); others are extras.
CONTRACT_NAMES = (
    "auto", "exact", "lie-poisson-2", "lie-poisson-4", "lie-poisson-6", "lie-poisson-8",
    "rattle-2", "rattle-4", "midpoint", "scipy-RK45", "scipy-DOP853",
)


def method_names() -> list[str]:
    """Every method name, ``auto`` and the contract names first."""
    _load_all()
    extras = sorted(n for n in METHODS if n not in CONTRACT_NAMES)
    return [*CONTRACT_NAMES, *extras]


def get_method(name: str) -> Method:
    """The method called ``name``.

    Raises
    ------
    InputError
        Unknown name; the message lists the known names.
    """
    _load_all()
    if isinstance(name, Method):
        return name
    if name not in METHODS:
        raise InputError(f"unknown method {name!r}; choose one of: {', '.join(method_names())}")
    return METHODS[name]
