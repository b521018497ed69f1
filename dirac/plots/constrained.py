"""Pictures of a general constrained system: path, coordinates, conserved-quantity errors.

For a system with coordinates ``q`` and holonomic constraints ``chi(q) = 0`` (paper (1),
Sect. X): the path in configuration space (which must stay on the constraint surface;
in 3-D for three coordinates), the coordinates against time, and the relative energy
error together with the constraint residual over time. A system that depends on time
does not conserve its energy: its energy curve says so, and a conserved combination
(the Jacobi integral of uniformly turning constraints) is drawn when one is given.
"""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from typing import Any

import numpy as np

from dirac.errors import InputError
from dirac.plots.canvas import new_figure
from dirac.plots.rigid_body import draw_conservation

__all__ = ["draw_configuration", "draw_coordinates", "constrained_errors", "constrained_figure"]

#: a general system has no fixed units: every axis says "system units"
_TIME = "time $t$ (system units)"


def _names(names: Sequence[str] | None, n: int) -> list[str]:
    if names is not None and len(names) == n:
        return [str(v) for v in names]
    return [f"q_{k + 1}" for k in range(n)]


def _math(name: str) -> str:
    """A coordinate name as mathtext (``theta_1`` -> ``$theta_{1}$``)."""
    base, _, sub = name.partition("_")
    return f"${base}_{{{sub}}}$" if sub else f"${base}$"


def draw_configuration(ax: Any, q: np.ndarray, names: Sequence[str]) -> None:
    """Draw the path ``q(t)`` in the plane of the first two coordinates, or in the space of
    all three when ``ax`` is a 3-D axis (start and end marked)."""
    solid = getattr(ax, "name", "") == "3d"
    columns = [q[:, k] for k in range(3 if solid else 2)]
    ax.plot(*columns, color="tab:blue", linewidth=1.3, marker="." if q.shape[0] <= 100 else None,
            markersize=3, label="computed path")
    ax.plot(*[c[:1] for c in columns], "o", color="tab:green", markersize=8, markeredgecolor="black", label="$t=0$")
    ax.plot(*[c[-1:] for c in columns], "s", color="tab:red", markersize=7, markeredgecolor="black", label="end")
    ax.set_xlabel(f"{_math(names[0])} (system units)")
    ax.set_ylabel(f"{_math(names[1])} (system units)")
    if solid:
        ax.set_zlabel(f"{_math(names[2])} (system units)")
        spans = [float(np.ptp(c)) for c in columns]
        ax.set_box_aspect([max(s, 1e-3 * max(spans) + 1e-12) for s in spans])  # equal scales on the axes
    else:
        ax.set_aspect("equal", adjustable="datalim")
    ax.grid(True, alpha=0.3)
    ax.set_title("Path in configuration space", fontsize=11)
    ax.legend(fontsize=8, loc="best")


def draw_coordinates(ax: Any, t: np.ndarray, q: np.ndarray, names: Sequence[str]) -> None:
    """Draw every coordinate ``q_i(t)`` against time."""
    for k, name in enumerate(names):
        ax.plot(t, q[:, k], linewidth=1.3, label=_math(name))
    ax.set_xlabel(_TIME)
    ax.set_ylabel("coordinate value (system units)")
    ax.grid(True, alpha=0.3)
    ax.set_title("Coordinates over time", fontsize=11)
    ax.legend(fontsize=8, loc="best", ncol=min(4, len(names)))


def constrained_errors(
    energy: Any | None,
    constraint_residual: Any | None,
    constraints: Mapping[str, Any] | None = None,
    *,
    energy_conserved: bool = True,
    conserved: Mapping[str, Any] | None = None,
    work: Any | None = None,
) -> dict[str, np.ndarray]:
    """Energy error and constraint residuals, by legend label.

    With ``work`` (the work ``W(t)`` of generalized forces, a forced run) the conserved
    quantity is ``E - W`` (Lamb's energy balance ``dT/dt = sum_r Q_r q_dot_r``): its error
    ``|(E - W) - E0| / |E0|`` is drawn, and the change of the energy itself, labelled as
    not conserved.

    The energy error is relative, ``|E - E0| / |E0|`` (absolute, and labelled so, when
    ``E0 = 0``); with ``energy_conserved=False`` (a system that depends on time) it is
    labelled "not conserved". ``conserved`` (label -> samples) adds curves of conserved
    combinations (e.g. a Jacobi integral). With ``constraints`` (name -> residual samples)
    every constraint gets its own curve ``|chi_a|``; otherwise the run's
    ``constraint_residual`` output (``max_a |chi_a|`` over the constraints) is drawn as
    one curve.
    """
    errors: dict[str, np.ndarray] = {}
    if energy is not None and work is not None:
        E = np.asarray(energy, dtype=float).reshape(-1)
        W = np.asarray(work, dtype=float).reshape(-1)
        scale = abs(E[0]) if E[0] != 0 else 1.0
        balance = E - W
        errors[r"energy $-$ work $|(E-W)-(E_0-W_0)|/|E_0|$ (conserved)"] = np.abs(balance - balance[0]) / scale
        errors[r"energy $|E-E_0|/|E_0|$ (not conserved: forces act)"] = np.abs(E - E[0]) / scale
    elif energy is not None:
        E = np.asarray(energy, dtype=float).reshape(-1)
        scale = abs(E[0])
        note = "" if energy_conserved else " (not conserved: the system depends on time)"
        if scale > 0:
            errors[r"energy $|E-E_0|/|E_0|$" + note] = np.abs(E - E[0]) / scale
        else:
            errors[r"energy $|E-E_0|$ ($E_0=0$)" + note] = np.abs(E - E[0])
    for label, values in (conserved or {}).items():
        errors[label] = np.abs(np.asarray(values, dtype=float).reshape(-1))
    if constraints:
        for name, values in constraints.items():
            errors[f"constraint {name}"] = np.abs(np.asarray(values, dtype=float).reshape(-1))
    elif constraint_residual is not None:
        errors[r"largest constraint residual $\max_a|\chi_a|$"] = np.abs(
            np.asarray(constraint_residual, dtype=float).reshape(-1))
    return errors


def constrained_figure(
    t: Any,
    q: Any,
    *,
    energy: Any | None = None,
    constraint_residual: Any | None = None,
    names: Sequence[str] | None = None,
    title: str | None = None,
    constraints: Mapping[str, Any] | None = None,
    energy_conserved: bool = True,
    conserved: Mapping[str, Any] | None = None,
    work: Any | None = None,
) -> Any:
    """The three-panel picture of a constrained-system run.

    Parameters
    ----------
    t : array_like, shape (n,)
    q : array_like, shape (n, d)
        Coordinates at the sample times.
    energy, constraint_residual : array_like, shape (n,), optional
        Outputs of the run; drawn as errors over time (:func:`constrained_errors`).
    constraints : mapping of str to array_like, shape (n,), optional
        The residual of each constraint by name; one curve each, in place of
        ``constraint_residual``.
    work : array_like, shape (n,), optional
        The work of the generalized forces (a forced run): the error of ``energy - work``
        is drawn, and the energy labelled as not conserved (:func:`constrained_errors`).
    names : sequence of str, optional
        Coordinate names (default ``q_1 … q_d``).
    title : str, optional
    energy_conserved : bool
        ``False`` for a system that depends on time: its energy curve says "not conserved"
        and the panel's title names what is drawn.
    conserved : mapping of str to array_like, shape (n,), optional
        Errors of conserved combinations (label -> samples), e.g. a Jacobi integral.

    Returns
    -------
    matplotlib.figure.Figure
    """
    t = np.asarray(t, dtype=float).reshape(-1)
    q = np.asarray(q, dtype=float)
    if q.ndim == 1:
        q = q[:, None]
    if q.ndim != 2 or q.shape[0] != t.size or t.size == 0:
        raise InputError(f"q must have shape ({t.size}, d) to match t; got {q.shape}")
    labels = _names(names, q.shape[1])
    errors = constrained_errors(energy, constraint_residual, constraints, energy_conserved=energy_conserved,
                                conserved=conserved, work=work)
    fig = new_figure(13.0, 9.5)
    legend_rows = (len(errors) + 2) // 2  # the legend under the error panel: two columns, one more entry
    grid = fig.add_gridspec(2, 2, left=0.07, right=0.98, bottom=max(0.12, 0.04 + 0.025 * legend_rows), top=0.93,
                            wspace=0.2, hspace=0.3)
    if q.shape[1] >= 2:
        solid = {"projection": "3d"} if q.shape[1] == 3 else {}
        draw_configuration(fig.add_subplot(grid[0, 0], **solid), q, labels)
        draw_coordinates(fig.add_subplot(grid[0, 1]), t, q, labels)
    else:
        draw_coordinates(fig.add_subplot(grid[0, :]), t, q, labels)
    if errors:
        panel = fig.add_subplot(grid[1, :])
        draw_conservation(panel, t, errors, ylabel="error (see legend)", time_label=_TIME)
        if not energy_conserved:
            drawn = "Constraint residuals and conserved quantities" if conserved else "Constraint residuals"
            panel.set_title(f"{drawn} over time (the energy changes: the system depends on time)", fontsize=11)
    fig.suptitle(title or "Constrained system", fontsize=12)
    return fig
