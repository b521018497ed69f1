"""Bad input everywhere is refused cleanly (exit 2, one ``error:`` line), by property-based tests.

Random bad scenes, system files and command lines must give exit status 2 and exactly one
``error:`` line on stderr (``warning:`` lines may precede it), never a traceback or a
hang, and must write no result file; random good scenes must run and write a complete
file. Each command runs under an alarm so that a hang fails the test instead of
stopping the suite.
"""

from __future__ import annotations

import json
import math
import signal
import tomllib
from pathlib import Path

import numpy as np
import pytest
from hypothesis import HealthCheck, assume, given, settings
from hypothesis import strategies as st

CLI_SECONDS = 60
SETTINGS = settings(max_examples=25, deadline=None, derandomize=True,
                    suppress_health_check=[HealthCheck.function_scoped_fixture, HealthCheck.too_slow])


# ----------------------------------------------------------------------------- helpers
def toml_value(value: object) -> str:
    """TOML text of a number, string, boolean, list or inline table (nan and inf included)."""
    if isinstance(value, bool):
        return "true" if value else "false"
    if isinstance(value, int):
        return str(value)
    if isinstance(value, float):
        if math.isnan(value):
            return "nan"
        if math.isinf(value):
            return "inf" if value > 0 else "-inf"
        return repr(value)
    if isinstance(value, str):
        return json.dumps(value)
    if isinstance(value, (list, tuple)):
        return "[" + ", ".join(toml_value(v) for v in value) + "]"
    if isinstance(value, dict):
        return "{ " + ", ".join(f"{json.dumps(k)} = {toml_value(v)}" for k, v in value.items()) + " }"
    raise TypeError(value)


def toml_document(tables: dict) -> str:
    """A TOML document of top-level tables (``{"system": {...}, ...}``)."""
    lines = []
    for name, table in tables.items():
        lines.append(f"[{name}]")
        lines += [f"{json.dumps(key)} = {toml_value(value)}" for key, value in table.items()]
    return "\n".join(lines) + "\n"


def _timeout(signum, frame):
    raise TimeoutError(f"a dirac command ran longer than {CLI_SECONDS} s (hang?)")


@pytest.fixture
def cli(run_cli):
    """``run_cli`` under an alarm."""

    def run(*argv: str) -> tuple[int, str, str]:
        previous = signal.signal(signal.SIGALRM, _timeout)
        signal.alarm(CLI_SECONDS)
        try:
            return run_cli(*argv)
        finally:
            signal.alarm(0)
            signal.signal(signal.SIGALRM, previous)

    return run


@pytest.fixture
def run_scene(cli, tmp_path):
    """``dirac run`` of a scene text, written to ``scene.toml``, into a fresh ``out.npz``.

    Returns ``(status, stderr, out)``. Hypothesis reuses ``tmp_path`` across examples, so a
    result file of an earlier example is removed first.
    """

    def run(text: str) -> tuple[int, str, Path]:
        path = tmp_path / "scene.toml"
        path.write_text(text, encoding="utf-8")
        out = tmp_path / "out.npz"
        out.unlink(missing_ok=True)
        status, _, err = cli("run", str(path), "--out", str(out), "--no-progress")
        return status, err, out

    return run


def assert_one_error_line(status: int, err: str) -> str:
    """Exit status 2 and one ``error:`` line (only ``warning:`` lines besides); return it."""
    lines = [line for line in err.splitlines() if line.strip()]
    assert status == 2, err
    assert "Traceback" not in err, err
    errors = [line for line in lines if line.startswith("error:")]
    assert len(errors) == 1, err
    assert all(line.startswith(("error:", "warning:", "dirac: compiling ")) for line in lines), err
    return errors[0]


def good_scene() -> dict:
    return {
        "system": {"name": "rigid_body", "inertia": [1.0, 2.0, 2.5]},
        "initial": {"M": [1.0, 0.2, 0.1]},
        "run": {"t_end": 0.5, "method": "lie-poisson-2", "dt": 0.05, "samples": 3},
    }


# ----------------------------------------------------------------------------- strategies
finite = st.floats(min_value=-1e3, max_value=1e3, allow_nan=False, allow_infinity=False)
non_finite = st.sampled_from([math.nan, math.inf, -math.inf])
non_positive = st.one_of(st.just(0.0), st.just(-0.0), st.floats(max_value=-1e-300, min_value=-1e6))
not_a_number = st.one_of(st.text(max_size=5), st.booleans(), st.lists(st.integers(), max_size=2))
METHOD_NAMES = {"auto", "exact", "midpoint", "scipy-RK45", "scipy-DOP853"} | {
    f"{prefix}{suffix}" for prefix in ("lie-poisson-", "lie-poisson-sym-", "rattle-", "exact-kick-")
    for suffix in ("2", "4", "6", "8", "4-suzuki", "8-s15")}


@st.composite
def left_handed_or_skewed_rotation(draw) -> list:
    """A matrix that is not a proper rotation: a rotation with one column flipped, or skewed."""
    q = np.array(draw(st.lists(st.floats(-1, 1, allow_nan=False), min_size=4, max_size=4)))
    assume(np.linalg.norm(q) > 0.1)
    w, x, y, z = q / np.linalg.norm(q)
    R = np.array([[1 - 2 * (y * y + z * z), 2 * (x * y - z * w), 2 * (x * z + y * w)],
                  [2 * (x * y + z * w), 1 - 2 * (x * x + z * z), 2 * (y * z - x * w)],
                  [2 * (x * z - y * w), 2 * (y * z + x * w), 1 - 2 * (x * x + y * y)]])
    if draw(st.booleans()):
        R[:, draw(st.integers(0, 2))] *= -1.0  # left-handed
    else:
        i, j = draw(st.integers(0, 2)), draw(st.integers(0, 2))
        R[i, j] += draw(st.one_of(st.floats(1e-6, 0.5), st.floats(-0.5, -1e-6)))  # not orthogonal
    return R.tolist()


@st.composite
def bad_scene(draw) -> dict:
    """A good scene with exactly one thing wrong."""
    scene = good_scene()
    kind = draw(st.sampled_from([
        "inertia", "inertia_shape", "M", "R", "t_end", "dt", "samples", "method", "tolerance",
        "outputs", "missing_table", "system_name", "initial_both",
    ]))
    if kind == "inertia":
        bad = draw(st.one_of(non_finite, non_positive, not_a_number))
        scene["system"]["inertia"][draw(st.integers(0, 2))] = bad
    elif kind == "inertia_shape":
        scene["system"]["inertia"] = draw(st.lists(st.floats(0.5, 2.0), max_size=5).filter(lambda v: len(v) != 3))
    elif kind == "M":
        scene["initial"]["M"][draw(st.integers(0, 2))] = draw(st.one_of(non_finite, not_a_number))
    elif kind == "R":
        scene["initial"]["R"] = draw(left_handed_or_skewed_rotation())
    elif kind == "t_end":
        scene["run"]["t_end"] = draw(st.one_of(non_positive, non_finite, not_a_number))
    elif kind == "dt":
        scene["run"]["dt"] = draw(st.one_of(non_positive, non_finite, not_a_number))
    elif kind == "samples":
        scene["run"]["samples"] = draw(st.one_of(st.integers(-10**6, 0), st.floats(0.5, 10.0), not_a_number))
    elif kind == "method":
        scene["run"]["method"] = draw(st.text(min_size=1, max_size=12).filter(lambda s: s not in METHOD_NAMES))
    elif kind == "tolerance":
        scene["run"]["tolerance"] = draw(st.one_of(non_positive, st.floats(1.0, 1e6), non_finite))
    elif kind == "outputs":
        scene["run"]["outputs"] = draw(st.one_of(
            st.just([]), st.lists(st.sampled_from(["q", "p", "constraint_residual", "bogus"]), min_size=1, max_size=3)))
    elif kind == "missing_table":
        del scene[draw(st.sampled_from(["system", "initial", "run"]))]
    elif kind == "system_name":
        scene["system"]["name"] = draw(st.text(alphabet="abcxyz_", min_size=1, max_size=8).filter(
            lambda s: s not in ("rigid_body", "heavy_top")))
    elif kind == "initial_both":
        scene["initial"]["omega"] = [0.1, 0.2, 0.3]
    return scene


@st.composite
def good_rigid_scene(draw) -> dict:
    inertia = draw(st.lists(st.floats(0.1, 10.0), min_size=3, max_size=3))
    M = draw(st.lists(st.floats(-3.0, 3.0), min_size=3, max_size=3))
    method = draw(st.sampled_from(["lie-poisson-2", "lie-poisson-4", "exact", "midpoint", "scipy-DOP853", "auto"]))
    run = {"t_end": draw(st.floats(0.05, 3.0)), "method": method, "samples": draw(st.integers(1, 12))}
    if method in ("lie-poisson-2", "lie-poisson-4", "midpoint"):
        run["dt"] = draw(st.floats(0.005, 0.1))
    return {"system": {"name": "rigid_body", "inertia": inertia}, "initial": {"M": M}, "run": run}


# ----------------------------------------------------------------------------- scenes
@SETTINGS
@given(scene=bad_scene())
def test_bad_scene_exits_2_with_one_error_line_and_writes_nothing(scene, run_scene):
    status, err, out = run_scene(toml_document(scene))
    assert_one_error_line(status, err)
    assert not out.exists()


@SETTINGS
@given(text=st.text(max_size=60))
def test_malformed_toml_exits_2_with_one_error_line(text, run_scene):
    try:
        tomllib.loads(text.replace("\r\n", "\n").replace("\r", "\n"))  # as read_text() will see it
    except tomllib.TOMLDecodeError:
        pass
    else:
        assume(False)  # only malformed documents here
    status, err, _ = run_scene(text)
    line = assert_one_error_line(status, err)
    assert "TOML" in line


@SETTINGS
@given(scene=good_rigid_scene())
def test_good_scene_runs_and_writes_a_complete_file(scene, run_scene):
    from dirac.io.results import read_results

    status, err, out = run_scene(toml_document(scene))
    assert status == 0, err
    assert all(line.startswith("warning:") for line in err.splitlines() if line.strip()), err
    arrays, meta = read_results(out)
    assert meta["complete"] is True
    assert arrays["t"].shape == (scene["run"]["samples"],)
    assert np.all(np.isfinite(arrays["M"]))


@SETTINGS
@given(keys=st.lists(st.text(alphabet="abcdefghij_", min_size=3, max_size=8), min_size=1, max_size=3, unique=True),
       table=st.sampled_from(["system", "initial", "run"]))
def test_unknown_keys_are_one_error_naming_the_file_the_table_and_every_key(keys, table, run_scene):
    from cli_output import one_error_line

    scene = good_scene()
    known = {"system": {"name", "inertia", "description"}, "initial": {"M", "omega", "m", "R"},
             "run": {"t_end", "method", "dt", "tolerance", "samples", "outputs", "drift_limit",
                     "newton_tolerance", "max_newton_iterations"}}
    assume(not set(keys) & known[table])
    for key in keys:
        scene[table][key] = 1.0
    status, err, out = run_scene(toml_document(scene))
    line = one_error_line(status, err)
    assert line.startswith(f"error: {out.parent / 'scene.toml'}: [{table}] has "), line
    assert all(repr(key) in line for key in keys)
    assert line.endswith(f"known keys: {', '.join(sorted(known[table]))}")
    assert not out.exists()


# ----------------------------------------------------------------------------- system files
@st.composite
def bad_system(draw) -> dict:
    system = {"name": "pendulum", "coordinates": ["x", "y"], "lagrangian": "m/2*(x_dot**2 + y_dot**2) - m*g*y",
              "constraints": ["x**2 + y**2 - l**2"], "parameters": {"m": 1.0, "g": 9.81, "l": 1.0}}
    kind = draw(st.sampled_from(["unknown_name", "non_holonomic", "syntax", "forbidden_call", "coordinates",
                                 "duplicate", "parameter_value", "empty_lagrangian", "zero_constraint",
                                 "missing_key", "types", "clash"]))
    if kind == "unknown_name":
        name = draw(st.sampled_from(["k", "omega", "z", "x_ddot", "lambda_2", "p_z"]))
        system["lagrangian"] += f" + {name}*x"
    elif kind == "non_holonomic":
        system["constraints"] = [draw(st.sampled_from(["x_dot - y", "x*y_dot", "x_dot**2 + y**2 - 1"]))]
    elif kind == "syntax":
        system["lagrangian"] = draw(st.sampled_from(["m/2*(x_dot**2", "x_dot**", "x_dot ++* 2", "lambda x: x", "x_dot; y", ""]))
    elif kind == "forbidden_call":
        system["lagrangian"] = draw(st.sampled_from(["__import__('os').getcwd()", "open('f')", "x_dot.real",
                                                     "eval('1')", "(lambda: 1)()", "[x for x in y]"]))
    elif kind == "coordinates":
        system["coordinates"] = draw(st.sampled_from([[], "x y", ["1x", "y"], ["x", "y-z"], ["class", "y"], [1, 2]]))
    elif kind == "duplicate":
        system["coordinates"] = ["x", "x"]
    elif kind == "parameter_value":
        system["parameters"]["m"] = draw(st.one_of(non_finite, st.text(max_size=3)))
    elif kind == "empty_lagrangian":
        system["lagrangian"] = "0"
    elif kind == "zero_constraint":
        system["constraints"] = ["x - x"]
    elif kind == "missing_key":
        del system[draw(st.sampled_from(["name", "coordinates", "lagrangian"]))]
    elif kind == "types":
        system["constraints"] = "x**2 + y**2 - l**2"
    elif kind == "clash":
        system["coordinates"] = ["x", "p_x"]
    return {"system": system}


@SETTINGS
@given(system=bad_system())
def test_bad_system_file_exits_2_with_one_error_line(system, cli, tmp_path):
    path = tmp_path / "system.toml"
    path.write_text(toml_document(system))
    status, _, err = cli("analyze", str(path))
    assert_one_error_line(status, err)


def test_inconsistent_lagrangian_is_refused_by_analyze(cli, tmp_path):
    """``L = x_dot^2/2 + y``: the consistency of ``p_y = 0`` demands ``1 = 0``: exit 2, ``error:``."""
    path = tmp_path / "system.toml"
    path.write_text(toml_document({"system": {"name": "inconsistent", "coordinates": ["x", "y"],
                                              "lagrangian": "x_dot**2/2 + y"}}))
    status, _, err = cli("analyze", str(path))
    assert "1 = 0" in assert_one_error_line(status, err)


# ----------------------------------------------------------------------------- command lines
WORDS = ["run", "analyze", "systems", "--out", "--json", "--latex", "--param", "m=1", "m", "=1", "q=nan",
         "--no-progress", "--bogus", "-x", "nosuch", "missing.toml", "x.npz", "x.txt", "--help-me", "", " ", "ü"]


@SETTINGS
@given(argv=st.lists(st.sampled_from(WORDS), min_size=1, max_size=5))  # includes bare `dirac` (once status 2 without an error: line)
def test_random_command_lines_never_crash(argv, cli, tmp_path, monkeypatch):
    monkeypatch.chdir(tmp_path)
    status, out, err = cli(*argv)
    assert status in (0, 2), (argv, err)
    assert "Traceback" not in err
    if status == 2:
        assert_one_error_line(status, err)
    assert not Path("x.npz").exists()


# ----------------------------------------------------------------------------- Python API
@SETTINGS
@given(inertia=st.lists(st.one_of(finite, non_finite, non_positive), min_size=0, max_size=4),
       M=st.lists(st.one_of(finite, non_finite), min_size=0, max_size=4))
def test_rigid_body_problem_refuses_bad_numbers_with_input_error(inertia, M):
    from dirac.errors import InputError
    from dirac.flows.problems import RigidBodyProblem

    bad = (len(inertia) != 3 or len(M) != 3 or not all(math.isfinite(v) and v > 0 for v in inertia)
           or not all(math.isfinite(v) for v in M))
    assume(bad)
    with pytest.raises(InputError):
        RigidBodyProblem(inertia, M)


@SETTINGS
@given(t_end=st.one_of(finite, non_finite), dt=st.one_of(st.none(), finite, non_finite),
       samples=st.one_of(st.integers(-5, 5), st.floats(-2.0, 2.0)), method=st.sampled_from(
           ["lie-poisson-2", "exact", "midpoint", "rattle-2", "rk4", "", "auto"]))
def test_integrate_refuses_bad_arguments_with_input_error_and_runs_good_ones(t_end, dt, samples, method):
    import warnings

    from dirac.errors import InputError
    from dirac.flows.integration import integrate
    from dirac.flows.problems import RigidBodyProblem

    problem = RigidBodyProblem([1.0, 2.0, 2.5], [1.0, 0.2, 0.1])
    good = (math.isfinite(t_end) and 0 < t_end <= 5 and isinstance(samples, int) and samples >= 1
            and method in ("exact", "auto", "lie-poisson-2", "midpoint")
            and (method in ("exact", "auto") or (dt is not None and math.isfinite(dt) and dt >= 1e-3)))
    bad = (not math.isfinite(t_end) or t_end <= 0 or not isinstance(samples, int) or samples < 1
           or method in ("rattle-2", "rk4", "") or (dt is not None and (not math.isfinite(dt) or dt <= 0))
           or (method in ("lie-poisson-2", "midpoint") and dt is None))
    assume(good or bad)
    if bad:
        with pytest.raises(InputError):
            integrate(problem, method, t_end=t_end, dt=dt, samples=samples)
    else:
        with warnings.catch_warnings():
            warnings.simplefilter("error")  # nothing suspicious about this input
            solution = integrate(problem, method, t_end=t_end, dt=dt, samples=samples)
        assert solution.complete and len(solution.t) == samples
        assert np.all(np.isfinite(solution["M"]))


@SETTINGS
@given(name=st.text(max_size=12), value=st.one_of(finite, non_finite, st.text(max_size=3)))
def test_load_system_refuses_unknown_names_and_bad_parameters(name, value):
    import dirac
    from dirac.errors import InputError

    assume(name not in dirac.builtin_systems())
    with pytest.raises(InputError):
        dirac.load_system(name)
    if not (isinstance(value, float) and math.isfinite(value)):
        with pytest.raises(InputError):
            dirac.load_system("pendulum", l=value)


# ----------------------------------------------------------------------------- constraint surface
@settings(max_examples=10, deadline=None, derandomize=True, suppress_health_check=[HealthCheck.function_scoped_fixture])
@given(angle=st.floats(-3.0, 3.0), radius=st.one_of(st.floats(0.5, 0.999), st.floats(1.001, 2.0)),
       radial_speed=st.one_of(st.floats(-2.0, -1e-3), st.floats(1e-3, 2.0)), which=st.booleans())
def test_initial_data_off_the_constraint_surface_is_refused(angle, radius, radial_speed, which, run_scene):
    """Pendulum (l = 1): q off the circle, or q on it with a radial velocity."""
    x, y = math.sin(angle), -math.cos(angle)
    if which:
        initial = {"q": {"x": radius * x, "y": radius * y}}
        phrase = "off the constraint surface"
    else:
        initial = {"q": {"x": x, "y": y}, "q_dot": {"x": radial_speed * x, "y": radial_speed * y}}
        phrase = "not tangent"
    scene = {"system": {"name": "pendulum"}, "initial": initial,
             "run": {"t_end": 0.1, "method": "rattle-2", "dt": 0.01, "samples": 2}}
    status, err, out = run_scene(toml_document(scene))
    assert phrase in assert_one_error_line(status, err)
    assert not out.exists()
