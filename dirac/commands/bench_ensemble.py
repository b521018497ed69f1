"""``dirac bench --ensemble [--quick]``: ensemble throughput, plain batched vs local engine vs dask.

1e6 members x 100 steps (``--quick``: 2e5 x 50) on a two-worker dask ``LocalCluster``, two
repeats each (:func:`dirac.ensemble.bench.measure`); prints the table. Then the general systems' table
(:func:`dirac.ensemble.bench.measure_general`): the double pendulum's ensemble per member-step against a
single long run and a hand-written prange loop over members of the same RATTLE step. Last the double
pendulum's flip-time map at full size (256 x 256; ``--quick``: 64 x 64), in both coordinates
(:func:`dirac.ensemble.bench.measure_flip_maps`).
"""

from __future__ import annotations

import argparse


def main(args: argparse.Namespace) -> int:
    """Measure and print the throughput table; exit status 0."""
    import numpy as np

    from dirac.ensemble.bench import (
        BENCH_SIZES,
        format_flip_table,
        format_general_table,
        format_table,
        measure,
        measure_flip_maps,
        measure_general,
    )

    members, steps = BENCH_SIZES[bool(getattr(args, "quick", False))]
    np.seterr(all="ignore")
    print(format_table(measure(members, steps, workers=2, repeats=2)))
    print()
    quick = bool(getattr(args, "quick", False))
    print(format_general_table(measure_general(members=256 if quick else 1024, steps=500 if quick else 2000)))
    print()
    print(format_flip_table(measure_flip_maps(side=64 if quick else 256)))
    return 0
