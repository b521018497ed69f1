"""``dirac demo``: the flagship scene -- a free asymmetric rigid body that tumbles.

The body is a homogeneous box with edges 1, 2, 3 and mass 12: mass-matrix principal
values ``g = (1, 4, 9)`` (66), so ``I = (13, 10, 5)`` by (72), which satisfies the
triangle inequality of docs/conventions.md. ``M(0) = (0.1, 1, 0.1)``, ``R(0) = 1``:
spun about the intermediate axis with a small wobble, it flips over twice per period of
``M(t)`` (the tennis-racket effect). Integrated to ``t = 1000`` with ``method = "auto"``;
prints the body, the period, the method, steps, CPU time and the conserved-quantity
errors: energy ``H_0`` (247), the Casimir ``|M|^2``, the lab angular momentum ``m = R M``
and ``|R^T R - 1|``. The standard test case ``I = (2, 1, 2/3)`` (no physical body) stays
the body of ``dirac bench`` and the tests.
"""

from __future__ import annotations

import argparse
import sys


def register(subparsers: argparse._SubParsersAction) -> argparse.ArgumentParser:
    parser = subparsers.add_parser(
        "demo",
        help="run the flagship free-rigid-body scene and print a summary",
        description="Run the flagship scene (free asymmetric rigid body: a homogeneous box with edges "
        "1, 2, 3 and mass 12, I = (13, 10, 5), spun about its intermediate axis with M(0) = (0.1, 1, 0.1), "
        "so that it tumbles) and print method, steps, time and conserved-quantity errors.",
    )
    parser.add_argument("--method", default=None, help="integration method (default: auto; see 'dirac run --help')")
    parser.add_argument("--t-end", type=float, default=None, help="final time (default 1000)")
    parser.add_argument("--dt", type=float, default=None, help="step size for fixed-step methods (default 0.01)")
    parser.add_argument("--out", metavar="FILE.npz", default=None, help="also write the results")
    parser.add_argument("--plot", metavar="FILE", default=None,
                        help="also draw the run (png, pdf, svg, ...: the suffix names the format): polhode, body axes, "
                        "M(t), conserved-quantity errors (needs matplotlib)")
    parser.add_argument("--no-progress", action="store_true", help="do not draw a progress bar")
    return parser


def main(args: argparse.Namespace) -> int:
    import copy

    import numpy as np

    from dirac.flows.integration import integrate
    from dirac.flows.problems import RigidBodyProblem
    from dirac.io.scene import FLAGSHIP_SCENE, scene_from_dict
    from dirac.rigidbody.exact import ExactRigidBodyFlow

    plot_path = None
    if args.plot:  # checked before the run, so that a bad name fails fast
        from dirac.plots.canvas import check_plot_path

        plot_path = check_plot_path(args.plot)
    data = copy.deepcopy(FLAGSHIP_SCENE)
    run = data["run"]
    assert isinstance(run, dict)
    if args.method:
        from dirac.flows.methods.registry import method_names
        from dirac.validate import unknown_name_error

        if args.method not in method_names():
            raise unknown_name_error("method", args.method, method_names(), "--method")
        run["method"] = args.method
    if args.t_end is not None:
        run["t_end"] = args.t_end
    run["dt"] = args.dt if args.dt is not None else 0.01
    scene = scene_from_dict(data, source="flagship scene")
    progress = (not args.no_progress) and getattr(args, "verbosity", 0) >= 0 and sys.stderr.isatty()
    problem = scene.problem
    assert isinstance(problem, RigidBodyProblem)  # the flagship scene is the free rigid body
    solution = integrate(problem, progress=progress, **scene.run)
    if args.out:
        from dirac.io.results import write_results

        write_results(solution, args.out, extra_meta=scene.meta)
    M, R = solution["M"], solution["R"]
    energy = solution["energy"]
    casimir = solution["casimir"]
    lab = solution["lab_momentum"]
    orthogonality = np.max(np.abs(np.einsum("nki,nkj->nij", R, R) - np.eye(3)))
    inertia = problem.inertia
    choice = solution.extra.get("auto", {})
    period = ExactRigidBodyFlow(inertia, M[0]).period
    print("dirac demo: free asymmetric rigid body -- a homogeneous box, edges 1 x 2 x 3, mass 12")
    print(f"  inertia        I = ({', '.join(f'{x:.6g}' for x in inertia)})")
    print(f"  initial        M(0) = ({', '.join(f'{x + 0.0:.6g}' for x in M[0])}), R(0) = identity")
    print(f"  motion         spun about the intermediate axis 2 with a small wobble: M(t) has period {period:.6g},")
    print("                 and the body flips over twice per period (the tennis-racket effect)")
    if solution.method == "exact":
        method_line = "  method         exact flow (Jacobi elliptic functions; no time steps)"
    else:
        method_line = f"  method         {solution.method} (order {solution.order})"
    if solution.dt:
        method_line += f", dt = {solution.dt:.6g}"
    if isinstance(choice, dict) and choice:  # the "auto" method's record of its choice
        method_line += f"  [auto: {choice.get('reason', '')}]"
    print(method_line)
    print(f"  time span      t = 0 .. {solution.t[-1]:g}, {len(solution.t)} samples")
    print(f"  steps          {solution.steps} ({solution.evaluations} evaluations)")
    print(f"  CPU time       {solution.cpu_seconds:.4g} s (compilation excluded)")
    print("  conserved quantities, max deviation from t = 0:")
    print(f"    energy H_0            {np.max(np.abs(energy - energy[0])) / abs(energy[0]):.3e} (relative; H_0 = {energy[0]:.15g})")
    print(f"    Casimir |M|^2         {np.max(np.abs(casimir - casimir[0])):.3e}")
    print(f"    lab momentum m = R M  {np.max(np.linalg.norm(lab - lab[0], axis=1)):.3e}")
    print(f"    |R^T R - 1|           {orthogonality:.3e}")
    if plot_path is not None:
        from dirac.plots import plot_result

        plot_result(solution, plot_path)
        print(f"  picture        {plot_path}")
    return 0
