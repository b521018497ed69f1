"""``dirac run SCENE.toml [--out FILE.npz] [--plot FILE] [--no-progress]``: run a scene, write its results.

The results (docs/file_formats.md) are written atomically. When the integration stops early
(non-finite state, Newton non-convergence, constraint drift, Ctrl-C or SIGTERM) the
samples computed so far are saved with ``meta["complete"] = false``: to the output file
when it does not exist yet, otherwise next to it as ``<name>.partial.npz``, so a failed
run never replaces an existing result. Exit status 2 for a failed run, 130 when
interrupted.
"""

from __future__ import annotations

import argparse
import signal
import sys
from pathlib import Path
from typing import TYPE_CHECKING, cast

if TYPE_CHECKING:
    from dirac.flows.solution import Solution


def register(subparsers: argparse._SubParsersAction) -> argparse.ArgumentParser:
    parser = subparsers.add_parser(
        "run",
        help="run a scene file and write its results",
        description="Run a scene file (TOML: [system], [initial], [run]) and write t, the requested outputs and meta to an .npz file.",
        formatter_class=argparse.RawDescriptionHelpFormatter,
        epilog=_methods_epilog(),
    )
    parser.add_argument("scene", metavar="SCENE.toml", help="the scene file")
    parser.add_argument("--out", metavar="FILE.npz", help="result file (default: the scene's name with .npz)")
    parser.add_argument("--plot", metavar="FILE", default=None,
                        help="also draw the run, in the format of FILE's suffix (png, pdf, svg, ...): each system "
                        "with the errors of its own conserved quantities; needs matplotlib")
    parser.add_argument("--no-progress", action="store_true", help="do not draw a progress bar")
    return parser


def _methods_epilog() -> str:
    """The method list for ``--help`` (cheap: no numba/scipy import)."""
    lines = ["methods ([run] method = NAME):"]
    for name, text in METHOD_HELP:
        lines.append(f"  {name:<22} {text}")
    return "\n".join(lines)


#: One line per method for ``dirac run --help`` (kept here so that --help stays fast; a
#: test checks it lists every registered method).
METHOD_HELP: tuple[tuple[str, str], ...] = (
    ("auto", "cheapest method meeting [run] tolerance (exact, splitting or rattle)"),
    ("exact", "free rigid body: exact elliptic-function flow, no time steps"),
    ("lie-poisson-2/4/6/8", "rigid body / heavy top: Lie-Poisson splitting, order 2/4/6/8"),
    ("lie-poisson-sym-2/4/6/8", "the same with the symmetric-top split (Fasso 2003)"),
    ("lie-poisson-4-suzuki", "order 4, Suzuki's 5-stage composition"),
    ("lie-poisson-8-s15", "order 8, Suzuki-Umeno / McLachlan 15-stage composition"),
    ("lie-poisson-sym-4-suzuki", "symmetric-top split, Suzuki's order-4 composition"),
    ("lie-poisson-sym-8-s15", "symmetric-top split, 15-stage order-8 composition"),
    ("exact-kick-2/4/6/8", "heavy top, torqued body: exact free flow + gravity/torque kick (Celledoni et al. 2008)"),
    ("rattle-2/4/6/8", "constrained systems: RATTLE and its symmetric compositions"),
    ("forced-rattle-2/4", "forces Q(q, q_dot, t) and impulses: RATTLE with discrete Lagrange-d'Alembert forces"),
    ("conformal-2/4", "linear damping Q = -gamma M q_dot: conformal-symplectic splitting (McLachlan-Perlmutter)"),
    ("midpoint", "implicit midpoint (rigid body; Dirac vector field of general systems)"),
    ("scipy-RK45", "baseline: scipy RK45, rtol = atol = tolerance"),
    ("scipy-DOP853", "baseline: scipy DOP853, rtol = atol = tolerance"),
)


def _partial_path(out: Path) -> Path:
    return out if not out.exists() else out.with_name(out.stem + ".partial.npz")


def main(args: argparse.Namespace) -> int:
    from dirac.errors import InputError, IntegrationError
    from dirac.flows.integration import IntegrationInterrupted, integrate
    from dirac.io.results import write_results
    from dirac.io.scene import load_scene

    scene_path = Path(args.scene)
    out = Path(args.out) if args.out else scene_path.with_suffix(".npz")
    if out.suffix != ".npz":
        raise InputError(f"--out {str(out)!r} must end in .npz")
    if out.is_dir():
        raise InputError(f"--out {str(out)!r} is a directory; give a file name ending in .npz")
    if not (out.parent if str(out.parent) else Path(".")).is_dir():
        raise InputError(f"--out {str(out)!r}: directory {str(out.parent)!r} does not exist")
    plot_path = None
    if args.plot:  # checked before the run, so that a bad name fails fast
        from dirac.plots.canvas import check_plot_path

        plot_path = check_plot_path(args.plot)
    scene = load_scene(scene_path)
    level = getattr(args, "verbosity", 0)
    progress = (not args.no_progress) and level >= 0 and sys.stderr.isatty()

    def terminate(signum, frame):
        raise KeyboardInterrupt

    previous = signal.signal(signal.SIGTERM, terminate)
    try:
        try:
            solution = integrate(scene.problem, progress=progress, **scene.run)
        except IntegrationError as exc:
            # integrate's errors carry a dirac.flows.Solution; errors.py imports no other layer to say so
            partial = cast("Solution | None", exc.partial)
            if partial is None:
                raise
            target = write_results(partial, _partial_path(out), extra_meta=scene.meta)
            note = (f"{len(partial.t)} samples up to t = {partial.t[-1]:.6g} saved in {target} (meta complete = false)"
                    if len(partial.t) else f"no samples were computed; {target} records the failure (meta complete = false)")
            if isinstance(exc, IntegrationInterrupted):
                print(f"error: {exc}; {note}", file=sys.stderr)
                return 130
            raise IntegrationError(f"{exc}; {note}") from None
        write_results(solution, out, extra_meta=scene.meta)
    except KeyboardInterrupt:  # before the loop or while writing: no temporary file is left behind
        print(f"error: interrupted; {out} was left as it was", file=sys.stderr)
        return 130
    finally:
        signal.signal(signal.SIGTERM, previous)
    if level > 0:
        print(f"run: integration {solution.cpu_seconds:.3g} s CPU (compilation excluded)", file=sys.stderr)
    dt = f", dt = {solution.dt:.6g}" if solution.dt else ""
    if level < 0:  # -q: the results are in the --out file; no summary
        if plot_path is not None:
            from dirac.plots import plot_result

            plot_result(solution, plot_path, problem=scene.problem)
        return 0
    print(
        f"{scene.system}: method {solution.method} (order {solution.order}{dt}), {solution.steps} steps, "
        f"{solution.evaluations} evaluations, {solution.cpu_seconds:.3g} s CPU; "
        f"{len(solution.t)} samples of {', '.join(solution.outputs)} written to {out}"
    )
    if plot_path is not None:
        from dirac.plots import plot_result

        plot_result(solution, plot_path, problem=scene.problem)
        print(f"picture written to {plot_path}")
    return 0
