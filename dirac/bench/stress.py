"""``dirac bench --stress``: long runs, hard bodies and constrained long runs.

Three parts, each a list of rows with a pass/fail verdict against a stated criterion:

1. **Long runs** on the standard body (:mod:`dirac.bench.standard_body`):
   ``lie-poisson-2`` for ``1e7`` steps and ``lie-poisson-4``/``-6`` for ``1e6`` steps; the
   Casimir ``|M|^2`` and ``R^T R = 1`` of the Euler–Poisson flow (250)–(251) stay within
   ``2e-12`` and the energy ``H_0`` (247) error does not grow secularly
   (:mod:`dirac.bench.long_runs`, criteria in :mod:`dirac.bench.stress_criteria`).
2. **Hard bodies**: near the separatrix, near-symmetric, needle-like, flat and a fast spin;
   every method against the 50-digit Taylor reference
   (:mod:`dirac.bench.hard_bodies`, :mod:`dirac.bench.taylor_reference`).
3. **Constrained long runs**: ``rattle-2`` on the pendulum and the double pendulum over
   ``1e6`` steps; the constraint residual stays at the Newton tolerance and the energy
   error is bounded as in part 1 (:mod:`dirac.bench.long_runs`).

This module holds the plan (which runs, of what size) and runs it
(:func:`run_stress`); :mod:`dirac.bench.stress_tables` prints the result and
:mod:`dirac.commands.bench_stress` is the command.
"""

from __future__ import annotations

import time
from collections.abc import Callable
from dataclasses import dataclass, field

from dirac.bench.hard_bodies import HARD_BODIES, HardBody, hard_body_rows
from dirac.bench.long_runs import constrained_long_run, long_run

__all__ = ["StressPlan", "plan", "run_stress"]


@dataclass
class StressPlan:
    """Sizes of one stress run (``quick`` shrinks every part)."""

    long_runs: list[tuple[str, int, float]] = field(default_factory=list)
    constrained: list[tuple[str, str, int, float]] = field(default_factory=list)
    bodies: tuple[HardBody, ...] = HARD_BODIES
    samples: int = 201


def plan(quick: bool) -> StressPlan:
    """The full sizes, or a quick version (``quick``) 100 times shorter."""
    factor = 100 if quick else 1
    return StressPlan(
        long_runs=[("lie-poisson-2", 10_000_000 // factor, 0.01), ("lie-poisson-4", 1_000_000 // factor, 0.05),
                   ("lie-poisson-6", 1_000_000 // factor, 0.05)],
        constrained=[("pendulum", "rattle-2", 1_000_000 // factor, 0.01),
                     ("double_pendulum", "rattle-2", 1_000_000 // factor, 0.01)],
        bodies=HARD_BODIES,
        samples=101 if quick else 201,
    )


def run_stress(quick: bool = False, progress: Callable[[str], None] | None = None) -> dict:
    """Run every part; return ``{"machine", "long_runs", "hard_bodies", "constrained", "passed"}``."""
    from dirac.bench.report import machine_description

    say = progress or (lambda message: None)
    sizes = plan(quick)
    document: dict = {"machine": machine_description(), "quick": bool(quick)}
    start = time.perf_counter()
    document["long_runs"] = []
    for method, steps, dt in sizes.long_runs:
        say(f"long run: {method}, {steps} steps")
        document["long_runs"].append(long_run(method, steps, dt))
    document["hard_bodies"] = []
    for body in sizes.bodies:
        say(f"hard body: {body.name}")
        document["hard_bodies"].extend(hard_body_rows(body, samples=sizes.samples))
    document["constrained"] = []
    for system, method, steps, dt in sizes.constrained:
        say(f"constrained long run: {system}, {method}, {steps} steps")
        document["constrained"].append(constrained_long_run(system, method, steps, dt))
    document["wall_seconds"] = time.perf_counter() - start
    rows = document["long_runs"] + document["hard_bodies"] + document["constrained"]
    document["passed"] = all(row["passed"] for row in rows)
    return document
