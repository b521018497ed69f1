"""Ensemble throughput (``dirac bench --ensemble``), plain batched vs local engine vs dask.

Three ways to advance the same members (drawn from the same seed) by the same steps of
``lie-poisson-4`` with the attitude, reporting members x steps per second:

1. *plain batched*: the members drawn in memory (the same counter-based draws) and
   advanced by one call of :func:`dirac.rigidbody.batch.advance_batch` (no chunks, no
   store, no scheduler) -- the reference; the kernel call alone is shown too;
2. *local engine*: :func:`dirac.ensemble.engine.run_ensemble` on this machine (chunks,
   counter-based draws, zarr store with markers and meta);
3. *dask LocalCluster*: the same on a two-worker ``LocalCluster`` (loopback, one thread
   per worker); the cluster is started and warmed up (kernels loaded in each worker)
   before the clock starts.

The overhead of a configuration is its time over the plain batched time, minus one.
Each figure is the best of ``repeats`` runs (the machine may be shared).
"""

from __future__ import annotations

import tempfile
import time
import warnings
from pathlib import Path
from typing import Any

__all__ = ["measure", "format_table", "BENCH_SIZES"]


def _scene(count: int, steps: int, dt: float):
    from dirac.ensemble.scene import parse_ensemble_scene

    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        return parse_ensemble_scene(
            {
                "system": {"name": "rigid_body", "inertia": [3.0, 2.0, 1.5]},
                "run": {"method": "lie-poisson-4", "dt": dt, "t_end": steps * dt, "samples": 2},
                "ensemble": {
                    "count": count,
                    "seed": 2026,
                    "reductions": ["final_state"],
                    "M": {"distribution": "sphere", "norm": 1.0},
                    "R": {"distribution": "uniform"},
                    "inertia": {"distribution": "uniform", "low": [1.5, 1.5, 1.5], "high": [2.5, 2.5, 2.5]},
                },
            }
        )


#: ``quick -> (members, steps)`` of ``dirac bench --ensemble`` (full: 1e6 x 100; quick: 2e5 x 50).
BENCH_SIZES: dict[bool, tuple[int, int]] = {False: (1_000_000, 100), True: (200_000, 50)}


def _best(runs: list[tuple[float, float]]) -> dict[str, float]:
    """The run with the least wall time: ``seconds`` and ``cpu_seconds``."""
    wall, cpu = min(runs)
    return {"seconds": wall, "cpu_seconds": cpu}


def measure(members: int, steps: int, workers: int = 2, repeats: int = 2) -> dict[str, Any]:
    """Time the three configurations (module docstring).

    Parameters
    ----------
    members, steps : int
        Ensemble size and steps per member.
    workers : int
        Workers of the dask LocalCluster.
    repeats : int
        Runs per configuration; the fastest is kept.

    Returns
    -------
    dict
        ``members``, ``steps``, ``chunk_size``, ``chunks`` and per configuration
        (``kernel``, ``plain``, ``local``, ``dask``) the wall ``seconds``, the
        ``cpu_seconds`` of every process involved (dask: the driver and all workers)
        and the ``throughput`` (members x steps / wall second); ``overhead`` and
        ``cpu_overhead`` (percent, against ``plain``) of ``local`` and ``dask``. The CPU
        figures stay meaningful on a machine shared with other jobs, where wall times
        are not.
    """
    from dirac.ensemble.chunk import KERNEL_LOCK, warm_up
    from dirac.ensemble.chunk_plan import default_chunk_size
    from dirac.ensemble.dask_executor import dask_client, local_cluster
    from dirac.ensemble.engine import run_ensemble
    from dirac.rigidbody.batch import advance_batch

    dt = 0.01
    scene = _scene(members, steps, dt)
    warm = _scene(4, 2, dt)
    work = members * steps
    results: dict[str, Any] = {"members": members, "steps": steps}

    warm_up()
    plain_runs, kernel_runs = [], []
    for _ in range(repeats):
        wall, cpu = time.perf_counter(), time.process_time()
        M, R, inertia = scene.source.members(0, members)
        inv = 1.0 / inertia
        wall_mid, cpu_mid = time.perf_counter(), time.process_time()
        with KERNEL_LOCK:
            advance_batch(M, R, inv, dt, steps, scene.coefficients, True)
        wall_end, cpu_end = time.perf_counter(), time.process_time()
        plain_runs.append((wall_end - wall, cpu_end - cpu))
        kernel_runs.append((wall_end - wall_mid, cpu_end - cpu_mid))
        del M, R, inertia, inv
    results["kernel"] = _best(kernel_runs)
    results["plain"] = _best(plain_runs)

    chunk_size = default_chunk_size(scene)
    results["chunk_size"] = chunk_size
    results["chunks"] = -(-members // chunk_size)
    with tempfile.TemporaryDirectory(prefix="dirac-ensemble-bench-") as tmp:
        root = Path(tmp)
        run_ensemble(warm, root / "warm-local")
        local_runs = []
        for i in range(repeats):
            cpu = time.process_time()
            report = run_ensemble(scene, root / f"local-{i}")
            local_runs.append((report.seconds, time.process_time() - cpu))
        results["local"] = _best(local_runs)

        cluster = local_cluster(workers)
        client = dask_client(cluster)
        try:
            client.run(warm_up)
            dask_runs = []
            for i in range(repeats):
                before, cpu = client.run(time.process_time), time.process_time()
                report = run_ensemble(scene, root / f"dask-{i}", client=client)
                after = client.run(time.process_time)
                used = time.process_time() - cpu + sum(after[w] - before[w] for w in after if w in before)
                dask_runs.append((report.seconds, used))
        finally:
            client.close()
            cluster.close()
        results["dask"] = {**_best(dask_runs), "workers": workers}
    for key in ("kernel", "plain", "local", "dask"):
        results[key]["throughput"] = work / results[key]["seconds"]
    for key in ("local", "dask"):
        results[key]["overhead"] = 100.0 * (results[key]["seconds"] / results["plain"]["seconds"] - 1.0)
        results[key]["cpu_overhead"] = 100.0 * (results[key]["cpu_seconds"] / results["plain"]["cpu_seconds"] - 1.0)
    return results


def format_table(results: dict[str, Any]) -> str:
    """A readable table of :func:`measure`'s results."""
    lines = [
        f"ensemble throughput: {results['members']:.3g} members x {results['steps']} steps of lie-poisson-4 "
        f"(M and R), chunks of {results['chunk_size']} ({results['chunks']} chunks)",
        "  (plain batched = draw the members and advance them in one kernel call, in memory;",
        "   CPU s = processor time of every process involved, dask workers included)",
        f"  {'configuration':<30} {'seconds':>8} {'members x steps/s':>18} {'overhead':>9} {'CPU s':>8} {'CPU overhead':>13}",
    ]
    rows = (
        ("kernel call alone", "kernel"),
        ("plain batched (in memory)", "plain"),
        ("local engine (zarr store)", "local"),
        (f"dask LocalCluster, {results['dask']['workers']} workers", "dask"),
    )
    for label, key in rows:
        entry = results[key]
        overhead = f"{entry['overhead']:+8.1f}%" if "overhead" in entry else ""
        cpu_overhead = f"{entry['cpu_overhead']:+12.1f}%" if "cpu_overhead" in entry else ""
        lines.append(
            f"  {label:<30} {entry['seconds']:8.3f} {entry['throughput']:18.4g} {overhead:>9} "
            f"{entry['cpu_seconds']:8.2f} {cpu_overhead:>13}"
        )
    dask = results["dask"]
    verdict = "meets" if dask["overhead"] <= 15.0 else "misses"
    lines.append(
        f"  dask overhead against the plain batched run: {dask['overhead']:.1f}% wall ({verdict} the 15% goal), "
        f"{dask['cpu_overhead']:.1f}% CPU"
    )
    return "\n".join(lines)



# ---------------------------------------------------------------- general systems
#: The systems of the general-ensemble table: the double pendulum in Cartesian coordinates
#: (two rods, constant-mass RATTLE) and in its two angles (configuration-dependent mass).
GENERAL_SYSTEMS: dict[str, tuple[dict, dict]] = {
    "double pendulum (x1, y1, x2, y2; 2 rods)": (
        {"name": "double_pendulum"},
        {"x1": "sin(a)", "y1": "-cos(a)", "x2": "sin(a) + sin(b)", "y2": "-cos(a) - cos(b)"},
    ),
    "double pendulum (th1, th2)": (
        {"name": "double_pendulum_angles", "coordinates": ["th1", "th2"],
         "parameters": {"m1": 1.0, "m2": 1.0, "g": 9.81, "l1": 1.0, "l2": 1.0},
         "lagrangian": "(m1 + m2)/2*l1**2*th1_dot**2 + m2/2*l2**2*th2_dot**2 + m2*l1*l2*th1_dot*th2_dot*cos(th1 - th2)"
                       " + (m1 + m2)*g*l1*cos(th1) + m2*g*l2*cos(th2)"},
        {"th1": "a", "th2": "b"},
    ),
}


#: Further rows of the member-loop table of :func:`measure_general` (not flip maps): a system
#: of another shape, with the expression of its ``max`` reduction. The triple pendulum of unit
#: masses and rods in its angles (bobs at ``x_k = sum_{j<=k} (sin th_j, -cos th_j)``): a full
#: 3 x 3 mass, ``v = M^-1 p`` by its adjugate; the reduction, the last bob's ``x``, reads the
#: step's sines.
GENERAL_EXTRA: dict[str, tuple[dict, dict, str]] = {
    "triple pendulum (th1, th2, th3)": (
        {"name": "triple_pendulum_angles", "coordinates": ["th1", "th2", "th3"],
         "parameters": {"m": 1.0, "l": 1.0, "g": 9.81},
         "lagrangian": "m*l**2*(3/2*th1_dot**2 + th2_dot**2 + 1/2*th3_dot**2 + 2*th1_dot*th2_dot*cos(th1 - th2)"
                       " + th1_dot*th3_dot*cos(th1 - th3) + th2_dot*th3_dot*cos(th2 - th3))"
                       " + m*g*l*(3*cos(th1) + 2*cos(th2) + cos(th3))"},
        {"th1": "a", "th2": "b", "th3": 0.0},
        "l*(sin(th1) + sin(th2) + sin(th3))",
    ),
}


def _prange_baseline():
    """The hand-written baseline: ``numba.prange`` over members, each advanced by the
    system's own RATTLE step loop for all its steps in one call (no reductions)."""
    import numba
    import numpy as np

    @numba.njit(parallel=True, cache=False)
    def run(step, Q, P, C, fractions, dt, n_steps, tol, max_iter):  # pragma: no cover - compiled
        for i in numba.prange(Q.shape[0]):
            info = np.zeros(4)
            step(Q[i], P[i], 0.0, C[i], fractions, dt, n_steps, tol, max_iter, info)

    return run


def measure_general(members: int = 1024, steps: int = 2000, dt: float = 2e-3, repeats: int = 3) -> list[dict[str, Any]]:
    """Per-member-step cost of a general ensemble against a single long run and a prange loop.

    For each system of :data:`GENERAL_SYSTEMS` and :data:`GENERAL_EXTRA`, members released at
    rest from a grid of angles ``[0.2, 0.6]^2`` (none flips: every member runs every step),
    ``rattle-2``:

    * *single run*: the system's compiled RATTLE loop (the kernel of ``dirac run``) for
      ``members * steps`` steps of one member, ns per step;
    * *ensemble, 1 thread*: the ensemble's member loop (one step at a time, a ``max``
      reduction evaluated after every step), numba on one thread, ns per member-step;
    * *ensemble* and *prange baseline*: all threads; the baseline is a hand-written
      ``numba.prange`` loop over the members calling the same RATTLE loop for all steps.

    Each figure is the best of ``repeats`` (CPU time for one thread, wall time for all).
    """
    from dirac.ensemble.general_scene import parse_general_scene

    side = int(round(members ** 0.5))
    baseline = _prange_baseline()
    rows = []
    systems = [(label, system, q, next(iter(q))) for label, (system, q) in GENERAL_SYSTEMS.items()]
    systems += [(label, system, q, expr) for label, (system, q, expr) in GENERAL_EXTRA.items()]
    for label, system, q, expr in systems:
        scene = parse_general_scene({
            "system": system, "initial": {"q": q},
            "run": {"method": "rattle-2", "dt": dt, "t_end": steps * dt, "samples": 2},
            "ensemble": {"grid": {"a": [0.2, 0.6, side], "b": [0.2, 0.6, side]},
                         "reductions": [{"kind": "max", "expr": expr}]},
        })
        rows.append({"system": label, **_measure_scene(scene, steps, repeats, baseline)})
    return rows


def _measure_scene(scene: Any, steps: int, repeats: int, baseline: Any) -> dict[str, Any]:
    """The figures of :func:`measure_general` for one scene."""
    import numba
    import numpy as np

    from dirac.ensemble.general_chunk import initial_states, step_grid
    from dirac.ensemble.general_kernel import compiled_ensemble

    compiled = compiled_ensemble(scene)
    module = compiled.module
    Q, P, C = initial_states(scene, compiled, scene.source.members(0, scene.count))
    starts, ends, per, step_dt = step_grid(scene)
    kernel = module.rattle_constant_mass if compiled.mechanics.constant_mass is not None else module.rattle_general
    count = scene.count
    shapes = module.ENS_SHAPES

    def ensemble(threads: int) -> float:
        q, p = Q.copy(), P.copy()
        n = Q.shape[1]
        arrays = (np.full((count, shapes[0]), np.nan), np.full((count, shapes[1]), np.nan), np.full(count, np.nan),
                  np.full(count, np.nan), np.full((count, shapes[2], shapes[3]), np.nan),
                  np.full((count, shapes[2], shapes[3], n), np.nan), np.full((count, shapes[2], shapes[3], n), np.nan),
                  np.zeros(count), np.zeros(count))
        numba.set_num_threads(threads)
        clock = time.process_time if threads == 1 else time.perf_counter
        start = clock()
        module.ens_run(0, count, q, p, C, compiled.fractions, step_dt, starts, ends, per, 1e-12, 50, 0.0, False, *arrays,
                       threads)
        return clock() - start

    def single() -> float:
        q, p, info = Q[0].copy(), P[0].copy(), np.zeros(4)
        start = time.process_time()
        kernel(q, p, 0.0, C[0], compiled.fractions, step_dt, count * steps, 1e-12, 50, info)
        return time.process_time() - start

    def prange() -> float:
        q, p = Q.copy(), P.copy()
        start = time.perf_counter()
        baseline(kernel, q, p, C, compiled.fractions, step_dt, steps, 1e-12, 50)
        return time.perf_counter() - start

    threads = numba.get_num_threads()
    try:
        ensemble(1), single(), prange()  # compile and warm up
        work = count * steps
        return {
            "single_ns": 1e9 * min(single() for _ in range(repeats)) / work,
            "ensemble_1_ns": 1e9 * min(ensemble(1) for _ in range(repeats)) / work,
            "ensemble_rate": work / min(ensemble(threads) for _ in range(repeats)),
            "prange_rate": work / min(prange() for _ in range(repeats)),
            "threads": threads,
        }
    finally:
        numba.set_num_threads(threads)


def format_general_table(rows: list[dict[str, Any]]) -> str:
    """The general-ensemble table: cost per member-step against a single run and a prange loop."""
    lines = [
        "general systems, rattle-2, every member runs every step:",
        f"{'system':<42} {'single run':>12} {'ensemble 1 thr':>15} {'ratio':>6} {'ensemble':>12} {'prange':>12} {'ratio':>6}",
        f"{'':<42} {'ns/step':>12} {'ns/member-step':>15} {'':>6} {'member-st/s':>12} {'member-st/s':>12} {'':>6}",
    ]
    for row in rows:
        lines.append(
            f"{row['system']:<42} {row['single_ns']:>12.1f} {row['ensemble_1_ns']:>15.1f} "
            f"{row['ensemble_1_ns'] / row['single_ns']:>6.2f} {row['ensemble_rate']:>12.3g} {row['prange_rate']:>12.3g} "
            f"{row['ensemble_rate'] / row['prange_rate']:>6.2f}"
        )
    lines.append("targets: ensemble per member-step <= 1.2 x a single run; ensemble throughput >= 0.5 x the prange loop "
                 f"({rows[0]['threads'] if rows else 0} threads)")
    return "\n".join(lines)


# ---------------------------------------------------------------- the flip map at full size
#: The flip-time map's reduction (Heyl's map): the first time either arm passes over its pivot.
FLIP_REDUCTIONS: dict[str, dict[str, list[str]]] = {
    "double pendulum (x1, y1, x2, y2; 2 rods)": {"expr": ["x1", "x2 - x1"], "when": ["y1 > 0", "y2 - y1 > 0"]},
    "double pendulum (th1, th2)": {"expr": ["sin(th1)", "sin(th2)"], "when": ["cos(th1) < 0", "cos(th2) < 0"]},
}

#: The flip map's target (seconds of wall time on a two-core machine).
FLIP_TARGET_SECONDS = 60.0


def flip_scene(label: str, side: int, t_end: float = 10.0, dt: float = 2e-3) -> Any:
    """The double pendulum's flip-map scene of :data:`GENERAL_SYSTEMS` ``label``: unit masses
    and rods, ``g = 9.81``, released at rest from a ``side x side`` grid of angles in
    ``[-3, 3]^2``, ``rattle-2``, the first time either arm flips over, members stopping at it."""
    from dirac.ensemble.general_scene import parse_general_scene

    system, q = GENERAL_SYSTEMS[label]
    return parse_general_scene({
        "system": system, "initial": {"q": q},
        "run": {"method": "rattle-2", "dt": dt, "t_end": t_end},
        "ensemble": {"grid": {"a": [-3.0, 3.0, side], "b": [-3.0, 3.0, side]},
                     "reductions": [{"kind": "first_crossing", "name": "flip_time", **FLIP_REDUCTIONS[label]}]},
    })


def measure_flip_maps(side: int = 256) -> list[dict[str, Any]]:
    """The flip-time map of each system of :data:`GENERAL_SYSTEMS` at ``side x side``, once each.

    ``run_ensemble`` into a temporary store on this machine (all threads), after a 4 x 4 map of
    the same system has loaded the compiled kernels (the first run's compilation is not in the
    figure). Reported: wall and CPU seconds (CPU of this process, all threads), the member-steps
    actually run (members stop at their flip), member-steps per wall and per CPU second,
    the members that flip, the threads and the 1-minute load average before the run (the
    machine may be shared: the CPU figure is the one to compare).
    """
    import os

    import numba
    import numpy as np
    import zarr

    from dirac.ensemble.engine import run_ensemble
    from dirac.ensemble.plot import _read_array

    rows = []
    with tempfile.TemporaryDirectory(prefix="dirac-flip-bench-") as tmp:
        for k, label in enumerate(GENERAL_SYSTEMS):
            run_ensemble(flip_scene(label, 4), Path(tmp) / f"warm-{k}")
            load = os.getloadavg()[0] if hasattr(os, "getloadavg") else float("nan")
            cpu = time.process_time()
            wall = time.perf_counter()
            run_ensemble(flip_scene(label, side), Path(tmp) / f"map-{k}")
            wall = time.perf_counter() - wall
            cpu = time.process_time() - cpu
            group = zarr.open_group(str(Path(tmp) / f"map-{k}" / "data.zarr"), mode="r")
            steps = float(np.sum(_read_array(group, "steps")))
            flips = int(np.sum(np.isfinite(_read_array(group, "flip_time"))))
            rows.append({"system": label, "side": side, "seconds": wall, "cpu_seconds": cpu, "member_steps": steps,
                         "flips": flips, "threads": numba.get_num_threads(), "load": load})
    return rows


def format_flip_table(rows: list[dict[str, Any]]) -> str:
    """The flip-map table of :func:`measure_flip_maps`."""
    side = rows[0]["side"] if rows else 0
    lines = [
        f"double pendulum flip map, {side} x {side} angles in [-3, 3]^2 at rest, t_end = 10, rattle-2, dt = 2e-3, "
        "members stop at their flip:",
        f"{'system':<42} {'wall s':>7} {'CPU s':>7} {'member-steps':>13} {'flipped':>8} {'member-st/s':>12} "
        f"{'per CPU s':>10} {'load':>5}",
    ]
    for row in rows:
        lines.append(
            f"{row['system']:<42} {row['seconds']:>7.1f} {row['cpu_seconds']:>7.1f} {row['member_steps']:>13.3g} "
            f"{row['flips']:>8d} {row['member_steps'] / row['seconds']:>12.3g} "
            f"{row['member_steps'] / row['cpu_seconds']:>10.3g} {row['load']:>5.1f}"
        )
    threads = rows[0]["threads"] if rows else 0
    lines.append(f"target: <= {FLIP_TARGET_SECONDS:.0f} s wall on a two-core machine ({threads} threads here; "
                 "on a shared machine compare CPU s / 2)")
    return "\n".join(lines)
