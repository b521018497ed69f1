"""Output of ``dirac bench``: the machine line, readable tables, JSON and the plot."""

from __future__ import annotations

import json
import math
import os
import platform
from pathlib import Path

from dirac.versions import installed_versions

__all__ = ["machine_description", "format_rows", "format_targets", "write_json", "write_plot", "wrap_title"]


def _cpu_model() -> str:
    try:
        for line in Path("/proc/cpuinfo").read_text().splitlines():
            if line.startswith("model name"):
                return line.split(":", 1)[1].strip()
    except OSError:
        pass
    return platform.processor() or platform.machine()


def machine_description() -> dict:
    """CPU model, logical CPUs, OS, load average and library versions."""
    versions = installed_versions(("numpy", "scipy", "numba", "dirac-mechanics"), missing="not installed", python=False)
    try:
        load = os.getloadavg()
    except OSError:
        load = (math.nan, math.nan, math.nan)
    return {
        "cpu": _cpu_model(),
        "logical_cpus": os.cpu_count(),
        "usable_cpus": len(os.sched_getaffinity(0)) if hasattr(os, "sched_getaffinity") else os.cpu_count(),
        "system": f"{platform.system()} {platform.release()} {platform.machine()}",
        "python": platform.python_version(),
        "versions": versions,
        "load_average_1min_at_start": load[0],
    }


def machine_line(machine: dict) -> str:
    """One line: the lscpu-style machine summary."""
    v = machine["versions"]
    return (f"{machine['cpu']}, {machine['usable_cpus']} CPUs, {machine['system']}, Python {machine['python']}, "
            f"numpy {v['numpy']}, scipy {v['scipy']}, numba {v['numba']}; load average {machine['load_average_1min_at_start']:.2f}")


def _number(value: float | None, fmt: str = ".2e") -> str:
    if value is None:
        return "-"
    if isinstance(value, float) and not math.isfinite(value):
        return str(value)
    return format(value, fmt)


def format_rows(rows: list[dict]) -> str:
    """The work–precision table, one block per problem."""
    lines: list[str] = []
    problems = list(dict.fromkeys(row["problem"] for row in rows))
    for problem in problems:
        subset = [row for row in rows if row["problem"] == problem]
        rigid = "error_M" in subset[0] or any("error_M" in r for r in subset)
        lines.append(f"\n== {problem} (T = {subset[0]['t_end']:.6g}) ==")
        if rigid:
            header = (f"{'method':<15}{'dt/tol':>9}{'CPU ms':>10}{'steps':>9}{'f-evals':>9}{'err M':>10}"
                      f"{'err R':>10}{'energy':>10}{'|M|^2':>10}{'R^TR-1':>10}")
        else:
            header = (f"{'method':<15}{'dt/tol':>9}{'CPU ms':>10}{'steps':>9}{'f-evals':>9}{'err q':>10}"
                      f"{'err p':>10}{'energy':>10}{'constr.':>10}")
        lines.append(header)
        lines.append("-" * len(header))
        for row in subset:
            value = "-" if row["value"] is None else f"{row['value']:g}"
            if "failed" in row:
                lines.append(f"{row['method']:<15}{value:>9}  failed: {row['failed']}")
                continue
            start = (f"{row['method']:<15}{value:>9}{row['cpu_s'] * 1e3:>10.3f}{row['steps']:>9d}"
                     f"{row['evaluations']:>9d}")
            if rigid:
                lines.append(start + "".join(f"{_number(row[k]):>10}" for k in (
                    "error_M", "error_R", "energy_error", "casimir_error", "orthogonality_error")))
            else:
                lines.append(start + "".join(f"{_number(row.get(k)):>10}" for k in (
                    "error_q", "error_p", "energy_error", "constraint_residual")))
        reference = subset[0].get("reference")
        if reference:
            lines.append(f"reference: {reference} (its own error about {_number(subset[0].get('reference_error'), '.1e')})")
    return "\n".join(lines)


def format_targets(targets: list) -> str:
    """The performance targets (docs/performance.md): value, target, met or missed by how much."""
    lines = [
        "\n== targets (each measured in this run; ratios against baselines of this run) ==",
        "A target is the speed (or memory, or accuracy per CPU time) the project aims at (docs/performance.md).",
        "'MISSED by 3.00x' means this figure is 3 times worse than its target on this machine under its present",
        "load: that operation is slower than planned. Results are as accurate either way; timings vary with load.",
    ]
    counts = {"met": 0, "missed": 0, "not measured": 0}
    for t in targets:
        if t.value is None or t.met is None:
            status, value = "not measured", "-" if t.value is None else f"{t.value:.3g} {t.unit}"
            counts["not measured"] += 1
        else:
            value = f"{t.value:.3g} {t.unit}"
            if t.met:
                status = "met"
                counts["met"] += 1
            elif t.sense == "<=":
                status = f"MISSED by {t.value / t.target:.2f}x (over the target: slower than planned)"
                counts["missed"] += 1
            else:
                status = (f"MISSED by {t.target / t.value:.2f}x (under the target: less gain than planned)"
                          if t.value > 0 else "MISSED")
                counts["missed"] += 1
        lines.append(f"- {t.name}: {value} (target {t.sense} {t.target:g} {t.unit}) -> {status}")
        if t.detail:
            lines.append(f"    {t.detail}")
    lines.append(f"{counts['met']} of {len(targets)} targets met, {counts['missed']} missed, "
                 f"{counts['not measured']} not measured")
    return "\n".join(lines)


def _clean(value: object) -> object:
    if isinstance(value, float) and not math.isfinite(value):
        return None
    if isinstance(value, dict):
        return {k: _clean(v) for k, v in value.items()}
    if isinstance(value, list):
        return [_clean(v) for v in value]
    return value


def write_json(path: str | Path, document: dict) -> None:
    """Write the JSON document (``runs``: one row per run; ``targets``; ``machine``)."""
    Path(path).write_text(json.dumps(_clean(document), indent=1, sort_keys=False) + "\n")


_STYLE = {
    "lie-poisson-2": ("tab:blue", "o"),
    "lie-poisson-4": ("tab:orange", "s"),
    "lie-poisson-6": ("tab:green", "^"),
    "lie-poisson-8": ("tab:red", "D"),
    "midpoint": ("tab:purple", "v"),
    "exact": ("black", "*"),
    "scipy-RK45": ("tab:gray", "x"),
    "scipy-DOP853": ("tab:brown", "+"),
    "lie-poisson-sym-4": ("tab:olive", "s"),
    "lie-poisson-sym-6": ("tab:cyan", "^"),
    "lie-poisson-sym-8": ("tab:pink", "D"),
    "rattle-2": ("tab:blue", "o"),
    "rattle-4": ("tab:orange", "s"),
    "exact-kick-4": ("tab:olive", "P"),
    "exact-kick-8": ("tab:cyan", "X"),
}


def wrap_title(title: str, width: int = 100) -> str:
    """``title`` in lines of at most ``width`` characters (the command, then the machine and
    versions broken at commas and spaces): a line wider than the figure is cut off at both
    ends, as the machine line was (100 characters of 7-point text fit a 6.4-inch figure)."""
    import textwrap

    lines: list[str] = []
    for part in title.split(" -- "):
        lines.extend(textwrap.wrap(part, width=width, break_on_hyphens=False) or [""])
    return "\n".join(lines)


def write_plot(path: str | Path, rows: list[dict], title: str) -> None:
    """CPU time against global error, log–log, one panel per problem."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    problems = list(dict.fromkeys(row["problem"] for row in rows))
    columns = min(3, len(problems))
    rows_of_panels = math.ceil(len(problems) / columns)
    figure, axes = plt.subplots(rows_of_panels, columns, figsize=(5.2 * columns, 4.2 * rows_of_panels), squeeze=False)
    for index, problem in enumerate(problems):
        axis = axes[index // columns][index % columns]
        subset = [r for r in rows if r["problem"] == problem and "failed" not in r]
        for method in dict.fromkeys(r["method"] for r in subset):
            points = sorted(((max(r["error"], 1e-17), r["cpu_s"]) for r in subset if r["method"] == method),
                            key=lambda p: p[1])
            colour, marker = _STYLE.get(method, (None, "o"))
            style = "--" if "-sym-" in method else ("-." if method.startswith("scipy-") else "-")
            axis.loglog([p[0] for p in points], [max(p[1], 1e-7) for p in points], marker=marker, color=colour,
                        label=method, linewidth=1.2, markersize=5, linestyle=style)
        axis.axvline(1e-9, color="0.7", linewidth=0.8, linestyle="--")
        axis.set_xlabel("global error at T (max over M, R / q, p)")
        axis.set_ylabel("CPU time [s]")
        axis.set_title(problem, fontsize=10)
        axis.grid(True, which="major", alpha=0.3)
        axis.legend(fontsize=7)
    for index in range(len(problems), rows_of_panels * columns):
        axes[index // columns][index % columns].axis("off")
    text = wrap_title(title, width=int(5.2 * columns * 72 / (0.6 * 9)))  # characters of 9-point text the width holds
    lines = text.count("\n") + 1
    figure.suptitle(text, fontsize=9)
    figure.tight_layout(rect=(0.0, 0.0, 1.0, 1.0 - 0.17 * lines / (4.2 * rows_of_panels)))  # room for the title's lines
    figure.savefig(path, dpi=110)
    plt.close(figure)


def format_markdown(document: dict, problems: list[str] | None = None) -> str:
    """Markdown tables (work–precision per problem, then the targets) of a bench JSON document."""
    rows = document["runs"]
    lines: list[str] = []
    wanted = problems or list(dict.fromkeys(r["problem"] for r in rows))
    for problem in wanted:
        subset = [r for r in rows if r["problem"] == problem]
        if not subset:
            continue
        rigid = any("error_M" in r for r in subset)
        keys: tuple[str, ...]
        lines.append(f"\n#### {problem} (T = {subset[0]['t_end']:.6g})\n")
        if rigid:
            lines.append("| method | dt / tol | CPU ms | steps | f-evals | err M | err R | energy | \\|M\\|² | \\|RᵀR−1\\| |")
            lines.append("|---|---:|---:|---:|---:|---:|---:|---:|---:|---:|")
            keys = ("error_M", "error_R", "energy_error", "casimir_error", "orthogonality_error")
        else:
            lines.append("| method | dt / tol | CPU ms | steps | f-evals | err q | err p | energy | constraint |")
            lines.append("|---|---:|---:|---:|---:|---:|---:|---:|---:|")
            keys = ("error_q", "error_p", "energy_error", "constraint_residual")
        for r in subset:
            value = "–" if r["value"] is None else f"{r['value']:g}"
            if "failed" in r:
                lines.append(f"| {r['method']} | {value} | failed: {r['failed']} |" + " |" * (len(keys) + 2))
                continue
            cells = [r["method"], value, f"{r['cpu_s'] * 1e3:.3f}", str(r["steps"]), str(r["evaluations"])]
            cells += [_number(r.get(k), ".1e") for k in keys]
            lines.append("| " + " | ".join(cells) + " |")
    lines.append("\n### Targets\n")
    lines.append("| figure | measured | target | status |")
    lines.append("|---|---:|---:|---|")
    for t in document["targets"]:
        value = "–" if t["value"] is None else f"{t['value']:.3g} {t['unit']}"
        if t["met"] is None:
            status = "not measured"
        elif t["met"]:
            status = "met"
        elif t["sense"] == "<=":
            status = f"**missed** ({t['value'] / t['target']:.2f}× over)"
        else:
            status = f"**missed** ({t['target'] / t['value']:.2f}× short)"
        lines.append(f"| {t['name']} | {value} | {t['sense']} {t['target']:g} {t['unit']} | {status} |")
        if t.get("detail"):
            lines.append(f"| ↳ {t['detail']} | | | |")
    return "\n".join(lines)
