"""Pictures of the free rigid body: polhode, body axes, conserved-quantity errors.

What a reader of the paper wants to see (Sects. VII, IX–XI):

* the **polhode** -- the path of the body angular momentum ``M(t)`` on the intersection
  of the Casimir sphere ``|M| = G`` (248) with the energy ellipsoid
  ``sum_i M_i^2 / I_i = 2E`` (247), drawn among the other polhodes of the same body, with
  the separatrix through the middle axis;
* the **body axes** -- the tips of the columns of ``R(t)`` (the principal axes in the lab,
  (109)) on the unit sphere, around the fixed lab angular momentum ``m = R M``;
* the **conserved quantities** -- relative errors of the energy ``H_0`` (247), of the
  Casimir ``|M|^2``, of ``m = R M`` and of ``R^T R = 1`` over time.

A body driven by an external torque or angular impulses conserves none of these: its
picture (:func:`driven_figure`) shows the energy ``E(t)`` and the work ``W(t)`` of the
torque, and the error of ``E - W``, the one quantity the exact motion keeps.

Units: ``dirac`` works in any consistent units; the axes are labelled in SI (moments of
inertia in kg m^2, angular momentum in kg m^2/s, time in s).
"""

from __future__ import annotations

from typing import Any

import numpy as np

from dirac.errors import InputError
from dirac.plots.canvas import new_figure
from dirac.plots.geometry import (
    ellipsoid_mesh,
    level_curves_on_sphere,
    polhode_levels,
    sphere_mesh,
    split_front_back,
    view_direction,
)

__all__ = [
    "conserved_quantity_errors",
    "draw_polhode",
    "draw_body_axes",
    "draw_conservation",
    "draw_momentum",
    "rigid_body_figure",
    "heavy_top_errors",
    "heavy_top_figure",
    "draw_energy_and_work",
    "driven_figure",
]

#: colours of the three principal axes (x, y, z convention: red, green, blue)
AXIS_COLOURS = ("tab:red", "tab:green", "tab:blue")
#: errors of exactly zero are drawn at this floor on the logarithmic axis
ERROR_FLOOR = 1e-18
_ELEV, _AZIM = 22.0, 38.0
_MOMENTUM_UNIT = r"kg m$^2$/s"


def _validate(t: Any, M: Any, R: Any, inertia: Any) -> tuple[np.ndarray, np.ndarray, np.ndarray | None, np.ndarray]:
    t = np.asarray(t, dtype=float).reshape(-1)
    M = np.asarray(M, dtype=float)
    if M.ndim != 2 or M.shape[1] != 3 or M.shape[0] != t.size:
        raise InputError(f"M must have shape ({t.size}, 3) to match t; got {M.shape}")
    if R is not None:
        R = np.asarray(R, dtype=float)
        if R.shape != (t.size, 3, 3):
            raise InputError(f"R must have shape ({t.size}, 3, 3) to match t; got {R.shape}")
    inertia = np.asarray(inertia, dtype=float).reshape(-1)
    if inertia.size != 3 or not np.all(inertia > 0):
        raise InputError(f"inertia must be three positive moments; got {inertia.tolist()}")
    if t.size == 0:
        raise InputError("nothing to draw: the result has no samples")
    return t, M, R, inertia


def conserved_quantity_errors(t: Any, M: Any, R: Any | None, inertia: Any) -> dict[str, np.ndarray]:
    """Relative errors of the conserved quantities of the free rigid body along a result.

    Parameters
    ----------
    t : array_like, shape (n,)
        Sample times.
    M : array_like, shape (n, 3)
        Body angular momentum.
    R : array_like, shape (n, 3, 3), or None
        Attitude (body to lab); without it only the energy and Casimir errors are formed.
    inertia : array_like, shape (3,)
        Principal moments ``I_i``.

    Returns
    -------
    dict of str to numpy.ndarray
        Keyed by a legend label: ``|E - E0| / E0`` with ``E = sum_i M_i^2 / (2 I_i)`` (247),
        ``||M|^2 - |M0|^2| / |M0|^2`` (Casimir of (248)), ``|m - m0| / |m0|`` with
        ``m = R M`` the lab angular momentum, and ``||R^T R - 1||_F`` (orthogonality, (81)).
    """
    t, M, R, inertia = _validate(t, M, R, inertia)
    energy = 0.5 * np.sum(M * M / inertia, axis=1)
    casimir = np.sum(M * M, axis=1)
    errors = {
        r"energy $|E-E_0|/E_0$": np.abs(energy - energy[0]) / max(abs(energy[0]), np.finfo(float).tiny),
        r"Casimir $||M|^2-|M_0|^2|/|M_0|^2$": np.abs(casimir - casimir[0]) / max(casimir[0], np.finfo(float).tiny),
    }
    if R is not None:
        m = np.einsum("nij,nj->ni", R, M)
        scale = max(float(np.linalg.norm(m[0])), np.finfo(float).tiny)
        errors[r"lab momentum $|m-m_0|/|m_0|$"] = np.linalg.norm(m - m[0], axis=1) / scale
        gram = np.einsum("nki,nkj->nij", R, R) - np.eye(3)
        errors[r"orthogonality $\|R^TR-1\|_F$"] = np.sqrt(np.sum(gram * gram, axis=(1, 2)))
    return errors


def _style_3d(ax: Any, limit: float, label: str, unit: str | None) -> None:
    suffix = f" [{unit}]" if unit else ""
    ax.set_xlabel(f"${label}_1${suffix}", labelpad=2)
    ax.set_ylabel(f"${label}_2${suffix}", labelpad=2)
    ax.set_zlabel(f"${label}_3${suffix}", labelpad=2)
    for setter in (ax.set_xlim, ax.set_ylim, ax.set_zlim):
        setter(-limit, limit)
    ax.set_box_aspect((1, 1, 1))
    ax.view_init(elev=_ELEV, azim=_AZIM)
    ax.tick_params(labelsize=7, pad=0)


def _sphere_curve(ax: Any, points: np.ndarray, view: np.ndarray, **style: Any) -> None:
    visible, hidden = split_front_back(points, view)
    label = style.pop("label", None)
    ax.plot(*visible.T, label=label, **style)
    faint = dict(style)
    faint["alpha"] = 0.25 * style.get("alpha", 1.0)
    faint["linestyle"] = ":"
    ax.plot(*hidden.T, **faint)


def draw_polhode(ax: Any, M: Any, inertia: Any, *, family: int = 8) -> None:
    """Draw the polhode of ``M`` on the Casimir sphere and the energy ellipsoid (3-D axes).

    The curve is the exact intersection ``|M| = G``, ``sum_i M_i^2 / I_i = 2E`` for the
    first sample's ``G`` and ``E``; the computed samples are drawn on it as dots, so any
    drift of a numerical method shows as dots leaving the curve. ``family`` other polhodes
    of the same body and the separatrix (dashed) are drawn on the sphere for context.

    Parameters
    ----------
    ax : mpl_toolkits.mplot3d.Axes3D
    M : array_like, shape (n, 3)
        Body angular momentum samples.
    inertia : array_like, shape (3,)
        Principal moments ``I_i``.
    family : int
        Number of other polhodes to draw (0 for none).
    """
    M = np.asarray(M, dtype=float)
    inertia = np.asarray(inertia, dtype=float)
    G = float(np.linalg.norm(M[0]))
    if G == 0.0:
        raise InputError("the body does not rotate (M = 0): there is no polhode to draw")
    E = 0.5 * float(np.sum(M[0] ** 2 / inertia))
    view = view_direction(_ELEV, _AZIM)
    ax.computed_zorder = False  # draw in call order: the computed dots stay on top
    ax.plot_wireframe(*sphere_mesh(G, 25), color="0.6", linewidth=0.3, alpha=0.35)
    ax.plot_surface(*ellipsoid_mesh(np.sqrt(2.0 * E * inertia), 41), color="tab:orange", alpha=0.07, linewidth=0)
    ax.plot_wireframe(*ellipsoid_mesh(np.sqrt(2.0 * E * inertia), 17), color="tab:orange", linewidth=0.4, alpha=0.5)
    if family:
        levels, separatrix = polhode_levels(inertia, family)
        for curve in level_curves_on_sphere(inertia, levels, G):
            for line in curve:
                _sphere_curve(ax, line, view, color="0.45", linewidth=0.7)
        for k, line in enumerate(level_curves_on_sphere(inertia, [separatrix], G)[0]):
            _sphere_curve(ax, line, view, color="black", linewidth=1.0, linestyle="--",
                          label="separatrix" if k == 0 else None)
    own = level_curves_on_sphere(inertia, [2.0 * E / G**2], G)[0]
    for k, line in enumerate(own):
        _sphere_curve(ax, line, view, color="tab:blue", linewidth=2.2, label="polhode (exact)" if k == 0 else None)
    ax.scatter(*M.T, s=4, color="tab:red", depthshade=False, label="computed $M(t)$")
    ax.plot([], [], color="tab:orange", linewidth=1.0, label=r"energy ellipsoid $\sum M_i^2/I_i=2E$")
    ax.plot([], [], color="0.6", linewidth=0.8, label=r"sphere $|M|=G$ and other polhodes")
    _style_3d(ax, 1.05 * max(G, float(np.sqrt(2.0 * E * inertia.max()))), "M", _MOMENTUM_UNIT)
    ax.set_title("Polhode of $M$: sphere $\\cap$ energy ellipsoid", fontsize=11)
    ax.legend(loc="upper center", bbox_to_anchor=(0.5, -0.07), ncol=2, fontsize=7, framealpha=0.8)


def _sparse(points: np.ndarray, max_angle: float = 0.35) -> bool:
    """True when consecutive unit vectors are typically more than ``max_angle`` rad apart."""
    if points.shape[0] < 3:
        return False
    cosines = np.clip(np.sum(points[1:] * points[:-1], axis=1), -1.0, 1.0)
    return bool(np.median(np.arccos(cosines)) > max_angle)


def draw_body_axes(ax: Any, R: Any, M: Any | None = None) -> None:
    """Draw the tips of the body axes (columns of ``R``) on the unit sphere (3-D axes).

    Column ``j`` of ``R(t)`` is the principal axis of ``I_j`` seen in the lab (109); its tip
    moves on the unit sphere. With ``M`` given, the fixed direction of the lab angular
    momentum ``m = R M`` is drawn as a black arrow.

    Parameters
    ----------
    ax : mpl_toolkits.mplot3d.Axes3D
    R : array_like, shape (n, 3, 3)
        Attitude samples (body to lab).
    M : array_like, shape (n, 3), optional
        Body angular momentum samples.
    """
    R = np.asarray(R, dtype=float)
    view = view_direction(_ELEV, _AZIM)
    ax.plot_wireframe(*sphere_mesh(1.0, 25), color="0.6", linewidth=0.3, alpha=0.35)
    for j in range(3):
        tips = R[:, :, j]
        label = f"tip of body axis {j + 1} (moment $I_{j + 1}$)"
        if _sparse(tips):  # samples too far apart for a line to mean anything: dots
            ax.scatter(*tips.T, s=3, color=AXIS_COLOURS[j], alpha=0.6, depthshade=False, label=label)
        else:
            _sphere_curve(ax, tips, view, color=AXIS_COLOURS[j], linewidth=1.2, label=label)
        ax.scatter(*tips[0], color=AXIS_COLOURS[j], s=40, marker="o", edgecolor="black", depthshade=False)
    if M is not None:
        m = np.einsum("ij,j->i", R[0], np.asarray(M, dtype=float)[0])
        norm = float(np.linalg.norm(m))
        if norm > 0:
            d = 1.25 * m / norm
            ax.quiver(0, 0, 0, *d, color="black", linewidth=2.0, arrow_length_ratio=0.12)
            ax.plot([], [], color="black", linewidth=2.0, label="direction of lab momentum $m=RM$")
    ax.scatter([], [], color="white", edgecolor="black", s=40, label="position at $t=0$")
    _style_3d(ax, 1.1, "x", None)
    ax.set_xlabel("lab $x$ (unit sphere)", labelpad=2)
    ax.set_ylabel("lab $y$", labelpad=2)
    ax.zaxis.set_rotate_label(False)
    ax.set_zlabel("lab $z$", labelpad=2, rotation=90)
    ax.set_title("Body axes in the lab: columns of $R(t)$", fontsize=11)
    ax.legend(loc="upper center", bbox_to_anchor=(0.5, -0.07), ncol=2, fontsize=7, framealpha=0.8)


def draw_conservation(
    ax: Any,
    t: Any,
    errors: dict[str, np.ndarray],
    ylabel: str = "relative error (dimensionless)",
    time_label: str = "time $t$ [s]",
) -> None:
    """Draw the errors of conserved quantities against time on a logarithmic axis.

    Each quantity is drawn twice in its own colour: the error itself at every sample (solid
    line), so that a bounded oscillation can be told from a drift, and its running maximum
    ``max_{s <= t} err(s)`` (thin dashed line), the envelope a user quotes. Errors of
    exactly zero are drawn at :data:`ERROR_FLOOR`; the double-precision round-off level
    ``2.2e-16`` is marked for reference.
    """
    t = np.asarray(t, dtype=float)
    for k, (label, values) in enumerate(errors.items()):
        colour = f"C{k % 10}"
        error = np.maximum(np.asarray(values, dtype=float), ERROR_FLOOR)
        ax.semilogy(t, error, color=colour, linewidth=1.2, label=label)
        ax.semilogy(t, np.maximum.accumulate(error), color=colour, linewidth=0.8, linestyle="--", alpha=0.7)
    if errors:
        ax.plot([], [], color="0.3", linewidth=0.8, linestyle="--", label="(dashed: largest error so far)")
    eps = np.finfo(float).eps
    ax.axhline(eps, color="0.5", linewidth=0.8, linestyle=(0, (1, 3)))
    ax.annotate("double-precision round-off $2.2\\times10^{-16}$", (1.0, eps), xycoords=("axes fraction", "data"),
                xytext=(-4, 3), textcoords="offset points", ha="right", fontsize=7, color="0.35")
    ax.set_xlabel(time_label)
    ax.set_ylabel(ylabel)
    ax.set_title("Conserved quantities: error over time", fontsize=11)
    low, high = ax.get_ylim()
    ax.set_ylim(min(low, 1e-17), max(high, 1e-14))
    ax.grid(True, which="major", alpha=0.3)
    ax.legend(fontsize=8, loc="upper center", bbox_to_anchor=(0.5, -0.13), ncol=2, framealpha=0.8)


def draw_momentum(ax: Any, t: Any, M: Any, max_samples: int = 150) -> None:
    """Draw the components ``M_i(t)`` of the body angular momentum against time.

    Long runs are shown over their first ``max_samples`` samples (named in the title), so
    that the oscillations stay readable; the error panel covers the whole run.
    """
    t = np.asarray(t, dtype=float)
    M = np.asarray(M, dtype=float)
    shown = min(t.size, max_samples)
    styles = ("-", "--", "-.")
    for j in range(3):
        ax.plot(t[:shown], M[:shown, j], color=AXIS_COLOURS[j], linestyle=styles[j], linewidth=1.4,
                marker="." if shown <= 120 else None, markersize=3, label=f"$M_{j + 1}$")
    ax.set_xlabel("time $t$ [s]")
    ax.set_ylabel(f"body angular momentum [{_MOMENTUM_UNIT}]")
    title = "Euler equations: $M(t)$ in the body frame"
    if shown < t.size:
        title += f" (first {t[shown - 1]:.4g} s of {t[-1]:.4g} s)"
    ax.set_title(title, fontsize=11)
    ax.grid(True, alpha=0.3)
    low, high = ax.get_ylim()
    ax.set_ylim(low, high + 0.18 * (high - low))  # room for the legend above the curves
    ax.legend(fontsize=8, loc="upper right", ncol=3, framealpha=0.8)


def rigid_body_figure(
    t: Any, M: Any, R: Any | None, inertia: Any, *, title: str | None = None
) -> Any:
    """The four-panel picture of a free-rigid-body run.

    Panels: polhode on the energy ellipsoid and the ``|M|`` sphere (:func:`draw_polhode`),
    body-axis tips on the unit sphere (:func:`draw_body_axes`, or ``M(t)`` against time
    when ``R`` is not available), ``M_i(t)`` (:func:`draw_momentum`), and the
    conserved-quantity errors (:func:`draw_conservation`).

    Parameters
    ----------
    t : array_like, shape (n,)
    M : array_like, shape (n, 3)
    R : array_like, shape (n, 3, 3), or None
    inertia : array_like, shape (3,)
    title : str, optional
        Figure title (for example the method and step).

    Returns
    -------
    matplotlib.figure.Figure
        On an Agg canvas; save it with :func:`dirac.plots.save_png`.
    """
    t, M, R, inertia = _validate(t, M, R, inertia)
    fig = new_figure(13.0, 12.0)
    grid = fig.add_gridspec(2, 2, left=0.07, right=0.98, bottom=0.10, top=0.92, wspace=0.22, hspace=0.42)
    draw_polhode(fig.add_subplot(grid[0, 0], projection="3d"), M, inertia)
    if R is not None:
        draw_body_axes(fig.add_subplot(grid[0, 1], projection="3d"), R, M)
        draw_momentum(fig.add_subplot(grid[1, 0]), t, M)
    else:
        draw_momentum(fig.add_subplot(grid[0, 1]), t, M)
    draw_conservation(fig.add_subplot(grid[1, :] if R is None else grid[1, 1]), t,
                      conserved_quantity_errors(t, M, R, inertia))
    heading = title or "Free rigid body"
    I_text = ", ".join(f"{v:.4g}" for v in inertia)
    M_text = ", ".join(f"{v + 0.0:.4g}" for v in M[0])
    fig.suptitle(f"{heading}\n$I = ({I_text})$ kg m$^2$,  $M(0) = ({M_text})$ "
                 f"{_MOMENTUM_UNIT},  {t.size} samples", fontsize=12)
    return fig


def _relative(values: np.ndarray, scale: float) -> np.ndarray:
    return np.abs(values - values[0]) / max(scale, np.finfo(float).tiny)


def heavy_top_errors(
    t: Any,
    M: Any,
    R: Any | None,
    inertia: Any,
    weight: Any | None = None,
    *,
    energy: Any | None = None,
    lab_momentum_z: Any | None = None,
) -> dict[str, np.ndarray]:
    """Errors of the quantities a heavy top conserves, by legend label.

    A top with a fixed point in uniform gravity conserves its total energy
    ``H = sum_i M_i^2 / (2 I_i) + (m g chi) . Gamma`` and the vertical component
    ``m_z = Gamma . M`` of the lab angular momentum, where ``Gamma = R^T e_z`` is the lab
    vertical in the body frame (the third row of ``R``); ``R^T R = 1`` holds for any
    rotation (81). The kinetic energy ``H_0`` (247) and ``|M|^2`` are *not* conserved once
    gravity acts, so they are not drawn.

    Parameters
    ----------
    t, M, R, inertia
        As for :func:`conserved_quantity_errors`.
    weight : array_like, shape (3,), optional
        ``m g chi`` in the body frame; needed to form ``H`` from ``M`` and ``R``.
    energy, lab_momentum_z : array_like, shape (n,), optional
        The run's own outputs; used as they are when given.

    Returns
    -------
    dict of str to numpy.ndarray
        ``|H - H0| / |H0|`` (absolute when ``H0 = 0``), ``|m_z - m_z0| / |M0|`` and
        ``||R^T R - 1||_F``, each present when its data are.
    """
    t, M, R, inertia = _validate(t, M, R, inertia)
    errors: dict[str, np.ndarray] = {}
    if energy is None and R is not None and weight is not None:
        energy = 0.5 * np.sum(M * M / inertia, axis=1) + R[:, 2, :] @ np.asarray(weight, dtype=float)
    if energy is not None:
        H = np.asarray(energy, dtype=float).reshape(-1)
        if H[0] != 0.0:
            errors[r"total energy $|H-H_0|/|H_0|$"] = _relative(H, abs(float(H[0])))
        else:
            errors[r"total energy $|H-H_0|$ ($H_0=0$)"] = np.abs(H - H[0])
    if lab_momentum_z is None and R is not None:
        lab_momentum_z = np.einsum("nj,nj->n", R[:, 2, :], M)
    if lab_momentum_z is not None:
        m_z = np.asarray(lab_momentum_z, dtype=float).reshape(-1)
        errors[r"vertical lab momentum $|m_z-m_{z,0}|/|M_0|$"] = _relative(m_z, float(np.linalg.norm(M[0])))
    if R is not None:
        gram = np.einsum("nki,nkj->nij", R, R) - np.eye(3)
        errors[r"orthogonality $\|R^TR-1\|_F$"] = np.sqrt(np.sum(gram * gram, axis=(1, 2)))
    return errors


def heavy_top_figure(
    t: Any,
    M: Any,
    R: Any | None,
    inertia: Any,
    weight: Any | None = None,
    *,
    energy: Any | None = None,
    lab_momentum_z: Any | None = None,
    title: str | None = None,
) -> Any:
    """The picture of a heavy-top run: body axes, ``M(t)``, errors of its own conserved quantities.

    Panels: the body-axis tips on the unit sphere (:func:`draw_body_axes`, when ``R`` is
    known), the components ``M_i(t)`` (:func:`draw_momentum`), and the errors of
    :func:`heavy_top_errors` (total energy, ``m_z``, ``R^T R``) against time. No polhode:
    under gravity ``M`` leaves the free body's sphere and ellipsoid, so that picture would
    mean nothing.

    Returns
    -------
    matplotlib.figure.Figure
    """
    t, M, R, inertia = _validate(t, M, R, inertia)
    errors = heavy_top_errors(t, M, R, inertia, weight, energy=energy, lab_momentum_z=lab_momentum_z)
    fig = new_figure(13.0, 11.0 if R is not None else 9.5)
    grid = fig.add_gridspec(2, 2, left=0.07, right=0.98, bottom=0.12, top=0.91, wspace=0.22, hspace=0.42)
    if R is not None:
        draw_body_axes(fig.add_subplot(grid[0, 0], projection="3d"), R)
        draw_momentum(fig.add_subplot(grid[0, 1]), t, M)
    else:
        draw_momentum(fig.add_subplot(grid[0, :]), t, M)
    if errors:
        draw_conservation(fig.add_subplot(grid[1, :]), t, errors, ylabel="error (see legend)")
    heading = title or "Heavy top"
    I_text = ", ".join(f"{v:.4g}" for v in inertia)
    M_text = ", ".join(f"{v + 0.0:.4g}" for v in M[0])
    w_text = "" if weight is None else ",  $mg\\chi = (" + ", ".join(f"{v:.4g}" for v in np.asarray(weight)) + ")$"
    fig.suptitle(f"{heading}\n$I = ({I_text})${w_text},  $M(0) = ({M_text})$,  {t.size} samples", fontsize=12)
    return fig


def draw_energy_and_work(ax: Any, t: Any, energy: Any, work: Any | None) -> None:
    """Draw the energy ``E(t)`` (not conserved under a torque), the work ``W(t)`` done by the
    torque and impulses, and ``E - W`` (constant along the exact motion) against time."""
    t = np.asarray(t, dtype=float)
    energy = np.asarray(energy, dtype=float)
    ax.plot(t, energy, color="C0", linewidth=1.4, label="energy $E(t)$ (not conserved: external torque)")
    if work is not None:
        work = np.asarray(work, dtype=float)
        ax.plot(t, work, color="C1", linewidth=1.2, linestyle="--", label=r"work $W(t)=\int N\cdot\Omega\,dt$")
        ax.plot(t, energy - work, color="C2", linewidth=1.2, linestyle="-.", label="$E - W$ (conserved)")
    ax.set_xlabel("time $t$ [s]")
    ax.set_ylabel("energy [J]")
    ax.set_title("Energy and the work of the torque", fontsize=11)
    ax.grid(True, alpha=0.3)
    ax.legend(fontsize=8, loc="upper center", bbox_to_anchor=(0.5, -0.13), ncol=2, framealpha=0.8)


def driven_figure(
    t: Any,
    M: Any,
    R: Any | None,
    inertia: Any,
    energy: Any,
    work: Any | None,
    *,
    title: str | None = None,
    heading: str = "Rigid body under a torque",
) -> Any:
    """The picture of a run driven by an external torque or angular impulses.

    Panels: the body axes (:func:`draw_body_axes`, when ``R`` is known), ``M_i(t)``
    (:func:`draw_momentum`), the energy and the work (:func:`draw_energy_and_work`), and
    the relative error of ``E - W`` (``E_0 - (E - W)`` over ``E_0``; ``dE/dt = N·Omega``
    along the exact motion). No polhode: under a torque ``M`` leaves the free body's
    sphere and ellipsoid. Without ``work`` only the energy is drawn.

    Returns
    -------
    matplotlib.figure.Figure
    """
    t, M, R, inertia = _validate(t, M, R, inertia)
    energy = np.asarray(energy, dtype=float).reshape(-1)
    fig = new_figure(13.0, 11.0)
    grid = fig.add_gridspec(2, 2, left=0.07, right=0.98, bottom=0.12, top=0.91, wspace=0.22, hspace=0.45)
    if R is not None:
        draw_body_axes(fig.add_subplot(grid[0, 0], projection="3d"), R)
        draw_momentum(fig.add_subplot(grid[0, 1]), t, M)
    else:
        draw_momentum(fig.add_subplot(grid[0, :]), t, M)
    draw_energy_and_work(fig.add_subplot(grid[1, 0]), t, energy, work)
    errors_ax = fig.add_subplot(grid[1, 1])
    if work is not None:
        balance = energy - np.asarray(work, dtype=float).reshape(-1)
        draw_conservation(errors_ax, t, {r"$|(E-W)-E_0|/|E_0|$": _relative(balance, abs(float(energy[0])))})
    else:
        errors_ax.text(0.5, 0.5, "output 'work' not stored:\nthe balance E - W cannot be drawn",
                       ha="center", va="center", transform=errors_ax.transAxes)
        errors_ax.set_axis_off()
    I_text = ", ".join(f"{v:.4g}" for v in inertia)
    M_text = ", ".join(f"{v + 0.0:.4g}" for v in M[0])
    fig.suptitle(f"{title or heading}\n$I = ({I_text})$ kg m$^2$,  $M(0) = ({M_text})$ {_MOMENTUM_UNIT},  "
                 f"{t.size} samples", fontsize=12)
    return fig
