"""The member loop of a general ensemble: the system's own step kernel, batched over members.

:func:`compiled_ensemble` builds, once per process and scene, the system exactly as a
single run does (:meth:`dirac.flows.mechanics.MechanicalSystem.from_lagrangian`: the same
generated module, the same RATTLE or forced-RATTLE step loop) and appends to that module's
source

* ``ens_values`` / ``ens_conditions`` -- the reductions' expressions and the ``when``
  conditions (``lhs - rhs``), straight-line code (:func:`dirac.codegen.kernel_source.emit_function`);
* ``ens_locate`` -- regula falsi (Illinois) for the zero of one expression on the line
  between two consecutive states;
* ``ens_member`` -- one member from ``t = 0`` to ``t_end`` (or until its reductions are
  decided): step by step, each step the module's own step loop (its body pasted in, or the
  loop called for one step) at the time a single run gives that step (``t_k + j dt`` on the sample grid ``t_k`` of
  :func:`dirac.flows.integration.sample_times`), so a member's state equals a single
  run's to the last bit (with ``[[impulses]]``, the steps of each sample interval follow a
  single run's plan of pieces and kicks instead: :mod:`dirac.ensemble.impulse_plan`, module
  constants ``ENS_OP_*`` and the kick ``impulse_kick``);
* ``ens_run`` -- ``numba.prange`` over the members of a chunk calling ``ens_member``
  (interleaved over the threads: its last argument is numba's thread count);
* ``ens_momenta`` / ``ens_surface`` -- ``p = M(q) q_dot`` and the constraint residuals of
  many initial states.

The combined module is imported through :func:`dirac.codegen.numba_backend.import_source`
(cached on disk under the hash of its source: compiled once per machine).
"""

from __future__ import annotations

import re
from dataclasses import dataclass
from typing import Any, cast

import numpy as np

from dirac.ensemble.crossing_source import locate_source
from dirac.ensemble.general_scene import GeneralEnsembleScene, load_lagrangian
from dirac.ensemble.step_transcendentals import step_transcendentals, substitute_transcendentals
from dirac.errors import InputError

__all__ = ["CompiledEnsemble", "compiled_ensemble", "FAILURES"]

#: Codes of the ``failures`` array (0: the member completed).
FAILURES: dict[int, str] = {
    1: "Newton iteration did not converge (reduce dt)",
    2: "non-finite state (the step diverged; reduce dt)",
    3: "singular Newton matrix (the constraints are not independent here)",
    4: ("stepped across a pole of the equations of motion (a denominator of the force, the mass matrix, the "
        "constraints or the forces changed sign between two steps: a singularity the motion reaches; a smaller dt "
        "does not cure it)"),
}

_CACHE: dict[str, CompiledEnsemble] = {}

#: Whether the reductions evaluated after a step read the transcendental functions of ``q``
#: the step has just evaluated (:mod:`dirac.ensemble.step_transcendentals`); off, they compute
#: them again (the same bits: tests compare both).
REUSE_STEP_TRANSCENDENTALS = True


@dataclass(frozen=True)
class _Reuse:
    """What a member loop may read from the step's ``w`` after a step: the expression of each
    entry (``entries``) and whether the module has ``velocity_w`` (``v = M^{-1} p`` from ``w``)."""

    entries: list
    velocity: bool

#: The step loops a member loop calls (one step at a time).
_STEP_KERNELS = ("rattle_constant_mass", "rattle_general", "forced_rattle_run", "conformal_run", "midpoint_run")


@dataclass
class CompiledEnsemble:
    """The compiled pieces of one general ensemble scene (see the module docstring).

    Attributes
    ----------
    mechanics : MechanicalSystem
        The system with the scene's fixed parameter values.
    module : module
        The generated module with the ensemble loop appended.
    fractions : numpy.ndarray
        Sub-steps of the composition (fractions of ``dt``).
    gamma : float
        The conformal rate (``conformal-*`` methods), else 0.
    layout : dict
        Where each reduction's values sit in the kernel's arrays.
    """

    mechanics: Any
    module: Any
    fractions: np.ndarray
    gamma: float
    layout: dict
    parameter_exprs: dict
    variable_names: tuple[str, ...]


def compiled_ensemble(scene: GeneralEnsembleScene) -> CompiledEnsemble:
    """The compiled ensemble of ``scene`` (built once per process, then cached)."""
    key = scene.fingerprint()
    if key not in _CACHE:
        _CACHE[key] = _build(scene)
    return _CACHE[key]


def _build(scene: GeneralEnsembleScene) -> CompiledEnsemble:
    import sympy

    from dirac.codegen.numba_backend import import_source
    from dirac.ensemble.general_scene import _state_names
    from dirac.ensemble.reduction_layout import reduction_layout
    from dirac.flows.mechanics import MechanicalSystem, NotMechanicalError
    from dirac.flows.methods.registry import get_method
    from dirac.model.expressions import parse_expression

    lagrangian = load_lagrangian(scene.system, scene.base_dir)
    fixed = {k: float(v) for k, v in scene.parameters.items() if not isinstance(v, str)}
    placeholders = {k: 1.0 for k, v in scene.parameters.items() if isinstance(v, str)}
    try:
        mechanics = MechanicalSystem.from_lagrangian(lagrangian, {**placeholders, **fixed}, with_forces=scene.forced)
    except NotMechanicalError as exc:
        raise InputError(f"ensembles integrate L = 1/2 q_dot^T M(q) q_dot - V(q) with RATTLE: {exc}") from None
    method = get_method(scene.method)
    if scene.forced:
        family, coefficients = cast(tuple[str, tuple[float, ...]], method.data)
        fractions = np.array(coefficients, dtype=np.float64)
        if family == "conformal":
            if placeholders:
                raise InputError(f"[run] method = {scene.method!r} takes its damping rate from fixed parameter values; "
                                 "with parameters that vary over the ensemble use forced-rattle-2 or forced-rattle-4")
            if mechanics.conformal_rate is None:
                raise InputError(f"[run] method = {scene.method!r} needs linear damping Q = -gamma M q_dot with a constant "
                                 "mass; use forced-rattle-2 or forced-rattle-4")
            step = "conformal_run(q, p, ta, c, gamma, fractions, dt, 1, tol, max_iter, info, work_done)"
        else:
            step = "forced_rattle_run(q, p, ta, c, fractions, dt, 1, tol, max_iter, info, work_done)"
        gamma = float(mechanics.conformal_rate or 0.0)
    elif scene.method == "midpoint":
        mechanics.require_field("midpoint")
        fractions = np.ones(1)
        step = "midpoint_run(z, m_a, c, dt, 1, tol, max_iter, info)"
        gamma = 0.0
    else:
        fractions = np.array(cast(tuple[float, ...], method.data), dtype=np.float64)
        name = "rattle_constant_mass" if mechanics.constant_mass is not None else "rattle_general"
        step = f"{name}(q, p, ta, c, fractions, dt, 1, tol, max_iter, info)"
        gamma = 0.0
    state = _state_names(lagrangian)
    exprs, conditions, layout = reduction_layout(scene, state)
    kinds = {r.kind for r in scene.reductions}
    n = len(scene.coordinate_names)
    velocities = [state[f"{q}_dot"] for q in scene.coordinate_names]
    used = set().union(*(e.free_symbols for e in exprs), *(c.free_symbols for c, _ in conditions)) if exprs else set()
    needs_velocity = bool(used & set(velocities))
    # the step loop's body is pasted into the member loop when it has the usual shape (its work
    # arrays then allocated once per member); else the loop is called for one step, compiled into
    # the member loop (numba inlines it at its IR level); the arithmetic is the same either way
    system_source = mechanics.module.source
    for kernel in _STEP_KERNELS:
        system_source = system_source.replace(f"@numba.njit(cache=True)\ndef {kernel}(",
                                              f'@numba.njit(cache=True, inline="always")\ndef {kernel}(')
    pasted = _paste_step(system_source, step.split("(")[0])
    if pasted is None and scene.method == "midpoint":
        # the midpoint rule's time t + (step + 1/2) dt is a single run's only with its own step count
        raise InputError("[run] method = 'midpoint' is not available in ensembles of this system (its step loop "
                         "has an unusual form); use rattle-2 or rattle-4")
    plan = None
    if scene.impulses:  # a single run's pieces and kicks (dirac.ensemble.impulse_plan)
        from dirac.ensemble.impulse_plan import run_plan

        starts, _ends, per_interval, dt = scene.step_grid()
        plan = run_plan(starts, per_interval, dt, scene.impulses)
    reuse = None
    if REUSE_STEP_TRANSCENDENTALS and pasted is not None and step.startswith("rattle_general(") and any(
            line.strip().startswith("w = np.empty(") for line in pasted[0]):
        # the step leaves w = transcendentals(q) at its final q: the reductions read their sines
        entries = step_transcendentals(system_source, lagrangian.coordinates, lagrangian.parameters, sympy.Dummy("t"))
        reuse = _Reuse(entries, "\ndef velocity_w(q, p, w, t, c, out, work, piv):" in system_source) if entries else None
    from dirac.flows.pole_guard import pole_guard

    guard = pole_guard(mechanics)  # the poles of the equations of motion, read after every step (failure code 4)
    poles = list(guard.expressions) if guard is not None else []
    source = _ensemble_source(scene, lagrangian, state, exprs, conditions, layout, step, n,
                              mechanics.n_constraints, needs_velocity, "energy_error" in kinds,
                              "constraint_error" in kinds, pasted, plan, reuse, poles)
    module = import_source(system_source + source)
    variables = {name: sympy.Symbol(name, real=True) for name in scene.source.names}
    parameter_exprs = {k: parse_expression(v, variables, what=f"[system] parameters.{k}")
                       for k, v in scene.parameters.items() if isinstance(v, str)}
    return CompiledEnsemble(mechanics, module, fractions, gamma, layout, parameter_exprs, scene.source.names)


#: The statements after a step loop's ``for step`` loop that the member loop may drop: the
#: closing ``report`` call, or its body (assignments to ``info[k]``) where
#: :mod:`dirac.codegen.flatten` inlined it.
_REPORT_CALL = "report(info, n_steps, False, evals, residual)"
_INFO_ENTRY = re.compile(r"info\[\d\] = [^=]+$")


def _is_report_tail(lines: list[str]) -> bool:
    """Whether ``lines`` (stripped, non-empty) only report the steps done (see above)."""
    return lines == [_REPORT_CALL] or (bool(lines) and all(_INFO_ENTRY.match(line) for line in lines))


def _paste_step(source: str, kernel: str) -> tuple[list[str], list[str], list[str]] | None:
    """The step loop ``kernel`` of the system's module cut into the three parts the member
    loop pastes in: its work-array allocations and the statements before its loop over steps
    (once per member), and the body of that loop indented for the member's loop over steps
    (once per step, with ``t = t_k`` the sample time and ``step = j`` the step's number in
    its sample interval, so its times ``t + step dt`` -- and the midpoint rule's
    ``t + (step + 1/2) dt`` -- are a single run's), the same statements as in a single run. None when the loop does not
    have that shape (allocations, set-up, ``for step in range(n_steps):``, then only
    ``report(...)``): the member loop then calls it.

    A one-step call of a loop that allocates two dozen small arrays spends most of its time
    allocating (the angles' RATTLE: 3.5 x the per-step cost of a long run), and passing
    them in costs a reference count per array and step. Since the system's module inlines its
    helpers at the source level (:mod:`dirac.codegen.flatten`), the closing ``report`` may be
    its inlined body: both forms are recognised, else the general RATTLE's member loop fell
    back to the one-step call and cost 3 x a single run per step."""
    start = source.find(f"def {kernel}(")
    if start < 0:
        return None
    stop = source.find("\n@numba", start)
    text = source[start:] if stop < 0 else source[start:stop]
    doc_end = text.index('"""', text.index('"""') + 3) + 3
    lines = text[text.index("\n", doc_end) + 1:].rstrip().split("\n")
    loop = "    for step in range(n_steps):"
    if loop not in lines:
        return None
    at = lines.index(loop)
    head, rest = lines[:at], lines[at + 1:]
    split = next((k for k, line in enumerate(rest) if line.strip() and not line.startswith("        ")), len(rest))
    body, tail = rest[:split], rest[split:]
    if not _is_report_tail([line.strip() for line in tail if line.strip()]):
        return None
    allocations = [line for line in head if "= np." in line]
    prelude = [line for line in head if "= np." not in line]
    return allocations, prelude, ["    " + line if line.strip() else line for line in body]  # one level deeper


def _ensemble_source(scene: GeneralEnsembleScene, lagrangian: Any, state: dict, exprs: list, conditions: list,
                     layout: dict, step: str, n: int, m: int, needs_velocity: bool, energy: bool,
                     constraint: bool, pasted: tuple[list[str], list[str], list[str]] | None = None,
                     plan: Any = None, reuse: _Reuse | None = None, poles: list | None = None) -> str:
    from dirac.codegen.kernel_source import emit_function

    poles = list(poles or [])

    q = list(lagrangian.coordinates)
    p = [state[f"p_{s.name}"] for s in q]
    v = [state[f"{s.name}_dot"] for s in q]
    params = list(lagrangian.parameters)
    arrays = [("q", q), ("p", p), ("v", v)]
    scalars = [("t", state["t"])]
    out = ["\n\n# ---- ensemble loop (dirac.ensemble.general_kernel) ----\n"]
    out.append(emit_function("ens_values", "the reductions' expressions", arrays, scalars, exprs,
                             (len(exprs),), params))
    out.append(emit_function("ens_conditions", "the when conditions (lhs - rhs)", arrays, scalars,
                             [c for c, _ in conditions], (len(conditions),), params))
    if poles:
        out.append(emit_function("ens_poles", "the factors of the denominators of the equations of motion "
                                 "(dirac.flows.pole_guard)", arrays, scalars, poles, (len(poles),), params))
    # after a step: the reductions read the sines and cosines of q the step left in w (the
    # same bits; module docstring of dirac.ensemble.step_transcendentals), and v = M^-1 p too
    # when no entry of w depends on the time
    fixed = {*q, *params}
    substituted = substitute_transcendentals(exprs, reuse.entries, fixed) if reuse is not None else None
    after_values = "ens_values(q, p, m_v, tb, c, m_f)"
    if substituted is not None:
        out.append(emit_function("ens_values_w", "the reductions' expressions after a step, reading w", [*arrays, ("w", substituted[1])],
                                 scalars, substituted[0], (len(exprs),), params))
        after_values = "ens_values_w(q, p, m_v, w, tb, c, m_f)"
    after_velocity = "ens_velocity(q, p, tb, c, m_v, m_vw, m_vpiv)"
    if (needs_velocity and reuse is not None and reuse.velocity
            and all(entry.free_symbols <= fixed for entry in reuse.entries)):
        after_velocity = "velocity_w(q, p, w, tb, c, m_v, m_vw, m_vpiv)"
    velocity_body = "    velocity(q, p, t, c, v, work, piv)" if needs_velocity else "    return"
    out.append(f'''
@numba.njit(cache=True, inline="always")
def ens_velocity(q, p, t, c, v, work, piv):
    """v = M^-1 p when an expression uses velocities."""
{velocity_body}
''')
    out.append(locate_source(
        "ens_locate", "qa, pa, q, p, ta, dt, c, qs, ps, vs, fs",
        "Zero of expression e on the line between (qa, pa) at ta and (q, p) at ta + dt\n"
        "    (Illinois regula falsi); leaves the state there in qs, ps, vs, fs and returns its fraction.",
        f"        for x in range({n}):\n"
        "            qs[x] = qa[x] + s * (q[x] - qa[x])\n"
        "            ps[x] = pa[x] + s * (p[x] - pa[x])\n"
        "        ts = ta + s * dt\n",
        "        ens_velocity(qs, ps, ts, c, vs, vw, vpiv)\n"
        "        ens_values(qs, ps, vs, ts, c, fs)\n", trailing=", vw, vpiv"))
    n_cross = len(layout["cross"])
    n_ext = len(layout["ext"])
    n_poin = len(layout["poincare"])
    k_max = max([count for _, _, count in layout["poincare"]], default=1)
    lines: list[str] = []

    def w(depth: int, text: str) -> None:
        lines.append("    " * depth + text)

    w(0, "@numba.njit(cache=True)")
    w(0, "def ens_member(m_i, Q, P, C, fractions, dt, starts, ends, per_interval, tol, max_iter, gamma, early,")
    w(0, "               CROSS, EXT, EERR, CERR, PT, PQ, PP, STATUS, STEPS):")
    w(1, '"""One member from t = 0 to the end or until its reductions are decided (module docstring)."""')
    # the names of the step loop's arguments are the member's variables (q, p, t, c, info, work_done,
    # n_steps, step): its body can be pasted in; the member's own names start with m_
    w(1, "q = Q[m_i]")
    w(1, "p = P[m_i]")
    w(1, "c = C[m_i]")
    w(1, "info = np.zeros(4)")
    w(1, "work_done = np.zeros(1)")
    w(1, "n_steps = 1")
    w(1, "step = 0")
    midpoint = step.startswith("midpoint_run")
    if midpoint:
        w(1, f"z = np.empty({2 * n})  # the midpoint rule's state (q, p)")
    if pasted is not None:
        allocations, prelude, _body = pasted
        # the set-up first: the midpoint rule sizes its arrays by NZ = z.shape[0]
        for line in [*prelude, *allocations]:
            w(0, line)
    w(1, f"m_v = np.zeros({n})")
    w(1, f"m_vw = np.empty(({n}, {n}))")
    w(1, f"m_vpiv = np.zeros({n}, dtype=np.int64)")
    for name in ("m_qa", "m_pa", "m_qs", "m_ps"):
        w(1, f"{name} = np.empty({n})")
    w(1, f"m_vs = np.zeros({n})")
    nf = max(1, len(exprs))
    w(1, f"m_f = np.zeros({nf})")
    w(1, f"m_fa = np.zeros({nf})")
    w(1, f"m_fs = np.zeros({nf})")
    w(1, f"m_g = np.zeros({max(1, len(conditions))})")
    w(1, f"m_res = np.zeros({max(1, 2 * m)})")
    w(1, f"m_pc = np.zeros({max(1, n_poin)}, dtype=np.int64)")
    w(1, "m_t0 = starts[0]")
    if poles:
        w(1, f"m_pole = np.zeros({len(poles)})")
        w(1, f"m_polea = np.zeros({len(poles)})")
        w(1, "ens_poles(q, p, m_v, m_t0, c, m_pole)")
    w(1, "ens_velocity(q, p, m_t0, c, m_v, m_vw, m_vpiv)")
    w(1, "ens_values(q, p, m_v, m_t0, c, m_f)")
    for x, (_, _, e) in enumerate(layout["ext"]):
        w(1, f"EXT[m_i, {x}] = m_f[{e}]")
    if energy:
        w(1, "m_e0 = energy(q, p, m_t0, c)")
        w(1, "EERR[m_i] = 0.0")
    if constraint:
        w(1, "CERR[m_i] = 0.0")
        if m:
            w(1, "residuals(q, p, m_t0, c, m_res)")
            w(1, f"for m_x in range({2 * m}):")
            w(2, "if abs(m_res[m_x]) > CERR[m_i]:")
            w(3, "CERR[m_i] = abs(m_res[m_x])")
    w(1, "m_status = 0.0")
    w(1, "m_steps = 0")
    w(1, "m_stop = False")
    w(1, "STATUS[m_i] = 1.0  # until the member completes (a failing step returns from inside)")
    w(1, "for m_k in range(starts.shape[0]):")
    w(2, "m_a = starts[m_k]")
    w(2, "for m_j in range(per_interval):")
    body_start = len(lines)  # the step's body, followed op by op when impulses cut the steps
    w(3, f"for m_x in range({n}):")
    w(4, "m_qa[m_x] = q[m_x]")
    w(4, "m_pa[m_x] = p[m_x]")
    w(3, f"for m_x in range({len(exprs)}):")
    w(4, "m_fa[m_x] = m_f[m_x]")
    w(3, "ta = m_a + m_j * dt")
    if pasted is not None:
        # the step loop's time of step m_j of this sample interval, t + step dt, as in a single
        # run that advances the interval in one call (t the sample time t_k, step = m_j)
        w(3, "t = m_a")
        w(3, "step = m_j")
        if midpoint:
            w(3, f"for m_x in range({n}):")
            w(4, "z[m_x] = q[m_x]")
            w(4, f"z[{n} + m_x] = p[m_x]")
        for line in pasted[2]:
            if line.strip() == "return":
                indent = line[: len(line) - len(line.lstrip())]
                w(0, f"{indent}STEPS[m_i] = m_steps")
            w(0, line)
        if midpoint:
            w(3, f"for m_x in range({n}):")
            w(4, "q[m_x] = z[m_x]")
            w(4, f"p[m_x] = z[{n} + m_x]")
    else:
        w(3, step)
        w(3, "if info[1] != 0.0:")
        w(4, "m_status = 1.0")
        w(4, "m_stop = True")
        w(4, "break")
    w(3, "m_steps += 1")
    w(3, "tb = m_a + (m_j + 1) * dt")
    w(3, "m_bad = False")
    w(3, f"for m_x in range({n}):")
    w(4, "if not (abs(q[m_x]) < np.inf and abs(p[m_x]) < np.inf):")
    w(5, "m_bad = True")
    w(3, "if m_bad:")
    w(4, "m_status = 2.0")
    w(4, "m_stop = True")
    w(4, "break")
    if poles:  # a factor of a denominator that changed sign in the step: the step jumped over a pole
        w(3, f"for m_x in range({len(poles)}):")
        w(4, "m_polea[m_x] = m_pole[m_x]")
        w(3, "ens_poles(q, p, m_v, tb, c, m_pole)")
        w(3, f"for m_x in range({len(poles)}):")
        w(4, "if (m_polea[m_x] > 0.0 and m_pole[m_x] <= 0.0) or (m_polea[m_x] < 0.0 and m_pole[m_x] >= 0.0):")
        w(5, "m_status = 4.0")
        w(5, "m_stop = True")
        w(3, "if m_stop:")
        w(4, "break")
    if needs_velocity:
        w(3, after_velocity)
    w(3, after_values)
    for x, (_, kind, e) in enumerate(layout["ext"]):
        op = ">" if kind == "max" else "<"
        w(3, f"if m_f[{e}] {op} EXT[m_i, {x}]:")
        w(4, f"EXT[m_i, {x}] = m_f[{e}]")
    locate = "m_qa, m_pa, q, p, ta, dt, c, m_qs, m_ps, m_vs, m_fs"
    for gi, (_, group) in enumerate(layout["cross"]):
        w(3, f"if CROSS[m_i, {gi}] != CROSS[m_i, {gi}]:")
        w(4, "m_best = np.inf")
        for e, cond in group:
            w(4, f"if (m_fa[{e}] < 0.0 and m_f[{e}] >= 0.0) or (m_fa[{e}] > 0.0 and m_f[{e}] <= 0.0):")
            w(5, f"m_s = ens_locate({e}, {locate}, m_fa[{e}], m_f[{e}], m_vw, m_vpiv)")
            if cond >= 0:
                w(5, "ens_conditions(m_qs, m_ps, m_vs, ta + m_s * dt, c, m_g)")
                w(5, f"if m_g[{cond}] {conditions[cond][1]} 0.0 and ta + m_s * dt < m_best:")
            else:
                w(5, "if ta + m_s * dt < m_best:")
            w(6, "m_best = ta + m_s * dt")
        w(4, "if m_best < np.inf:")
        w(5, f"CROSS[m_i, {gi}] = m_best")
    for pj, (_, e, count) in enumerate(layout["poincare"]):
        w(3, f"if m_pc[{pj}] < {count} and m_fa[{e}] < 0.0 and m_f[{e}] >= 0.0:")
        w(4, f"m_s = ens_locate({e}, {locate}, m_fa[{e}], m_f[{e}], m_vw, m_vpiv)")
        w(4, f"PT[m_i, {pj}, m_pc[{pj}]] = ta + m_s * dt")
        w(4, f"for m_x in range({n}):")
        w(5, f"PQ[m_i, {pj}, m_pc[{pj}], m_x] = m_qs[m_x]")
        w(5, f"PP[m_i, {pj}, m_pc[{pj}], m_x] = m_ps[m_x]")
        w(4, f"m_pc[{pj}] += 1")
    decided = [f"CROSS[m_i, {gi}] == CROSS[m_i, {gi}]" for gi in range(n_cross)]
    decided += [f"m_pc[{pj}] >= {count}" for pj, (_, _, count) in enumerate(layout["poincare"])]
    if decided:
        w(3, f"if early and {' and '.join(decided)}:")
        w(4, "m_stop = True")
        w(4, "break")
    if plan is not None:
        from dirac.ensemble.impulse_plan import impulse_steps, plan_source

        lines[body_start - 1:] = impulse_steps(lines[body_start:], layout, conditions, n, m, len(exprs), decided)
        out.append(plan_source(plan))
    w(2, "if m_stop:")
    w(3, "break")
    if energy:
        w(2, "m_err = abs(energy(q, p, ends[m_k], c) - work_done[0] - m_e0)")
        w(2, "if not (m_err <= EERR[m_i]):")
        w(3, "EERR[m_i] = m_err")
    if constraint and m:
        w(2, "residuals(q, p, ends[m_k], c, m_res)")
        w(2, f"for m_x in range({2 * m}):")
        w(3, "if not (abs(m_res[m_x]) <= CERR[m_i]):")
        w(4, "CERR[m_i] = abs(m_res[m_x])")
    w(1, "STATUS[m_i] = m_status")
    w(1, "STEPS[m_i] = m_steps")
    out.append("\n".join(lines) + "\n")
    out.append(f'''

@numba.njit(cache=True, parallel=True)
def ens_run(lo, hi, Q, P, C, fractions, dt, starts, ends, per_interval, tol, max_iter, gamma, early,
            CROSS, EXT, EERR, CERR, PT, PQ, PP, STATUS, STEPS, threads):
    """ens_member for members lo .. hi-1, in parallel over members (numba.prange): with
    ``threads`` = numba's thread count T, thread k runs members lo + k, lo + k + T, ...
    (neighbouring members cost alike, so the threads' shares cost alike even where many members
    stop early; halves of the range did not: the 256 x 256 flip map's threads idled 4 % of the
    wall time). The count is an argument: numba.get_num_threads() here would keep numba from
    caching this function."""
    stripes = max(1, min(threads, hi - lo))
    for k in numba.prange(stripes):
        for i in range(lo + k, hi, stripes):
            ens_member(i, Q, P, C, fractions, dt, starts, ends, per_interval, tol, max_iter, gamma, early,
                       CROSS, EXT, EERR, CERR, PT, PQ, PP, STATUS, STEPS)


@numba.njit(cache=True)
def ens_momenta(Q, QD, C, P):
    """P[i] = M(Q[i], 0) QD[i]."""
    Mw = np.empty(({n}, {n}))
    for i in range(Q.shape[0]):
        mass(Q[i], 0.0, C[i], Mw)
        for a in range({n}):
            acc = 0.0
            for b in range({n}):
                acc += Mw[a, b] * QD[i, b]
            P[i, a] = acc


@numba.njit(cache=True)
def ens_surface(Q, P, C, OUT):
    """OUT[i] = (chi, G M^-1 p + d chi/dt) at (Q[i], P[i], t = 0)."""
    for i in range(Q.shape[0]):
        residuals(Q[i], P[i], 0.0, C[i], OUT[i])


#: shapes of the kernel's result arrays
ENS_SHAPES = ({max(1, n_cross)}, {max(1, n_ext)}, {max(1, n_poin)}, {k_max})
''')
    return "".join(out)
