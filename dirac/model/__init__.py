"""The symbolic input: safe expressions, the :class:`Lagrangian`, and the built-in systems."""
