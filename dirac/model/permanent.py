"""The objects of sympy's import kept out of the garbage collector's way.

``import sympy`` creates a few hundred thousand objects (modules, classes, functions,
caches) that live as long as the process. Python's cyclic garbage collector traverses
every tracked object at each full collection, and the interpreter runs full collections
as it shuts down: in a fresh process that built a model, the shutdown alone cost 0.1-0.2 s
of CPU (about a sixth of a whole ``t_end = 100`` run of a pendulum in its angle, and as
much as the run itself), almost all of it walking sympy's objects, which are never
garbage. :func:`gc.freeze` moves every object tracked at the time into a permanent
generation that the collector no longer visits (Python documentation, ``gc.freeze``;
objects created later are collected as before), which takes that cost away.

:func:`freeze_imports` does this once per process, right after the model layer has
imported sympy (:mod:`dirac.model.lagrangian`). The objects frozen are those alive at that
moment: the interpreter's, numpy's and sympy's modules and whatever the program made
before; a cycle among them that became garbage later would stay in memory until
:func:`gc.unfreeze`. ``DIRAC_GC_FREEZE=0`` in the environment leaves the collector alone.
"""

from __future__ import annotations

import gc
import os

__all__ = ["freeze_imports", "FREEZE_VARIABLE"]

#: the environment variable that turns the freeze off (``0``)
FREEZE_VARIABLE = "DIRAC_GC_FREEZE"

_frozen = False


def freeze_imports() -> bool:
    """Move the objects alive now into the collector's permanent generation, once per
    process (see the module docstring); whether this call froze them."""
    global _frozen
    if _frozen or os.environ.get(FREEZE_VARIABLE, "1").strip() == "0":
        return False
    _frozen = True
    gc.freeze()
    return True
