"""``dirac bench --latency [--quick] [--json FILE]``: time to the first result on everyday systems.

Each system of the corpus (:mod:`dirac.bench.latency`) runs in a fresh process with an
empty cache of generated code and the default kernel policy: a first result, a 1e5-step
study, a ``t_end = 100`` run beside scipy's DOP853 on a hand-written right-hand side, and
the paper's rigid-body Lagrangians through ``dirac analyze``. Prints the table and the
compile time against kernel size. Exit status 0 when every wall-time target is met and
no ``t_end`` run takes more CPU than scipy (the medians of repeated runs), 1 otherwise.
"""

from __future__ import annotations

import argparse
import json
import sys


def main(args: argparse.Namespace) -> int:
    from dirac.bench.latency import CORPUS, format_latency, rows_as_json, run_latency, targets_met

    quick = bool(getattr(args, "quick", False))
    progress = None
    if not getattr(args, "no_progress", False) and getattr(args, "verbosity", 0) >= 0:
        def progress(text: str) -> None:
            print(text, file=sys.stderr, flush=True)
    models = CORPUS[:3] if quick else CORPUS
    rows = run_latency(models, study_steps=10_000 if quick else 100_000, analyze=() if quick else
                       ("rigid_body_momentum", "rigid_body_particles", "rigid_body_matrix"), progress=progress)
    print(format_latency(rows))
    if getattr(args, "json", None):
        with open(args.json, "w", encoding="utf-8") as stream:
            json.dump({"latency": rows_as_json(rows)}, stream, indent=1)
    return 0 if targets_met(rows) else 1
