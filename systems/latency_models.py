"""Everyday systems as a new user writes them: the corpus of ``dirac bench --latency``.

Generalized coordinates with configuration-dependent inertia ``a_rs(q)`` (pendulums in
angles, tops in Euler angles, a bead on a turning hoop), the same pendulums in Cartesian
coordinates with rod constraints, and a relativistic particle (a Lagrangian that is not
quadratic in the velocities, integrated on its analysed flow). Each function returns a
:class:`LatencyModel`; :data:`MODELS` names them. Never imported by the engine.

References for the Lagrangians: Goldstein, Poole & Safko, *Classical Mechanics* (3rd ed.),
Sect. 1.6 (bead on a rotating hoop, its Jacobi integral in Sect. 2.7), Sect. 5.7 (the heavy
symmetric top in Euler angles, eq. 5.59) and Sect. 7.9 (the relativistic Lagrangian
``-m c^2 sqrt(1 - v^2/c^2)``); Landau & Lifshitz, *Mechanics*, Sect. 5 (double pendulum).
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass, field

import numpy as np

from dirac.model.lagrangian import Lagrangian

__all__ = ["LatencyModel", "MODELS"]


@dataclass(frozen=True)
class LatencyModel:
    """One system of the corpus and how a user runs it.

    Attributes
    ----------
    system : Lagrangian
    state : list of float
        ``q0 + p0`` (road ``"constrained"``) or ``z0`` (road ``"analysed"``).
    road : str
        ``"constrained"``: ``ConstrainedProblem(system, q0, p0)``; ``"analysed"``:
        ``dirac.analyze`` then ``AnalysedProblem`` (systems RATTLE cannot take).
    first_method, first_dt : str or None, float or None
        The first run (``t_end = 1``): None is the default method.
    conserved : str
        What the energy output is: ``"energy"`` or ``"Jacobi integral"``.
    baseline : str or None
        The name of the hand-written scipy right-hand side of the same motion
        (:mod:`dirac.bench.latency`), for pendulum-like systems; else None.
    angles : callable or None
        ``q`` at the output samples (samples, n) -> the baseline's angles (samples, k), so
        that both runs are compared with one reference; None without a baseline.
    """

    system: Lagrangian
    state: list[float]
    road: str = "constrained"
    first_method: str | None = None
    first_dt: float | None = None
    conserved: str = "energy"
    baseline: str | None = None
    notes: dict[str, str] = field(default_factory=dict)
    angles: Callable[[np.ndarray], np.ndarray] | None = None


_PENDULUM = {"m": 1.0, "g": 9.81, "l": 1.0}


def _same(q: np.ndarray) -> np.ndarray:
    """The coordinates are the angles."""
    return q


def _rod_angles(q: np.ndarray) -> np.ndarray:
    """Angles from the downward vertical of the rods of a chain of bobs ``(x1, y1, x2, y2, ...)``
    hanging from the origin: ``atan2(dx, -dy)`` of each rod (unwrapped along the samples)."""
    bobs = np.concatenate([np.zeros((q.shape[0], 2)), q], axis=1).reshape(q.shape[0], -1, 2)
    rods = np.diff(bobs, axis=1)
    return np.unwrap(np.arctan2(rods[..., 0], -rods[..., 1]), axis=0)
_DOUBLE = {"m1": 1.0, "m2": 1.0, "g": 9.81, "l1": 1.0, "l2": 1.0}


def pendulum_angle() -> LatencyModel:
    """Planar pendulum in its angle: ``L = m l^2/2 th_dot^2 + m g l cos th``."""
    system = Lagrangian.from_strings("pendulum_angle", ["th"], "m*l**2/2*th_dot**2 + m*g*l*cos(th)", parameters=_PENDULUM)
    return LatencyModel(system, [1.0, 0.0], baseline="pendulum", angles=_same)


def double_pendulum_angles() -> LatencyModel:
    """Double pendulum in its two angles (Landau & Lifshitz Sect. 5):
    ``L = (m1+m2)/2 l1^2 a_dot^2 + m2/2 l2^2 b_dot^2 + m2 l1 l2 a_dot b_dot cos(a-b)
    + (m1+m2) g l1 cos a + m2 g l2 cos b``."""
    system = Lagrangian.from_strings(
        "double_pendulum_angles", ["a", "b"],
        "(m1+m2)/2*l1**2*a_dot**2 + m2/2*l2**2*b_dot**2 + m2*l1*l2*a_dot*b_dot*cos(a-b)"
        " + (m1+m2)*g*l1*cos(a) + m2*g*l2*cos(b)", parameters=_DOUBLE)
    return LatencyModel(system, [1.0, 0.5, 0.0, 0.0], baseline="double_pendulum", angles=_same)


def triple_pendulum_angles() -> LatencyModel:
    """Triple pendulum of unit masses and rods in its three angles: the kinetic energy of
    the three bobs ``x_k = sum_{j<=k} (sin q_j, -cos q_j)``."""
    kinetic = ("3/2*a_dot**2 + b_dot**2 + 1/2*c_dot**2 + 2*a_dot*b_dot*cos(a-b) + a_dot*c_dot*cos(a-c)"
               " + b_dot*c_dot*cos(b-c)")
    system = Lagrangian.from_strings("triple_pendulum_angles", ["a", "b", "c"],
                                     f"m*l**2*({kinetic}) + m*g*l*(3*cos(a) + 2*cos(b) + cos(c))", parameters=_PENDULUM)
    return LatencyModel(system, [1.0, 0.5, 0.2, 0.0, 0.0, 0.0])


def pendulum_cartesian() -> LatencyModel:
    """The planar pendulum in Cartesian coordinates with its rod ``x^2 + y^2 = l^2``."""
    system = Lagrangian.from_strings("pendulum_cartesian", ["x", "y"], "m/2*(x_dot**2 + y_dot**2) - m*g*y",
                                     constraints=["x**2 + y**2 - l**2"], parameters=_PENDULUM)
    return LatencyModel(system, [0.8414709848078965, -0.5403023058681398, 0.0, 0.0], baseline="pendulum",
                        angles=_rod_angles)


def double_pendulum_cartesian() -> LatencyModel:
    """The double pendulum in Cartesian coordinates with two rod constraints."""
    system = Lagrangian.from_strings(
        "double_pendulum_cartesian", ["x1", "y1", "x2", "y2"],
        "m1/2*(x1_dot**2 + y1_dot**2) + m2/2*(x2_dot**2 + y2_dot**2) - g*(m1*y1 + m2*y2)",
        constraints=["x1**2 + y1**2 - l1**2", "(x2 - x1)**2 + (y2 - y1)**2 - l2**2"], parameters=_DOUBLE)
    s1, c1, s2, c2 = 0.8414709848078965, 0.5403023058681398, 0.479425538604203, 0.8775825618903728
    return LatencyModel(system, [s1, -c1, s1 + s2, -c1 - c2, 0.0, 0.0, 0.0, 0.0], baseline="double_pendulum",
                        angles=_rod_angles)


def symmetric_top_euler() -> LatencyModel:
    """Heavy symmetric top in Euler angles (Goldstein eq. 5.59):
    ``L = I1/2 (th_dot^2 + ph_dot^2 sin^2 th) + I3/2 (ps_dot + ph_dot cos th)^2 - M g l cos th``;
    ``rattle-2`` with ``dt = 1e-3`` for the first result."""
    system = Lagrangian.from_strings(
        "symmetric_top_euler", ["ph", "th", "ps"],
        "I1/2*(th_dot**2 + ph_dot**2*sin(th)**2) + I3/2*(ps_dot + ph_dot*cos(th))**2 - M*g*l*cos(th)",
        parameters={"I1": 1.0, "I3": 0.5, "M": 1.0, "g": 9.81, "l": 1.0})
    return LatencyModel(system, [0.0, 0.5, 0.0, 0.3, 0.0, 2.0], first_method="rattle-2", first_dt=1e-3)


def asymmetric_top_euler() -> LatencyModel:
    """Heavy asymmetric top in Euler angles: body angular velocities
    ``w1 = ph_dot sin th sin ps + th_dot cos ps``, ``w2 = ph_dot sin th cos ps - th_dot sin ps``,
    ``w3 = ps_dot + ph_dot cos th`` (Goldstein eq. 4.87), ``L = sum I_k w_k^2 / 2 - M g l cos th``."""
    w1 = "(ph_dot*sin(th)*sin(ps) + th_dot*cos(ps))"
    w2 = "(ph_dot*sin(th)*cos(ps) - th_dot*sin(ps))"
    w3 = "(ps_dot + ph_dot*cos(th))"
    system = Lagrangian.from_strings(
        "asymmetric_top_euler", ["ph", "th", "ps"],
        f"I1/2*{w1}**2 + I2/2*{w2}**2 + I3/2*{w3}**2 - M*g*l*cos(th)",
        parameters={"I1": 1.0, "I2": 0.8, "I3": 0.5, "M": 1.0, "g": 9.81, "l": 1.0})
    return LatencyModel(system, [0.0, 0.7, 0.3, 0.3, 0.1, 2.0], first_method="rattle-2", first_dt=1e-3)


def bead_on_rotating_hoop() -> LatencyModel:
    """A bead on a hoop of radius R turning at the rate w about its vertical diameter, in its
    angle from the bottom (Goldstein Sect. 2.7): ``L = m R^2/2 (th_dot^2 + w^2 sin^2 th)
    + m g R cos th``; the energy output ``H = m R^2/2 th_dot^2 - m R^2 w^2/2 sin^2 th -
    m g R cos th`` is the Jacobi integral, not the energy in the lab."""
    system = Lagrangian.from_strings("bead_on_rotating_hoop", ["th"],
                                     "m*R**2/2*(th_dot**2 + w**2*sin(th)**2) + m*g*R*cos(th)",
                                     parameters={"m": 1.0, "R": 1.0, "w": 4.0, "g": 9.81})
    return LatencyModel(system, [0.3, 0.5], conserved="Jacobi integral")


def relativistic_oscillator() -> LatencyModel:
    """A relativistic particle in a harmonic well (Goldstein Sect. 7.9):
    ``L = -m c^2 sqrt(1 - x_dot^2/c^2) - k x^2/2``, ``H = sqrt(p^2 c^2 + m^2 c^4) + k x^2/2``;
    not quadratic in the velocity, so it runs on its analysed flow (``midpoint``)."""
    system = Lagrangian.from_strings("relativistic_oscillator", ["x"], "-m*c**2*sqrt(1 - x_dot**2/c**2) - k*x**2/2",
                                     parameters={"m": 1.0, "c": 1.0, "k": 1.0})
    return LatencyModel(system, [1.0, 0.0], road="analysed")


MODELS: dict[str, Callable[[], LatencyModel]] = {
    "pendulum_angle": pendulum_angle,
    "double_pendulum_angles": double_pendulum_angles,
    "triple_pendulum_angles": triple_pendulum_angles,
    "pendulum_cartesian": pendulum_cartesian,
    "double_pendulum_cartesian": double_pendulum_cartesian,
    "symmetric_top_euler": symmetric_top_euler,
    "asymmetric_top_euler": asymmetric_top_euler,
    "bead_on_rotating_hoop": bead_on_rotating_hoop,
    "relativistic_oscillator": relativistic_oscillator,
}
