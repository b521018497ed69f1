"""``dirac bench --scale [--quick] [--json FILE] [--plot FILE.png]``: analysis time against system size.

Each size of each model (:mod:`dirac.bench.scale`) is measured in a fresh Python process
running :func:`measure_one` (import excluded from the timed region, that of the analysis and of
the scipy modules it imports on first use; peak memory from the
operating system), stopped after a time budget; the table, the fitted exponents and the
targets are printed. Exit status 0 when every measured target is met, 1 otherwise.
"""

from __future__ import annotations

import argparse
import json
import os
import subprocess
import sys
import time

#: seconds one size may take before its process is stopped (larger sizes are then skipped)
BUDGET_SECONDS = 180.0
QUICK_BUDGET_SECONDS = 60.0
#: dirac_bracket(at=) calls timed after the first one
BRACKET_CALLS = 20
#: thread counts of the BLAS libraries, set to 1 in the measuring processes unless already set:
#: the analysis factorises many small dense blocks, for which BLAS threads only add
#: contention (on a loaded 2-core machine a 256 x 127 QR took 0.5-4 s with threads, 2 ms without)
BLAS_THREAD_VARIABLES = ("OPENBLAS_NUM_THREADS", "OMP_NUM_THREADS", "MKL_NUM_THREADS")


def measure_one(model: str, size: int) -> dict:
    """Analyse one model at one size in this process: seconds of ``analyze`` and of ``dirac_bracket(at=)``.

    The bracket is ``{x1, p_x1}_D`` (chain) or ``{A1_1, p_A1_1}_D`` / ``{Ax_0_0, p_Ax_0_0}_D``
    (Maxwell) at a point of the constraint surface.
    """
    import importlib
    import resource

    # scipy: the libraries the analysis imports on first use on its road for many variables
    # (sparse elimination, SPARSE_HESSIAN and LARGE_SYSTEM), imported here, outside the timed region
    # like the analysis itself, so that their import (0.1 s, a constant of the process) is not read
    # as growth between a size below those thresholds and one above (the torus of 4 x 4 and 5 x 5)
    import scipy.linalg  # noqa: F401
    import scipy.sparse  # noqa: F401
    import scipy.sparse.linalg  # noqa: F401

    from dirac.analysis.constraint_analysis import analyze

    # the models are functions of the size in the systems package (dirac_systems), which
    # the engine never imports at module level: looked up here, in the measuring process
    system = getattr(importlib.import_module("dirac_systems.scale_models"), model)(size)
    start = time.perf_counter()
    analysis = analyze(system)
    analyze_s = time.perf_counter() - start
    counts = (
        f"stages {'+'.join(str(len(s)) for s in analysis.stages)}, {len(analysis.first_class)} first, "
        f"{len(analysis.second_class)} second class, {len(analysis.reducible_constraints)} reducible, "
        f"{analysis.physical_degrees_of_freedom} dof"
    )
    pair = {"chain": ("x1", "p_x1"), "maxwell_ring": ("A1_1", "p_A1_1"), "maxwell_torus": ("Ax_0_0", "p_Ax_0_0")}[model]
    point = analysis.surface_point(seed=1)
    start = time.perf_counter()
    analysis.dirac_bracket(*pair, at=point)
    first = time.perf_counter() - start
    start = time.perf_counter()
    for _ in range(BRACKET_CALLS):
        analysis.dirac_bracket(*pair, at=point)
    per_call_ms = (time.perf_counter() - start) / BRACKET_CALLS * 1e3
    peak_mb = resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1024.0
    return {"analyze_s": analyze_s, "first_bracket_s": first, "bracket_ms": per_call_ms, "peak_mb": peak_mb, "counts": counts}


def _measure_in_child(model: str, size: int, budget: float) -> dict:
    """:func:`measure_one` in a fresh process; ``{"failed": why}`` when it fails or runs over ``budget``."""
    code = (
        "import json, sys; from dirac.commands.bench_scale import measure_one; "
        f"print(json.dumps(measure_one({model!r}, {size})))"
    )
    env = dict(os.environ)
    for name in BLAS_THREAD_VARIABLES:  # unless the user chose: see BLAS_THREADS
        env.setdefault(name, "1")
    try:
        done = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, timeout=budget, env=env)
    except subprocess.TimeoutExpired:
        return {"failed": f"over the {budget:g} s budget"}
    if done.returncode != 0:
        last = (done.stderr.strip().splitlines() or ["no output"])[-1]
        return {"failed": last[:160]}
    return json.loads(done.stdout.strip().splitlines()[-1])


def run_scale(quick: bool, progress) -> list:
    """Measure every model at its sizes, smallest first; a size over budget ends that model."""
    from dirac.bench.scale import ScaleRow, phase_space_size, scale_sizes

    budget = QUICK_BUDGET_SECONDS if quick else BUDGET_SECONDS
    rows: list[ScaleRow] = []
    for model, sizes in scale_sizes(quick).items():
        for size in sizes:
            progress(f"{model} at size {size}")
            result = _measure_in_child(model, size, budget)
            row = ScaleRow(model, size, phase_space_size(model, size), result.get("analyze_s"),
                           result.get("first_bracket_s"), result.get("bracket_ms"), result.get("peak_mb"),
                           result.get("counts", ""), result.get("failed", ""))
            rows.append(row)
            if row.failed:
                break
    return rows


def main(args: argparse.Namespace) -> int:
    """Run the scale benchmark with the flags of ``dirac bench`` (``quick``, ``json``, ``plot``, ``no_progress``)."""
    from dirac.bench.report import format_targets, machine_description, machine_line
    from dirac.bench.scale import format_scale_rows, scale_targets, write_scale_plot

    quick = bool(getattr(args, "quick", False))
    show = not bool(getattr(args, "no_progress", False)) and getattr(args, "verbosity", 0) >= 0

    def progress(message: str) -> None:
        if show:
            print(f"scale: {message}", file=sys.stderr, flush=True)

    machine = machine_description()
    rows = run_scale(quick, progress)
    targets = scale_targets(rows, quick)
    command = "dirac bench --scale" + (" --quick" if quick else "")
    print(f"{command}: dirac.analyze wall time against system size, every figure measured in this run")
    print(f"machine: {machine_line(machine)}")
    threads = ", ".join(f"{name}={os.environ.get(name, '1')}" for name in BLAS_THREAD_VARIABLES)
    print(f"measuring processes: {threads} (BLAS threads; 1 unless set in the environment)")
    print(format_scale_rows(rows))
    print(format_targets(targets))
    if getattr(args, "json", None):
        with open(args.json, "w", encoding="utf-8") as stream:
            json.dump({"command": command, "machine": machine, "rows": [r.as_dict() for r in rows],
                       "targets": [t.as_dict() for t in targets]}, stream, indent=1)
        print(f"wrote {args.json}")
    if getattr(args, "plot", None):
        write_scale_plot(args.plot, rows, f"{command} -- {machine_line(machine)}")
        print(f"wrote {args.plot}")
    return 0 if all(t.met is not False for t in targets) else 1
