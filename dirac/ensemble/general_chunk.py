"""One chunk of a general ensemble: members' initial states, the batched member loop, arrays.

The initial states are evaluated from the scene's expressions of the ensemble variables
(numpy, once per chunk), put on the constraint surface when ``project = true``, and
advanced by ``ens_run`` of :mod:`dirac.ensemble.general_kernel` (the system's own
compiled step, ``numba.prange`` over members). A member the kernel cannot continue is
marked in ``failures`` (codes :data:`~dirac.ensemble.general_kernel.FAILURES`) and its
reductions are NaN; the others complete.
"""

from __future__ import annotations

import dataclasses

import numpy as np

from dirac.ensemble.general_kernel import CompiledEnsemble, compiled_ensemble
from dirac.ensemble.general_scene import GeneralEnsembleScene
from dirac.ensemble.kernel_lock import KERNEL_LOCK
from dirac.ensemble.member_values import member_column
from dirac.ensemble.member_values import member_label as _where
from dirac.errors import InputError

__all__ = ["check_initial_states", "compute_general_chunk", "forget_projected", "initial_states", "member_results", "step_grid"]

#: Members whose initial states are checked at once by :func:`check_initial_states`.
_CHECK_BLOCK = 65536

#: Projected initial states ``(Q, P)`` that :func:`check_initial_states` computed for the
#: chunks of a new ensemble, by ``(scene fingerprint, start, stop)``; a chunk computed in this
#: process takes (and drops) its entry instead of projecting every member again.
_PROJECTED: dict[tuple[str, int, int], tuple[np.ndarray, np.ndarray]] = {}

#: Projected states kept at most (values of ``Q`` and ``P`` together, 128 MB).
_PROJECTED_LIMIT = 16_000_000


def step_grid(scene: GeneralEnsembleScene) -> tuple[np.ndarray, np.ndarray, int, float]:
    """``(starts, ends, steps per interval, dt)`` exactly as :func:`dirac.flows.integrate` cuts
    ``[0, t_end]`` (its sample grid and step), so members step at the times a single run does
    (:meth:`GeneralEnsembleScene.step_grid`)."""
    return scene.step_grid()


def initial_states(scene: GeneralEnsembleScene, compiled: CompiledEnsemble, values: np.ndarray,
                   projected: tuple[np.ndarray, np.ndarray] | None = None
                   ) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """``(Q, P, C)`` of members with the ensemble variables ``values`` (rows): positions,
    momenta (``p = M(q) q_dot`` unless ``p`` is given) and parameter values; projected onto
    the constraints when the scene says ``project = true`` (``projected``: these members'
    projected ``(Q, P)``, computed before by this function, which are then taken as they are:
    the projection is a Python loop over members, about 0.15 ms each)."""
    count = values.shape[0]
    names = scene.source.names

    def column(value: float | str, where: str) -> np.ndarray:
        return member_column(value, where, names, values)

    mechanics = compiled.mechanics
    C = np.tile(np.asarray(mechanics.params, dtype=float), (count, 1))
    for key, value in scene.parameters.items():
        C[:, scene.parameter_names.index(key)] = column(value, f"[system] parameters.{key}")
    n = len(scene.coordinate_names)
    Q = np.empty((count, n))
    rates = np.zeros((count, n))
    for j, name in enumerate(scene.coordinate_names):
        Q[:, j] = column(scene.initial_q[name], f"[initial] q.{name}")
        if name in scene.initial_rates:
            rates[:, j] = column(scene.initial_rates[name], f"[initial] {scene.rate_kind}.{name}")
    bad = ~(np.all(np.isfinite(Q), axis=1) & np.all(np.isfinite(rates), axis=1) & np.all(np.isfinite(C), axis=1))
    if np.any(bad):
        first = int(np.argmax(bad))
        raise InputError(f"the initial state or parameters of member {first} ({_where(names, values[first])}) are not "
                         "finite; check the expressions in [initial] and [system] parameters")
    if scene.rate_kind == "p":
        P = rates
    else:
        P = np.empty((count, n))
        compiled.module.ens_momenta(Q, rates, C, P)
    if scene.project and projected is not None:
        Q, P = projected[0].copy(), projected[1].copy()
    elif scene.project:
        for i in range(count):
            member = dataclasses.replace(mechanics, params=C[i].copy(), constant_mass=None)
            try:
                Q[i], P[i] = member.project(Q[i], P[i])
            except InputError as exc:
                raise InputError(f"member {i} ({_where(names, values[i])}): {exc}") from None
    return np.ascontiguousarray(Q), np.ascontiguousarray(P), np.ascontiguousarray(C)


def check_initial_states(scene: GeneralEnsembleScene, chunk_size: int | None = None) -> None:
    """Refuse, before anything is written, members whose initial state is off the constraint
    surface (with ``project = false``), or not finite, or cannot be projected (``project = true``).

    With ``chunk_size`` the members are taken chunk by chunk (the engine's chunks), and with
    ``project = true`` their projected states are kept for :func:`compute_general_chunk` in
    this process (the same function on the same members: the same bits), so that each member
    is projected once.

    The test is a single scene's (:class:`dirac.flows.problems.ConstrainedProblem`):
    ``|chi| <= 1e-9 (1 + |q|^2)`` and ``|G M^-1 p + d chi/dt| <= 1e-9 sqrt((1 + |q|^2)(1 + |p|^2))``.

    Raises
    ------
    InputError
        Naming the first offending member, its ensemble variables and the fix.
    """
    if scene.analysed:  # the Dirac flow of the system's analysis: its own initial states (kept as projected ones)
        from dirac.ensemble.analysed_members import check_analysed_states

        check_analysed_states(scene, chunk_size, _PROJECTED if chunk_size is not None else None, _PROJECTED_LIMIT)
        return
    compiled = compiled_ensemble(scene)
    m = compiled.mechanics.n_constraints
    keep = scene.project and m > 0 and chunk_size is not None and (
        2 * scene.count * len(scene.coordinate_names) <= _PROJECTED_LIMIT)
    block = chunk_size if keep and chunk_size is not None else _CHECK_BLOCK
    for start in range(0, scene.count, block):
        stop = min(scene.count, start + block)
        values = scene.source.members(start, stop)
        Q, P, C = initial_states(scene, compiled, values)
        if start == 0 and stop > 0:  # a mass matrix a single run refuses (singular, as an einbein's): refused too
            try:
                dataclasses.replace(compiled.mechanics, params=C[0].copy(), constant_mass=None).mass_matrix(Q[0])
            except InputError as exc:
                raise InputError(f"member 0 ({_where(scene.source.names, values[0])}): {exc}") from None
        if keep:
            _PROJECTED[(scene.fingerprint(), start, stop)] = (Q, P)
        if scene.project or m == 0:
            continue
        residual = np.empty((stop - start, 2 * m))
        compiled.module.ens_surface(Q, P, C, residual)
        qscale = 1.0 + np.einsum("ij,ij->i", Q, Q)
        pscale = np.sqrt(qscale * (1.0 + np.einsum("ij,ij->i", P, P)))
        off_q = np.any(np.abs(residual[:, :m]) > 1e-9 * qscale[:, None], axis=1)
        off_p = np.any(np.abs(residual[:, m:]) > 1e-9 * pscale[:, None], axis=1)
        off = off_q | off_p
        if np.any(off):
            i = int(np.argmax(off))
            what = "q" if off_q[i] else f"{scene.rate_kind} (velocities not tangent)"
            worst = float(np.max(np.abs(residual[i, :m] if off_q[i] else residual[i, m:])))
            raise InputError(
                f"[initial] {what} of member {start + i} ({_where(scene.source.names, values[i])}) is off the "
                f"constraint surface (residual {worst:.3g}); give [initial] expressions on the surface or set "
                "project = true in [initial]"
            )


def forget_projected(scene: GeneralEnsembleScene) -> None:
    """Drop the projected states :func:`check_initial_states` kept for ``scene`` (a run that
    ended without computing every chunk leaves some)."""
    key = scene.fingerprint()
    for entry in [entry for entry in _PROJECTED if entry[0] == key]:
        _PROJECTED.pop(entry, None)


def compute_general_chunk(scene: GeneralEnsembleScene, start: int, stop: int,
                          values: np.ndarray | None = None) -> dict[str, np.ndarray]:
    """Integrate members ``start .. stop-1`` and return their arrays (:meth:`GeneralEnsembleScene.array_layout`)."""
    if values is None:
        values = scene.source.members(start, stop)
    if scene.analysed:  # the Dirac flow of the system's analysis (dirac.ensemble.analysed_members)
        from dirac.ensemble.analysed_members import analysed_initial_states, compiled_analysed

        compiled = compiled_analysed(scene)
        completed = _PROJECTED.pop((scene.fingerprint(), start, stop), None)
        Q, P, C = analysed_initial_states(scene, compiled.mechanics, values, start, completed)
    else:
        compiled = compiled_ensemble(scene)
        projected = _PROJECTED.pop((scene.fingerprint(), start, stop), None)
        Q, P, C = initial_states(scene, compiled, values, projected)
    count, n = Q.shape
    starts, ends, per_interval, dt = step_grid(scene)
    n_cross, n_ext, n_poin, k_max = compiled.module.ENS_SHAPES
    CROSS = np.full((count, n_cross), np.nan)
    EXT = np.full((count, n_ext), np.nan)
    EERR = np.full(count, np.nan)
    CERR = np.full(count, np.nan)
    PT = np.full((count, n_poin, k_max), np.nan)
    PQ = np.full((count, n_poin, k_max, n), np.nan)
    PP = np.full((count, n_poin, k_max, n), np.nan)
    STATUS = np.zeros(count)
    STEPS = np.zeros(count)
    Q0, P0 = Q.copy(), P.copy()
    arguments = (Q, P, C, compiled.fractions, dt, starts, ends, per_interval, scene.newton_tolerance,
                 scene.max_newton_iterations, compiled.gamma, scene.early_stop,
                 CROSS, EXT, EERR, CERR, PT, PQ, PP, STATUS, STEPS)
    import numba

    with KERNEL_LOCK:
        try:
            compiled.module.ens_run(0, count, *arguments, numba.get_num_threads())
        except ZeroDivisionError:
            # a singular Newton matrix in some member: redo the members one by one to find it
            Q[:], P[:] = Q0, P0
            for array in (CROSS, EXT, EERR, CERR, PT, PQ, PP):
                array[:] = np.nan
            for i in range(count):
                try:
                    compiled.module.ens_member(i, *arguments)
                except ZeroDivisionError:
                    STATUS[i] = 3.0
    k = len(scene.coordinate_names)  # an analysed system's state also holds its multipliers: not stored
    return member_results(scene, values, compiled.layout, CROSS, EXT, {"t": PT, "q": PQ[..., :k], "p": PP[..., :k]},
                          {"final_q": Q[:, :k], "final_p": P[:, :k]}, EERR, CERR, STATUS, STEPS)


def member_results(scene: GeneralEnsembleScene, values: np.ndarray, layout: dict, CROSS: np.ndarray, EXT: np.ndarray,
                   sections: dict[str, np.ndarray], final: dict[str, np.ndarray], EERR: np.ndarray, CERR: np.ndarray,
                   STATUS: np.ndarray, STEPS: np.ndarray) -> dict[str, np.ndarray]:
    """A chunk's arrays by name from a member loop's outputs (general systems and the heavy top).

    ``values`` are the members' ensemble variables; ``sections`` the Poincaré arrays by
    suffix (``{"t": PT, "q": PQ, "p": PP}``: ``<name>_t`` ...), ``final`` the final state's
    arrays by name. A failed member's reductions are NaN.
    """
    results: dict[str, np.ndarray] = {name: values[:, k].copy() for k, name in enumerate(scene.source.names)}
    for index, (name, _group) in enumerate(layout["cross"]):
        results[name] = CROSS[:, index]
    for index, (name, _kind, _e) in enumerate(layout["ext"]):
        results[name] = EXT[:, index]
    for index, (name, _e, k) in enumerate(layout["poincare"]):
        for suffix, array in sections.items():
            results[f"{name}_{suffix}"] = array[:, index, :k]
    kinds = {r.kind for r in scene.reductions}
    if "final" in kinds:
        results.update(final)
    if "energy_error" in kinds:
        results["energy_error"] = EERR
    if "constraint_error" in kinds:
        results["constraint_error"] = CERR
    failed = STATUS != 0.0
    if np.any(failed):
        for name in list(results):
            if name not in scene.source.names:
                results[name] = np.array(results[name], dtype=float)
                results[name][failed] = np.nan
    results["failures"] = STATUS
    results["steps"] = STEPS
    return results
