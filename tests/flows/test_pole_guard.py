"""A run whose motion reaches or steps across a pole of its equations of motion stops and says so.

``L = x_dot^2/2 - log(x)``: the potential ``V = log(x)`` pulls towards ``x = 0`` with the force
``-1/x``, and ``v^2/2 + log(x) = E`` makes the speed infinite there. From ``x0 = 0.5`` at rest,
``v^2/2 = log(x0) - log(x)``, so the motion reaches ``x = 0`` at (by hand)

    t* = integral_0^{x0} dx / sqrt(2 log(x0/x))
       = x0 integral_0^inf e^{-u} du / sqrt(2 u)        (x = x0 e^{-u})
       = x0 Gamma(1/2) / sqrt(2) = x0 sqrt(pi/2) = 0.626657...

(the quadrature of the first integral is checked below as well). The force ``-1/x`` is defined
on both sides of ``x = 0``, so a fixed step jumps over the pole: with ``dt = 0.01`` and 7
samples up to ``t = 1`` the runs used to finish with a relative energy jump above 1 and no word.
"""

from __future__ import annotations

import math

import numpy as np
import pytest

import dirac
from dirac.errors import IntegrationError, PoleError
from dirac.flows import ConstrainedProblem, integrate
from dirac.flows.pole_guard import pole_guard

X0 = 0.5
T_STAR = X0 * math.sqrt(math.pi / 2)  # module docstring
DT = 0.01


def _log_well() -> ConstrainedProblem:
    L = dirac.Lagrangian.from_strings("log_well", ["x"], "x_dot**2/2 - log(x)", [], parameters={})
    return ConstrainedProblem(L, q0=[X0], qdot0=[0.0])


def test_the_hand_time_of_arrival_agrees_with_a_quadrature():
    """``t* = x0 sqrt(pi/2)`` (module docstring) against the quadrature of ``dx / sqrt(2 log(x0/x))``
    over ``(0, x0)`` (an integrable singularity at each end)."""
    from scipy.integrate import quad

    value, error = quad(lambda x: 1.0 / math.sqrt(2.0 * math.log(X0 / x)), 0.0, X0, limit=200)
    assert error < 1e-7
    assert value == pytest.approx(T_STAR, rel=1e-7)


def test_the_guard_finds_the_pole_of_the_force():
    """``-dV/dx = -1/x``: one factor, ``x``, a denominator of the force; ``x = 0`` also ends the real
    domain of ``log(x)``."""
    guard = pole_guard(_log_well().mechanics)
    assert guard is not None
    assert guard.factors == ["x"] and guard.origins == ["the force -dV/dq"] and guard.bounds == [True]


@pytest.mark.parametrize("method", ["rattle-2", "midpoint", "auto"])
def test_a_run_over_the_pole_stops_at_the_hand_time(method):
    """Every method stops with a PoleError naming ``x = 0`` in the step that reaches ``t*``: the
    interval it names starts before ``t*`` and the run stopped within two steps after it; the
    partial run keeps only samples before ``t*``, all with ``x > 0`` and the energy of the start
    (``log(x0)``) to 1e-3. (``auto`` picks a composition of RATTLE whose stages jump over the pole
    and back inside one step: the guard sees ``x`` come within a step of 0, faster and faster, and
    go back.)"""
    options = {} if method == "auto" else {"dt": DT}
    with pytest.raises(PoleError, match=r"pole x = 0") as caught:
        integrate(_log_well(), method, t_end=1.0, samples=7, **options)
    error = caught.value
    text = str(error)
    assert "a smaller step does not cure this" in text and "regularise" in text
    if method != "auto":  # an approach that sped up to the crossing: no hedge about a turn before the pole
        assert "stepped across the pole x = 0" in text and "resolves the turn" not in text
    start = float(text.split("between t = ")[1].split(" and")[0])
    reached = error.partial.extra["t_reached"]
    assert start <= T_STAR < reached <= T_STAR + 2 * max(DT, error.partial.dt)
    partial = error.partial
    assert not partial.complete and partial.t[-1] < T_STAR
    assert np.all(partial.outputs["q"][:, 0] > 0.0)
    assert np.max(np.abs(partial.outputs["energy"] - math.log(X0))) < 1e-3


def test_without_the_guard_the_jump_completes_and_only_the_energy_watch_speaks(monkeypatch):
    """The mutation: with the guard disabled, the same run of ``rattle-2`` completes and its energy
    jumps by more than the whole initial energy ``|log(x0)|`` (the defect the guard cures); only the
    energy watch (``dirac.flows.energy_watch``) says that the energy changed."""
    monkeypatch.setattr("dirac.flows.pole_guard.pole_guard", lambda mechanics: None)
    with pytest.warns(dirac.DiracWarning, match="the energy of 'log_well' changed by"):
        solution = integrate(_log_well(), "rattle-2", t_end=1.0, dt=DT, samples=7)
    assert solution.complete
    energy = solution.outputs["energy"]
    assert energy[0] == pytest.approx(math.log(X0), rel=1e-12)
    assert np.max(np.abs(energy - energy[0])) / abs(energy[0]) > 1.0


def test_a_pole_reached_from_the_other_side_of_a_tangent():
    """``V = tan(q)`` from ``q = 0`` at rest: ``-dV/dq = -1/cos(q)^2`` pulls towards ``q = -pi/2``, where
    ``V -> -inf`` (by hand, ``v^2/2 = -tan(q)``: the speed is infinite there), reached at a finite time
    since ``integral dq / sqrt(-2 tan(q))`` converges at ``-pi/2`` (``tan(q) ~ 1/(q + pi/2)``). The
    factor found is ``cos(q)``, and the run stops naming ``cos(q) = 0``, its partial run inside
    ``(-pi/2, 0]``."""
    L = dirac.Lagrangian.from_strings("tangent", ["q"], "q_dot**2/2 - tan(q)", [], parameters={})
    problem = ConstrainedProblem(L, q0=[0.0], qdot0=[0.0])
    guard = pole_guard(problem.mechanics)
    assert guard is not None and guard.factors == ["cos(q)"]
    with pytest.raises(PoleError, match=r"pole cos\(q\) = 0") as caught:
        integrate(problem, "rattle-2", t_end=5.0, dt=0.01, samples=51)
    q = caught.value.partial.outputs["q"][:, 0]
    assert np.all((q > -math.pi / 2) & (q <= 0.0))


def _away_from_the_pole() -> ConstrainedProblem:
    L = dirac.Lagrangian.from_strings("near_pole", ["x"], "x_dot**2/2 - x**2/2", [], parameters={"a": 3.0, "c": 0.1},
                                      forces={"x": "c/(x - a)"})
    return ConstrainedProblem(L, q0=[1.0], qdot0=[0.0])


def test_a_force_pole_the_motion_stays_away_from_changes_no_bit(monkeypatch):
    """A harmonic oscillator of amplitude about 1 with the force ``c/(x - a)``, ``a = 3``: the motion
    stays in ``|x| <= 1.1`` (the force is below ``c/1.9`` in size), far from the pole ``x = 3``. The guard
    exists (the factor ``x - a`` of the applied force) and is read, and the run is the same to the
    last bit as without it."""
    guard = pole_guard(_away_from_the_pole().mechanics)
    assert guard is not None and guard.factors == ["a - x"] and guard.origins == ["the applied forces"]
    guarded = integrate(_away_from_the_pole(), "rattle-2", t_end=20.0, dt=0.01, samples=41)
    monkeypatch.setattr("dirac.flows.pole_guard.pole_guard", lambda mechanics: None)
    bare = integrate(_away_from_the_pole(), "rattle-2", t_end=20.0, dt=0.01, samples=41)
    assert guarded.complete and bare.complete
    assert np.max(np.abs(guarded.outputs["q"])) < 1.1
    for name in ("q", "p", "energy", "work"):
        assert np.array_equal(guarded.outputs[name], bare.outputs[name]), name
    assert guarded.steps == bare.steps


def test_a_system_without_denominators_has_no_guard():
    """The pendulum in Cartesian coordinates: polynomials only, so no guard (and no derivative is taken)."""
    problem = ConstrainedProblem(dirac.load_system("pendulum"), q0=[0.6, -0.8], qdot0=[0.0, 0.0])
    assert pole_guard(problem.mechanics) is None


def test_a_scene_over_the_pole_is_one_error_line_and_keeps_its_partial_run(tmp_path, run_cli):
    """``dirac run`` of the log well: exit 2, one ``error:`` line naming ``x = 0``, and the partial run
    saved with ``complete = false`` and only samples before ``t*``."""
    from cli_output import one_error_line

    (tmp_path / "well.toml").write_text(
        '[system]\nname = "log_well"\ncoordinates = ["x"]\nlagrangian = "x_dot**2/2 - log(x)"\n')
    scene = tmp_path / "scene.toml"
    scene.write_text('[system]\nfile = "well.toml"\n[initial]\nq = { x = 0.5 }\nq_dot = { x = 0.0 }\n'
                     '[run]\nt_end = 1.0\nmethod = "rattle-2"\ndt = 0.01\nsamples = 7\noutputs = ["q", "energy"]\n')
    out = tmp_path / "result.npz"
    status, _out, err = run_cli("run", str(scene), "--out", str(out), "--no-progress")
    line = one_error_line(status, err)
    assert "pole x = 0" in line and str(out) in line
    with np.load(out) as data:
        assert data["t"][-1] < T_STAR and np.all(data["q"][:, 0] > 0.0)
        assert '"complete": false' in str(data["meta"])


def test_a_pole_error_is_an_integration_error():
    """Callers that catch IntegrationError (the command line, scripts) keep catching it."""
    assert issubclass(PoleError, IntegrationError)


def test_a_sign_change_between_readings_far_from_the_pole_is_caught():
    """No reading near the pole is needed: ``x`` read at 1, then at -1 a thousand steps later, has
    changed sign, so the motion crossed ``x = 0`` in between (intermediate value theorem: ``x(t)`` is
    continuous), and the reading says so, naming both values and both times."""
    from dirac.flows.pole_guard import PoleCrossing

    guard = pole_guard(_log_well().mechanics)
    assert guard is not None
    guard.start(np.array([1.0]), 0.0, 0)
    with pytest.raises(PoleCrossing, match=r"stepped across the pole x = 0 \(x went from 1 to -1") as caught:
        guard.check(np.array([-1.0]), 10.0, 1000, 1000)
    assert "between t = 0 and t = 10 (steps 0 to 1000)" in str(caught.value)


def test_a_batch_names_the_member_that_meets_the_pole():
    """Two members of the log well, ``x0 = 0.5`` (``t* = 0.627``) and ``x0 = 2`` (``t* = 2.51``, module
    docstring): the run stops at the first one's pole, naming member 0, and keeps both members' samples
    before it."""
    L = dirac.Lagrangian.from_strings("log_well", ["x"], "x_dot**2/2 - log(x)", [], parameters={})
    problem = ConstrainedProblem(L, q0=[[0.5], [2.0]], qdot0=[[0.0], [0.0]])
    with pytest.raises(PoleError, match=r"member 0 of the batch\) stepped across the pole x = 0") as caught:
        integrate(problem, "rattle-2", t_end=1.0, dt=DT, samples=7)
    q = caught.value.partial.outputs["q"]
    assert q.shape == (4, 2, 1) and caught.value.partial.t[-1] < T_STAR and np.all(q > 0.0)


def test_a_pole_in_time_is_named():
    """The force ``c/(t - 1/2)`` on a free particle has a pole at ``t = 1/2`` whatever the motion: the run
    stops there (its step fails next to it, or steps across it) naming the factor ``2*t - 1``, with the
    samples before ``t = 1/2``."""
    L = dirac.Lagrangian.from_strings("pole_in_time", ["x"], "x_dot**2/2", [], parameters={"c": 0.01},
                                      forces={"x": "c/(t - 0.5)"})
    with pytest.raises(PoleError, match=r"2\*t - 1") as caught:
        integrate(ConstrainedProblem(L, q0=[0.0], qdot0=[1.0]), "rattle-2", t_end=1.0, dt=0.01, samples=11)
    assert caught.value.partial.t[-1] == pytest.approx(0.4)


def _repelled(dt: float):
    L = dirac.Lagrangian.from_strings("repelled", ["x"], "x_dot**2/2 - c/x", [], parameters={"c": 1e-3})
    return integrate(ConstrainedProblem(L, q0=[1.0], qdot0=[-1.0]), "rattle-2", t_end=2.0, dt=dt, samples=5)


def test_a_repelling_pole_a_step_does_not_resolve_is_named_with_the_smaller_step():
    """``V = c/x``, ``c = 1e-3``, thrown from ``x = 1`` towards the pole at speed 1: energy conservation
    ``v^2/2 + c/x = 1/2 + c`` turns the exact motion at ``x_min = c/(1/2 + c) ~ 2e-3`` (by hand), a fifth of
    the step ``dt = 0.01`` travels. That step lands at ``x ~ 5e-4``, where the force ``c/x^2`` is
    thousands, and the run used to finish with its energy 1000 times the true one. It stops, saying the
    steps do not resolve the motion at the pole and that a smaller ``dt`` resolves a turn before it;
    with ``dt = 1e-3`` the run completes and keeps the energy ``1/2 + c`` to 1e-2."""
    with pytest.raises(PoleError, match=r"came within a step of the pole x = 0") as caught:
        _repelled(0.01)
    assert "a smaller dt resolves the turn" in str(caught.value)
    solution = _repelled(1e-3)
    assert solution.complete
    assert np.max(np.abs(solution.outputs["energy"] - (0.5 + 1e-3))) < 1e-2


def test_a_removable_singularity_is_no_pole_and_the_motion_passes_it():
    """``V = -sin(x)/x``: its force ``(x cos x - sin x)/x^2`` has the denominator ``x`` but stays bounded at
    ``x = 0`` (``-x/3 + O(x^3)``), so the motion oscillates through it. From ``x = 1`` at rest the energy is
    ``E = -sin(1)`` and, by symmetry of ``V``, the motion reaches ``x = -1`` at half its period,
    ``T/2 = 2 integral_0^1 dx / sqrt(2 (sin(x)/x - sin(1)))`` (quadrature here). ``V = (x^2 - x)/(x - 1)``
    is ``x``: the factor cancels, and ``x = 2 - t - t^2/2`` from ``x = 2`` at speed ``-1`` passes ``x = 1``."""
    from scipy.integrate import quad

    sinc = dirac.Lagrangian.from_strings("sinc_well", ["x"], "x_dot**2/2 + sin(x)/x", [], parameters={})
    problem = ConstrainedProblem(sinc, q0=[1.0], qdot0=[0.0])
    assert pole_guard(problem.mechanics) is None
    half = 2 * quad(lambda x: 1 / math.sqrt(2 * (math.sin(x) / x - math.sin(1.0))), 0.0, 1.0, limit=200)[0]
    run = integrate(problem, "rattle-4", t_end=half, dt=half / 2000, samples=2)
    assert run["q"][-1, 0] == pytest.approx(-1.0, abs=1e-6)
    cancelled = dirac.Lagrangian.from_strings("cancelled", ["x"], "x_dot**2/2 - (x**2 - x)/(x - 1)", [], parameters={})
    problem = ConstrainedProblem(cancelled, q0=[2.0], qdot0=[-1.0])
    assert pole_guard(problem.mechanics) is None
    run = integrate(problem, "rattle-2", t_end=3.0, dt=0.01, samples=4)
    assert np.allclose(run["q"][:, 0], [2.0 - t - t * t / 2 for t in (0.0, 1.0, 2.0, 3.0)], atol=1e-9)


def test_a_pole_under_a_root_is_still_a_pole():
    """``V = -(x**2)**(1/4) = -sqrt(|x|)`` gives a force that grows like ``|x|^(-1/2)`` at ``x = 0``: a pole
    (the growth between the distances read is ``1000^(1/2) = 32``, above the threshold 10), kept as the
    factor ``Abs(x)`` (sympy writes the root of ``x**2`` with it)."""
    root = dirac.Lagrangian.from_strings("quarter", ["x"], "x_dot**2/2 + (x**2)**(1/4)", [], parameters={})
    guard = pole_guard(ConstrainedProblem(root, q0=[1.0], qdot0=[0.0]).mechanics)
    assert guard is not None and guard.factors == ["Abs(x)"]


#: ``V = -1/x`` from ``x = 1`` at rest reaches ``x = 0`` at ``t* = pi / (2 sqrt(2))`` (by hand: the radial
#: Kepler fall, ``t* = (pi/2) sqrt(x0^3 / (2 k))`` with ``k = 1``)
T_FALL = math.pi / (2.0 * math.sqrt(2.0))


def _fall(road: str, potential: str = "-1/x"):
    L = dirac.Lagrangian.from_strings("fall", ["x"], f"x_dot**2/2 - ({potential})", [], parameters={})
    if road == "constrained":
        return ConstrainedProblem(L, q0=[1.0], qdot0=[0.0])
    from dirac.flows.analysed import AnalysedProblem, AnalysedSystem

    analysed = AnalysedSystem.from_analysis(dirac.analyze(L))
    return AnalysedProblem(analysed, analysed.initial_state({"x": 1.0}, q_dot={"x": 0.0}))


@pytest.mark.parametrize("road", ["constrained", "analysed"])
def test_a_failed_step_in_a_fall_into_a_1_over_r_pole_names_the_pole(road):
    """``V = -1/x`` from ``x = 1`` at rest with ``midpoint``, ``dt = 0.01``: the Newton iteration fails at
    ``x = 0.078``, about one step before ``t*`` (module constant), where the rate of the last steps (a
    secant, which lags the fall ``x ~ (t* - t)^(2/3)``) put the pole three steps away and the run used to
    stop with "reduce dt". It stops with a PoleError at the step before ``t*``, judged by that fall, and
    with the hedge that a smaller step resolves a turn before the pole."""
    with pytest.raises(PoleError, match=r"falls as \(t\* - t\)\^0\.67") as caught:
        integrate(_fall(road), "midpoint", t_end=3.0, dt=0.01, samples=7)
    text = str(caught.value)
    failed = float(text.split("a step failed at t = ")[1].split(" ")[0])
    assert failed <= T_FALL <= failed + 2 * 0.01
    assert "pole of the equations of motion (x = " in text and "a smaller dt resolves the turn" in text


def test_a_close_pass_a_step_fails_at_is_named_with_the_smaller_step():
    """``V = -1/x + 0.01/x^2`` from ``x = 1`` at rest: energy ``-0.99`` turns the motion at
    ``x_min = (1 - sqrt(1 - 0.0396)) / 1.98 = 0.0101`` (by hand), a close pass, not a fall into ``x = 0``.
    With ``dt = 0.01`` the midpoint step fails next to it; the PoleError hedges that a smaller step
    resolves a turn, and with ``dt = 1e-4`` the run passes and keeps the energy to 1e-6."""
    with pytest.raises(PoleError, match=r"a step failed at t = .* next to a pole") as caught:
        integrate(_fall("constrained", "-1/x + 0.01/x**2"), "midpoint", t_end=1.5, dt=0.01, samples=4)
    assert "a smaller dt resolves the turn" in str(caught.value)
    solution = integrate(_fall("constrained", "-1/x + 0.01/x**2"), "midpoint", t_end=1.5, dt=1e-4, samples=4)
    assert solution.complete
    assert np.max(np.abs(solution.outputs["energy"] + 0.99)) < 1e-6
