"""Flows of a gauge system: free multipliers chosen by the user, and gauge-fixed flows.

Christ-Lee model (gauge_system, k = 1), by hand: on the constraint surface the Gauss law
J = y p_x - x p_y = 0 says the angular momentum vanishes, so the motion is radial along a
fixed direction n: (x, y) = r(t) n, p = r_dot n, with r_ddot = -r, and

    r(t)^2 = (r0 cos t + pr0 sin t)^2,    H_c = (pr0^2 + r0^2)/2,

whatever the free multiplier u of p_z (z_dot = u only turns the frame: the gauge
transformation). In the gauge y = 0 (with z = 0) the reduced system is the oscillator
(x, p_x); in the gauge y = x (with z = 0) it is x = y = s, p_x = p_y = pi with
{s, pi}_D = 1/2, the same motion along the diagonal. Every rotation gauge is singular at
the origin, which this motion reaches at tan t = -r0/pr0 (t = 2.03 for r0 = 1, pr0 = 0.5),
so the gauge-fixed runs stop before it.
"""

from __future__ import annotations

import numpy as np
import pytest

import dirac
from dirac.flows.analysed import AnalysedProblem, AnalysedSystem

R0, PR0, T_END = 1.0, 0.5, 1.5


@pytest.fixture(scope="module")
def christ_lee():
    return dirac.analyze(dirac.load_system("gauge_system", k=1.0))


def _radius2(solution):
    z = solution["z"]
    return z[:, 0] ** 2 + z[:, 1] ** 2


def _unfixed_start(system):
    n = np.array([0.6, 0.8])
    return system.initial_state({"x": R0 * n[0], "y": R0 * n[1], "z": 0.3}, p={"x": PR0 * n[0], "y": PR0 * n[1]})


def test_energy_and_gauss_law_do_not_depend_on_the_free_multiplier(christ_lee):
    """Implicit midpoint keeps quadratic invariants exactly: J, and H_c - z J (the
    oscillator energy), so H_c is the same to round-off for every constant u. (A u that
    depends on the phase-space point adds u p_z to H, which is not quadratic: then the
    midpoint rule keeps H_c only to its O(dt^2) error.)"""
    runs = []
    for u in (None, {"u_1": 0.7}, {"u_1": -1.3}):
        system = AnalysedSystem.from_analysis(christ_lee, u)
        sol = dirac.integrate(AnalysedProblem(system, _unfixed_start(system)), "midpoint", t_end=3.0, dt=0.01,
                              samples=31, outputs=["z", "energy"])
        z = sol["z"]
        runs.append((sol["energy"], z[:, 1] * z[:, 3] - z[:, 0] * z[:, 4], z[:, 2]))
    (e0, j0, z0), (e1, j1, z1), (e2, j2, z2) = runs
    assert np.max(np.abs(e1 - e0)) < 1e-13 and np.max(np.abs(e2 - e0)) < 1e-13
    assert np.max(np.abs(e0 - (PR0**2 + R0**2) / 2)) < 1e-13
    assert np.max(np.abs(np.concatenate([j0, j1, j2]))) < 1e-13
    assert np.max(np.abs(z1 - z0)) > 1.0  # the gauge variable itself does depend on u


def test_radius_does_not_depend_on_the_free_multiplier(christ_lee):
    """r^2 is gauge invariant: with DOP853 at tolerance 1e-13 three choices of u (one a
    phase-space function) agree to 1e-11 and follow the closed form (r0 cos t + pr0 sin t)^2."""
    radii = []
    for u in (None, {"u_1": 0.7}, {"u_1": "x*p_y - 0.4"}):
        system = AnalysedSystem.from_analysis(christ_lee, u)
        sol = dirac.integrate(AnalysedProblem(system, _unfixed_start(system)), "scipy-DOP853", t_end=3.0,
                              tolerance=1e-13, samples=31, outputs=["z"])
        radii.append(_radius2(sol))
    t = np.linspace(0.0, 3.0, 31)
    assert np.max(np.abs(radii[1] - radii[0])) < 1e-11 and np.max(np.abs(radii[2] - radii[0])) < 1e-11
    assert np.max(np.abs(radii[0] - (R0 * np.cos(t) + PR0 * np.sin(t)) ** 2)) < 1e-10


@pytest.mark.parametrize(
    "gauge, q, p",
    [
        (["z", "y"], {"x": R0}, {"x": PR0}),
        (["z", "y - x"], {"x": R0 / np.sqrt(2), "y": R0 / np.sqrt(2)}, {"x": PR0 / np.sqrt(2), "y": PR0 / np.sqrt(2)}),
    ],
    ids=["y=0", "y=x"],
)
def test_gauge_fixed_flows_give_the_same_physical_motion(christ_lee, gauge, q, p):
    """Midpoint on the gauge-fixed Dirac vector field (all constraints second class):
    r^2 follows the closed form to the method's O(dt^2) error and the surface is kept."""
    fixed = christ_lee.fix_gauge(gauge)
    system = AnalysedSystem.from_analysis(fixed)
    assert system.n_constraints == 4
    errors = []
    for dt in (0.01, 0.005):
        sol = dirac.integrate(AnalysedProblem(system, system.initial_state(q, p=p)), "midpoint", t_end=T_END, dt=dt,
                              samples=16, outputs=["z", "energy", "constraint_residual"])
        t = np.linspace(0.0, T_END, 16)
        errors.append(np.max(np.abs(_radius2(sol) - (R0 * np.cos(t) + PR0 * np.sin(t)) ** 2)))
        assert np.max(sol["constraint_residual"]) < 1e-10
        assert np.max(np.abs(sol["energy"] - (PR0**2 + R0**2) / 2)) < 1e-12
    assert errors[0] < 1e-4
    assert 3.0 < errors[0] / errors[1] < 5.0  # second order: the error is discretisation only


def test_a_multiplier_that_is_not_free_is_refused(christ_lee):
    with pytest.raises(dirac.InputError, match=r"unknown free multiplier 'u_2' \(did you mean 'u_1'"):
        AnalysedSystem.from_analysis(christ_lee, {"u_2": 1.0})
    with pytest.raises(dirac.InputError, match="no free multiplier"):
        AnalysedSystem.from_analysis(christ_lee.fix_gauge(["z", "y"]), {"u_1": 1.0})
