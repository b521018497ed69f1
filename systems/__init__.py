"""Concrete constrained systems built on the `dirac` engine (import name ``dirac_systems``).

Each module defines a factory ``system(**options) -> dirac.Lagrangian`` whose docstring's
first line describes it, and is registered under the ``dirac.systems`` entry-point group
in ``pyproject.toml``. The engine never imports this package directly.
"""
