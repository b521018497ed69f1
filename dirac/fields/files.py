"""The ``[field]`` table of a system file (docs/field_theories.md).

```toml
[field]
name = "maxwell"
space = ["x", "y", "z"]
fields = ["A0", "A1", "A2", "A3"]
density = "((A1_t - A0_x)**2 + (A2_t - A0_y)**2 + (A3_t - A0_z)**2)/2 - ..."
parameters = { m = 1.0 }       # optional
constraints = ["..."]          # optional: holonomic, at every point
description = "..."            # optional
```
"""

from __future__ import annotations

import tomllib
from pathlib import Path

from dirac.errors import InputError
from dirac.fields.theory import FieldTheory
from dirac.validate import check_known_keys

__all__ = ["is_field_file", "load_field_theory", "theory_from_table"]

_FIELD_KEYS = {"name", "space", "fields", "density", "parameters", "constraints", "description"}


def _read(path: Path) -> dict:
    try:
        return tomllib.loads(path.read_text(encoding="utf-8"))
    except (tomllib.TOMLDecodeError, UnicodeDecodeError) as exc:
        raise InputError(f"system file {str(path)!r} is not valid TOML: {exc}") from None


def is_field_file(name_or_path: str | Path) -> bool:
    """True for an existing ``.toml`` file with a ``[field]`` table."""
    path = Path(name_or_path)
    if path.suffix != ".toml" or not path.is_file():
        return False
    try:
        return "field" in tomllib.loads(path.read_text(encoding="utf-8"))
    except (tomllib.TOMLDecodeError, UnicodeDecodeError, OSError):
        return False


def load_field_theory(path: str | Path, **parameters: float) -> FieldTheory:
    """Read the ``[field]`` table of a system file; ``parameters`` fix some parameters to numbers.

    Raises
    ------
    InputError
        For a missing file or table, an unknown key (with the closest known keys) or an
        invalid theory; the message names the file.
    """
    path = Path(path)
    if not path.is_file():
        raise InputError(f"system file {str(path)!r} does not exist")
    theory = theory_from_table(_read(path).get("field"), source=str(path))
    return theory.fix(**parameters) if parameters else theory


def theory_from_table(table: object, source: str = "field table") -> FieldTheory:
    """A :class:`FieldTheory` from a ``[field]`` table."""
    if not isinstance(table, dict):
        raise InputError(f"{source}: missing [field] table (with name, space, fields and density)")
    check_known_keys(table, _FIELD_KEYS, "[field]", source)
    for key in ("name", "fields", "density"):
        if key not in table:
            raise InputError(f"{source}: [field] lacks the required key {key!r}")
    try:
        return FieldTheory.from_strings(
            table["name"], table.get("space", []), table["fields"], table["density"],
            parameters=table.get("parameters", {}), constraints=table.get("constraints", []),
            description=str(table.get("description", "")),
        )
    except InputError as exc:
        raise InputError(f"{source}: {exc}") from None
