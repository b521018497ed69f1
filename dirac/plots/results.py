"""Draw a run's result -- a :class:`dirac.flows.Solution` or a result file -- as one picture.

This is what ``dirac.plot``, ``dirac run SCENE --plot FILE`` and ``dirac demo --plot FILE``
call (FILE in any format matplotlib writes: png, pdf, svg, ...). The picture is chosen by the
kind of system, from the outputs present and the ``meta`` record (docs/file_formats.md):
see :func:`result_figure`.
"""

from __future__ import annotations

import json
from collections.abc import Mapping, Sequence
from pathlib import Path
from typing import Any

import numpy as np

from dirac.errors import InputError
from dirac.plots.canvas import check_plot_path, save_figure

__all__ = ["plot", "result_figure", "plot_result", "load_result"]


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


def _title(meta: Mapping[str, Any], default: str, time_unit: str = "s") -> str:
    """The figure's title line; ``time_unit`` is that of the figure's time axes (empty: none)."""
    parts = [str(meta.get("system", default))]
    if meta.get("method"):
        method = str(meta["method"])
        if meta.get("order"):
            method += f" (order {meta['order']})"
        parts.append(f"method {method}")
    if meta.get("dt"):
        parts.append(f"dt = {float(meta['dt']):.3g}" + (f" {time_unit}" if time_unit else ""))
    if meta.get("steps"):
        parts.append(f"{int(meta['steps'])} steps")
    if meta.get("complete") is False:
        parts.append("INCOMPLETE run")
    return ",  ".join(parts)


def _constraint_residuals(result: Any, problem: Any) -> dict[str, np.ndarray] | None:
    """Each constraint's residual along the run, by mathtext label, when ``problem`` can tell.

    ``problem.mechanics`` (a compiled holonomic system, duck-typed so that this layer imports
    no engine module) gives ``residuals(q, p, t) -> (chi(q, t), G M^{-1} p + d_t chi)``: the
    position constraints ``chi_a`` and their total time derivatives ``dchi_a/dt`` (the
    second-stage constraints of the Dirac analysis, Sect. X, with the partial time derivative
    of a moving constraint), one curve each, each sample at its own time ``t``; the latter
    only when the run kept the momenta ``p``.
    """
    mechanics = getattr(problem, "mechanics", None)
    if mechanics is None or not hasattr(mechanics, "residuals") or not _has(result, "q"):
        return None
    q = _first_body(_get(result, "q"), 2)
    times = np.asarray(_get(result, "t"), dtype=float).reshape(-1)
    with_momenta = _has(result, "p")  # without p only the position constraints chi_a can be formed
    p = _first_body(_get(result, "p"), 2) if with_momenta else np.zeros_like(q)
    pairs = [mechanics.residuals(a, b, float(time)) for a, b, time in zip(q, p, times)]
    if not pairs or np.asarray(pairs[0][0]).size == 0:
        return None
    chi = np.array([np.asarray(c, dtype=float) for c, _ in pairs])
    tangent = np.array([np.asarray(v, dtype=float) for _, v in pairs])
    expressions = list(getattr(mechanics, "symbolic", {}).get("constraints", []))
    residuals: dict[str, np.ndarray] = {}
    for a in range(chi.shape[1]):
        formula = str(expressions[a]).replace("**", "^").replace("*", r"\,") if a < len(expressions) else ""
        text = f", $\\chi_{{{a + 1}}} = {formula}$" if formula else ""
        residuals[f"$|\\chi_{{{a + 1}}}|${text}"] = np.abs(chi[:, a])
    for a in range(tangent.shape[1] if with_momenta else 0):
        residuals[f"$|\\dot\\chi_{{{a + 1}}}|$ (velocity)"] = np.abs(tangent[:, a])
    return residuals


def _energy_curves(result: Any, problem: Any) -> tuple[dict[str, np.ndarray] | None, bool]:
    """``(extra curves, time_dependent)``: for a time-dependent system the energy is not conserved;
    when its constraints turn uniformly (``problem.mechanics.rotation``, duck-typed) the Jacobi
    integral ``J = H - w (q_i p_j - q_j p_i)`` is, and its relative change is drawn."""
    mechanics = getattr(problem, "mechanics", None)
    time_dependent = getattr(mechanics, "time_symbol", None) is not None
    rotation = getattr(mechanics, "rotation", None)
    if not time_dependent or rotation is None or not all(_has(result, k) for k in ("q", "p", "energy")):
        return None, time_dependent
    i, j, rate, text = rotation
    q = _first_body(_get(result, "q"), 2)
    p = _first_body(_get(result, "p"), 2)
    J = _first_body(_get(result, "energy"), 1) - rate * (q[:, i] * p[:, j] - q[:, j] * p[:, i])
    scale = abs(J[0])
    label = text.replace("*", " ")
    if scale > 0:
        return {f"Jacobi integral $|J-J_0|/|J_0|$, J = {label} (conserved)": np.abs(J - J[0]) / scale}, True
    return {f"Jacobi integral $|J-J_0|$ ($J_0=0$), J = {label} (conserved)": np.abs(J - J[0])}, True


def _kind(result: Any, meta: Mapping[str, Any]) -> str:
    if _has(result, "M"):
        parameters = meta.get("parameters") or {}
        heavy = meta.get("system") == "heavy_top" or "mass_gravity" in parameters or _has(result, "lab_momentum_z")
        return "heavy_top" if heavy else "rigid_body"
    if _has(result, "q"):
        return "constrained"
    raise InputError("the result has neither 'M' (rigid body) nor 'q' (constrained system) among its outputs: "
                     "add \"M\" or \"q\" to outputs in the scene's [run] table to draw it")


def _driven(result: Any, meta: Mapping[str, Any], kind: str, t: np.ndarray, M: np.ndarray, R: np.ndarray | None,
            inertia: Any, parameters: Mapping[str, Any]) -> Any:
    """The picture of a rigid body or heavy top driven by a torque or impulses."""
    from dirac.plots.rigid_body import driven_figure

    if _has(result, "energy"):
        energy = _first_body(_get(result, "energy"), 1)
    elif kind == "rigid_body":
        energy = 0.5 * np.sum(M * M / np.asarray(inertia, dtype=float), axis=1)
    else:
        raise InputError("a heavy top's picture under a torque needs the output 'energy'; add it to [run] outputs")
    work = _first_body(_get(result, "work"), 1) if _has(result, "work") else None
    heading = "heavy top" if kind == "heavy_top" else "rigid body"
    return driven_figure(t, M, R, inertia, energy, work, title=_title(meta, f"{heading} under a torque"))


def result_figure(result: Any, coordinates: Sequence[str] | None = None, problem: Any | None = None) -> Any:
    """The picture of one run, chosen by the kind of system; returns a matplotlib Figure.

    - free rigid body (``M``): polhode, body axes, ``M(t)`` and the errors of ``H_0``,
      ``|M|^2``, ``m = R M`` and ``R^T R`` (:func:`dirac.plots.rigid_body.rigid_body_figure`);
    - heavy top (``M`` with gravity): body axes, ``M(t)`` and the errors of the total
      energy, ``m_z`` and ``R^T R`` (:func:`dirac.plots.rigid_body.heavy_top_figure`);
    - constrained system (``q``): path, coordinates, the energy error and every
      constraint's residual (:func:`dirac.plots.constrained.constrained_figure`).

    Parameters
    ----------
    result : dirac.flows.Solution or mapping
        Anything with the outputs of a result file by name (``t`` and ``M``/``R`` or
        ``q``/``energy``/``constraint_residual``) and a ``meta`` record (dict, JSON
        string, or a ``meta()`` method). A batched result is drawn for its first state.
    coordinates : sequence of str, optional
        Names of the coordinates ``q`` (default: ``meta["coordinates"]``, the problem's
        names, else ``q_1 …``).
    problem : optional
        The problem that was integrated; for a constrained system it gives one residual
        curve per constraint (otherwise the run's largest residual is drawn).

    Raises
    ------
    dirac.errors.InputError
        If the result has neither ``M`` nor ``q``, or the rigid body's inertia is unknown.
    """
    if not _has(result, "t"):
        raise InputError("the result has no sample times 't'; nothing to draw")
    t = np.asarray(_get(result, "t"), dtype=float)
    meta = _meta(result)
    kind = _kind(result, meta)
    if kind in ("rigid_body", "heavy_top"):
        from dirac.plots.rigid_body import heavy_top_figure, rigid_body_figure

        parameters = meta.get("parameters") or {}
        inertia = parameters.get("inertia")
        if inertia is None:
            raise InputError("the result's meta has no parameters.inertia: cannot draw the energy ellipsoid")
        M = _first_body(_get(result, "M"), 2)
        R = _first_body(_get(result, "R"), 3) if _has(result, "R") else None
        if "torque" in parameters or "impulses" in parameters:
            return _driven(result, meta, kind, t, M, R, inertia, parameters)
        if kind == "rigid_body":
            return rigid_body_figure(t, M, R, inertia, title=_title(meta, "rigid body"))
        weight = None
        if "center_of_mass" in parameters:
            weight = float(parameters.get("mass_gravity", 1.0)) * np.asarray(parameters["center_of_mass"], dtype=float)
        energy = _first_body(_get(result, "energy"), 1) if _has(result, "energy") else None
        m_z = _first_body(_get(result, "lab_momentum_z"), 1) if _has(result, "lab_momentum_z") else None
        return heavy_top_figure(t, M, R, inertia, weight, energy=energy, lab_momentum_z=m_z,
                                title=_title(meta, "heavy top"))
    from dirac.plots.constrained import constrained_figure

    q = _first_body(_get(result, "q"), 2)
    energy = _first_body(_get(result, "energy"), 1) if _has(result, "energy") else None
    residual = _first_body(_get(result, "constraint_residual"), 1) if _has(result, "constraint_residual") else None
    work = _first_body(_get(result, "work"), 1) if _has(result, "work") else None
    names = list(coordinates) if coordinates is not None else meta.get("coordinates")
    if names is None:
        names = getattr(getattr(problem, "mechanics", None), "coordinate_names", None)
    conserved, time_dependent = _energy_curves(result, problem)
    return constrained_figure(t, q, energy=energy, constraint_residual=residual, names=names,
                              title=_title(meta, "constrained system", time_unit=""),
                              constraints=_constraint_residuals(result, problem),
                              energy_conserved=not time_dependent, conserved=conserved, work=work)


def plot(solution: Any, problem: Any | None = None, *, coordinates: Sequence[str] | None = None) -> Any:
    """Draw a run as a matplotlib Figure (``dirac.plot``), chosen by the kind of system.

    The panels show each system's own conserved quantities as errors against time on
    logarithmic axes (see :func:`result_figure`). Save the figure with
    ``fig.savefig("motion.pdf")`` (any format matplotlib writes) or show it in a notebook.

    Parameters
    ----------
    solution : dirac.Solution or mapping
        What :func:`dirac.integrate` returned, or a result file read by
        :func:`dirac.read_results` / :func:`load_result`.
    problem : optional
        The problem that was integrated (gives one residual curve per constraint).
    coordinates : sequence of str, optional
        Names of the coordinates of a constrained system.

    Returns
    -------
    matplotlib.figure.Figure

    Examples
    --------
    >>> import dirac
    >>> problem = dirac.RigidBodyProblem(inertia=[2.0, 1.5, 1.0], M0=[0.3, 0.2, 1.0])
    >>> fig = dirac.plot(dirac.integrate(problem, t_end=1.0, dt=0.1, method="lie-poisson-2"))
    >>> type(fig).__name__
    'Figure'
    """
    return result_figure(solution, coordinates, problem)


def plot_result(
    result: Any, path: str | Path, coordinates: Sequence[str] | None = None, problem: Any | None = None
) -> Path:
    """Draw ``result`` (see :func:`result_figure`) and write it to ``path``, in the format its suffix names.

    ``path`` is checked before any drawing, so a bad name fails fast.
    """
    target = check_plot_path(path)
    fig = result_figure(result, coordinates, problem)
    return save_figure(fig, target)
