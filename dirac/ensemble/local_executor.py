"""The local executor of the ensemble engine: chunk after chunk on this machine.

Each chunk is run by the scene's member loop in parallel over all cores (numba); the
members of the next chunk are drawn, and the previous chunk is written, while a chunk is
integrated. A failing chunk is tried ``retries + 1`` times, then reported (never dropped).
"""

from __future__ import annotations

import time
from collections.abc import Callable
from concurrent.futures import Future, ThreadPoolExecutor
from typing import Any

from dirac.ensemble.chunk import compute_chunk
from dirac.ensemble.chunk_work import ChunkWork

__all__ = ["run_local"]

def run_local(work: ChunkWork) -> None:
    """Compute and write the chunks ``work.missing`` one after the other, reporting each to ``work.record``."""
    scene, store, missing, retries, record = work.scene, work.store, work.missing, work.retries, work.record

    def write(index: int, start: int, stop: int, arrays: dict, info: dict) -> dict:
        for attempt in range(retries + 1):
            try:
                return store.write_chunk(index, start, stop, arrays, info)
            except OSError:
                if attempt == retries:
                    raise
        raise AssertionError("unreachable")  # pragma: no cover

    def finish(pending: tuple[int, Future[dict]]) -> None:
        index, future = pending
        try:
            marker = future.result()
        except Exception as exc:
            record(None, index, f"write failed: {type(exc).__name__}: {exc}")
        else:
            record(marker, index, None)

    def attempts(start: int, stop: int, members) -> tuple[dict | None, dict, int, str | None]:
        error = None
        for attempt in range(retries + 1):
            try:
                wall, cpu = time.perf_counter(), time.process_time()
                arrays = compute_chunk(scene, start, stop, members if attempt == 0 else None)
                return arrays, {"seconds": time.perf_counter() - wall, "cpu_seconds": time.process_time() - cpu}, attempt, None
            except Exception as exc:
                error = f"{type(exc).__name__}: {exc} (after {attempt + 1} attempts)"
        return None, {}, retries, error

    pending: tuple[int, Future[dict]] | None = None
    draw: Callable[[int, int], Any] = scene.source.members
    bounds = [work.bounds(index) for index in missing]
    with (ThreadPoolExecutor(max_workers=1) as writer, ThreadPoolExecutor(max_workers=1) as drawer,
          ThreadPoolExecutor(max_workers=1) as computer):
        # draw the next chunk's members while this one is integrated (numpy's generators
        # and array operations release the GIL)
        upcoming = drawer.submit(draw, *bounds[0]) if bounds else None
        for position, index in enumerate(missing):
            start, stop = bounds[position]
            try:
                members = upcoming.result() if upcoming is not None else None
            except Exception:
                members = None
            upcoming = drawer.submit(draw, *bounds[position + 1]) if position + 1 < len(bounds) else None
            computing = computer.submit(attempts, start, stop, members)
            # the previous chunk is reported as soon as its write is done, while this one is integrated
            if pending is not None:
                finish(pending)
                pending = None
            arrays, timing, attempt, error = computing.result()
            if arrays is None:
                record(None, index, error)
                continue
            info = {"run_id": work.run_id, "attempt": attempt + 1, "worker": None, **timing}
            pending = (index, writer.submit(write, index, start, stop, arrays, info))
        if pending is not None:
            finish(pending)
