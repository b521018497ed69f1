"""The Dirac–Bergmann analysis of a linear field theory, mode by mode, read per spatial point.

:func:`analyze_field_theory` builds the pair Lagrangian of the modes ``(k, -k)`` and the
zero-mode Lagrangian (:mod:`dirac.fields.modes`), hands both to the engine
(:func:`dirac.analysis.components.analyze`) unchanged, and reads the answers back in the
language of field theory: constraints in position space, the counts per spatial point (the
pair's counts halved, :mod:`dirac.fields.modes`), gauge generators as local
transformations, and Dirac brackets as the Fourier coefficient of the delta function.
"""

from __future__ import annotations

from collections.abc import Callable, Sequence
from dataclasses import dataclass
from typing import Any

import sympy

from dirac.errors import AnalysisError, InputError
from dirac.fields.modes import (
    ModeMap,
    check_linear,
    latex_of_operator,
    pair_lagrangian,
    wave_vector,
    zero_mode_lagrangian,
)
from dirac.fields.theory import TIME_DIRECTION, FieldTheory
from dirac.model.expressions import parse_expression
from dirac.model.lagrangian import momentum_name

__all__ = ["FieldAnalysis", "FieldGauge", "FieldCase", "GaugeFixedField", "analyze_field_theory"]


def _text(expr: sympy.Expr) -> str:
    return str(expr)


def _latex(expr: sympy.Expr) -> str:
    names = {s: latex_of_operator(s.name) for s in expr.free_symbols if isinstance(s, sympy.Symbol)}
    return sympy.latex(expr, symbol_names=names)


@dataclass
class FieldGauge:
    """One gauge symmetry as a local transformation: ``G = int sum_n epsilon^(n) G_n``."""

    parameter: str
    terms: list[sympy.Expr]
    delta: dict[str, sympy.Expr]

    def to_json(self) -> dict:
        return {"parameter": self.parameter, "terms": [_text(t) for t in self.terms],
                "delta": {k: _text(v) for k, v in self.delta.items()}}


@dataclass
class FieldCase:
    """A special wave vector or parameter value, analysed as its own mode (counts per mode)."""

    condition: str
    analysis: Any
    per: int
    mapping: ModeMap
    error: str | None = None

    def _counts(self, items: Sequence) -> int:
        return len(items) // self.per

    def to_json(self) -> dict:
        if self.error is not None:
            return {"condition": self.condition, "error": self.error}
        a = self.analysis
        return {
            "condition": self.condition,
            "stages": [{"stage": k, "constraints": [_text(c) for c in _select(self.mapping, stage)]}
                       for k, stage in enumerate(a.stages, start=1)],
            "first_class": [_text(c) for c in _select(self.mapping, a.first_class)],
            "second_class": [_text(c) for c in _select(self.mapping, a.second_class)],
            "constraints_per_stage": [self._counts(s) for s in a.stages],
            "first_class_count": self._counts(a.first_class),
            "second_class_count": self._counts(a.second_class),
            "physical_degrees_of_freedom": a.physical_degrees_of_freedom // self.per
            if self.per == 2 else a.physical_degrees_of_freedom,
            "per": "mode" if self.per == 1 else "mode (pair k, -k halved)",
        }

    def summary(self) -> str:
        if self.error is not None:
            return f"{self.condition}: {self.error}"
        d = self.to_json()
        return (f"{self.condition}: constraints per stage {d['constraints_per_stage']}, {d['first_class_count']} first "
                f"class, {d['second_class_count']} second class, {d['physical_degrees_of_freedom']} degrees of "
                "freedom per mode")


def _select(mapping: ModeMap, constraints: Sequence[sympy.Expr], before: Sequence = ()) -> list[sympy.Expr]:
    """The constraints independent over C, in position space."""
    vectors = [mapping.complex_vector(c) for c in constraints]
    if any(v is None for v in vectors):
        return list(constraints)
    kept = mapping.independent([v for v in vectors if v is not None], before=before)
    return [mapping.expression(mapping.normalised(vectors[i]), mapping.labels) for i in kept]  # type: ignore[arg-type]


class _Brackets:
    """Dirac brackets of fields and momenta as Fourier coefficients of the delta function."""

    theory: FieldTheory
    mode: Any
    mapping: ModeMap

    def _pair(self, name: str) -> tuple[sympy.Symbol, sympy.Symbol | None]:
        labels = self.mapping.labels
        if name not in labels:
            from dirac.validate import did_you_mean

            raise InputError(f"unknown field or momentum {name!r}{did_you_mean(name, labels)}; known: {', '.join(labels)}")
        index = labels.index(name)
        return self.mapping.real[index], (self.mapping.imag[index] if self.mapping.pair else None)

    def _bracket(self, f: str, g: str, kind: Callable) -> sympy.Expr:
        fr, fi = self._pair(f)
        gr, _ = self._pair(g)
        value = kind(fr, gr)
        if fi is not None:
            value = value + sympy.I * kind(fi, gr)
        return sympy.factor(sympy.cancel(sympy.together(value)))

    def dirac_bracket(self, f: str, g: str) -> sympy.Expr:
        """``{f(x), g(y)}_D = K(d_x) delta(x - y)``: the Fourier coefficient ``K(k)`` (a function of the wave vector).

        ``f`` and ``g`` name fields or momenta (``"A1"``, ``"p_A2"``). In the pair variables,
        ``K = {Re f, Re g}_D + i {Im f, Re g}_D`` (docs/field_theories.md).
        """
        return self._bracket(f, g, self.mode.dirac_bracket)

    def poisson_bracket(self, f: str, g: str) -> sympy.Expr:
        """As :meth:`dirac_bracket` for the Poisson bracket (``{A1, p_A1} = 1``)."""
        return self._bracket(f, g, self.mode.poisson_bracket)


class FieldAnalysis(_Brackets):
    """The analysis of a linear field theory (use :func:`dirac.analyze` on a :class:`FieldTheory`).

    Attributes
    ----------
    theory, name, wave_vector
        The input, its name and ``(k_x, ...)``.
    mode
        The engine's analysis of the pair Lagrangian at a generic wave vector (the zero mode's
        for a theory without spatial directions).
    zero_mode
        The engine's analysis of the zero mode ``k = 0`` (None without spatial directions).
    stages, constraints, first_class, second_class
        Constraints in position space (``d_x(...)`` notation), one per constraint per point.
    constraints_per_stage, first_class_count, second_class_count, physical_degrees_of_freedom
        Counts per spatial point (the local gauge transformations: :attr:`gauge_generators`).
    parameter_cases
        :class:`FieldCase` list: ``k = 0`` and every special wave vector or parameter value.
    """

    def __init__(self, theory: FieldTheory, progress: Callable[[str], None] | None = None) -> None:
        from dirac.analysis.components import analyze

        check_linear(theory)
        self.theory = theory
        self.name = theory.name
        self.wave_vector = wave_vector(theory)
        self.gauge_conditions: tuple[str, ...] = ()
        zero = analyze(zero_mode_lagrangian(theory), progress=progress)
        self.zero_mode = zero if theory.space else None
        if theory.space:
            self.mode = analyze(pair_lagrangian(theory), progress=progress)
            self.mapping = ModeMap(theory, pair=True)
            self.per = 2
        else:
            self.mode = zero
            self.mapping = ModeMap(theory, pair=False)
            self.per = 1
        self._read(self.mode)
        self.parameter_cases = self._cases(progress)

    # ------------------------------------------------------------------ reading the mode analysis
    def _read(self, mode: Any) -> None:
        per = self.per
        for label, items in (("constraints", mode.constraints), ("first class", mode.first_class),
                             ("second class", mode.second_class)):
            if len(items) % per:
                raise AnalysisError(f"{self.name}: the pair analysis has an odd number ({len(items)}) of {label}: "
                                    "the modes k and -k do not pair up; the counts per point cannot be read")
        self.constraints_per_stage = [len(s) // per for s in mode.stages]
        self.first_class_count = len(mode.first_class) // per
        self.second_class_count = len(mode.second_class) // per
        self.physical_degrees_of_freedom = mode.physical_degrees_of_freedom // per \
            if per == 2 else mode.physical_degrees_of_freedom
        if per == 2 and mode.physical_degrees_of_freedom % 2:
            raise AnalysisError(f"{self.name}: odd number of degrees of freedom of the mode pair")
        stages: list[list[sympy.Expr]] = []
        vectors: list = []
        for stage in mode.stages:
            maybe = [self.mapping.complex_vector(c) for c in stage]
            vecs = [v for v in maybe if v is not None]
            if len(vecs) != len(maybe):
                raise AnalysisError(f"{self.name}: a constraint of the linear theory is not linear: {stage}")
            kept = self.mapping.independent(vecs, before=vectors)
            stages.append([self.mapping.expression(self.mapping.normalised(vecs[i]), self.mapping.labels) for i in kept])
            vectors.extend(vecs[i] for i in kept)
        if [len(s) for s in stages] != self.constraints_per_stage:
            raise AnalysisError(f"{self.name}: the constraints of the mode pair do not pair up into local constraints "
                                f"({[len(s) for s in stages]} against {self.constraints_per_stage})")
        self.stages = stages
        self.constraints = [c for s in stages for c in s]
        self.first_class = _select(self.mapping, mode.first_class)
        self.second_class = _select(self.mapping, mode.second_class)
        if (len(self.first_class), len(self.second_class)) != (self.first_class_count, self.second_class_count):
            raise AnalysisError(f"{self.name}: the classes of the mode pair do not pair up into local constraints "
                                f"({len(self.first_class)} and {len(self.second_class)} local constraints against "
                                f"{self.first_class_count} first and {self.second_class_count} second class per point)")

    @property
    def gauge_generators(self) -> list[FieldGauge]:
        """The gauge transformations, local in position space (from Castellani's generators of the mode)."""
        if not hasattr(self, "_gauge"):
            self._gauge = self._local_generators()
        return self._gauge

    def _local_generators(self) -> list[FieldGauge]:
        m = self.mapping
        n_fields = len(self.theory.fields)
        found: list[tuple[list, list]] = []
        for gen in self.mode.gauge_generators:
            parts = [m.complex_vector(term) for term in gen.terms]
            if any(p is None for p in parts):
                continue
            joint = [e for p in parts for e in p]  # type: ignore[union-attr]
            # delta phi_a = sum_n beta_{n,a}(-d) eps^(n), delta pi_a = -sum_n alpha_{n,a}(-d) eps^(n)
            found.append((joint, parts))
        vectors = [j for j, _ in found]
        kept = m.independent(vectors)
        out: list[FieldGauge] = []
        for number, index in enumerate(kept, start=1):
            joint = m.normalised(found[index][0])
            width = 2 * n_fields
            terms_vec = [joint[n * width:(n + 1) * width] for n in range(len(joint) // width)]
            flip = {d: -d for d in m.ds.values()}
            name = "epsilon" if len(kept) == 1 else f"epsilon_{number}"
            eps = [name + ("_" + TIME_DIRECTION * n if n else "") for n in range(len(terms_vec))]
            delta_vec: dict[str, list[sympy.Expr]] = {}
            for a, f in enumerate(self.theory.field_names):
                delta_vec[f] = [sympy.expand(vec[n_fields + a].xreplace(flip)) for vec in terms_vec]
                delta_vec[momentum_name(f)] = [sympy.expand(-vec[a].xreplace(flip)) for vec in terms_vec]
            lead = sympy.Integer(1)
            for coefficients in delta_vec.values():
                nonzero = [c for c in coefficients if c != 0]
                if nonzero:
                    lead = m.leading(nonzero, [0])
                    break
            sign = 1 / lead if lead.is_number else (-1 if lead.could_extract_minus_sign() else 1)
            delta = {}
            for label, coefficients in delta_vec.items():
                value = m.expression([sympy.expand(sign * c) for c in coefficients], eps)
                if value != 0:
                    delta[label] = value
            terms = [sympy.expand(sign * m.expression(vec, m.labels)) for vec in terms_vec]
            out.append(FieldGauge(name, terms, delta))
        return out

    # ------------------------------------------------------------------ cases
    def _cases(self, progress: Callable[[str], None] | None) -> list[FieldCase]:
        from dirac.analysis.components import analyze

        cases: list[FieldCase] = []
        if self.zero_mode is not None:
            condition = " = ".join(k.name for k in self.wave_vector) + " = 0"
            cases.append(FieldCase(condition, self.zero_mode, 1, ModeMap(self.theory, pair=False)))
        for special in getattr(self.mode, "special_parameter_values", []):
            condition = special.equation
            lagrangian = self.mode.lagrangian
            try:
                symbol = next(p for p in lagrangian.parameters if p.name == special.parameter)
                if sympy.expand(lagrangian.expression.subs(symbol, special.value)) == 0:
                    cases.append(FieldCase(condition, None, self.per, self.mapping,
                                           error="the density vanishes there: no theory left to analyse"))
                    continue
                fixed = _substituted(lagrangian, symbol, special.value)
                cases.append(FieldCase(condition, analyze(fixed, progress=progress), self.per, self.mapping))
            except Exception as exc:  # noqa: BLE001 - a case that cannot be analysed is reported, not hidden
                cases.append(FieldCase(condition, None, self.per, self.mapping, error=f"{type(exc).__name__}: {exc}"))
        return cases

    # ------------------------------------------------------------------ gauge fixing
    def fix_gauge(self, conditions: Sequence[str | sympy.Expr]) -> GaugeFixedField:
        """The theory in a gauge: conditions in the density's syntax (``"A0"``, ``"A1_x + A2_y + A3_z"``).

        Each condition is linear in the fields, their spatial derivatives and the momenta
        ``p_<field>`` (and theirs, ``p_A1_x``), with constant coefficients; its Fourier
        transform gives two real conditions on the generic mode pair (real and imaginary
        parts), handed to the engine's gauge fixing. The zero mode is not fixed.
        """
        if isinstance(conditions, str):
            conditions = [conditions]
        mode_conditions = []
        for text in conditions:
            mode_conditions.extend(self._mode_condition(text))
        try:
            fixed = self.mode.fix_gauge(mode_conditions)
        except InputError as exc:  # the engine speaks of mode variables: say which conditions they come from
            raise InputError(f"gauge conditions {', '.join(map(str, conditions))} (Fourier modes "
                             f"{', '.join(map(str, mode_conditions))}, <field>_re/_im the real and imaginary parts of "
                             f"a mode): {exc}") from None
        return GaugeFixedField(self, fixed, tuple(str(c) for c in conditions))

    def _mode_condition(self, text: str | sympy.Expr) -> list[sympy.Expr]:
        theory = self.theory
        names: dict[str, sympy.Symbol] = {}
        labels = [*theory.field_names, *(momentum_name(f) for f in theory.field_names)]
        for label in labels:
            names[label] = sympy.Symbol(label, real=True)
            for d in theory.space:
                names[f"{label}_{d}"] = sympy.Symbol(f"{label}_{d}", real=True)
        params = {p.name: p for p in theory.parameters}
        time_derivatives = {f"{f}_t": "a gauge condition is a function on phase space: use the momenta p_<field>, "
                            "not time derivatives" for f in theory.field_names}
        expr = parse_expression(str(text), {**names, **params}, what="gauge condition", refused=time_derivatives)
        expr = sympy.expand(expr)
        variables = list(names.values())
        try:
            poly = sympy.Poly(expr, *variables)
        except sympy.PolynomialError:
            poly = None
        if poly is None or poly.total_degree() != 1 or any(sum(m) != 1 for m in poly.monoms()):
            raise InputError(f"gauge condition {text!r} must be linear and homogeneous in the fields, their spatial "
                             "derivatives and the momenta, with constant coefficients")
        m = self.mapping
        ks = dict(zip(theory.space, self.wave_vector))
        hat = sympy.Integer(0)
        for label_index, label in enumerate(labels):
            real = m.real[label_index]
            imag = m.imag[label_index] if m.pair else sympy.Integer(0)
            amplitude = real + sympy.I * imag
            hat += expr.coeff(names[label]) * amplitude
            for d in theory.space:
                hat += expr.coeff(names[f"{label}_{d}"]) * sympy.I * ks[d] * amplitude
        hat = sympy.expand(hat)
        parts = [sympy.expand(sympy.re(hat)), sympy.expand(sympy.im(hat))] if m.pair else [sympy.expand(hat)]
        return [p for p in parts if p != 0]

    # ------------------------------------------------------------------ output
    def field_theory_json(self) -> dict:
        return {"space": list(self.theory.space), "fields": self.theory.field_names,
                "method": "fourier" if self.theory.space else "modes (no spatial directions)",
                "wave_vector": [k.name for k in self.wave_vector],
                "counts": "per spatial point (the mode pair k, -k counts twice)"}

    def to_json(self) -> dict:
        mode_json = self.mode.to_json()
        out = {
            "system": self.name,
            "coordinates": self.theory.field_names,
            "phase_space_dimension": 2 * len(self.theory.fields),
            "stages": [{"stage": k, "constraints": [_text(c) for c in s]} for k, s in enumerate(self.stages, start=1)],
            "first_class": [_text(c) for c in self.first_class],
            "second_class": [_text(c) for c in self.second_class],
            "constraints_per_stage": self.constraints_per_stage,
            "first_class_count": self.first_class_count,
            "second_class_count": self.second_class_count,
            "multipliers": mode_json["multipliers"],
            "physical_degrees_of_freedom": self.physical_degrees_of_freedom,
            "field_theory": self.field_theory_json(),
            "gauge_generators": [{"terms": [_text(t) for t in g.terms]} for g in self.gauge_generators],
            "gauge_transformations": [g.to_json() for g in self.gauge_generators],
            "gauge_conditions": list(self.gauge_conditions),
            "special_parameter_values": [c.condition for c in self.parameter_cases],
            "parameter_cases": [self._generic_case(), *(c.to_json() for c in self.parameter_cases)],
            "mode_analysis": mode_json,
        }
        return out

    def _generic_case(self) -> dict:
        return {"condition": "generic wave vector" if self.theory.space else "generic",
                "stages": [{"stage": k, "constraints": [_text(c) for c in s]} for k, s in enumerate(self.stages, start=1)],
                "first_class": [_text(c) for c in self.first_class],
                "second_class": [_text(c) for c in self.second_class],
                "constraints_per_stage": self.constraints_per_stage,
                "first_class_count": self.first_class_count, "second_class_count": self.second_class_count,
                "physical_degrees_of_freedom": self.physical_degrees_of_freedom, "per": "spatial point"}

    def to_text(self) -> str:
        t = self.theory
        lines = [
            f"field theory {self.name!r}: fields {', '.join(t.field_names)}; "
            + (f"space {', '.join(t.space)}; Fourier modes, wave vector ({', '.join(k.name for k in self.wave_vector)}), "
               "d_j = i k_j" if t.space else "no spatial directions"),
            f"density: {t.density}",
            "counts per spatial point (constraints written in position space, d_x(...) = spatial derivative):",
        ]
        for k, stage in enumerate(self.stages, start=1):
            lines.append(f"  stage {k} ({'primary' if k == 1 else 'secondary' if k == 2 else 'stage ' + str(k)}): "
                         f"{len(stage)} constraint(s)")
            lines.extend(f"    {c} = 0" for c in stage)
        lines.append(f"first class: {self.first_class_count}" + (f": {', '.join(map(str, self.first_class))}" if self.first_class else ""))
        lines.append(f"second class: {self.second_class_count}" + (f": {', '.join(map(str, self.second_class))}" if self.second_class else ""))
        lines.append(f"physical degrees of freedom per spatial point: {self.physical_degrees_of_freedom}")
        if self.gauge_conditions:
            lines.append(f"gauge conditions: {', '.join(c + ' = 0' for c in self.gauge_conditions)}")
        for g in self.gauge_generators:
            lines.append(f"gauge transformation with parameter {g.parameter}(t, x):")
            lines.extend(f"  delta {name} = {value}" for name, value in g.delta.items())
        if self.parameter_cases:
            lines.append("special cases (counts per mode):")
            lines.extend(f"  {c.summary()}" for c in self.parameter_cases)
        # what the special-value search of the mode pair did not search symbolically (or at all) is said
        lines.extend(f"note (mode pair): {n}" for n in getattr(self.mode, "notes", [])
                     if n.startswith("special parameter values:"))
        return "\n".join(lines)

    def to_latex(self) -> str:
        rows = []
        for k, stage in enumerate(self.stages, start=1):
            for c in stage:
                rows.append(rf"\text{{stage {k}}} &\quad {_latex(c)} \approx 0 \\")
        rows.append(rf"\text{{first class}} &\quad {self.first_class_count} \\")
        rows.append(rf"\text{{second class}} &\quad {self.second_class_count} \\")
        rows.append(rf"\text{{degrees of freedom per point}} &\quad {self.physical_degrees_of_freedom} \\")
        for g in self.gauge_generators:
            for name, value in g.delta.items():
                rows.append(rf"\delta {latex_of_operator(name)} &= {_latex(value)} \\")
        for case in self.parameter_cases:
            if case.error is None:
                d = case.to_json()
                condition = case.condition.replace("_", r"\_")
                rows.append(rf"\text{{{condition}}} &\quad \text{{{d['physical_degrees_of_freedom']} per mode}} \\")
        return "\\begin{align*}\n" + "\n".join(rows) + "\n\\end{align*}"

    def __repr__(self) -> str:
        return (f"<FieldAnalysis {self.name!r}: constraints per stage {self.constraints_per_stage}, "
                f"{self.first_class_count} first class, {self.second_class_count} second class, "
                f"{self.physical_degrees_of_freedom} degrees of freedom per point>")


class GaugeFixedField(_Brackets):
    """A field theory in a gauge: brackets per mode, in the generic mode pair."""

    def __init__(self, unfixed: FieldAnalysis, mode: Any, conditions: tuple[str, ...]) -> None:
        self.unfixed = unfixed
        self.theory = unfixed.theory
        self.mapping = unfixed.mapping
        self.mode = mode
        self.gauge_conditions = conditions
        self.first_class = _select(self.mapping, mode.first_class)
        self.second_class = _select(self.mapping, mode.second_class)
        self.physical_degrees_of_freedom = unfixed.physical_degrees_of_freedom

    def to_json(self) -> dict:
        out = self.unfixed.to_json()
        out["gauge_conditions"] = list(self.gauge_conditions)
        out["first_class"] = [_text(c) for c in self.first_class]
        out["second_class"] = [_text(c) for c in self.second_class]
        brackets = {}
        for f in self.theory.field_names:
            for g in self.theory.field_names:
                value = self.dirac_bracket(f, momentum_name(g))
                brackets[f"{{{f}, {momentum_name(g)}}}"] = _text(value)
        out["dirac_brackets"] = brackets
        return out

    def to_text(self) -> str:
        lines = [self.unfixed.to_text(), f"gauge conditions: {', '.join(c + ' = 0' for c in self.gauge_conditions)}",
                 f"first class left: {len(self.first_class)}",
                 "Dirac brackets {f(x), g(y)}_D = K(k) delta(x - y), K as a function of the wave vector:"]
        for f in self.theory.field_names:
            for g in self.theory.field_names:
                value = self.dirac_bracket(f, momentum_name(g))
                if value != 0:
                    lines.append(f"  {{{f}, {momentum_name(g)}}}_D: {value}")
        return "\n".join(lines)

    def to_latex(self) -> str:
        rows = []
        for f in self.theory.field_names:
            for g in self.theory.field_names:
                value = self.dirac_bracket(f, momentum_name(g))
                if value != 0:
                    rows.append(rf"\{{{f}, p_{{{g}}}\}}_D &= {sympy.latex(value)} \\")
        return self.unfixed.to_latex() + "\n\\begin{align*}\n" + "\n".join(rows) + "\n\\end{align*}"


def _substituted(lagrangian: Any, symbol: sympy.Symbol, value: sympy.Expr) -> Any:
    from dirac.model.lagrangian import Lagrangian

    parameters = {p: v for p, v in lagrangian.parameters.items() if p != symbol}
    return Lagrangian(lagrangian.name, lagrangian.coordinates, lagrangian.velocities,
                      sympy.expand(lagrangian.expression.subs(symbol, value)), (), parameters, lagrangian.description)


def analyze_field_theory(theory: FieldTheory, progress: Callable[[str], None] | None = None) -> FieldAnalysis:
    """The mode-by-mode analysis of a linear field theory (:class:`FieldAnalysis`).

    Raises
    ------
    InputError
        If the density is not quadratic with constant coefficients (the message names the
        lattice road, :func:`dirac.fields.lattice.lattice`).
    """
    if not isinstance(theory, FieldTheory):
        raise InputError(f"analyze_field_theory() needs a dirac.FieldTheory, not {type(theory).__name__}")
    return FieldAnalysis(theory, progress=progress)

