"""``dirac bench --stress [--quick] [--json FILE] [--no-progress]``: the stress benchmark.

Prints the machine line and the tables of :func:`dirac.bench.stress.run_stress`; writes
every row as JSON with ``--json``. Exit status 0 when every row passed, 1 otherwise.
"""

from __future__ import annotations

import argparse
import json
import sys


def main(args: argparse.Namespace) -> int:
    """Run the stress benchmark with the flags of ``dirac bench`` (``quick``, ``json``, ``no_progress``)."""
    from dirac.bench.report import machine_line
    from dirac.bench.stress import run_stress
    from dirac.bench.stress_tables import format_table

    quick = bool(getattr(args, "quick", False))
    json_path = getattr(args, "json", None)
    show = not bool(getattr(args, "no_progress", False)) and getattr(args, "verbosity", 0) >= 0

    def progress(message: str) -> None:
        if show:
            print(f"stress: {message}", file=sys.stderr, flush=True)

    document = run_stress(quick=quick, progress=progress)
    print(f"machine: {machine_line(document['machine'])}")
    print(format_table(document))
    if json_path:
        with open(json_path, "w", encoding="utf-8") as stream:
            json.dump(document, stream, indent=1, default=lambda v: v.item() if hasattr(v, "item") else str(v))
    return 0 if document["passed"] else 1
