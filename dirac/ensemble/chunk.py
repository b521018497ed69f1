"""One chunk of an ensemble: draw its members, run them through the scene's member loop, return arrays.

This is the unit of work of both executors (the local loop and a dask task): it depends
only on the scene and the member range, so a chunk computed anywhere, any number of
times, gives the same bits.
"""

from __future__ import annotations

import numpy as np

from dirac.ensemble.general_scene import GeneralEnsembleScene, HeavyTopEnsembleScene
from dirac.ensemble.kernel_lock import KERNEL_LOCK
from dirac.ensemble.scene import AnyScene

__all__ = ["compute_chunk", "warm_up", "KERNEL_LOCK"]


def compute_chunk(
    scene: AnyScene,
    start: int,
    stop: int,
    members: tuple[np.ndarray, np.ndarray, np.ndarray] | np.ndarray | None = None,
) -> dict[str, np.ndarray]:
    """Integrate members ``start .. stop-1`` of ``scene`` and return their arrays.

    Every kind of scene runs one compiled member loop over the chunk: a free rigid body's
    (:func:`dirac.ensemble.rigid_members.compute_rigid_chunk`), a heavy top's
    (:func:`dirac.ensemble.heavy_top_members.compute_heavy_top_chunk`) or any other
    system's (:func:`dirac.ensemble.general_chunk.compute_general_chunk`).

    Parameters
    ----------
    scene : EnsembleScene or GeneralEnsembleScene
    start, stop : int
        Member range.
    members : optional
        ``scene.source.members(start, stop)`` if already drawn (e.g. prefetched).

    Returns
    -------
    dict
        Array name -> array with ``stop - start`` rows (trajectory outputs have shape
        ``(n, samples, ...)``, reductions ``(n, ...)``).
    """
    if isinstance(scene, HeavyTopEnsembleScene):
        from dirac.ensemble.heavy_top_members import compute_heavy_top_chunk

        return compute_heavy_top_chunk(scene, start, stop, members)  # type: ignore[arg-type]
    if isinstance(scene, GeneralEnsembleScene):
        from dirac.ensemble.general_chunk import compute_general_chunk

        return compute_general_chunk(scene, start, stop, members)  # type: ignore[arg-type]
    from dirac.ensemble.rigid_members import compute_rigid_chunk

    return compute_rigid_chunk(scene, start, stop, members)  # type: ignore[arg-type]


def warm_up() -> None:
    """Load the compiled rigid-body member loop and the store's modules in this process
    (a one-member chunk; e.g. on dask workers, before timing)."""
    import zarr  # noqa: F401 -- imported by the first chunk write otherwise

    from dirac.ensemble.rigid_members import warm_up as warm_rigid

    warm_rigid()
