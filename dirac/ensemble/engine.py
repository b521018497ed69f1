"""The ensemble engine: plan chunks, run the missing ones locally or on dask, keep meta.

:func:`run_ensemble` runs (or resumes) an ensemble in five steps, each a function here:

1. check the executor arguments (:func:`_check_executor`);
2. plan the chunks: the chunk size of a new ensemble, or the stored one of an ensemble
   being resumed (:func:`_plan_chunk_size`, :mod:`dirac.ensemble.chunk_plan`);
3. open or resume the store: check that a stored ensemble is of this scene
   (:func:`_check_stored_scene`), or create the store with a new ``meta.json``
   (:func:`_create_store`);
4. run the chunks without a completion marker with one of two executors
   (:func:`_run_missing`):

   * local (default, :mod:`dirac.ensemble.local_executor`): the chunks one after the
     other, each run by the scene's member loop in parallel over all cores (numba), the
     write of chunk ``i`` overlapping the computation of chunk ``i + 1``;
   * dask (``scheduler=ADDRESS``, ``cluster="local"`` or a ``client``,
     :mod:`dirac.ensemble.dask_executor`): one task per chunk; each task draws,
     integrates and writes its own chunk and marker, so only the scene travels over the
     network;

5. reduce: every finished chunk is summarised into ``meta.json`` as it arrives
   (:class:`~dirac.ensemble.run_record.RunRecord`), and the call into an
   :class:`EnsembleReport`.

A failing chunk is retried ``retries`` times (dask: ``retries=``; a dead worker's tasks
are rescheduled by dask), then reported in ``meta.json`` under ``failed_chunks`` and in
the returned report -- never dropped: the next run of the same command retries it.

Errors about the arguments name them as keyword arguments (``out=``, ``chunk_size=``);
they are :class:`~dirac.ensemble.arguments.ArgumentError`, which the command line spells
as its flags.
"""

from __future__ import annotations

import sys
import threading
import time
from collections.abc import Callable
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

from dirac.ensemble.arguments import ArgumentError
from dirac.ensemble.chunk_plan import chunk_count, default_chunk_size
from dirac.ensemble.chunk_work import ChunkWork
from dirac.ensemble.dask_executor import run_dask
from dirac.ensemble.general_scene import GeneralEnsembleScene, HeavyTopEnsembleScene
from dirac.ensemble.local_executor import run_local
from dirac.ensemble.run_record import RunRecord, new_meta
from dirac.ensemble.scene import AnyScene, EnsembleScene, load_ensemble_scene
from dirac.ensemble.store import FORMAT, EnsembleStore
from dirac.errors import InputError

__all__ = ["EnsembleReport", "run_ensemble"]


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



class _Progress:
    """tqdm over members from the start of the run, advanced as chunks complete, or nothing.

    The bar is opened before the first chunk starts, so its elapsed time and members/s are
    measured over the wall time of the run (a bar opened at the first finished chunk would
    show the members of that chunk over a few milliseconds). While no chunk completes (a
    single chunk, or a long one) a thread redraws it every ``refresh`` seconds so the elapsed
    time keeps running.
    """

    def __init__(self, enabled: bool, total: int, initial: int, refresh: float = 0.5) -> None:
        self.enabled, self.total, self.initial = enabled, total, initial
        self.bar = None
        self._stop = threading.Event()
        self._ticker: threading.Thread | None = None
        if enabled:
            from tqdm import tqdm

            self.bar = tqdm(
                total=total, initial=initial, unit="member", unit_scale=True, desc="ensemble", file=sys.stderr,
                smoothing=0,  # the rate is members done in this call over its wall time
            )
            self._ticker = threading.Thread(target=self._tick, args=(refresh,), daemon=True)
            self._ticker.start()

    def _tick(self, refresh: float) -> None:
        while not self._stop.wait(refresh):
            bar = self.bar
            if bar is not None:
                bar.refresh()

    def update(self, n: int) -> None:
        if self.bar is not None:
            self.bar.update(n)

    def close(self) -> None:
        self._stop.set()
        if self._ticker is not None:
            self._ticker.join()
        if self.bar is not None:
            self.bar.close()


def run_ensemble(
    scene: AnyScene | str | Path,
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
    ArgumentError
        ``out`` holds a different ensemble, or was started with another chunk size, or is
        a non-empty folder of something else; ``chunk_size < 1``; a bad ``cluster``.
    InputError
        Both ``scheduler`` and ``cluster`` are given, or dask is not installed, or the
        scheduler cannot be reached.
    """
    say = notify or (lambda message: None)
    if not isinstance(scene, (EnsembleScene, GeneralEnsembleScene)):
        scene = load_ensemble_scene(scene)
    _check_executor(scheduler, cluster)
    store = EnsembleStore(out)
    meta = store.read_meta()
    if meta is not None:
        _check_stored_scene(scene, store, meta)
    chunk_size = _plan_chunk_size(scene, store, meta, chunk_size)
    n_chunks = chunk_count(scene.count, chunk_size)
    local = scheduler is None and cluster is None and client is None
    if meta is None:
        if isinstance(scene, HeavyTopEnsembleScene):
            from dirac.ensemble.heavy_top_members import check_heavy_top_states

            check_heavy_top_states(scene)  # bad numbers of a member: refused before anything is written
        elif isinstance(scene, GeneralEnsembleScene):
            from dirac.ensemble.general_chunk import check_initial_states

            # bad initial data: refused before anything is written (locally the projected
            # states are kept for the chunks, computed in this process)
            check_initial_states(scene, chunk_size if local else None)
        meta = _create_store(scene, store, chunk_size, n_chunks)
    done = store.completed()
    missing = [i for i in range(n_chunks) if i not in done]
    if done:
        say(f"resuming: {len(done)} of {n_chunks} chunks already complete, computing the other {len(missing)}")
    record = RunRecord(store, meta, scene, chunk_size, n_chunks, done,
                       executor="local" if local else "dask", scheduler=scheduler or cluster)
    report = EnsembleReport(store.root, scene.count, chunk_size, n_chunks, chunks_skipped=len(done))
    bar = _Progress(progress, scene.count, record.members_done())

    def on_chunk(marker: dict | None, index: int, error: str | None) -> None:
        added = record.record(marker, index, error)
        if added:
            bar.update(added)

    try:
        work = ChunkWork(scene, store, missing, chunk_size, record.run_id, retries, on_chunk)
        report.seconds, report.dashboard = _run_missing(
            work, scheduler=scheduler, n_workers=n_workers, client=client, say=say, local=local,
        )
    finally:
        bar.close()
        record.finish()
        if isinstance(scene, GeneralEnsembleScene):
            from dirac.ensemble.general_chunk import forget_projected

            forget_projected(scene)
    report.chunks_computed = record.chunks_computed
    report.member_steps = record.member_steps
    report.failed = dict(record.failed)
    return report


def _check_executor(scheduler: str | None, cluster: str | None) -> None:
    """Step 1: ``cluster`` is ``"local"`` or None, and not given with ``scheduler``."""
    if cluster is not None and cluster != "local":
        raise ArgumentError("{cluster} is unknown; use cluster='local' or scheduler=ADDRESS", {"cluster": cluster})
    if scheduler is not None and cluster is not None:
        raise InputError("give scheduler=ADDRESS or cluster='local', not both")


def _plan_chunk_size(scene: AnyScene, store: EnsembleStore, meta: dict | None, chunk_size: int | None) -> int:
    """Step 2: the chunk size: the stored one when resuming, else the asked or default one.

    Raises
    ------
    ArgumentError
        A resumed ensemble was started with another chunk size, or ``chunk_size < 1``.
    """
    if meta is not None:
        stored = int(meta["chunk_size"])
        asked = chunk_size or scene.chunk_size
        if asked is not None and min(asked, scene.count) != stored:
            raise ArgumentError(
                "{out} was started with chunk size {stored}; resume with {chunk_size} (or without the option)",
                {"out": str(store.root), "chunk_size": stored},
                stored=stored,
            )
        return stored
    chosen = chunk_size or scene.chunk_size or default_chunk_size(scene)
    if chosen < 1:
        raise ArgumentError("{chunk_size} must be >= 1", {"chunk_size": chosen})
    return min(chosen, scene.count)


def _check_stored_scene(scene: AnyScene, store: EnsembleStore, meta: dict) -> None:
    """Step 3, resuming: the store must hold an ensemble of this scene (same fingerprint)."""
    if meta.get("format") != FORMAT or meta.get("fingerprint") != scene.fingerprint():
        raise ArgumentError(
            "{out} holds an ensemble of a different scene; give another folder (or delete it to start over)",
            {"out": str(store.root)},
        )


def _create_store(scene: AnyScene, store: EnsembleStore, chunk_size: int, n_chunks: int) -> dict:
    """Step 3, a new ensemble: create the store and its ``meta.json``; return the meta."""
    meta = new_meta(scene, chunk_size, n_chunks)
    store.create(scene, chunk_size, {**meta, "complete": False, "chunks_complete": 0, "chunks_done": []})
    return meta


def _run_missing(
    work: ChunkWork,
    *,
    scheduler: str | None,
    n_workers: int | None,
    client: Any,
    say: Callable[[str], None],
    local: bool,
) -> tuple[float, str | None]:
    """Step 4: run the chunks ``work.missing``; return (computation seconds, dask dashboard address).

    No cluster is started when nothing is missing.
    """
    if not work.missing or local:
        start_time = time.perf_counter()
        if work.missing:
            run_local(work)
        return time.perf_counter() - start_time, None
    start_time, dashboard = run_dask(
        work,
        scheduler=scheduler, n_workers=n_workers, client=client, say=say,
    )
    return time.perf_counter() - start_time, dashboard
