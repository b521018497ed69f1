"""dirac: constrained Hamiltonian mechanics.

The Dirac–Bergmann algorithm on a Lagrangian with holonomic constraints (multipliers as
dynamical variables), Dirac brackets, and structure-preserving flows; the flagship is the
free asymmetric rigid body, whose Dirac bracket is the Chetaev bracket.

Heavy dependencies (sympy, numba, scipy) load on first use of the names that need them.
"""

from __future__ import annotations

from dirac.errors import (
    AnalysisError,
    DiracError,
    DiracWarning,
    InconsistentSystemError,
    InputError,
    IntegrationError,
)
from dirac.lazy_exports import lazy_exports

__all__ = [
    "DiracError",
    "InputError",
    "InconsistentSystemError",
    "AnalysisError",
    "IntegrationError",
    "DiracWarning",
    "Lagrangian",
    "load_system",
    "builtin_systems",
    "analyze",
    "integrate",
    "RigidBodyProblem",
    "HeavyTopProblem",
    "ConstrainedProblem",
    "Solution",
    "load_scene",
    "write_results",
    "read_results",
]

#: public name -> module that defines it (imported on first access)
_LAZY: dict[str, str] = {
    "Lagrangian": "dirac.model.lagrangian",
    "load_system": "dirac.model.systems",
    "builtin_systems": "dirac.model.systems",
    "analyze": "dirac.analysis.constraint_analysis",
    "integrate": "dirac.flows.integration",
    "RigidBodyProblem": "dirac.flows.problems",
    "HeavyTopProblem": "dirac.flows.problems",
    "ConstrainedProblem": "dirac.flows.problems",
    "Solution": "dirac.flows.solution",
    "load_scene": "dirac.io.scene",
    "write_results": "dirac.io.results",
    "read_results": "dirac.io.results",
}


__getattr__, __dir__ = lazy_exports("dirac", globals(), _LAZY)
