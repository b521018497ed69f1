"""``dirac ensemble SCENE.toml --out DIR``: run (or resume) an ensemble of rigid bodies or of any system.

Locally by default (all cores, no set-up); on a dask.distributed cluster with
``--scheduler ADDRESS`` or ``--cluster local``. Results go to a zarr store in ``DIR``;
rerunning the same command after an interruption computes only the missing chunks.
"""

from __future__ import annotations

import argparse
import sys
from typing import TYPE_CHECKING

if TYPE_CHECKING:
    from dirac.ensemble.engine import EnsembleReport


def register(subparsers: argparse._SubParsersAction) -> argparse.ArgumentParser:
    """Declare ``dirac ensemble`` and its options."""
    parser = subparsers.add_parser(
        "ensemble",
        help="run an ensemble scene (many members of any system, chunked, resumable)",
        description="Run an ensemble scene: many free rigid bodies drawn from named distributions "
        "(or read from a file), advanced in chunks by the batched Lie-Poisson kernels, or many members "
        "of any other system (a grid and/or random draws of ensemble variables) advanced by the system's "
        "own RATTLE step batched over members; results written chunk by chunk to a zarr store in DIR. "
        "Rerun the same command to resume an interrupted run (only missing chunks are computed). "
        "See docs/ensembles.md and docs/ensembles_general.md.",
    )
    parser.add_argument("scene", metavar="SCENE.toml", help="ensemble scene file ([system], [initial], [run], [ensemble])")
    parser.add_argument("--out", metavar="DIR", required=True, help="output folder (zarr store data.zarr, meta.json)")
    where = parser.add_mutually_exclusive_group()
    where.add_argument("--scheduler", metavar="ADDRESS", help="run on the dask.distributed scheduler at ADDRESS (tcp://host:8786); DIR must be on a file system all workers see")
    where.add_argument("--cluster", choices=["local"], help="start a dask LocalCluster on this machine (loopback) for the run")
    parser.add_argument("--workers", type=int, metavar="N", help="workers of --cluster local (default: one per core)")
    parser.add_argument("--chunk-size", type=int, metavar="N", help="members per chunk (default: the scene's chunk_size, else about 64 MiB of results per chunk)")
    parser.add_argument("--retries", type=int, default=2, metavar="N", help="extra attempts of a failing chunk (default 2)")
    parser.add_argument("--no-progress", action="store_true", help="no progress bar")
    return parser


def flag_spelling(name: str, value: object) -> str:
    """An argument of :func:`~dirac.ensemble.engine.run_ensemble` as its flag: ``chunk_size, 10`` -> ``--chunk-size 10``."""
    return f"--{name.replace('_', '-')} {value}"


def main(args: argparse.Namespace) -> int:
    """Run or resume the ensemble; 0 when complete, 1 when chunks failed (listed on stderr)."""
    from dirac.errors import InputError

    if args.chunk_size is not None and args.chunk_size < 1:
        raise InputError(f"--chunk-size {args.chunk_size} must be >= 1")
    if args.workers is not None and (args.workers < 1 or args.cluster is None):
        raise InputError("--workers N needs --cluster local and N >= 1")
    if args.retries < 0:
        raise InputError(f"--retries {args.retries} must be >= 0")
    report = _run(args)
    quiet = getattr(args, "verbosity", 0) < 0
    if not quiet:  # -q: the results are in --out DIR; no summary
        _print_report(report)
    if report.failed:
        listed = ", ".join(f"{index} ({message})" for index, message in sorted(report.failed.items())[:3])
        print(
            f"error: {len(report.failed)} chunk(s) failed after all retries: {listed}; they are listed in "
            f"{report.out / 'meta.json'}; rerun the same command to retry them",
            file=sys.stderr,
        )
        return 1
    if not quiet:
        print("  complete")
    return 0


def _run(args: argparse.Namespace) -> EnsembleReport:
    """:func:`~dirac.ensemble.engine.run_ensemble` with the flags; its argument errors name the flags."""
    from dirac.ensemble.arguments import ArgumentError
    from dirac.ensemble.engine import run_ensemble
    from dirac.errors import InputError

    quiet = getattr(args, "verbosity", 0) < 0

    def notify(message: str) -> None:
        if not quiet:
            print(message, file=sys.stderr, flush=True)

    try:
        return run_ensemble(
            args.scene,
            args.out,
            chunk_size=args.chunk_size,
            scheduler=args.scheduler,
            cluster=args.cluster,
            n_workers=args.workers,
            retries=args.retries,
            progress=not args.no_progress and not quiet,
            notify=notify,
        )
    except ArgumentError as exc:
        raise InputError(exc.spelled(flag_spelling)) from None


def _print_report(report: EnsembleReport) -> None:
    """The summary lines on stdout."""
    print(f"ensemble: {report.count} members in {report.chunks_total} chunks of {report.chunk_size} -> {report.out}")
    print(f"  computed {report.chunks_computed} chunks, {report.chunks_skipped} already complete")
    if report.member_steps:
        print(f"  {report.member_steps:.3g} member-steps in {report.seconds:.2f} s: {report.throughput:.3g} member-steps/s")
