"""Analysis time of the textbook linear field theories (:mod:`dirac.fields.catalog`).

Each theory is analysed mode by mode (``dirac.analyze(theory)``: the generic mode pair,
the zero mode and the special values, and the local gauge transformations) in a fresh Python process, as in
:mod:`dirac.bench.analysis_times`: the import of ``dirac`` and the building of the theory
are outside the timed region. The figure is the median CPU time over the repeats; the
target is 10 s per theory, linearised Einstein (ten field components, twenty mode
coordinates) included.
"""

from __future__ import annotations

import json
import subprocess
import sys
from statistics import median

__all__ = ["FIELD_THEORY_TARGET_SECONDS", "field_theory_runs", "field_theory_table"]

#: CPU seconds each linear theory's analysis may take
FIELD_THEORY_TARGET_SECONDS = 10.0

_CHILD = """
import json, time, warnings
import dirac
from dirac.fields.catalog import CATALOG
warnings.simplefilter("ignore")
theory = CATALOG[{name!r}]()
analyze = dirac.analyze
c0, w0 = time.process_time(), time.perf_counter()
a = analyze(theory)
gauge = len(a.gauge_generators)  # the local gauge transformations are part of the answer
cpu, wall = time.process_time() - c0, time.perf_counter() - w0
print(json.dumps({{"cpu": cpu, "wall": wall, "dof": a.physical_degrees_of_freedom,
                   "stages": a.constraints_per_stage, "first": a.first_class_count, "second": a.second_class_count,
                   "gauge": gauge}}))
"""


def field_theory_runs(repeats: int) -> list[tuple[str, list[dict]]]:
    """Each theory of the catalog with its ``repeats`` runs (fresh processes, theories interleaved)."""
    from dirac.fields.catalog import CATALOG

    runs: dict[str, list[dict]] = {name: [] for name in CATALOG}
    for _ in range(repeats):
        for name in CATALOG:
            completed = subprocess.run([sys.executable, "-c", _CHILD.format(name=name)], capture_output=True, text=True,
                                       timeout=900)
            if completed.returncode != 0:
                raise RuntimeError(f"{name}: the analysis process failed: {completed.stderr.strip().splitlines()[-1:]}")
            runs[name].append(json.loads(completed.stdout.strip().splitlines()[-1]))
    return list(runs.items())


def field_theory_table(runs: list[tuple[str, list[dict]]]) -> tuple[str, float]:
    """The table (one row per theory: counts per point and median CPU and wall seconds) and the largest median CPU."""
    lines = ["field theories (dirac.analyze mode by mode, fresh process, median of "
             f"{len(runs[0][1]) if runs else 0}; target <= {FIELD_THEORY_TARGET_SECONDS:g} s CPU each):",
             f"  {'theory':24s} {'stages':14s} {'first':>5s} {'second':>6s} {'dof/pt':>6s} {'gauge':>5s} {'CPU s':>7s} {'wall s':>7s}"]
    worst = 0.0
    for name, rows in runs:
        cpu = median(r["cpu"] for r in rows)
        wall = median(r["wall"] for r in rows)
        worst = max(worst, cpu)
        r = rows[0]
        lines.append(f"  {name:24s} {str(r['stages']):14s} {r['first']:5d} {r['second']:6d} {r['dof']:6d} "
                     f"{r.get('gauge', 0):5d} {cpu:7.2f} {wall:7.2f}")
    return "\n".join(lines), worst


if __name__ == "__main__":  # python -m dirac.bench.field_theories [REPEATS]: the table alone
    table, _ = field_theory_table(field_theory_runs(int(sys.argv[1]) if len(sys.argv) > 1 else 3))
    print(table)
