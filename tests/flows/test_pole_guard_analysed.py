"""A run of an analysed system (the flow on the whole phase space) that reaches a pole stops and names it.

``L = x_dot^2/2 - log(x)`` analysed: ``H = p_x^2/2 + log(x)`` and the flow ``x_dot = p_x``,
``p_x_dot = -1/x``, whose pole ``x = 0`` is a denominator of ``grad H``. From ``x0 = 0.5`` at rest
the motion reaches it at ``t* = x0 sqrt(pi/2)`` (by hand, tests/flows/test_pole_guard.py). The
implicit midpoint step's Newton iteration fails next to the pole; the run used to stop with
"Newton iteration did not converge ...; reduce dt", which a smaller step does not cure.
"""

from __future__ import annotations

import math

import numpy as np
import pytest

import dirac
from dirac.errors import IntegrationError, PoleError
from dirac.flows import integrate
from dirac.flows.analysed import AnalysedProblem, AnalysedSystem
from dirac.flows.pole_guard import analysed_pole_guard

X0 = 0.5
T_STAR = X0 * math.sqrt(math.pi / 2)
DT = 0.01


def _analysed(lagrangian: str, parameters: dict[str, float] | None = None) -> AnalysedSystem:
    L = dirac.Lagrangian.from_strings("well", ["x"], lagrangian, [], parameters=parameters or {})
    return AnalysedSystem.from_analysis(dirac.analyze(L))


def _log_well(x0: float = X0) -> AnalysedProblem:
    analysed = _analysed("x_dot**2/2 - log(x)")
    return AnalysedProblem(analysed, analysed.initial_state({"x": x0}, q_dot={"x": 0.0}))


def test_the_guard_of_an_analysed_system_reads_the_pole_of_grad_h():
    """One factor, ``x``, a denominator of ``grad H`` (``dH/dx = 1/x``), read at the state ``(x, p_x)``;
    ``x = 0`` also ends the real domain of ``log(x)``."""
    guard = analysed_pole_guard(_log_well().analysed)
    assert guard is not None
    assert guard.factors == ["x"] and guard.origins == ["the gradient of the Hamiltonian"] and guard.bounds == [True]
    assert guard.read(np.array([0.25, 3.0]))[0, 0] == 0.25


@pytest.mark.parametrize("method", ["midpoint", "auto"])
def test_an_analysed_run_over_the_pole_stops_at_the_hand_time(method):
    """The run stops with a PoleError naming ``x = 0`` and ``grad H`` in the step that reaches ``t*``,
    with the remedy that fits a pole; the partial run keeps only samples before ``t*``, with ``x > 0``
    and the energy ``log(x0)`` of the start to 1e-3."""
    options = {} if method == "auto" else {"dt": DT}
    with pytest.raises(PoleError) as caught:
        integrate(_log_well(), method, t_end=1.0, samples=7, **options)
    error = caught.value
    text = str(error)
    assert "a denominator of the gradient of the Hamiltonian" in text and "regularise" in text
    assert "Newton" not in text
    step = max(DT, error.partial.dt)
    if "stepped across the pole x = 0" in text:  # a step landed beyond the pole
        start = float(text.split("between t = ")[1].split(" and")[0])
        end = float(text.split("between t = ")[1].split(" and t = ")[1].split(" ")[0])
        assert start <= T_STAR <= end <= start + 2 * step
    else:  # the Newton iteration of the step into the pole failed
        assert "pole of the equations of motion (x = " in text
        failed = float(text.split("a step failed at t = ")[1].split(" ")[0])
        assert failed <= T_STAR <= failed + 2 * step
    partial = error.partial
    assert not partial.complete and partial.t[-1] < T_STAR
    assert np.all(partial.outputs["z"][:, 0] > 0.0)
    assert np.max(np.abs(partial.outputs["energy"] - math.log(X0))) < 1e-3


def test_without_the_guard_the_refusal_asks_for_a_smaller_step(monkeypatch):
    """The mutation: without the guard the same run stops with the Newton failure's advice "reduce dt"
    (an IntegrationError that is not a PoleError), which does not cure a pole."""
    monkeypatch.setattr("dirac.flows.pole_guard.analysed_pole_guard", lambda analysed: None)
    with pytest.raises(IntegrationError, match="reduce dt") as caught:
        integrate(_log_well(), "midpoint", t_end=1.0, dt=DT, samples=7)
    assert not isinstance(caught.value, PoleError)


def test_a_pole_the_analysed_motion_stays_away_from_changes_no_bit(monkeypatch):
    """``V = x^2/2 - c log(a - x)``, ``a = 3``, ``c = 0.1``: from ``x = 1`` at rest the motion stays in
    ``|x| < 1.1`` (energy: ``V(x) <= V(1)`` there), far from the pole ``x = a`` of ``dV/dx``. The guard
    exists and is read, and the run is the same to the last bit as without it."""
    analysed = _analysed("x_dot**2/2 - x**2/2 + c*log(a - x)", {"a": 3.0, "c": 0.1})
    guard = analysed_pole_guard(analysed)
    assert guard is not None and guard.factors in (["a - x"], ["x - a"])
    z0 = analysed.initial_state({"x": 1.0}, q_dot={"x": 0.0})
    guarded = integrate(AnalysedProblem(analysed, z0), "midpoint", t_end=20.0, dt=0.01, samples=41)
    monkeypatch.setattr("dirac.flows.pole_guard.analysed_pole_guard", lambda analysed: None)
    bare = integrate(AnalysedProblem(analysed, z0), "midpoint", t_end=20.0, dt=0.01, samples=41)
    assert guarded.complete and bare.complete
    assert np.max(np.abs(guarded.outputs["z"][:, 0])) < 1.1
    for name in ("z", "energy"):
        assert np.array_equal(guarded.outputs[name], bare.outputs[name]), name


def test_an_analysed_system_without_denominators_has_no_guard():
    """The harmonic oscillator: ``grad H`` is linear, so no guard (and no derivative is taken)."""
    assert analysed_pole_guard(_analysed("x_dot**2/2 - x**2/2")) is None


def test_a_denominator_without_a_real_zero_is_not_read():
    """The relativistic oscillator ``L = -m c^2 sqrt(1 - x_dot^2/c^2) - k x^2/2``: ``H = sqrt(p^2 c^2 + m^2 c^4)
    + k x^2/2`` and ``dH/dp = p c^2 / sqrt(p^2 c^2 + m^2 c^4)``, whose denominator ``c^2 m^2 + p_x^2`` (with
    the values of ``m`` and ``c``) is positive for every real ``p_x``: no motion reaches a zero of it, so
    there is nothing to read and no guard."""
    analysed = _analysed("-m*c**2*sqrt(1 - x_dot**2/c**2) - k*x**2/2", {"m": 1.0, "c": 1.0, "k": 1.0})
    assert analysed_pole_guard(analysed) is None
