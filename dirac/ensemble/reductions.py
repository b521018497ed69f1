"""The per-member summaries of a free rigid-body ensemble: which arrays each stores.

A reduction keeps O(1) numbers per member, updated at every sample time ``t_k`` inside
the member loop (:mod:`dirac.ensemble.rigid_members`, where each is defined with its
equation), so an ensemble of 1e7 members that asks only for reductions needs neither the
memory nor the disk of its trajectories:

* ``flip_time`` -- the first sign change of ``M_a`` (the flip axis), interpolated between
  the samples bracketing it (Ashbaugh, Chicone & Cushman 1991); NaN if none;
* ``max_energy_error`` -- ``max_k |H_0(t_k) - H_0(0)| / H_0(0)``, ``H_0`` of (247);
* ``max_casimir_error`` -- ``max_k ||M(t_k)|^2 - |M(0)|^2| / |M(0)|^2``, Casimir (248);
* ``final_state`` -- ``M`` and ``R`` at ``t_end``;
* ``initial_state`` -- the member's initial ``M``, ``R`` and inertia.
"""

from __future__ import annotations

__all__ = ["reduction_arrays"]


def reduction_arrays(name: str) -> dict[str, tuple[int, ...]]:
    """The arrays a reduction stores: array name -> shape of one member's entry."""
    layouts: dict[str, dict[str, tuple[int, ...]]] = {
        "flip_time": {"flip_time": ()},
        "max_energy_error": {"max_energy_error": ()},
        "max_casimir_error": {"max_casimir_error": ()},
        "final_state": {"final_M": (3,), "final_R": (3, 3)},
        "initial_state": {"initial_M": (3,), "initial_R": (3, 3), "inertia": (3,)},
    }
    return layouts[name]
