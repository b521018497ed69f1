"""Heavy-top ensembles: members equal single runs to the last bit, the Maxwell-Routh stability
chart of the sleeping top against its closed form, crossings and Poincaré points, failed
members, local / dask / resumed runs, and refused bad input. Driven tops (``[forces] torque``)
are in test_heavy_top_driven_ensemble.py, impulses in test_heavy_top_impulse_ensemble.py: files
of their own, which pytest-xdist's ``--dist loadfile`` runs beside this one on other workers."""

from __future__ import annotations

import numpy as np
import pytest
import zarr
from ensemble_stores import run_ensemble_cli as _cli
from ensemble_stores import stored_arrays as _arrays
from heavy_tops import tilted as _tilted

from dirac.ensemble.engine import run_ensemble

TILT = 0.01  # the initial tilt angle of the chart's tops (rad)

CHART = f"""[system]
name = "heavy_top"
inertia = [1.0, 1.0, "0.4 + 0.1*mgl"]
mass_gravity = "mgl"
center_of_mass = [0.0, 0.0, 1.0]

[initial]
M = [0.0, 0.0, "spin"]
R = [[1.0, 0.0, 0.0], [0.0, "cos({TILT})", "-sin({TILT})"], [0.0, "sin({TILT})", "cos({TILT})"]]

[run]
method = "lie-poisson-4"
dt = 0.01
t_end = 30.0
samples = 31

[ensemble]
grid = {{ spin = [0.4, 4.6, 8], mgl = [0.5, 1.0, 2] }}
reductions = [{{ kind = "max", name = "max_tilt", expr = "1 - gamma_3" }}, "final", "energy_error", "constraint_error"]
"""



@pytest.fixture(scope="module")
def chart(tmp_path_factory):
    """The stability chart of the sleeping top: (scene path, stored arrays, output folder)."""
    folder = tmp_path_factory.mktemp("chart")
    path = folder / "chart.toml"
    path.write_text(CHART)
    assert run_ensemble(path, folder / "out").complete
    return path, _arrays(folder / "out"), folder / "out"


def test_members_equal_single_runs(chart):
    """A member's state at t_end is dirac.integrate's on a HeavyTopProblem of the same initial
    state, method, dt and samples, to the last bit (the same kick and Lie-Poisson kernels, the
    kicks merged within the same calls); its energy error is that run's max |E(t_k) - E(0)|."""
    from dirac.flows import integrate
    from dirac.flows.problems import HeavyTopProblem

    _, stored, _ = chart
    for i in (0, 3, 9, 15):
        spin, mgl = float(stored["spin"][i]), float(stored["mgl"][i])
        problem = HeavyTopProblem([1.0, 1.0, 0.4 + 0.1 * mgl], [0.0, 0.0, spin], _tilted(TILT), mass_gravity=mgl,
                                  center_of_mass=[0.0, 0.0, 1.0])
        single = integrate(problem, "lie-poisson-4", t_end=30.0, dt=0.01, samples=31, outputs=["M", "R", "energy"])
        assert np.array_equal(single.outputs["M"][-1], stored["final_M"][i])
        assert np.array_equal(single.outputs["R"][-1], stored["final_R"][i])
        energy = single.outputs["energy"]
        assert stored["energy_error"][i] == pytest.approx(np.max(np.abs(energy - energy[0])), rel=1e-9, abs=1e-15)
    assert np.all(stored["failures"] == 0) and np.all(stored["steps"] == 3000)
    assert np.max(stored["constraint_error"]) < 1e-12  # R stays orthogonal: every sub-step is a rotation


def test_exact_kick_members_equal_single_runs(tmp_path):
    """exact-kick-4 (kick + the exact free flow of Jacobi elliptic functions): an asymmetric
    top's members with the inertia and omega (M = I omega) varying equal dirac.integrate to
    the last bit."""
    from dirac.flows import integrate
    from dirac.flows.problems import HeavyTopProblem

    path = tmp_path / "exact.toml"
    path.write_text(ASYMMETRIC.replace('"lie-poisson-sym-2"', '"exact-kick-4"').replace("k*1e308", "k")
                    .replace("m = [0.1, 0.2, 2.0]", 'omega = [0.1, "b", 2.0]').replace("t_end = 6.0", "t_end = 1.0")
                    .replace("samples = 601", "samples = 5").replace("dt = 0.01", "dt = 0.05")
                    .replace('  { kind = "poincare", name = "section", expr = "gamma1", count = 2 },\n', '  "final",\n'))
    assert run_ensemble(path, tmp_path / "out").complete
    stored = _arrays(tmp_path / "out")
    for i in range(6):
        b, k = float(stored["b"][i]), float(stored["k"][i])
        inertia = np.array([1.0, b, 0.6])
        problem = HeavyTopProblem(inertia, inertia * np.array([0.1, b, 2.0]), _tilted(0.4), mass_gravity=1.0 + k,
                                  center_of_mass=[0.3, 0.0, 10.0])
        single = integrate(problem, "exact-kick-4", t_end=1.0, dt=0.05, samples=5, outputs=["M", "R"])
        assert np.array_equal(single.outputs["M"][-1], stored["final_M"][i])
        assert np.array_equal(single.outputs["R"][-1], stored["final_R"][i])


def test_members_follow_a_single_runs_calls(chart, monkeypatch):
    """A single run advances a sample interval in calls of at most CHUNK_STEPS steps, and the
    kernel merges the half kicks between two steps of one call (so the grouping shows in the
    last bits): with calls of 37 steps (100 steps per interval: calls of 37, 37, 26) members
    still equal single runs bit for bit, and differ from the run in one call per interval."""
    import dirac.flows.integration as integration
    from dirac.ensemble.heavy_top_members import compute_heavy_top_chunk
    from dirac.ensemble.scene import load_ensemble_scene
    from dirac.flows import integrate
    from dirac.flows.problems import HeavyTopProblem

    path, stored, _ = chart
    scene = load_ensemble_scene(path)
    monkeypatch.setattr(integration, "CHUNK_STEPS", 37)
    monkeypatch.setattr(integration, "MIN_CHUNK_STEPS", 10)
    arrays = compute_heavy_top_chunk(scene, 0, 4)
    for i in range(4):
        spin, mgl = float(arrays["spin"][i]), float(arrays["mgl"][i])
        problem = HeavyTopProblem([1.0, 1.0, 0.4 + 0.1 * mgl], [0.0, 0.0, spin], _tilted(TILT), mass_gravity=mgl,
                                  center_of_mass=[0.0, 0.0, 1.0])
        single = integrate(problem, "lie-poisson-4", t_end=30.0, dt=0.01, samples=31, outputs=["M", "R"])
        assert np.array_equal(single.outputs["M"][-1], arrays["final_M"][i])
        assert np.array_equal(single.outputs["R"][-1], arrays["final_R"][i])
    assert not np.array_equal(arrays["final_M"], stored["final_M"][:4])


def test_maxwell_routh_stability_chart(chart):
    """The sleeping top (I1 = I2 = I, chi = (0, 0, l), M = (0, 0, M3), tilted by a from the
    vertical) is stable iff M3^2 > 4 I m g l (Maxwell; Routh), whatever I3.

    Derivation. Linearising dM/dt = M x Omega + m g l gamma x e3, dgamma/dt = gamma x Omega
    about M = (0, 0, M3), gamma = e3 (M3 stays constant), z = M1 + i M2 and w = gamma1 + i gamma2
    obey dz/dt = -i A z - i m g l w, dw/dt = -i B w + i z / I with A = M3 (1/I3 - 1/I),
    B = M3 / I3. With z, w ~ exp(-i lam t): I lam^2 - I (A + B) lam + I A B + m g l = 0, of
    discriminant I^2 (A - B)^2 - 4 I m g l = M3^2 - 4 I m g l: real frequencies (stable) iff
    M3^2 > 4 I m g l.

    How far the top tips (exact, nonlinear): the energy (M1^2 + M2^2)/(2I) + M3^2/(2 I3) +
    m g l u (u = gamma3), M3 and <gamma, M> = M3 u0 are conserved; <gamma, M> = M3 u +
    <gamma_perp, M_perp> gives M_perp^2 >= M3^2 (u0 - u)^2 / (1 - u^2), with equality at the
    turning points. With M_perp^2 = 2 I m g l (u0 - u) the top moves between u0 = cos a and
    the root below u0 of 2 I m g l u^2 - M3^2 u + M3^2 u0 - 2 I m g l = 0,
    u_min = (M3^2 - sqrt(M3^4 - 8 I m g l (M3^2 u0 - 2 I m g l))) / (4 I m g l);
    max(1 - gamma3) = 1 - u_min: about (1 - u0) ratio / (ratio - 1) above the threshold
    (ratio = M3^2 / (4 I m g l); linearise the quadratic about u = 1), and
    (4 I m g l - M3^2) / (2 I m g l) (of order one) below it as a -> 0.
    The members sit away from the threshold (M3^2 / (4 I m g l) outside [0.8, 1.2]); the
    stored max is over every step, t_end = 30 is long enough for the slowest unstable member
    (growth rate sqrt(4 I m g l - M3^2) / (2 I) >= 0.6) to reach its lowest point.
    """
    _, stored, _ = chart
    spin, mgl, tilt = stored["spin"], stored["mgl"], stored["max_tilt"]
    u0 = np.cos(TILT)
    ratio = spin**2 / (4 * mgl)
    assert np.all(np.abs(ratio - 1) > 0.2)
    u_min = (spin**2 - np.sqrt(spin**4 - 8 * mgl * (spin**2 * u0 - 2 * mgl))) / (4 * mgl)
    np.testing.assert_allclose(tilt, 1 - u_min, rtol=1e-3)
    # well above the threshold the tilt stays near its start (1 - u0) ratio / (ratio - 1) < 3 (1 - u0)
    # (the root above, for small 1 - u0); well below it the top tips over by a tilt of order one
    above, below = ratio > 1.5, ratio < 0.8
    assert above.sum() >= 6 and below.sum() >= 4
    assert np.all(tilt[above] < 3 * (1 - u0))
    assert np.all(tilt[below] > 0.4)


ASYMMETRIC = """[system]
name = "heavy_top"
inertia = [1.0, "b", 0.6]
mass_gravity = "1.0 + k*1e308"
center_of_mass = [0.3, 0.0, 10.0]

[initial]
m = [0.1, 0.2, 2.0]
R = [[1.0, 0.0, 0.0], [0.0, "cos(0.4)", "-sin(0.4)"], [0.0, "sin(0.4)", "cos(0.4)"]]

[run]
method = "lie-poisson-sym-2"
dt = 0.01
t_end = 6.0
samples = 601

[ensemble]
grid = { b = [0.8, 1.4, 3], k = [0.0, 1.0, 2] }
reductions = [
  { kind = "poincare", name = "section", expr = "gamma1", count = 2 },
  { kind = "first_crossing", name = "swing", expr = "M_1", when = "Omega_2 > 0" },
]
"""


def test_crossings_sections_early_stop_and_failures(tmp_path):
    """An asymmetric top with lab m (M = R^T m) and the symmetric-top split, every step a
    sample (so a single run has each step's state): the Poincaré points lie on gamma_1 = 0 to
    1e-12, on the straight line between the single run's two states that bracket the upward
    crossing; the first crossing of M_1 with Omega_2 > 0 lies in the single run's bracketing
    step; members stop at their last crossing. The members with m g = 1e308 (a weight 1e309:
    not finite) fail with the code of a non-finite state and NaN reductions; the others complete."""
    from dirac.flows import integrate
    from dirac.flows.problems import HeavyTopProblem

    path = tmp_path / "top.toml"
    path.write_text(ASYMMETRIC)
    assert run_ensemble(path, tmp_path / "out").complete
    stored = _arrays(tmp_path / "out")
    failed = stored["k"] == 1.0
    assert np.all(stored["failures"][failed] == 2.0) and np.all(stored["failures"][~failed] == 0.0)
    assert np.all(np.isnan(stored["section_t"][failed])) and np.all(np.isnan(stored["swing"][failed]))
    t_sec, M_sec, R_sec = stored["section_t"], stored["section_M"], stored["section_R"]
    assert t_sec.shape == (6, 2) and M_sec.shape == (6, 2, 3) and R_sec.shape == (6, 2, 3, 3)
    R0 = _tilted(0.4)
    for i in np.flatnonzero(~failed):
        assert np.all(np.isfinite(t_sec[i])) and np.isfinite(stored["swing"][i])
        assert np.max(np.abs(R_sec[i, :, 2, 0])) <= 1e-12
        last = max(t_sec[i, -1], stored["swing"][i])
        assert stored["steps"][i] == np.ceil(last / 0.01 - 1e-9) < 600  # stopped in the step of its last crossing
        problem = HeavyTopProblem([1.0, float(stored["b"][i]), 0.6], R0.T @ np.array([0.1, 0.2, 2.0]), R0,
                                  mass_gravity=1.0, center_of_mass=[0.3, 0.0, 10.0])
        single = integrate(problem, "lie-poisson-sym-2", t_end=6.0, dt=0.01, samples=601, outputs=["M", "R"])
        gamma1 = single.outputs["R"][:, 2, 0]
        upward = np.flatnonzero((gamma1[:-1] < 0) & (gamma1[1:] >= 0))[:2]
        for point, k in enumerate(upward):
            assert single.t[k] <= t_sec[i, point] <= single.t[k + 1]
            s = (t_sec[i, point] - single.t[k]) / 0.01
            line_M = single.outputs["M"][k] + s * (single.outputs["M"][k + 1] - single.outputs["M"][k])
            np.testing.assert_allclose(M_sec[i, point], line_M, rtol=0, atol=1e-9)
        M1 = single.outputs["M"][:, 0]
        Omega2 = single.outputs["M"][:, 1] / float(stored["b"][i])
        change = np.flatnonzero((((M1[:-1] < 0) & (M1[1:] >= 0)) | ((M1[:-1] > 0) & (M1[1:] <= 0))) & (Omega2[1:] > 0))
        assert single.t[change[0]] <= stored["swing"][i] <= single.t[change[0] + 1]
    # the section's picture: gamma_i from the third row of the stored R, M_i from the stored M
    from dirac.ensemble.plot import picture_data

    data = picture_data(tmp_path / "out", "section", x="gamma_2", y="M_3")
    assert data["kind"] == "section" and np.isfinite(data["x"]).sum() == 6  # 2 points of each of 3 members
    assert np.array_equal(data["x"], R_sec[..., 2, 1].ravel(), equal_nan=True)
    assert np.array_equal(data["y"], M_sec[..., 2].ravel(), equal_nan=True)


def test_chart_map_puts_each_member_at_its_grid_point(chart):
    """The map of a grid listed as (spin, mgl) -- not in alphabetical order, as meta.json
    lists it -- has row i = spin_i, column j = mgl_j: the member numbered i * 2 + j."""
    from dirac.ensemble.plot import picture_data

    _, stored, out = chart
    data = picture_data(out, "max_tilt")
    assert data["x"] == ("spin", 0.4, 4.6) and data["y"] == ("mgl", 0.5, 1.0)
    assert data["values"].shape == (8, 2)
    for i in range(8):
        for j in range(2):
            member = i * 2 + j
            assert stored["spin"][member] == pytest.approx(0.4 + 0.6 * i)
            assert stored["mgl"][member] == pytest.approx(0.5 + 0.5 * j)
            assert data["values"][i, j] == stored["max_tilt"][member]


def test_chart_identical_local_dask_and_resumed(chart, tmp_path):
    """The chart does not depend on where or in how many pieces it is computed."""
    path, reference, _ = chart
    assert run_ensemble(path, tmp_path / "dask", cluster="local", n_workers=2, chunk_size=4).complete
    stored = _arrays(tmp_path / "dask")
    for name in ("max_tilt", "final_M", "final_R", "energy_error"):
        assert np.array_equal(stored[name], reference[name])
    out = tmp_path / "dask"
    for index in (1, 2):  # an interruption leaves chunks without a marker: they are recomputed
        (out / "chunks" / f"chunk-{index:06d}.json").unlink()
        zarr.open_array(str(out / "data.zarr"), path="max_tilt", mode="r+")[4 * index: 4 * index + 4] = 123.0
    report = run_ensemble(path, out)
    assert report.complete and report.chunks_computed == 2 and report.chunks_skipped == 2
    assert np.array_equal(_arrays(out)["max_tilt"], reference["max_tilt"])



@pytest.mark.parametrize("change, message", [
    (('"spin"]', '"spn"]'), "unknown name 'spn'"),  # a misspelt ensemble variable
    (('"0.4 + 0.1*mgl"', '"0.4 + 0.1*c"'), "unknown name 'c'"),  # a variable used but not defined
    (('expr = "1 - gamma_3"', 'expr = "1 - gama_3"'), "did you mean 'gamma_3'"),  # a misspelt state name
    (('"cos(0.01)", "-sin(0.01)"', '"cos(0.01)", "sin(0.01)"'), "is not orthogonal"),  # R is no rotation
    (('"lie-poisson-4"', '"rattle-4"'), "unknown method 'rattle-4'"),
    (("0.4, 4.6, 8]", "0.4, 4.6, 0]"), "n = 0 must be an integer >= 1"),
])
def test_bad_input_is_refused_before_anything_is_written(tmp_path, change, message):
    path = tmp_path / "bad.toml"
    assert change[0] in CHART
    path.write_text(CHART.replace(*change))
    result = _cli(path, tmp_path / "out")
    assert result.returncode == 2, result.stderr
    assert result.stderr.startswith("error: ") and message in result.stderr and len(result.stderr.splitlines()) == 1
    assert not (tmp_path / "out").exists()
