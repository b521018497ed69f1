"""The work order an executor of the ensemble engine receives: which chunks, where, how often.

Both executors (:mod:`dirac.ensemble.local_executor`, :mod:`dirac.ensemble.dask_executor`)
compute the chunks :attr:`ChunkWork.missing` of :attr:`ChunkWork.scene`, write them into
:attr:`ChunkWork.store`, try a failing chunk ``retries + 1`` times and report every chunk,
finished or failed, to :attr:`ChunkWork.record`.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass

from dirac.ensemble.chunk_plan import chunk_bounds
from dirac.ensemble.scene import AnyScene
from dirac.ensemble.store import EnsembleStore

__all__ = ["ChunkWork", "Recorder"]

#: ``record(marker, index, error)``: a finished chunk's marker (``error`` None) or its error.
Recorder = Callable[[dict | None, int, str | None], None]


@dataclass(frozen=True)
class ChunkWork:
    """The chunks one call of the engine computes.

    Attributes
    ----------
    scene : EnsembleScene
    store : EnsembleStore
    missing : list of int
        Indices of the chunks to compute (those without a marker).
    chunk_size : int
    run_id : str
        Identifies this call in the chunk markers and ``meta.json``.
    retries : int
        Extra attempts of a failing chunk.
    record : Recorder
        Receives each finished or failed chunk.
    """

    scene: AnyScene
    store: EnsembleStore
    missing: list[int]
    chunk_size: int
    run_id: str
    retries: int
    record: Recorder

    def bounds(self, index: int) -> tuple[int, int]:
        """Member range ``[start, stop)`` of chunk ``index``."""
        return chunk_bounds(self.scene.count, self.chunk_size, index)
