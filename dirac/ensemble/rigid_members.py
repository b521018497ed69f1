"""The member loop of a free rigid-body ensemble: a batched run's kernel, over a chunk's whole time span.

A free rigid body (``H_0 = sum_i M_i^2 / (2 I_i)`` (247), Euler–Poisson (250)–(251)) is
advanced by the composed 3-term Lie–Poisson splitting, each sub-flow an exact rotation
of ``M`` about ``e_k`` by ``-theta`` and of ``R`` on the right by ``+theta``,
``theta = fraction dt M_k / I_k`` (McLachlan 1993; Reich 1994; Touma & Wisdom 1994).
A run of many bodies (:class:`dirac.flows.methods.lie_poisson.LiePoissonStepper` with a
batch) advances them by :func:`dirac.rigidbody.batch.advance_batch`: blocks of
:data:`~dirac.rigidbody.batch.BLOCK` bodies in structure-of-arrays form, each sub-flow
``dirac.rigidbody.batch.rotate_block`` (vectorised polynomial ``sin``/``cos``).

:func:`compute_rigid_chunk` runs a chunk of members through one compiled call,
:func:`_rb_run`: ``numba.prange`` over the blocks of members, and for each block the whole
sample grid ``t_k = k t_end / (samples - 1)`` -- the same ``rotate_block`` sub-flows in
the same order, the steps of each sample interval merged (first-same-as-last: adjacent
half-steps of the same sub-flow joined) exactly as one ``advance_batch`` call over that
interval merges them -- recording the trajectory outputs and updating the reductions at every
sample inside the loop (no Python loop over samples or members). The attitude rows are
neither loaded nor turned when no output needs ``R`` (``with_R``).

The reductions (:data:`dirac.ensemble.scene.REDUCTIONS`) at the samples:

* ``flip_time`` -- the first sign change of ``M_a`` after ``t = 0`` (the body axis
  ``e_a`` turns over with respect to ``m = R M``: ``(R e_a) . m / |m| = M_a / |M|``),
  located between the bracketing samples by linear interpolation,
  ``t* = t_{k-1} + (t_k - t_{k-1}) M_a(t_{k-1}) / (M_a(t_{k-1}) - M_a(t_k))``; ``a`` a
  fixed axis or each member's intermediate axis (the tennis-racket flip; Ashbaugh,
  Chicone & Cushman 1991). NaN if no flip by ``t_end`` or if ``M_a(0) = 0``.
* ``max_energy_error`` -- ``max_k |H_0(t_k) - H_0(0)| / H_0(0)``, ``H_0`` of (247).
* ``max_casimir_error`` -- ``max_k ||M(t_k)|^2 - |M(0)|^2| / |M(0)|^2``, Casimir (248).
* ``final_state`` -- ``M`` and ``R`` at ``t_end``; ``initial_state`` -- the drawn data.

The trigonometry (polynomial, or libm beyond :data:`~dirac.rigidbody.batch.MAX_POLY_ANGLE`
radians per sub-step) is chosen once per chunk from the largest rotation angle of its
initial data (:func:`~dirac.rigidbody.batch.choose_trigonometry`, the choice
``advance_batch`` makes per call; ``|M|`` is conserved by every sub-flow).
"""

from __future__ import annotations

import numpy as np
from numba import njit, prange

from dirac.ensemble.kernel_lock import KERNEL_LOCK
from dirac.ensemble.scene import TRAJECTORY_OUTPUTS, EnsembleScene
from dirac.rigidbody.batch import BLOCK, choose_trigonometry, composed_sequence, rotate_block

__all__ = ["compute_rigid_chunk", "warm_up"]

# what the loop records (indices into its ``wants`` flags)
_WANT_M, _WANT_R, _WANT_ENERGY, _WANT_CASIMIR, _WANT_LAB, _FLIP, _ENERGY_ERROR, _CASIMIR_ERROR = range(8)
_OUTPUT_FLAGS = {"M": _WANT_M, "R": _WANT_R, "energy": _WANT_ENERGY, "casimir": _WANT_CASIMIR, "lab_momentum": _WANT_LAB}
_REDUCTION_FLAGS = {"flip_time": _FLIP, "max_energy_error": _ENERGY_ERROR, "max_casimir_error": _CASIMIR_ERROR}


@njit(cache=True, inline="always")
def _energy(X, i):
    """``H_0 = (M_1^2 / I_1 + M_2^2 / I_2 + M_3^2 / I_3) / 2`` (247) of body ``i`` of a block.

    The three terms are summed as ``(1 + 3) + 2``, the order in which numpy's ``einsum``
    sums a row of three (so stored energies keep the bits of a numpy evaluation).
    """
    return 0.5 * (((X[0, i] * X[3, i]) * X[0, i] + (X[2, i] * X[5, i]) * X[2, i]) + (X[1, i] * X[4, i]) * X[1, i])


@njit(cache=True, inline="always")
def _casimir(X, i):
    """``|M|^2`` (248) of body ``i`` of a block (summed as :func:`_energy`)."""
    return (X[0, i] * X[0, i] + X[2, i] * X[2, i]) + X[1, i] * X[1, i]


@njit(cache=True, inline="always")
def _worse(current, value):
    """``max(current, value)`` propagating NaN (as ``numpy.maximum``)."""
    if current != current:
        return current
    if value != value or value > current:
        return value
    return current


@njit(cache=True, inline="always")
def _record(X, width, start, k, wants, TM, TR, TE, TC, TL):
    """The trajectory outputs of sample ``k`` of the block's bodies."""
    for i in range(width):
        b = start + i
        if wants[_WANT_M]:
            for a in range(3):
                TM[b, k, a] = X[a, i]
        if wants[_WANT_R]:
            for a in range(3):
                for c in range(3):
                    TR[b, k, a, c] = X[6 + 3 * a + c, i]
        if wants[_WANT_ENERGY]:
            TE[b, k] = _energy(X, i)
        if wants[_WANT_CASIMIR]:
            TC[b, k] = _casimir(X, i)
        if wants[_WANT_LAB]:  # m = R M
            for a in range(3):
                TL[b, k, a] = (X[6 + 3 * a, i] * X[0, i] + X[8 + 3 * a, i] * X[2, i]) + X[7 + 3 * a, i] * X[1, i]


@njit(cache=True, parallel=True)
def _rb_run(M, R, inv, axes, fractions, dt, times, per_interval, with_R, trig, n_workers, wants, cols,
            TM, TR, TE, TC, TL, FLIP, EERR, CERR):
    """Advance every member over the sample grid ``times``, recording outputs and reductions.

    ``M`` (n, 3) and, with ``with_R``, ``R`` (n, 3, 3) are overwritten with the final
    state; ``inv`` (n, 3) holds ``1/I``; ``cols`` the flip axis of each member. ``TM`` ...
    ``TL`` are the trajectory arrays (n, samples, ...), ``FLIP``, ``EERR``, ``CERR`` (n,)
    the reductions (``wants`` says which are filled; the others may be dummies).
    """
    n_bodies = M.shape[0]
    length = axes.shape[0]
    last = length - 1
    n_blocks = (n_bodies + BLOCK - 1) // BLOCK
    fd = np.empty(length)
    for q in range(length):
        fd[q] = fractions[q] * dt
    fd_join = (fractions[0] + fractions[last]) * dt
    scratch = np.empty((n_workers, 17, BLOCK))  # one private block per worker
    memory = np.empty((n_workers, 5, BLOCK))  # M_a(0), M_a(t_{k-1}), H_0(0) and |M(0)|^2 with their scales
    for worker in prange(n_workers):
        X = scratch[worker]
        S = X[15]
        C = X[16]
        Y = memory[worker]
        for block in range(worker, n_blocks, n_workers):
            start = block * BLOCK
            width = min(BLOCK, n_bodies - start)
            for i in range(width):
                b = start + i
                for a in range(3):
                    X[a, i] = M[b, a]
                    X[3 + a, i] = inv[b, a]
                if with_R:
                    for a in range(3):
                        for c in range(3):
                            X[6 + 3 * a + c, i] = R[b, a, c]
                if wants[_FLIP]:
                    Y[0, i] = X[cols[b], i]
                    Y[1, i] = Y[0, i]
                    FLIP[b] = np.nan
                if wants[_ENERGY_ERROR]:
                    Y[2, i] = _energy(X, i)
                    EERR[b] = 0.0
                if wants[_CASIMIR_ERROR]:
                    Y[3, i] = _casimir(X, i)
                    CERR[b] = 0.0
            _record(X, width, start, 0, wants, TM, TR, TE, TC, TL)
            for k in range(1, times.shape[0]):
                # the interval's steps, half-steps merged between them (as advance_batch)
                rotate_block(X, S, C, width, axes[0], fd[0], with_R, trig)
                for step in range(per_interval):
                    for q in range(1, last):
                        rotate_block(X, S, C, width, axes[q], fd[q], with_R, trig)
                    h_last = fd_join if step < per_interval - 1 else fd[last]
                    rotate_block(X, S, C, width, axes[last], h_last, with_R, trig)
                _record(X, width, start, k, wants, TM, TR, TE, TC, TL)
                t_prev = times[k - 1]
                t = times[k]
                for i in range(width):
                    b = start + i
                    if wants[_FLIP]:
                        value = X[cols[b], i]
                        if FLIP[b] != FLIP[b] and value * Y[0, i] < 0.0:
                            p = Y[1, i]
                            FLIP[b] = t_prev + (t - t_prev) * (p / (p - value))
                        Y[1, i] = value
                    if wants[_ENERGY_ERROR]:
                        f0 = Y[2, i]
                        scale = abs(f0) if f0 != 0.0 else 1.0
                        EERR[b] = _worse(EERR[b], abs(_energy(X, i) - f0) / scale)
                    if wants[_CASIMIR_ERROR]:
                        f0 = Y[3, i]
                        scale = abs(f0) if f0 != 0.0 else 1.0
                        CERR[b] = _worse(CERR[b], abs(_casimir(X, i) - f0) / scale)
            for i in range(width):
                b = start + i
                for a in range(3):
                    M[b, a] = X[a, i]
                if with_R:
                    for a in range(3):
                        for c in range(3):
                            R[b, a, c] = X[6 + 3 * a + c, i]


def _flip_columns(scene: EnsembleScene, inertia: np.ndarray) -> np.ndarray:
    """Each member's flip axis: the scene's, or the member's intermediate axis (the middle
    moment; of equal moments the later one in a stable sort)."""
    if scene.flip_axis is not None:
        return np.full(inertia.shape[0], scene.flip_axis, dtype=np.int64)
    return np.ascontiguousarray(np.argsort(inertia, axis=1, kind="stable")[:, 1], dtype=np.int64)


def compute_rigid_chunk(scene: EnsembleScene, start: int, stop: int,
                        members: tuple[np.ndarray, np.ndarray, np.ndarray] | None = None) -> dict[str, np.ndarray]:
    """Integrate members ``start .. stop-1`` of a free rigid-body ensemble; their arrays by name.

    Parameters
    ----------
    scene : EnsembleScene
    start, stop : int
        Member range.
    members : tuple of numpy.ndarray, optional
        ``scene.source.members(start, stop)`` (``M``, ``R``, inertia) if already drawn.

    Returns
    -------
    dict
        Array name -> array with ``stop - start`` rows: trajectory outputs ``(n, samples, ...)``
        (:data:`~dirac.ensemble.scene.TRAJECTORY_OUTPUTS`), reductions ``(n, ...)``
        (:func:`dirac.ensemble.reductions.reduction_arrays`).
    """
    M, R, inertia = scene.source.members(start, stop) if members is None else members
    M = np.ascontiguousarray(M, dtype=float)
    R = np.ascontiguousarray(R, dtype=float)
    inertia = np.ascontiguousarray(inertia, dtype=float)
    n = M.shape[0]
    initial: dict[str, np.ndarray] = {}  # the drawn data, before the loop overwrites M and R
    if "initial_state" in scene.reductions:
        initial.update(initial_M=M.copy(), initial_R=R.copy(), inertia=inertia.copy())
    inv = np.ascontiguousarray(1.0 / inertia)
    axes, fractions = composed_sequence(tuple(float(c) for c in scene.coefficients))
    wants = np.zeros(8, dtype=np.bool_)
    for name in scene.outputs:
        wants[_OUTPUT_FLAGS[name]] = True
    for name in scene.reductions:
        if name in _REDUCTION_FLAGS:
            wants[_REDUCTION_FLAGS[name]] = True

    def array(flag: int, shape: tuple[int, ...]) -> np.ndarray:
        return np.empty(shape if wants[flag] else (1,) * len(shape))

    samples = scene.samples
    TM = array(_WANT_M, (n, samples, 3))
    TR = array(_WANT_R, (n, samples, 3, 3))
    TE = array(_WANT_ENERGY, (n, samples))
    TC = array(_WANT_CASIMIR, (n, samples))
    TL = array(_WANT_LAB, (n, samples, 3))
    FLIP, EERR, CERR = (array(flag, (n,)) for flag in (_FLIP, _ENERGY_ERROR, _CASIMIR_ERROR))
    cols = _flip_columns(scene, inertia) if wants[_FLIP] else np.zeros(1, dtype=np.int64)
    with_R = scene.with_R
    R_arg = R if with_R else np.zeros((1, 3, 3))
    trig = choose_trigonometry(M, inv, fractions, scene.dt)
    import numba

    n_workers = max(1, min(int(numba.get_num_threads()), -(-n // BLOCK)))
    if n > 0:
        with KERNEL_LOCK:
            _rb_run(M, R_arg, inv, axes, fractions, float(scene.dt), scene.times(), scene.steps_per_sample,
                    with_R, trig, n_workers, wants, cols,
                    TM, TR, TE, TC, TL, FLIP, EERR, CERR)
    trajectories = {"M": TM, "R": TR, "energy": TE, "casimir": TC, "lab_momentum": TL}
    arrays: dict[str, np.ndarray] = {name: trajectories[name] for name in scene.outputs if name in TRAJECTORY_OUTPUTS}
    for name in scene.reductions:
        if name == "flip_time":
            arrays["flip_time"] = FLIP
        elif name == "max_energy_error":
            arrays["max_energy_error"] = EERR
        elif name == "max_casimir_error":
            arrays["max_casimir_error"] = CERR
        elif name == "final_state":
            arrays.update(final_M=M, final_R=R)
        elif name == "initial_state":
            arrays.update(initial)
    return arrays


def warm_up() -> None:
    """Load the compiled member loop in this process (a one-member, one-step chunk)."""
    from dirac.ensemble.scene import parse_ensemble_scene

    scene = parse_ensemble_scene({
        "system": {"name": "rigid_body", "inertia": [1.0, 2.0, 3.0]},
        "initial": {"M": [0.1, 1.0, 0.0]},
        "run": {"method": "lie-poisson-2", "dt": 0.1, "t_end": 0.1, "samples": 2, "outputs": ["M"]},
        "ensemble": {"count": 1, "reductions": ["flip_time"]},
    })
    assert isinstance(scene, EnsembleScene)
    compute_rigid_chunk(scene, 0, 1)
