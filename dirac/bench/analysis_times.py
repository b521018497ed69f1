"""Symbolic speed of ``dirac.analyze`` on the paper's Lagrangians and a square-root one.

Each case is analysed in a fresh Python process (so that sympy's global cache of an
earlier analysis does not help a later one); the import of ``dirac`` and of its analysis
modules (``dirac.analyze`` is a lazy export: its first use imports them, scipy.sparse
among them) and the building of the Lagrangian are outside the timed region. Modules the
analysis itself imports on demand (``scipy.optimize`` for the Legendre transform of
(228)) are inside it. The figure is the median CPU time
(``time.process_time``) of the ``dirac.analyze`` call over the repeats: the analysis is
single-threaded, and CPU time does not grow when other jobs share the machine, as wall
time does; the median wall time is reported beside it.

Cases: the rigid body as particles (the paper's (19)), as a matrix with the
orthogonality constraint (78), through its angular momentum (228), and the
relativistic particle ``L = -m sqrt(t_dot^2 - x_dot^2 - y_dot^2)`` on the ellipse
``x^2 + y^2/4 = 1`` (the engine refuses it at stage 2 with a clear error: the
consistency of the mass shell gives ``lambda_1 (4 x p_x + y p_y) = 0``, two branches that
meet; the figure is the time to that answer), and the regular relativistic particle
``L = -m c^2 sqrt(1 - (x_dot^2 + y_dot^2)/c^2)`` on the ellipse ``x^2/a^2 + y^2/b^2 = 1``
with all four parameters symbolic (4 second class, 1 degree of freedom; its
special-parameter-value search has square roots in every entry of ``C``).

:data:`REPORT_CASES` time the analysis with its text report on everyday systems users write
(a pendulum on a cart, a triple pendulum in Cartesian coordinates, a slider-crank, a
spherical double pendulum, a triple pendulum in its angles, an asymmetric top in Euler
angles): target 5 s of CPU each, "a few seconds" for a system of a few coordinates.

:data:`ANALYZE_COMMAND_TARGETS` are the end-to-end times of ``dirac analyze NAME`` as a
user meets them (:func:`dirac.bench.targets.analyze_command_targets`).
"""

from __future__ import annotations

import json
import subprocess
import sys
from dataclasses import dataclass

__all__ = ["ANALYSIS_CASES", "ANALYZE_COMMAND_TARGETS", "BOUNDED_CASES", "REPORT_CASES", "AnalysisCase", "analysis_time",
           "analysis_runs"]


@dataclass(frozen=True)
class AnalysisCase:
    """One Lagrangian to analyse: Python that builds ``L``, and the CPU-time target (s).

    With ``report`` the text report (``analysis.to_text()``, what ``dirac analyze`` prints)
    is timed with the analysis.
    """

    name: str
    build: str
    target: float
    report: bool = False


#: the ellipse the square-root particle is held on (a regular curve: its gradient never vanishes on it)
CONIC = "x**2 + y**2/4 - 1"

ANALYSIS_CASES = (
    AnalysisCase("rigid body (228), angular momentum", "dirac.load_system('rigid_body_momentum')", 2.0),
    AnalysisCase("rigid body (19), particles", "dirac.load_system('rigid_body_particles')", 1.5),
    AnalysisCase("rigid body (78), matrix", "dirac.load_system('rigid_body_matrix')", 1.0),
    AnalysisCase(
        "square-root particle on an ellipse (refused at stage 2)",
        "dirac.Lagrangian.from_strings('relativistic_conic', ['t', 'x', 'y'], "
        "'-m*sqrt(t_dot**2 - x_dot**2 - y_dot**2)', constraints=[" + repr(CONIC) + "], parameters={'m': 1.0})",
        5.0,
    ),
)

#: cases whose every symbolic step is bounded (the special-value search under its budget)
BOUNDED_CASES = (
    AnalysisCase(
        "relativistic particle on a conic, all parameters symbolic (4 second class, 1 degree of freedom)",
        "dirac.Lagrangian.from_strings('relativistic_ellipse', ['x', 'y'], "
        "'-m*c**2*sqrt(1 - (x_dot**2 + y_dot**2)/c**2)', constraints=['x**2/a**2 + y**2/b**2 - 1'], "
        "parameters={'m': 1.0, 'c': 1.0, 'a': 2.0, 'b': 1.0})",
        5.0,
    ),
)

#: everyday systems as users write them (``dirac_systems.report_models``): the analysis and its text report, whose
#: proofs and factorisations once took seconds to minutes (a trigsimp that did not end, a divisor expanded for 3 s)
REPORT_CASES = tuple(
    AnalysisCase(f"{name.replace('_', ' ')}, analysis and report",
                 f"__import__('dirac_systems.report_models', fromlist=['MODELS']).MODELS[{name!r}]()", 5.0, report=True)
    for name in ("pendulum_on_a_cart", "triple_pendulum_cartesian", "slider_crank", "spherical_double_pendulum",
                 "triple_pendulum_angles", "asymmetric_top_euler")
)

#: ``dirac analyze NAME`` end to end (fresh process: interpreter, imports, analysis, report): target CPU seconds
ANALYZE_COMMAND_TARGETS = {"rigid_body_momentum": 3.0, "rigid_body_particles": 2.5, "rigid_body_matrix": 2.0}

_CHILD = """
import json, time, warnings
import dirac
warnings.simplefilter("ignore")
L = {build}
analyze = dirac.analyze  # a lazy export: resolving it imports the analysis modules, outside the timed region
c0, w0 = time.process_time(), time.perf_counter()
try:
    analysis = analyze(L)
    if {report}:
        analysis.to_text()
    outcome = "analysed"
except dirac.DiracError as exc:
    outcome = type(exc).__name__
print(json.dumps({{"cpu": time.process_time() - c0, "wall": time.perf_counter() - w0, "outcome": outcome}}))
"""


def analysis_time(case: AnalysisCase) -> dict:
    """CPU and wall seconds of ``dirac.analyze`` on ``case`` in a fresh process, and its outcome."""
    completed = subprocess.run(
        [sys.executable, "-c", _CHILD.format(build=case.build, report=case.report)], capture_output=True, text=True, timeout=900
    )
    if completed.returncode != 0:
        raise RuntimeError(f"{case.name}: the analysis process failed: {completed.stderr.strip().splitlines()[-1:]}")
    return json.loads(completed.stdout.strip().splitlines()[-1])


def analysis_runs(repeats: int) -> list[tuple[AnalysisCase, list[dict]]]:
    """Each case with its ``repeats`` runs (:func:`analysis_time`), cases interleaved.

    The cases are run in turn (case 1, 2, 3, 4, then again), so that a change in the
    load of the machine touches them alike.
    """
    cases = (*ANALYSIS_CASES, *BOUNDED_CASES, *REPORT_CASES)
    runs: dict[str, list[dict]] = {case.name: [] for case in cases}
    for _ in range(repeats):
        for case in cases:
            runs[case.name].append(analysis_time(case))
    return [(case, runs[case.name]) for case in cases]
