"""Numerical kernels of the free rigid body (docs/conventions.md, paper Sect. IX).

Modules, one job each:

- :mod:`dirac.rigidbody.inertia` -- validation of inertia, rotation matrix, momentum;
- :mod:`dirac.rigidbody.euler_poisson` -- invariants and the Euler–Poisson vector field
  (250)–(251), plus lean scipy right-hand sides for baselines;
- :mod:`dirac.rigidbody.splitting` -- Lie–Poisson splitting methods (numba kernels; the
  composition coefficients are the rows of :mod:`dirac.compositions`);
- :mod:`dirac.rigidbody.heavy_top` -- gravity kicks composed with a free-body splitting
  step (the heavy top);
- :mod:`dirac.rigidbody.midpoint` -- the implicit midpoint rule on (250)–(251), Newton on
  ``M`` and a Cayley step for ``R``;
- :mod:`dirac.rigidbody.elliptic` -- Jacobi functions (accurate as ``m -> 1``) and Carlson's
  symmetric integrals, as numba kernels;
- :mod:`dirac.rigidbody.exact` -- the exact flow in Jacobi elliptic functions and an
  elliptic integral of the third kind;
- :mod:`dirac.rigidbody.exact_step` -- one step of that flow set up and evaluated in
  compiled code, and the heavy top's exact-free-flow + kick compositions;
- :mod:`dirac.rigidbody.closed_forms` -- the paper's elementary solutions (165), (183);
- :mod:`dirac.rigidbody.batch` -- many bodies at once with the 3-term splitting.

Heavy modules (numba, scipy) are imported only when used; importing this package is cheap.
"""
