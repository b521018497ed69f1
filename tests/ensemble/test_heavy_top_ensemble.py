"""Heavy-top ensembles: members equal single runs to the last bit, the Maxwell-Routh stability
chart of the sleeping top against its closed form, crossings and Poincaré points, failed
members, local / dask / resumed runs, and refused bad input; driven tops (``[forces] torque``):
members equal single driven runs, a spin-up against its closed form, the balance E - W,
members whose torque kick fails."""

from __future__ import annotations

import numpy as np
import pytest
import zarr
from ensemble_stores import run_ensemble_cli as _cli
from ensemble_stores import stored_arrays as _arrays

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



def _tilted(angle: float) -> np.ndarray:
    """The rotation by ``angle`` about the body's first axis (as the scenes' R)."""
    return np.array([[1.0, 0.0, 0.0], [0.0, np.cos(angle), -np.sin(angle)], [0.0, np.sin(angle), np.cos(angle)]])


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


# ----------------------------------------------------------------------------- driven tops

DRIVEN = """[system]
name = "heavy_top"
inertia = [1.0, "b", 0.6]
mass_gravity = 1.5
center_of_mass = [0.3, 0.0, 1.0]

[forces]
torque = ["-0.2*Omega_1 + 0.1*sin(3*t)", "-0.2*Omega_2", "0.05*R_31 - 0.2*Omega_3"]

[initial]
omega = [0.3, "w", 2.0]
R = [[1.0, 0.0, 0.0], [0.0, "cos(0.4)", "-sin(0.4)"], [0.0, "sin(0.4)", "cos(0.4)"]]

[run]
method = "lie-poisson-4"
dt = 0.007
t_end = 2.0
samples = 5

[ensemble]
grid = { b = [0.8, 1.4, 3], w = [-0.5, 0.5, 2] }
reductions = ["final", "energy_error", "constraint_error"]
"""






def _single(method: str, b: float, w: float, torque: list[str] | None, t_end: float = 2.0, samples: int = 5,
            impulses: list | None = None):
    from dirac.flows import integrate
    from dirac.flows.problems import HeavyTopProblem

    inertia = np.array([1.0, b, 0.6])
    problem = HeavyTopProblem(inertia, inertia * np.array([0.3, w, 2.0]), _tilted(0.4), mass_gravity=1.5,
                              center_of_mass=[0.3, 0.0, 1.0], torque=torque, impulses=impulses or ())
    return integrate(problem, method, t_end=t_end, dt=0.007, samples=samples, outputs=["M", "R", "energy", "work"])


TORQUE = ["-0.2*Omega_1 + 0.1*sin(3*t)", "-0.2*Omega_2", "0.05*R_31 - 0.2*Omega_3"]
TORQUE_TEXT = "[" + ", ".join(f'"{component}"' for component in TORQUE) + "]"  # as DRIVEN gives it


@pytest.mark.parametrize("method", ["lie-poisson-4", "exact-kick-4"])
def test_driven_members_equal_single_runs(tmp_path, method, monkeypatch):
    """A member's final state is dirac.integrate's on a driven HeavyTopProblem of the same
    initial state to the last bit: the same torque kick (implicit midpoint here: the torque
    depends on Omega; and on t and R), not merged, with the time of a call's steps counted
    from the end of the call before, in calls of 37 steps (72 steps of 0.5/72 per sample
    interval: 37 + 35) in both runs. The energy error
    is the single run's max |E - W - E(0)| over the samples (W the torque's work)."""
    import dirac.flows.integration as integration

    monkeypatch.setattr(integration, "CHUNK_STEPS", 37)
    monkeypatch.setattr(integration, "MIN_CHUNK_STEPS", 10)
    path = tmp_path / "driven.toml"
    path.write_text(DRIVEN.replace('"lie-poisson-4"', f'"{method}"'))
    assert run_ensemble(path, tmp_path / "out").complete
    stored = _arrays(tmp_path / "out")
    assert np.all(stored["failures"] == 0) and np.all(stored["steps"] == 288)
    for i in range(6):
        single = _single(method, float(stored["b"][i]), float(stored["w"][i]), TORQUE)
        assert np.array_equal(single.outputs["M"][-1], stored["final_M"][i])
        assert np.array_equal(single.outputs["R"][-1], stored["final_R"][i])
        balance = single.outputs["energy"] - single.outputs["work"]
        assert stored["energy_error"][i] == pytest.approx(np.max(np.abs(balance - balance[0])), rel=1e-9, abs=1e-15)
        # the damping does work: E alone is not conserved, E - W is to the method's error
        assert abs(single.outputs["work"][-1]) > 1e-2 and stored["energy_error"][i] < 1e-6
    assert np.max(stored["constraint_error"]) < 1e-12


def test_a_constant_spin_torque_spins_up_a_symmetric_top_at_its_rate(tmp_path):
    """A symmetric top (I_1 = I_2) with its centre of mass on its axis (chi = (0, 0, l)) under a
    body torque N = (0, 0, k): the third Euler-Poisson equation is
    dM_3/dt = (M x Omega)_3 + m g (gamma x chi)_3 + N_3 = M_1 M_2 (1/I_2 - 1/I_1) + m g (gamma_1 chi_2 - gamma_2 chi_1) + k = k,
    so M_3(t) = M_3(0) + k t, whatever the nutation. The exact free flow keeps M_3 of a
    symmetric body and the exact kick adds tau k: the largest M_3 over the run and the final
    M_3 are M_3(0) + k T to rounding."""
    path = tmp_path / "spin.toml"
    path.write_text("""[system]
name = "heavy_top"
inertia = [1.0, 1.0, 2.0]
mass_gravity = 1.0
center_of_mass = [0.0, 0.0, 0.5]

[forces]
torque = ["0", "0", "0.25"]

[initial]
M = [0.1, 0.0, "m3"]
R = [[1.0, 0.0, 0.0], [0.0, "cos(0.1)", "-sin(0.1)"], [0.0, "sin(0.1)", "cos(0.1)"]]

[run]
method = "exact-kick-4"
dt = 0.01
t_end = 4.0
samples = 5

[ensemble]
grid = { m3 = [1.0, 3.0, 5] }
reductions = [{ kind = "max", name = "top_spin", expr = "M3" }, "final"]
""")
    assert run_ensemble(path, tmp_path / "out").complete
    stored = _arrays(tmp_path / "out")
    expected = stored["m3"] + 0.25 * 4.0
    assert np.allclose(stored["top_spin"], expected, rtol=0.0, atol=1e-12)
    assert np.allclose(stored["final_M"][:, 2], expected, rtol=0.0, atol=1e-12)
    assert np.all(np.abs(stored["final_M"][:, :2]) > 1e-3)  # the top nutates: M_1, M_2 are not trivially zero


def test_a_member_whose_kick_fails_is_marked_and_the_rest_complete(tmp_path):
    """With one Newton iteration allowed, the midpoint kick of a torque that depends on Omega
    cannot confirm convergence (its first correction is the whole step's): every member of
    that scene fails with code 1 (Newton), as a single run raises. A torque free of M and
    Omega is an exact kick (no Newton iteration), so the same limit fails nobody."""
    from dirac.errors import IntegrationError

    failing = DRIVEN.replace('samples = 5', 'samples = 5\nmax_newton_iterations = 1')
    path = tmp_path / "fail.toml"
    path.write_text(failing)
    assert run_ensemble(path, tmp_path / "out").complete
    stored = _arrays(tmp_path / "out")
    assert np.all(stored["failures"] == 1.0)
    assert np.all(np.isnan(stored["energy_error"])) and np.all(np.isnan(stored["final_M"]))
    from dirac.flows import integrate
    from dirac.flows.problems import HeavyTopProblem

    problem = HeavyTopProblem([1.0, 0.8, 0.6], [0.3, -0.4, 1.2], _tilted(0.4), mass_gravity=1.5,
                              center_of_mass=[0.3, 0.0, 1.0], torque=TORQUE)
    with pytest.raises(IntegrationError, match="did not converge in 1 Newton"):
        integrate(problem, "lie-poisson-4", t_end=2.0, dt=0.007, samples=5, max_newton_iterations=1)

    assert TORQUE_TEXT in failing
    exact_kick = failing.replace(TORQUE_TEXT, '["0.1*sin(3*t)", "0", "0.05*R_31"]')
    path.write_text(exact_kick)
    assert run_ensemble(path, tmp_path / "out2").complete
    assert np.all(_arrays(tmp_path / "out2")["failures"] == 0.0)






@pytest.mark.parametrize("change, message", [
    (('"-0.2*Omega_2"', '"-0.2*Omega2 + b"'), "unknown name 'b'"),  # an ensemble variable in a torque
    (('"-0.2*Omega_2"', '"-0.2*Omga_2"'), "did you mean 'Omega_2'"),  # a misspelt torque variable
    (("torque = [", "torqe = ["), "did you mean 'torque'"),
    (('"0.05*R_31 - 0.2*Omega_3"]', '"0.05*R_31 - 0.2*Omega_3", "0"]'), "must be three expressions"),
])
def test_bad_torques_are_refused_before_anything_is_written(tmp_path, change, message):
    path = tmp_path / "bad.toml"
    assert change[0] in DRIVEN
    path.write_text(DRIVEN.replace(*change))
    _refused(path, tmp_path / "out", message)


#: impulses at t = 0, inside a step (cut in two), on a step boundary (0.5 = 72 steps of 0.5/72),
#: two inside one step, and at t_end (after the last step of the last call)
IMPULSES = [(0.0, [0.0, 0.0, 0.3]), (0.3001, [0.2, -0.1, 0.0]), (0.5, [0.0, 0.4, 0.0]),
            (1.20001, [0.1, 0.0, 0.0]), (1.20003, [0.0, 0.0, -0.2]), (2.0, [0.5, 0.5, 0.5])]


@pytest.mark.parametrize("method, torque", [("lie-poisson-4", True), ("exact-kick-4", False)])
def test_members_with_impulses_equal_single_runs(tmp_path, method, torque, monkeypatch):
    """Angular impulses cut a single run's steps at their times (TorquedStepper.step): a member
    with the same impulses equals dirac.integrate of the driven HeavyTopProblem to the last bit,
    with a torque and with impulses alone (a zero torque, as a single run), in calls of 37 steps;
    its energy error is the single run's max |E - W - (E - W)(0)|, W counting each impulse's jump
    of the kinetic energy. An impulse at t = 0 acts on the initial state."""
    import dirac.flows.integration as integration

    monkeypatch.setattr(integration, "CHUNK_STEPS", 37)
    monkeypatch.setattr(integration, "MIN_CHUNK_STEPS", 10)
    scene = DRIVEN.replace('"lie-poisson-4"', f'"{method}"').replace("reductions = [", "reductions = [{ kind = \"max\", name = \"spin\", expr = \"M_3\" }, ")
    if not torque:
        scene = scene.replace(f"[forces]\ntorque = {TORQUE_TEXT}\n", "")
    scene += "".join(f"\n[[impulses]]\nt = {t}\nangular_impulse = {vector}\n" for t, vector in IMPULSES)
    path = tmp_path / "kicked.toml"
    path.write_text(scene)
    assert run_ensemble(path, tmp_path / "out").complete
    stored = _arrays(tmp_path / "out")
    assert np.all(stored["failures"] == 0)
    for i in range(6):
        single = _single(method, float(stored["b"][i]), float(stored["w"][i]), TORQUE if torque else None,
                         impulses=IMPULSES)
        assert np.array_equal(single.outputs["M"][-1], stored["final_M"][i])
        assert np.array_equal(single.outputs["R"][-1], stored["final_R"][i])
        balance = single.outputs["energy"] - single.outputs["work"]
        assert stored["energy_error"][i] == pytest.approx(np.max(np.abs(balance - balance[0])), rel=1e-9, abs=1e-15)
        assert single.outputs["M"][0][2] == pytest.approx(0.6 * 2.0 + 0.3)  # M_3 = I_3 omega_3, then the jump at t = 0
        assert stored["spin"][i] >= single.outputs["M"][0][2]


def _refused(path, out, message):
    result = _cli(path, out)
    assert result.returncode == 2, result.stderr
    assert result.stderr.startswith("error: ") and message in result.stderr and len(result.stderr.splitlines()) == 1
    assert not out.exists()


def test_a_driven_free_body_runs_as_a_heavy_top_without_weight(tmp_path):
    """A rigid-body ensemble scene with [forces] is refused with the way out: a heavy top with
    mass_gravity = 0. That scene's members equal single driven RigidBodyProblem runs in M to
    the last bit (the same torque kick with a zero weight vector, around the same free step)."""
    from dirac.flows import integrate
    from dirac.flows.problems import RigidBodyProblem

    rigid = tmp_path / "rigid.toml"
    rigid.write_text('[system]\nname = "rigid_body"\ninertia = [1.0, 2.0, 3.0]\n\n[forces]\n'
                     'torque = ["0", "0", "-0.1*Omega_3"]\n\n[initial]\nM = [0.1, 1.0, 0.1]\n\n[run]\n'
                     'method = "lie-poisson-4"\ndt = 0.01\nt_end = 1.0\n\n[ensemble]\ncount = 4\nreductions = ["flip_time"]\n')
    _refused(rigid, tmp_path / "out", 'write [system] name = "heavy_top" with mass_gravity = 0')
    top = tmp_path / "top.toml"
    top.write_text('[system]\nname = "heavy_top"\ninertia = [1.0, 2.0, 3.0]\nmass_gravity = 0.0\n\n[forces]\n'
                   'torque = ["0", "0", "-0.1*Omega_3"]\n\n[initial]\nM = [0.1, "m2", 0.1]\n\n[run]\n'
                   'method = "lie-poisson-4"\ndt = 0.01\nt_end = 1.0\nsamples = 3\n\n[ensemble]\n'
                   'grid = { m2 = [0.5, 1.5, 3] }\nreductions = ["final"]\n')
    assert run_ensemble(top, tmp_path / "top").complete
    stored = _arrays(tmp_path / "top")
    for i, m2 in enumerate(stored["m2"]):
        problem = RigidBodyProblem([1.0, 2.0, 3.0], [0.1, float(m2), 0.1], torque=["0", "0", "-0.1*Omega_3"])
        single = integrate(problem, "lie-poisson-4", t_end=1.0, dt=0.01, samples=3, outputs=["M"])
        assert np.array_equal(single.outputs["M"][-1], stored["final_M"][i])


def test_reductions_see_an_impulse_as_a_jump(tmp_path):
    """A sphere (I = 1, no weight) keeps M between impulses (dM/dt = M x Omega = 0): M_3 = 1,
    then -1 after the blow (0, 0, -2) at t = 0.2537 (inside a step of 0.01), then 1 after
    (0, 0, 2) at t = 0.6 (on a step boundary). By hand: M_3 first changes sign at the first
    blow, so its first crossing is at t = 0.2537 exactly (a line across the jump would put it
    at 0.25 + 0.5 * 0.01 for the middle of the step); its `when` M_1 > 0 holds after the blow
    (M_1 = 0.3 throughout); no state of the flow lies on the section M_3 = 0 (both crossings are
    jumps), so the Poincare section is empty; max M_3 = 1 and min M_3 = -1 (the states before and
    after each blow)."""
    scene = ('[system]\nname = "heavy_top"\ninertia = [1.0, 1.0, 1.0]\nmass_gravity = 0.0\n\n[initial]\n'
             'M = [0.3, "m2", 1.0]\n\n[run]\nmethod = "lie-poisson-4"\ndt = 0.01\nt_end = 1.0\nsamples = 3\n\n'
             '[[impulses]]\nt = 0.2537\nangular_impulse = [0.0, 0.0, -2.0]\n\n'
             '[[impulses]]\nt = 0.6\nangular_impulse = [0.0, 0.0, 2.0]\n\n'
             '[ensemble]\ngrid = { m2 = [0.0, 0.0, 1] }\nreductions = [\n'
             '  { kind = "first_crossing", name = "flip", expr = "M_3", when = "M_1 > 0" },\n'
             '  { kind = "poincare", name = "section", expr = "M_3", count = 2 },\n'
             '  { kind = "max", name = "high", expr = "M_3" },\n  { kind = "min", name = "low", expr = "M_3" },\n'
             '  "final",\n]\n')
    path = tmp_path / "jumps.toml"
    path.write_text(scene)
    assert run_ensemble(path, tmp_path / "out").complete
    stored = _arrays(tmp_path / "out")
    assert stored["flip"][0] == 0.2537
    assert np.all(np.isnan(stored["section_t"][0]))
    assert stored["high"][0] == pytest.approx(1.0, abs=1e-12) and stored["low"][0] == pytest.approx(-1.0, abs=1e-12)
    # the splitting of a sphere is exact up to its O(dt^4) error (each sub-flow turns M about one axis)
    assert stored["final_M"][0] == pytest.approx([0.3, 0.0, 1.0], abs=1e-8)
