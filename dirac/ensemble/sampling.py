"""Counter-based drawing of members: member ``i``'s data depends on ``(seed, i)`` only.

The members are cut into fixed blocks of :data:`SAMPLING_BLOCK` (a constant of the file
format, independent of the chunk size). Block ``b`` of quantity ``q`` draws from its own
generator ``Generator(Philox(SeedSequence(seed, spawn_key=(q, b))))`` -- Philox is a
counter-based generator (Salmon et al., SC'11) and ``SeedSequence`` hashes the key into
independent streams. A chunk ``[start, stop)`` draws the blocks it overlaps in full and
keeps its slice, so the same seed gives bit-identical members whatever the chunking, the
executor or the number of workers.

Each quantity (``M``, ``R``, ``inertia``) has its own stream, so changing the
distribution of one leaves the draws of the others unchanged.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from dirac.ensemble.distributions import Distribution

__all__ = ["SAMPLING_BLOCK", "STREAMS", "MemberSource", "block_generator", "draw_range", "open_member_file"]

#: Members per sampling block (part of the format: changing it changes every draw).
SAMPLING_BLOCK = 1024

#: Stream number of each quantity in the spawn key.
STREAMS = {"M": 0, "R": 1, "inertia": 2}


def block_generator(seed: int, stream: int, block: int) -> np.random.Generator:
    """The generator of one sampling block: Philox keyed by ``(seed, stream, block)``."""
    return np.random.Generator(np.random.Philox(np.random.SeedSequence(seed, spawn_key=(stream, block))))


def draw_range(distribution: Distribution, seed: int, stream: int, start: int, stop: int) -> np.ndarray:
    """Draw members ``start .. stop-1`` of one quantity.

    Parameters
    ----------
    distribution : Distribution
        What to draw.
    seed : int
        The ensemble's seed (``[ensemble] seed``).
    stream : int
        The quantity's stream (:data:`STREAMS`).
    start, stop : int
        Member range, ``0 <= start <= stop``.

    Returns
    -------
    numpy.ndarray, shape ``(stop - start, *distribution.shape)``
    """
    n = stop - start
    out = np.empty((n, *distribution.shape))
    if n == 0:
        return out
    first, last = start // SAMPLING_BLOCK, (stop - 1) // SAMPLING_BLOCK
    for block in range(first, last + 1):
        b0 = block * SAMPLING_BLOCK
        values = distribution.draw(block_generator(seed, stream, block), SAMPLING_BLOCK)
        lo, hi = max(start, b0), min(stop, b0 + SAMPLING_BLOCK)
        out[lo - start : hi - start] = values[lo - b0 : hi - b0]
    return out


def open_member_file(path: str) -> dict:
    """The arrays ``M``, ``R``, ``inertia`` present in a member file (``.npz`` or zarr group).

    Zarr arrays are returned unread (sliced lazily); ``.npz`` arrays are loaded.
    """
    if str(path).endswith(".npz"):
        with np.load(path) as data:
            return {name: data[name] for name in data.files if name in STREAMS}
    import zarr

    group = zarr.open_group(path, mode="r")
    return {name: group[name] for name in STREAMS if name in group}


@dataclass(frozen=True)
class MemberSource:
    """Where the members' initial data come from: distributions and a seed, or a file.

    Attributes
    ----------
    count : int
        Number of members.
    seed : int
        Seed of the counter-based draws (unused for a file).
    distributions : dict
        ``{"M": Distribution, "R": Distribution, "inertia": Distribution}``.
    file : str or None
        Absolute path of an ``.npz`` file or a zarr group (for large ensembles: read chunk
        by chunk) with arrays ``M`` (count, 3) and optionally ``R`` (count, 3, 3) and
        ``inertia`` (count, 3); quantities it lacks are drawn.
    """

    count: int
    seed: int
    distributions: dict
    file: str | None = None

    def members(self, start: int, stop: int) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """Initial ``M`` (n, 3), ``R`` (n, 3, 3) and inertia (n, 3) of members ``start..stop-1``."""
        arrays = {}
        loaded = open_member_file(self.file) if self.file else {}
        for quantity, stream in STREAMS.items():
            if quantity in loaded:
                arrays[quantity] = np.array(loaded[quantity][start:stop], dtype=float)
            else:
                arrays[quantity] = draw_range(self.distributions[quantity], self.seed, stream, start, stop)
        return (
            np.ascontiguousarray(arrays["M"]),
            np.ascontiguousarray(arrays["R"]),
            np.ascontiguousarray(arrays["inertia"]),
        )
