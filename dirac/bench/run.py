"""``dirac bench`` end to end: work–precision suite, targets, table, JSON and plot."""

from __future__ import annotations

import sys
import time
import warnings
from collections.abc import Callable
from typing import TYPE_CHECKING

if TYPE_CHECKING:
    from dirac.bench.targets import Target

__all__ = ["run_benchmark"]


def _progress(enabled: bool) -> Callable[[str], None]:
    start = time.perf_counter()

    def report(message: str) -> None:
        if enabled:
            print(f"[{time.perf_counter() - start:6.1f} s] {message}", file=sys.stderr, flush=True)

    return report


def run_benchmark(quick: bool, json_path: str | None = None, plot_path: str | None = None,
                  progress: bool = True, targets: bool = True) -> dict:
    """Run the benchmark and print its report on stdout; return the JSON document.

    Parameters
    ----------
    quick : bool
        Smaller grid and sizes (under a minute); otherwise the full run (under ten).
    json_path, plot_path : str, optional
        Where to write the JSON rows and the work–precision plot.
    progress : bool
        Progress lines on stderr.
    targets : bool
        Also measure the kernel/batch/start-up targets (the tests switch them off).
    """
    from dirac.bench.report import (
        format_rows,
        format_targets,
        machine_description,
        machine_line,
        write_json,
    )
    from dirac.bench.suite import constrained_cases, rigid_body_cases
    from dirac.bench.workprecision import run_constrained_case, run_rigid_body_case

    say = _progress(progress)
    started = time.perf_counter()
    machine = machine_description()
    repeats = 3 if quick else 7
    rows: list[dict] = []
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")  # e.g. the standard body's inertia warning, once per run
        for case in rigid_body_cases(quick):
            rows += run_rigid_body_case(case, repeats, say)
        for constrained in constrained_cases(quick):
            try:
                rows += run_constrained_case(constrained, repeats, say)
            except Exception as exc:  # a system that cannot be built is reported, not fatal
                rows.append({"problem": constrained.name, "method": "-", "parameter": "", "value": None, "t_end": 0.0,
                             "failed": f"{type(exc).__name__}: {' '.join(str(exc).split())[:200]}"})
        if targets:  # the heavy-top table is there for its targets (the tests' small suites run neither)
            from dirac.bench.heavy_top import heavy_top_cases, run_heavy_top_case

            for top in heavy_top_cases(quick):
                rows += run_heavy_top_case(top, repeats, say)
            from dirac.bench.torqued import run_torqued_case, torqued_cases

            for torqued in torqued_cases(quick):
                rows += run_torqued_case(torqued, repeats, say)
    measured: list[Target] = []
    notes: list[str] = []
    field_rows: list[dict] = []
    general_rows: list = []
    forced: list[dict] = []
    if targets:
        from dirac.bench.general_systems import measure_general_systems
        from dirac.bench.targets import measure_targets
        from dirac.bench.vector_field import measure_vector_field

        measured, notes = measure_targets(quick, rows, say)
        say("Dirac vector field against a lean Python right-hand side")
        try:
            field_rows, field_target = measure_vector_field(repeats, 20_000, 10_000, before=not quick)
            measured.append(field_target)
        except Exception as exc:  # one failed measurement must not hide the others
            notes.append(f"vector field: not measured ({type(exc).__name__}: {' '.join(str(exc).split())[:200]})")
        general_rows = measure_general_systems(quick, measured, notes, say)
        from dirac.bench.forced import forced_rows, forced_target

        try:
            forced = forced_rows(quick, repeats, say)
            measured.append(forced_target(forced))
        except Exception as exc:  # one failed measurement must not hide the others
            notes.append(f"forced systems: not measured ({type(exc).__name__}: {' '.join(str(exc).split())[:200]})")
        say("brackets at a point: the chain at 8, 32, 128 links")
        try:
            from dirac.bench.brackets_at_point import format_brackets_at_point, measure_brackets_at_point

            bracket_rows, bracket_targets = measure_brackets_at_point(quick, repeats)
            measured.extend(bracket_targets)
            notes.append(format_brackets_at_point(bracket_rows))
        except Exception as exc:  # one failed measurement must not hide the others
            notes.append(f"brackets at a point: not measured ({type(exc).__name__}: {' '.join(str(exc).split())[:200]})")
        say("field theories: the linear theories analysed mode by mode")
        try:
            from dirac.bench.field_theories import FIELD_THEORY_TARGET_SECONDS, field_theory_runs, field_theory_table
            from dirac.bench.targets import Target

            table, worst = field_theory_table(field_theory_runs(1 if quick else 3))
            measured.append(Target("analysis: slowest linear field theory (s CPU)", worst, "s",
                                   FIELD_THEORY_TARGET_SECONDS, "<=", "dirac.analyze(theory) in a fresh process"))
            notes.append(table)
        except Exception as exc:  # one failed measurement must not hide the others
            notes.append(f"field theories: not measured ({type(exc).__name__}: {' '.join(str(exc).split())[:200]})")
        say("codegen scale: chain first call and per-step cost against N, cold first results")
        try:
            from dirac.bench.codegen_scale import codegen_scale_targets

            scale_targets, scale_table = codegen_scale_targets(quick)
            measured.extend(scale_targets)
            notes.append(scale_table)
        except Exception as exc:  # one failed measurement must not hide the others
            notes.append(f"codegen scale: not measured ({type(exc).__name__}: {' '.join(str(exc).split())[:200]})")
    else:
        from dirac.bench.targets import work_precision_targets

        measured = work_precision_targets(rows)
    elapsed = time.perf_counter() - started
    command = "dirac bench" + (" --quick" if quick else "")
    print(f"{command}: work-precision against scipy baselines, every figure measured in this run")
    print(f"machine: {machine_line(machine)}")
    print("CPU ms = median over repeats of the integration's CPU time (compiled kernels, warm-up excluded); "
          "errors at T against independent references")
    print(format_rows(rows))
    if field_rows:
        from dirac.bench.vector_field import format_vector_field_table

        print(format_vector_field_table(field_rows))

    if general_rows:
        from dirac.bench.general_systems import format_general_rows

        print(format_general_rows(general_rows))
    if forced:
        from dirac.bench.forced import format_forced_rows

        print(format_forced_rows(forced))
    print(format_targets(measured))
    for note in notes:
        print(f"note: {note}")
    print(f"\ntotal wall time {elapsed:.1f} s")
    document = {
        "command": command,
        "quick": quick,
        "machine": machine,
        "elapsed_s": elapsed,
        "runs": rows,
        "targets": [t.as_dict() for t in measured],
        "vector_field": field_rows,
        "general_systems": [row.as_dict() for row in general_rows],
        "forced_systems": forced,
        "notes": notes,
    }
    if json_path:
        write_json(json_path, document)
        print(f"wrote {json_path}")
    if plot_path:
        from dirac.bench.report import write_plot

        write_plot(plot_path, rows, f"{command} -- {machine_line(machine)}")
        print(f"wrote {plot_path}")
    return document
