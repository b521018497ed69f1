"""Lazy package attributes (PEP 562): import a submodule only when its name is used.

``dirac`` and ``dirac.plots`` export names whose modules pull in numba, sympy or
matplotlib; importing them on first use keeps ``dirac --help`` fast.
"""

from __future__ import annotations

from collections.abc import Callable, Mapping
from importlib import import_module
from types import ModuleType
from typing import Any

__all__ = ["lazy_exports"]


def lazy_exports(
    package: str,
    namespace: dict[str, Any],
    exports: Mapping[str, str],
    computed: Mapping[str, Callable[[], Any]] | None = None,
) -> tuple[Callable[[str], Any], Callable[[], list[str]]]:
    """``(__getattr__, __dir__)`` for ``package`` that resolve names on first use.

    Parameters
    ----------
    package
        Dotted name of the package, for the error message of an unknown attribute.
    namespace
        The package's ``globals()``; a resolved value is stored there, so the work
        happens once.
    exports
        Public name -> module that defines it (imported on first access).
    computed
        Name -> function computing its value on first access (e.g. ``__version__``
        from the package metadata, which is slow to import).

    Returns
    -------
    tuple
        ``__getattr__`` and ``__dir__`` for the package module. ``__dir__`` lists the
        package's own names and the lazy ones, not the submodules it happens to have
        imported.
    """
    computed = dict(computed or {})

    def __getattr__(name: str) -> Any:
        if name in computed:
            value = computed[name]()
        elif name in exports:
            value = getattr(import_module(exports[name]), name)
        else:
            raise AttributeError(f"module {package!r} has no attribute {name!r}")
        namespace[name] = value
        return value

    def __dir__() -> list[str]:
        own = {name for name, value in namespace.items() if not isinstance(value, ModuleType)}
        return sorted(own | set(exports) | set(computed))

    return __getattr__, __dir__
