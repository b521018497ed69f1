"""Impulses in the member loop of a general ensemble: a single run's plan of pieces and kicks.

A single run of a system with ``[[impulses]]`` (:class:`dirac.flows.methods.forced.ForcedStepper`)
advances each sample interval in calls ``step(n, dt)`` of at most
:data:`dirac.flows.integration.CHUNK_STEPS` steps, and each call cuts the steps at the impulses
inside it (:func:`dirac.flows.methods.forced.plan_call`): pieces from the grid point to an
impulse, between impulses, and to the next grid point (counted as one step), a kick at each
impulse (on a grid point within ``1e-9 dt``: between two steps). :func:`run_plan` replays
that loop once per scene -- the same calls, from the same times -- and flattens the pieces
into operations per sample interval; the member loop (:func:`impulse_steps`) follows them,
each advance the system's own step at the piece's times (``base + k size``), each kick
:func:`dirac.flows.impulse_kick.impulse_kick` compiled from the text a single run runs, so a
member equals a single run to the last bit.

What the reductions see at a kick (the state just before and just after it are both states
of the trajectory, at the same time):

* ``max`` / ``min`` take the state after the kick as well as the one before;
* ``first_crossing``: a sign change of an expression across the kick (a momentum reversed by
  the blow) is a crossing at the kick's time, with its ``when`` condition evaluated just after
  the kick; no line is interpolated across the jump. Crossings inside a piece are located on
  the line between the piece's two states, as inside a step;
* ``poincare``: only crossings by the flow are section points (a jump across the section has
  no state on it); the first piece after a kick starts from the state after it.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from dirac.flows.methods.forced import Advance, plan_call

__all__ = ["ImpulsePlan", "run_plan", "single_run_call", "impulse_steps", "plan_source"]

#: operation kinds of a plan
ADVANCE, KICK = 0, 1


@dataclass(frozen=True)
class ImpulsePlan:
    """The operations of every sample interval: interval ``k`` runs ``lo[k] .. lo[k + 1] - 1``.

    Operation ``o`` is an advance (``kind 0``: ``count[o]`` steps of ``size[o]`` from
    ``time[o]``, then ``adjust[o]`` added to the step count) or a kick (``kind 1``: the
    impulse ``count[o]`` at ``time[o]``).
    """

    lo: np.ndarray
    kind: np.ndarray
    time: np.ndarray
    count: np.ndarray
    size: np.ndarray
    adjust: np.ndarray
    vectors: np.ndarray


def single_run_call() -> int:
    """Steps per ``step`` call of a single (unbatched) run within a sample interval
    (:meth:`dirac.flows.integration._Loop._run_fixed` with a batch of one and no chart guard)."""
    from dirac.flows.integration import CHUNK_STEPS, MIN_CHUNK_STEPS

    return max(MIN_CHUNK_STEPS, CHUNK_STEPS)


def run_plan(starts: np.ndarray, per_interval: int, dt: float,
             impulses: tuple[tuple[float, tuple[float, ...]], ...], call: int | None = None) -> ImpulsePlan:
    """The single run's pieces and kicks over the sample intervals starting at ``starts``
    (``per_interval`` steps of ``dt`` each), with the ``impulses`` ``(t, J)`` sorted by time,
    in calls of ``call`` steps (default :func:`single_run_call`)."""
    call = single_run_call() if call is None else call
    times = [float(t) for t, _ in impulses]
    lo = [0]
    kind: list[int] = []
    time: list[float] = []
    count: list[int] = []
    size: list[float] = []
    adjust: list[int] = []
    used = 0
    for start in starts:
        now = float(start)  # the loop sets the stepper's time to the sample time after each interval
        done = 0
        while done < per_interval:
            n = min(call, per_interval - done)
            plan, taken = plan_call(now, n, dt, times[used:])
            for piece in plan:
                if isinstance(piece, Advance):
                    steps = piece.steps if piece.steps > 0 and piece.size > 0.0 else 0  # as _advance skips
                    kind.append(ADVANCE)
                    time.append(piece.base)
                    count.append(steps)
                    size.append(piece.size)
                    adjust.append(piece.adjust)
                else:
                    kind.append(KICK)
                    time.append(piece.time)
                    count.append(used + piece.impulse)
                    size.append(0.0)
                    adjust.append(0)
            used += taken
            now = now + n * dt
            done += n
        lo.append(len(kind))
    width = len(impulses[0][1]) if impulses else 0
    vectors = np.array([list(vector) for _, vector in impulses], dtype=np.float64).reshape(len(impulses), width)
    return ImpulsePlan(np.array(lo, dtype=np.int64), np.array(kind, dtype=np.int64), np.array(time, dtype=np.float64),
                       np.array(count, dtype=np.int64), np.array(size, dtype=np.float64),
                       np.array(adjust, dtype=np.int64), vectors)


def _literal(array: np.ndarray) -> str:
    dtype = "np.int64" if array.dtype.kind == "i" else "np.float64"
    values = ", ".join(repr(int(x)) if array.dtype.kind == "i" else repr(float(x)) for x in array.ravel())
    return f"np.array([{values}], dtype={dtype}).reshape({array.shape!r})"


def plan_source(plan: ImpulsePlan) -> str:
    """The plan as constants of the generated module and the kick (:func:`dirac.flows.impulse_kick.kick_source`)."""
    from dirac.flows.impulse_kick import kick_source

    lines = ["", "", "# ---- impulses (dirac.ensemble.impulse_plan) ----"]
    for name in ("lo", "kind", "time", "count", "size", "adjust", "vectors"):
        lines.append(f"ENS_OP_{name.upper()} = {_literal(getattr(plan, name))}")
    return "\n".join(lines) + "\n\n\n" + kick_source() + "\n"


def impulse_steps(body: list[str], layout: dict, conditions: list, n: int, m: int, n_values: int,
                  decided: list[str]) -> list[str]:
    """The member loop's steps of one sample interval following the plan: ``body`` is the
    loop body of one step (lines at depth 3, run with ``m_a`` the base time, ``m_j`` the
    step number and ``dt`` the step), replaced by a loop over the interval's operations
    (depth 2), each an advance (``body`` one level deeper, once per step) or a kick
    (module docstring); ``decided`` the member's stopping conditions."""
    out: list[str] = []

    def w(depth: int, text: str) -> None:
        out.append("    " * depth + text)

    w(2, "for m_o in range(ENS_OP_LO[m_k], ENS_OP_LO[m_k + 1]):")
    w(3, f"if ENS_OP_KIND[m_o] == {KICK}:")
    w(4, "m_tk = ENS_OP_TIME[m_o]")
    w(4, f"for m_x in range({n_values}):")
    w(5, "m_fa[m_x] = m_f[m_x]")
    w(4, f"m_M = np.empty(({n}, {n}))")
    w(4, "mass(q, m_tk, c, m_M)")
    w(4, f"m_G = np.zeros(({m}, {n}))")
    if m:
        w(4, "jacobian(q, m_tk, c, m_G)")
    w(4, "work_done[0] += impulse_kick(m_M, m_G, p, ENS_OP_VECTORS[ENS_OP_COUNT[m_o]])")
    w(4, "ens_velocity(q, p, m_tk, c, m_v, m_vw, m_vpiv)")
    w(4, "ens_values(q, p, m_v, m_tk, c, m_f)")
    for x, (_, kind, e) in enumerate(layout["ext"]):
        w(4, f"if m_f[{e}] {'>' if kind == 'max' else '<'} EXT[m_i, {x}]:")
        w(5, f"EXT[m_i, {x}] = m_f[{e}]")
    for gi, (_, group) in enumerate(layout["cross"]):
        w(4, f"if CROSS[m_i, {gi}] != CROSS[m_i, {gi}]:")
        for e, cond in group:
            w(5, f"if (m_fa[{e}] < 0.0 and m_f[{e}] >= 0.0) or (m_fa[{e}] > 0.0 and m_f[{e}] <= 0.0):")
            if cond >= 0:
                w(6, "ens_conditions(q, p, m_v, m_tk, c, m_g)")
                w(6, f"if m_g[{cond}] {conditions[cond][1]} 0.0:")
                w(7, f"CROSS[m_i, {gi}] = m_tk")
            else:
                w(6, f"CROSS[m_i, {gi}] = m_tk")
    if decided:
        w(4, f"if early and {' and '.join(decided)}:")
        w(5, "m_stop = True")
        w(5, "break")
    w(4, "continue")
    w(3, "m_a = ENS_OP_TIME[m_o]")
    w(3, "dt = ENS_OP_SIZE[m_o]")
    w(3, "for m_j in range(ENS_OP_COUNT[m_o]):")
    out.extend("    " + line if line.strip() else line for line in body)
    w(3, "m_steps += ENS_OP_ADJUST[m_o]")
    w(3, "if m_stop:")
    w(4, "break")
    return out
