"""Result files (docs/file_formats.md): ``.npz`` with ``t``, the requested outputs and ``meta``.

Files are written atomically: the data go to a temporary file in the destination's
directory, are flushed to disk, and the temporary file is renamed over the destination
(:func:`os.replace`). A failed or interrupted write therefore never leaves a half-written
file and never destroys an existing one.
"""

from __future__ import annotations

import json
import os
import tempfile
from pathlib import Path
from typing import Any, Protocol

import numpy as np

from dirac.errors import InputError

__all__ = ["write_results", "read_results"]


class RunResult(Protocol):
    """What a result file holds (a :class:`dirac.flows.Solution` is one): sample times,
    outputs by name and the run's ``meta``."""

    t: np.ndarray
    outputs: dict[str, np.ndarray]

    def meta(self) -> dict[str, object]: ...


def _json_default(value: object) -> object:
    if isinstance(value, np.generic):
        return value.item()
    if isinstance(value, np.ndarray):
        return value.tolist()
    return str(value)


def write_results(solution: RunResult, path: str | Path, extra_meta: dict[str, object] | None = None) -> Path:
    """Write ``solution`` to ``path`` atomically (docs/file_formats.md).

    Parameters
    ----------
    solution : RunResult
        A :class:`dirac.flows.Solution`, complete or partial (``complete = False`` is recorded in ``meta``).
    path
        Destination ``.npz`` file; its directory must exist.
    extra_meta
        More keys for ``meta`` (e.g. the scene file).

    Returns
    -------
    pathlib.Path
        The destination.

    Raises
    ------
    InputError
        The directory does not exist or is not writable.
    """
    destination = Path(path)
    directory = destination.parent if str(destination.parent) else Path(".")
    if not directory.is_dir():
        raise InputError(f"cannot write {str(destination)!r}: directory {str(directory)!r} does not exist")
    meta = solution.meta()
    if extra_meta:
        meta.update(extra_meta)
    arrays: dict[str, Any] = {"t": np.asarray(solution.t, dtype=float)}  # Any: np.savez(**arrays) keywords
    arrays.update({name: np.asarray(value) for name, value in solution.outputs.items()})
    arrays["meta"] = np.array(json.dumps(meta, default=_json_default, allow_nan=True))
    try:
        handle, temporary = tempfile.mkstemp(prefix=f".{destination.name}.", suffix=".tmp", dir=directory)
    except OSError as exc:
        raise InputError(f"cannot write {str(destination)!r}: {exc.strerror}") from None
    try:
        with os.fdopen(handle, "wb") as stream:
            np.savez(stream, **arrays)
            stream.flush()
            os.fsync(stream.fileno())
        os.replace(temporary, destination)
    except BaseException:
        try:
            os.unlink(temporary)
        except OSError:
            pass
        raise
    return destination


def read_results(path: str | Path) -> tuple[dict[str, np.ndarray], dict[str, object]]:
    """Read a result file: ``(arrays without meta, meta as a dict)``."""
    with np.load(path, allow_pickle=False) as data:
        arrays = {name: data[name] for name in data.files if name != "meta"}
        meta = json.loads(str(data["meta"]))
    return arrays, meta
