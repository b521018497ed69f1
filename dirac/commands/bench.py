"""``dirac bench``: work–precision benchmark against scipy baselines, in one run.

``dirac bench [--quick] [--json FILE] [--plot FILE.png]``. The flags ``--stress``,
``--ensemble``, ``--latency`` (:mod:`dirac.commands.bench_latency`) and ``--scale`` (:mod:`dirac.commands.bench_scale`) hand over to their own commands, :mod:`dirac.commands.bench_stress` and
:mod:`dirac.commands.bench_ensemble`, when those are installed.
"""

from __future__ import annotations

import argparse
import importlib
import os
from pathlib import Path

from dirac.errors import InputError


def register(subparsers: argparse._SubParsersAction) -> argparse.ArgumentParser:
    parser = subparsers.add_parser(
        "bench",
        help="work-precision benchmark against scipy baselines",
        description="Work-precision benchmark: every method at a range of step sizes or tolerances on a suite "
        "of rigid bodies and constrained systems, CPU time (median of repeats) against the global error from "
        "independent references, plus kernel, batch, memory and start-up figures against their targets. "
        "Every ratio is against a baseline measured in the same run.",
    )
    parser.add_argument("--quick", action="store_true", help="small grid and sizes (under a minute)")
    parser.add_argument("--json", metavar="FILE", help="write every run (one row each) and the targets as JSON")
    parser.add_argument("--plot", metavar="FILE.png", help="draw CPU time against error (log-log)")
    parser.add_argument("--no-progress", action="store_true", help="no progress lines on stderr")
    parser.add_argument("--stress", action="store_true", help="run the stress benchmark instead (docs/stress.md)")
    parser.add_argument("--ensemble", action="store_true", help="run the ensemble benchmark instead (docs/ensembles.md)")
    parser.add_argument("--latency", action="store_true",
                        help="time to the first result on everyday systems, fresh process and empty cache (docs/performance.md)")
    parser.add_argument("--scale", action="store_true",
                        help="analysis time against system size instead, with fitted exponents (docs/scale.md)")
    return parser


def _delegate(flag: str, module_name: str, args: argparse.Namespace) -> int:
    try:
        module = importlib.import_module(module_name)
    except ModuleNotFoundError as exc:
        if exc.name is not None and module_name.startswith(exc.name):
            raise InputError(f"dirac bench --{flag} is not available in this version yet") from None
        raise
    return int(module.main(args) or 0)


def main(args: argparse.Namespace) -> int:
    previous = os.environ.get("DIRAC_KERNELS")
    os.environ["DIRAC_KERNELS"] = "compiled"  # the benchmark times compiled kernels, never the interpreted tier
    try:
        return _main(args)
    finally:
        if previous is None:
            os.environ.pop("DIRAC_KERNELS", None)
        else:
            os.environ["DIRAC_KERNELS"] = previous


def _main(args: argparse.Namespace) -> int:
    chosen = [flag for flag in ("stress", "ensemble", "scale", "latency") if getattr(args, flag, False)]
    if len(chosen) > 1:
        raise InputError(f"give only one of --stress, --ensemble, --scale, --latency, not {' and '.join('--' + f for f in chosen)}")
    if args.stress:
        return _delegate("stress", "dirac.commands.bench_stress", args)
    if args.ensemble:
        return _delegate("ensemble", "dirac.commands.bench_ensemble", args)
    for flag, path in (("--json", args.json), ("--plot", args.plot)):
        if path and not Path(path).resolve().parent.is_dir():
            raise InputError(f"{flag} {path!r}: the folder {str(Path(path).resolve().parent)!r} does not exist; create it first")
    if args.plot and not str(args.plot).lower().endswith(".png"):
        raise InputError(f"--plot {args.plot!r}: give a file name ending in .png")
    if args.plot:
        try:
            import matplotlib  # noqa: F401 -- imported only to check that it is installed
        except ModuleNotFoundError:
            raise InputError("--plot needs matplotlib: pip install 'dirac-mechanics[plot]'") from None
    if args.scale:
        return _delegate("scale", "dirac.commands.bench_scale", args)
    if getattr(args, "latency", False):
        if args.plot:
            raise InputError("--latency draws no picture: drop --plot")
        return _delegate("latency", "dirac.commands.bench_latency", args)
    from dirac.bench.run import run_benchmark

    run_benchmark(quick=bool(args.quick), json_path=args.json, plot_path=args.plot, progress=not args.no_progress and getattr(args, "verbosity", 0) >= 0)
    return 0
