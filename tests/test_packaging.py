"""The packaging lists every package, and the CLI dispatcher's contract holds."""

from __future__ import annotations

import tomllib
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]


def test_every_package_folder_is_listed_in_pyproject():
    config = tomllib.loads((ROOT / "pyproject.toml").read_text())
    listed = set(config["tool"]["setuptools"]["packages"])
    found = {
        ".".join(p.parent.relative_to(ROOT).parts) for p in (ROOT / "dirac").rglob("__init__.py")
    } | {"dirac_systems"}
    assert found == listed


def test_every_builtin_entry_point_has_a_module_and_description():
    from dirac.model.systems import builtin_systems

    systems = builtin_systems()
    assert "pendulum" in systems
    for name, description in systems.items():
        assert description, f"built-in system {name!r} has no one-line description"


def test_distribution_name_is_not_dirac():
    config = tomllib.loads((ROOT / "pyproject.toml").read_text())
    assert config["project"]["name"] == "dirac-mechanics"
    assert config["project"]["scripts"]["dirac"] == "dirac.cli:main"


def test_the_typed_marker_is_shipped():
    config = tomllib.loads((ROOT / "pyproject.toml").read_text())
    assert (ROOT / "dirac" / "py.typed").is_file()
    assert "py.typed" in config["tool"]["setuptools"]["package-data"]["dirac"]
