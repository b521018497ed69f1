"""Field theories: a Lagrangian density in, its constraint analysis per spatial point out.

A layer above the analysis (docs/architecture.md): :mod:`dirac.fields.theory` holds the
input (:class:`~dirac.fields.theory.FieldTheory`), :mod:`dirac.fields.modes` turns a linear
theory into mechanical Lagrangians of its Fourier modes, :mod:`dirac.fields.analysis`
reads the engine's answers back in position space, :mod:`dirac.fields.lattice` turns any
density into the Lagrangian of a periodic lattice, :mod:`dirac.fields.files` reads the
``[field]`` table of a system file. The engine itself never knows about fields.
"""
