"""The ensemble engine: plan chunks, run the missing ones locally or on dask, keep meta.

``run_ensemble`` is the one loop. It opens (or creates) the store, finds the chunks
without a completion marker, runs them with one of two executors and records each
finished chunk in ``meta.json``:

* local (default): the chunks one after the other, each advanced by the batched kernel
  in parallel over all cores (numba), the write of chunk ``i`` overlapping the
  computation of chunk ``i + 1``;
* dask (``scheduler=ADDRESS``, ``cluster="local"`` or a ``client``): one task per chunk;
  each task draws, integrates and writes its own chunk and marker, so only the scene
  travels over the network. Numba threads per task = cores of the host / dask threads
  on that host, so workers do not oversubscribe the cores.

A failing chunk is retried ``retries`` times (dask: ``retries=``; a dead worker's tasks
are rescheduled by dask), then reported in ``meta.json`` under ``failed_chunks`` and in
the returned report -- never dropped: the next run of the same command retries it.
"""

from __future__ import annotations

import os
import platform
import sys
import time
import uuid
from collections.abc import Callable
from concurrent.futures import ThreadPoolExecutor
from dataclasses import dataclass, field
from pathlib import Path

from dirac.ensemble.chunk import compute_chunk, warm_up
from dirac.ensemble.scene import EnsembleScene, load_ensemble_scene
from dirac.ensemble.store import FORMAT, EnsembleStore, array_layout
from dirac.errors import InputError

__all__ = [
    "EnsembleReport",
    "QUIET_DASK",
    "chunk_bounds",
    "dask_client",
    "default_chunk_size",
    "local_cluster",
    "run_chunk",
    "run_ensemble",
]

#: Memory target of one chunk's arrays (bytes) and the largest default chunk.
CHUNK_BYTES = 64 * 2**20
MAX_DEFAULT_CHUNK = 65536


@dataclass
class EnsembleReport:
    """What a call of :func:`run_ensemble` did.

    Attributes
    ----------
    out : Path
    count, chunk_size, chunks_total : int
    chunks_computed : int
        Chunks computed by this call.
    chunks_skipped : int
        Chunks already complete before this call (not recomputed).
    failed : dict
        Chunk index -> error message, for chunks that failed after all retries.
    seconds : float
        Wall time of this call's computation (set-up and cluster start excluded).
    member_steps : int
        Members x steps computed by this call.
    dashboard : str or None
        The dask dashboard address, if any.
    """

    out: Path
    count: int
    chunk_size: int
    chunks_total: int
    chunks_computed: int = 0
    chunks_skipped: int = 0
    failed: dict[int, str] = field(default_factory=dict)
    seconds: float = 0.0
    member_steps: int = 0
    dashboard: str | None = None

    @property
    def complete(self) -> bool:
        return not self.failed and self.chunks_computed + self.chunks_skipped == self.chunks_total

    @property
    def throughput(self) -> float:
        """Members x steps per second of this call."""
        return self.member_steps / self.seconds if self.seconds > 0 else float("nan")


def default_chunk_size(scene: EnsembleScene) -> int:
    """Members per chunk such that one chunk's arrays take about :data:`CHUNK_BYTES`.

    Counts the stored arrays plus the working state (``M``, ``R``, ``1/I``) of a member;
    at most :data:`MAX_DEFAULT_CHUNK`; the chunks are then made (nearly) equal, which
    keeps the workers of a cluster evenly loaded.
    """
    per_member = 8 * (21 + sum(int(_size(shape)) for shape in array_layout(scene).values()))
    largest = max(1, min(scene.count, MAX_DEFAULT_CHUNK, CHUNK_BYTES // per_member))
    chunks = -(-scene.count // largest)
    return -(-scene.count // chunks)  # equal chunks: no small straggler at the end


def _size(shape: tuple[int, ...]) -> int:
    size = 1
    for extent in shape:
        size *= extent
    return size


def chunk_bounds(count: int, chunk_size: int, index: int) -> tuple[int, int]:
    """Member range ``[start, stop)`` of chunk ``index``."""
    start = index * chunk_size
    return start, min(count, start + chunk_size)


def _ranges(indices: list[int]) -> list[list[int]]:
    """``[0, 1, 2, 5]`` -> ``[[0, 2], [5, 5]]`` (inclusive ranges, for meta.json)."""
    ranges: list[list[int]] = []
    for i in sorted(indices):
        if ranges and ranges[-1][1] == i - 1:
            ranges[-1][1] = i
        else:
            ranges.append([i, i])
    return ranges


def _versions() -> dict[str, str]:
    from importlib.metadata import PackageNotFoundError, version

    found = {"python": platform.python_version()}
    for name in ("dirac-mechanics", "numpy", "numba", "zarr", "dask", "distributed"):
        try:
            found[name] = version(name)
        except PackageNotFoundError:
            pass
    return found


def run_chunk(
    scene: EnsembleScene,
    root: str,
    index: int,
    start: int,
    stop: int,
    info: dict,
    host_threads: dict[str, int] | None = None,
) -> dict:
    """Compute one chunk and write it with its marker (the dask task; also usable alone).

    Parameters
    ----------
    scene : EnsembleScene
    root : str
        The store folder.
    index, start, stop : int
        Chunk number and member range.
    info : dict
        Fields added to the marker (run id, ...).
    host_threads : dict, optional
        Host -> dask threads on that host; sets the numba threads of this task to
        ``cpu_count // threads`` (avoids oversubscription by several workers per host).

    Returns
    -------
    dict
        The marker.
    """
    worker = None
    if host_threads is not None:
        import numba
        from distributed import get_worker

        worker = get_worker().address
        host = worker.split("://")[-1].rsplit(":", 1)[0]
        threads = max(1, (os.cpu_count() or 1) // max(1, host_threads.get(host, 1)))
        numba.set_num_threads(min(threads, numba.config.NUMBA_NUM_THREADS))
    wall, cpu = time.perf_counter(), time.process_time()
    arrays = compute_chunk(scene, start, stop)
    timing = {"seconds": time.perf_counter() - wall, "cpu_seconds": time.process_time() - cpu}
    return EnsembleStore(root).write_chunk(index, start, stop, arrays, {**info, **timing, "worker": worker})


class _Progress:
    """tqdm over members (shown from the first finished chunk on), or nothing."""

    def __init__(self, enabled: bool, total: int, initial: int) -> None:
        self.enabled, self.total, self.initial = enabled, total, initial
        self.bar = None

    def update(self, n: int) -> None:
        if self.enabled and self.bar is None:
            from tqdm import tqdm

            self.bar = tqdm(
                total=self.total, initial=self.initial, unit="member", unit_scale=True, desc="ensemble", file=sys.stderr
            )
        if self.bar is not None:
            self.bar.update(n)

    def close(self) -> None:
        if self.bar is not None:
            self.bar.close()


def run_ensemble(
    scene: EnsembleScene | str | Path,
    out: str | Path,
    *,
    chunk_size: int | None = None,
    scheduler: str | None = None,
    cluster: str | None = None,
    n_workers: int | None = None,
    client: object | None = None,
    retries: int = 2,
    progress: bool = False,
    notify: Callable[[str], None] | None = None,
) -> EnsembleReport:
    """Run (or resume) an ensemble into the store ``out``.

    Parameters
    ----------
    scene : EnsembleScene or path
        The validated scene, or a scene file.
    out : str or Path
        Output folder (created; an existing ensemble of the same scene is resumed).
    chunk_size : int, optional
        Members per chunk; default the scene's ``chunk_size``, else
        :func:`default_chunk_size`. A resumed run keeps the stored one.
    scheduler : str, optional
        Address of a running dask scheduler (``tcp://host:8786``).
    cluster : {"local"}, optional
        Start a dask ``LocalCluster`` on the loopback for this run (``n_workers``
        processes, default one per core).
    client : distributed.Client, optional
        Use this dask client (not closed here).
    retries : int
        Extra attempts of a failing chunk.
    progress : bool
        Show a tqdm progress bar over members (stderr).
    notify : callable, optional
        Receives one-line messages (the dashboard address, resuming, ...).

    Returns
    -------
    EnsembleReport

    Raises
    ------
    InputError
        The folder holds a different ensemble, or a chunk size that differs from the
        stored one, or dask is not installed.
    """
    say = notify or (lambda message: None)
    if not isinstance(scene, EnsembleScene):
        scene = load_ensemble_scene(scene)
    if cluster is not None and cluster != "local":
        raise InputError(f"--cluster {cluster!r} is unknown; use --cluster local or --scheduler ADDRESS")
    if scheduler is not None and cluster is not None:
        raise InputError("give --scheduler ADDRESS or --cluster local, not both")
    store = EnsembleStore(out)
    meta = store.read_meta()
    fingerprint = scene.fingerprint()
    if meta is not None:
        if meta.get("format") != FORMAT or meta.get("fingerprint") != fingerprint:
            raise InputError(
                f"--out {store.root} holds an ensemble of a different scene; give another folder "
                "(or delete it to start over)"
            )
        stored = int(meta["chunk_size"])
        asked = chunk_size or scene.chunk_size
        if asked is not None and min(asked, scene.count) != stored:
            raise InputError(
                f"--out {store.root} was started with chunk size {stored}; resume with --chunk-size {stored} "
                "(or without the option)"
            )
        chunk_size = stored
    else:
        chunk_size = chunk_size or scene.chunk_size or default_chunk_size(scene)
        if chunk_size < 1:
            raise InputError(f"--chunk-size {chunk_size} must be >= 1")
        chunk_size = min(chunk_size, scene.count)
    n_chunks = -(-scene.count // chunk_size)
    if meta is None:
        meta = {
            "format": FORMAT,
            "fingerprint": fingerprint,
            "scene_file": scene.path,
            "scene": scene.describe(),
            "system": "rigid_body",
            "parameters": scene.describe()["distributions"],
            "method": scene.method,
            "order": scene.order,
            "dt": scene.dt,
            "steps": scene.steps,
            "count": scene.count,
            "chunk_size": chunk_size,
            "chunks_total": n_chunks,
            "arrays": {name: [scene.count, *shape] for name, shape in array_layout(scene).items()},
            "runs": [],
            "versions": _versions(),
        }
        store.create(scene, chunk_size, {**meta, "complete": False, "chunks_complete": 0, "chunks_done": []})

    done = store.completed()
    missing = [i for i in range(n_chunks) if i not in done]
    report = EnsembleReport(store.root, scene.count, chunk_size, n_chunks, chunks_skipped=len(done))
    if done:
        say(f"resuming: {len(done)} of {n_chunks} chunks already complete, computing the other {len(missing)}")
    run = {
        "run_id": uuid.uuid4().hex,
        "started_at": time.time(),
        "executor": "local" if scheduler is None and cluster is None and client is None else "dask",
        "scheduler": scheduler or cluster,
        "chunks_computed": 0,
        "chunks_failed": 0,
    }
    meta["runs"] = [*meta.get("runs", []), run]
    failures: dict[str, str] = dict(meta.get("failed_chunks", {}))

    def record(marker: dict | None, index: int, error: str | None) -> None:
        if error is None:
            done[index] = marker
            failures.pop(str(index), None)
            run["chunks_computed"] += 1
            start, stop = chunk_bounds(scene.count, chunk_size, index)
            report.member_steps += (stop - start) * scene.steps
            bar.update(stop - start)
        else:
            failures[str(index)] = error
            report.failed[index] = error
            run["chunks_failed"] += 1
        _write_meta(store, meta, done, failures, scene, chunk_size, n_chunks, run)

    bar = _Progress(progress, scene.count, sum(m["stop"] - m["start"] for m in done.values()))
    try:
        if not missing:  # nothing to do: no cluster is started
            start_time = time.perf_counter()
        elif run["executor"] == "local":
            start_time = time.perf_counter()
            _run_local(scene, store, missing, chunk_size, run["run_id"], retries, record)
        else:
            start_time, report.dashboard = _run_dask(
                scene, store, missing, chunk_size, run["run_id"], retries, record,
                scheduler=scheduler, n_workers=n_workers, client=client, say=say,
            )
        report.seconds = time.perf_counter() - start_time
    finally:
        bar.close()
        run["finished_at"] = time.time()
        _write_meta(store, meta, done, failures, scene, chunk_size, n_chunks, run)
    report.chunks_computed = run["chunks_computed"]
    return report


def _write_meta(store, meta, done, failures, scene, chunk_size, n_chunks, run) -> None:  # noqa: ANN001, PLR0913
    meta["chunks_complete"] = len(done)
    meta["members_complete"] = sum(m["stop"] - m["start"] for m in done.values())
    meta["chunks_done"] = _ranges(list(done))
    meta["complete"] = len(done) == n_chunks
    meta["failed_chunks"] = dict(failures)
    meta["cpu_seconds"] = sum(float(m.get("cpu_seconds", 0.0)) for m in done.values())
    meta["runs"][-1] = run
    store.write_meta(meta)


def _run_local(scene, store, missing, chunk_size, run_id, retries, record) -> None:  # noqa: ANN001, PLR0913
    """Chunks one after the other; the write of one overlaps the computation of the next."""

    def write(index: int, start: int, stop: int, arrays: dict, info: dict) -> dict:
        for attempt in range(retries + 1):
            try:
                return store.write_chunk(index, start, stop, arrays, info)
            except OSError:
                if attempt == retries:
                    raise
        raise AssertionError("unreachable")  # pragma: no cover

    def finish(pending) -> None:  # noqa: ANN001
        index, future = pending
        try:
            marker = future.result()
        except Exception as exc:  # noqa: BLE001 -- reported, never dropped
            record(None, index, f"write failed: {type(exc).__name__}: {exc}")
        else:
            record(marker, index, None)

    pending = None
    bounds = [chunk_bounds(scene.count, chunk_size, index) for index in missing]
    with ThreadPoolExecutor(max_workers=1) as writer, ThreadPoolExecutor(max_workers=1) as drawer:
        # draw the next chunk's members while this one is integrated (numpy's generators
        # and array operations release the GIL)
        upcoming = drawer.submit(scene.source.members, *bounds[0]) if bounds else None
        for position, index in enumerate(missing):
            start, stop = bounds[position]
            try:
                members = upcoming.result()
            except Exception:  # noqa: BLE001 -- drawn again below, where errors are counted
                members = None
            upcoming = drawer.submit(scene.source.members, *bounds[position + 1]) if position + 1 < len(bounds) else None
            error = None
            for attempt in range(retries + 1):
                try:
                    wall, cpu = time.perf_counter(), time.process_time()
                    arrays = compute_chunk(scene, start, stop, members if attempt == 0 else None)
                    timing = {"seconds": time.perf_counter() - wall, "cpu_seconds": time.process_time() - cpu}
                    break
                except Exception as exc:  # noqa: BLE001 -- retried, then reported
                    error = f"{type(exc).__name__}: {exc} (after {attempt + 1} attempts)"
            else:
                record(None, index, error)
                continue
            if pending is not None:
                finish(pending)
            info = {"run_id": run_id, "attempt": attempt + 1, "worker": None, **timing}
            pending = (index, writer.submit(write, index, start, stop, arrays, info))
        if pending is not None:
            finish(pending)


def _run_dask(scene, store, missing, chunk_size, run_id, retries, record, *, scheduler, n_workers, client, say):  # noqa: ANN001, ANN202, PLR0913
    """One dask task per chunk; returns (start time, dashboard address)."""
    try:
        from distributed import as_completed
    except ImportError:
        raise InputError(
            "dask.distributed is not installed; install it with  pip install 'dirac-mechanics[ensemble]'"
        ) from None
    own_cluster = own_client = None
    try:
        if client is None:
            if scheduler is not None:
                try:
                    client = own_client = dask_client(scheduler)
                except (OSError, TimeoutError) as exc:
                    raise InputError(f"cannot reach the dask scheduler at {scheduler!r} ({exc}); check the address") from None
            else:
                own_cluster = local_cluster(n_workers or os.cpu_count() or 1, dashboard_address=":0")
                client = own_client = dask_client(own_cluster)
        client.run(warm_up)  # load the kernels in every worker before the clock starts
        dashboard = _dashboard(client)
        if dashboard:
            say(f"dask dashboard: {dashboard}")
        host_threads: dict[str, int] = {}
        for address, worker in client.scheduler_info(n_workers=-1)["workers"].items():
            host = address.split("://")[-1].rsplit(":", 1)[0]
            host_threads[host] = host_threads.get(host, 0) + int(worker.get("nthreads", 1))
        start_time = time.perf_counter()
        futures = {}
        for index in missing:
            start, stop = chunk_bounds(scene.count, chunk_size, index)
            info = {"run_id": run_id}
            future = client.submit(
                run_chunk, scene, str(store.root), index, start, stop, info, host_threads,
                key=f"dirac-ensemble-chunk-{index}-{run_id}", retries=retries,
            )
            futures[future.key] = (future, index)
        for future in as_completed([f for f, _ in futures.values()]):
            index = futures[future.key][1]
            if future.status == "finished":
                record(future.result(), index, None)
            elif future.status == "cancelled":
                record(None, index, "the task was cancelled by the cluster (e.g. its scheduler restarted)")
            else:
                exc = future.exception()
                record(None, index, f"{type(exc).__name__}: {exc} (after {retries + 1} attempts)")
            future.release()
        return start_time, dashboard
    finally:
        if own_client is not None:
            own_client.close()
        if own_cluster is not None:
            own_cluster.close()


#: dask settings for compute-bound ensembles: slower housekeeping timers (event-loop tick
#: monitor 20 ms -> 1 s, system monitor 0.5 s -> 2 s, worker memory monitor 0.1 s -> 1 s).
#: Measured on two idle workers and a client: 0.072 -> 0.013 cores of background CPU.
QUIET_DASK = {
    "distributed.admin.tick.interval": "1s",
    "distributed.admin.system-monitor.interval": "2s",
    "distributed.worker.memory.monitor-interval": "1s",
}


def dask_client(address_or_cluster: object):  # noqa: ANN201
    """A ``distributed.Client`` created with :data:`QUIET_DASK` (its own timers are slower)."""
    import dask
    from distributed import Client

    with dask.config.set(QUIET_DASK):
        return Client(address_or_cluster, timeout="20s")


def local_cluster(n_workers: int, dashboard_address: str | None = None):  # noqa: ANN201
    """A dask ``LocalCluster`` for ensembles: ``n_workers`` processes on the loopback.

    One thread per worker (each task's kernel gets the host's cores divided by the
    workers), and the workers' statistical profiler is off: it samples the task
    thread's stack every 10 ms, which costs a noticeable share of a compute-bound
    task's CPU time. Log messages below CRITICAL are silenced (a worker still
    heartbeating while the cluster shuts down logs a traceback); task failures reach
    the engine through their futures and are reported there.
    """
    import logging

    import dask
    from distributed import LocalCluster

    with dask.config.set({**QUIET_DASK, "distributed.worker.profile.enabled": False}):
        return LocalCluster(
            n_workers=n_workers, threads_per_worker=1, processes=True,
            host="127.0.0.1", dashboard_address=dashboard_address, silence_logs=logging.CRITICAL,
        )


def _dashboard(client) -> str | None:  # noqa: ANN001
    """The dashboard address, if the scheduler runs one (needs bokeh)."""
    try:
        services = client.scheduler_info(n_workers=0).get("services", {})
    except Exception:  # noqa: BLE001 -- the address is a convenience
        return None
    if "dashboard" not in services:
        return None
    return client.dashboard_link
