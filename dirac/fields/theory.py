"""A classical field theory given by its Lagrangian density.

A :class:`FieldTheory` holds real fields ``phi_a(t, x)`` on a flat space with the
spatial directions ``space`` (any number, none included), and a Lagrangian density
``L(phi, d_t phi, d_j phi)`` in the fields and their **first** derivatives, written
``A1_t`` (time) and ``A0_x`` (along ``x``). Higher derivatives are not taken: a density
with second derivatives must be rewritten with auxiliary fields first. The action is
``S = int dt d^d x L`` (Henneaux–Teitelboim, *Quantization of Gauge Systems*;
Sundermeyer, *Constrained Dynamics*).

Optional holonomic constraints ``chi(phi) = 0`` hold at every point (the O(3) sigma
model's ``phi . phi = 1``); they are imposed on a lattice (:func:`dirac.fields.lattice.lattice`).
The analysis (:func:`dirac.fields.modes.analyze_field_theory`, or :func:`dirac.analyze`)
goes mode by mode for densities quadratic with constant coefficients.
"""

from __future__ import annotations

import ast
import keyword
import re
from collections.abc import Iterable, Mapping, Sequence
from dataclasses import dataclass, field
from typing import Any

import sympy

from dirac.errors import InputError, warn
from dirac.model.expressions import parse_expression
from dirac.validate import did_you_mean, is_real_number

__all__ = ["FieldTheory", "TIME_DIRECTION", "derivative_name"]

#: the suffix of a time derivative: ``A1_t``
TIME_DIRECTION = "t"

_IDENTIFIER = re.compile(r"^[A-Za-z][A-Za-z0-9]*$")


def derivative_name(field_name: str, direction: str) -> str:
    """``("A1", "x")`` -> ``"A1_x"``; ``direction`` is ``"t"`` or a spatial direction."""
    return f"{field_name}_{direction}"


def _names_in(text: str) -> list[str]:
    """The names an expression uses (for the messages on derivatives), empty on a syntax error."""
    try:
        tree = ast.parse(text.strip(), mode="eval")
    except SyntaxError:
        return []
    return [node.id for node in ast.walk(tree) if isinstance(node, ast.Name)]


@dataclass(frozen=True)
class FieldTheory:
    """Real fields on ``space`` with a Lagrangian density in the fields and first derivatives.

    Build one with :meth:`from_strings` or :meth:`from_sympy`, which validate the input.

    Parameters
    ----------
    name
        Short name of the theory.
    space
        Names of the spatial directions (``("x", "y", "z")``; ``()`` for none).
    fields
        The field symbols (real), in order.
    density
        The Lagrangian density, a real sympy expression in the fields, the derivative
        symbols (:meth:`derivative`) and the parameters.
    parameters
        Parameter symbol -> default value (``None``: none).
    constraints
        Holonomic constraints ``chi(phi) = 0`` at every point (fields and parameters only).
    description
        One line on the theory.
    """

    name: str
    space: tuple[str, ...]
    fields: tuple[sympy.Symbol, ...]
    density: sympy.Expr
    parameters: Mapping[sympy.Symbol, float | None] = field(default_factory=dict)
    constraints: tuple[sympy.Expr, ...] = ()
    description: str = ""

    # ------------------------------------------------------------------ names
    @property
    def directions(self) -> tuple[str, ...]:
        """``("t", *space)``: the directions of the first derivatives."""
        return (TIME_DIRECTION, *self.space)

    def derivative(self, field_symbol: sympy.Symbol | str, direction: str) -> sympy.Symbol:
        """The symbol of ``d_direction field`` (``A1_t``, ``A0_x``)."""
        name = field_symbol if isinstance(field_symbol, str) else field_symbol.name
        return sympy.Symbol(derivative_name(name, direction), real=True)

    @property
    def field_names(self) -> list[str]:
        return [f.name for f in self.fields]

    @property
    def variables(self) -> dict[str, sympy.Symbol]:
        """Name -> symbol of every field and first derivative."""
        out = {f.name: f for f in self.fields}
        for f in self.fields:
            for d in self.directions:
                s = self.derivative(f, d)
                out[s.name] = s
        return out

    @property
    def parameter_symbols(self) -> dict[str, sympy.Symbol]:
        return {p.name: p for p in self.parameters}

    def fix(self, **values: float) -> FieldTheory:
        """The theory with some parameters replaced by numbers (exact rationals)."""
        symbols = self.parameter_symbols
        substitution = {}
        remaining = dict(self.parameters)
        for label, value in values.items():
            if label not in symbols:
                raise InputError(f"unknown parameter {label!r}{did_you_mean(label, symbols)} of {self.name!r}; "
                                 f"parameters: {', '.join(symbols) or '(none)'}")
            substitution[symbols[label]] = sympy.Rational(repr(float(value)))
            remaining.pop(symbols[label])
        return FieldTheory(self.name, self.space, self.fields, self.density.subs(substitution), remaining,
                           tuple(c.subs(substitution) for c in self.constraints), self.description)

    # ------------------------------------------------------------------ construction
    @classmethod
    def from_strings(
        cls,
        name: str,
        space: Sequence[str],
        fields: Sequence[str],
        density: str,
        parameters: Mapping[str, float | None] | None = None,
        constraints: Iterable[str] = (),
        description: str = "",
    ) -> FieldTheory:
        """A theory from text, as in a system file's ``[field]`` table (docs/field_theories.md).

        Names in ``density``: the fields, their first derivatives ``<field>_t`` and
        ``<field>_<direction>`` for each direction of ``space``, and the parameters.

        Examples
        --------
        >>> kg = FieldTheory.from_strings("klein_gordon", ["x"], ["phi"],
        ...     "phi_t**2/2 - phi_x**2/2 - m**2*phi**2/2", parameters={"m": 1.0})
        >>> kg.density
        -m**2*phi**2/2 + phi_t**2/2 - phi_x**2/2

        Raises
        ------
        InputError
            For malformed names, an unknown name (with the closest known names), a
            derivative along a direction not in ``space``, a higher derivative, or a
            density that is not real.
        """
        space_names, field_names, parameters = _checked_names(name, space, fields, parameters)
        theory_fields = tuple(sympy.Symbol(f, real=True) for f in field_names)
        params = {sympy.Symbol(p, real=True): v for p, v in parameters.items()}
        shell = cls(name, space_names, theory_fields, sympy.Integer(0), params)
        names = {**shell.variables, **shell.parameter_symbols}
        if not isinstance(density, str):
            raise InputError(f"the density of {name!r} must be a string expression")
        _check_derivatives(density, shell, "density")
        expr = parse_expression(density, names, what="density",
                                unknown_hint="if it is a parameter, add it to parameters; if a field, to fields")
        if isinstance(constraints, str):
            raise InputError("constraints must be a list of expressions, e.g. ['n1**2 + n2**2 + n3**2 - 1']")
        positions = {**{f.name: f for f in theory_fields}, **shell.parameter_symbols}
        refused = {s: "a constraint holds at every point and may use the fields and parameters only, not their "
                   "derivatives" for s in shell.variables if s not in positions}
        chis = tuple(parse_expression(text, positions, what=f"constraint {k}", refused=refused)
                     for k, text in enumerate(list(constraints), start=1))
        return cls._checked(name, space_names, theory_fields, expr, params, chis, description)

    @classmethod
    def from_sympy(
        cls,
        name: str,
        space: Sequence[str],
        fields: Sequence[sympy.Symbol | str],
        density: sympy.Expr,
        parameters: Mapping[sympy.Symbol | str, float | None] | None = None,
        constraints: Iterable[sympy.Expr] = (),
        description: str = "",
    ) -> FieldTheory:
        """A theory from sympy expressions.

        The density uses symbols named as in :meth:`from_strings` (``A1_t``, ``A0_x``;
        any assumptions: they are matched by name), or undefined functions of
        ``(t, *space)`` with their first derivatives (``A1(t, x).diff(x)``).
        ``parameters=None`` makes every other symbol a parameter without a value.
        """
        field_names = [f if isinstance(f, str) else getattr(f, "name", str(f)) for f in fields]
        density = sympy.sympify(density)
        chis = [sympy.sympify(c) for c in constraints]
        density, chis = _plain(density, chis, field_names, [TIME_DIRECTION, *space])
        known = set(field_names) | {derivative_name(f, d) for f in field_names for d in [TIME_DIRECTION, *space]}
        used = sorted({s.name for e in [density, *chis] for s in e.free_symbols})
        probe = cls(name, tuple(space), tuple(sympy.Symbol(f, real=True) for f in field_names), sympy.Integer(0), {})
        _check_derivatives(str(density), probe, "density", names=[u for u in used if u not in known])
        if parameters is None:
            free = set().union(*(e.free_symbols for e in [density, *chis]))
            parameters = {s.name: None for s in sorted(free, key=lambda s: s.name) if s.name not in known}
        plain_parameters = {(p if isinstance(p, str) else p.name): v for p, v in parameters.items()}
        space_names, field_names, plain_parameters = _checked_names(name, space, field_names, plain_parameters)
        theory_fields = tuple(sympy.Symbol(f, real=True) for f in field_names)
        params = {sympy.Symbol(p, real=True): v for p, v in plain_parameters.items()}
        shell = cls(name, space_names, theory_fields, sympy.Integer(0), params)
        names = {**shell.variables, **shell.parameter_symbols}
        by_name = {}
        for e in [density, *chis]:
            for s in e.free_symbols:
                if s.name not in names:
                    hint = did_you_mean(s.name, names)
                    raise InputError(f"the density of {name!r} uses the unknown name {s.name!r}{hint}; "
                                     f"the names allowed are: {', '.join(sorted(names))}")
                by_name[s] = names[s.name]
        expr = density.xreplace(by_name)
        return cls._checked(name, space_names, theory_fields, expr, params,
                            tuple(c.xreplace(by_name) for c in chis), description)

    @classmethod
    def _checked(cls, name, space, fields, density, params, constraints, description) -> FieldTheory:
        theory = cls(name, space, fields, density, params, constraints, description)
        if density == 0:
            raise InputError(f"the density of {name!r} is zero: give L(phi, d phi)")
        imaginary = sympy.expand(sympy.im(sympy.expand(density)))
        if imaginary != 0:
            raise InputError(
                f"the density of {name!r} is not real (imaginary part {imaginary}): a Lagrangian density of real "
                "fields is real; write a complex field as two real fields"
            )
        for chi in constraints:
            if chi == 0 or not (chi.free_symbols & set(fields)):
                raise InputError(f"constraint {chi} of {name!r} involves no field")
        used = set(density.free_symbols).union(*(c.free_symbols for c in constraints))
        variables = theory.variables
        for f in fields:
            mine = {f} | {variables[derivative_name(f.name, d)] for d in theory.directions}
            if not mine & used:
                warn(f"field {f.name!r} of {name!r} appears nowhere in the density or the constraints: it is "
                     "arbitrary (a pure gauge direction); remove it from fields if it is a slip")
        return theory

    def __repr__(self) -> str:
        return (f"<FieldTheory {self.name!r}: fields {', '.join(self.field_names)} on "
                f"{', '.join(self.space) or 'no spatial directions'}>")


def _checked_names(name: Any, space: Any, fields: Any, parameters: Any) -> tuple[tuple[str, ...], list[str], dict]:
    if not isinstance(name, str) or not name.strip():
        raise InputError("the field theory needs a name")
    if isinstance(space, str) or not isinstance(space, Sequence):
        raise InputError(f"space of {name!r} must be a list of direction names, e.g. [\"x\", \"y\", \"z\"] ([] for none)")
    if isinstance(fields, str) or not isinstance(fields, Sequence) or not fields:
        raise InputError(f"fields of {name!r} must be a non-empty list of names, e.g. [\"A0\", \"A1\"]")
    if parameters is not None and not isinstance(parameters, Mapping):
        raise InputError(f"parameters of {name!r} must be a mapping name -> value, e.g. {{\"m\": 1.0}}")
    parameters = dict(parameters or {})
    for d in space:
        if not isinstance(d, str) or not _IDENTIFIER.match(d) or d == TIME_DIRECTION:
            raise InputError(f"spatial direction {d!r} of {name!r} is not a valid name (letters and digits, not 't', "
                             "which is time)")
    for f in [*fields, *parameters]:
        if not isinstance(f, str) or not re.match(r"^[A-Za-z][A-Za-z0-9_]*$", f) or keyword.iskeyword(f):
            raise InputError(f"name {f!r} of {name!r} is not a valid name: use letters, digits and '_'")
    for f in fields:
        if "_" in f:
            raise InputError(f"field name {f!r} of {name!r} has '_', which marks derivatives (A1_x): use letters "
                             "and digits, e.g. h11")
    names = [*space, *fields, *parameters]
    twice = sorted({n for n in names if names.count(n) > 1})
    if twice:
        raise InputError(f"name(s) {', '.join(twice)} of {name!r} used twice among space, fields and parameters")
    generated = {f"k_{d}" for d in space} | {f"p_{f}" for f in fields}
    clash = sorted(set(parameters) & generated)
    if clash:
        raise InputError(f"parameter name(s) {', '.join(clash)} of {name!r} are generated names (wave vector k_<x>, "
                         "momenta p_<field>): rename them")
    for p, v in parameters.items():
        if v is not None and not is_real_number(v):
            raise InputError(f"parameter {p!r} = {v!r} of {name!r} is not a number")
    return tuple(space), list(fields), parameters


def _check_derivatives(text: str, theory: FieldTheory, what: str, names: Iterable[str] | None = None) -> None:
    """Clear errors for ``A1_w`` (an undeclared direction) and ``A1_xx`` (a higher derivative)
    among the names ``text`` uses (or ``names``, for sympy input)."""
    known = set(theory.variables) | set(theory.parameter_symbols)
    for used in (_names_in(text) if names is None else names):
        if used in known or "_" not in used:
            continue
        base, _, suffix = used.partition("_")
        if base not in theory.field_names:
            continue
        if len(suffix) > 1 and all(ch in theory.directions for ch in suffix):
            raise InputError(
                f"{what} {text!r}: {used!r} is a derivative of order {len(suffix)}; only first derivatives are "
                f"taken ({', '.join(derivative_name(base, d) for d in theory.directions)}): introduce an auxiliary "
                "field for a higher derivative"
            )
        raise InputError(
            f"{what} {text!r}: {used!r} is a derivative of {base!r} along {suffix!r}, which is not a declared "
            f"direction{did_you_mean(used, theory.variables)}; space = [{', '.join(theory.space)}] (and t, time)"
        )


def _plain(density: sympy.Expr, chis: list, fields: list[str], directions: list[str]) -> tuple[sympy.Expr, list]:
    """Undefined functions ``A1(t, x)`` and their first derivatives -> the plain symbols ``A1``, ``A1_x``."""
    applied = {f for e in [density, *chis] for f in e.atoms(sympy.core.function.AppliedUndef)}
    if not applied:
        return density, chis
    substitution: dict = {}
    for expr in [density, *chis]:
        for d in expr.atoms(sympy.Derivative):
            function = d.expr
            name = getattr(getattr(function, "func", None), "__name__", "")
            variables = [v for v, count in d.variable_count for _ in range(count)]
            if name not in fields or len(variables) != 1:
                raise InputError(f"{d}: only first derivatives of the fields are taken")
            args = [getattr(a, "name", str(a)) for a in function.args]
            direction = getattr(variables[0], "name", str(variables[0]))
            if direction not in directions:
                raise InputError(f"{d}: a derivative along {direction!r}, which is not t or a declared direction")
            if args != directions:
                raise InputError(f"field {name} must be a function of ({', '.join(directions)}), not of ({', '.join(args)})")
            substitution[d] = sympy.Symbol(derivative_name(name, direction), real=True)
    for f in applied:
        substitution.setdefault(f, sympy.Symbol(f.func.__name__, real=True))
    return density.subs(substitution), [c.subs(substitution) for c in chis]
