"""Draw a run's result -- a :class:`dirac.flows.Solution` or a result file -- as one PNG.

This is what ``dirac run SCENE --plot FILE.png`` and ``dirac demo --plot FILE.png`` call.
The picture is chosen from the outputs present (docs/file_formats.md): ``M`` (and ``R``) give
the rigid-body picture (:func:`dirac.plots.rigid_body.rigid_body_figure`), ``q`` the
constrained-system picture (:func:`dirac.plots.constrained.constrained_figure`).
"""

from __future__ import annotations

import json
from collections.abc import Mapping, Sequence
from pathlib import Path
from typing import Any

import numpy as np

from dirac.errors import InputError
from dirac.plots.canvas import check_png_path, save_png

__all__ = ["result_figure", "plot_result", "load_result"]


def load_result(path: str | Path) -> dict[str, Any]:
    """Read a result file (``.npz``, docs/file_formats.md) into a dict; ``meta`` becomes a dict."""
    target = Path(path)
    if not target.is_file():
        raise InputError(f"result file {str(path)!r} does not exist: give the --out file of 'dirac run'")
    with np.load(target, allow_pickle=False) as data:
        return {name: data[name] for name in data.files}


def _has(result: Any, name: str) -> bool:
    try:
        return name in result
    except TypeError:
        return hasattr(result, name)


def _get(result: Any, name: str) -> Any:
    return result[name] if isinstance(result, Mapping) or hasattr(result, "__getitem__") else getattr(result, name)


def _meta(result: Any) -> dict[str, Any]:
    meta = getattr(result, "meta", None)
    if callable(meta):
        meta = meta()
    if meta is None and isinstance(result, Mapping):
        meta = result.get("meta")
    if isinstance(meta, np.ndarray):
        meta = meta.item() if meta.shape == () else str(meta)
    if isinstance(meta, (str, bytes)):
        try:
            meta = json.loads(meta)
        except json.JSONDecodeError:
            meta = {}
    return dict(meta) if isinstance(meta, Mapping) else {}


def _first_body(array: np.ndarray, single_ndim: int) -> np.ndarray:
    """Drop a batch axis (samples, batch, ...) by keeping the first state."""
    array = np.asarray(array, dtype=float)
    return array[:, 0] if array.ndim == single_ndim + 1 else array


def _title(meta: Mapping[str, Any], default: str) -> str:
    parts = [str(meta.get("system", default))]
    if meta.get("method"):
        method = str(meta["method"])
        if meta.get("order"):
            method += f" (order {meta['order']})"
        parts.append(f"method {method}")
    if meta.get("dt"):
        parts.append(f"dt = {float(meta['dt']):.3g} s")
    if meta.get("steps"):
        parts.append(f"{int(meta['steps'])} steps")
    if meta.get("complete") is False:
        parts.append("INCOMPLETE run")
    return ",  ".join(parts)


def result_figure(result: Any, coordinates: Sequence[str] | None = None) -> Any:
    """The picture of one run (see the module docstring); returns a matplotlib Figure.

    Parameters
    ----------
    result : dirac.flows.Solution or mapping
        Anything with the outputs of a result file by name (``t`` and ``M``/``R`` or
        ``q``/``energy``/``constraint_residual``) and a ``meta`` record (dict, JSON
        string, or a ``meta()`` method). A batched result is drawn for its first state.
    coordinates : sequence of str, optional
        Names of the coordinates ``q`` (default: ``meta["coordinates"]``, else ``q_1 …``).

    Raises
    ------
    dirac.errors.InputError
        If the result has neither ``M`` nor ``q``, or the rigid body's inertia is unknown.
    """
    if not _has(result, "t"):
        raise InputError("the result has no sample times 't'; nothing to draw")
    t = np.asarray(_get(result, "t"), dtype=float)
    meta = _meta(result)
    if _has(result, "M"):
        from dirac.plots.rigid_body import rigid_body_figure

        inertia = (meta.get("parameters") or {}).get("inertia")
        if inertia is None:
            raise InputError("the result's meta has no parameters.inertia: cannot draw the energy ellipsoid")
        M = _first_body(_get(result, "M"), 2)
        R = _first_body(_get(result, "R"), 3) if _has(result, "R") else None
        return rigid_body_figure(t, M, R, inertia, title=_title(meta, "rigid body"))
    if _has(result, "q"):
        from dirac.plots.constrained import constrained_figure

        q = _first_body(_get(result, "q"), 2)
        energy = _first_body(_get(result, "energy"), 1) if _has(result, "energy") else None
        residual = (
            _first_body(_get(result, "constraint_residual"), 1) if _has(result, "constraint_residual") else None
        )
        names = list(coordinates) if coordinates is not None else meta.get("coordinates")
        return constrained_figure(t, q, energy=energy, constraint_residual=residual, names=names,
                                  title=_title(meta, "constrained system"))
    raise InputError("the result has neither 'M' (rigid body) nor 'q' (constrained system) among its outputs: "
                     "add \"M\" or \"q\" to outputs in the scene's [run] table to draw it")


def plot_result(result: Any, path: str | Path, coordinates: Sequence[str] | None = None) -> Path:
    """Draw ``result`` (see :func:`result_figure`) and write it to the PNG file ``path``.

    ``path`` is checked before any drawing, so a bad name fails fast.
    """
    target = check_png_path(path)
    fig = result_figure(result, coordinates)
    return save_png(fig, target)
