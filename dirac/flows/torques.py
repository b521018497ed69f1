"""External torques and angular impulses on a rigid body or heavy top.

Euler's equations with a torque ``N`` given in the body frame (Euler; Landau & Lifshitz,
Mechanics §36)::

    Omega = I^{-1} M,   dM/dt = M x Omega + N,   dR/dt = R hat(Omega)

(plus the gravity torque ``gamma x m g chi`` of a heavy top). ``N`` is an expression in
``M_1..M_3``, ``Omega_1..Omega_3``, ``R_11..R_33`` and ``t``, parsed safely by
:func:`dirac.model.expressions.parse_expression` and compiled once by :mod:`dirac.codegen`
(:mod:`dirac.flows.torque_kernels`); sympy never runs in a time step.

The work done by the torque, ``W(t) = ∫ N·Omega dt``, makes ``E - W`` a constant of the
exact motion: ``dE/dt = Omega·dM/dt (+ dV/dt) = Omega·N`` since ``Omega·(M x Omega) = 0``
and the gravity part is conservative. An angular impulse ``J`` (body frame) at time ``t_J``
makes ``M`` jump by ``J``; its work is the jump of the kinetic energy,
``E(M + J) - E(M)`` (the limit of ``∫ N·Omega dt`` over a short, strong torque); the
impulses are in :mod:`dirac.flows.impulses` (no sympy: a free body never imports it).
"""

from __future__ import annotations

import ast
from collections.abc import Sequence
from functools import cached_property
from types import ModuleType

import numpy as np
import sympy

from dirac.errors import InputError
from dirac.flows.torque_kernels import torque_module, torque_module_source
from dirac.model.expressions import ALLOWED_CONSTANTS, TIME, parse_expression
from dirac.validate import unknown_name_error

__all__ = ["Torque", "TORQUE_SYMBOLS", "torque_symbols"]


def torque_symbols() -> dict[str, sympy.Symbol]:
    """Name -> symbol of every variable a torque may use (``t`` besides: :data:`TIME`)."""
    names = [f"M_{i}" for i in (1, 2, 3)] + [f"Omega_{i}" for i in (1, 2, 3)]
    names += [f"R_{i}{j}" for i in (1, 2, 3) for j in (1, 2, 3)]
    return {name: sympy.Symbol(name, real=True) for name in names}


#: The variables of a torque expression, by name.
TORQUE_SYMBOLS: dict[str, sympy.Symbol] = torque_symbols()
_MOMENTUM = tuple(TORQUE_SYMBOLS[f"M_{i}"] for i in (1, 2, 3))
_RATE = tuple(TORQUE_SYMBOLS[f"Omega_{i}"] for i in (1, 2, 3))
_ATTITUDE = tuple(TORQUE_SYMBOLS[f"R_{i}{j}"] for i in (1, 2, 3) for j in (1, 2, 3))


def _check_names(text: str, where: str) -> None:
    """Refuse a name that is not a torque variable, ``t``, a constant or a function, with
    the closest known names ("did you mean")."""
    try:
        tree = ast.parse(text.strip(), mode="eval")
    except SyntaxError:
        return  # parse_expression reports it
    called = {id(node.func) for node in ast.walk(tree) if isinstance(node, ast.Call)}
    known = [*TORQUE_SYMBOLS, TIME.name, *ALLOWED_CONSTANTS]
    for node in ast.walk(tree):
        if isinstance(node, ast.Name) and id(node) not in called and node.id not in known:
            raise unknown_name_error("name", node.id, known, where,
                                     hint="a torque is an expression in M_1..M_3, Omega_1..Omega_3, R_11..R_33, t "
                                     "and numbers")


class Torque:
    """A torque ``N`` in the body frame: three expressions, parsed and classified.

    Parameters
    ----------
    components : sequence of 3 str (or numbers, or sympy expressions)
        ``N_1, N_2, N_3`` in ``M_i``, ``Omega_i``, ``R_ij``, ``t`` and numbers.
    source : str
        Where the torque comes from, put in front of error messages (e.g. a scene file).

    Attributes
    ----------
    texts : tuple of str
        The components as given (printed by sympy for sympy input).
    expressions : tuple of sympy.Expr
    depends_on_momentum : bool
        ``N`` uses ``M`` or ``Omega``: the kick ``dM/dt = N`` with ``R`` and ``t`` frozen is
        then solved by the implicit midpoint rule; otherwise it is exact, ``M += h N``.
    depends_on_attitude, depends_on_time : bool

    Raises
    ------
    InputError
        Not three components, an unknown name ("did you mean"), a syntax error.
    """

    def __init__(self, components: Sequence[object], source: str = "") -> None:
        where = f"{source}: [forces] torque" if source else "torque"
        if isinstance(components, (str, bytes)) or not isinstance(components, Sequence) or len(components) != 3:
            count = len(components) if isinstance(components, Sequence) and not isinstance(components, str) else 1
            raise InputError(
                f"{where} must be three expressions [N_1, N_2, N_3] (the body-frame components), got {count}; "
                'e.g. torque = ["-0.1*Omega_1", "-0.1*Omega_2", "-0.1*Omega_3"]'
            )
        expressions = []
        texts = []
        for k, component in enumerate(components, start=1):
            label = f"{where} component {k}"
            if isinstance(component, sympy.Basic):
                expression = sympy.sympify(component)
                unknown = sorted(s.name for s in expression.free_symbols
                                 if s not in TORQUE_SYMBOLS.values() and s != TIME)
                if unknown:
                    raise unknown_name_error("name", unknown[0], [*TORQUE_SYMBOLS, TIME.name], label)
                texts.append(str(expression))
            else:
                if isinstance(component, str):
                    _check_names(component, label)
                expression = parse_expression(component, TORQUE_SYMBOLS, what=label, time=TIME)  # type: ignore[arg-type]
                texts.append(str(component).strip())
            expressions.append(sympy.sympify(expression))
        self.texts: tuple[str, ...] = tuple(texts)
        self.expressions: tuple[sympy.Expr, ...] = tuple(expressions)
        used: set[sympy.Basic] = set().union(*(e.free_symbols for e in self.expressions))
        self.depends_on_momentum = bool(used & set(_MOMENTUM + _RATE))
        self.depends_on_attitude = bool(used & set(_ATTITUDE))
        self.depends_on_time = TIME in used

    def __repr__(self) -> str:
        return f"Torque({list(self.texts)!r})"

    @property
    def kick(self) -> str:
        """``"exact"`` (``N`` free of ``M``, ``Omega``) or ``"midpoint"``."""
        return "midpoint" if self.depends_on_momentum else "exact"

    @cached_property
    def kernels(self) -> ModuleType:
        """The compiled kick and step loops of this torque (:mod:`dirac.flows.torque_kernels`)."""
        return torque_module(torque_module_source(self.expressions, _MOMENTUM, _RATE, _ATTITUDE, TIME))

    @cached_property
    def _scalar(self):
        from dirac.codegen import scalar_function

        symbols = [*_MOMENTUM, *_RATE, *_ATTITUDE, TIME]
        return scalar_function(symbols, list(self.expressions))

    def evaluate(self, M: np.ndarray, R: np.ndarray, t: float, inertia: np.ndarray) -> np.ndarray:
        """``N(M, Omega = I^{-1} M, R, t)`` for one state (plain Python; baselines, tests)."""
        M = np.asarray(M, dtype=float)
        omega = M / np.asarray(inertia, dtype=float)
        values = self._scalar(*M, *omega, *np.asarray(R, dtype=float).ravel(), float(t))
        return np.asarray(values, dtype=float).reshape(3)
