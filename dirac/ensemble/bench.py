"""``dirac bench --ensemble``: ensemble throughput, plain batched vs local engine vs dask.

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

import argparse
import math
import tempfile
import time
import warnings
from pathlib import Path

import numpy as np

__all__ = ["measure", "main"]


def _scene(count: int, steps: int, dt: float):  # noqa: ANN202
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


def measure(members: int, steps: int, workers: int = 2, repeats: int = 2) -> dict[str, object]:
    """Time the three configurations (module docstring).

    Parameters
    ----------
    members, steps : int
        Ensemble size and steps per member.
    workers : int
        Workers of the dask LocalCluster.
    repeats : int
        Runs per configuration; the best is kept.

    Returns
    -------
    dict
        ``members``, ``steps``, ``chunk_size``, ``chunks`` and per configuration
        (``plain``, ``local``, ``dask``) the ``seconds`` and ``throughput``
        (members x steps / s); ``overhead_local`` and ``overhead_dask`` in percent.
    """
    from distributed import Client, LocalCluster

    from dirac.ensemble.chunk import advance_members
    from dirac.ensemble.engine import default_chunk_size, run_ensemble

    dt = 0.01
    scene = _scene(members, steps, dt)
    warm = _scene(4, 2, dt)
    work = members * steps
    results: dict[str, object] = {"members": members, "steps": steps}

    M, R, inertia = warm.source.members(0, 4)
    advance_members(M, R, 1.0 / inertia, dt, 1, scene.coefficients, True)  # load the kernel
    best = best_kernel = math.inf
    for _ in range(repeats):
        start = time.perf_counter()
        M, R, inertia = scene.source.members(0, members)
        inv = 1.0 / inertia
        middle = time.perf_counter()
        advance_members(M, R, inv, dt, steps, scene.coefficients, True)
        end = time.perf_counter()
        best, best_kernel = min(best, end - start), min(best_kernel, end - middle)
        del M, R, inertia, inv
    results["plain"] = {"seconds": best, "throughput": work / best}
    results["kernel"] = {"seconds": best_kernel, "throughput": work / best_kernel}

    chunk_size = default_chunk_size(scene)
    results["chunk_size"] = chunk_size
    results["chunks"] = -(-members // chunk_size)
    with tempfile.TemporaryDirectory(prefix="dirac-ensemble-bench-") as tmp:
        root = Path(tmp)
        run_ensemble(warm, root / "warm-local")
        best = min(run_ensemble(scene, root / f"local-{i}").seconds for i in range(repeats))
        results["local"] = {"seconds": best, "throughput": work / best}

        cluster = LocalCluster(
            n_workers=workers, threads_per_worker=1, processes=True, host="127.0.0.1", dashboard_address=None
        )
        client = Client(cluster)
        try:
            best = min(run_ensemble(scene, root / f"dask-{i}", client=client).seconds for i in range(repeats))
        finally:
            client.close()
            cluster.close()
        results["dask"] = {"seconds": best, "throughput": work / best, "workers": workers}
    plain = results["plain"]["seconds"]
    results["overhead_local"] = 100.0 * (results["local"]["seconds"] / plain - 1.0)
    results["overhead_dask"] = 100.0 * (results["dask"]["seconds"] / plain - 1.0)
    return results


def format_table(results: dict[str, object]) -> str:
    """A readable table of :func:`measure`'s results."""
    lines = [
        f"ensemble throughput: {results['members']:.3g} members x {results['steps']} steps of lie-poisson-4 "
        f"(M and R), chunks of {results['chunk_size']} ({results['chunks']} chunks)",
        "  (plain batched = draw the members and advance them in one kernel call, in memory)",
        f"  {'configuration':<28} {'seconds':>9} {'members x steps/s':>18} {'overhead':>9}",
    ]
    rows = (
        ("kernel call alone", "kernel", None),
        ("plain batched (in memory)", "plain", None),
        ("local engine (zarr store)", "local", "overhead_local"),
        (f"dask LocalCluster, {results['dask']['workers']} workers", "dask", "overhead_dask"),
    )
    for label, key, overhead in rows:
        entry = results[key]
        extra = "" if overhead is None else f"{results[overhead]:+8.1f}%"
        lines.append(f"  {label:<28} {entry['seconds']:9.3f} {entry['throughput']:18.4g} {extra:>9}")
    verdict = "meets" if results["overhead_dask"] <= 15.0 else "misses"
    lines.append(f"  dask overhead against the plain batched run: {results['overhead_dask']:.1f}% ({verdict} the 15% goal)")
    return "\n".join(lines)


def main(args: argparse.Namespace) -> int:
    """Entry of ``dirac bench --ensemble``: 1e6 members x 100 steps (``--quick``: 2e5 x 50)."""
    quick = bool(getattr(args, "quick", False))
    members, steps = (200_000, 50) if quick else (1_000_000, 100)
    np.seterr(all="ignore")
    print(format_table(measure(members, steps, workers=2, repeats=1 if quick else 2)))
    return 0
