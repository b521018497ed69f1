"""Pictures of general ensembles: a two-dimensional grid's reduction as a map, a Poincaré section as a scatter.

Both draw arrays they are handed (read from an ensemble's store by
:func:`dirac.ensemble.plot.plot_ensemble`); matplotlib is imported only here, when drawing.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np

from dirac.errors import InputError
from dirac.plots.canvas import new_figure, save_figure

__all__ = ["draw_grid_map", "draw_section"]


def draw_grid_map(values: np.ndarray, x: tuple[str, float, float], y: tuple[str, float, float], label: str,
                  path: str | Path, log: bool = True, title: str = "") -> Path:
    """``values`` (shape ``(nx, ny)``, C order over the grid variables ``x`` then ``y``) as a map.

    ``x`` and ``y`` are ``(name, lo, hi)``. Colour = the value on a logarithmic scale
    (``log``; values <= 0 are drawn as missing), NaN (never happened, or a failed member)
    in white. Heyl's flip-time fractal of the double pendulum is this map of the first flip time.
    """
    from matplotlib.colors import LogNorm

    finite = values[np.isfinite(values)]
    if finite.size == 0:
        raise InputError(f"{label}: no member has a finite value; nothing to draw")
    fig = new_figure(6.0, 5.0)
    ax = fig.add_subplot(1, 1, 1)
    shown = np.where(values > 0, values, np.nan) if log else values
    positive = shown[np.isfinite(shown)]
    norm = LogNorm(vmin=float(positive.min()), vmax=float(positive.max())) if log and positive.size else None
    image = ax.imshow(shown.T, origin="lower", extent=(x[1], x[2], y[1], y[2]), aspect="auto",
                      cmap="viridis", norm=norm, interpolation="nearest")
    ax.set_facecolor("white")
    ax.set_xlabel(x[0])
    ax.set_ylabel(y[0])
    missing = int(np.sum(~np.isfinite(values)))
    ax.set_title(title or f"{label}: {missing} of {values.size} members without one (white)")
    fig.colorbar(image, ax=ax, label=label + (" (log scale)" if log else ""))
    fig.tight_layout()
    return save_figure(fig, path, dpi=110)


def draw_section(x: np.ndarray, y: np.ndarray, xlabel: str, ylabel: str, path: str | Path, title: str = "") -> Path:
    """The points ``(x, y)`` of a Poincaré section (NaN points, i.e. missing crossings, left out)."""
    keep = np.isfinite(x) & np.isfinite(y)
    if not np.any(keep):
        raise InputError("the Poincaré section has no points (no member crossed the section by t_end)")
    fig = new_figure(6.0, 5.0)
    ax = fig.add_subplot(1, 1, 1)
    ax.plot(x[keep], y[keep], ".", ms=1.5, color="tab:blue", alpha=0.6)
    ax.set_xlabel(xlabel)
    ax.set_ylabel(ylabel)
    ax.set_title(title or f"Poincaré section: {int(keep.sum())} points")
    fig.tight_layout()
    return save_figure(fig, path, dpi=110)
