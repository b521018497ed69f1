"""Kernel, batch, skipping, memory and start-up measurements, each against its target.

Each function measures one thing in this process (or in a fresh ``dirac`` subprocess for
start-up), after a warm-up outside the timed region, and returns a :class:`Target`:
value, target, whether it is met, and the baseline measured in the same run where the
target is a ratio.
"""

from __future__ import annotations

import math
import os
import subprocess
import sys
import tempfile
import time
import tracemalloc
import warnings
from collections.abc import Callable
from dataclasses import asdict, dataclass, field

import numpy as np

from dirac.bench.standard_body import STANDARD_INERTIA, STANDARD_M0
from dirac.bench.timing import median_of, time_call

__all__ = ["Target", "analysis_targets", "analyze_command_targets", "measure_targets", "work_precision_targets"]

#: ``dirac bench --scale``: wall time of ``dirac.analyze`` at each model's target size (s)
SCALE_TARGET_SECONDS = 10.0
#: ``dirac bench --scale``: growth exponent of the analysis time between the two largest sizes
SCALE_TARGET_EXPONENT = 1.3
#: ``dirac bench --scale``: peak resident memory of one analysis process (MB)
SCALE_TARGET_MEMORY_MB = 2048.0
#: ``dirac bench --scale``: the size at which each model must meet SCALE_TARGET_SECONDS
SCALE_TARGET_SIZES = {"chain": 128, "maxwell_ring": 1024, "maxwell_torus": 16}

_STANDARD_INERTIA = np.array(STANDARD_INERTIA)
_STANDARD_M0 = np.array(STANDARD_M0)


@dataclass
class Target:
    """One measured figure and its target."""

    name: str
    value: float | None
    unit: str
    target: float
    sense: str  # "<=" or ">="
    detail: str = ""
    extra: dict = field(default_factory=dict)

    @property
    def met(self) -> bool | None:
        if self.value is None or not math.isfinite(self.value):
            return None
        return self.value <= self.target if self.sense == "<=" else self.value >= self.target

    def as_dict(self) -> dict:
        data = asdict(self)
        data["met"] = self.met
        return data


def _quiet() -> warnings.catch_warnings:
    manager = warnings.catch_warnings()
    manager.__enter__()
    warnings.simplefilter("ignore")
    return manager


# --------------------------------------------------------------------------- kernel vs C
def kernel_against_c(repeats: int, n_steps: int) -> tuple[Target, str]:
    """ns per lie-poisson-2 step (M and R) of the numba kernel and of the C reference."""
    from dirac.bench.c_reference import compile_reference
    from dirac.rigidbody.splitting import advance_sequence, build_sequence

    inv = 1.0 / _STANDARD_INERTIA
    axes, rates, fractions, casimir_rate = build_sequence(inv, (1.0,), "axes")
    dt = 0.01

    def state() -> tuple[np.ndarray, np.ndarray]:
        return _STANDARD_M0.copy(), np.eye(3)

    numba_time = time_call(
        lambda s: advance_sequence(s[0], s[1], axes, rates, fractions, casimir_rate, dt, n_steps, True),
        repeats, setup=state,
    )
    numba_ns = numba_time.cpu / n_steps * 1e9
    reference, note = compile_reference()
    if reference is None:
        return Target("kernel: lie-poisson-2 step (M, R) / C reference", None, "x", 1.3, "<=",
                      f"numba {numba_ns:.1f} ns/step; {note}"), note
    c_time = time_call(lambda s: reference.advance(s[0], s[1], inv, dt, n_steps, True), repeats, setup=state)
    c_ns = c_time.cpu / n_steps * 1e9
    # same algorithm: the two must agree (checked here too, not only in the tests)
    a, b = state()
    advance_sequence(a, b, axes, rates, fractions, casimir_rate, dt, 1000, True)
    c, d = state()
    reference.advance(c, d, inv, dt, 1000, True)
    agree = max(float(np.max(np.abs(a - c))), float(np.max(np.abs(b - d))))
    return Target(
        "kernel: lie-poisson-2 step (M, R) / C reference", numba_ns / c_ns, "x", 1.3, "<=",
        f"numba {numba_ns:.1f} ns/step, C {c_ns:.1f} ns/step ({n_steps} steps, median of {repeats}); "
        f"states agree to {agree:.1e}",
        {"numba_ns_per_step": numba_ns, "c_ns_per_step": c_ns, "c_compile": reference.command},
    ), note


# --------------------------------------------------------------------------- work-precision
def work_precision_targets(rows: list[dict], threshold: float = 1e-9) -> list[Target]:
    """Fastest non-exact package method and DOP853 reaching ``threshold`` (standard body)."""
    standard = [r for r in rows if r.get("problem") == "standard" and "failed" not in r]
    reached = [r for r in standard if r.get("error", math.inf) <= threshold]
    ours = [r for r in reached if r["method"] != "exact" and not r["method"].startswith("scipy-")]
    dop = [r for r in reached if r["method"] == "scipy-DOP853"]
    best = min(ours, key=lambda r: r["cpu_s"]) if ours else None
    best_dop = min(dop, key=lambda r: r["cpu_s"]) if dop else None
    targets = []
    if best is None:
        targets.append(Target("work-precision: fastest non-exact method, error <= 1e-9 (ms CPU)", None, "ms",
                              1.0, "<=", "no package method reached 1e-9 in this run"))
    else:
        plain = [r for r in ours if r["method"] in ("lie-poisson-2", "lie-poisson-4", "lie-poisson-6", "lie-poisson-8")]
        best_plain = min(plain, key=lambda r: r["cpu_s"]) if plain else None
        also = (f"; best 3-term split: {best_plain['method']} dt = {best_plain['value']}, "
                f"{best_plain['cpu_s'] * 1e3:.2f} ms" if best_plain is not None and best_plain is not best else "")
        targets.append(Target(
            "work-precision: fastest non-exact method, error <= 1e-9 (ms CPU)", best["cpu_s"] * 1e3, "ms", 1.0,
            "<=", f"{best['method']} dt = {best['value']}: error {best['error']:.2g}, {best['steps']} steps, "
            f"whole integrate call {best['call_cpu_s'] * 1e3:.2f} ms{also}",
        ))
    if best is None or best_dop is None:
        targets.append(Target("work-precision: DOP853 CPU / fastest (same error)", None, "x", 50.0, ">=",
                              "DOP853 or the package did not reach 1e-9 in this run"))
    else:
        targets.append(Target(
            "work-precision: DOP853 CPU / fastest (same error)", best_dop["cpu_s"] / best["cpu_s"], "x", 50.0,
            ">=", f"DOP853 tol {best_dop['value']:g}: {best_dop['cpu_s'] * 1e3:.1f} ms, error "
            f"{best_dop['error']:.2g}, {best_dop['evaluations']} RHS calls (lean float RHS)",
        ))
    return targets


# --------------------------------------------------------------------------- exact flow
def exact_targets(repeats: int, n_times: int) -> list[Target]:
    """Exact flow: one full state, ``n_times`` states, M-only skipping, t_end independence."""
    from dirac.flows import RigidBodyProblem, integrate
    from dirac.rigidbody.exact import ExactRigidBodyFlow

    quiet = _quiet()
    try:
        flow = ExactRigidBodyFlow(_STANDARD_INERTIA, _STANDARD_M0)
        one = np.array([37.3])
        single = time_call(lambda: flow.state(one), max(repeats, 20))
        setup = time_call(lambda: ExactRigidBodyFlow(_STANDARD_INERTIA, _STANDARD_M0), max(repeats, 20))
        times = np.linspace(0.0, 100.0, n_times)
        many = time_call(lambda: flow.state(times), repeats)
        problem = RigidBodyProblem(_STANDARD_INERTIA, _STANDARD_M0)

        def run(outputs: list[str], t_end: float) -> float:
            return integrate(problem, "exact", t_end=t_end, samples=n_times, outputs=outputs).cpu_seconds

        run(["M"], 100.0)
        with_R = median_of([run(["M", "R"], 100.0) for _ in range(repeats)])
        only_M = median_of([run(["M"], 100.0) for _ in range(repeats)])
        short = time_call(lambda: flow.state(np.linspace(0.0, 1e2, 1000)), repeats)
        long = time_call(lambda: flow.state(np.linspace(0.0, 1e6, 1000)), repeats)
    finally:
        quiet.__exit__(None, None, None)
    return [
        Target("exact: full state (M, R) at one time (us)", single.cpu * 1e6, "us", 20.0, "<=",
               f"ExactRigidBodyFlow.state at one time; building the flow once costs {setup.cpu * 1e6:.0f} us"),
        Target(f"exact: {n_times:.0e} output times (s)", many.cpu, "s", 0.1 * n_times / 1e5, "<=",
               f"ExactRigidBodyFlow.state on {n_times} times" + ("" if n_times == 100_000 else
                                                                  " (target scaled from 0.1 s per 1e5)")),
        Target(f"skipping: exact, M only vs M and R at {n_times:.0e} times", with_R / only_M, "x", 1.5, ">=",
               f"integrate(exact, samples={n_times}): M,R {with_R * 1e3:.1f} ms, M {only_M * 1e3:.1f} ms"),
        Target("exact: cost at t_end = 1e6 / cost at t_end = 1e2", long.cpu / short.cpu, "x", 1.1, "<=",
               f"1000 times each: {short.cpu * 1e3:.2f} ms vs {long.cpu * 1e3:.2f} ms"),
    ]


# --------------------------------------------------------------------------- skipping R
def splitting_skip_target(repeats: int, n_steps: int) -> Target:
    """integrate(lie-poisson-2) with outputs M only against M and R."""
    from dirac.flows import RigidBodyProblem, integrate

    quiet = _quiet()
    try:
        problem = RigidBodyProblem(_STANDARD_INERTIA, _STANDARD_M0)
        dt = 0.01

        def run(outputs: list[str]) -> float:
            return integrate(problem, "lie-poisson-2", t_end=n_steps * dt, dt=dt, samples=1,
                             outputs=outputs).cpu_seconds

        run(["M"])
        run(["M", "R"])
        both_runs: list[float] = []
        only_runs: list[float] = []
        for _ in range(repeats):  # interleaved, so slow drifts of the machine hit both alike
            both_runs.append(run(["M", "R"]))
            only_runs.append(run(["M"]))
        both, only = median_of(both_runs), median_of(only_runs)
    finally:
        quiet.__exit__(None, None, None)
    return Target("skipping: lie-poisson-2, M only vs M and R", both / only, "x", 1.1, ">=",
                  f"{n_steps} steps: M,R {both * 1e9 / n_steps:.0f} ns/step, M {only * 1e9 / n_steps:.0f} ns/step")


# --------------------------------------------------------------------------- memory
def memory_target(small_steps: int, large_steps: int) -> Target:
    """Peak traced memory of a final-state-only run: ``small_steps`` against ``large_steps``."""
    from dirac.flows import RigidBodyProblem, integrate

    quiet = _quiet()
    try:
        problem = RigidBodyProblem(_STANDARD_INERTIA, _STANDARD_M0)
        dt = 0.01

        def peak(n_steps: int) -> int:
            tracemalloc.start()
            try:
                integrate(problem, "lie-poisson-2", t_end=n_steps * dt, dt=dt, samples=1, outputs=["M", "R"])
                return tracemalloc.get_traced_memory()[1]
            finally:
                tracemalloc.stop()

        peak(small_steps)  # imports and compilation outside the measurement
        small = peak(small_steps)
        large = peak(large_steps)
    finally:
        quiet.__exit__(None, None, None)
    return Target(f"memory: peak of a final-state run, {large_steps:.0e} / {small_steps:.0e} steps",
                  large / small, "x", 1.1, "<=",
                  f"tracemalloc peak {small / 1024:.0f} KiB vs {large / 1024:.0f} KiB (samples = 1)")


# --------------------------------------------------------------------------- batch
def batch_targets(repeats: int, n_bodies: int, n_steps: int, numpy_steps: int) -> list[Target]:
    """Batched lie-poisson-2 (M and R) per body-step, and against plain numpy."""
    import numba

    from dirac.rigidbody.batch import advance_batch, advance_batch_numpy

    rng = np.random.default_rng(0)
    M0 = rng.normal(size=(n_bodies, 3))
    inv = 1.0 / rng.uniform(0.5, 2.0, size=(n_bodies, 3))
    dt = 0.01

    def state() -> tuple[np.ndarray, np.ndarray]:
        return M0.copy(), np.repeat(np.eye(3)[None], n_bodies, axis=0)

    compiled = time_call(lambda s: advance_batch(s[0], s[1], inv, dt, n_steps, (1.0,)), repeats, setup=state)
    only_M = time_call(lambda s: advance_batch(s[0], s[1], inv, dt, n_steps, (1.0,), with_R=False), repeats,
                       setup=state)
    plain = time_call(lambda s: advance_batch_numpy(s[0], s[1], inv, dt, numpy_steps, (1.0,)),
                      max(1, repeats // 2), setup=state)
    per = compiled.wall / (n_bodies * n_steps) * 1e9
    per_numpy = plain.wall / (n_bodies * numpy_steps) * 1e9
    threads = numba.get_num_threads()
    return [
        Target(f"batch: {n_bodies:.0e} bodies x {n_steps} lie-poisson-2 steps (ns per body-step)", per, "ns",
               20.0, "<=", f"wall time {compiled.wall * 1e3:.1f} ms on {threads} threads "
               f"(CPU {compiled.cpu / (n_bodies * n_steps) * 1e9:.1f} ns per body-step summed over threads)"),
        Target("batch: speed-up over plain numpy vectorisation", per_numpy / per, "x", 5.0, ">=",
               f"numpy {per_numpy:.0f} ns per body-step ({numpy_steps} steps, same bodies)"),
        Target("skipping: batched lie-poisson-2, M only vs M and R", compiled.cpu / only_M.cpu, "x", 1.1, ">=",
               f"CPU per body-step {compiled.cpu / (n_bodies * n_steps) * 1e9:.1f} ns (M, R) vs "
               f"{only_M.cpu / (n_bodies * n_steps) * 1e9:.1f} ns (M)"),
    ]


def batch_integrate_target(n_bodies: int, n_steps: int) -> Target:
    """The same batch through :func:`dirac.flows.integrate` (the user-facing path)."""
    from dirac.flows import RigidBodyProblem, integrate

    rng = np.random.default_rng(0)
    M0 = rng.normal(size=(n_bodies, 3))
    quiet = _quiet()
    try:
        problem = RigidBodyProblem(_STANDARD_INERTIA, M0)
        dt = 0.01

        def run() -> tuple[float, float]:
            w0 = time.perf_counter()
            solution = integrate(problem, "lie-poisson-2", t_end=n_steps * dt, dt=dt, samples=1, outputs=["M", "R"])
            return time.perf_counter() - w0, solution.cpu_seconds

        run()
        wall, cpu = run()
    finally:
        quiet.__exit__(None, None, None)
    per = wall / (n_bodies * n_steps) * 1e9
    return Target(f"batch via integrate: {n_bodies:.0e} bodies x {n_steps} lie-poisson-2 steps (ns per body-step)",
                  per, "ns", 20.0, "<=", f"whole integrate call, wall {wall * 1e3:.0f} ms (loop CPU {cpu * 1e3:.0f} ms); "
                  "the path a batched RigidBodyProblem takes today")


# --------------------------------------------------------------------------- general systems
def double_pendulum_target(repeats: int, n_steps: int) -> Target:
    """``n_steps`` rattle-2 steps of the double pendulum (CPU of the integrate loop)."""
    from dirac.bench.suite import constrained_cases
    from dirac.bench.workprecision import _constrained_problem
    from dirac.flows import integrate

    case = [c for c in constrained_cases(True) if c.system == "double_pendulum"][0]
    quiet = _quiet()
    try:
        problem, _ = _constrained_problem(case)
        dt = 1e-3

        def run() -> float:
            return integrate(problem, "rattle-2", t_end=n_steps * dt, dt=dt, samples=1, outputs=["q"]).cpu_seconds

        run()
        cpu = median_of([run() for _ in range(repeats)])
    finally:
        quiet.__exit__(None, None, None)
    return Target(f"general: {n_steps:.0e} rattle-2 steps of the double pendulum (s)", cpu * 1e5 / n_steps, "s",
                  1.0, "<=", f"measured {cpu:.3f} s for {n_steps} steps (dt = 1e-3), scaled to 1e5 steps"
                  if n_steps != 100_000 else "dt = 1e-3, CPU of the integrate loop")


# --------------------------------------------------------------------------- heavy top
def _heavy_top_per_step(problem, method: str, dt: float, n_steps: int) -> float:
    from dirac.flows import integrate

    return integrate(problem, method, t_end=n_steps * dt, dt=dt, samples=1, outputs=["M", "R"]).cpu_seconds / n_steps


def heavy_top_step_targets(repeats: int, n_steps: int) -> list[Target]:
    """``exact-kick-4`` per step against ``lie-poisson-4`` and against the hand-written anchor
    :func:`dirac.bench.heavy_top.anchor_exact_kick` (asymmetric heavy top)."""
    from dirac.bench.heavy_top import ASYMMETRIC_TOP, anchor_exact_kick
    from dirac.flows import HeavyTopProblem, integrate
    from dirac.flows.methods.registry import get_method

    inertia, direction, mass_gravity, chi = ASYMMETRIC_TOP
    problem = HeavyTopProblem(list(inertia), list(direction), mass_gravity=mass_gravity, center_of_mass=list(chi))
    a = 1.0 / np.array(inertia)
    w = mass_gravity * np.array(chi)
    gammas = np.array(get_method("exact-kick-4").data, dtype=float)
    dt = 0.01

    def anchor() -> float:
        M, R = np.array(direction), np.eye(3)
        c0 = time.process_time()
        anchor_exact_kick(M, R, a, w, gammas, dt, n_steps)
        return (time.process_time() - c0) / n_steps

    quiet = _quiet()
    try:
        exact_kick, split, hand = [], [], []
        _heavy_top_per_step(problem, "exact-kick-4", dt, 10)
        _heavy_top_per_step(problem, "lie-poisson-4", dt, 10)
        anchor()
        for _ in range(repeats):  # interleaved: a slow spell of the machine hits all three alike
            exact_kick.append(_heavy_top_per_step(problem, "exact-kick-4", dt, n_steps))
            split.append(_heavy_top_per_step(problem, "lie-poisson-4", dt, n_steps))
            hand.append(anchor())
        # the same algorithm: the two states agree to round-off (checked here too)
        package = integrate(problem, "exact-kick-4", t_end=1000 * dt, dt=dt, samples=1, outputs=["M", "R"])
    finally:
        quiet.__exit__(None, None, None)
    ek, lp, an = min(exact_kick), min(split), min(hand)
    M, R = np.array(direction), np.eye(3)
    anchor_exact_kick(M, R, a, w, gammas, dt, 1000)
    agree = max(float(np.max(np.abs(package["M"][-1] - M))), float(np.max(np.abs(package["R"][-1] - R))))
    return [
        Target("heavy top: exact-kick-4 step / lie-poisson-4 step", ek / lp, "x", 3.0, "<=",
               f"asymmetric top I = (1, 2, 3), dt = {dt:g}, {n_steps} steps through integrate: exact-kick-4 "
               f"{ek * 1e6:.2f} us/step, lie-poisson-4 {lp * 1e6:.2f} us/step (minima of {repeats}, interleaved)",
               {"exact_kick_4_us": ek * 1e6, "lie_poisson_4_us": lp * 1e6}),
        Target("heavy top: exact-kick-4 step / hand-written numba anchor", ek / an, "x", 1.3, "<=",
               f"anchor {an * 1e6:.2f} us/step (plain textbook kernel of the same composition); states after "
               f"1000 steps agree to {agree:.1e}", {"anchor_us": an * 1e6, "agreement": agree}),
    ]


def _log_interpolate(points: list[tuple[float, float]], cpu: float) -> float | None:
    """Error of a method at CPU time ``cpu`` by log–log interpolation of its ``(cpu, error)``
    points; None outside their range."""
    points = sorted(points)
    for (c0, e0), (c1, e1) in zip(points, points[1:]):
        if c0 <= cpu <= c1 and c1 > c0:
            s = (math.log(cpu) - math.log(c0)) / (math.log(c1) - math.log(c0))
            return math.exp(math.log(e0) + s * (math.log(e1) - math.log(e0)))
    return None


def heavy_top_equal_cpu_target(rows: list[dict], problem: str = "heavy top (fast)") -> Target:
    """``lie-poisson-4`` error over ``exact-kick-4`` error at the CPU time of each
    ``exact-kick-4`` run (interpolated on the ``lie-poisson-4`` curve); the smallest ratio."""
    name = f"{problem}: lie-poisson-4 error / exact-kick-4 error at equal CPU"
    subset = [r for r in rows if r.get("problem") == problem and "failed" not in r]
    split = [(r["cpu_s"], r["error"]) for r in subset if r["method"] == "lie-poisson-4"]
    ratios = []
    for r in subset:
        if r["method"] == "exact-kick-4":
            other = _log_interpolate(split, r["cpu_s"])
            if other is not None:
                ratios.append((other / r["error"], r))
    if not ratios:
        return Target(name, None, "x", 1.0, ">=", "no exact-kick-4 run fell within the lie-poisson-4 CPU range")
    ratio, row = min(ratios, key=lambda item: item[0])
    return Target(name, ratio, "x", 1.0, ">=",
                  f"smallest over {len(ratios)} exact-kick-4 runs; at dt = {row['value']:g} ({row['cpu_s'] * 1e3:.2f} ms) "
                  f"its error is {row['error']:.2g}; {row.get('description', '')}")


def torqued_target(rows: list[dict], threshold: float = 1e-8) -> Target:
    """The torqued body (:mod:`dirac.bench.torqued`): CPU of the fastest DOP853 run over that
    of the fastest package run, both with error ``<= threshold``."""
    name = f"torqued body: DOP853 CPU / fastest kick composition (error <= {threshold:g})"
    subset = [r for r in rows if r.get("problem") == "torqued body" and "failed" not in r
              and r.get("error", math.inf) <= threshold]
    ours = [r for r in subset if not r["method"].startswith("scipy-")]
    dop = [r for r in subset if r["method"] == "scipy-DOP853"]
    if not ours or not dop:
        return Target(name, None, "x", 1.0, ">=", "DOP853 or the package did not reach the error in this run")
    best = min(ours, key=lambda r: r["cpu_s"])
    best_dop = min(dop, key=lambda r: r["cpu_s"])
    return Target(name, best_dop["cpu_s"] / best["cpu_s"], "x", 1.0, ">=",
                  f"{best['method']} dt = {best['value']:g}: {best['cpu_s'] * 1e3:.2f} ms, error {best['error']:.2g}; "
                  f"DOP853 tol {best_dop['value']:g}: {best_dop['cpu_s'] * 1e3:.2f} ms, error {best_dop['error']:.2g}, "
                  f"{best_dop['evaluations']} RHS calls (lean float RHS)")


# --------------------------------------------------------------------------- start-up
def _dirac_command() -> list[str]:
    return [sys.executable, "-m", "dirac"]


_CHILD_CPU: list[float] = []


def _wall(command: list[str], env: dict | None = None) -> tuple[float, int]:
    """Wall time and exit status of a fresh process; its CPU time goes to ``_CHILD_CPU``."""
    import resource

    before = resource.getrusage(resource.RUSAGE_CHILDREN)
    start = time.perf_counter()
    completed = subprocess.run(command, capture_output=True, text=True, env=env, timeout=600)
    wall = time.perf_counter() - start
    after = resource.getrusage(resource.RUSAGE_CHILDREN)
    _CHILD_CPU.append((after.ru_utime - before.ru_utime) + (after.ru_stime - before.ru_stime))
    return wall, completed.returncode


def startup_targets(repeats: int, cold: bool) -> list[Target]:
    """``dirac --help`` and ``dirac demo`` wall time in fresh processes."""
    help_times = []
    _wall(_dirac_command() + ["--help"])
    _CHILD_CPU.clear()
    for _ in range(max(3, repeats)):
        help_times.append(_wall(_dirac_command() + ["--help"])[0])
    targets = [Target("start-up: dirac --help (s)", median_of(help_times), "s", 0.3, "<=",
                      f"wall time of a fresh process, median of {len(help_times)} "
                      f"(its CPU time: {median_of(_CHILD_CPU):.3f} s)")]
    first, status = _wall(_dirac_command() + ["demo"])
    if status != 0:
        targets.append(Target("start-up: dirac demo, warm cache (s)", None, "s", 3.0, "<=",
                              f"'dirac demo' exited with status {status}; not measured"))
        return targets
    _CHILD_CPU.clear()
    warm = median_of([_wall(_dirac_command() + ["demo"])[0] for _ in range(max(2, repeats // 2))])
    detail = f"wall time of a fresh process with compiled kernels cached on disk (CPU {median_of(_CHILD_CPU):.2f} s)"
    extra: dict = {}
    if cold:
        with tempfile.TemporaryDirectory(prefix="dirac-cold-") as scratch:
            env = dict(os.environ, NUMBA_CACHE_DIR=os.path.join(scratch, "numba"),
                       DIRAC_CACHE_DIR=os.path.join(scratch, "dirac"))
            cold_time, cold_status = _wall(_dirac_command() + ["demo"], env)
        detail += (f"; cold first run (empty numba and dirac caches) {cold_time:.1f} s wall, "
                   f"{_CHILD_CPU[-1]:.1f} s CPU")
        extra = {"cold_s": cold_time, "cold_status": cold_status}
    else:
        detail += "; cold first run measured by the full run only"
    targets.append(Target("start-up: dirac demo, warm cache (s)", warm, "s", 3.0, "<=", detail, extra))
    return targets


# --------------------------------------------------------------------------- symbolic analysis
def analysis_targets(repeats: int) -> list[Target]:
    """Median CPU time of ``dirac.analyze`` per case of :mod:`dirac.bench.analysis_times`."""
    from dirac.bench.analysis_times import analysis_runs

    targets = []
    for case, rows in analysis_runs(repeats):
        cpu = median_of([r["cpu"] for r in rows])
        wall = median_of([r["wall"] for r in rows])
        outcomes = ", ".join(sorted({r["outcome"] for r in rows}))
        targets.append(Target(
            f"analysis: {case.name} (s CPU)", cpu, "s", case.target, "<=",
            f"dirac.analyze in a fresh process (import excluded), median of {len(rows)}: CPU {cpu:.2f} s, "
            f"wall {wall:.2f} s; outcome {outcomes}",
            {"cpu_s": [r["cpu"] for r in rows], "wall_s": [r["wall"] for r in rows]},
        ))
    return targets


def analyze_command_targets(repeats: int) -> list[Target]:
    """``dirac analyze NAME`` end to end in a fresh process: median CPU time (wall beside) per system.

    The whole command as a user meets it: interpreter start, imports, loading the
    system, the analysis and the text report. CPU time (user + sys of the child) is the
    figure, since wall time grows with the load of a shared machine.
    """
    from dirac.bench.analysis_times import ANALYZE_COMMAND_TARGETS

    runs: dict[str, list[tuple[float, float, int]]] = {name: [] for name in ANALYZE_COMMAND_TARGETS}
    for _ in range(repeats):
        for name in ANALYZE_COMMAND_TARGETS:  # interleaved, so that a change of load touches each alike
            wall, status = _wall(_dirac_command() + ["analyze", name])
            runs[name].append((_CHILD_CPU[-1], wall, status))
    targets = []
    for name, target in ANALYZE_COMMAND_TARGETS.items():
        rows = runs[name]
        failed = [status for _, _, status in rows if status != 0]
        cpu = median_of([c for c, _, _ in rows]) if not failed else None
        wall = median_of([w for _, w, _ in rows])
        targets.append(Target(
            f"analysis: dirac analyze {name}, end to end (s CPU)", cpu, "s", target, "<=",
            (f"fresh process, median of {len(rows)}: CPU {cpu:.2f} s, wall {wall:.2f} s" if cpu is not None
             else f"'dirac analyze {name}' exited with status {failed[0]}; not measured"),
            {"cpu_s": [c for c, _, _ in rows], "wall_s": [w for _, w, _ in rows]},
        ))
    return targets


# what one measurement returns: a target or several, optionally with a note for the report
_Measured = Target | list[Target] | tuple[Target, str] | tuple[list[Target], str]


def measure_targets(quick: bool, rows: list[dict], progress: Callable[[str], None]) -> tuple[list[Target], list[str]]:
    """Every performance target of docs/performance.md (smaller sizes in ``quick`` mode, scaled where said)."""
    notes: list[str] = []
    targets: list[Target] = []
    repeats = 5 if quick else 9

    def attempt(label: str, function: Callable[[], _Measured]) -> None:
        progress(label)
        try:
            outcome = function()
        except Exception as exc:  # one failed measurement must not hide the others
            notes.append(f"{label}: not measured ({type(exc).__name__}: {' '.join(str(exc).split())[:200]})")
            return
        if isinstance(outcome, tuple):
            result, note = outcome
            notes.append(note)
        else:
            result = outcome
        targets.extend(result if isinstance(result, list) else [result])

    attempt("kernel against the C reference", lambda: kernel_against_c(repeats, 100_000 if quick else 1_000_000))
    targets.extend(work_precision_targets(rows))
    attempt("exact flow", lambda: exact_targets(repeats, 100_000))
    attempt("skipping R with splitting", lambda: splitting_skip_target(repeats, 100_000 if quick else 1_000_000))
    attempt("peak memory", lambda: memory_target(10_000, 1_000_000 if quick else 10_000_000))
    attempt("batched bodies", lambda: batch_targets(repeats, 100_000, 100, 5 if quick else 10))
    def batch_through_integrate() -> Target:
        # probe with 1e4 bodies; the full 1e5 only when the path is batched (a body-by-body
        # path slows down more than linearly with the batch size and would take minutes)
        if quick:
            return batch_integrate_target(1_000, 100)
        probe = batch_integrate_target(10_000, 100)
        if probe.value is not None and probe.value <= 300.0:
            return batch_integrate_target(100_000, 100)
        probe.detail += " (1e5 bodies not run: over 300 ns per body-step at 1e4 bodies)"
        return probe

    attempt("batch through integrate", batch_through_integrate)
    attempt("double pendulum", lambda: double_pendulum_target(3 if quick else 5, 20_000 if quick else 100_000))
    attempt("heavy top: exact-kick-4 and lie-poisson-4 per step, hand-written anchor",
            lambda: heavy_top_step_targets(repeats, 20_000 if quick else 100_000))
    targets.append(heavy_top_equal_cpu_target(rows))
    targets.append(torqued_target(rows))
    attempt("start-up", lambda: startup_targets(3 if quick else 5, cold=not quick))

    attempt("symbolic analysis: the paper's Lagrangians (19), (78), (228) and a square-root one",
            lambda: analysis_targets(1 if quick else 3))
    attempt("symbolic analysis: dirac analyze end to end on the paper's Lagrangians",
            lambda: analyze_command_targets(1 if quick else 3))
    return targets, notes
