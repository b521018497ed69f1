"""The member loop's reductions read the sines and cosines the RATTLE step has just evaluated."""

from __future__ import annotations

import numpy as np
import pytest
import sympy

from dirac.ensemble import general_kernel
from dirac.ensemble.general_chunk import initial_states, step_grid
from dirac.ensemble.general_scene import parse_general_scene
from dirac.ensemble.step_transcendentals import step_transcendentals, substitute_transcendentals

ANGLES = {"name": "double_pendulum_angles", "coordinates": ["th1", "th2"],
          "parameters": {"m1": 1.0, "m2": 1.0, "g": 9.81, "l1": 1.0, "l2": 1.0},
          "lagrangian": "(m1 + m2)/2*l1**2*th1_dot**2 + m2/2*l2**2*th2_dot**2"
                        " + m2*l1*l2*th1_dot*th2_dot*cos(th1 - th2) + (m1 + m2)*g*l1*cos(th1) + m2*g*l2*cos(th2)"}


def _scene(method: str, side: int = 5, t_end: float = 3.0) -> object:
    """Heyl's flip map in angles (x1 = l1 sin th1 crossing zero with y1 = -l1 cos th1 > 0, ...)
    plus extrema of expressions of the angles and of the velocities (the velocity reads w too)."""
    return parse_general_scene({
        "system": ANGLES, "initial": {"q": {"th1": "a", "th2": "b"}},
        "run": {"method": method, "dt": 0.004, "t_end": t_end},
        "ensemble": {"grid": {"a": [-3.0, 3.0, side], "b": [-3.0, 3.0, side]},
                     "reductions": [
                         {"kind": "first_crossing", "name": "flip_time", "expr": ["l1*sin(th1)", "l2*sin(th2)"],
                          "when": ["-l1*cos(th1) > 0", "-l2*cos(th2) > 0"]},
                         {"kind": "max", "name": "top", "expr": "sin(th1 - th2) + 2*cos(th1 - th2)"},
                         {"kind": "min", "name": "low", "expr": "th1_dot*cos(th1 - th2) + sin(th2)"}]},
    })


def _run(compiled: general_kernel.CompiledEnsemble, scene: object) -> list[np.ndarray]:
    Q, P, C = initial_states(scene, compiled, scene.source.members(0, scene.count))
    starts, ends, per, dt = step_grid(scene)
    shapes = compiled.module.ENS_SHAPES
    count, n = Q.shape
    arrays = [np.full((count, shapes[0]), np.nan), np.full((count, shapes[1]), np.nan), np.full(count, np.nan),
              np.full(count, np.nan), np.full((count, shapes[2], shapes[3]), np.nan),
              np.full((count, shapes[2], shapes[3], n), np.nan), np.full((count, shapes[2], shapes[3], n), np.nan),
              np.zeros(count), np.zeros(count)]
    compiled.module.ens_run(0, count, Q, P, C, compiled.fractions, dt, starts, ends, per, scene.newton_tolerance,
                            scene.max_newton_iterations, compiled.gamma, scene.early_stop, *arrays, 2)
    return [Q, P, *arrays]


@pytest.mark.parametrize("method", ["rattle-2", "rattle-4"])
def test_reductions_from_the_step_equal_those_computed_again(monkeypatch, method):
    """The member loop that reads sin(th1), sin(th2), sin(th1 - th2) and cos(th1 - th2) (and
    v = M^-1 p) from the step's w gives the same bits as the one that evaluates them again at
    the member's state after each step: w holds them at that state (the step's last evaluation
    is at its final q). A stale w -- one configuration behind -- would move every extremum and
    crossing time. rattle-4 has three sub-steps per step: w is the last one's."""
    scene = _scene(method)
    monkeypatch.setattr(general_kernel, "REUSE_STEP_TRANSCENDENTALS", True)
    reading = general_kernel._build(scene)
    monkeypatch.setattr(general_kernel, "REUSE_STEP_TRANSCENDENTALS", False)
    computing = general_kernel._build(scene)
    source = open(reading.module.__file__).read()
    assert "ens_values_w(q, p, m_v, w, tb, c, m_f)" in source and "velocity_w(q, p, w, tb, c, m_v" in source
    assert "ens_values_w" not in open(computing.module.__file__).read()
    first, second = _run(reading, scene), _run(computing, scene)
    for a, b in zip(first, second):
        assert np.array_equal(a, b, equal_nan=True)
    flips = first[2][:, 0]
    assert 5 <= np.isfinite(flips).sum() < scene.count  # some members flip, some do not


def test_the_entries_of_w_are_read_back_from_the_module():
    """The double pendulum in angles: M has cos(th1 - th2), the force sin(th1), sin(th2) and
    sin(th1 - th2) (dV/dth1 = (m1 + m2) g l1 sin th1, dV/dth2 = m2 g l2 sin th2; d/dth of the
    coupling m2 l1 l2 cos(th1 - th2)): those four, whatever their order."""
    from dirac.ensemble.general_scene import load_lagrangian
    from dirac.flows import MechanicalSystem

    lagrangian = load_lagrangian(ANGLES, ".")
    mechanics = MechanicalSystem.from_lagrangian(lagrangian)
    th1, th2 = lagrangian.coordinates
    entries = step_transcendentals(mechanics.module.source, lagrangian.coordinates, lagrangian.parameters,
                                   sympy.Dummy("t"))
    assert entries is not None
    assert set(entries) == {sympy.cos(th1 - th2), sympy.sin(th1), sympy.sin(th2), sympy.sin(th1 - th2)}


def test_unknown_code_and_time_dependent_entries_are_not_read():
    """Anything but plain straight-line code gives None (the reductions then compute their
    functions themselves); an entry that depends on the time is never substituted (the step
    leaves w at its last stage's time, not the member loop's step time)."""
    q0, w, t = sympy.symbols("q0 w t", real=True)
    plain = ('\n@numba.njit\ndef transcendentals(q, t, c, out):\n    """doc"""\n    q0_ = q[0]\n'
             "    out[0] = math.sin((1.0/2.0)*q0_)\n    out[1] = math.cos(c[0]*t)\n")
    entries = step_transcendentals(plain, [q0], [w], t)
    assert entries == [sympy.sin(q0 / 2), sympy.cos(w * t)]
    for odd in ("    out[0] = math.gamma(q0_)\n", "    out[0] = q0_ if q0_ > 0 else 0.0\n", "    for i in range(2):\n"):
        assert step_transcendentals(plain.replace("    out[0] = math.sin((1.0/2.0)*q0_)\n", odd), [q0], [w], t) is None
    assert step_transcendentals("def other(q):\n    return q\n", [q0], [w], t) is None
    substituted, symbols = substitute_transcendentals([3 * sympy.sin(q0 / 2) + sympy.cos(w * t)], entries, {q0, w})
    assert substituted == [3 * symbols[0] + sympy.cos(w * t)]
    assert substitute_transcendentals([sympy.cos(w * t) + q0], entries, {q0, w}) is None
