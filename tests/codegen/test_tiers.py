"""The two tiers of a generated module: interpreted and compiled give the same numbers;
the first compilation says so on stderr, once, and never on a warm cache."""

from __future__ import annotations

import math
import sys

import numpy as np
import pytest
from sine_loop import SINE_LOOP, hand_loop

from dirac import Lagrangian
from dirac.codegen import tiers
from dirac.codegen.numba_backend import interpret_source
from dirac.flows.integration import integrate
from dirac.flows.problems import ConstrainedProblem

_SOURCE = '''"""tiny -- generated for a test"""
import math
import numpy as np
import numba


@numba.njit(cache=True)
def run(x, n_steps, out):
    """n_steps of x <- x + sin(x) / 8 (a map whose iterates a hand loop reproduces)."""
    for _ in range(n_steps):
        x = x + math.sin(x) / 8.0
    out[0] = x
'''


def _pendulum() -> Lagrangian:
    return Lagrangian.from_strings("pendulum", ["x", "y"], "m/2*(x_dot**2 + y_dot**2) - m*g*y",
                                   constraints=["x**2 + y**2 - l**2"], parameters={"m": 1.0, "g": 9.81, "l": 1.0})


def test_interpreted_source_runs_without_numba_and_matches_a_hand_loop() -> None:
    module = interpret_source(_SOURCE)
    out = np.empty(1)
    module.run(0.5, 20, out)
    x = 0.5
    for _ in range(20):
        x += np.sin(x) / 8.0
    assert out[0] == pytest.approx(x, rel=1e-15)
    assert "numba" not in type(module.run).__module__  # a plain Python function


def test_first_compilation_is_announced_once_with_the_cache_and_not_again(monkeypatch, tmp_path, capsys) -> None:
    monkeypatch.setenv("DIRAC_CACHE_DIR", str(tmp_path))
    monkeypatch.setattr(tiers, "_announced", False)
    source = _SOURCE.replace("for a test", f"for a test in {tmp_path.name}")  # a source of its own: a cold cache
    module = tiers.TieredModule(source, "a test module")
    function = module.function("run")
    assert function.tier == "interpreted"
    out = np.empty(1)
    function.run_steps(3, None, 0.5, 3, out)  # unknown run length: compiles at once
    assert function.tier == "compiled"
    err = capsys.readouterr().err
    assert err.count("dirac: compiling") == 1
    assert str(tmp_path) in err and "DIRAC_CACHE_DIR" in err and "run of a test module" in err
    # a second module of another source in the same process: no second line
    other = tiers.TieredModule(source + "\n# another source\n", "another module")
    other.function("run").run_steps(3, None, 0.5, 3, out)
    assert capsys.readouterr().err == ""
    # the same source imported afresh (a later process): numba's cache is warm, no compilation
    monkeypatch.setattr(tiers, "_announced", False)
    for name in [name for name in sys.modules if name.startswith("dirac_gen_")]:
        if sys.modules[name].__file__ and str(tmp_path) in sys.modules[name].__file__:
            del sys.modules[name]
    again = tiers.TieredModule(source, "a test module").function("run")
    assert again.tier == "compiled"
    again(0.5, 3, out)
    assert capsys.readouterr().err == ""


@pytest.mark.parametrize("method", ["rattle-2", "midpoint"])
def test_a_short_run_is_interpreted_and_gives_the_compiled_numbers(method: str, monkeypatch) -> None:
    """Same source, same floating-point operations: the two tiers agree to the last bit."""
    q0, p0 = [np.sin(1.0), -np.cos(1.0)], [0.3 * np.cos(1.0), 0.3 * np.sin(1.0)]
    short = ConstrainedProblem(_pendulum(), q0, p0)
    kernel = "midpoint_run" if method == "midpoint" else "rattle_constant_mass"
    function = short.mechanics.module.function(kernel)
    before = function.interpreted_calls
    interpreted = integrate(short, method, t_end=0.05, dt=0.01, samples=6)
    assert function.interpreted_calls > before or function.tier == "compiled"  # interpreted unless compiled already
    monkeypatch.setenv("DIRAC_KERNELS", "compiled")
    compiled = integrate(ConstrainedProblem(_pendulum(), q0, p0), method, t_end=0.05, dt=0.01, samples=6)
    assert function.tier == "compiled"
    np.testing.assert_array_equal(interpreted.outputs["q"], compiled.outputs["q"])
    np.testing.assert_array_equal(interpreted.outputs["p"], compiled.outputs["p"])


def test_policy_names_are_checked(monkeypatch) -> None:
    with pytest.raises(ValueError, match="auto, compiled"):
        tiers.set_policy("fast")
    previous = tiers.set_policy("compiled")
    assert tiers.current_policy() == "compiled"
    assert tiers.set_policy(previous) == "compiled"
    monkeypatch.setenv("DIRAC_KERNELS", "fastest")
    with pytest.warns(UserWarning, match="DIRAC_KERNELS='fastest'"):
        assert tiers.current_policy() == "auto"




def _loop_module(tmp_path, monkeypatch) -> tiers.TieredFunction:
    # the roads of a loop without a tape (one the tape declines, or DIRAC_TAPE=0): the tape's
    # rows of the table are tested in test_tape_tiers.py
    monkeypatch.setenv("DIRAC_TAPE", "0")
    monkeypatch.setenv("DIRAC_CACHE_DIR", str(tmp_path))
    monkeypatch.setattr(tiers, "_announced", False)
    monkeypatch.setattr(tiers, "_policy", "auto")
    return tiers.TieredModule(SINE_LOOP.replace("for a test", f"for a test in {tmp_path.name}"), "a loop").function("run")


def test_a_long_loop_compiles_in_the_background_and_switches_at_a_step_boundary(tmp_path, monkeypatch, capsys) -> None:
    """Planned beyond a second of interpreted work and beyond the estimated compilation, yet
    less than twice it, with an idle core: a child process compiles while the loop goes on
    interpreted in parts; after it is done the next part runs compiled. The iterates are the
    hand loop's to the last bit (the same operations)."""
    monkeypatch.setattr(tiers, "spare_core", lambda: True)
    # 0.6 of the interpreted remainder (measured rate times the 10^9 steps planned): remainder / estimate = 1.67
    monkeypatch.setattr(tiers.TieredFunction, "compile_estimate", lambda self: 0.6 * (self.seconds_per_step() or 0.0) * 1e9)
    function = _loop_module(tmp_path, monkeypatch)
    x, info = np.array([0.5]), np.zeros(4)
    function.run_steps(300, 10**9, x, 0.0, 0.1, 300, info)
    assert function.background is not None and function.tier == "interpreted"
    assert "in a separate process" in capsys.readouterr().err
    assert (info[0], info[1], info[2]) == (300, 0.0, 300)  # parts add up to one call's report
    assert function.finish_background(timeout=300) is True
    function.run_steps(200, 10**9, x, 30.0, 0.1, 200, info)
    assert function.tier == "compiled" and function.background is None
    assert x[0] == hand_loop(0.5, 500)
    assert function.ready_marker().exists()
    history = (tmp_path / "compile_history.json").read_text()
    assert '"chars"' in history and "background" in history


def test_a_long_loop_on_a_busy_machine_compiles_in_the_process(tmp_path, monkeypatch) -> None:
    """No idle core and a run far longer than the estimated compilation: compiled at once in
    the process (the cheapest in CPU), after one interpreted step that measured the rate."""
    monkeypatch.setattr(tiers, "spare_core", lambda: False)
    function = _loop_module(tmp_path, monkeypatch)
    x, info = np.array([0.5]), np.zeros(4)
    function.run_steps(50, 10**12, x, 0.0, 0.1, 50, info)
    assert function.background is None and function.tier == "compiled"
    assert function.interpreted_steps == 1
    assert x[0] == hand_loop(0.5, 50) and info[0] == 50 and info[2] == 50


def test_a_loop_far_longer_than_its_compilation_waits_for_it_even_with_an_idle_core(tmp_path, monkeypatch) -> None:
    """An interpreted remainder above WAIT_FACTOR times the estimated compile time: compiled
    at once in the process (a child would add its start-up to the wait), after one
    interpreted step that measured the rate; the iterates are the hand loop's."""
    monkeypatch.setattr(tiers, "spare_core", lambda: True)
    function = _loop_module(tmp_path, monkeypatch)
    x, info = np.array([0.5]), np.zeros(4)
    function.run_steps(50, 10**12, x, 0.0, 0.1, 50, info)
    assert function.background is None and function.tier == "compiled"
    assert function.interpreted_steps == 1
    assert x[0] == hand_loop(0.5, 50) and info[0] == 50 and info[2] == 50


def test_kernel_size_counts_the_function_and_what_it_calls_not_the_module() -> None:
    """The size of what numba compiles for one function: its definition and those of the
    module's functions it calls, directly or not (counted by hand below), not the others."""
    from dirac.codegen.background import kernel_chars

    a = "def a(x):\n    return b(x) + 1"
    b = "def b(x):\n    return c(x) * 2"
    c = "def c(x):\n    return x"
    unused = "def unused(x):\n    return a(x) - b(x) - c(x)"
    source = "\n\n".join([a, b, c, unused]) + "\n"
    assert kernel_chars(source, "a") == len(a) + len(b) + len(c)
    assert kernel_chars(source, "c") == len(c)
    assert kernel_chars(source, "unused") == len(source) - 7  # all four definitions: the source less its separators


def test_a_loop_shorter_than_its_compilation_starts_none_even_with_an_idle_core(tmp_path, monkeypatch) -> None:
    """Planned beyond a second of interpreted work but below the estimated compile time: no
    compilation, in the process or beside it, since it would cost more CPU than the whole
    interpreted remainder; the loop runs interpreted to the end, the hand loop's iterates."""
    monkeypatch.setattr(tiers, "spare_core", lambda: True)
    monkeypatch.setattr(tiers.TieredFunction, "compile_estimate", lambda self: 1e9)
    function = _loop_module(tmp_path, monkeypatch)
    x, info = np.array([0.5]), np.zeros(4)
    function.run_steps(300, 10**9, x, 0.0, 0.1, 300, info)
    assert function.background is None and function.tier == "interpreted"
    assert x[0] == hand_loop(0.5, 300) and info[0] == 300 and info[2] == 300


def test_a_short_loop_stays_interpreted_and_starts_no_compilation(tmp_path, monkeypatch) -> None:
    monkeypatch.setattr(tiers, "spare_core", lambda: True)
    function = _loop_module(tmp_path, monkeypatch)
    x, info = np.array([0.5]), np.zeros(4)
    function.run_steps(40, 40, x, 0.0, 0.1, 40, info)
    assert function.background is None and function.tier == "interpreted"
    assert x[0] == hand_loop(0.5, 40) and info[0] == 40


def test_the_rattle_loop_of_a_configuration_dependent_mass_gives_the_same_numbers_on_both_tiers(monkeypatch) -> None:
    """The heavy symmetric top in Euler angles (Goldstein eq. 5.59): its mass depends on
    theta, so RATTLE runs the general loop (one residual site, M(q, tau) factored once per
    sub-step). Interpreted and compiled agree to the last bit; phi and psi are cyclic, so
    p_phi and p_psi stay at their initial values (Goldstein Sect. 5.7) up to rounding."""
    top = Lagrangian.from_strings(
        "symmetric_top_tiers", ["ph", "th", "ps"],
        "I1/2*(th_dot**2 + ph_dot**2*sin(th)**2) + I3/2*(ps_dot + ph_dot*cos(th))**2 - M*g*l*cos(th)",
        parameters={"I1": 1.0, "I3": 0.5, "M": 1.0, "g": 9.81, "l": 1.0})
    q0, p0 = [0.0, 0.5, 0.0], [0.3, 0.0, 2.0]
    problem = ConstrainedProblem(top, q0, p0)
    function = problem.mechanics.module.function("rattle_general")
    before = function.interpreted_calls
    interpreted = integrate(problem, "rattle-2", t_end=0.02, dt=1e-3, samples=5)
    assert function.interpreted_calls > before or function.tier == "compiled"
    monkeypatch.setenv("DIRAC_KERNELS", "compiled")
    compiled = integrate(ConstrainedProblem(top, q0, p0), "rattle-2", t_end=0.02, dt=1e-3, samples=5)
    assert function.tier == "compiled"
    np.testing.assert_array_equal(interpreted.outputs["q"], compiled.outputs["q"])
    np.testing.assert_array_equal(interpreted.outputs["p"], compiled.outputs["p"])
    p = np.asarray(compiled.outputs["p"])
    assert np.max(np.abs(p[:, 0] - 0.3)) < 1e-13 and np.max(np.abs(p[:, 2] - 2.0)) < 1e-13
    assert np.max(np.abs(np.asarray(compiled.outputs["q"])[:, 1] - 0.5)) > 1e-6  # theta moves: a real run


def test_quiet_information_holds_back_the_line_and_restores_the_state(monkeypatch, tmp_path, capsys) -> None:
    """``dirac CMD -q`` promises no informational stderr line; the compilation's announcement
    is one. Inside ``dirac.errors.quiet_information`` a first compilation prints nothing; after
    it the next first compilation of the process is announced again."""
    from dirac.errors import quiet_information

    monkeypatch.setenv("DIRAC_CACHE_DIR", str(tmp_path))
    monkeypatch.setattr(tiers, "_announced", False)
    source = _SOURCE.replace("for a test", f"for a silent test in {tmp_path.name}")
    out = np.empty(1)
    with quiet_information():
        tiers.TieredModule(source, "a silent module").function("run").run_steps(3, None, 0.5, 3, out)
    assert capsys.readouterr().err == ""
    tiers.TieredModule(source + "\n# another\n", "a loud module").function("run").run_steps(3, None, 0.5, 3, out)
    assert capsys.readouterr().err.count("dirac: compiling") == 1


def test_run_quiet_prints_no_compilation_line(monkeypatch, tmp_path, run_cli) -> None:
    """``dirac run SCENE -q`` with a cold cache in a process that has not compiled yet: the
    results go to the file and stderr stays empty (the line used to appear whenever the
    process had not announced before, as in a fresh ``dirac run``)."""
    from pathlib import Path

    monkeypatch.setenv("DIRAC_CACHE_DIR", str(tmp_path / "cache"))
    monkeypatch.setattr(tiers, "_announced", False)
    monkeypatch.setattr(tiers, "_policy", "compiled")  # compile at once, whatever the run's length
    scene = Path(__file__).resolve().parents[2] / "docs" / "scenes" / "pendulum.toml"
    status, out, err = run_cli("run", str(scene), "--out", str(tmp_path / "q.npz"), "-q")
    assert (status, out, err) == (0, "", "")
    assert (tmp_path / "q.npz").exists()


def test_the_cold_first_call_does_not_count_in_the_rate_that_decides_the_tier(tmp_path, monkeypatch) -> None:
    """The first interpreted call of a step loop is cold (here made to burn 0.2 s of CPU, as
    the first call of a generated RATTLE loop took 77 ms against 0.1 ms for the next): the
    warm-up leaves it out of the measured rate, so a run of 1000 steps of a loop that takes
    microseconds a step is estimated at milliseconds, not at 1000 times the cold call, and
    neither compiles nor starts a compilation; its iterates are the hand loop's. Before, the
    rate was the cold call's and the same run compiled."""
    import time

    monkeypatch.setattr(tiers, "spare_core", lambda: True)
    function = _loop_module(tmp_path, monkeypatch)
    plain = function.module.interpreted_function("run")
    calls = []

    def cold_first(*args):
        if not calls:
            start = time.process_time()
            while time.process_time() - start < 0.2:
                pass
        calls.append(args)
        return plain(*args)

    monkeypatch.setattr(function.module, "interpreted_function", lambda name: cold_first)
    scratch, scratch_info = np.array([0.5]), np.zeros(4)
    function.warm_up(1000, scratch, 0.0, 1e-6, 1, scratch_info)
    per_step = function.seconds_per_step()
    assert per_step is not None and per_step < 0.2 / 1000  # counted, the cold call made it 0.2
    x, info = np.array([0.5]), np.zeros(4)
    function.run_steps(1000, 1000, x, 0.0, 0.1, 1000, info)
    assert function.background is None and function.tier == "interpreted"
    assert x[0] == hand_loop(0.5, 1000) and info[0] == 1000 and info[2] == 1000


@pytest.mark.parametrize(("interpreted", "compile_seconds", "background", "road"), [
    (0.9, 0.1, None, "interpreted"),   # under COMPILE_SECONDS: never compiled
    (3.0, 4.0, 2.0, "interpreted"),    # I <= E: the wait would exceed the interpreted run
    (4.0, 4.0, 2.0, "interpreted"),    # I = E: compiling saves nothing
    (8.5, 4.0, 5.0, "compile"),        # I > 2 E: waiting here is the shortest road
    (math.inf, 4.0, 5.0, "compile"),   # a run of unknown length
    (7.0, 4.0, 5.5, "background"),     # E < I <= 2 E and the child ends the run before the interpreter would
    (5.0, 4.0, 5.5, "compile"),        # E < I <= 2 E but B >= I: the background road would only interpret
    (7.0, 4.0, None, "compile"),       # no background road open (busy machine): compile here
])
def test_the_road_table(interpreted: float, compile_seconds: float, background: float | None, road: str) -> None:
    """choose_road against its table, worked by hand with COMPILE_SECONDS = 1 and
    WAIT_FACTOR = 2: walls are interpreted I, compile E, background min(I, B); the background
    road is taken only where compiling pays by less than the factor (I in (E, 2E]) and it
    can end the run sooner than the interpreter (B < I)."""
    assert (tiers.COMPILE_SECONDS, tiers.WAIT_FACTOR) == (1.0, 2.0)
    assert tiers.choose_road(interpreted, compile_seconds, background) == road


def test_the_triple_pendulum_study_compiles_in_the_process_when_the_child_cannot_win(tmp_path, monkeypatch) -> None:
    """The regression this rule fixes, with the study's own figures put in by hand (the rate
    and the estimates are fakes): 1e5 steps at 50 us a step, I = 5 s interpreted; a compile
    estimate E = 4.19 s (its 13663 characters at the default 2.7e-4 s each, 3.69 s, and
    numba's import, 0.5 s); an idle core; numba already imported here (pytest), so the
    background road's estimate is B = 1.45 (0.5 + 4.19) + 0.3 = 7.10 s: 1.45 the slowdown
    of two processes on two shared cores, 0.5 the child's start-up, 0.3 the load from the
    cache. B > I: the child could not end the run before the interpreter, and the loop
    compiles in the process (before, with I in (E, 2E], it started a child: 7.3 s of wall and
    13.1 s of CPU against 4.9 and 5.2). The same loop planned for 1.6e5 steps (I = 8 s, still
    below 2E = 8.38 s, and above B) takes the background road."""
    import sys

    monkeypatch.setitem(sys.modules, "numba", sys.modules.get("numba", object()))  # numba's import: paid
    monkeypatch.setattr(tiers, "spare_core", lambda: True)
    monkeypatch.setattr(tiers.TieredFunction, "compile_estimate", lambda self: 4.19)
    monkeypatch.setattr(tiers.TieredFunction, "seconds_per_step", lambda self: 5e-5)
    monkeypatch.setattr(tiers, "estimate_child_start_seconds", lambda: 0.5)
    roads = []
    monkeypatch.setattr(tiers.TieredFunction, "compile", lambda self, why, args=None: roads.append("compile"))
    monkeypatch.setattr(tiers, "BackgroundCompile", lambda *a: roads.append("background"))
    function = _loop_module(tmp_path, monkeypatch)
    assert function.background_estimate() == pytest.approx(1.45 * (0.5 + 4.19) + 0.3)
    args = (np.array([0.5]), 0.0, 1e-3, 1, np.zeros(4))
    function._decide(100_000, args)
    function._decide(160_000, args)
    assert roads == ["compile", "background"]
