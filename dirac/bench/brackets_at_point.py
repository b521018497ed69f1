"""``brackets at a point``: Dirac brackets and the motion at a numeric point of the planar chain.

For the chain of ``N`` links (``dirac_systems.scale_models.chain``: ``6N`` phase-space
variables, ``4N`` second-class constraints) analysed once, this measures the CPU time of

* ``dirac_bracket(f, g, at=point)`` for pairs of phase-space variables not asked before,
  at a point already met (``C`` factorised: the cost of one bracket), and at a new point
  each call (evaluation and sparse factorisation of ``C`` included);
* ``equations_of_motion(at=point)``: every ``z_dot`` at a new point each call;
* the baseline a user would write by hand for ``{x_i, p_j}_D``: the closed form
  ``delta_ij - (G^T (G G^T)^{-1} G)_ij`` with numpy, one dense ``N x N`` solve
  (tests/analysis/brackets/test_dirac_bracket_at_point.py derives it).

Each size runs in a fresh process. The minimum over repeats of the CPU time per call is reported (the machine is shared:
the minimum is the figure least disturbed by other jobs). Target: a bracket, and the
motion, at a new point of the 128-link chain within 5 ms.
"""

from __future__ import annotations

import json
import os
import subprocess
import sys
import tempfile

from dirac.bench.targets import Target

__all__ = ["measure_brackets_at_point", "format_brackets_at_point"]

#: the target: milliseconds per bracket (or motion) at a new point of the largest chain
TARGET_MS = 5.0


#: what a fresh process runs for one size: the public API as a user calls it (the analysis layer is
#: above the bench's, so it is imported there, not here); prints one JSON line
_CHILD = r"""
import json, sys, time
import numpy as np
import dirac
from dirac_systems.scale_models import chain

n, repeats = int(sys.argv[1]), int(sys.argv[2])


def per_call(function, calls):
    best = np.inf
    for _ in range(repeats):
        start = time.process_time()
        for k in range(calls):
            function(k)
        best = min(best, (time.process_time() - start) / calls)
    return float(best)


def closed_form(point, i, j):
    # {x_i, p_x_j}_D = delta_ij - (G^T (G G^T)^-1 G)_ij over (x1, y1, x2, ...), numpy, dense
    r = np.array([[point[f"x{k}"], point[f"y{k}"]] for k in range(1, n + 1)])
    G = np.zeros((n, 2 * n))
    for k in range(n):
        d = r[k] - (r[k - 1] if k else 0.0)
        G[k, 2 * k:2 * k + 2] = d
        if k:
            G[k, 2 * k - 2:2 * k] = -d
    return float((i == j) - G[:, 2 * (i - 1)] @ np.linalg.solve(G @ G.T, G[:, 2 * (j - 1)]))


start = time.process_time()
analysis = dirac.analyze(chain(n))
analyse_s = time.process_time() - start
point = analysis.surface_point(seed=1)
start = time.process_time()
analysis.dirac_bracket("x1", "p_x1", at=point)
first_s = time.process_time() - start
names = [s.name for s in analysis.phase_space]
pairs = [(names[a], names[b]) for a, b in np.random.default_rng(7).integers(0, len(names), (200, 2))]
calls = 20
points = [dict(point, p_x1=point["p_x1"] + 1e-6 * (k + 1)) for k in range(2 * calls * repeats + 2)]
used = iter(points)
same = per_call(lambda k: analysis.dirac_bracket(*pairs[k % len(pairs)], at=point), 100)
fresh = per_call(lambda k: analysis.dirac_bracket("x1", f"p_x{n}", at=next(used)), calls)
motion = per_call(lambda k: analysis.equations_of_motion(at=next(used)), calls)
by_hand = per_call(lambda k: closed_form(point, 1, n), calls)
error = abs(analysis.dirac_bracket(f"x{n - 1}", f"p_x{n}", at=point) - closed_form(point, n - 1, n))
print(json.dumps({"N": n, "variables": len(names), "second_class": len(analysis.second_class),
                  "analyse_s": analyse_s, "first_bracket_s": first_s, "bracket_same_point_ms": same * 1e3,
                  "bracket_new_point_ms": fresh * 1e3, "motion_new_point_ms": motion * 1e3,
                  "closed_form_ms": by_hand * 1e3, "error": error}))
"""


def _chain_row(n: int, repeats: int) -> dict:
    """One size in a fresh process (its own cache of generated code)."""
    with tempfile.TemporaryDirectory(prefix="dirac-brackets-") as scratch:
        env = dict(os.environ, DIRAC_CACHE_DIR=scratch)
        result = subprocess.run([sys.executable, "-c", _CHILD, str(n), str(repeats)], env=env, capture_output=True,
                                text=True, timeout=1800)
    if result.returncode != 0:
        raise RuntimeError(f"child failed: {result.stderr.strip().splitlines()[-1:]}")
    return json.loads(result.stdout.strip().splitlines()[-1])


def measure_brackets_at_point(quick: bool, repeats: int = 5) -> tuple[list[dict], list[Target]]:
    """The rows (N = 8, 32; and 128 unless ``quick``) and the targets at the largest N."""
    sizes = (8, 32) if quick else (8, 32, 128)
    rows = [_chain_row(n, repeats) for n in sizes]
    largest = rows[-1]
    targets = [
        Target(f"brackets at a point: dirac_bracket at a new point, chain of {largest['N']} links (ms)",
               largest["bracket_new_point_ms"], "ms", TARGET_MS, "<=",
               f"CPU, min over repeats; C evaluated and factorised at each point; the closed form by hand "
               f"{largest['closed_form_ms']:.2f} ms"),
        Target(f"brackets at a point: equations_of_motion at a new point, chain of {largest['N']} links (ms)",
               largest["motion_new_point_ms"], "ms", TARGET_MS, "<=", "CPU, min over repeats; every z_dot"),
        Target("brackets at a point: largest difference from the closed form", max(r["error"] for r in rows), "",
               1e-9, "<=", "{x_(N-1), p_x_N}_D against delta - G^T (G G^T)^{-1} G"),
    ]
    return rows, targets


def format_brackets_at_point(rows: list[dict]) -> str:
    """The ``brackets at a point`` table."""
    lines = ["brackets at a point: the planar chain (CPU ms per call, min over repeats; analysis once per N)",
             f"  {'N':>4} {'vars':>5} {'2nd cl':>6} {'analyse s':>9} {'1st s':>6} {'same pt':>8} {'new pt':>7} "
             f"{'motion':>7} {'by hand':>8} {'error':>8}"]
    lines += [f"  {r['N']:>4} {r['variables']:>5} {r['second_class']:>6} {r['analyse_s']:>9.2f} "
              f"{r['first_bracket_s']:>6.2f} {r['bracket_same_point_ms']:>8.3f} {r['bracket_new_point_ms']:>7.2f} "
              f"{r['motion_new_point_ms']:>7.2f} {r['closed_form_ms']:>8.2f} {r['error']:>8.1e}" for r in rows]
    lines.append("  same pt: a bracket of new variables at a point already met; new pt: C evaluated and factorised "
                 "too; motion: equations_of_motion(at=) at a new point; by hand: numpy's closed form of {x_1, p_x_N}_D")
    return "\n".join(lines)
