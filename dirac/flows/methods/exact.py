"""``exact``: the exact free rigid-body flow evaluated directly at the output times.

``M(t)`` in Jacobi elliptic functions and ``R(t)`` with an elliptic integral of the third
kind (Jacobi; Celledoni, Fassò, Säfström & Zanna, SIAM J. Sci. Comput. 30 (2008)), from
:class:`dirac.rigidbody.exact.ExactRigidBodyFlow`. There is no time stepping: the cost
depends on the number of samples only, not on ``t_end``; when no output needs ``R`` only
``M(t)`` is evaluated.
"""

from __future__ import annotations

import numpy as np

from dirac.flows.methods.base import Method, Stepper
from dirac.flows.methods.rigid_body_stepper import exact_flow, needs_attitude, rigid_body_outputs

__all__ = ["ExactStepper", "METHODS"]


class ExactStepper(Stepper):
    """Evaluates the exact flow of each initial state at the requested times."""

    kind = "exact"

    def __init__(self, problem, outputs: tuple[str, ...]) -> None:
        super().__init__()
        self.problem = problem
        self.outputs = outputs
        self.with_R = needs_attitude(outputs)
        self.flows = [exact_flow(problem.inertia, M, R) for M, R in zip(problem.M0, problem.R0)]

    def warm_up(self) -> None:
        flow = self.flows[0]
        flow.state(np.array([0.0])) if self.with_R else flow.M(np.array([0.0]))

    def evaluate(self, times: np.ndarray) -> dict[str, np.ndarray]:
        times = np.asarray(times, dtype=float)
        n, batch = times.shape[0], len(self.flows)
        M = np.empty((n, batch, 3))
        R = np.empty((n, batch, 3, 3)) if self.with_R else None
        for b, flow in enumerate(self.flows):
            if R is not None:  # with_R
                M[:, b], R[:, b] = flow.state(times)
            else:
                M[:, b] = flow.M(times)
        self.evaluations += n * batch
        flat_M = M.reshape(n * batch, 3)
        flat_R = R.reshape(n * batch, 3, 3) if R is not None else None
        values = rigid_body_outputs(self.outputs, flat_M, flat_R, np.asarray(self.problem.inertia))
        return {name: value.reshape((n, batch) + value.shape[1:]) for name, value in values.items()}


def _factory(method: Method, problem, outputs, options) -> Stepper:
    return ExactStepper(problem, outputs)


#: The one method of this family.
METHODS: tuple[Method, ...] = (
    Method(
        name="exact",
        order=0,
        kind="exact",
        symplectic=True,
        preserves_casimirs=True,
        description="free rigid body: exact flow (Jacobi elliptic functions, elliptic integral of the 3rd kind), no time steps",
        reference="Jacobi; Celledoni, Fasso, Safstrom & Zanna, SIAM J. Sci. Comput. 30 (2008)",
        factories={"rigid_body": _factory},
    ),
)
