"""How an ensemble is cut into chunks: the default chunk size and each chunk's member range."""

from __future__ import annotations

from dirac.ensemble.general_scene import GeneralEnsembleScene
from dirac.ensemble.scene import AnyScene
from dirac.ensemble.store import array_layout

__all__ = ["CHUNK_BYTES", "MAX_DEFAULT_CHUNK", "chunk_bounds", "chunk_count", "default_chunk_size"]


#: Memory target of one chunk's arrays (bytes) and the largest default chunk.
CHUNK_BYTES = 64 * 2**20
MAX_DEFAULT_CHUNK = 65536

#: Default members per chunk of a general system's ensemble (each member runs many steps).
GENERAL_CHUNK = 4096


def default_chunk_size(scene: AnyScene) -> int:
    """Members per chunk such that one chunk's arrays take about :data:`CHUNK_BYTES`.

    Counts the stored arrays plus the working state (``M``, ``R``, ``1/I``) of a member;
    at most :data:`MAX_DEFAULT_CHUNK`; the chunks are then made (nearly) equal, which
    keeps the workers of a cluster evenly loaded.
    """
    if isinstance(scene, GeneralEnsembleScene):  # small arrays: chunks sized by work, for progress and resuming
        largest = max(1, min(scene.count, GENERAL_CHUNK))
        chunks = -(-scene.count // largest)
        return -(-scene.count // chunks)
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



def chunk_count(count: int, chunk_size: int) -> int:
    """Chunks of ``chunk_size`` members needed for ``count`` members (the last may be shorter)."""
    return -(-count // chunk_size)
