"""Finding systems: built-in names (entry points) and system files.

Built-in systems are factories ``system(**options) -> Lagrangian`` registered under the
entry-point group ``dirac.systems`` (see ``pyproject.toml``). The engine discovers them
through package metadata and never imports the ``systems/`` folder directly, so other
packages can register systems of their own the same way.
"""

from __future__ import annotations

import inspect
from collections.abc import Callable
from importlib.metadata import EntryPoint, entry_points
from pathlib import Path

from dirac.model.lagrangian import Lagrangian
from dirac.model.system_file import read_system_file
from dirac.validate import unknown_name_error

__all__ = ["load_system", "builtin_systems", "ENTRY_POINT_GROUP"]

ENTRY_POINT_GROUP = "dirac.systems"


def _entry_points() -> dict[str, EntryPoint]:
    return {ep.name: ep for ep in entry_points(group=ENTRY_POINT_GROUP)}


def builtin_systems() -> dict[str, str]:
    """Built-in system name -> one-line description (first docstring line of its factory)."""
    result: dict[str, str] = {}
    for name, ep in sorted(_entry_points().items()):
        factory = ep.load()
        doc = inspect.getdoc(factory) or ""
        result[name] = doc.splitlines()[0] if doc else ""
    return result


def _factory(name: str) -> Callable[..., Lagrangian]:
    eps = _entry_points()
    if name not in eps:
        raise unknown_name_error("system", name, eps, hint="give a built-in name or a path to a .toml or .py system file")
    return eps[name].load()


def load_system(name_or_path: str | Path, **options: object) -> Lagrangian:
    """Load a built-in system by name, or a system file by path.

    Parameters
    ----------
    name_or_path
        A built-in name (``dirac systems`` lists them) or a path to a ``.toml`` system
        file (docs/file_formats.md) or a ``.py`` file defining ``system()``.
    **options
        Keywords naming a parameter fix it to a number (:meth:`Lagrangian.fix`); the
        parameters not named stay symbolic. Other keywords that the system's factory
        accepts (structural options such as particle masses and positions) go to the
        factory. Factories therefore never take parameter values as arguments.

    Examples
    --------
    >>> import dirac
    >>> system = dirac.load_system("pendulum", l=2.0)
    """
    text = str(name_or_path)
    if isinstance(name_or_path, Path) or text.endswith((".toml", ".py")) or "/" in text:
        lagrangian = read_system_file(text)
        factory_options: dict[str, object] = {}
        fixed = dict(options)
    else:
        factory = _factory(text)
        accepted = inspect.signature(factory).parameters
        takes_any = any(p.kind is inspect.Parameter.VAR_KEYWORD for p in accepted.values())
        factory_options = {k: v for k, v in options.items() if k in accepted or takes_any}
        fixed = {k: v for k, v in options.items() if k not in factory_options}
        lagrangian = factory(**factory_options)
        if not isinstance(lagrangian, Lagrangian):
            raise TypeError(f"built-in system {text!r} returned {type(lagrangian).__name__}, not a Lagrangian")
    return lagrangian.fix(**fixed) if fixed else lagrangian  # type: ignore[arg-type]  # user options; fix() raises InputError for a non-number
