"""dirac: constrained Hamiltonian mechanics.

The Dirac–Bergmann algorithm on a Lagrangian with holonomic constraints (multipliers as
dynamical variables), Dirac brackets, and structure-preserving flows; the flagship is the
free asymmetric rigid body, whose Dirac bracket is the Chetaev bracket.

Heavy dependencies (sympy, numba, scipy) load on first use of the names that need them,
and so does ``__version__`` (the installed distribution's version, read from its metadata).
Equation numbers such as (248) refer to A. A. Deriglazov, "Lagrangian and Hamiltonian
formulations of asymmetric rigid body, considered as a constrained system" (2024); see
docs/conventions.md and docs/references.md.
"""

from __future__ import annotations as _annotations

from dirac.errors import (
    AnalysisError,
    DiracError,
    DiracWarning,
    InconsistentSystemError,
    InputError,
    IntegrationError,
)
from dirac.lazy_exports import lazy_exports as _lazy_exports

#: Name of the distribution on the package index (the import name ``dirac`` is taken there).
_DISTRIBUTION = "dirac-mechanics"

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
    "ForcedProblem",
    "Solution",
    "load_scene",
    "write_results",
    "read_results",
    "plot",
    "TIME",
    "FieldTheory",
    "lattice",
    "load_field_theory",
]

#: public name -> module that defines it (imported on first access)
_LAZY: dict[str, str] = {
    "Lagrangian": "dirac.model.lagrangian",
    "load_system": "dirac.model.systems",
    "builtin_systems": "dirac.model.systems",
    "analyze": "dirac.fields.api",
    "integrate": "dirac.flows.integration",
    "RigidBodyProblem": "dirac.flows.problems",
    "HeavyTopProblem": "dirac.flows.problems",
    "ConstrainedProblem": "dirac.flows.problems",
    "ForcedProblem": "dirac.flows.problems",
    "Solution": "dirac.flows.solution",
    "load_scene": "dirac.io.scene",
    "write_results": "dirac.io.results",
    "read_results": "dirac.io.results",
    "plot": "dirac.plots.results",
    "TIME": "dirac.model.expressions",
    "FieldTheory": "dirac.fields.theory",
    "lattice": "dirac.fields.lattice",
    "load_field_theory": "dirac.fields.files",
}


def _installed_version() -> str:
    """Version of the installed distribution, or ``"0+unknown"`` when it is not installed."""
    from importlib.metadata import PackageNotFoundError, version

    try:
        return version(_DISTRIBUTION)
    except PackageNotFoundError:  # imported from a source tree that was never installed
        return "0+unknown"


__getattr__, __dir__ = _lazy_exports("dirac", globals(), _LAZY, computed={"__version__": _installed_version})
