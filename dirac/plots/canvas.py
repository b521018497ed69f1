"""Headless figures: matplotlib's object API on the Agg canvas, never pyplot.

No global state is touched (no ``pyplot``, no backend switch), so drawing works on a
machine without a display and inside programs that use matplotlib themselves.
matplotlib is imported only when a figure is made: it is an optional dependency
(``pip install 'dirac-mechanics[plot]'``).
"""

from __future__ import annotations

from pathlib import Path
from typing import Any

from dirac.errors import InputError

__all__ = ["new_figure", "plot_formats", "check_plot_path", "save_figure", "save_png", "check_png_path"]


def _require_matplotlib() -> None:
    try:
        import matplotlib  # noqa: F401 -- imported only to check that it is installed
    except ModuleNotFoundError as exc:  # pragma: no cover - matplotlib is in the test extra
        raise InputError(
            "drawing needs matplotlib, which is not installed: "
            "pip install 'dirac-mechanics[plot]' (or pip install matplotlib)"
        ) from exc


def new_figure(width: float, height: float) -> Any:
    """A :class:`matplotlib.figure.Figure` of ``width x height`` inches on an Agg canvas."""
    _require_matplotlib()
    from matplotlib.backends.backend_agg import FigureCanvasAgg
    from matplotlib.figure import Figure

    fig = Figure(figsize=(width, height))  # fixed margins: the constrained layout is slow with 3-D axes
    FigureCanvasAgg(fig)
    return fig


def plot_formats() -> dict[str, str]:
    """The file formats matplotlib writes here, by suffix (``{"png": "Portable Network Graphics", ...}``)."""
    _require_matplotlib()
    from matplotlib.backends.backend_agg import FigureCanvasAgg

    return dict(sorted(FigureCanvasAgg.get_supported_filetypes().items()))


def check_plot_path(path: str | Path) -> Path:
    """Validate the target of a ``--plot FILE`` option and return it as a :class:`Path`.

    The suffix chooses the format: any that matplotlib writes (png, pdf, svg, eps, ...).

    Raises
    ------
    dirac.errors.InputError
        If the suffix is not a format matplotlib writes (the message lists them), the
        folder does not exist, or matplotlib is not installed (so that a run with
        ``--plot`` fails before it starts, not after).
    """
    target = Path(path)
    formats = plot_formats()
    suffix = target.suffix.lower().lstrip(".")
    if suffix not in formats:
        known = ", ".join(f".{name}" for name in formats)
        what = f"suffix .{suffix}" if suffix else "no suffix"
        raise InputError(f"plot file {str(path)!r} has {what}, not a picture format matplotlib writes; "
                         f"use one of {known} (for example --plot motion.png or --plot motion.pdf)")
    folder = target.parent if str(target.parent) else Path(".")
    if not folder.is_dir():
        raise InputError(f"folder {str(folder)!r} of the plot file {str(path)!r} does not exist: create it first")
    return target


def save_figure(fig: Any, path: str | Path, dpi: int = 110) -> Path:
    """Write ``fig`` in the format its suffix names (validated by :func:`check_plot_path`)."""
    target = check_plot_path(path)
    fig.savefig(target, dpi=dpi, format=target.suffix.lower().lstrip("."))
    return target


def check_png_path(path: str | Path) -> Path:
    """Like :func:`check_plot_path`, for a file that must be a PNG."""
    target = Path(path)
    if target.suffix.lower() != ".png":
        raise InputError(f"plot file {str(path)!r} must end in .png (for example --plot motion.png)")
    return check_plot_path(target)


def save_png(fig: Any, path: str | Path, dpi: int = 110) -> Path:
    """Write ``fig`` as a PNG file and return its path (validated by :func:`check_png_path`)."""
    target = check_png_path(path)
    fig.savefig(target, dpi=dpi, format="png")
    return target
