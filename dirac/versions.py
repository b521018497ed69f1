"""Versions of Python, dirac and the numerical libraries, for the records a run leaves.

Result files (``meta["versions"]``), ensemble stores (``meta.json``) and benchmark reports
each record which software produced them; this module is the one place that asks the
installed distributions.
"""

from __future__ import annotations

import platform
from collections.abc import Mapping, Sequence
from importlib.metadata import PackageNotFoundError, version

__all__ = ["installed_versions", "result_versions"]


def installed_versions(
    distributions: Sequence[str],
    *,
    keys: Mapping[str, str] | None = None,
    missing: str | None = "unknown",
    python: bool = True,
) -> dict[str, str]:
    """Installed version of each distribution.

    Parameters
    ----------
    distributions : sequence of str
        Distribution names as on the package index (``"dirac-mechanics"``, ``"numpy"``).
    keys : mapping, optional
        Key to record a distribution under, where it differs from its name.
    missing : str or None
        Recorded for a distribution that is not installed; ``None`` leaves it out.
    python : bool
        Record the Python version first, under ``"python"``.
    """
    keys = keys or {}
    found = {"python": platform.python_version()} if python else {}
    for name in distributions:
        try:
            found[keys.get(name, name)] = version(name)
        except PackageNotFoundError:
            if missing is not None:
                found[keys.get(name, name)] = missing
    return found


def result_versions() -> dict[str, str]:
    """The ``versions`` record of a result file's ``meta`` (docs/file_formats.md)."""
    return installed_versions(("dirac-mechanics", "numpy", "scipy", "numba", "sympy"), keys={"dirac-mechanics": "dirac"})
