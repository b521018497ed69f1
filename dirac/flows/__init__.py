"""Numerical flows: problems, methods, the one ``integrate`` loop and its solutions.

Scene and result files are read and written by :mod:`dirac.io` (``dirac.load_scene``,
``dirac.write_results``, ``dirac.read_results``), which builds on this package.

Public names (imported on first use, so ``import dirac.flows`` stays cheap):
:func:`integrate`, :class:`Solution`, :class:`RigidBodyProblem`, :class:`HeavyTopProblem`,
:class:`ConstrainedProblem`, :class:`ForcedProblem` (forces and impulses), :class:`MechanicalSystem`, :class:`AnalysedSystem`,
:class:`AnalysedProblem`, :class:`Problem` (what they have in common), :func:`get_method`,
:func:`method_names`, :data:`METHODS`.
"""

from __future__ import annotations

from importlib import import_module
from typing import Any

_LAZY = {
    "integrate": "dirac.flows.integration",
    "IntegrationInterrupted": "dirac.flows.integration",
    "Solution": "dirac.flows.solution",
    "RigidBodyProblem": "dirac.flows.problems",
    "HeavyTopProblem": "dirac.flows.problems",
    "ConstrainedProblem": "dirac.flows.problems",
    "ForcedProblem": "dirac.flows.problems",
    "Impulse": "dirac.flows.problems",
    "MechanicalSystem": "dirac.flows.mechanics",
    "AnalysedSystem": "dirac.flows.analysed",
    "AnalysedProblem": "dirac.flows.analysed",
    "get_method": "dirac.flows.methods.registry",
    "method_names": "dirac.flows.methods.registry",
    "METHODS": "dirac.flows.methods.registry",
    "Problem": "dirac.flows.problems",
}

__all__ = sorted(_LAZY)


def __getattr__(name: str) -> Any:
    module = _LAZY.get(name)
    if module is None:
        raise AttributeError(f"module 'dirac.flows' has no attribute {name!r}")
    value = getattr(import_module(module), name)
    globals()[name] = value
    return value


def __dir__() -> list[str]:
    return sorted(set(globals()) | set(_LAZY))
