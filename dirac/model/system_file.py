"""System files: a :class:`~dirac.model.lagrangian.Lagrangian` read from TOML or from Python.

A TOML system file has one ``[system]`` table (``name``, ``coordinates``, ``lagrangian``,
optional ``parameters``, ``constraints``, ``description``, ``forces`` (generalized
forces by coordinate); docs/file_formats.md; the name
``t`` is the time unless a coordinate is called ``t``); a ``.py``
system file defines ``system()`` returning a Lagrangian. Scene files reuse
:func:`lagrangian_from_table` for a system written inline.
"""

from __future__ import annotations

import tomllib
from pathlib import Path

from dirac.errors import DiracError, InputError
from dirac.model.lagrangian import Lagrangian
from dirac.validate import check_known_keys

__all__ = ["read_system_file", "lagrangian_from_table"]

_SYSTEM_KEYS = {"name", "coordinates", "parameters", "lagrangian", "constraints", "description", "forces"}


def read_system_file(path: str | Path) -> Lagrangian:
    """Read a system file: TOML as in docs/file_formats.md, or a ``.py`` file defining ``system()``.

    Unknown keys in ``[system]`` are errors that name them and suggest the closest known keys.

    Raises
    ------
    InputError
        If the file is missing, malformed, lacks a required key, or describes an invalid
        Lagrangian; the message names the file and the item.
    """
    path = Path(path)
    if not path.is_file():
        raise InputError(f"system file {str(path)!r} does not exist")
    if path.suffix == ".py":
        return _read_python_system(path)
    if path.suffix != ".toml":
        raise InputError(f"system file {str(path)!r} must end in .toml or .py")
    try:
        data = tomllib.loads(path.read_text(encoding="utf-8"))
    except (tomllib.TOMLDecodeError, UnicodeDecodeError) as exc:
        raise InputError(f"system file {str(path)!r} is not valid TOML: {exc}") from None
    if "system" not in data and "field" in data:
        raise InputError(
            f"system file {str(path)!r} has a [field] table: it is a field theory, not a mechanical system; read it "
            "with dirac.load_field_theory(path) and analyse it with dirac.analyze, or run dirac analyze FILE"
        )
    return lagrangian_from_table(data.get("system"), source=str(path))


def lagrangian_from_table(table: object, source: str = "system table") -> Lagrangian:
    """Build a :class:`Lagrangian` from the ``[system]`` table of a system file."""
    if not isinstance(table, dict):
        raise InputError(f"{source}: missing [system] table (with name, coordinates and lagrangian; see docs/file_formats.md)")
    check_known_keys(table, _SYSTEM_KEYS, "[system]", source)
    for key in ("name", "coordinates", "lagrangian"):
        if key not in table:
            raise InputError(f"{source}: [system] lacks the required key {key!r}")
    name, coordinates, lagrangian = table["name"], table["coordinates"], table["lagrangian"]
    constraints = table.get("constraints", [])
    parameters = table.get("parameters", {})
    if not isinstance(name, str):
        raise InputError(f"{source}: [system] name must be a string")
    if not isinstance(coordinates, list) or not all(isinstance(c, str) for c in coordinates):
        raise InputError(f"{source}: [system] coordinates must be a list of names, e.g. [\"x\", \"y\"]")
    if not isinstance(lagrangian, str):
        raise InputError(f"{source}: [system] lagrangian must be a string expression")
    if not isinstance(constraints, list) or not all(isinstance(c, str) for c in constraints):
        raise InputError(f"{source}: [system] constraints must be a list of string expressions")
    if not isinstance(parameters, dict):
        raise InputError(f"{source}: [system] parameters must be a table, e.g. {{ m = 1.0 }}")
    forces = table.get("forces", {})
    if not isinstance(forces, dict):
        raise InputError(f"{source}: [system] forces must be a table, e.g. {{ x = \"-c*x_dot\" }}")
    try:
        return Lagrangian.from_strings(
            name, coordinates, lagrangian, constraints, parameters, str(table.get("description", "")), forces=forces
        )
    except InputError as exc:
        raise InputError(f"{source}: {exc}") from None


def _read_python_system(path: Path) -> Lagrangian:
    import importlib.util

    spec = importlib.util.spec_from_file_location(f"_dirac_user_system_{abs(hash(path))}", path)
    if spec is None or spec.loader is None:
        raise InputError(f"system file {str(path)!r} cannot be imported")
    module = importlib.util.module_from_spec(spec)
    try:
        spec.loader.exec_module(module)
    except Exception as exc:  # the user's own code failed: report it, do not crash
        raise InputError(f"system file {str(path)!r} failed to import: {type(exc).__name__}: {exc}") from exc
    factory = getattr(module, "system", None)
    if not callable(factory):
        raise InputError(f"system file {str(path)!r} must define a function system() returning a dirac.Lagrangian")
    try:
        result = factory()
    except DiracError:
        raise
    except Exception as exc:  # the user's own code failed: report it, do not crash
        raise InputError(f"system() in {str(path)!r} failed: {type(exc).__name__}: {exc}") from exc
    if not isinstance(result, Lagrangian):
        raise InputError(f"system() in {str(path)!r} returned {type(result).__name__}, not a dirac.Lagrangian")
    return result
