"""Pictures of the motion (matplotlib, headless): each kind of system with its own conserved quantities.

Modules, one job each:

- :mod:`dirac.plots.canvas` -- figures on the Agg canvas (no pyplot, no display), written in
  any format matplotlib writes (png, pdf, svg, ...);
- :mod:`dirac.plots.geometry` -- spheres, ellipsoids, polhode curves (numpy only);
- :mod:`dirac.plots.rigid_body` -- the free rigid body: polhode on the energy ellipsoid and
  the ``|M|`` sphere, body-axis tips on the unit sphere, errors of ``E``, ``|M|^2``,
  ``m = R M`` and ``R^T R``; the heavy top: body axes, ``M(t)``, errors of the total
  energy, of ``m_z`` and of ``R^T R`` (no polhode: gravity moves ``M`` off it);
- :mod:`dirac.plots.constrained` -- a general constrained system: path, coordinates,
  energy error and the residual of every constraint;
- :mod:`dirac.plots.results` -- ``dirac.plot(solution)`` (a Figure) and the one call that
  draws a run's result to a file (what ``dirac run --plot`` and ``dirac demo --plot`` use).

matplotlib is imported only when a figure is drawn (``pip install 'dirac-mechanics[plot]'``).

Examples
--------
>>> import numpy as np
>>> from dirac.plots import rigid_body_figure, save_png
>>> t = np.linspace(0.0, 1.0, 3)
>>> M = np.tile([0.0, 0.0, 1.0], (3, 1))            # steady rotation about axis 3
>>> fig = rigid_body_figure(t, M, None, [2.0, 1.5, 1.0])
>>> len(fig.axes)                                  # polhode, M(t), errors (no R given)
3
>>> save_png(fig, "steady.png")                     # doctest: +SKIP
"""

from __future__ import annotations as _annotations

from dirac.lazy_exports import lazy_exports as _lazy_exports

__all__ = [
    "plot",
    "plot_result",
    "result_figure",
    "load_result",
    "rigid_body_figure",
    "constrained_figure",
    "conserved_quantity_errors",
    "heavy_top_figure",
    "heavy_top_errors",
    "save_figure",
    "plot_formats",
    "save_png",
]

_LAZY: dict[str, str] = {
    "plot": "dirac.plots.results",
    "plot_result": "dirac.plots.results",
    "result_figure": "dirac.plots.results",
    "load_result": "dirac.plots.results",
    "rigid_body_figure": "dirac.plots.rigid_body",
    "conserved_quantity_errors": "dirac.plots.rigid_body",
    "constrained_figure": "dirac.plots.constrained",
    "heavy_top_figure": "dirac.plots.rigid_body",
    "heavy_top_errors": "dirac.plots.rigid_body",
    "save_figure": "dirac.plots.canvas",
    "plot_formats": "dirac.plots.canvas",
    "save_png": "dirac.plots.canvas",
}


__getattr__, __dir__ = _lazy_exports("dirac.plots", globals(), _LAZY)
