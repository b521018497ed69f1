"""Scene files (docs/file_formats.md): a system, its initial state and how to run it.

```toml
[system]
name = "rigid_body"            # or "heavy_top", a built-in Lagrangian ("pendulum"), or
# file = "path/to/system.toml" # a system file (relative to the scene), or the system
                               # itself inline (coordinates, lagrangian, constraints, ...)
inertia = [2.0, 1.0, 0.6666666666666666]

[initial]
M = [0.4535961214255773, 0.0, 0.8912073600614354]   # or omega = [...] or m = [...] (lab)
R = [[1, 0, 0], [0, 1, 0], [0, 0, 1]]

[run]
t_end = 100.0
method = "auto"
dt = 0.01
tolerance = 1e-8
samples = 101
outputs = ["M", "R", "energy"]
```

A rigid-body scene gives exactly one of ``M`` (body angular momentum), ``omega`` (body
angular velocity, ``M = I omega``) or ``m`` (lab angular momentum, ``M = R^T m``). A
heavy top adds ``mass_gravity`` (``m g``) and ``center_of_mass`` (body frame) under
``[system]``. A general system gives ``q = { x = ..., ... }`` and ``q_dot = {...}`` or
``p = {...}`` (omitted velocities mean rest); initial data off the constraint surface
are refused unless ``project = true`` in ``[initial]``. A Lagrangian that is not of the
form ``1/2 q_dot^T M(q) q_dot - V(q)`` (terms linear in the velocities, singular) is
integrated on the full phase space of its Dirac–Bergmann analysis (``midpoint`` or the
scipy baselines; the multipliers are completed on the constraint surface from a fixed start, ``project = true``
is refused; outputs ``z``,
``q``, ``p``, ``energy``, ``constraint_residual``). Parameters of a Lagrangian are
overridden under ``[system] parameters``. A system with generalized forces (``forces``
in its system file or inline) or a scene with ``[[impulses]]`` (``t = 0.5``,
``Q = { x = 1.0 }``) is a :class:`~dirac.flows.problems.ForcedProblem`. Optional ``[run]`` keys: ``drift_limit``,
``newton_tolerance``, ``max_newton_iterations``. Unknown keys are errors that suggest the closest known key.

A rigid body or heavy top may be driven: ``[forces] torque = ["N1", "N2", "N3"]`` (the
external torque in the body frame, expressions in ``M_i``, ``Omega_i``, ``R_ij``, ``t``)
and ``[[impulses]]`` tables with ``t`` and ``angular_impulse = [a, b, c]`` (``M`` jumps).

This module is the one scene reader: reading the file (:func:`read_scene_file`), its
tables (:func:`scene_table`), numbers, vectors and the rigid body's inertia
(:func:`scene_number`, :func:`scene_integer`, :func:`scene_vector`,
:func:`scene_inertia`) and unknown-key errors (:func:`reject_unknown_keys`).
:mod:`dirac.ensemble.scene` reads ensemble scenes with the same helpers and adds only
what is particular to ensembles.
"""

from __future__ import annotations

import tomllib
from dataclasses import dataclass, field
from pathlib import Path
from typing import TYPE_CHECKING, Any

import numpy as np

from dirac.errors import InputError
from dirac.validate import (
    check_known_keys,
    unknown_name_error,
    validate_array,
    validate_boolean,
    validate_finite,
    validate_integer,
    validate_positive,
)

if TYPE_CHECKING:
    from dirac.flows.analysed import AnalysedProblem
    from dirac.flows.integration import RunOptions
    from dirac.flows.problems import ConstrainedProblem, RigidBodyProblem
    from dirac.model.lagrangian import Lagrangian

    SceneProblem = RigidBodyProblem | ConstrainedProblem | AnalysedProblem

__all__ = ["Scene", "load_scene", "scene_from_dict", "SCENE_SYSTEMS", "FLAGSHIP_SCENE"]

#: Numerical systems a scene can name besides the Lagrangian systems (``dirac systems``).
SCENE_SYSTEMS: dict[str, str] = {
    "rigid_body": "free asymmetric rigid body (Euler-Poisson (250)-(251)); inertia = [I1, I2, I3]; initial M, omega or m, and R",
    "heavy_top": "rigid body with a fixed point in uniform gravity; adds mass_gravity (m g) and center_of_mass (body frame)",
}

#: The flagship scene of ``dirac demo``: a homogeneous box with edges 1, 2, 3 and mass 12,
#: so mass-matrix principal values g = (1, 4, 9) (66) and I = (13, 10, 5) (72), spun
#: about its intermediate axis with a small wobble (it tumbles: the tennis-racket effect).
#: The standard test case of docs/conventions.md, I = (2, 1, 2/3), is no body; it stays
#: the body of the benchmarks and the tests.
FLAGSHIP_SCENE: dict[str, object] = {
    "system": {"name": "rigid_body", "inertia": [13.0, 10.0, 5.0]},
    "initial": {"M": [0.1, 1.0, 0.1]},
    "run": {
        "t_end": 1000.0,
        "method": "auto",
        "tolerance": 1e-10,
        "samples": 1001,
        "outputs": ["M", "R", "energy", "casimir", "lab_momentum"],
    },
}

_TOP_KEYS = {"system", "initial", "run", "description", "forces", "impulses"}
_IMPULSE_KEYS = {"t", "Q"}
_RUN_KEYS = {"t_end", "method", "dt", "tolerance", "samples", "outputs", "drift_limit", "newton_tolerance",
             "max_newton_iterations"}
_RIGID_KEYS = {"name", "inertia", "description"}
_HEAVY_KEYS = _RIGID_KEYS | {"mass_gravity", "center_of_mass"}
_LAGRANGIAN_KEYS = {"name", "file", "parameters", "coordinates", "lagrangian", "constraints", "description", "forces"}
_RIGID_INITIAL = {"M", "omega", "m", "R"}
_GENERAL_INITIAL = {"q", "q_dot", "p", "project"}


@dataclass
class Scene:
    """A parsed scene: the problem and the arguments of :func:`dirac.flows.integrate`."""

    problem: SceneProblem
    run: RunOptions
    source: str
    system: str
    meta: dict[str, object] = field(default_factory=dict)


# ----------------------------------------------------------------------------- reading helpers
# Shared by every scene reader (this module and dirac.ensemble.scene): messages name the
# scene (``source``, left out when empty), the table and the key, and say what to give.


def scene_label(source: str, name: str) -> str:
    """How a message names ``name`` (a table or key) of the scene ``source``."""
    return f"{source}: {name}" if source else name


def read_scene_file(path: str | Path) -> dict:
    """The tables of a scene file (TOML).

    Raises
    ------
    InputError
        When the file cannot be read (missing, a directory, no permission) or is not
        valid UTF-8 TOML.
    """
    path = Path(path)
    try:
        text = path.read_text(encoding="utf-8")
    except OSError as exc:
        reason = "it does not exist" if isinstance(exc, FileNotFoundError) else exc.strerror
        raise InputError(f"cannot read scene file {str(path)!r}: {reason}; check the path") from None
    except UnicodeDecodeError as exc:
        raise InputError(f"scene file {str(path)!r} is not valid TOML: {exc}") from None
    try:
        return tomllib.loads(text)
    except tomllib.TOMLDecodeError as exc:
        raise InputError(f"scene file {str(path)!r} is not valid TOML: {exc}") from None


def scene_table(data: dict, key: str, source: str = "", required: bool = True,
                hint: str = "a scene needs [system], [initial] and [run]; see docs/file_formats.md") -> dict:
    """The table ``[key]`` of a scene (``{}`` when it is absent and not ``required``).

    Raises
    ------
    InputError
        A required table is missing (the message adds ``hint``: which tables the scene
        needs and where its format is described), or ``key`` is not a table.
    """
    value = data.get(key)
    if value is None:
        if required:
            raise InputError(f"{scene_label(source, f'missing [{key}] table')} ({hint})")
        return {}
    if not isinstance(value, dict):
        raise InputError(f"{scene_label(source, f'[{key}]')} must be a table")
    return value


def reject_unknown_keys(table: dict, known: set[str], where: str, source: str = "", kind: str = "key") -> None:
    """Refuse the keys of ``table`` outside ``known`` with "did you mean" suggestions.

    Parameters
    ----------
    table : dict
        The table read.
    known : set of str
        The keys the reader uses.
    where : str
        The table in messages, e.g. ``"[run]"``.
    source : str
        The scene, named in front of the message when given.
    kind : str
        ``"key"``, or ``"section"`` for the tables of the scene itself.

    Raises
    ------
    InputError
        Naming the file, the table, each unknown key with the closest known ones, and
        the known keys (:func:`dirac.validate.check_known_keys`).
    """
    check_known_keys(table, known, where, source, kind)


def scene_number(value: object, name: str, source: str = "", positive: bool = False) -> float:
    """A finite number (``> 0`` with ``positive``) named ``name``, e.g. ``"[run] dt"``."""
    label = scene_label(source, name)
    return validate_positive(value, label) if positive else validate_finite(value, label)


def scene_integer(value: object, name: str, source: str = "", minimum: int = 1) -> int:
    """An integer ``>= minimum`` named ``name``, e.g. ``"[run] samples"``."""
    return validate_integer(value, scene_label(source, name), minimum=minimum)


def scene_vector(value: object, name: str, source: str, shape: tuple[int, ...]) -> np.ndarray:
    """A finite float64 array of the given shape named ``name``, e.g. ``"[initial] M"``."""
    return validate_array(value, scene_label(source, name), shape)


def scene_inertia(system: dict, source: str = "") -> np.ndarray:
    """The principal moments ``[system] inertia`` of a rigid-body scene, shape (3,).

    Only the numbers are checked here (shape, finiteness);
    :func:`dirac.rigidbody.inertia.validate_inertia` checks them as the moments of a body.

    Raises
    ------
    InputError
        The key is missing or is not three finite numbers.
    """
    if "inertia" not in system:
        raise InputError(scene_label(source, "[system] lacks 'inertia' (the principal moments [I1, I2, I3])"))
    return scene_vector(system["inertia"], "[system] inertia", source, (3,))


# ----------------------------------------------------------------------------- single-run scenes


def load_scene(path: str | Path) -> Scene:
    """Read and validate a scene file.

    Raises
    ------
    InputError
        Missing file, invalid TOML, missing or malformed keys, bad initial data; the
        message names the file and the key.
    """
    path = Path(path)
    return scene_from_dict(read_scene_file(path), source=str(path), base=path.parent)


def scene_from_dict(data: dict, source: str = "scene", base: Path | None = None) -> Scene:
    """Build a :class:`Scene` from the parsed TOML tables (see the module docstring)."""
    reject_unknown_keys(data, _TOP_KEYS, "the scene", source, kind="section")
    system = scene_table(data, "system", source)
    initial = scene_table(data, "initial", source)
    run_table = scene_table(data, "run", source)
    run = _run_options(run_table, source)
    name = system.get("name")
    if name in SCENE_SYSTEMS:
        rigid = _rigid_problem(str(name), system, initial, source)
        _drive(rigid, data, run["t_end"], source)
        problem: SceneProblem = rigid
    else:
        if "forces" in data:
            raise InputError(f"{source}: [forces] (torques) applies to rigid_body and heavy_top scenes; give the "
                             "forces of a Lagrangian system in its system file (forces = { x = \"...\" } under [system])")
        impulses = _impulse_tables(data.get("impulses", []), source)
        problem = _general_problem(system, initial, source, base or Path("."), impulses)
    available: tuple[str, ...] = problem.outputs
    for output in run.get("outputs", []):
        if output not in available:
            raise unknown_name_error("output", output, available, scene_label(source, "[run] outputs"),
                                     hint=f"these are the outputs of a {problem.kind.replace('_', ' ')} problem")
    meta: dict[str, object] = {"scene": source}
    return Scene(problem=problem, run=run, source=source, system=str(problem.system), meta=meta)


def _run_options(table: dict, source: str) -> RunOptions:
    reject_unknown_keys(table, _RUN_KEYS, "[run]", source)
    if "t_end" not in table:
        raise InputError(f"{source}: [run] lacks the required key 't_end' (the final time)")
    run: RunOptions = {"t_end": scene_number(table["t_end"], "[run] t_end", source, positive=True)}
    method = table.get("method", "auto")
    if not isinstance(method, str):
        raise InputError(f"{source}: [run] method must be a name (a string), e.g. \"auto\"")
    from dirac.flows.methods.registry import method_names

    if method not in method_names():
        raise unknown_name_error("method", method, method_names(), scene_label(source, "[run] method"))
    run["method"] = method
    if "dt" in table:
        run["dt"] = scene_number(table["dt"], "[run] dt", source, positive=True)
    for key in ("tolerance", "drift_limit", "newton_tolerance"):
        if key in table:
            run[key] = scene_number(table[key], f"[run] {key}", source, positive=True)
    if "samples" in table:
        run["samples"] = scene_integer(table["samples"], "[run] samples", source)
    if "max_newton_iterations" in table:
        run["max_newton_iterations"] = scene_integer(table["max_newton_iterations"], "[run] max_newton_iterations", source)
    if "outputs" in table:
        outputs = table["outputs"]
        if not isinstance(outputs, list) or not all(isinstance(o, str) for o in outputs):
            raise InputError(f"{source}: [run] outputs must be a list of names, e.g. [\"M\", \"energy\"]")
        run["outputs"] = outputs
    return run


def _rigid_problem(name: str, system: dict, initial: dict, source: str) -> RigidBodyProblem:
    from dirac.flows.problems import HeavyTopProblem, RigidBodyProblem

    reject_unknown_keys(system, _HEAVY_KEYS if name == "heavy_top" else _RIGID_KEYS, "[system]", source)
    reject_unknown_keys(initial, _RIGID_INITIAL, "[initial]", source)
    inertia = scene_inertia(system, source)
    R = scene_vector(initial["R"], "[initial] R", source, (3, 3)) if "R" in initial else np.eye(3)
    given = [key for key in ("M", "omega", "m") if key in initial]
    if len(given) != 1:
        raise InputError(
            f"{source}: [initial] must give exactly one of M (body angular momentum), omega (body angular "
            f"velocity) or m (lab angular momentum); it gives {', '.join(given) or 'none'}"
        )
    key = given[0]
    vector = scene_vector(initial[key], f"[initial] {key}", source, (3,))
    if key == "omega":
        M = inertia * vector
    elif key == "m":
        from dirac.rigidbody.inertia import validate_rotation

        M = validate_rotation(R).T @ vector
    else:
        M = vector
    if name == "heavy_top":
        weight = scene_number(system.get("mass_gravity", 1.0), "[system] mass_gravity", source)
        chi = scene_vector(system.get("center_of_mass", [0.0, 0.0, 1.0]), "[system] center_of_mass", source, (3,))
        return HeavyTopProblem(inertia, M, R, mass_gravity=weight, center_of_mass=chi)
    return RigidBodyProblem(inertia, M, R)


_RIGID_FORCE_KEYS = {"torque"}
_RIGID_IMPULSE_KEYS = {"t", "angular_impulse"}


def _drive(problem: RigidBodyProblem, data: dict, t_end: float, source: str) -> None:
    """``[forces] torque = [...]`` and ``[[impulses]]`` of a rigid-body or heavy-top scene,
    set on ``problem`` (:func:`rigid_drive`)."""
    torque, impulses = rigid_drive(data, t_end, source)
    if torque is not None:
        problem.torque = torque
    if impulses:
        problem.impulses = impulses


def rigid_drive(data: dict, t_end: float, source: str) -> tuple[Any, tuple[Any, ...]]:
    """The torque (:class:`dirac.flows.torques.Torque` or None) and the angular impulses
    (sorted, those at one time added: :func:`dirac.flows.impulses.validate_impulses`) of a
    rigid-body or heavy-top scene's ``[forces] torque = [...]`` and ``[[impulses]]``.

    Raises
    ------
    InputError
        A key, expression or number that is not valid, named with the fix.
    """
    from dirac.errors import warn
    from dirac.flows.impulses import AngularImpulse, validate_impulses

    torque = None
    forces = scene_table(data, "forces", source, required=False)
    reject_unknown_keys(forces, _RIGID_FORCE_KEYS, "[forces]", source)
    if "torque" in forces:
        components = forces["torque"]
        if not isinstance(components, list):
            raise InputError(f'{source}: [forces] torque must be a list of three expressions, e.g. ["0", "0", "-0.1*Omega_3"]')
        from dirac.flows.torques import Torque

        torque = Torque(components, source)
    tables = data.get("impulses", [])
    if not isinstance(tables, list) or not all(isinstance(table, dict) for table in tables):
        raise InputError(f"{source}: impulses must be [[impulses]] tables, each with t and angular_impulse = [a, b, c]")
    impulses = []
    for k, table in enumerate(tables, start=1):
        where = f"[[impulses]] {k}"
        reject_unknown_keys(table, _RIGID_IMPULSE_KEYS, where, source)
        for key in ("t", "angular_impulse"):
            if key not in table:
                raise InputError(f"{source}: {where} lacks {key} (give t = time and angular_impulse = [a, b, c], "
                                 "body frame)")
        t = scene_number(table["t"], f"{where} t", source)
        if t < 0:
            raise InputError(f"{source}: {where} t = {t:g} is before the start of the run; give t >= 0")
        if t > t_end:
            warn(f"{source}: {where} at t = {t:g} is after [run] t_end = {t_end:g}: it never acts")
        impulses.append(AngularImpulse(t, scene_vector(table["angular_impulse"], f"{where} angular_impulse", source,
                                                       (3,))))
    return torque, validate_impulses(impulses) if impulses else ()


def _impulse_tables(tables: object, source: str) -> list[tuple[float, dict[str, float]]]:
    """The ``[[impulses]]`` of a scene: ``t`` (> 0) and ``Q = { x = 1.0 }``, in the order given."""
    if not isinstance(tables, list) or not all(isinstance(t, dict) for t in tables):
        raise InputError(f"{source}: impulses must be [[impulses]] tables, each with t and Q = {{ x = 1.0 }}")
    result = []
    for k, table in enumerate(tables, start=1):
        where = f"[[impulses]] {k}"
        reject_unknown_keys(table, _IMPULSE_KEYS, where, source)
        for key in ("t", "Q"):
            if key not in table:
                raise InputError(f"{source}: {where} lacks {key!r} (give t = time and Q = {{ x = 1.0 }})")
        time = scene_number(table["t"], f"{where} t", source)
        if not time > 0.0:
            raise InputError(f"{source}: {where} is at t = {time:g}, not after the start t = 0: give t > 0 "
                             "(a blow at the start is an initial velocity)")
        values = table["Q"]
        if not isinstance(values, dict) or not values:
            raise InputError(f"{source}: {where} Q must be a table of coordinates, e.g. Q = {{ x = 1.0 }}")
        result.append((time, {str(key): scene_number(v, f"{where} Q.{key}", source) for key, v in values.items()}))
    return result


def _general_problem(system: dict, initial: dict, source: str, base: Path,
                     impulses: list | None = None) -> ConstrainedProblem | AnalysedProblem:
    from dirac.flows.mechanics import MechanicalSystem, NotMechanicalError
    from dirac.flows.problems import ConstrainedProblem, ForcedProblem, OffSurfaceError
    from dirac.model.system_file import lagrangian_from_table
    from dirac.model.systems import load_system

    if isinstance(system.get("name"), str) and not ({"file", "lagrangian"} & set(system)):
        from dirac.model.systems import builtin_systems

        known = (*SCENE_SYSTEMS, *builtin_systems())
        if system["name"] not in known and not system["name"].endswith((".toml", ".py")) and "/" not in system["name"]:
            raise unknown_name_error("system", system["name"], known, scene_label(source, "[system] name"),
                                     hint="or give file = a system file")
    reject_unknown_keys(system, _LAGRANGIAN_KEYS, "[system]", source)
    reject_unknown_keys(initial, _GENERAL_INITIAL, "[initial]", source)
    if "file" in system:
        file = Path(str(system["file"]))
        if not file.is_absolute():
            file = base / file
        lagrangian = load_system(file)
    elif "lagrangian" in system:
        table = {k: v for k, v in system.items() if k not in ("file",)}
        lagrangian = lagrangian_from_table(table, source=f"{source} [system]")
        system = {k: v for k, v in system.items() if k != "parameters"}  # values already in the table
    elif isinstance(system.get("name"), str):
        lagrangian = load_system(system["name"])
    else:
        raise InputError(
            f"{source}: [system] needs name (rigid_body, heavy_top or a built-in system; 'dirac systems' lists "
            "them), file (a system file) or an inline system (coordinates, lagrangian, constraints)"
        )
    overrides = system.get("parameters", {})
    if not isinstance(overrides, dict):
        raise InputError(f"{source}: [system] parameters must be a table, e.g. {{ l = 2.0 }}")
    for key in overrides:
        if key not in lagrangian.parameter_symbols:
            raise unknown_name_error("parameter", key, lagrangian.parameter_symbols,
                                     scene_label(source, f"[system] parameters of {lagrangian.name!r}"))
    forced = lagrangian.is_forced or bool(impulses)
    try:
        mechanics = MechanicalSystem.from_lagrangian(lagrangian, overrides, with_forces=forced)
    except NotMechanicalError as exc:
        if forced:
            raise InputError(
                f"{source}: forces and impulses are integrated for L = 1/2 q_dot^T M(q) q_dot - V(q) only; "
                f"{exc.reason}"
            ) from None
        return _analysed_problem(lagrangian, overrides, initial, source)
    names = mechanics.coordinate_names
    if "q" not in initial:
        raise InputError(f"{source}: [initial] lacks q (the coordinates {', '.join(names)})")
    q = _coordinates(initial["q"], "q", names, source, required=True)
    if "q_dot" in initial and "p" in initial:
        raise InputError(f"{source}: [initial] gives both q_dot and p; give one of them")
    if "p" in initial:
        p = _coordinates(initial["p"], "p", names, source, required=False)
    else:
        velocity = _coordinates(initial.get("q_dot", {}), "q_dot", names, source, required=False)
        p = mechanics.mass_matrix(q) @ velocity
    if validate_boolean(initial.get("project", False), scene_label(source, "[initial] project")):
        q, p = mechanics.project(q, p)
    try:
        if forced:
            return ForcedProblem(mechanics, q, p, impulses=tuple(impulses or ()))
        return ConstrainedProblem(mechanics, q, p)
    except OffSurfaceError as exc:
        what = "give q" if "initial q" in exc.detail else "give q_dot (or p)"
        raise InputError(f"{source}: {exc.detail}; {what} on the constraint surface, or set project = true "
                         "in [initial]") from None
    except InputError as exc:
        raise InputError(f"{source}: {exc}") from None


def _analysed_problem(lagrangian: Lagrangian, overrides: dict, initial: dict, source: str) -> AnalysedProblem:
    """A Lagrangian that is not of the form 1/2 q_dot^T M q_dot - V (velocity-linear or
    singular): integrate the Dirac vector field of its analysis (``midpoint``, scipy).

    The Lagrangian is analysed once, with the scene's parameter values fixed
    (:meth:`AnalysedSystem.from_lagrangian`: analyze, then ``from_analysis``); that same
    analysis completes the initial state on the constraint surface."""
    from dirac.flows.analysed import AnalysedProblem, AnalysedSystem

    if validate_boolean(initial.get("project", False), scene_label(source, "[initial] project")):
        # the values given are held and the rest completed on the surface: nothing would be projected
        raise InputError(f"{source}: [initial] project = true: {lagrangian.name!r} runs on the Dirac flow of its "
                         "analysis, whose initial state is completed on the constraint surface from q and q_dot "
                         "(or p); set project = false and give values on the surface")
    analysed = AnalysedSystem.from_lagrangian(lagrangian, overrides)
    names = tuple(s.name for s in lagrangian.coordinates)
    if "q" not in initial:
        raise InputError(f"{source}: [initial] lacks q (the coordinates {', '.join(names)})")
    q = dict(zip(names, _coordinates(initial["q"], "q", names, source, required=True).tolist()))
    if "p" in initial:
        p = dict(zip(names, _coordinates(initial["p"], "p", names, source, required=False).tolist()))
        z0 = analysed.initial_state(q, p=p, seed=0)
    else:
        velocity = dict(zip(names, _coordinates(initial.get("q_dot", {}), "q_dot", names, source, required=False).tolist()))
        z0 = analysed.initial_state(q, q_dot=velocity, seed=0)
    try:
        return AnalysedProblem(analysed, z0)
    except InputError as exc:
        raise InputError(f"{source}: {exc}") from None


def _coordinates(value: object, key: str, names: tuple[str, ...], source: str, required: bool) -> np.ndarray:
    if isinstance(value, list):
        array = scene_vector(value, f"[initial] {key}", source, (len(names),))
        return array
    if not isinstance(value, dict):
        raise InputError(f"{source}: [initial] {key} must be a table {{ {names[0]} = ... }} or a list")
    unknown = sorted(set(value) - set(names))
    if unknown:
        raise InputError(f"{source}: [initial] {key} names unknown coordinates {', '.join(unknown)}; the coordinates are {', '.join(names)}")
    missing = [n for n in names if n not in value]
    if missing and required:
        raise InputError(f"{source}: [initial] {key} lacks {', '.join(missing)}")
    return np.array([scene_number(value.get(n, 0.0), f"[initial] {key}.{n}", source) for n in names])
