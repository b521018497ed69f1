"""The symbolic input of the engine: a Lagrangian with holonomic constraints.

A :class:`Lagrangian` holds coordinates ``q``, their velocities ``q_dot``, parameters,
the expression ``L(q, q_dot)`` and holonomic constraints ``chi_a(q) = 0``. Both may
depend explicitly on the time ``t`` (a rheonomic system, e.g. a bead on a rotating hoop,
``chi(q, t) = 0``) unless ``t`` is one of the coordinates (as in the relativistic
particle, where ``t`` is the coordinate time); see :attr:`Lagrangian.time`. The Dirac
analysis (:func:`dirac.analyze`) treats the multipliers of the constraints as
dynamical variables, as in the paper's extended Lagrangian (1):

    L_ext = L(q, q_dot) - sum_a lambda_a chi_a(q).

Lagrangians come from the Python API (:meth:`Lagrangian.from_strings` or sympy
expressions directly), from a system file (docs/file_formats.md, :func:`dirac.model.system_file.read_system_file`), or
from a built-in factory (:func:`dirac.load_system`).
"""

from __future__ import annotations

import keyword
import math
import re
from collections.abc import Callable, Iterable, Mapping, Sequence
from dataclasses import dataclass, field
from typing import Any

import sympy

from dirac.errors import InputError
from dirac.model.expressions import ALLOWED_CONSTANTS, ALLOWED_FUNCTIONS, TIME, non_real_constant, parse_expression
from dirac.model.from_sympy import plain_forces, plain_parts
from dirac.model.lagranges_method import is_lagranges_method, lagranges_method_parts
from dirac.model.permanent import freeze_imports
from dirac.validate import did_you_mean, is_real_number, unknown_name_error, validate_finite

freeze_imports()  # sympy's objects live as long as the process: out of the collector's way (dirac.model.permanent)

__all__ = ["Lagrangian", "TIME", "velocity_name", "momentum_name", "multiplier_name", "latex_name", "latex_names"]

_IDENTIFIER = re.compile(r"^[A-Za-z][A-Za-z0-9_]*$")


def _time_hint(unknown: set) -> str:
    """A hint when an unknown name is a time ``t`` other than :data:`TIME` (e.g. not real)."""
    if any(s.name == TIME.name for s in unknown):
        return (
            " (the engine's time is dirac.TIME, the real symbol sympy.Symbol('t', real=True): write t as dirac.TIME, "
            "or build the system with Lagrangian.from_sympy, which takes any t, and dynamicsymbols, as time)"
        )
    return ""


def _time_refused(role: str) -> InputError:
    """The error for a parameter (or other non-coordinate) named ``t``, which is time."""
    return InputError(
        f"the name 't' is time (an explicitly time-dependent Lagrangian or constraint may use it), so it "
        f"cannot be a {role}: rename the {role}, or list t among the coordinates if it is a coordinate "
        "(as the time coordinate of a relativistic particle)"
    )


def velocity_name(coordinate: str) -> str:
    """Name of the velocity of ``coordinate``: ``x`` -> ``x_dot`` (docs/conventions.md)."""
    return f"{coordinate}_dot"


def momentum_name(coordinate: str) -> str:
    """Name of the momentum of ``coordinate``: ``x`` -> ``p_x`` (docs/conventions.md)."""
    return f"p_{coordinate}"


def multiplier_name(index: int) -> str:
    """Name of the multiplier of constraint ``index`` (1-based): ``lambda_1``, …"""
    return f"lambda_{index}"


def latex_name(name: str) -> str:
    """LaTeX of a symbol name, reading the generated names (docs/conventions.md).

    ``x_dot`` -> ``\\dot{x}``, ``p_x`` -> ``p_{x}``, ``lambda_1`` -> ``\\lambda_{1}``,
    ``p_lambda_1`` -> ``p_{\\lambda_{1}}``; other names as sympy writes them. The
    symbols keep their names: only LaTeX renderings use this.
    """
    if name.endswith("_dot") and len(name) > 4:
        return rf"\dot{{{latex_name(name[:-4])}}}"
    if name.startswith("p_") and len(name) > 2:
        return rf"p_{{{latex_name(name[2:])}}}"
    return sympy.latex(sympy.Symbol(name))


def latex_names(*exprs: sympy.Basic) -> dict[sympy.Symbol, str]:
    """``symbol_names=`` for :func:`sympy.latex`: every free symbol of ``exprs`` -> :func:`latex_name`."""
    found: set[sympy.Symbol] = set()
    for e in exprs:
        found |= {s for s in sympy.sympify(e).free_symbols if isinstance(s, sympy.Symbol)}
    return {s: latex_name(s.name) for s in found}


def _as_rational(value: float | int) -> sympy.Rational:
    """Exact rational of a parameter value as written (``0.1`` -> ``1/10``)."""
    if isinstance(value, int):
        return sympy.Integer(value)
    return sympy.Rational(repr(float(value)))


@dataclass(frozen=True)
class Lagrangian:
    """A Lagrangian ``L(q, q_dot)`` with holonomic constraints ``chi(q) = 0``.

    Parameters
    ----------
    name
        Short name of the system (used in reports and result files).
    coordinates
        The generalized coordinates ``q`` as sympy symbols, in order.
    velocities
        The velocities ``q_dot``, one per coordinate, in the same order.
    expression
        ``L(q, q_dot)``; may contain the parameter symbols.
    constraints
        Holonomic constraint functions ``chi_a(q)``, "expressions that should be zero";
        they must not contain velocities.
    parameters
        Parameter symbol -> default numerical value (``None`` if it has none). Parameters
        stay symbolic in the analysis until fixed with :meth:`fix`; numerical flows use
        the defaults.
    description
        One line saying what the system is.
    validator
        Optional check of parameter values: called by :meth:`fix` with every parameter
        fixed so far (name -> number); raises :class:`~dirac.errors.InputError` for values
        the system cannot take (e.g. an inertia whose mass matrix (66) is not positive).
    fixed_values
        The parameters fixed so far (name -> number); kept for ``validator``.
    forces
        Generalized forces not derived from a potential: coordinate symbol -> ``Q_r(q,
        q_dot, t)``, so that Lagrange's equations read
        ``d/dt dL/dq_dot_r - dL/dq_r = Q_r + (constraint forces)`` (Lamb, *Dynamics*;
        Goldstein, *Classical Mechanics*, Sect. 1.4). Coordinates not listed get 0.

    Notes
    -----
    Construction validates the input: coordinates are distinct identifiers, no name is
    used twice or clashes with the generated names (``<q>_dot``, ``p_<q>``,
    ``lambda_<k>``), ``L`` is not empty, constraints are holonomic and not identically
    zero, and parameter values are finite.
    """

    name: str
    coordinates: tuple[sympy.Symbol, ...]
    velocities: tuple[sympy.Symbol, ...]
    expression: sympy.Expr
    constraints: tuple[sympy.Expr, ...] = ()
    parameters: Mapping[sympy.Symbol, float | None] = field(default_factory=dict)
    description: str = ""
    validator: Callable[[Mapping[str, float]], None] | None = field(default=None, compare=False, repr=False)
    fixed_values: Mapping[str, float] = field(default_factory=dict, compare=False)
    forces: Mapping[sympy.Symbol, sympy.Expr] = field(default_factory=dict)

    def __post_init__(self) -> None:
        object.__setattr__(self, "coordinates", tuple(self.coordinates))
        object.__setattr__(self, "velocities", tuple(self.velocities))
        object.__setattr__(self, "constraints", tuple(sympy.sympify(c) for c in self.constraints))
        object.__setattr__(self, "expression", sympy.sympify(self.expression))
        object.__setattr__(self, "parameters", dict(self.parameters))
        object.__setattr__(self, "fixed_values", dict(self.fixed_values))
        object.__setattr__(self, "forces", self._checked_forces(self.forces))
        self._validate()

    # ----------------------------------------------------------------- validation
    def _validate(self) -> None:
        if not isinstance(self.name, str) or not self.name.strip():
            raise InputError("system name is empty: give the system a name")
        if not self.coordinates:
            raise InputError(f"system {self.name!r} has no coordinates: list at least one")
        if len(self.velocities) != len(self.coordinates):
            raise InputError(
                f"system {self.name!r} has {len(self.coordinates)} coordinates but "
                f"{len(self.velocities)} velocities: give one velocity per coordinate"
            )
        _check_names(self.coordinates, self.velocities, tuple(self.parameters), len(self.constraints))
        for p, value in self.parameters.items():
            if value is None:
                continue
            if not is_real_number(value):
                raise InputError(f"parameter {p.name!r} = {value!r} is not a number")
            if not math.isfinite(value):
                raise InputError(f"parameter {p.name!r} = {value!r} is not finite: give a finite number")

        allowed = set(self.coordinates) | set(self.velocities) | set(self.parameters)
        if self.time is not None:
            if any(p.name == TIME.name for p in self.parameters):
                raise _time_refused("parameter")
            allowed.add(self.time)
        if self.expression == 0:
            raise InputError(f"the Lagrangian of {self.name!r} is empty (zero): give L(q, q_dot)")
        unknown = self.expression.free_symbols - allowed
        if unknown:
            names = ", ".join(sorted(s.name for s in unknown))
            raise InputError(f"the Lagrangian of {self.name!r} uses unknown names: {names}{_time_hint(unknown)}")
        _refuse_non_real(self.expression, f"the Lagrangian of {self.name!r}", self.parameters)
        velocity_set = set(self.velocities)
        for index, chi in enumerate(self.constraints, start=1):
            label = f"constraint {index} ({chi})"
            _refuse_non_real(chi, label, self.parameters)
            extra = chi.free_symbols - allowed
            if extra:
                names = ", ".join(sorted(s.name for s in extra))
                raise InputError(f"{label} uses unknown names: {names}{_time_hint(extra)}")
            in_velocity = sorted(s.name for s in chi.free_symbols & velocity_set)
            if in_velocity:
                raise InputError(
                    f"{label} contains the velocities {', '.join(in_velocity)}: only holonomic "
                    "constraints chi(q) = 0 are supported; write it in the coordinates alone"
                )
            if chi == 0:
                raise InputError(f"{label} is identically zero: remove it")
            if not (chi.free_symbols & set(self.coordinates)):
                raise InputError(
                    f"{label} does not depend on any coordinate: a constraint chi(q) = 0 must restrict q"
                )

    def _checked_forces(self, forces: object) -> dict[sympy.Symbol, sympy.Expr]:
        """``forces`` keyed by coordinate symbols (names accepted), zero forces dropped.

        Raises
        ------
        InputError
            A key that is not a coordinate (with the closest coordinate names), an
            expression with names other than the coordinates, velocities, parameters and
            ``t``, or a non-finite number.
        """
        if not isinstance(forces, Mapping):
            raise InputError("forces must be a mapping coordinate -> expression, e.g. {'x': '-c*x_dot'}")
        by_name = {q.name: q for q in self.coordinates}
        allowed = set(self.coordinates) | set(self.velocities) | set(self.parameters)
        if self.time is not None:
            allowed.add(self.time)
        checked: dict[sympy.Symbol, sympy.Expr] = {}
        for key, value in forces.items():
            label = key.name if isinstance(key, sympy.Symbol) else str(key)
            if label not in by_name:
                raise InputError(
                    f"a force is given on {label!r}, which is not a coordinate of {self.name!r}"
                    f"{did_you_mean(label, by_name)}; coordinates: {', '.join(by_name)}"
                )
            try:
                expression = sympy.sympify(value)
            except (sympy.SympifyError, TypeError):
                raise InputError(f"the force on {label!r} ({value!r}) is not an expression") from None
            unknown = expression.free_symbols - allowed
            if unknown:
                names = sorted(s.name for s in unknown)
                hints = "".join(did_you_mean(n, [s.name for s in allowed]) for n in names)
                raise InputError(
                    f"the force on {label!r} uses unknown names: {', '.join(names)}{hints}; a force may use the "
                    "coordinates, their velocities <q>_dot, the parameters and t"
                )
            if expression.has(sympy.zoo, sympy.oo, -sympy.oo, sympy.nan):
                raise InputError(f"the force on {label!r} is not finite: {expression}")
            _refuse_non_real(expression, f"the force on {label!r}", self.parameters)
            if expression != 0:
                checked[by_name[label]] = expression
        return checked

    @property
    def is_forced(self) -> bool:
        """Whether generalized forces not derived from a potential act (:attr:`forces`)."""
        return bool(self.forces)

    @property
    def force_vector(self) -> tuple[sympy.Expr, ...]:
        """``(Q_1, ..., Q_n)`` in coordinate order (0 where no force is given)."""
        return tuple(self.forces.get(q, sympy.S.Zero) for q in self.coordinates)

    # ----------------------------------------------------------------- construction
    @classmethod
    def from_strings(
        cls,
        name: str,
        coordinates: Sequence[str],
        lagrangian: str,
        constraints: Iterable[str] = (),
        parameters: Mapping[str, float | None] | None = None,
        description: str = "",
        forces: Mapping[str, str] | None = None,
    ) -> Lagrangian:
        """Build a Lagrangian from expressions written as text (docs/file_formats.md).

        The name ``t`` is the time (:attr:`time`) unless ``t`` is one of ``coordinates``.
        ``forces`` maps coordinate names to generalized forces ``Q_r(q, q_dot, t)`` as
        text (:attr:`forces`), e.g. ``{"x": "-c*x_dot"}``.

        Examples
        --------
        >>> pendulum = Lagrangian.from_strings(
        ...     "pendulum", ["x", "y"], "m/2*(x_dot**2 + y_dot**2) - m*g*y",
        ...     constraints=["x**2 + y**2 - l**2"], parameters={"m": 1.0, "g": 9.81, "l": 1.0})
        >>> pendulum.constraints
        (-l**2 + x**2 + y**2,)
        """
        if isinstance(coordinates, str) or not isinstance(coordinates, Sequence):
            raise InputError("coordinates must be a list of names, e.g. ['x', 'y']")
        if isinstance(constraints, str):
            raise InputError("constraints must be a list of expressions, e.g. ['x**2 + y**2 - l**2']")
        if parameters is not None and not isinstance(parameters, Mapping):
            raise InputError(
                f"parameters must be a mapping name -> value, e.g. {{'m': 1.0, 'g': 9.81}} (None for a parameter "
                f"without a value), not a {type(parameters).__name__}"
            )
        parameters = dict(parameters or {})
        labels = [str(c) for c in coordinates]
        if TIME.name in parameters and TIME.name not in labels:
            raise _time_refused("parameter")
        for label in [*labels, *parameters]:
            if not isinstance(label, str) or not _IDENTIFIER.match(label) or keyword.iskeyword(label):
                raise InputError(f"name {label!r} is not a valid name: use letters, digits and '_', starting with a letter")
        duplicates = sorted({x for x in labels if labels.count(x) > 1} | (set(labels) & set(parameters)))
        if duplicates:
            raise InputError(f"name(s) {', '.join(duplicates)} used twice among coordinates and parameters")
        q = tuple(sympy.Symbol(c, real=True) for c in labels)
        v = tuple(sympy.Symbol(velocity_name(c), real=True) for c in labels)
        psyms = {label: sympy.Symbol(label, real=True) for label in parameters}
        constraints = list(constraints)
        _check_names(q, v, tuple(psyms.values()), len(constraints))
        names = {s.name: s for s in (*q, *v, *psyms.values())}
        add = "if it is a parameter, add it to parameters (with its value); if a coordinate, to coordinates"
        expr = parse_expression(lagrangian, names, what="lagrangian", time=TIME, unknown_hint=add)
        positions = {s.name: s for s in (*q, *psyms.values())}  # a constraint chi(q, t) has no velocities
        holonomic = {
            s.name: "it is a velocity, and only holonomic constraints chi(q, t) = 0 are supported: write the "
            "constraint in the coordinates, parameters and t alone"
            for s in v
        }
        chis = tuple(
            parse_expression(text, positions, what=f"constraint {k}", time=TIME, refused=holonomic, unknown_hint=add)
            for k, text in enumerate(constraints, start=1)
        )
        values = {psyms[label]: (None if value is None else value) for label, value in parameters.items()}
        for label, value in parameters.items():
            if value is not None and not is_real_number(value):
                raise InputError(f"parameter {label!r} = {value!r} is not a number")
        if forces is None:
            forces = {}
        if not isinstance(forces, Mapping):
            raise InputError("forces must be a table coordinate -> expression, e.g. { x = \"-c*x_dot\" }")
        parsed: dict[str, sympy.Expr] = {}
        for label, text in forces.items():
            if label not in labels:
                raise InputError(
                    f"a force is given on {label!r}, which is not a coordinate of {name!r}"
                    f"{did_you_mean(str(label), labels)}; coordinates: {', '.join(labels)}"
                )
            parsed[label] = parse_expression(text, names, what=f"the force on {label!r}", time=TIME)
        return cls(name, q, v, expr, chis, values, description, forces=parsed)

    @classmethod
    def from_sympy(
        cls,
        L: sympy.Expr | Any,
        coordinates: Sequence[sympy.Basic] | None = None,
        constraints: Iterable[sympy.Expr] = (),
        parameters: Mapping[sympy.Symbol | str, float | None] | Iterable[sympy.Symbol | str] | None = None,
        name: str = "system",
        description: str = "",
        forces: Mapping[object, sympy.Expr] | None = None,
    ) -> Lagrangian:
        """Build a Lagrangian from sympy expressions: plain symbols or ``dynamicsymbols``.

        Coordinates are symbols ``q`` (velocities written as symbols named ``q_dot``) or
        functions of time ``q(t)`` from ``sympy.physics.mechanics.dynamicsymbols``
        (velocities written as ``q(t).diff(t)``, replaced by ``q_dot``; ``q(t)`` by ``q``).
        ``parameters=None`` makes every other symbol a parameter without a default. Any
        symbol named ``t`` and the time of ``dynamicsymbols`` (``dynamicsymbols._t``)
        become the engine's time :data:`dirac.TIME`. See
        :func:`dirac.model.from_sympy.plain_parts`. ``forces`` maps a coordinate (symbol,
        ``dynamicsymbols`` function or name) to its generalized force ``Q_r`` written like
        ``L`` (:attr:`forces`).

        ``L`` may also be a ``sympy.physics.mechanics.LagrangesMethod`` (given alone,
        without ``coordinates`` and ``constraints``): its Lagrangian, coordinates and
        holonomic constraints are taken (:mod:`dirac.model.lagranges_method`); a
        ``forcelist`` becomes generalized forces ``Q_r`` (:mod:`dirac.model.lagranges_method`);
        non-holonomic constraints are refused.

        Examples
        --------
        >>> import sympy
        >>> from sympy.physics.mechanics import dynamicsymbols
        >>> x = dynamicsymbols("x")
        >>> t, m, k = sympy.symbols("t m k")
        >>> print(Lagrangian.from_sympy(m / 2 * x.diff(t) ** 2 - k / 2 * x**2, [x], name="oscillator"))
        oscillator: L = -k*x**2/2 + m*x_dot**2/2
        """
        if is_lagranges_method(L):
            if coordinates is not None or constraints != ():
                raise InputError("give a LagrangesMethod alone: its coordinates (lm.q) and constraints (hol_coneqs) "
                                 "are taken from it")
            L, coordinates, constraints, loads = lagranges_method_parts(L)
            if loads and forces:
                raise InputError("the LagrangesMethod has a forcelist and forces= is given too: give the forces once")
            forces = forces or loads
        elif coordinates is None:
            raise InputError("from_sympy needs the coordinates, e.g. Lagrangian.from_sympy(L, [x, y]), "
                             "or a sympy LagrangesMethod alone")
        if forces:
            parts, converted = plain_forces(L, coordinates, constraints, parameters, velocity_name, forces)
            return cls(name, *parts, description, forces=converted)
        return cls(name, *plain_parts(L, coordinates, constraints, parameters, velocity_name), description)

    # ----------------------------------------------------------------- derived views
    @property
    def time(self) -> sympy.Symbol | None:
        """The time symbol ``t`` (real) of ``L`` and the constraints; ``None`` if ``t`` is a coordinate.

        A system with a coordinate called ``t`` (the relativistic particle's coordinate
        time) cannot depend on time explicitly: there ``t`` is that coordinate.
        """
        if any(q.name == TIME.name for q in self.coordinates):
            return None
        return TIME

    @property
    def is_time_dependent(self) -> bool:
        """Whether the time ``t`` occurs explicitly in ``L`` or in a constraint (a rheonomic system)."""
        t = self.time
        if t is None:
            return False
        return any(t in e.free_symbols for e in (self.expression, *self.constraints))

    @property
    def parameter_symbols(self) -> dict[str, sympy.Symbol]:
        """Parameter name -> symbol."""
        return {p.name: p for p in self.parameters}

    @property
    def parameter_values(self) -> dict[str, float | None]:
        """Parameter name -> default value (``None`` if none)."""
        return {p.name: value for p, value in self.parameters.items()}

    @property
    def symbols(self) -> dict[str, sympy.Symbol]:
        """Every symbol of the input by name: coordinates, velocities, parameters."""
        return {s.name: s for s in (*self.coordinates, *self.velocities, *self.parameters)}

    def velocity_of(self, coordinate: sympy.Symbol) -> sympy.Symbol:
        """The velocity symbol that belongs to ``coordinate``."""
        return self.velocities[self.coordinates.index(coordinate)]

    def fix(self, **values: float) -> Lagrangian:
        """Substitute numbers for some parameters; the others stay symbolic.

        Values are substituted as exact rationals of the numbers as written, so the
        symbolic analysis stays exact.

        Raises
        ------
        InputError
            For a name that is not a parameter, a value that is not a finite number, or
            values the system's ``validator`` refuses.
        """
        symbols = self.parameter_symbols
        substitution: dict[sympy.Symbol, sympy.Expr] = {}
        remaining = dict(self.parameters)
        for label, value in values.items():
            if label not in symbols:
                raise unknown_name_error("parameter", label, symbols, source=f"system {self.name!r}")
            substitution[symbols[label]] = _as_rational(validate_finite(value, f"parameter {label!r}"))
            remaining.pop(symbols[label])
        merged = {**self.fixed_values, **{k: float(v) for k, v in values.items()}}
        if self.validator is not None:
            self.validator(merged)
        given: dict[sympy.Symbol, float | None] = {symbols[k]: float(v) for k, v in values.items()}
        _refuse_non_real(self.expression, f"the Lagrangian of {self.name!r}", given)  # named before substitution
        for index, chi in enumerate(self.constraints, start=1):
            _refuse_non_real(chi, f"constraint {index} ({chi})", given)
        for q, force in self.forces.items():
            _refuse_non_real(force, f"the force on {q.name!r}", given)
        return Lagrangian(
            self.name,
            self.coordinates,
            self.velocities,
            self.expression.subs(substitution),
            tuple(c.subs(substitution) for c in self.constraints),
            remaining,
            self.description,
            self.validator,
            merged,
            {q: e.subs(substitution) for q, e in self.forces.items()},
        )

    def with_defaults(self) -> Lagrangian:
        """All parameters that have a default value fixed to it (for numerical work)."""
        return self.fix(**{p.name: v for p, v in self.parameters.items() if v is not None})

    def to_latex(self) -> str:
        """``L`` and the constraints ``chi_k = 0`` as one ``aligned`` block (velocities as ``\\dot{q}``)."""
        names = latex_names(self.expression, *self.constraints)
        rows = [rf"L &= {sympy.latex(self.expression, symbol_names=names)}"]
        rows += [
            rf"\chi_{{{k}}} &= {sympy.latex(c, symbol_names=names)} = 0" for k, c in enumerate(self.constraints, start=1)
        ]
        return "\\begin{aligned}\n" + " \\\\\n".join(rows) + "\n\\end{aligned}"

    def _repr_latex_(self) -> str:
        return f"$${self.to_latex()}$$"

    def __str__(self) -> str:
        lines = [f"{self.name}: L = {self.expression}"]
        lines += [f"  constraint {k}: {c} = 0" for k, c in enumerate(self.constraints, start=1)]
        lines += [f"  force on {q.name}: Q = {e}" for q, e in self.forces.items()]
        return "\n".join(lines)


def _refuse_non_real(expression: sympy.Expr, label: str, values: Mapping[sympy.Symbol, float | None]) -> None:
    """Refuse ``expression`` when a part of it has no real value (:func:`non_real_constant`),
    as written or with the parameters' values in ``values``."""
    given = {p: _as_rational(v) for p, v in values.items() if is_real_number(v) and math.isfinite(v)}
    found = non_real_constant(expression, given)
    if found is None:
        return
    part, value = found
    used = sorted((p for p in part.free_symbols if p in given), key=lambda p: p.name)
    where = f" with {', '.join(f'{p.name} = {values[p]!r}' for p in used)}" if used else ""
    if value != value:  # nan: no finite value
        raise InputError(f"{label} is not finite{where}: its part {part} has no finite value")
    raise InputError(
        f"{label} is not real{where}: its part {part} = {value.real:.6g}{value.imag:+.6g} I is complex (a "
        "Lagrangian, its constraints and forces are real functions); "
        + ("give the parameter a value in its real domain" if used else
           "write a real constant (for an odd root of a negative number, -(8**(1/3)) instead of (-8)**(1/3))")
    )


def _check_names(
    coordinates: Sequence[sympy.Symbol],
    velocities: Sequence[sympy.Symbol],
    parameters: Sequence[sympy.Symbol],
    n_constraints: int,
) -> None:
    """Every name is a valid identifier, used once, and clashes with no generated name."""
    seen: dict[str, str] = {}

    def claim(sym: object, role: str) -> None:
        if not isinstance(sym, sympy.Symbol):
            raise InputError(f"{role} {sym!r} must be a sympy Symbol")
        label = sym.name
        if not _IDENTIFIER.match(label) or keyword.iskeyword(label):
            raise InputError(
                f"{role} name {label!r} is not a valid name: use letters, digits and '_', starting with a letter"
            )
        if label in ALLOWED_FUNCTIONS or label in ALLOWED_CONSTANTS:
            raise InputError(f"{role} name {label!r} is reserved for a function or constant: rename it")
        if label in seen:
            raise InputError(f"name {label!r} is used twice (as {seen[label]} and as {role}): names must be distinct")
        seen[label] = role

    for q in coordinates:
        claim(q, "coordinate")
    for v in velocities:
        claim(v, "velocity")
    for p in parameters:
        claim(p, "parameter")
    generated = {momentum_name(q.name) for q in coordinates}
    generated |= {multiplier_name(k + 1) for k in range(n_constraints)}
    generated |= {momentum_name(multiplier_name(k + 1)) for k in range(n_constraints)}
    for label, role in seen.items():
        if label in generated:
            raise InputError(
                f"{role} name {label!r} clashes with a name the engine generates "
                "(momenta p_<q>, multipliers lambda_<k>): rename it"
            )
