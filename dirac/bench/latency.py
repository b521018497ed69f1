"""Latency to the first result on everyday systems, timed the way a new user meets them.

``dirac bench --latency``. Each system of the corpus (``dirac_systems.latency_models``:
pendulums and double pendulums in angles and in Cartesian coordinates, a triple pendulum,
tops in Euler angles, a bead on a turning hoop, a relativistic particle) is run in a
fresh Python process with an empty cache of generated code (a temporary
``DIRAC_CACHE_DIR`` and ``NUMBA_CACHE_DIR``) and the default kernel policy, interpreter
start included (the engine's bytecode compiled beforehand, as an install does:
:func:`compile_bytecode`):

* **first**: ``t_end = 1`` with the default method (``rattle-2``, ``dt = 1e-3`` for the
  tops in Euler angles);
* **study**: ``10^5`` steps (``rattle-2``, or ``midpoint`` on an analysed flow, at
  ``dt = 1e-3``), compilation included;
* **t=100**: ``t_end = 100`` with the default method, side by side with **scipy**:
  ``solve_ivp`` with DOP853 at ``rtol = 1e-8`` on a hand-written right-hand side of the
  same motion, in a fresh process too (pendulum-like systems); the ratio is the
  machine-independent figure, taken of the medians of :data:`REPEATS` fresh processes on
  each side, alternating (:func:`median_row`). The default run asks for ``tolerance = 1e-8`` (the error
  ``auto`` must reach); DOP853 at ``rtol = 1e-8`` does not reach that: its global error
  over ``t = 100`` is about ``1e-6`` in the angles of the pendulum and ``5e-6`` of the
  double pendulum (printed by this bench). So a second run, ``tol=1e-6``
  (:data:`MATCHED_TOLERANCE`), asks ``auto`` for an error no larger than what DOP853
  attains; each of these rows prints its largest error of the angles at the output
  samples against a reference (DOP853 at ``rtol = atol = 1e-13``, untimed), so the
  accuracy of both sides is on the table.

Each run prints its largest relative error of the energy (or of the Jacobi integral).
The paper's three rigid-body Lagrangians are timed end to end as ``dirac analyze NAME``.
Wall time is what a user waits; CPU time (user + system of the child, without a
background compilation it left running) is steadier on a loaded machine. Finally the
compilations the runs made (``compile_history.json`` of each cache) give compile time
against kernel size.

The module imports only the standard library: the children import ``dirac``.
"""

from __future__ import annotations

import json
import os
import resource
import statistics
import subprocess
import sys
import tempfile
import time
from collections.abc import Callable, Sequence
from dataclasses import asdict, dataclass, field, replace
from pathlib import Path

__all__ = ["LatencyRow", "cold_environment", "run_latency", "median_row", "scipy_ratio", "targets_met", "format_latency", "BreakdownRow", "run_breakdown", "format_breakdown", "CORPUS", "ANALYZE_TARGETS", "FIRST_TARGET", "STUDY_TARGET"]

#: the corpus (names of ``dirac_systems.latency_models.MODELS``)
CORPUS = ("pendulum_angle", "double_pendulum_angles", "triple_pendulum_angles", "pendulum_cartesian",
          "double_pendulum_cartesian", "symmetric_top_euler", "asymmetric_top_euler", "bead_on_rotating_hoop",
          "relativistic_oscillator")
#: ``dirac analyze NAME`` end to end and its target in seconds of wall time
ANALYZE_TARGETS = {"rigid_body_momentum": 3.0, "rigid_body_particles": 2.5, "rigid_body_matrix": 2.0}
#: ``tolerance`` of the second ``t_end`` run: no larger than the global error of the angles that
#: scipy's DOP853 at ``rtol = 1e-8`` reaches over ``t = 100`` (about 1e-6 and 5e-6, measured by
#: the bench against its tight reference)
MATCHED_TOLERANCE = 1e-6
#: the tight reference of the global errors: DOP853 with ``rtol = atol =`` this (untimed)
REFERENCE_RTOL = 1e-13
#: fresh processes per ``t_end`` run and per scipy baseline, whose medians the table shows
REPEATS = 3
#: targets of a first result and of a 1e5-step study, seconds of wall time
FIRST_TARGET = 2.0
STUDY_TARGET = 5.0

_RUN = r'''
import json, sys
import numpy as np
spec = json.loads(sys.argv[1])
import dirac
from dirac_systems.latency_models import MODELS
model = MODELS[spec["model"]]()
if model.road == "analysed":
    from dirac.flows.analysed import AnalysedProblem, AnalysedSystem
    problem = AnalysedProblem(AnalysedSystem.from_analysis(dirac.analyze(model.system)), model.state)
else:
    n = len(model.state) // 2
    problem = dirac.ConstrainedProblem(model.system, q0=model.state[:n], p0=model.state[n:])
kwargs = {"t_end": spec["t_end"], "samples": spec["samples"]}
if spec.get("tolerance") is not None:
    kwargs["tolerance"] = spec["tolerance"]
if spec["method"] is not None:
    kwargs["dt"] = spec["dt"]
    run = dirac.integrate(problem, spec["method"], **kwargs)
else:
    run = dirac.integrate(problem, **kwargs)
energy = np.asarray(run["energy"], dtype=float)
scale = max(abs(energy[0]), 1e-300)
result = {"method": run.method, "steps": int(run.steps), "error": float(np.max(np.abs(energy - energy[0])) / scale),
          "engine": dirac.__file__}
if spec.get("angles") and model.angles is not None:
    result["angles"] = np.asarray(model.angles(np.asarray(run["q"], dtype=float))).tolist()
print(json.dumps(result))
'''

_SCIPY = r'''
import json, math, sys
import numpy as np
from scipy.integrate import solve_ivp
spec = json.loads(sys.argv[1])
g, l = 9.81, 1.0
if spec["baseline"] == "pendulum":
    def rhs(t, y):
        return [y[1], -g / l * math.sin(y[0])]
    def energy(y):
        return 0.5 * y[1] ** 2 - g / l * np.cos(y[0])
    y0 = [1.0, 0.0]
else:  # double pendulum, unit masses and rods, in its angles (Landau & Lifshitz Sect. 5)
    def rhs(t, y):
        a, b, wa, wb = y
        d = a - b
        s, c = math.sin(d), math.cos(d)
        den = 2.0 - c * c
        da = (-s * (wb * wb + wa * wa * c) - 2.0 * g * math.sin(a) + g * math.sin(b) * c) / den
        db = (s * (2.0 * wa * wa + wb * wb * c) + 2.0 * g * (math.sin(a) * c - math.sin(b))) / den
        return [wa, wb, da, db]
    def energy(y):
        a, b, wa, wb = y
        return wa ** 2 + 0.5 * wb ** 2 + wa * wb * np.cos(a - b) - 2.0 * g * np.cos(a) - g * np.cos(b)
    y0 = [1.0, 0.5, 0.0, 0.0]
t_eval = np.linspace(0.0, spec["t_end"], spec["samples"])
rtol, atol = spec.get("rtol", 1e-8), spec.get("atol", 1e-10)
solution = solve_ivp(rhs, (0.0, spec["t_end"]), y0, method="DOP853", rtol=rtol, atol=atol, t_eval=t_eval)
e = energy(solution.y)
result = {"method": f"DOP853 rtol={rtol:g}", "steps": int(solution.nfev), "error": float(np.max(np.abs(e - e[0])) / abs(e[0]))}
if spec.get("angles"):
    result["angles"] = solution.y[: len(y0) // 2].T.tolist()
print(json.dumps(result))
'''

_BREAKDOWN = r'''
import json, sys, time
stamps = [("interpreter start", time.process_time())]
import numpy as np
import dirac
stamps.append(("import numpy, dirac", time.process_time()))
spec = json.loads(sys.argv[1])
from dirac_systems.latency_models import MODELS
model = MODELS[spec["model"]]()
stamps.append(("model (sympy, Lagrangian)", time.process_time()))
n = len(model.state) // 2
problem = dirac.ConstrainedProblem(model.system, q0=model.state[:n], p0=model.state[n:])
stamps.append(("problem (kernel source, flattening)", time.process_time()))
import dirac.flows.methods.auto as auto
chosen = auto.choose_method
pilots = []
def timed_choice(*args, **kwargs):
    start = time.process_time()
    try:
        return chosen(*args, **kwargs)
    finally:
        pilots.append(time.process_time() - start)
auto.choose_method = timed_choice
start = time.process_time()
run = dirac.integrate(problem, t_end=spec["t_end"], samples=spec["samples"])
stamps.append(("integrate", time.process_time()))
print(json.dumps({"stamps": stamps, "pilots": sum(pilots), "method": run.method, "steps": int(run.steps),
                  "modules": sorted(m for m in ("numba", "scipy", "sympy", "tqdm") if m in sys.modules)}))
'''


@dataclass
class BreakdownRow:
    """Where the CPU of one fresh-process run goes (:func:`run_breakdown`), seconds."""

    system: str
    method: str
    steps: int
    phases: dict[str, float]
    total: float
    modules: list[str]
    failed: str = ""


def run_breakdown(models: Sequence[str] = ("pendulum_angle", "double_pendulum_angles", "pendulum_cartesian",
                                           "double_pendulum_cartesian"), *, t_end: float = 100.0, samples: int = 101,
                  pythonpath: str | None = None, timeout: float = 600.0) -> list[BreakdownRow]:
    """The ``t_end`` run with the default method of each system, in a fresh process with an
    empty cache as :func:`run_latency` times it, cut into phases by CPU time stamps: the
    interpreter's start, ``import dirac`` (with numpy), the model (sympy's import and the
    Lagrangian), the problem (the generated kernel source and its flattening), ``auto``'s
    pilot runs, compilations in the process (from the cache's compile history, without
    numba's import, which counts in the run), the run itself, the exit (the interpreter's
    shutdown, the rest of the child's CPU) and, apart, a compilation in a background child,
    its start-up included (in the total, within the exit, only when the run waited for it
    to finish)."""
    compile_bytecode(pythonpath)
    rows = []
    for name in models:
        spec = {"model": name, "t_end": t_end, "samples": samples}
        wall, cpu, out, err, code, compilations = _child(["-c", _BREAKDOWN, json.dumps(spec)], pythonpath, timeout)
        lines = [line for line in out.splitlines() if line.startswith("{")]
        if code != 0 or not lines:
            tail = [line for line in err.strip().splitlines() if line.strip()]
            rows.append(BreakdownRow(name, "", 0, {}, cpu, [], tail[-1][:160] if tail else f"exit status {code}"))
            continue
        result = json.loads(lines[-1])
        stamps = result["stamps"]
        phases = {label: stamps[0][1] if index == 0 else stamps[index][1] - stamps[index - 1][1]
                  for index, (label, _) in enumerate(stamps)}
        integrate = phases.pop("integrate")
        compiled_here = sum(float(str(c.get("seconds", 0.0))) for c in compilations
                            if isinstance(c, dict) and "background" not in str(c.get("what", "")))
        # a child's whole CPU: its start-up (interpreter, numpy, numba; recorded as "start") and its compilation
        in_background = sum(float(str(c.get("seconds", 0.0))) + float(str(c.get("start", 0.0))) for c in compilations
                            if isinstance(c, dict) and "background" in str(c.get("what", "")))
        phases["auto's pilot runs"] = result["pilots"]
        phases["compilation in the process"] = compiled_here
        phases["the run (steps, sampling)"] = integrate - result["pilots"] - compiled_here
        phases["exit and the rest"] = cpu - sum(phases.values())
        # a child the run reaped counts in the total (in "exit and the rest"), one it left running does not
        phases["background compilation (child)"] = in_background
        rows.append(BreakdownRow(name, result["method"], result["steps"], phases, cpu, result["modules"]))
    return rows


def format_breakdown(rows: list[BreakdownRow]) -> str:
    """The phases of :func:`run_breakdown` as a table (CPU seconds, one column per system)."""
    good = [row for row in rows if not row.failed]
    labels = list(good[0].phases) if good else []
    lines = [f"{'CPU seconds':36s}" + "".join(f" {row.system[:26]:>26s}" for row in good)]
    for label in labels:
        lines.append(f"{label:36s}" + "".join(f" {row.phases[label]:26.2f}" for row in good))
    lines.append(f"{'total (child user + system)':36s}" + "".join(f" {row.total:26.2f}" for row in good))
    lines.append(f"{'method, steps':36s}" + "".join(f" {row.method + ', ' + str(row.steps):>26s}" for row in good))
    lines.append(f"{'imported':36s}" + "".join(f" {' '.join(row.modules):>26s}" for row in good))
    lines += [f"{row.system}: FAILED: {row.failed}" for row in rows if row.failed]
    return "\n".join(lines)


@dataclass
class LatencyRow:
    """One timed run: which system and run, wall and CPU seconds, what it measured."""

    system: str
    run: str
    wall: float
    cpu: float
    method: str = ""
    steps: int = 0
    error: float | None = None
    conserved: str = "energy"
    target: float | None = None
    failed: str = ""
    compilations: list[dict[str, object]] = field(default_factory=list)
    #: ``t_end`` rows: largest error of the angles at the output samples against the reference
    global_error: float | None = None
    angles: list[list[float]] | None = field(default=None, repr=False)
    #: fresh processes this row's ``wall`` and ``cpu`` are the medians of (:func:`median_row`)
    runs: int = 1
    #: the smallest and largest CPU seconds of those runs
    cpu_range: tuple[float, float] | None = None


def cold_environment(scratch: str, pythonpath: str | None = None) -> dict[str, str]:
    """The environment of a fresh child as a new user meets it: empty caches of generated code
    (``DIRAC_CACHE_DIR``) and of numba (``NUMBA_CACHE_DIR``) in ``scratch``, the default kernel
    policy (no ``DIRAC_KERNELS``), and ``pythonpath`` (a checkout to time) in front."""
    env = dict(os.environ, DIRAC_CACHE_DIR=os.path.join(scratch, "dirac"), NUMBA_CACHE_DIR=os.path.join(scratch, "numba"))
    env.pop("DIRAC_KERNELS", None)
    if pythonpath:
        env["PYTHONPATH"] = pythonpath + os.pathsep + env.get("PYTHONPATH", "")
    return env


def _child(arguments: list[str], pythonpath: str | None, timeout: float) -> tuple[float, float, str, str, int, list]:
    """Run ``python arguments`` fresh with an empty cache: (wall, cpu, stdout, stderr, exit code, compilations)."""
    with tempfile.TemporaryDirectory(prefix="dirac-latency-") as scratch:
        env = cold_environment(scratch, pythonpath)
        before = resource.getrusage(resource.RUSAGE_CHILDREN)
        start = time.perf_counter()
        try:
            done = subprocess.run([sys.executable, *arguments], capture_output=True, text=True, env=env, timeout=timeout,
                                  cwd=scratch)
            out, err, code = done.stdout, done.stderr, done.returncode
        except subprocess.TimeoutExpired:
            out, err, code = "", f"timed out after {timeout:.0f} s", -1
        wall = time.perf_counter() - start
        after = resource.getrusage(resource.RUSAGE_CHILDREN)
        cpu = (after.ru_utime - before.ru_utime) + (after.ru_stime - before.ru_stime)
        try:
            compilations = json.loads((Path(scratch) / "dirac" / "compile_history.json").read_text())
        except (OSError, ValueError):
            compilations = []
    return wall, cpu, out, err, code, compilations


_BYTECODE = r'''
import compileall, importlib.util, os
for name in ("dirac", "dirac_systems"):
    spec = importlib.util.find_spec(name)
    if spec is not None and spec.origin:
        compileall.compile_dir(os.path.dirname(spec.origin), quiet=1, force=False)
'''


def compile_bytecode(pythonpath: str | None = None) -> None:
    """Compile the bytecode of the engine the children import, as ``pip install`` does.

    An installed package comes with its ``.pyc`` files; a source checkout gets them on its
    first import, unless ``PYTHONDONTWRITEBYTECODE`` is set, in which case every fresh
    process compiles the whole engine again (about 0.5 s) and no user meets that. Done in
    a child with the children's ``sys.path`` (run from an empty folder, with ``pythonpath``
    in front), so that the engine compiled is the engine timed.
    """
    env = dict(os.environ)
    if pythonpath:
        env["PYTHONPATH"] = pythonpath + os.pathsep + env.get("PYTHONPATH", "")
    with tempfile.TemporaryDirectory(prefix="dirac-latency-") as scratch:
        subprocess.run([sys.executable, "-c", _BYTECODE], capture_output=True, text=True, env=env, cwd=scratch, timeout=600)


def _row(system: str, run: str, arguments: list[str], pythonpath: str | None, timeout: float, target: float | None,
         conserved: str = "energy") -> LatencyRow:
    wall, cpu, out, err, code, compilations = _child(arguments, pythonpath, timeout)
    row = LatencyRow(system, run, wall, cpu, conserved=conserved, target=target, compilations=compilations)
    lines = [line for line in out.splitlines() if line.startswith("{")]
    if code != 0 or (arguments[0] == "-c" and not lines):
        tail = [line for line in err.strip().splitlines() if line.strip()]
        row.failed = tail[-1][:160] if tail else f"exit status {code}"
        return row
    if lines:
        result = json.loads(lines[-1])
        row.method, row.steps, row.error = result["method"], int(result["steps"]), result["error"]
        row.angles = result.get("angles")
    return row


def _global_error(row: LatencyRow, reference: list[list[float]] | None) -> None:
    """Set ``row.global_error``: the largest difference of its angles from ``reference`` (the
    same output samples); the angles themselves are dropped from the row."""
    if row.angles is not None and reference is not None and len(row.angles) == len(reference):
        row.global_error = max(abs(a - b) for mine, theirs in zip(row.angles, reference) for a, b in zip(mine, theirs))
    row.angles = None


def median_row(runs: Sequence[LatencyRow]) -> LatencyRow:
    """One row for repeated fresh-process runs of the same command: the first run's results
    (method, steps, errors: the runs are deterministic) with the medians of their wall and CPU
    seconds, how many runs and the range of their CPU seconds. A failed run makes the row failed.

    The median of an odd number of runs is one of the runs and ignores the slowest half of
    them: a process that met another's load on one run moves it by nothing.
    """
    failed = [r.failed for r in runs if r.failed]
    if failed:
        return replace(runs[0], failed=failed[0])
    cpus = [r.cpu for r in runs]
    return replace(runs[0], wall=statistics.median(r.wall for r in runs), cpu=statistics.median(cpus), runs=len(runs),
                   cpu_range=(min(cpus), max(cpus)))


def run_latency(models: Sequence[str] = CORPUS, *, first_t_end: float = 1.0, study_steps: int = 100_000,
                long_t_end: float = 100.0, samples: int = 101, analyze: Sequence[str] = tuple(ANALYZE_TARGETS),
                scipy: bool = True, pythonpath: str | None = None, timeout: float = 600.0,
                progress: Callable[[str], None] | None = None, repeats: int = REPEATS) -> list[LatencyRow]:
    """Time the corpus (see the module docstring); one :class:`LatencyRow` per run.

    Parameters
    ----------
    models
        Names in ``dirac_systems.latency_models.MODELS``.
    first_t_end, study_steps, long_t_end, samples
        The first run's span, the study's steps (at ``dt = 1e-3``), the span of the run
        set against scipy (0: none), output samples of every run.
    analyze
        Systems timed as ``dirac analyze NAME``.
    scipy
        Time the scipy baselines of pendulum-like systems.
    pythonpath
        Put this in front of the children's ``PYTHONPATH`` (time another checkout of the
        engine with this corpus).
    timeout
        Seconds after which a child is stopped (the row says so).
    repeats
        Fresh processes per ``t_end`` run and per scipy baseline, alternating between the
        engine and scipy (:func:`median_row`: the table shows medians, so that the ratio
        against scipy is not one process against another, each with its own share of the
        machine's noise). The first results, studies and ``dirac analyze`` rows run once.
    """
    import importlib

    if repeats < 1:
        from dirac.errors import InputError

        raise InputError(f"repeats must be at least 1 (one fresh process per run), not {repeats}")

    latency_models = importlib.import_module("dirac_systems.latency_models").MODELS
    compile_bytecode(pythonpath)
    rows: list[LatencyRow] = []
    baseline_runs: dict[str, list[LatencyRow]] = {}
    baseline_row: dict[str, int] = {}  # where each baseline's row stands in ``rows`` (filled at the end)
    references: dict[str, list[list[float]] | None] = {}

    def say(text: str) -> None:
        if progress is not None:
            progress(text)

    for name in models:
        model = latency_models[name]()
        conserved = model.conserved

        def timed(run: str, method: str | None, dt: float | None, t_end: float, target: float | None,
                  name: str = name, conserved: str = conserved) -> None:
            spec = {"model": name, "method": method, "dt": dt, "t_end": t_end, "samples": samples}
            say(f"latency: {name} {run}")
            rows.append(_row(name, run, ["-c", _RUN, json.dumps(spec)], pythonpath, timeout, target, conserved))

        timed(f"first (t_end={first_t_end:g})", model.first_method, model.first_dt, first_t_end, FIRST_TARGET)
        if study_steps:
            method = "midpoint" if model.road == "analysed" else "rattle-2"
            timed(f"study ({study_steps:.0e} steps)", method, 1e-3, study_steps * 1e-3, STUDY_TARGET)
        if long_t_end and model.baseline is not None:
            if model.baseline not in references:  # untimed: the tight reference of the global errors
                spec = {"baseline": model.baseline, "t_end": long_t_end, "samples": samples, "angles": True,
                        "rtol": REFERENCE_RTOL, "atol": REFERENCE_RTOL}
                references[model.baseline] = _row("reference", "", ["-c", _SCIPY, json.dumps(spec)], pythonpath,
                                                  timeout, None).angles
            tolerances: list[float | None] = [None, MATCHED_TOLERANCE]
            runs: dict[float | None, list[LatencyRow]] = {tolerance: [] for tolerance in tolerances}
            for k in range(repeats):  # the engine's runs and scipy's alternate
                for tolerance in tolerances:
                    run = f"t_end={long_t_end:g}" + ("" if tolerance is None else f" tol={tolerance:g}")
                    spec = {"model": name, "method": None, "dt": None, "t_end": long_t_end, "samples": samples,
                            "tolerance": tolerance, "angles": True}
                    say(f"latency: {name} {run}" + (f" ({k + 1} of {repeats})" if repeats > 1 else ""))
                    runs[tolerance].append(_row(name, run, ["-c", _RUN, json.dumps(spec)], pythonpath, timeout, None,
                                                conserved))
                    _global_error(runs[tolerance][-1], references[model.baseline])
                if scipy:
                    spec = {"baseline": model.baseline, "t_end": long_t_end, "samples": samples, "angles": True}
                    say(f"latency: scipy {model.baseline}" + (f" ({k + 1} of {repeats})" if repeats > 1 else ""))
                    baseline_runs.setdefault(model.baseline, []).append(
                        _row(f"scipy {model.baseline}", f"t_end={long_t_end:g}", ["-c", _SCIPY, json.dumps(spec)],
                             pythonpath, timeout, None))
                    _global_error(baseline_runs[model.baseline][-1], references[model.baseline])
            rows.extend(median_row(runs[tolerance]) for tolerance in tolerances)
            if scipy and model.baseline not in baseline_row:  # its runs go on beside later systems of its kind
                baseline_row[model.baseline] = len(rows)
                rows.append(baseline_runs[model.baseline][0])
    for kind, index in baseline_row.items():  # each baseline's row: the medians of all its runs
        rows[index] = median_row(baseline_runs[kind])
    for name in analyze:
        say(f"latency: dirac analyze {name}")
        rows.append(_row(name, "dirac analyze", ["-m", "dirac", "analyze", name], pythonpath, timeout,
                         ANALYZE_TARGETS.get(name)))
    return rows


def scipy_ratio(rows: list[LatencyRow], row: LatencyRow) -> tuple[float, float] | None:
    """A ``t_end`` run against the scipy baseline of its system: (CPU ratio, wall ratio), or None
    for a row that is no such run or has no baseline in ``rows``."""
    import importlib

    if row.failed or row.system.startswith("scipy") or not row.run.startswith("t_end="):
        return None
    baseline = importlib.import_module("dirac_systems.latency_models").MODELS[row.system]().baseline
    for other in rows:
        if other.system == f"scipy {baseline}" and other.run == row.run.split()[0] and not other.failed:
            return row.cpu / other.cpu, row.wall / other.wall
    return None


def targets_met(rows: list[LatencyRow]) -> bool:
    """Whether every row ran, met its wall-time target, and every ``t_end`` run took no more CPU than
    scipy's baseline (the ratio of the medians, :func:`scipy_ratio`)."""
    return all(not row.failed and (row.target is None or row.wall <= row.target)
               and ((ratio := scipy_ratio(rows, row)) is None or ratio[0] <= 1.0) for row in rows)


def _ratio(rows: list[LatencyRow], row: LatencyRow) -> str:
    """The ratio column of a t_end run (CPU and wall)."""
    ratio = scipy_ratio(rows, row)
    return "" if ratio is None else f"{ratio[0]:.2f} / {ratio[1]:.2f}"


def _accuracy(row: LatencyRow) -> str:
    """The global error of a ``t_end`` row's angles against the reference."""
    return "" if row.global_error is None else f"  angles {row.global_error:.1e}"


def format_latency(rows: list[LatencyRow]) -> str:
    """The latency table (and compile time against kernel size) as text."""
    lines = [f"{'system':28s} {'run':22s} {'method':22s} {'steps':>7s} {'wall s':>7s} {'cpu s':>6s} {'target':>6s}"
             f" {'rel. error':>20s}  vs scipy cpu / wall"]
    for row in rows:
        if row.failed:
            lines.append(f"{row.system:28s} {row.run:22s} FAILED: {row.failed}")
            continue
        target = f"{row.target:g}" if row.target is not None else ""
        ratio = scipy_ratio(rows, row)
        over = (row.target is not None and row.wall > row.target) or (ratio is not None and ratio[0] > 1.0)
        mark = " (over)" if over else ""
        error = f"{row.error:.1e} {row.conserved}" if row.error is not None else ""
        lines.append(f"{row.system:28s} {row.run:22s} {row.method[:22]:22s} {row.steps or '':>7} {row.wall:7.2f}"
                     f" {row.cpu:6.2f} {target:>6s} {error:>20s}  {_ratio(rows, row)}{_accuracy(row)}{mark}")
    compiled = sorted({(int(str(c["chars"])), float(str(c["seconds"])), str(c.get("what", ""))) for row in rows
                       for c in row.compilations if isinstance(c, dict) and "chars" in c and "seconds" in c},
                      key=lambda entry: entry[0])
    if compiled:
        lines += ["", "compile time against kernel size (each cold, measured by the run that compiled it; size: the "
                  "characters of the function numba compiled and of the functions it calls):",
                  f"{'kernel chars':>12s} {'cpu s':>6s} {'us/char':>8s}  kernel"]
        lines += [f"{chars:12d} {seconds:6.2f} {1e6 * seconds / chars:8.1f}  {what}" for chars, seconds, what in compiled]
    lines += ["", "Fresh process and empty cache per row (the engine's bytecode compiled first, as an install does), default "
              "kernel policy; wall is what a user waits (distorted "
              "by other load), cpu is the child's user + system time. Targets: first result <= "
              f"{FIRST_TARGET:g} s, 1e5-step study <= {STUDY_TARGET:g} s; a t_end run no slower than scipy (ratio <= 1)."]
    repeated = sorted({row.runs for row in rows if row.runs > 1})
    if repeated:
        spreads = ", ".join(f"{row.system} {row.run} {row.cpu_range[0]:.2f}-{row.cpu_range[1]:.2f}" for row in rows
                            if row.cpu_range is not None)
        lines += [f"t_end and scipy rows: the medians of {' or '.join(str(n) for n in repeated)} fresh processes each, "
                  f"the engine's and scipy's alternating (a scipy row: all its runs beside the systems of its kind); "
                  f"their CPU seconds ranged over {spreads}."]
    if any(row.global_error is not None for row in rows):
        lines += [f"t_end rows: 'angles' is the largest error of the angles at the output samples against DOP853 at "
                  f"rtol = atol = {REFERENCE_RTOL:g}; the scipy rows' steps are right-hand-side evaluations. dirac's "
                  f"default run asks for tolerance 1e-8, 'tol={MATCHED_TOLERANCE:g}' for the error DOP853 at "
                  "rtol = 1e-8 attains (its 'angles' figure)."]
    return "\n".join(lines)


def rows_as_json(rows: list[LatencyRow]) -> list[dict[str, object]]:
    """The rows as plain dictionaries (``--json``)."""
    return [asdict(row) for row in rows]
