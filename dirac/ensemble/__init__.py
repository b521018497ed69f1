"""Ensembles of rigid bodies and of any system: chunked batched flows, locally or on a dask cluster.

Modules, one job each:

- :mod:`dirac.ensemble.scene` -- ``[ensemble]`` scenes, validated (:func:`load_ensemble_scene`);
- :mod:`dirac.ensemble.distributions` -- named distributions of ``M``, ``R``, inertia;
- :mod:`dirac.ensemble.sampling` -- counter-based draws keyed by ``(seed, member)``;
- :mod:`dirac.ensemble.reductions` -- the free rigid body's per-member summaries and their arrays;
- :mod:`dirac.ensemble.rigid_members` -- the free rigid body's member loop (a batched run's kernel, compiled);
- :mod:`dirac.ensemble.chunk` -- one chunk: draw, run the scene's member loop;
- :mod:`dirac.ensemble.store` -- zarr store, per-chunk markers, atomic ``meta.json``;
- :mod:`dirac.ensemble.chunk_plan` -- the default chunk size and each chunk's members;
- :mod:`dirac.ensemble.run_record` -- ``meta.json``: what the ensemble is, which chunks are done;
- :mod:`dirac.ensemble.local_executor` -- the chunks one after the other on this machine;
- :mod:`dirac.ensemble.dask_executor` -- one dask task per chunk on a cluster;
- :mod:`dirac.ensemble.arguments` -- errors that name :func:`run_ensemble`'s arguments;
- :mod:`dirac.ensemble.engine` -- :func:`run_ensemble`: plan, run locally or on dask, resume;
- :mod:`dirac.ensemble.bench` -- the throughput measurement of ``dirac bench --ensemble``;
- :mod:`dirac.ensemble.plot` -- the flip-time figure; the data of a general ensemble's map or section;
- :mod:`dirac.ensemble.variables` -- named ensemble variables: a grid and/or random draws;
- :mod:`dirac.ensemble.general_scene` -- scenes of any other system, their reductions;
- :mod:`dirac.ensemble.general_kernel` -- the system's own step batched over members (generated);
- :mod:`dirac.ensemble.general_chunk` -- one chunk of such an ensemble;
- :mod:`dirac.ensemble.analysed_members` -- members on the Dirac flow of an analysis (velocity-linear, gauge systems);
- :mod:`dirac.ensemble.reduction_layout` -- the reductions' expressions and where the member loops put them;
- :mod:`dirac.ensemble.member_values` -- expressions of the ensemble variables at the members, members' labels;
- :mod:`dirac.ensemble.heavy_top_members` -- the heavy top's member loop (a single run's kernels, generated);
- :mod:`dirac.ensemble.kernel_lock` -- the lock around the parallel kernels.

The command lines are in :mod:`dirac.commands` (``ensemble``, ``bench_ensemble``,
``ensemble_plot``).

zarr and dask are imported only when a run needs them.
"""

from dirac.ensemble.engine import EnsembleReport, run_ensemble
from dirac.ensemble.scene import EnsembleScene, load_ensemble_scene, parse_ensemble_scene

__all__ = ["EnsembleReport", "EnsembleScene", "load_ensemble_scene", "parse_ensemble_scene", "run_ensemble"]
