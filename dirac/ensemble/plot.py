"""Plot the flip times of an ensemble (``python -m dirac.commands.ensemble_plot DIR --out FILE.png``).

Left: the distribution of the members' first flip times (``flip_time`` reduction).
Right, when the store also holds ``initial_state`` and every member shares one inertia:
each member's flip time against the separatrix prediction

    t_flip = ln(c / |u_0|) / lambda,     lambda = |M| sqrt(p q),
    p = 1/I_a - 1/I_b,  q = 1/I_b - 1/I_c,  c = 4 |M| sqrt(q / (p + q))

(``I_a < I_b < I_c``): ``u`` is the unstable coordinate of the Euler equations (250)
linearised at ``M = |M| e_b`` (:func:`unstable_coordinate`); it grows like
``e^{lambda t}`` from ``u_0``, and on the separatrix solution ``M_b = -|M| tanh(lambda t)``,
``M_a, M_c ~ sech(lambda t)`` it behaves as ``c e^{lambda (t - t_flip)}`` for
``t -> -infinity``, ``t_flip`` being the crossing of ``M_b = 0``. The prediction is
exact as ``|u_0| / |M| -> 0``.
"""

from __future__ import annotations

import json
from pathlib import Path
from typing import TYPE_CHECKING

import numpy as np

from dirac.errors import InputError, warn

if TYPE_CHECKING:
    import zarr

__all__ = ["unstable_coordinate", "predicted_flip_time", "plot_flip_times"]


def unstable_coordinate(M: np.ndarray, inertia: np.ndarray) -> np.ndarray:
    """The unstable coordinate ``u`` of ``M`` near ``+|M| e_b`` (``b`` the intermediate axis).

    With ``x = M_a``, ``z = M_c`` (small; ``a, c`` the axes of the smallest and largest
    moments), (250) linearises to ``x' = -s |M| q z``, ``z' = -s |M| p x`` with ``s = +1``
    if ``(a, b, c)`` is a cyclic order of the axes, ``-1`` otherwise (``p, q`` of the
    module docstring); ``u = x - s sqrt(q / p) z`` obeys ``u' = lambda u``.
    """
    inertia = np.asarray(inertia, dtype=float)
    a, b, c = (int(i) for i in np.argsort(inertia, kind="stable"))
    s = 1.0 if (b - a) % 3 == 1 else -1.0
    p, q = _rates(inertia)
    return M[..., a] - s * np.sqrt(q / p) * M[..., c]


def _rates(inertia: np.ndarray) -> tuple[float, float]:
    small, middle, large = np.sort(np.asarray(inertia, dtype=float))
    return 1 / small - 1 / middle, 1 / middle - 1 / large


def predicted_flip_time(M0: np.ndarray, inertia: np.ndarray) -> np.ndarray:
    """``ln(c / |u_0|) / lambda`` (module docstring), exact as ``|u_0| / |M| -> 0``."""
    norm = np.linalg.norm(M0, axis=-1)
    p, q = _rates(inertia)
    lam = norm * np.sqrt(p * q)
    c = 4 * norm * np.sqrt(q / (p + q))
    return np.log(c / np.abs(unstable_coordinate(M0, inertia))) / lam


def _read_array(group: zarr.Group, name: str) -> np.ndarray:
    """The whole array ``name`` of the results group ``data.zarr``, read into memory."""
    import zarr

    array = group[name]
    if not isinstance(array, zarr.Array):
        raise InputError(f"{name} in the ensemble results is a zarr group, not an array")
    return np.asarray(array[:])


def plot_flip_times(out: str | Path, image: str | Path) -> dict[str, float]:
    """Draw the flip-time figure of the ensemble in ``out`` into ``image``.

    Returns
    -------
    dict
        ``members``, ``flipped`` and the median flip time; with initial states also
        ``max_deviation``, the largest ``|t_flip - prediction|``.
    """
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    import zarr

    try:
        meta = json.loads((Path(out) / "meta.json").read_text())
        group = zarr.open_group(str(Path(out) / "data.zarr"), mode="r")
    except (OSError, ValueError) as exc:
        raise InputError(f"{out} holds no ensemble results ({exc}); run 'dirac ensemble SCENE --out {out}' first") from None
    if not meta.get("complete"):
        warn(f"{out}: the ensemble is not complete ({meta.get('chunks_complete')} of {meta.get('chunks_total')} chunks); plotting the finished members")
    if "flip_time" not in group:
        raise InputError(f"{out} has no flip_time array; add \"flip_time\" to [ensemble] reductions and rerun")
    flip = _read_array(group, "flip_time")
    t_end = float(meta["scene"]["t_end"])
    summary = {"members": int(flip.size), "flipped": int(np.isfinite(flip).sum()), "median": float(np.nanmedian(flip))}
    inertia = _read_array(group, "inertia") if "inertia" in group else None
    shared_inertia = inertia[0] if inertia is not None and np.all(inertia == inertia[0]) else None
    panels = 2 if shared_inertia is not None else 1
    fig, axes = plt.subplots(1, panels, figsize=(5.2 * panels, 4.0), squeeze=False)
    ax = axes[0, 0]
    if not np.isfinite(flip).any():
        raise InputError(f"{out}: no member flipped by t_end = {t_end:g}; nothing to plot (raise t_end)")
    ax.hist(flip[np.isfinite(flip)], bins=80, color="tab:blue", alpha=0.85)
    ax.set_xlabel("time of the first flip of the intermediate axis")
    ax.set_ylabel("members")
    ax.set_title(f"{summary['flipped']} of {summary['members']} members flip by t = {t_end:g}")
    if shared_inertia is not None:
        M0 = _read_array(group, "initial_M")
        predicted = predicted_flip_time(M0, shared_inertia)
        ok = np.isfinite(flip)
        summary["max_deviation"] = float(np.max(np.abs(flip[ok] - predicted[ok])))
        ax = axes[0, 1]
        ax.plot(predicted[ok], flip[ok], ".", ms=2, alpha=0.4, color="tab:blue", label="members")
        lo, hi = float(np.min(predicted[ok])), float(np.max(predicted[ok]))
        ax.plot([lo, hi], [lo, hi], "k-", lw=1, label=r"$t = \ln(c/|u_0|)/\lambda$")
        ax.set_xlabel(r"separatrix prediction $\ln(c/|u_0|)/\lambda$")
        ax.set_ylabel("flip time")
        ax.set_title(f"max deviation {summary['max_deviation']:.2g}")
        ax.legend(loc="upper left")
    fig.tight_layout()
    fig.savefig(image, dpi=120)
    plt.close(fig)
    return summary



def _open_results(out: str | Path) -> tuple[dict, zarr.Group]:
    import zarr

    try:
        meta = json.loads((Path(out) / "meta.json").read_text())
        group = zarr.open_group(str(Path(out) / "data.zarr"), mode="r")
    except (OSError, ValueError) as exc:
        raise InputError(f"{out} holds no ensemble results ({exc}); run 'dirac ensemble SCENE --out {out}' first") from None
    if not meta.get("complete"):
        warn(f"{out}: the ensemble is not complete ({meta.get('chunks_complete')} of {meta.get('chunks_total')} chunks); "
             "unfinished members are missing")
    return meta, group


def picture_data(out: str | Path, array: str | None = None, x: str | None = None, y: str | None = None) -> dict:
    """What the picture of a general ensemble in ``out`` shows, read from its store.

    A Poincaré section (a ``poincare`` reduction, or ``array`` naming one) gives
    ``{"kind": "section", "x": ..., "y": ..., "xlabel", "ylabel"}``: the section points of
    every member, ``x`` and ``y`` a coordinate or a momentum ``p_<q>`` (default the first
    coordinate and its momentum). Otherwise a two-dimensional grid gives ``{"kind": "map",
    "values": (n1, n2), "x": (name, lo, hi), "y": (name, lo, hi), "label"}`` of ``array``
    (default the first scalar reduction: ``first_crossing``, ``max``, ``min``, ...).

    Raises
    ------
    InputError
        No results, an unknown array or coordinate, or a grid that is not two-dimensional.
    """
    meta, group = _open_results(out)
    scene = meta.get("scene", {})
    if "reductions" not in scene or not isinstance(scene["reductions"], list) or "variables" not in scene:
        raise InputError(f"{out} holds a rigid-body ensemble: draw it with 'python -m dirac.commands.ensemble_plot'")
    reductions = scene["reductions"]
    coordinates = _coordinates(scene)
    poincare = [r["name"] for r in reductions if r["kind"] == "poincare"]
    scalar = [r["name"] for r in reductions if r["kind"] in ("first_crossing", "max", "min", "energy_error",
                                                              "constraint_error")]
    if array is None:
        array = poincare[0] if poincare and not scalar else (scalar[0] if scalar else None)
        if array is None:
            raise InputError(f"{out} has no reduction to draw (first_crossing, max, min, poincare, ...)")
    if array in poincare and scene.get("heavy_top"):
        return _top_section(group, array, x, y)
    if array in poincare:
        names = [*coordinates, *(f"p_{c}" for c in coordinates)]
        x = x or coordinates[0]
        y = y or f"p_{coordinates[0]}"
        points = {}
        for axis, name in (("x", x), ("y", y)):
            if name not in names:
                from dirac.validate import unknown_name_error

                raise unknown_name_error("coordinate", name, names, f"--{axis}")
            stored = "p" if name.startswith("p_") and name[2:] in coordinates else "q"
            column = coordinates.index(name[2:] if stored == "p" else name)
            points[axis] = _read_array(group, f"{array}_{stored}")[..., column].ravel()
        return {"kind": "section", "x": points["x"], "y": points["y"], "xlabel": x, "ylabel": y,
                "title": f"Poincaré section {array!r}: {int(np.isfinite(points['x']).sum())} points"}
    if array not in scalar:
        raise InputError(f"{out} has no scalar reduction {array!r}; it has {', '.join(scalar + poincare) or 'none'}")
    grid = scene["variables"]["grid"]
    if len(grid) != 2 or scene["variables"]["draws"] != 1 or scene["variables"]["random"]:
        raise InputError(f"a map needs a two-dimensional grid (and no random draws); {out} has grid variables "
                         f"{', '.join(grid) or 'none'}")
    # meta.json lists the grid's variables sorted by name; the members are numbered in the
    # scene's order (C order, its last variable fastest), which "order" keeps when it is not
    # alphabetical. A store written before "order" existed: the variable that changes between
    # members 0 and 1 goes last (when they are computed)
    listed = scene["variables"].get("order", {}).get("grid")
    (xname, (xlo, xhi, nx)), (yname, (ylo, yhi, ny)) = ((name, grid[name]) for name in listed) if listed else grid.items()
    first = _read_array(group, xname)
    if not listed and first.size > 1 and bool(np.all(np.isfinite(first[:2]))) and first[0] != first[1]:
        (xname, xlo, xhi, nx), (yname, ylo, yhi, ny) = (yname, ylo, yhi, ny), (xname, xlo, xhi, nx)
    values = _read_array(group, array).reshape(int(nx), int(ny))
    return {"kind": "map", "values": values, "x": (xname, float(xlo), float(xhi)), "y": (yname, float(ylo), float(yhi)),
            "label": array}


def _top_section(group: zarr.Group, array: str, x: str | None, y: str | None) -> dict:
    """A heavy top's Poincaré section (:func:`picture_data`): axes among ``M_1 .. M_3`` (the
    stored ``<array>_M``) and ``gamma_1 .. gamma_3`` (the third row of ``<array>_R``);
    default ``M_1`` against ``M_2``."""
    columns = {**{f"M_{i}": ("M", i - 1) for i in (1, 2, 3)}, **{f"gamma_{i}": ("R", i - 1) for i in (1, 2, 3)}}
    x, y = x or "M_1", y or "M_2"
    points = {}
    for axis, name in (("x", x), ("y", y)):
        if name not in columns:
            from dirac.validate import unknown_name_error

            raise unknown_name_error("quantity", name, columns, f"--{axis} of a heavy top's section")
        stored, k = columns[name]
        values = _read_array(group, f"{array}_{stored}")
        points[axis] = (values[..., k] if stored == "M" else values[..., 2, k]).ravel()
    return {"kind": "section", "x": points["x"], "y": points["y"], "xlabel": x, "ylabel": y,
            "title": f"Poincaré section {array!r}: {int(np.isfinite(points['x']).sum())} points"}


def _coordinates(scene: dict) -> list[str]:
    return [str(name) for name in scene["coordinates"]]
