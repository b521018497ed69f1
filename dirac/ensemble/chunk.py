"""One chunk of an ensemble: draw its members, advance them, reduce, return arrays.

This is the unit of work of both executors (the local loop and a dask task): it depends
only on the scene and the member range, so a chunk computed anywhere, any number of
times, gives the same bits.
"""

from __future__ import annotations

from contextlib import contextmanager

import numpy as np

from dirac.ensemble.general_scene import GeneralEnsembleScene, HeavyTopEnsembleScene
from dirac.ensemble.kernel_lock import KERNEL_LOCK
from dirac.ensemble.reductions import casimir_of, energy_of, make_reductions
from dirac.ensemble.scene import TRAJECTORY_OUTPUTS, AnyScene

__all__ = ["advance_members", "compute_chunk", "warm_up", "KERNEL_LOCK"]


#: Member-steps below which one kernel call runs single-threaded (about 10 ms of work).
#: Measured on a shared two-core machine: a scene of 20000 members with 2 steps per
#: sample took 36 s single-threaded and 110 s (three times the CPU time) with parallel
#: calls, whose threads wait for one another at every call.
PARALLEL_WORK = 100_000


def advance_members(
    M: np.ndarray,
    R: np.ndarray | None,
    inv_inertia: np.ndarray,
    dt: float,
    n_steps: int,
    coefficients: tuple[float, ...],
    with_R: bool,
) -> None:
    """Advance a batch in place with the batched Lie-Poisson kernel (250)-(251).

    Delegates to :func:`dirac.rigidbody.batch.advance_batch` (numba, parallel over
    blocks of bodies), under :data:`KERNEL_LOCK`.
    """
    from dirac.rigidbody.batch import advance_batch

    with KERNEL_LOCK:
        advance_batch(M, R if with_R else None, inv_inertia, dt, n_steps, coefficients, with_R)


@contextmanager
def _threads_for(work_per_call: int):
    """One numba thread when a kernel call has less than :data:`PARALLEL_WORK` member-steps.

    Waking the other threads then costs more than it saves, and on a loaded machine a
    parallel launch can wait a whole scheduler time slice for a descheduled thread.
    """
    import numba

    threads = numba.get_num_threads()
    if work_per_call >= PARALLEL_WORK or threads == 1:
        yield
        return
    numba.set_num_threads(1)
    try:
        yield
    finally:
        numba.set_num_threads(threads)


def compute_chunk(
    scene: AnyScene,
    start: int,
    stop: int,
    members: tuple[np.ndarray, np.ndarray, np.ndarray] | None = None,
) -> dict[str, np.ndarray]:
    """Integrate members ``start .. stop-1`` of ``scene`` and return their arrays.

    The members are drawn (:meth:`MemberSource.members`), advanced over the sample grid
    ``t_k = k t_end / (samples - 1)`` by ``steps_per_sample`` steps of the scene's
    splitting method between samples, and at every sample the trajectory outputs are
    recorded and the reductions updated.

    Parameters
    ----------
    scene : EnsembleScene
    start, stop : int
        Member range.
    members : tuple of numpy.ndarray, optional
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
    M, R, inertia = scene.source.members(start, stop) if members is None else members
    inv = np.ascontiguousarray(1.0 / inertia)
    n = stop - start
    times = scene.times()

    traj = {name: np.empty((n, scene.samples, *TRAJECTORY_OUTPUTS[name])) for name in scene.outputs}
    reductions = make_reductions(scene.reductions, scene.flip_axis)

    def record(k: int) -> None:
        for name, array in traj.items():
            if name == "M":
                array[:, k] = M
            elif name == "R":
                array[:, k] = R
            elif name == "energy":
                array[:, k] = energy_of(M, inv)
            elif name == "casimir":
                array[:, k] = casimir_of(M)
            elif name == "lab_momentum":
                array[:, k] = np.einsum("nij,nj->ni", R, M)

    record(0)
    for reduction in reductions:
        reduction.start(M, R, inertia)
    with _threads_for(n * scene.steps_per_sample):
        for k in range(1, scene.samples):
            advance_members(M, R, inv, scene.dt, scene.steps_per_sample, scene.coefficients, scene.with_R)
            record(k)
            for reduction in reductions:
                reduction.update(times[k - 1], times[k], M, R)
    results: dict[str, np.ndarray] = dict(traj)
    for reduction in reductions:
        results.update(reduction.result())
    return results


def warm_up() -> None:
    """Load the compiled kernels and the store's modules in this process (a tiny advance;
    e.g. on dask workers, before timing)."""
    import zarr  # noqa: F401 -- imported by the first chunk write otherwise

    from dirac.rigidbody.splitting import SCHEMES

    M = np.array([[0.0, 1.0, 0.1]])
    advance_members(M, np.eye(3)[None].copy(), np.ones((1, 3)), 0.1, 1, SCHEMES["lie-poisson-2"].coefficients, True)
