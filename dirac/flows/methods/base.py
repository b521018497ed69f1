"""Integration methods as small objects: :class:`Method`, :class:`Stepper`, :class:`StepFailure`.

A :class:`Method` is data plus one stepper factory per problem kind it accepts: its name,
order, flags (``symplectic``, ``preserves_casimirs``) and :meth:`Method.start`, which
returns a :class:`Stepper` bound to one problem. Steppers hold the state and do the
mathematics of a step (or of a direct evaluation); they never loop over output times,
count CPU time or draw progress: :func:`dirac.flows.integrate` does that, once, for all.
The methods themselves are listed in :mod:`dirac.flows.methods.registry`.

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

from collections.abc import Callable, Mapping, Sequence
from dataclasses import dataclass, field, replace
from types import MappingProxyType
from typing import TYPE_CHECKING, Any

import numpy as np

from dirac.errors import InputError

if TYPE_CHECKING:
    from dirac.flows.problems import Problem

__all__ = ["Method", "Stepper", "StepFailure", "StepperFactory"]


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


#: ``factory(method, problem, outputs, options) -> Stepper`` for one problem kind.
StepperFactory = Callable[["Method", Any, tuple[str, ...], dict[str, object]], Stepper]


@dataclass(frozen=True)
class Method:
    """An integration method: data and one stepper factory per accepted problem kind.

    Attributes
    ----------
    name : str
        Registry name, e.g. ``"lie-poisson-4"`` (``dirac run --help`` lists them).
    order : int
        Classical order (0 for ``exact``: no discretisation error).
    kind : {"fixed", "adaptive", "exact"}
    symplectic : bool
        Symplectic (for constrained systems: on the constraint manifold), or Poisson for a
        Lie–Poisson system.
    preserves_casimirs : bool
        Keeps ``|M|^2`` (and ``R^T R = 1``) to round-off.
    description : str
        One line for ``dirac run --help``.
    reference : str
        Where the method comes from.
    factories : mapping of str to callable
        Problem kind (``"rigid_body"``, ``"heavy_top"``, ``"constrained"``,
        ``"analysed"``) -> ``factory(method, problem, outputs, options) -> Stepper``.
    data : object
        What the factories need besides the problem, e.g. composition coefficients.
    """

    name: str
    order: int
    kind: str
    symplectic: bool
    preserves_casimirs: bool
    description: str
    reference: str
    factories: Mapping[str, StepperFactory] = field(repr=False, compare=False)
    data: object = field(default=None, repr=False, compare=False)

    def __post_init__(self) -> None:
        if not self.factories:
            raise ValueError(f"method {self.name!r} accepts no problem kind")
        object.__setattr__(self, "factories", MappingProxyType(dict(self.factories)))

    @property
    def problems(self) -> tuple[str, ...]:
        """The problem kinds accepted, in the order the factories were given."""
        return tuple(self.factories)

    def accepts(self, problem_kind: str) -> bool:
        """Whether this method integrates problems of the given kind."""
        return problem_kind in self.factories

    def with_factories(self, factories: Mapping[str, StepperFactory]) -> Method:
        """This method, also accepting the kinds of ``factories`` (given after its own)."""
        return replace(self, factories={**self.factories, **factories})

    def start(self, problem: Problem, outputs: Sequence[str], options: Mapping[str, object]) -> Stepper:
        """A stepper of this method bound to ``problem`` (initial state copied).

        Raises
        ------
        InputError
            The method does not accept the problem's kind; the message names both and the
            kinds it accepts.
        """
        kind = problem.kind
        factory = self.factories.get(kind)
        if factory is None:
            raise InputError(
                f"method {self.name!r} cannot integrate a problem of kind {kind!r}; it accepts: "
                f"{', '.join(self.problems)}"
            )
        return factory(self, problem, tuple(outputs), dict(options))
