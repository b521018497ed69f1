"""The member loop of an ensemble of analysed systems: the Dirac flow a single run integrates.

A Lagrangian that is not of the form ``1/2 q_dot^T M(q) q_dot - V(q)`` -- terms linear in
the velocities (``L = x y_dot - (x^2 + y^2)/2``), a singular kinetic term, a gauge system
-- runs in a single scene on the Dirac vector field of its analysis
(:class:`dirac.flows.analysed.AnalysedSystem`, phase space ``z``: the coordinates and
multipliers, then their momenta):

    z_dot = J grad H - J grad Phi^T C^{-1} (grad Phi J grad H + d_t Phi),   C_ab = {Phi_a, Phi_b}

(Dirac 1964; the paper's (240)), over the second-class constraints ``Phi``, with the free
multipliers of a gauge system at 0, by the projected implicit midpoint rule
(``midpoint_run`` of its generated module: Hairer, Lubich & Wanner, *Geometric Numerical
Integration*, IV.2 and IV.4). :func:`compiled_analysed` builds that system exactly as a
single run does (:meth:`AnalysedSystem.from_lagrangian`, the scene's parameters fixed
before the analysis) and appends to its module's source the member loop of
:func:`dirac.ensemble.general_kernel._ensemble_source` -- the same reductions, crossing
location, early stop and failure codes as every general ensemble -- with the midpoint
step's body pasted in. The loop's ``q`` and ``p`` are the two halves of ``z``; three small
adapters give it what it asks of a mechanical system:

* ``energy(q, p, t, c)`` -- the canonical Hamiltonian ``H_c(z, t)`` (a single run's ``energy``);
* ``residuals(q, p, t, c, out)`` -- the second-class constraints ``Phi(z, t)`` (a single
  run's ``constraint_residual`` is their largest modulus);
* ``velocity(q, p, t, c, v, ...)`` -- ``v`` the coordinate half of the field ``z_dot``
  (what ``<q>_dot`` means in a reduction).

A member's state equals a single run's of the same initial state to the last bit (the
same compiled arithmetic, at the same times ``t_k + j dt``). Initial states are completed
on the constraint surface member by member by :meth:`AnalysedSystem.initial_state`, as a
single scene completes its one (from a fixed start of its solve).
"""

from __future__ import annotations

from types import SimpleNamespace
from typing import Any

import numpy as np

from dirac.ensemble.general_kernel import CompiledEnsemble
from dirac.ensemble.general_scene import GeneralEnsembleScene, load_lagrangian
from dirac.ensemble.member_values import evaluate, member_label
from dirac.errors import InputError

__all__ = ["analysed_system", "compiled_analysed", "analysed_initial_states", "check_analysed_states"]

_CACHE: dict[str, CompiledEnsemble] = {}
_SYSTEMS: dict[str, Any] = {}


def compiled_analysed(scene: GeneralEnsembleScene) -> CompiledEnsemble:
    """The compiled ensemble of an analysed ``scene`` (built once per process, then cached).

    ``mechanics`` of the result is the :class:`~dirac.flows.analysed.AnalysedSystem`."""
    key = scene.fingerprint()
    if key not in _CACHE:
        _CACHE[key] = _build(scene)
    return _CACHE[key]


def analysed_system(scene: GeneralEnsembleScene) -> Any:
    """The :class:`~dirac.flows.analysed.AnalysedSystem` of ``scene``, made as a single run
    makes it (:meth:`AnalysedSystem.from_lagrangian` with the scene's parameter values; once
    per process)."""
    from dirac.flows.analysed import AnalysedSystem

    key = scene.fingerprint()
    if key not in _SYSTEMS:
        lagrangian = load_lagrangian(scene.system, scene.base_dir)
        _SYSTEMS[key] = AnalysedSystem.from_lagrangian(lagrangian, {k: float(v) for k, v in scene.parameters.items()})
    return _SYSTEMS[key]


def _build(scene: GeneralEnsembleScene) -> CompiledEnsemble:
    import sympy

    from dirac.codegen.numba_backend import import_source
    from dirac.ensemble.general_kernel import _ensemble_source, _paste_step
    from dirac.ensemble.reduction_layout import reduction_layout

    lagrangian = load_lagrangian(scene.system, scene.base_dir)
    analysed = analysed_system(scene)
    analysis = analysed.analysis
    z = list(analysis.phase_space)
    half = len(z) // 2
    k = analysed.n_constraints
    if k % 2:  # C = {Phi_a, Phi_b} is antisymmetric and invertible: never odd
        raise InputError(f"system {lagrangian.name!r}: an odd number ({k}) of second-class constraints")
    parameters = [p for p, v in analysis.lagrangian.parameters.items() if v is not None]  # the module's c
    time = analysis.time if analysis.time is not None else sympy.Symbol("t", real=True)
    state: dict[str, Any] = {}
    for s in lagrangian.parameters:  # fixed before the analysis: their values
        state[s.name] = sympy.Float(analysed.parameter_values[s.name]) if s.name in analysed.parameter_values else s
    state.update({p.name: p for p in parameters})
    for i, s in enumerate(z[:half]):
        state[s.name] = s
        state[f"{s.name}_dot"] = sympy.Symbol(f"{s.name}_dot", real=True)
        state[f"p_{s.name}"] = z[half + i]
    state["t"] = time
    exprs, conditions, layout = reduction_layout(scene, state)
    velocities = {state[f"{s.name}_dot"] for s in z[:half]}
    used = set().union(*(e.free_symbols for e in exprs), *(c.free_symbols for c, _ in conditions)) if exprs else set()
    kinds = {r.kind for r in scene.reductions}
    source = analysed.module.source
    for old, new in (("def energy(z, t, c):", "def an_energy(z, t, c):"),
                     ("def residuals(z, t, c, out):", "def an_residuals(z, t, c, out):")):
        if source.count(old) != 1:
            raise InputError(f"system {lagrangian.name!r}: its generated module has no single {old!r}; "
                             "analysed ensembles need the module of dirac.codegen.analysed_kernel_source")
        source = source.replace(old, new)
    pasted = _paste_step(source, "midpoint_run")
    if pasted is None:
        raise InputError(f"[run] method = 'midpoint' is not available in ensembles of {lagrangian.name!r} (its step "
                         "loop has an unusual form); run its members one by one with dirac run")
    namespace = SimpleNamespace(coordinates=z[:half], parameters=parameters)
    step = "midpoint_run(z, m_a, c, dt, 1, tol, max_iter, info)"
    loop = _ensemble_source(scene, namespace, state, exprs, conditions, layout, step, half, k // 2,
                            bool(used & velocities), "energy_error" in kinds, "constraint_error" in kinds, pasted)
    module = import_source(source + _adapters(half) + loop)
    return CompiledEnsemble(analysed, module, np.ones(1), 0.0, layout, {}, scene.source.names)


def _adapters(half: int) -> str:
    """``energy``, ``residuals`` and ``velocity`` in the signatures of a mechanical system's
    module, on ``z = (q, p)`` (module docstring)."""
    return f'''

# ---- the analysed system in the member loop's signatures (dirac.ensemble.analysed_members) ----

@numba.njit(cache=True, inline="always")
def an_state(q, p, z):
    """z = (q, p)."""
    for i in range({half}):
        z[i] = q[i]
        z[{half} + i] = p[i]


@numba.njit(cache=True)
def energy(q, p, t, c):
    """H_c at z = (q, p)."""
    z = np.empty({2 * half})
    an_state(q, p, z)
    return an_energy(z, t, c)


@numba.njit(cache=True)
def residuals(q, p, t, c, out):
    """The second-class constraints Phi at z = (q, p)."""
    z = np.empty({2 * half})
    an_state(q, p, z)
    an_residuals(z, t, c, out)


@numba.njit(cache=True)
def velocity(q, p, t, c, v, work, piv):
    """v = the coordinate half of the Dirac field z_dot at z = (q, p)."""
    z = np.empty({2 * half})
    out = np.empty({2 * half})
    an_state(q, p, z)
    field(z, t, c, out)
    for i in range({half}):
        v[i] = out[i]
'''


def analysed_initial_states(scene: GeneralEnsembleScene, analysed: Any, values: np.ndarray, first: int = 0,
                            completed: tuple[np.ndarray, np.ndarray] | None = None
                            ) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """``(Q, P, C)`` of members with the ensemble variables ``values`` (rows): the two halves
    of each member's ``z``, completed on the constraint surface by
    :meth:`AnalysedSystem.initial_state` from its ``q`` and ``q_dot`` (or ``p``), as a single
    scene does, and checked there as :class:`~dirac.flows.analysed.AnalysedProblem` checks
    it (``max |Phi| <= 1e-8 (1 + |z|^2)``); the values it solves for (multipliers) from the
    same start for every member and in every process (``seed = 0``), so that they do not
    depend on where a chunk runs. ``C`` is the module's parameter rows, ``analysed``
    is the scene's :func:`analysed_system`; ``completed``: these members' ``(Q, P)`` computed
    before by this function, taken as they are (the completion is a Python loop over
    members, about 0.4 ms each). ``first`` is
    the number of the first of these members (for messages).

    Raises
    ------
    InputError
        Naming the first member (and its ensemble variables) whose initial values are not
        finite or leave the constraint surface, with the fix.
    """
    import sympy

    from dirac.flows.analysed import AnalysedProblem
    from dirac.model.expressions import parse_expression

    count = values.shape[0]
    C = np.tile(np.asarray(analysed.params, dtype=float), (count, 1))
    if completed is not None:
        return completed[0].copy(), completed[1].copy(), C
    names = scene.source.names
    symbols = {name: sympy.Symbol(name, real=True) for name in names}

    def column(value: float | str, where: str) -> np.ndarray:
        if isinstance(value, str):
            return evaluate(parse_expression(value, symbols, what=where), names, values)
        return np.full(count, float(value))

    coordinates = scene.coordinate_names
    q = np.column_stack([column(scene.initial_q[n], f"[initial] q.{n}") for n in coordinates])
    rates = np.column_stack([column(scene.initial_rates.get(n, 0.0), f"[initial] {scene.rate_kind}.{n}")
                             for n in coordinates])
    Z = np.empty((count, analysed.dimension))
    for i in range(count):
        where = f"member {first + i} ({member_label(names, values[i])})"
        if not (np.all(np.isfinite(q[i])) and np.all(np.isfinite(rates[i]))):
            raise InputError(f"the initial state of {where} is not finite; check the expressions in [initial]")
        given = dict(zip(coordinates, q[i].tolist()))
        other = dict(zip(coordinates, rates[i].tolist()))
        try:
            if scene.rate_kind == "p":
                Z[i] = analysed.initial_state(given, p=other, seed=0)
            else:
                Z[i] = analysed.initial_state(given, q_dot=other, seed=0)
            AnalysedProblem(analysed, Z[i])
        except InputError as exc:
            raise InputError(f"[initial] of {where}: {exc}") from None
    half = analysed.dimension // 2
    return np.ascontiguousarray(Z[:, :half]), np.ascontiguousarray(Z[:, half:]), np.ascontiguousarray(C)


def check_analysed_states(scene: GeneralEnsembleScene, chunk_size: int | None = None,
                          keep: dict[tuple[str, int, int], tuple[np.ndarray, np.ndarray]] | None = None,
                          limit: int = 0) -> None:
    """Refuse, before anything is written, a member whose initial state a single scene
    refuses (:func:`analysed_initial_states`).

    With ``chunk_size`` and ``keep`` the members are taken chunk by chunk and their states
    put in ``keep`` by ``(scene fingerprint, start, stop)`` (when they hold at most ``limit``
    numbers), for the chunks computed in this process to take instead of completing every
    member again (the same function on the same members: the same bits)."""
    analysed = analysed_system(scene)  # nothing compiled yet: a refusal is quick
    keeping = keep is not None and chunk_size is not None and scene.count * analysed.dimension <= limit
    block = chunk_size if keeping and chunk_size is not None else 65536
    for start in range(0, scene.count, block):
        stop = min(scene.count, start + block)
        Q, P, _ = analysed_initial_states(scene, analysed, scene.source.members(start, stop), start)
        if keeping and keep is not None:
            keep[(scene.fingerprint(), start, stop)] = (Q, P)
