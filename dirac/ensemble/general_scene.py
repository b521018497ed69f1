"""Ensemble scenes of any system a scene accepts (not only the free rigid body).

```toml
[system]
file = "double_pendulum_angles.toml"      # or name = "double_pendulum", or an inline system
parameters = { g = 9.81, l2 = "1 + 0.1*s" }   # values may be expressions of the ensemble variables

[initial]
q = { x1 = "sin(a)", y1 = "-cos(a)", x2 = "sin(a) + sin(b)", y2 = "-cos(a) - cos(b)" }
q_dot = {}                                # or p = {...}; omitted entries are 0
project = false                           # true: project each member onto the constraints

[run]
method = "rattle-2"                       # rattle-2/4/6/8, midpoint; forced: forced-rattle-2/4, conformal-2/4
dt = 2e-3
t_end = 10.0
samples = 101                             # energy and constraint errors are checked at these times

[ensemble]
grid = { a = [-3.0, 3.0, 256], b = [-3.0, 3.0, 256] }
reductions = [
  { kind = "first_crossing", name = "flip_time", expr = ["x1", "x2 - x1"], when = ["y1 > 0", "y2 - y1 > 0"] },
  "energy_error",
]
```

Reductions (each stores arrays indexed by member; a failed member is NaN, its reason in
``failures``):

* ``first_crossing`` -- ``expr`` (one expression or a list): the first time one of them
  changes sign with its ``when`` condition true (``"A > B"``, ``>=``, ``<``, ``<=``; one per
  expression or none), located between the two steps bracketing it by regula falsi on
  the straight line between the two states; NaN if none by ``t_end``.
* ``max`` / ``min`` -- of ``expr`` over every step (``t = 0`` included).
* ``final`` -- ``q`` and ``p`` at ``t_end`` (arrays ``final_q``, ``final_p``).
* ``energy_error`` -- ``max_k |E(t_k) - W(t_k) - E(0)|`` over the sample times (``W`` the
  work of the forces; 0 for an unforced system).
* ``constraint_error`` -- ``max_k`` of ``max(|chi|, |G M^{-1} p + d chi/dt|)`` over the samples.
* ``poincare`` -- the first ``count`` upward zero crossings of ``expr``
  (``expr(t_k) < 0 <= expr(t_{k+1})``): the time and the state on the line between the
  two steps where ``expr = 0`` (arrays ``<name>_t`` (count,), ``<name>_q``, ``<name>_p``
  (count, n)); NaN where fewer crossings happened.

``[[impulses]]`` tables (``t = 0.5``, ``Q = { x2 = 1.0 }``: numbers, the same for every
member) are read as a single scene reads them and make the system a forced one; each
member's steps are cut at their times as a single run's are
(:mod:`dirac.ensemble.impulse_plan`, which also says what the reductions see at a kick).

Expressions of reductions use the coordinates, their velocities ``<q>_dot``, momenta
``p_<q>``, the parameters and ``t``. A member whose reductions are all decided (its
crossings found) stops early when the scene asks for nothing that needs the rest of the
run (``max``, ``min``, ``final``, ``energy_error``, ``constraint_error``).

A Lagrangian that is not ``1/2 q_dot^T M(q) q_dot - V(q)`` (:func:`needs_analysis`: terms
linear in the velocities, gauge systems) runs, as in a single run, on the Dirac flow of its
analysis with ``midpoint`` (``analysed = True``; :mod:`dirac.ensemble.analysed_members`);
its parameters are fixed numbers and its initial state is completed on the surface, not
projected.

``[system] name = "heavy_top"`` is read by :func:`parse_heavy_top_scene` into a
:class:`HeavyTopEnsembleScene` (the keys of a single heavy-top scene, each entry a number or
an expression of the ensemble variables; reductions in the names of :func:`heavy_top_names`),
whose members :mod:`dirac.ensemble.heavy_top_members` advances.
"""

from __future__ import annotations

import hashlib
import json
import math
import re
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import numpy as np

from dirac.ensemble.variables import VariableSource, parse_variables
from dirac.errors import InputError
from dirac.io.scene import reject_unknown_keys, scene_number
from dirac.validate import unknown_name_error

__all__ = ["GeneralEnsembleScene", "HeavyTopEnsembleScene", "ReductionSpec", "parse_general_scene", "is_general_scene",
           "REDUCTION_KINDS", "heavy_top_names", "needs_analysis"]

#: Reduction kinds and the keys each takes besides ``kind`` and ``name``.
REDUCTION_KINDS: dict[str, set[str]] = {
    "first_crossing": {"expr", "when"},
    "max": {"expr"},
    "min": {"expr"},
    "final": set(),
    "energy_error": set(),
    "constraint_error": set(),
    "poincare": {"expr", "count"},
}

#: Kinds that need the whole run (a member asking for one never stops early).
WHOLE_RUN = {"max", "min", "final", "energy_error", "constraint_error"}

_RUN_KEYS = {"t_end", "method", "dt", "samples", "outputs", "newton_tolerance", "max_newton_iterations"}
_ENSEMBLE_KEYS = {"grid", "variables", "count", "seed", "chunk_size", "reductions", "reduction"}
_INITIAL_KEYS = {"q", "q_dot", "p", "project"}
_SYSTEM_KEYS = {"name", "file", "parameters", "coordinates", "lagrangian", "constraints", "forces", "description",
                "time"}

_COMPARISON = re.compile(r"^(.*?)(>=|<=|>|<)(.*)$")


def is_general_scene(data: dict) -> bool:
    """Whether an ensemble scene's ``[system]`` is anything but the built-in free rigid body."""
    system = data.get("system", {})
    if not isinstance(system, dict):
        return False
    return bool({"file", "lagrangian"} & set(system)) or system.get("name", "rigid_body") != "rigid_body"


@dataclass(frozen=True)
class ReductionSpec:
    """One reduction of a general ensemble scene (module docstring).

    Attributes
    ----------
    kind : str
    name : str
        The array name (or stem: ``final``, ``poincare``).
    exprs : tuple of str
    whens : tuple of (str or None)
        One per expression (``first_crossing``).
    count : int
        Crossings kept (``poincare``).
    """

    kind: str
    name: str
    exprs: tuple[str, ...] = ()
    whens: tuple[str | None, ...] = ()
    count: int = 0

    def arrays(self, n: int) -> dict[str, tuple[int, ...]]:
        """Array name -> shape of one member's entry (``n`` coordinates)."""
        if self.kind == "final":
            return {"final_q": (n,), "final_p": (n,)}
        if self.kind == "poincare":
            return {f"{self.name}_t": (self.count,), f"{self.name}_q": (self.count, n), f"{self.name}_p": (self.count, n)}
        return {self.name: ()}

    def describe(self) -> dict[str, object]:
        return {"kind": self.kind, "name": self.name, "expr": list(self.exprs),
                "when": [w or "" for w in self.whens], "count": self.count}


@dataclass(frozen=True)
class GeneralEnsembleScene:
    """A validated ensemble scene of a general system (module docstring).

    The system itself is rebuilt from ``system`` (the scene's table) in every process that
    computes chunks (:func:`dirac.ensemble.general_kernel.compiled_ensemble`, cached per
    process), so the scene is plain data that pickles to dask workers.
    """

    system: dict
    base_dir: str
    coordinate_names: tuple[str, ...]
    parameter_names: tuple[str, ...]
    forced: bool
    source: VariableSource
    initial_q: dict
    initial_rates: dict
    rate_kind: str
    parameters: dict
    project: bool
    method: str
    order: int
    dt: float
    dt_requested: float
    t_end: float
    samples: int
    steps_per_sample: int
    reductions: tuple[ReductionSpec, ...]
    newton_tolerance: float = 1e-12
    max_newton_iterations: int = 50
    chunk_size: int | None = None
    path: str | None = None
    outputs: tuple[str, ...] = field(default=())
    system_digest: str = ""
    analysed: bool = False
    impulses: tuple[tuple[float, tuple[float, ...]], ...] = ()

    general = True

    @property
    def count(self) -> int:
        return self.source.count

    @property
    def steps(self) -> int:
        """Steps per member when it runs to ``t_end``."""
        return self.steps_per_sample * (self.samples - 1)

    @property
    def early_stop(self) -> bool:
        """Whether a member stops once its crossings are found."""
        return not any(r.kind in WHOLE_RUN for r in self.reductions)

    def times(self) -> np.ndarray:
        from dirac.flows.integration import sample_times

        return sample_times(self.t_end, self.samples)

    def step_grid(self) -> tuple[np.ndarray, np.ndarray, int, float]:
        """``(starts, ends, steps per interval, dt)`` exactly as :func:`dirac.flows.integrate` cuts
        ``[0, t_end]`` (its sample grid and step), so members step at the times a single run does."""
        times = self.times()
        spacing = float(times[1] - times[0])
        per_interval = max(1, int(math.ceil(spacing / self.dt_requested * (1.0 - 1e-12))))
        return np.ascontiguousarray(times[:-1]), np.ascontiguousarray(times[1:]), per_interval, spacing / per_interval

    def array_layout(self) -> dict[str, tuple[int, ...]]:
        """Array name -> shape of one member's entry, for every array the store holds."""
        n = len(self.coordinate_names)
        layout: dict[str, tuple[int, ...]] = {name: () for name in self.source.names}
        for reduction in self.reductions:
            layout.update(reduction.arrays(n))
        layout["failures"] = ()
        layout["steps"] = ()
        return layout

    def describe(self) -> dict[str, object]:
        return {
            "system": {k: v for k, v in self.system.items() if k != "file"},
            "system_digest": self.system_digest,
            "coordinates": list(self.coordinate_names),
            "variables": self.source.describe(),
            "count": self.count,
            "initial": {"q": self.initial_q, self.rate_kind: self.initial_rates, "project": self.project},
            "parameters": self.parameters,
            "method": self.method,
            "order": self.order,
            "dt": self.dt,
            "dt_requested": self.dt_requested,
            "t_end": self.t_end,
            "samples": self.samples,
            "steps_per_sample": self.steps_per_sample,
            "newton_tolerance": self.newton_tolerance,
            "max_newton_iterations": self.max_newton_iterations,
            "reductions": [r.describe() for r in self.reductions],
            # only when set: the fingerprints of stores written before analysed systems stay
            **({"analysed": True} if self.analysed else {}),
            **({"impulses": [[t, list(vector)] for t, vector in self.impulses]} if self.impulses else {}),
        }

    def fingerprint(self) -> str:
        """SHA-256 of :meth:`describe` (a resumed run must match it)."""
        return hashlib.sha256(json.dumps(self.describe(), sort_keys=True, default=str).encode()).hexdigest()


def load_lagrangian(system: dict, base_dir: str | Path, where: str = "[system]") -> Any:
    """The Lagrangian of a scene's ``[system]`` table: ``name``, ``file`` or an inline system."""
    from dirac.model.system_file import lagrangian_from_table
    from dirac.model.systems import builtin_systems, load_system

    if "file" in system:
        file = Path(str(system["file"]))
        if not file.is_absolute():
            file = Path(base_dir) / file
        if not file.exists():
            raise InputError(f"{where} file {str(system['file'])!r} does not exist; give a path relative to the scene file")
        return load_system(file)
    if "lagrangian" in system:
        table = {k: v for k, v in system.items() if k != "file"}
        if isinstance(table.get("parameters"), dict):  # values that vary over the ensemble are set per member
            table["parameters"] = {k: 1.0 if isinstance(v, str) else v for k, v in table["parameters"].items()}
        return lagrangian_from_table(table, source=where)
    name = system.get("name")
    if not isinstance(name, str):
        raise InputError(f"{where} needs name (a built-in system), file (a system file) or an inline system")
    if name == "heavy_top":  # an ensemble scene of the top is read by parse_heavy_top_scene, without a Lagrangian
        raise InputError(f"{where} name = 'heavy_top' is the numerical heavy top, not a Lagrangian system; "
                         "write the top as a system file (Euler angles) to analyse it as one")
    known = builtin_systems()
    if name not in known:
        raise unknown_name_error("system", name, [*known, "rigid_body"], f"{where} name", hint="or give file = a system file")
    return load_system(name)


def _expression_value(value: object, where: str) -> float | str:
    if isinstance(value, str):
        return value
    return scene_number(value, where)


def _table_of_values(value: object, key: str, names: tuple[str, ...]) -> dict[str, float | str]:
    where = f"[initial] {key}"
    if isinstance(value, list):
        if len(value) != len(names):
            raise InputError(f"{where} has {len(value)} entries; give one per coordinate ({', '.join(names)})")
        value = dict(zip(names, value))
    if not isinstance(value, dict):
        raise InputError(f"{where} must be a table {{ {names[0]} = ... }} (numbers or expressions of the ensemble variables)")
    for name in value:
        if name not in names:
            raise unknown_name_error("coordinate", name, names, where)
    return {name: _expression_value(v, f"{where}.{name}") for name, v in value.items()}


def _reduction(item: object, position: int) -> ReductionSpec:
    where = f"[ensemble] reduction {position + 1}"
    if isinstance(item, str):
        item = {"kind": item}
    if not isinstance(item, dict) or "kind" not in item:
        raise InputError(f"{where} must be a kind ({', '.join(REDUCTION_KINDS)}) or a table with kind = ...")
    kind = item["kind"]
    if kind not in REDUCTION_KINDS:
        raise unknown_name_error("reduction", str(kind), REDUCTION_KINDS, where)
    reject_unknown_keys(item, {"kind", "name", *REDUCTION_KINDS[kind]}, f"{where} ({kind})")
    name = item.get("name", kind)
    if not isinstance(name, str) or not re.fullmatch(r"[A-Za-z_][A-Za-z0-9_]*", name):
        raise InputError(f"{where}: name = {name!r} must be an identifier (letters, digits, _)")
    exprs: tuple[str, ...] = ()
    whens: tuple[str | None, ...] = ()
    count = 0
    if "expr" in REDUCTION_KINDS[kind]:
        raw = item.get("expr")
        if raw is None:
            raise InputError(f"{where} ({kind}) needs expr = \"...\" (an expression of the state)")
        listed = raw if isinstance(raw, list) and kind == "first_crossing" else [raw]
        if not listed or not all(isinstance(e, str) for e in listed):
            raise InputError(f"{where} ({kind}): expr must be a string" + (" or a list of strings" if kind == "first_crossing" else ""))
        exprs = tuple(listed)
    if kind == "first_crossing":
        when = item.get("when")
        if when is None:
            whens = (None,) * len(exprs)
        else:
            listed_when = when if isinstance(when, list) else [when]
            if len(listed_when) != len(exprs) or not all(isinstance(w, str) for w in listed_when):
                raise InputError(f"{where}: give one when = \"A > B\" per expression ({len(exprs)}), as a list of strings")
            whens = tuple(w if w.strip() else None for w in listed_when)
    if kind == "poincare":
        count = item.get("count", 1)
        if isinstance(count, bool) or not isinstance(count, int) or count < 1:
            raise InputError(f"{where} (poincare): count = {count!r} must be an integer >= 1")
    return ReductionSpec(str(kind), name, exprs, whens, int(count))


def split_condition(text: str, where: str) -> tuple[str, str, str]:
    """``"A > B"`` -> ``("A", ">", "B")``; refuses a condition without one comparison."""
    match = _COMPARISON.match(text)
    if match is None or any(op in match.group(3) for op in "<>"):
        raise InputError(f"{where}: when = {text!r} must compare two expressions once: 'A > B', 'A >= B', 'A < B' or 'A <= B'")
    return match.group(1), match.group(2), match.group(3)


def parse_general_scene(data: dict, base_dir: str | Path = ".", path: str | None = None) -> GeneralEnsembleScene:
    """Validate an ensemble scene of a general system (module docstring).

    Every expression is parsed here against the names it may use, so a misspelt or
    undefined name is refused before anything runs.

    Raises
    ------
    InputError
        Any invalid key or value, named with the fix.
    """
    from dirac.flows.mechanics import resolve_parameters
    from dirac.model.expressions import parse_expression

    for section in ("system", "initial", "run", "ensemble"):
        if not isinstance(data.get(section), dict):
            raise InputError(f"an ensemble scene needs a [{section}] table; see docs/ensembles.md")
    if is_heavy_top_scene(data):
        return parse_heavy_top_scene(data, base_dir, path)
    reject_unknown_keys(data, {"system", "initial", "run", "ensemble", "impulses"}, "the scene", kind="section")
    system, initial, run, ensemble = data["system"], data["initial"], data["run"], data["ensemble"]
    reject_unknown_keys(system, _SYSTEM_KEYS, "[system]")
    reject_unknown_keys(initial, _INITIAL_KEYS, "[initial]")
    reject_unknown_keys(run, _RUN_KEYS, "[run]")
    reject_unknown_keys(ensemble, _ENSEMBLE_KEYS, "[ensemble]")
    lagrangian = load_lagrangian(system, base_dir)
    names = tuple(s.name for s in lagrangian.coordinates)
    parameter_names = tuple(s.name for s in lagrangian.parameters)
    source = parse_variables(ensemble)
    import sympy

    for name in source.names:
        if name in ("failures", "steps", "t") or not re.fullmatch(r"[A-Za-z_][A-Za-z0-9_]*", name):
            raise InputError(f"[ensemble] variable {name!r}: give an identifier other than failures, steps and t "
                             "(the store's own arrays)")
    variables = {name: sympy.Symbol(name, real=True) for name in source.names}
    hint = f"define it under [ensemble] grid or [ensemble.variables] (the ensemble variables are: {', '.join(source.names) or 'none'})"

    def check(text: float | str, where: str) -> None:
        if isinstance(text, str):
            parse_expression(text, variables, what=where, unknown_hint=hint)

    overrides = system.get("parameters", {})
    if not isinstance(overrides, dict):
        raise InputError("[system] parameters must be a table, e.g. { l = 2.0 }")
    parameters: dict[str, float | str] = {}
    for key, value in overrides.items():
        if key not in parameter_names:
            raise unknown_name_error("parameter", key, parameter_names, f"[system] parameters of {lagrangian.name!r}")
        parameters[key] = _expression_value(value, f"[system] parameters.{key}")
        check(parameters[key], f"[system] parameters.{key}")
    resolve_parameters(lagrangian, {k: 1.0 for k in parameters})  # every parameter has a value
    if "q" not in initial:
        raise InputError(f"[initial] lacks q (the coordinates {', '.join(names)})")
    initial_q = _table_of_values(initial["q"], "q", names)
    missing = [n for n in names if n not in initial_q]
    if missing:
        raise InputError(f"[initial] q lacks {', '.join(missing)}")
    if "q_dot" in initial and "p" in initial:
        raise InputError("[initial] gives both q_dot and p; give one of them")
    rate_kind = "p" if "p" in initial else "q_dot"
    rates = _table_of_values(initial.get(rate_kind, {}), rate_kind, names)
    for key, value in [*((f"[initial] q.{k}", v) for k, v in initial_q.items()),
                       *((f"[initial] {rate_kind}.{k}", v) for k, v in rates.items())]:
        check(value, key)
    project = initial.get("project", False)
    if not isinstance(project, bool):
        raise InputError(f"[initial] project = {project!r} must be true or false")

    impulses = _impulses(data.get("impulses", []), names, source.names)
    forced = bool(lagrangian.is_forced) or bool(impulses)  # as a single scene: impulses make the problem forced
    analysed = _analysed_system(lagrangian, forced, parameters, project)
    method, order = _method(run, forced, analysed)
    if "dt" not in run:
        raise InputError("[run] needs 'dt' (the fixed step)")
    dt = scene_number(run["dt"], "[run] dt", positive=True)
    if "t_end" not in run:
        raise InputError("[run] needs 't_end'")
    t_end = scene_number(run["t_end"], "[run] t_end", positive=True)
    late = [t for t, _ in impulses if t > t_end]
    if late:  # the words of a single run (dirac.flows.integrate)
        from dirac.errors import warn

        warn(f"impulses at t = {', '.join(f'{t:g}' for t in late)} come after t_end = {t_end:g}: they are not applied")
    samples = run.get("samples", 101)
    if isinstance(samples, bool) or not isinstance(samples, int) or samples < 2:
        raise InputError(f"[run] samples = {samples!r} must be an integer >= 2")
    outputs = run.get("outputs", [])
    if outputs:
        raise InputError("[run] outputs (full trajectories) are not stored by ensembles of general systems; "
                         "ask for reductions (final, max, min, poincare, ...) under [ensemble] reductions")
    spacing = t_end / (samples - 1)
    steps_per_sample = max(1, math.ceil(spacing / dt * (1.0 - 1e-12)))
    tolerance = scene_number(run.get("newton_tolerance", 1e-12), "[run] newton_tolerance", positive=True)
    iterations = run.get("max_newton_iterations", 50)
    if isinstance(iterations, bool) or not isinstance(iterations, int) or iterations < 1:
        raise InputError(f"[run] max_newton_iterations = {iterations!r} must be an integer >= 1")

    listed = ensemble.get("reductions", [])
    tables = ensemble.get("reduction", [])
    if not isinstance(listed, list) or not isinstance(tables, list):
        raise InputError("[ensemble] reductions must be a list (of kinds or tables); [[ensemble.reduction]] tables")
    reductions = tuple(_reduction(item, i) for i, item in enumerate([*listed, *tables]))
    if not reductions:
        raise InputError(f"the scene asks for nothing: give [ensemble] reductions (from {', '.join(REDUCTION_KINDS)})")
    state = _state_names(lagrangian)
    taken: dict[str, str] = {name: "an ensemble variable" for name in source.names}
    for reduction in reductions:
        for array in reduction.arrays(len(names)):
            if array in taken or array in ("failures", "steps", "t"):
                raise InputError(f"[ensemble] reduction {reduction.kind!r}: the array name {array!r} is taken "
                                 f"({taken.get(array, 'by the store')}); give it another name = ...")
            taken[array] = f"reduction {reduction.kind}"
        for k, text in enumerate(reduction.exprs):
            where = f"[ensemble] reduction {reduction.name} expr"
            parse_expression(text, state, what=where, unknown_hint="reductions use coordinates, <q>_dot, p_<q>, parameters and t")
            when = reduction.whens[k] if reduction.whens else None
            if when is not None:
                for side in split_condition(when, where)[0::2]:
                    parse_expression(side, state, what=f"[ensemble] reduction {reduction.name} when",
                                     unknown_hint="conditions use coordinates, <q>_dot, p_<q>, parameters and t")
    chunk_size = ensemble.get("chunk_size")
    if chunk_size is not None and (isinstance(chunk_size, bool) or not isinstance(chunk_size, int) or chunk_size < 1):
        raise InputError(f"[ensemble] chunk_size = {chunk_size!r} must be an integer >= 1")
    digest = ""
    if "file" in system:
        file = Path(str(system["file"]))
        file = file if file.is_absolute() else Path(base_dir) / file
        digest = hashlib.sha256(file.read_bytes()).hexdigest()
    return GeneralEnsembleScene(
        system=dict(system), base_dir=str(Path(base_dir).resolve()), coordinate_names=names,
        parameter_names=parameter_names, forced=forced, source=source, initial_q=initial_q,
        initial_rates=rates, rate_kind=rate_kind, parameters=parameters, project=project, method=method,
        order=order, dt=spacing / steps_per_sample, dt_requested=dt, t_end=t_end, samples=samples,
        steps_per_sample=steps_per_sample, reductions=reductions, newton_tolerance=tolerance,
        max_newton_iterations=iterations, chunk_size=chunk_size, path=path, system_digest=digest,
        analysed=analysed, impulses=impulses,
    )


def _impulses(tables: object, names: tuple[str, ...], variables: tuple[str, ...]
              ) -> tuple[tuple[float, tuple[float, ...]], ...]:
    """The scene's ``[[impulses]]`` (``t`` > 0 and ``Q = { x = 1.0 }``, read as a single scene
    reads them) as ``(t, J)`` with ``J`` one entry per coordinate, sorted by time (those at
    one time in the order given, as :class:`dirac.flows.problems.ForcedProblem` sorts them).
    Their times and values are numbers, the same for every member: an expression of the
    ensemble variables is refused with the way out."""
    from dirac.io.scene import _impulse_tables

    if isinstance(tables, list):
        for k, table in enumerate(tables, start=1):
            entries = [("t", table.get("t"))] if isinstance(table, dict) else []
            if isinstance(table, dict) and isinstance(table.get("Q"), dict):
                entries += [(f"Q.{key}", value) for key, value in table["Q"].items()]
            for key, value in entries:
                if isinstance(value, str):
                    raise InputError(
                        f"[[impulses]] {k} {key} = {value!r}: the impulses of an ensemble are numbers, the same for "
                        f"every member (expressions of the ensemble variables {', '.join(variables) or '(none)'} are "
                        "not taken there); give a number, and run one ensemble per value, or vary the initial "
                        "q_dot instead")
    result = []
    for k, (time, values) in enumerate(_impulse_tables(tables, "the scene"), start=1):
        for key in values:
            if key not in names:
                raise unknown_name_error("coordinate", key, names, f"[[impulses]] {k} Q")
        result.append((time, tuple(float(values.get(name, 0.0)) for name in names)))
    return tuple(sorted(result, key=lambda impulse: impulse[0]))


def _state_names(lagrangian: Any) -> dict[str, Any]:
    """The names a reduction may use -> symbols: coordinates, ``<q>_dot``, ``p_<q>``, parameters, ``t``."""
    import sympy

    names: dict[str, Any] = {}
    for s in lagrangian.coordinates:
        names[s.name] = s
        names[f"{s.name}_dot"] = sympy.Symbol(f"{s.name}_dot", real=True)
        names[f"p_{s.name}"] = sympy.Symbol(f"p_{s.name}", real=True)
    for s in lagrangian.parameters:
        names[s.name] = s
    names["t"] = lagrangian.time if lagrangian.time is not None else sympy.Symbol("t", real=True)
    return names


def needs_analysis(lagrangian: Any) -> bool:
    """Whether a single run integrates ``lagrangian`` on the Dirac flow of its analysis:
    the form ``1/2 q_dot^T M(q) q_dot - V(q)`` that :class:`dirac.flows.mechanics.MechanicalSystem`
    takes fails (a kinetic term not quadratic in the velocities, or terms linear in them).

    The same two tests as :meth:`MechanicalSystem.from_lagrangian` makes before it refuses
    with :class:`~dirac.flows.mechanics.NotMechanicalError`, without generating its kernels.
    """
    import sympy

    from dirac.flows.mechanics import _split_by_velocities

    velocities = list(lagrangian.velocities)
    hessian, gradient_at_rest, _ = _split_by_velocities(sympy.expand(lagrangian.expression), velocities)
    if any(entry.free_symbols & set(velocities) for entry in hessian):
        return True
    at_rest = {s: 0 for s in velocities}
    return any(term != 0 and sympy.simplify(term.subs(at_rest)) != 0 for term in gradient_at_rest)


def _analysed_system(lagrangian: Any, forced: bool, parameters: dict, project: bool) -> bool:
    """Whether the members run on the Dirac flow of the system's analysis, as a single run of
    it does (a Lagrangian not of the form ``1/2 q_dot^T M(q) q_dot - V(q)``:
    :func:`needs_analysis`); refuses what such an ensemble
    cannot take, with the message of a single scene where it refuses the same."""
    if not needs_analysis(lagrangian):
        return False
    if forced:  # the words of a single scene (dirac.io.scene)
        from dirac.flows.mechanics import MechanicalSystem, NotMechanicalError

        try:
            MechanicalSystem.from_lagrangian(lagrangian, {k: 1.0 for k in parameters}, with_forces=True)
        except NotMechanicalError as exc:
            raise InputError("forces and impulses are integrated for L = 1/2 q_dot^T M(q) q_dot - V(q) only; "
                             f"{exc}".replace('; use method = "midpoint" on the Dirac flow instead', "")) from None
    varying = [key for key, value in parameters.items() if isinstance(value, str)]
    if varying:
        raise InputError(f"[system] parameters {', '.join(varying)} of {lagrangian.name!r} vary over the ensemble, but "
                         "this system runs on the Dirac flow of its analysis, which is made with its parameters "
                         "fixed (as in a single run); give them numbers, and run one ensemble per value")
    if project:
        raise InputError(f"[initial] project = true: {lagrangian.name!r} runs on the Dirac flow of its analysis, whose "
                         "initial state is completed on the constraint surface from q and q_dot (or p), as in a single "
                         "run; set project = false and give values on the surface")
    return True


def _method(run: dict, forced: bool, analysed: bool = False) -> tuple[str, int]:
    """The step method of a member and its order. On a forced system the ordinary names
    ``rattle-2`` and ``rattle-4`` run as ``forced-rattle-2`` and ``forced-rattle-4``, as
    :func:`dirac.flows.integrate` runs them on a forced problem (the same stepper)."""
    from dirac.flows.methods.forced_ordinary import FORCED_VERSIONS
    from dirac.flows.methods.registry import get_method

    usable = ["forced-rattle-2", "forced-rattle-4", "conformal-2", "conformal-4"] if forced else \
        ["midpoint"] if analysed else ["rattle-2", "rattle-4", "rattle-6", "rattle-8", "midpoint"]
    name = run.get("method", "auto")
    if name == "auto":
        name = usable[0]
    if forced and name in FORCED_VERSIONS:
        name = FORCED_VERSIONS[name]
    if name not in usable:
        kind = "a forced system" if forced else "an ensemble of this system"
        if analysed:
            raise InputError(f"[run] method = {name!r} is not available for an ensemble of this system: it runs on the "
                             "Dirac flow of its analysis (not L = 1/2 q_dot^T M(q) q_dot - V(q)), which ensembles "
                             "integrate with 'midpoint'; choose 'auto' or 'midpoint'")
        names = [*FORCED_VERSIONS, *usable] if forced else usable
        raise InputError(f"[run] method = {name!r} is not available for {kind}; choose 'auto' or one of {names}")
    return str(name), int(get_method(name).order)


# ----------------------------------------------------------------------------- the heavy top
# ``[system] name = "heavy_top"`` in an ensemble scene: the keys of a single heavy-top scene
# (dirac.io.scene), any number of which may be expressions of the ensemble variables; its
# members are advanced by dirac.ensemble.heavy_top_members.

_TOP_SYSTEM_KEYS = {"name", "inertia", "mass_gravity", "center_of_mass", "description"}
_TOP_INITIAL_KEYS = {"M", "omega", "m", "R"}
_TOP_RUN_KEYS = {"t_end", "method", "dt", "samples", "outputs", "newton_tolerance", "max_newton_iterations"}

#: The parameters of a heavy top, in the order of a member's parameter row.
TOP_PARAMETERS = ("I_1", "I_2", "I_3", "mass_gravity", "chi_1", "chi_2", "chi_3")


def is_heavy_top_scene(data: dict) -> bool:
    """Whether an ensemble scene's ``[system]`` is the built-in heavy top."""
    system = data.get("system", {})
    return isinstance(system, dict) and not ({"file", "lagrangian"} & set(system)) and system.get("name") == "heavy_top"


def heavy_top_names() -> dict[str, Any]:
    """The names a heavy-top reduction may use -> sympy expressions of the state.

    The state is ``M_i`` (body angular momentum) and ``R_ij`` (attitude, body to lab); the
    parameters ``I_i``, ``mass_gravity`` (``m g``) and ``chi_i`` (centre of mass, body
    frame). Derived: ``gamma_i = R_3i`` (``gamma = R^T e_z``), ``Omega_i = M_i / I_i``, and
    the heavy top's outputs of :func:`dirac.integrate`: ``energy = sum M_i^2 / (2 I_i) +
    m g <chi, gamma>`` and ``lab_momentum_z = <gamma, M>``; ``t``. Each indexed name is also
    accepted without its underscore (``M3``, ``gamma3``, ``R31``, ``I1``).
    """
    import sympy

    symbol = {name: sympy.Symbol(name, real=True) for name in
              [*(f"M_{i}" for i in (1, 2, 3)), *(f"R_{i}{j}" for i in (1, 2, 3) for j in (1, 2, 3)),
               *TOP_PARAMETERS, "t"]}
    names: dict[str, Any] = dict(symbol)
    for i in (1, 2, 3):
        names[f"gamma_{i}"] = symbol[f"R_3{i}"]
        names[f"Omega_{i}"] = symbol[f"M_{i}"] / symbol[f"I_{i}"]
    names["energy"] = sum(symbol[f"M_{i}"] ** 2 / (2 * symbol[f"I_{i}"]) for i in (1, 2, 3)) + symbol["mass_gravity"] * sum(
        symbol[f"chi_{i}"] * symbol[f"R_3{i}"] for i in (1, 2, 3))
    names["lab_momentum_z"] = sum(symbol[f"R_3{i}"] * symbol[f"M_{i}"] for i in (1, 2, 3))
    for name in list(names):
        if "_" in name and name[-1].isdigit() and name.split("_")[0] in ("M", "R", "gamma", "Omega", "I", "chi"):
            names[name.replace("_", "")] = names[name]
    return names


@dataclass(frozen=True)
class HeavyTopEnsembleScene(GeneralEnsembleScene):
    """A validated ensemble scene of the heavy top (see :func:`parse_heavy_top_scene`).

    ``parameters`` holds the top's numbers by the names of :data:`TOP_PARAMETERS` (numbers
    or expressions of the ensemble variables); ``initial_momentum`` the three entries of
    ``[initial] M`` (or ``omega``, ``m``: ``rate_kind``), ``initial_R`` the nine of ``R``.
    """

    initial_momentum: tuple[float | str, ...] = ()
    initial_R: tuple[tuple[float | str, ...], ...] = ()
    torque: tuple[str, ...] | None = None
    impulses: tuple[tuple[float, tuple[float, ...]], ...] = ()

    heavy_top = True

    @property
    def driven(self) -> bool:
        """Whether a torque or angular impulses act (the single run's driven step)."""
        return self.torque is not None or bool(self.impulses)

    def array_layout(self) -> dict[str, tuple[int, ...]]:
        """Array name -> shape of one member's entry: ``final`` gives ``final_M`` (3,) and
        ``final_R`` (3, 3); ``poincare`` gives ``<name>_t``, ``<name>_M``, ``<name>_R``."""
        layout: dict[str, tuple[int, ...]] = {name: () for name in self.source.names}
        for reduction in self.reductions:
            layout.update(top_arrays(reduction))
        layout["failures"] = ()
        layout["steps"] = ()
        return layout

    def describe(self) -> dict[str, object]:
        described = super().describe()
        described["initial"] = {self.rate_kind: list(self.initial_momentum), "R": [list(row) for row in self.initial_R]}
        described["heavy_top"] = True  # its Poincaré sections are stored as <name>_M and <name>_R
        if self.torque is not None:  # (absent for an undriven top: the fingerprints of earlier stores hold)
            described["torque"] = list(self.torque)
        if self.impulses:
            described["impulses"] = [[t, list(vector)] for t, vector in self.impulses]
        return described


def top_arrays(reduction: ReductionSpec) -> dict[str, tuple[int, ...]]:
    """The arrays a heavy-top reduction stores: name -> shape of one member's entry."""
    if reduction.kind == "final":
        return {"final_M": (3,), "final_R": (3, 3)}
    if reduction.kind == "poincare":
        return {f"{reduction.name}_t": (reduction.count,), f"{reduction.name}_M": (reduction.count, 3),
                f"{reduction.name}_R": (reduction.count, 3, 3)}
    return {reduction.name: ()}


def _top_entries(value: object, where: str, shape: tuple[int, ...]) -> tuple:
    """A vector (3,) or matrix (3, 3) whose entries are numbers or expressions (strings)."""
    label = f"{where} must be {'a list of 3' if len(shape) == 1 else 'a 3 x 3 list of lists of'} numbers or expressions"
    if not isinstance(value, list) or len(value) != shape[0]:
        raise InputError(label)
    if len(shape) == 1:
        return tuple(_expression_value(v, f"{where}[{k}]") for k, v in enumerate(value))
    return tuple(_top_entries(row, f"{where}[{k}]", shape[1:]) for k, row in enumerate(value))


def parse_heavy_top_scene(data: dict, base_dir: str | Path = ".", path: str | None = None) -> HeavyTopEnsembleScene:
    """Validate an ensemble scene of the heavy top.

    ``[system]`` takes the keys of a single heavy-top scene (``inertia``, ``mass_gravity``,
    ``center_of_mass``), ``[initial]`` one of ``M``, ``omega`` (``M = I omega``) or ``m``
    (lab, ``M = R^T m``) and ``R`` (default the identity); every entry may be an
    expression of the ensemble variables. ``[run] method`` is a ``lie-poisson-*`` method
    (kick + Lie–Poisson free step) or ``exact-kick-*`` (kick + exact free flow), as for a
    single heavy-top run; ``auto`` means ``lie-poisson-2``. Reductions use the names of :func:`heavy_top_names`.

    Raises
    ------
    InputError
        Any invalid key or value, or an expression with an unknown name, named with the fix.
    """
    import sympy

    from dirac.model.expressions import parse_expression
    from dirac.rigidbody.schemes import SCHEMES

    reject_unknown_keys(data, {"system", "initial", "run", "ensemble", "forces", "impulses"}, "the scene", kind="section")
    system, initial, run, ensemble = data["system"], data["initial"], data["run"], data["ensemble"]
    reject_unknown_keys(system, _TOP_SYSTEM_KEYS, "[system]")
    reject_unknown_keys(initial, _TOP_INITIAL_KEYS, "[initial]")
    reject_unknown_keys(run, _TOP_RUN_KEYS, "[run]")
    reject_unknown_keys(ensemble, _ENSEMBLE_KEYS, "[ensemble]")
    source = parse_variables(ensemble)
    for name in source.names:
        if name in ("failures", "steps", "t") or not re.fullmatch(r"[A-Za-z_][A-Za-z0-9_]*", name):
            raise InputError(f"[ensemble] variable {name!r}: give an identifier other than failures, steps and t "
                             "(the store's own arrays)")
    variables = {name: sympy.Symbol(name, real=True) for name in source.names}
    hint = f"define it under [ensemble] grid or [ensemble.variables] (the ensemble variables are: {', '.join(source.names) or 'none'})"

    if "inertia" not in system:
        raise InputError("[system] lacks 'inertia' (the principal moments [I1, I2, I3] about the fixed point)")
    inertia = _top_entries(system["inertia"], "[system] inertia", (3,))
    weight = _expression_value(system.get("mass_gravity", 1.0), "[system] mass_gravity")
    chi = _top_entries(system.get("center_of_mass", [0.0, 0.0, 1.0]), "[system] center_of_mass", (3,))
    parameters: dict[str, float | str] = dict(zip(TOP_PARAMETERS, (*inertia, weight, *chi)))
    given = [key for key in ("M", "omega", "m") if key in initial]
    if len(given) != 1:
        raise InputError("[initial] must give exactly one of M (body angular momentum), omega (body angular velocity) "
                         f"or m (lab angular momentum); it gives {', '.join(given) or 'none'}")
    momentum = _top_entries(initial[given[0]], f"[initial] {given[0]}", (3,))
    attitude = _top_entries(initial.get("R", [[1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]]), "[initial] R", (3, 3))
    checks = [*((f"[system] {key}", value) for key, value in parameters.items()),
              *((f"[initial] {given[0]}[{k}]", value) for k, value in enumerate(momentum)),
              *((f"[initial] R[{i}][{j}]", value) for i, row in enumerate(attitude) for j, value in enumerate(row))]
    for where, value in checks:
        if isinstance(value, str):
            parse_expression(value, variables, what=where, unknown_hint=hint)

    from dirac.flows.methods.registry import get_method

    method = run.get("method", "auto")
    method = "lie-poisson-2" if method == "auto" else method
    usable = [*SCHEMES, *(f"exact-kick-{order}" for order in (2, 4, 6, 8))]
    if method not in usable:
        raise unknown_name_error("method", str(method), usable, "[run] method of a heavy-top ensemble")
    if "dt" not in run:
        raise InputError("[run] needs 'dt' (the fixed step)")
    dt = scene_number(run["dt"], "[run] dt", positive=True)
    if "t_end" not in run:
        raise InputError("[run] needs 't_end'")
    t_end = scene_number(run["t_end"], "[run] t_end", positive=True)
    samples = run.get("samples", 101)
    if isinstance(samples, bool) or not isinstance(samples, int) or samples < 2:
        raise InputError(f"[run] samples = {samples!r} must be an integer >= 2")
    if run.get("outputs"):
        raise InputError("[run] outputs (full trajectories) are not stored by heavy-top ensembles; ask for reductions "
                         "(final, max, min, poincare, ...) under [ensemble] reductions")
    spacing = t_end / (samples - 1)
    steps_per_sample = max(1, math.ceil(spacing / dt * (1.0 - 1e-12)))
    from dirac.io.scene import rigid_drive

    torque, impulses = rigid_drive(data, t_end, "the scene")  # as a single scene reads them (expressions of the state)
    tolerance = scene_number(run.get("newton_tolerance", 1e-12), "[run] newton_tolerance", positive=True)
    iterations = run.get("max_newton_iterations", 50)
    if isinstance(iterations, bool) or not isinstance(iterations, int) or iterations < 1:
        raise InputError(f"[run] max_newton_iterations = {iterations!r} must be an integer >= 1")

    listed = ensemble.get("reductions", [])
    tables = ensemble.get("reduction", [])
    if not isinstance(listed, list) or not isinstance(tables, list):
        raise InputError("[ensemble] reductions must be a list (of kinds or tables); [[ensemble.reduction]] tables")
    reductions = tuple(_reduction(item, i) for i, item in enumerate([*listed, *tables]))
    if not reductions:
        raise InputError(f"the scene asks for nothing: give [ensemble] reductions (from {', '.join(REDUCTION_KINDS)})")
    state = heavy_top_names()
    usable_names = "reductions of a heavy top use M_i, Omega_i, R_ij, gamma_i, energy, lab_momentum_z, I_i, mass_gravity, chi_i and t"
    taken: dict[str, str] = {name: "an ensemble variable" for name in source.names}
    for reduction in reductions:
        for array in top_arrays(reduction):
            if array in taken or array in ("failures", "steps", "t"):
                raise InputError(f"[ensemble] reduction {reduction.kind!r}: the array name {array!r} is taken "
                                 f"({taken.get(array, 'by the store')}); give it another name = ...")
            taken[array] = f"reduction {reduction.kind}"
        for k, text in enumerate(reduction.exprs):
            where = f"[ensemble] reduction {reduction.name} expr"
            parse_expression(text, state, what=where, unknown_hint=usable_names)
            when = reduction.whens[k] if reduction.whens else None
            if when is not None:
                for side in split_condition(when, where)[0::2]:
                    parse_expression(side, state, what=f"[ensemble] reduction {reduction.name} when",
                                     unknown_hint=usable_names)
    chunk_size = ensemble.get("chunk_size")
    if chunk_size is not None and (isinstance(chunk_size, bool) or not isinstance(chunk_size, int) or chunk_size < 1):
        raise InputError(f"[ensemble] chunk_size = {chunk_size!r} must be an integer >= 1")
    return HeavyTopEnsembleScene(
        system=dict(system), base_dir=str(Path(base_dir).resolve()), coordinate_names=(),
        parameter_names=TOP_PARAMETERS, forced=False, source=source, initial_q={}, initial_rates={},
        rate_kind=given[0], parameters=parameters, project=False, method=str(method),
        order=int(get_method(str(method)).order), dt=spacing / steps_per_sample, dt_requested=dt, t_end=t_end,
        samples=samples, steps_per_sample=steps_per_sample, reductions=reductions, chunk_size=chunk_size, path=path,
        initial_momentum=momentum, initial_R=attitude, torque=None if torque is None else torque.texts,
        impulses=tuple((float(impulse.t), tuple(float(x) for x in impulse.vector)) for impulse in impulses),
        newton_tolerance=tolerance, max_newton_iterations=int(iterations),
    )
