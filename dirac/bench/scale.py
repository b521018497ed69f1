"""The scale table of ``dirac bench --scale``: analysis time against system size, with the fitted exponent.

Three local systems built by functions of their size in ``dirac_systems.scale_models``
(docs/scale.md): the planar ``n``-link chain (``chain``), 1+1 lattice Maxwell theory on a
ring of ``n`` sites (``maxwell_ring``) and 2+1 lattice Maxwell theory on an ``L x L`` torus
(``maxwell_torus``). Each size is analysed in a fresh process (import excluded from the
timed region; the process's peak resident memory is read from the operating system), which
also bounds a size that would not finish: after ``budget`` seconds the process is stopped
and the larger sizes of that model are not tried. The growth exponent between the two
largest measured sizes is ``log(t2/t1) / log(N2/N1)`` with ``N`` the number of phase-space
variables.

This module only formats and judges rows; the rows are measured by
:mod:`dirac.commands.bench_scale`, which may import the analysis.
"""

from __future__ import annotations

import math
from dataclasses import asdict, dataclass

from dirac.bench.targets import (
    SCALE_TARGET_EXPONENT,
    SCALE_TARGET_MEMORY_MB,
    SCALE_TARGET_SECONDS,
    SCALE_TARGET_SIZES,
    Target,
)

__all__ = [
    "ScaleRow",
    "scale_sizes",
    "growth_exponent",
    "scale_targets",
    "format_scale_rows",
    "write_scale_plot",
    "SCALE_TARGET_SECONDS",
    "SCALE_TARGET_EXPONENT",
    "SCALE_TARGET_MEMORY_MB",
    "SCALE_TARGET_SIZES",
]



def scale_sizes(quick: bool) -> dict[str, list[int]]:
    """Sizes measured per model: small ones with ``--quick``, up to the target sizes otherwise."""
    if quick:
        return {"chain": [4, 8, 16], "maxwell_ring": [16, 32, 64], "maxwell_torus": [3, 4, 5]}
    return {"chain": [16, 32, 64, 128], "maxwell_ring": [128, 256, 512, 1024], "maxwell_torus": [4, 8, 12, 16]}


def phase_space_size(model: str, size: int) -> int:
    """Number of phase-space variables of a model at a size (the ``N`` of the fits)."""
    if model == "chain":
        return 6 * size  # x, y, lambda per link, and their momenta
    if model == "maxwell_ring":
        return 4 * size  # A0, A1 per site, and their momenta
    return 6 * size * size  # A0, Ax, Ay per site, and their momenta


@dataclass
class ScaleRow:
    """One analysed size: seconds of ``analyze``, of the first and of later ``dirac_bracket(at=)`` calls."""

    model: str
    size: int
    variables: int
    analyze_s: float | None
    first_bracket_s: float | None = None
    bracket_ms: float | None = None
    peak_mb: float | None = None
    counts: str = ""
    failed: str = ""

    def as_dict(self) -> dict:
        return asdict(self)


def growth_exponent(rows: list[ScaleRow], model: str) -> float | None:
    """``log(t2/t1) / log(N2/N1)`` between the two largest sizes of ``model`` that finished."""
    done = sorted((r for r in rows if r.model == model and r.analyze_s), key=lambda r: r.variables)
    if len(done) < 2:
        return None
    a, b = done[-2], done[-1]
    return math.log(b.analyze_s / a.analyze_s) / math.log(b.variables / a.variables)  # type: ignore[operator]


def scale_targets(rows: list[ScaleRow], quick: bool) -> list[Target]:
    """The targets: 10 s at each target size (full run only), exponent <= 1.3, peak memory <= 2 GB."""
    out: list[Target] = []
    for model, size in SCALE_TARGET_SIZES.items():
        if not quick:
            row = next((r for r in rows if r.model == model and r.size == size), None)
            out.append(Target(
                f"scale: analyze {model} at size {size}", row.analyze_s if row else None, "s", SCALE_TARGET_SECONDS, "<=",
                detail=(row.failed if row and row.failed else "wall time of dirac.analyze, import excluded"),
            ))
        exponent = growth_exponent(rows, model)
        out.append(Target(
            f"scale: growth exponent of {model}", exponent, "", SCALE_TARGET_EXPONENT, "<=",
            detail="log(t2/t1)/log(N2/N1) between the two largest sizes that finished",
        ))
    peaks = [r.peak_mb for r in rows if r.peak_mb is not None]
    out.append(Target("scale: peak memory of one analysis process", max(peaks) if peaks else None, "MB",
                      SCALE_TARGET_MEMORY_MB, "<=", detail="largest peak resident set of the measuring processes"))
    return out


def _cell(value: float | None, digits: int = 2) -> str:
    return "-" if value is None else f"{value:.{digits}f}"


def format_scale_rows(rows: list[ScaleRow]) -> str:
    """The scale table: one line per model and size, the exponent after each model."""
    lines = [
        "\n== scale: dirac.analyze against size (fresh process per size, import excluded) ==",
        f"{'model':<15}{'size':>6}{'N vars':>8}{'analyze s':>11}{'1st bracket s':>15}{'bracket ms':>12}"
        f"{'peak MB':>9}  counts",
    ]
    for model in dict.fromkeys(r.model for r in rows):
        for r in (r for r in rows if r.model == model):
            tail = r.counts if not r.failed else f"not finished: {r.failed}"
            lines.append(
                f"{r.model:<15}{r.size:>6}{r.variables:>8}{_cell(r.analyze_s):>11}{_cell(r.first_bracket_s):>15}"
                f"{_cell(r.bracket_ms, 3):>12}{_cell(r.peak_mb, 0):>9}  {tail}"
            )
        exponent = growth_exponent(rows, model)
        lines.append(f"{'':<15}growth exponent (two largest finished sizes): {_cell(exponent)}")
    return "\n".join(lines)


def write_scale_plot(path: str, rows: list[ScaleRow], title: str) -> None:
    """Analysis time against the number of phase-space variables, log-log, one line per model."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    figure, axis = plt.subplots(figsize=(6.4, 4.6))
    for model in dict.fromkeys(r.model for r in rows):
        done = sorted((r for r in rows if r.model == model and r.analyze_s), key=lambda r: r.variables)
        if not done:
            continue
        exponent = growth_exponent(rows, model)
        label = model + (f" (exponent {exponent:.2f})" if exponent is not None else "")
        axis.loglog([r.variables for r in done], [r.analyze_s for r in done], marker="o", label=label)
    axis.axhline(SCALE_TARGET_SECONDS, color="0.6", linestyle="--", linewidth=0.8, label=f"{SCALE_TARGET_SECONDS:g} s target")
    axis.set_xlabel("phase-space variables N")
    axis.set_ylabel("dirac.analyze wall time [s]")
    axis.grid(True, which="major", alpha=0.3)
    axis.legend(fontsize=8)
    from dirac.bench.report import wrap_title

    axis.set_title(wrap_title(title), fontsize=7)
    figure.tight_layout()
    figure.savefig(path, dpi=120)
    plt.close(figure)
