"""What ``meta.json`` says about an ensemble and its runs, kept up to date chunk by chunk.

:func:`new_meta` describes a new ensemble (scene, method, sizes, versions); a
:class:`RunRecord` appends one entry to ``meta["runs"]`` for a call of
:func:`~dirac.ensemble.engine.run_ensemble`, records each finished or failed chunk and
rewrites ``meta.json`` (atomically, through the store) with the summary of the markers:
chunks and members complete, the done ranges, the failed chunks and the CPU time.
"""

from __future__ import annotations

import time
import uuid

from dirac.ensemble.chunk_plan import chunk_bounds
from dirac.ensemble.general_kernel import FAILURES
from dirac.ensemble.general_scene import GeneralEnsembleScene
from dirac.ensemble.scene import AnyScene
from dirac.ensemble.store import FORMAT, EnsembleStore, array_layout
from dirac.versions import installed_versions

__all__ = ["RunRecord", "new_meta"]


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
    return installed_versions(("dirac-mechanics", "numpy", "numba", "zarr", "dask", "distributed"), missing=None)


def _system_name(scene: AnyScene) -> str:
    if not isinstance(scene, GeneralEnsembleScene):
        return "rigid_body"
    return str(scene.system.get("name") or scene.system.get("file") or "inline system")


def new_meta(scene: AnyScene, chunk_size: int, n_chunks: int) -> dict:
    """``meta.json`` of a new ensemble of ``scene`` in chunks of ``chunk_size`` (no run yet)."""
    return {
        "format": FORMAT,
        "fingerprint": scene.fingerprint(),
        "scene_file": scene.path,
        "scene": scene.describe(),
        "system": _system_name(scene),
        "parameters": scene.describe()["parameters" if isinstance(scene, GeneralEnsembleScene) else "distributions"],
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
        **({"failure_codes": {str(k): v for k, v in FAILURES.items()}} if isinstance(scene, GeneralEnsembleScene) else {}),
    }


class RunRecord:
    """One call's entry in ``meta["runs"]`` and the chunk bookkeeping of ``meta.json``.

    Parameters
    ----------
    store : EnsembleStore
    meta : dict
        The ensemble's meta (read from the store or :func:`new_meta`); updated in place.
    scene : EnsembleScene
    chunk_size, n_chunks : int
    done : dict
        Chunk index -> marker of the chunks complete before this call; updated in place.
    executor : {"local", "dask"}
    scheduler : str or None
        The scheduler address or ``"local"`` (dask LocalCluster).
    """

    def __init__(self, store: EnsembleStore, meta: dict, scene: AnyScene, chunk_size: int, n_chunks: int,
                 done: dict[int, dict], executor: str, scheduler: str | None) -> None:
        self.store, self.meta, self.scene = store, meta, scene
        self.chunk_size, self.n_chunks, self.done = chunk_size, n_chunks, done
        self.failures: dict[str, str] = dict(meta.get("failed_chunks", {}))
        self.run: dict = {
            "run_id": uuid.uuid4().hex,
            "started_at": time.time(),
            "executor": executor,
            "scheduler": scheduler,
            "chunks_computed": 0,
            "chunks_failed": 0,
        }
        meta["runs"] = [*meta.get("runs", []), self.run]
        #: Members x steps computed by this call.
        self.member_steps = 0
        #: Chunk index -> error of the chunks that failed in this call.
        self.failed: dict[int, str] = {}

    @property
    def run_id(self) -> str:
        return str(self.run["run_id"])

    @property
    def chunks_computed(self) -> int:
        return int(self.run["chunks_computed"])

    def members_done(self) -> int:
        """Members in the complete chunks."""
        return sum(m["stop"] - m["start"] for m in self.done.values())

    def record(self, marker: dict | None, index: int, error: str | None) -> int:
        """Record chunk ``index`` as finished (``marker``) or failed (``error``); save meta.

        Returns the members the chunk added (0 for a failure).
        """
        added = 0
        if error is None:
            assert marker is not None
            self.done[index] = marker
            self.failures.pop(str(index), None)
            self.run["chunks_computed"] += 1
            start, stop = chunk_bounds(self.scene.count, self.chunk_size, index)
            added = stop - start
            self.member_steps += int(marker.get("member_steps", added * self.scene.steps))
        else:
            self.failures[str(index)] = error
            self.failed[index] = error
            self.run["chunks_failed"] += 1
        self.save()
        return added

    def finish(self) -> None:
        """Stamp the end of this call and save meta."""
        self.run["finished_at"] = time.time()
        self.save()

    def save(self) -> None:
        """Summarise the markers into ``meta.json`` (rewritten atomically by the store)."""
        meta, done = self.meta, self.done
        meta["chunks_complete"] = len(done)
        meta["members_complete"] = self.members_done()
        meta["chunks_done"] = _ranges(list(done))
        meta["complete"] = len(done) == self.n_chunks
        meta["failed_chunks"] = dict(self.failures)
        meta["cpu_seconds"] = sum(float(m.get("cpu_seconds", 0.0)) for m in done.values())
        meta["runs"][-1] = self.run
        self.store.write_meta(meta)
