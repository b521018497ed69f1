"""Ensembles of rigid bodies: chunked batched flows, locally or on a dask cluster.

Modules, one job each:

- :mod:`dirac.ensemble.scene` -- ``[ensemble]`` scenes, validated (:func:`load_ensemble_scene`);
- :mod:`dirac.ensemble.distributions` -- named distributions of ``M``, ``R``, inertia;
- :mod:`dirac.ensemble.sampling` -- counter-based draws keyed by ``(seed, member)``;
- :mod:`dirac.ensemble.reductions` -- streaming per-member summaries (flip time, ...);
- :mod:`dirac.ensemble.chunk` -- one chunk: draw, advance (batched kernel), reduce;
- :mod:`dirac.ensemble.store` -- zarr store, per-chunk markers, atomic ``meta.json``;
- :mod:`dirac.ensemble.engine` -- :func:`run_ensemble`: plan, run locally or on dask, resume;
- :mod:`dirac.ensemble.bench` -- ``dirac bench --ensemble``;
- :mod:`dirac.ensemble.plot` -- the flip-time figure.

zarr and dask are imported only when a run needs them.
"""

from dirac.ensemble.engine import EnsembleReport, run_ensemble
from dirac.ensemble.scene import EnsembleScene, load_ensemble_scene, parse_ensemble_scene

__all__ = ["EnsembleReport", "EnsembleScene", "load_ensemble_scene", "parse_ensemble_scene", "run_ensemble"]
