"""The tables of ``dirac bench --stress``: fixed-width text that is also Markdown."""

from __future__ import annotations

__all__ = ["format_table"]


def _e(value: float | None) -> str:
    return "-" if value is None else f"{value:.2e}"


def format_table(document: dict) -> str:
    """The three parts as fixed-width text tables (also valid Markdown)."""
    lines = ["Long runs, standard body I = (2, 1, 2/3) (limits: deviations of M.M and R^T R <= 2e-12; energy bounded)", ""]
    lines.append("| method | steps | dt | max dev. of M.M | max dev. of R^T R from 1 | energy err. first 1/10 | energy err. last 1/10 | CPU s | pass |")
    lines.append("| --- | ---: | ---: | ---: | ---: | ---: | ---: | ---: | --- |")
    for r in document["long_runs"]:
        lines.append(f"| {r['method']} | {r['steps']:.0e} | {r['dt']:g} | {_e(r['casimir_error'])} | "
                     f"{_e(r['orthogonality_error'])} | {_e(r['energy_error_first_tenth'])} | "
                     f"{_e(r['energy_error_last_tenth'])} | {r['cpu_seconds']:.1f} | {'yes' if r['passed'] else 'NO'} |")
    lines += ["", "Hard bodies: max error over the samples against the 50-digit Taylor reference "
              "(M relative to the norm of M(0); exact must stay below its bound; no silent NaN)", ""]
    lines.append("| body | method | error M | error R | status | pass |")
    lines.append("| --- | --- | ---: | ---: | --- | --- |")
    for r in document["hard_bodies"]:
        status = r["status"] if len(r["status"]) <= 60 else r["status"][:57] + "..."
        if r["method"] == "exact" and "bound" in r:
            status += f" (bound {r['bound']:.1e})"
        lines.append(f"| {r['case']} | {r['method']} | {_e(r['error_M'])} | {_e(r['error_R'])} | {status} | "
                     f"{'yes' if r['passed'] else 'NO'} |")
    lines += ["", "Constrained long runs (limits: abs chi <= tol (1 + q.q), tol = 1e-12; velocity residual at "
              "round-off; energy bounded)", ""]
    lines.append("| system | method | steps | dt | max abs chi(q) | max abs G M^-1 p | energy err. first 1/10 | "
                 "energy err. last 1/10 | CPU s | pass |")
    lines.append("| --- | --- | ---: | ---: | ---: | ---: | ---: | ---: | ---: | --- |")
    for r in document["constrained"]:
        lines.append(f"| {r['case']} | {r['method']} | {r['steps']:.0e} | {r['dt']:g} | {_e(r['position_residual'])} | "
                     f"{_e(r['velocity_residual'])} | {_e(r['energy_error_first_tenth'])} | "
                     f"{_e(r['energy_error_last_tenth'])} | {r['cpu_seconds']:.1f} | {'yes' if r['passed'] else 'NO'} |")
    lines += ["", f"all passed: {'yes' if document['passed'] else 'NO'}; wall time {document['wall_seconds']:.0f} s"]
    return "\n".join(lines)
