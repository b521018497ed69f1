"""``codegen scale``: generated code against the size of the system, and the cold start.

Each figure is measured in a fresh process with an empty cache of generated code
(``DIRAC_CACHE_DIR`` a new temporary directory), so it includes everything a user waits
for on a new machine: import, the Lagrangian, code generation, compilation.

* **chain**: a planar chain of ``N`` unit links in Cartesian coordinates (``2N``
  coordinates, rods ``|r_1| = 1``, ``|r_k - r_{k-1}| = 1``, gravity). The first
  ``rattle-2`` call with the compiled kernel (CPU seconds, generation and compilation
  included), then the CPU nanoseconds per step and link, and the largest rod error.
  Targets: the first call grows at most like ``N^1.3`` (a log-log fit), the largest
  ``N`` starts within 20 s, a step costs per link at the largest ``N`` at most 1.5 times
  what it costs at the smallest (the per-link cost stays flat), rods kept to ``1e-10``.
  The same for a **bent** chain (every link at its own angle, :func:`chain_angles`), and
  at most 150 ns per step and link at the largest ``N``.
* **first result**: a fresh process that builds a pendulum (Cartesian) or a symmetric top
  (Euler angles) and runs 10 steps with ``rattle-2`` or ``midpoint``; CPU seconds of the
  whole process. Target 3 s (:mod:`dirac.codegen.tiers` runs short runs interpreted).
"""

from __future__ import annotations

import json
import math
import os
import subprocess
import sys
import tempfile
from typing import Any

import numpy as np

from dirac.bench.targets import Target

__all__ = ["codegen_scale_targets", "chain_lagrangian", "format_codegen_scale"]

_FIRST_RESULT_SYSTEMS = ("pendulum", "top")
#: ns per step and link of the compiled rattle-2 on the bent chain at the largest N
BENT_NS_TARGET = 150.0
_FIRST_RESULT_METHODS = ("rattle-2", "midpoint")


def chain_lagrangian(N: int):
    """The planar chain of ``N`` links (unit masses and lengths, gravity 9.81) as a Lagrangian."""
    from dirac.model.lagrangian import Lagrangian

    x = [f"x{k}" for k in range(1, N + 1)]
    y = [f"y{k}" for k in range(1, N + 1)]
    coordinates = [c for k in range(N) for c in (x[k], y[k])]
    kinetic = " + ".join(f"{a}_dot**2 + {b}_dot**2" for a, b in zip(x, y))
    rods = ["x1**2 + y1**2 - l**2"] + [f"({x[k]} - {x[k - 1]})**2 + ({y[k]} - {y[k - 1]})**2 - l**2"
                                       for k in range(1, N)]
    return Lagrangian.from_strings(f"chain{N}", coordinates, f"m/2*({kinetic}) - m*g*({' + '.join(y)})",
                                   constraints=rods, parameters={"m": 1.0, "g": 9.81, "l": 1.0})


def chain_angles(N: int, bent: bool) -> np.ndarray:
    """The links' angles from the downward vertical: all 0.3 (a straight chain, tilted), or
    bent (every link at its own angle, uniform in [-1.2, 1.2], a fixed seed)."""
    if not bent:
        return np.full(N, 0.3)
    return np.random.default_rng(3).uniform(-1.2, 1.2, N)


def _chain_child(N: int, steps: int, bent: bool = False) -> dict:
    """In a fresh process: first compiled rattle-2 call, then ns per step and link (CPU time)."""
    import time

    from dirac.flows.methods.registry import get_method
    from dirac.flows.problems import ConstrainedProblem

    start = time.process_time()
    angles = chain_angles(N, bent)
    q0 = np.cumsum(np.column_stack([np.sin(angles), -np.cos(angles)]), axis=0).ravel()
    problem = ConstrainedProblem(chain_lagrangian(N), q0, np.zeros(2 * N))
    stepper: Any = get_method("rattle-2").start(problem, ("q",), {})
    stepper.step(1, 1e-3)
    first = time.process_time() - start
    begin = time.process_time()
    stepper.step(steps, 1e-3)
    per_step = (time.process_time() - begin) / steps
    r = np.asarray(stepper.q)[0].reshape(N, 2)
    rods = np.linalg.norm(np.diff(np.vstack([[0.0, 0.0], r]), axis=0), axis=1)
    return {"N": N, "bent": bent, "first_call_s": first, "ns_per_step_link": per_step / N * 1e9,
            "rod_error": float(np.abs(rods - 1.0).max())}


def _first_result_child(system: str, method: str) -> dict:
    """In a fresh process: import, build, run 10 steps; CPU seconds of the process so far."""
    import time

    from dirac.flows.integration import integrate
    from dirac.flows.problems import ConstrainedProblem
    from dirac.model.lagrangian import Lagrangian

    if system == "pendulum":
        lagrangian = Lagrangian.from_strings("pendulum", ["x", "y"], "m/2*(x_dot**2 + y_dot**2) - m*g*y",
                                             constraints=["x**2 + y**2 - l**2"],
                                             parameters={"m": 1.0, "g": 9.81, "l": 1.0})
        q0, p0 = [math.sin(1.0), -math.cos(1.0)], [0.0, 0.0]
    else:
        lagrangian = Lagrangian.from_strings(
            "top", ["theta", "phi", "psi"],
            "A/2*(theta_dot**2 + phi_dot**2*sin(theta)**2) + C/2*(psi_dot + phi_dot*cos(theta))**2 - M*g*l*cos(theta)",
            parameters={"A": 1.0, "C": 0.5, "M": 1.0, "g": 9.81, "l": 0.3})
        q0, p0 = [0.5, 0.0, 0.0], [0.0, 0.3, 3.0]
    integrate(ConstrainedProblem(lagrangian, np.array(q0), np.array(p0)), method, t_end=0.1, dt=0.01, samples=3)
    return {"system": system, "method": method, "cpu_s": time.process_time()}


def _child(command: str, kernels: str = "auto") -> dict:
    """Run ``command`` (Python source calling a child function) in a fresh process with an
    empty cache of generated code and ``DIRAC_KERNELS=kernels``; its JSON result."""
    with tempfile.TemporaryDirectory(prefix="dirac-codegen-scale-") as scratch:
        env = dict(os.environ, DIRAC_CACHE_DIR=scratch, DIRAC_KERNELS=kernels)
        result = subprocess.run([sys.executable, "-c", f"import json; from dirac.bench.codegen_scale import *; "
                                 f"from dirac.bench.codegen_scale import _chain_child, _first_result_child; "
                                 f"print(json.dumps({command}))"],
                                env=env, capture_output=True, text=True, timeout=1800)
    if result.returncode != 0:
        raise RuntimeError(f"child failed: {result.stderr.strip().splitlines()[-1:]}")
    return json.loads(result.stdout.strip().splitlines()[-1])


def codegen_scale_targets(quick: bool) -> tuple[list[Target], str]:
    """The chain rows (N = 8, 16, 32; up to 128 unless ``quick``) and the first-result rows,
    their targets, and the table as a note."""
    sizes = (8, 16, 32) if quick else (8, 16, 32, 64, 128)
    chain = [_child(f"_chain_child({N}, {max(2000, 200_000 // N)})", "compiled") for N in sizes]
    bent = [_child(f"_chain_child({N}, {max(2000, 200_000 // N)}, bent=True)", "compiled") for N in sizes]
    first = [_child(f"_first_result_child({system!r}, {method!r})")
             for system in _FIRST_RESULT_SYSTEMS for method in _FIRST_RESULT_METHODS]
    slope = float(np.polyfit(np.log([r["N"] for r in chain]), np.log([r["first_call_s"] for r in chain]), 1)[0])
    largest, smallest = chain[-1], chain[0]
    targets = [
        Target(f"codegen scale: first rattle-2 call of the chain, growth exponent in N ({sizes[0]}..{sizes[-1]})",
               slope, "", 1.3, "<=", "log-log fit of the cold first call (generation + compilation) against N"),
        Target(f"codegen scale: first rattle-2 call of the chain at N = {largest['N']} (s)", largest["first_call_s"],
               "s", 20.0, "<=", "CPU seconds in a fresh process with an empty cache"),
        Target("codegen scale: ns per step and link, largest N / smallest N",
               largest["ns_per_step_link"] / smallest["ns_per_step_link"], "", 1.5, "<=",
               f"{largest['ns_per_step_link']:.0f} ns at N = {largest['N']}, {smallest['ns_per_step_link']:.0f} ns at "
               f"N = {smallest['N']}"),
        Target("codegen scale: ns per step and link, bent chain, largest N / smallest N",
               bent[-1]["ns_per_step_link"] / bent[0]["ns_per_step_link"], "", 1.5, "<=",
               f"{bent[-1]['ns_per_step_link']:.0f} ns at N = {bent[-1]['N']}, {bent[0]['ns_per_step_link']:.0f} ns "
               f"at N = {bent[0]['N']} (links at different angles)"),
        Target(f"codegen scale: ns per step and link, bent chain of {bent[-1]['N']} links",
               bent[-1]["ns_per_step_link"], "ns", BENT_NS_TARGET, "<=",
               "CPU time per step over the links, compiled rattle-2, dt = 1e-3, from rest"),
        Target("codegen scale: largest rod error of the chain", max(r["rod_error"] for r in [*chain, *bent]), "",
               1e-10, "<="),
        Target("codegen scale: first result, pendulum and top x rattle-2 and midpoint, worst (s)",
               max(r["cpu_s"] for r in first), "s", 3.0, "<=",
               "CPU seconds of a fresh process (import, system, 10 steps) with an empty cache"),
    ]
    return targets, format_codegen_scale(chain, first, slope, bent)


def format_codegen_scale(chain: list[dict], first: list[dict], slope: float, bent: list[dict] | None = None) -> str:
    """The ``codegen scale`` table (straight chain; the bent chain's ns per step and link beside it)."""
    bent_by_n = {r["N"]: r for r in bent or []}
    lines = ["codegen scale (fresh process, empty cache of generated code; CPU seconds; ns per step and link of "
             "the compiled rattle-2 in CPU time)",
             f"  {'N':>5} {'first call s':>13} {'ns/step/link':>13} {'rod error':>10} {'bent ns':>8} {'bent rod':>9}"]
    for r in chain:
        b = bent_by_n.get(r["N"])
        extra = f" {b['ns_per_step_link']:>8.1f} {b['rod_error']:>9.1e}" if b else ""
        lines.append(f"  {r['N']:>5} {r['first_call_s']:>13.2f} {r['ns_per_step_link']:>13.1f} "
                     f"{r['rod_error']:>10.1e}{extra}")
    lines.append(f"  first call grows like N^{slope:.2f}")
    lines += [f"  first result: {r['system']:<9} {r['method']:<9} {r['cpu_s']:.2f} s" for r in first]
    return "\n".join(lines)
