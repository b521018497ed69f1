"""The tape machine as a road of the tier rule: the same numbers as the interpreted and the
compiled tiers to the last bit, on step loops of different shapes; taken when it ends a run
before both; a run it cannot finish (an error where Python raises) goes on as the interpreted
tier would; a loop it declines keeps the two other roads."""

from __future__ import annotations

import numpy as np
import pytest
from sine_loop import SINE_LOOP, hand_loop

from dirac.codegen import tiers
from dirac.flows.integration import integrate
from dirac.flows.problems import ConstrainedProblem


def _captured_loop(model_name: str, monkeypatch) -> tuple[tiers.TieredModule, str, tuple]:
    """The generated module of a latency-corpus system, the name of the step loop its
    ``rattle-2`` run calls, and that call's arguments (copied at its first call)."""
    from dirac_systems.latency_models import MODELS

    model = MODELS[model_name]()
    n = len(model.state) // 2
    problem = ConstrainedProblem(model.system, q0=model.state[:n], p0=model.state[n:])
    return _capture(problem, "rattle-2", monkeypatch)


def _capture(problem, method: str, monkeypatch, name: str | None = None) -> tuple[tiers.TieredModule, str, tuple]:
    """The generated module of ``problem``, the name of the step loop its run with ``method``
    calls first (or the loop ``name``), and that call's arguments (copied at its first call)."""
    captured: list[tuple[tiers.TieredModule, str, tuple]] = []
    original = tiers.TieredFunction.run_steps

    def spy(self, steps, planned, *args):  # whatever the tier (the kernel may be in the cache already)
        if not captured and self._split_positions() is not None and name in (None, self.name):
            captured.append((self.module, self.name, tuple(a.copy() if isinstance(a, np.ndarray) else a for a in args)))
        return original(self, steps, planned, *args)

    monkeypatch.setattr(tiers.TieredFunction, "run_steps", spy)
    monkeypatch.setenv("DIRAC_TAPE", "0")
    integrate(problem, method, dt=1e-3, t_end=0.005)
    monkeypatch.setattr(tiers.TieredFunction, "run_steps", original)
    return captured[0]


def _fresh(args: tuple, steps: int) -> list:
    fresh = [a.copy() if isinstance(a, np.ndarray) else a for a in args]
    fresh[6] = steps  # n_steps of every RATTLE loop (q, p, t, c, fractions, dt, n_steps, ...)
    return fresh


@pytest.mark.parametrize("model_name", ["triple_pendulum_angles", "symmetric_top_euler", "double_pendulum_cartesian"])
def test_tape_interpreted_and_compiled_end_a_thousand_steps_on_the_same_bits(model_name: str, monkeypatch) -> None:
    """1000 RATTLE steps of three shapes of system: a triple pendulum in angles (a 3 x 3
    configuration-dependent mass), the heavy symmetric top in Euler angles (Goldstein eq.
    5.59; the mass singular at theta = 0), the double pendulum in Cartesian coordinates (two
    holonomic constraints, a constant mass: RATTLE's constrained loop). The three tiers run
    the same operations in the same order, so the final states, the evaluation counts and
    the last residual are equal with ``==``."""
    module, name, args = _captured_loop(model_name, monkeypatch)
    tape = module.tape_function(name)
    assert tape is not None, f"{name} of {model_name} should translate"
    runs = {"interpreted": module.interpreted_function(name), "tape": tape, "compiled": getattr(module.compiled, name)}
    finals = {}
    for tier, function in runs.items():
        state = _fresh(args, 1000)
        function(*state)
        finals[tier] = state
    for tier in ("tape", "compiled"):
        for position in (0, 1, 9):  # q, p, info
            assert np.array_equal(finals[tier][position], finals["interpreted"][position]), (tier, position)
    assert finals["tape"][9][0] == 1000 and finals["tape"][9][1] == 0.0  # all steps done, none failed


def test_a_time_dependent_system_runs_on_the_tape_with_the_interpreters_bits(monkeypatch) -> None:
    """The bead on a hoop turning at a constant rate (a Lagrangian with explicit time: the
    loop reads t, dt and the sub-steps' times): tape and interpreter agree to the last bit."""
    module, name, args = _captured_loop("bead_on_rotating_hoop", monkeypatch)
    tape = module.tape_function(name)
    assert tape is not None
    interpreted, on_tape = _fresh(args, 1000), _fresh(args, 1000)
    module.interpreted_function(name)(*interpreted)
    tape(*on_tape)
    for position in (0, 1, 9):
        assert np.array_equal(on_tape[position], interpreted[position])



@pytest.mark.parametrize("model_name", ["relativistic_oscillator", "anharmonic_oscillator", "quartic_oscillator",
                                        "pendulum_cartesian", "spherical_pendulum"])
def test_the_midpoint_loop_runs_on_the_tape_with_the_interpreters_and_numbas_bits(model_name: str, monkeypatch) -> None:
    """The implicit midpoint loop of an analysed flow (its Newton matrix of size 2n, factored
    by an unrolled LU whose pivots the interpreted text holds as doubles): the relativistic
    oscillator (its square root of H, the constraints solved out of the flow) and a regular
    anharmonic oscillator ``L = x'^2/2 - k x^2/2 - x^4/4`` and the quartic one without a parameter
    (its loop never reads the empty parameter vector), 500 steps on the three tiers end on
    the same state, evaluation count and residual. Two flows projected onto their
    second-class constraints after each step (the pendulum in Cartesian coordinates, z of
    size 6 and 4 constraints; the spherical pendulum, 8 and 4), whose projection numba
    compiles as a function and the interpreted text inlines
    (:func:`~dirac.codegen.flatten.inline_worked_helpers`), likewise."""
    import dirac
    from dirac.flows.analysed import AnalysedProblem, AnalysedSystem
    from dirac_systems.latency_models import MODELS

    if model_name == "relativistic_oscillator":
        model = MODELS[model_name]()
        analysed = AnalysedSystem.from_analysis(dirac.analyze(model.system))
        z0 = np.asarray(model.state, dtype=float)
    elif model_name == "anharmonic_oscillator":
        lagrangian = dirac.Lagrangian.from_strings(model_name, ["x"], "x_dot**2/2 - k*x**2/2 - x**4/4",
                                                   parameters={"k": 1.5})
        analysed = AnalysedSystem.from_analysis(dirac.analyze(lagrangian))
        z0 = np.array([0.5, 0.25])
    elif model_name == "pendulum_cartesian":
        analysed = AnalysedSystem.from_analysis(dirac.analyze(MODELS[model_name]().system))
        z0 = analysed.initial_state({"x": 0.8414709848078965, "y": -0.5403023058681398}, q_dot={"x": 0.0, "y": 0.0})
    elif model_name == "spherical_pendulum":
        analysed = AnalysedSystem.from_analysis(dirac.analyze(dirac.load_system(model_name)))
        z0 = analysed.initial_state({"x": 0.8414709848078965, "y": 0.0, "z": -0.5403023058681398},
                                    q_dot={"x": 0.0, "y": 1.0, "z": 0.0})
    else:  # no parameters: the loop never reads its (empty) parameter vector
        lagrangian = dirac.Lagrangian.from_strings(model_name, ["x"], "x_dot**2/2 - x**4/4")
        analysed = AnalysedSystem.from_analysis(dirac.analyze(lagrangian))
        z0 = np.array([0.5, 0.25])
    module, name, args = _capture(AnalysedProblem(analysed, z0), "midpoint", monkeypatch, "midpoint_run")
    reasons: list[str] = []
    from dirac.codegen.tape_source import translate

    assert translate(module._texts[name], name, reasons) is not None, reasons
    if model_name in ("pendulum_cartesian", "spherical_pendulum"):  # numba's text still calls the projection
        from dirac.codegen.flatten import function_text

        assert "project(z, " in (function_text(module.source, name) or "")
        assert "project(" not in module._texts[name]
    tape = module.tape_function(name)
    assert tape is not None
    finals = {}
    for tier, function in {"interpreted": module.interpreted_function(name), "tape": tape,
                           "compiled": getattr(module.compiled, name)}.items():
        state = [a.copy() if isinstance(a, np.ndarray) else a for a in args]
        state[4] = 500  # midpoint_run(z, t, c, dt, n_steps, tol, max_iter, info)
        function(*state)
        finals[tier] = state
    for tier in ("tape", "compiled"):
        for position in (0, 7):  # z, info
            assert np.array_equal(finals[tier][position], finals["interpreted"][position]), (tier, position)
    assert finals["tape"][7][0] == 500 and finals["tape"][7][1] == 0.0


def _loop(tmp_path, monkeypatch, source: str = SINE_LOOP) -> tiers.TieredFunction:
    monkeypatch.setenv("DIRAC_CACHE_DIR", str(tmp_path))
    monkeypatch.setenv("DIRAC_TAPE", "1")
    monkeypatch.setattr(tiers, "_announced", False)
    monkeypatch.setattr(tiers, "_policy", "auto")
    return tiers.TieredModule(source.replace("for a test", f"for a tape test in {tmp_path.name}"),
                              "a loop").function("run")


def test_a_loop_longer_than_a_second_but_shorter_than_its_compilation_goes_on_the_tape(tmp_path, monkeypatch) -> None:
    """Planned for 10^9 steps (hours interpreted) with a compile estimate of 10^9 s: before the
    tape it ran interpreted to its end; now the tape machine ends it far sooner, and its
    iterates are the hand loop's to the last bit."""
    monkeypatch.setattr(tiers, "spare_core", lambda: False)
    monkeypatch.setattr(tiers.TieredFunction, "compile_estimate", lambda self: 1e9)
    function = _loop(tmp_path, monkeypatch)
    x, info = np.array([0.5]), np.zeros(4)
    function.run_steps(3000, 10**9, x, 0.0, 0.1, 3000, info)
    assert function.tier == "tape" and function.background is None
    assert function.tape_steps >= tiers.TAPE_PROBE_STEPS
    assert x[0] == hand_loop(0.5, 3000) and (info[0], info[1], info[2]) == (3000, 0.0, 3000)


def test_a_loop_whose_tape_costs_less_than_any_compilation_never_reads_the_compile_estimate(tmp_path,
                                                                                          monkeypatch) -> None:
    """1.2e5 steps at 10 us a step interpreted (I = 1.2 s, beyond a second): the tape's estimate
    (a fifth of that, 0.24 s; then its measured rate, a fraction of a microsecond a step for this
    loop, which leaves the estimate below the floor even on a machine several times slower or
    busier: 1.2e6 steps of 1 us left too little margin, and a busy run of the suite read the
    estimate) is below the least any compilation is
    estimated at (:meth:`~dirac.codegen.tiers.TieredFunction.compile_floor`), so the tape is
    :func:`~dirac.codegen.tiers.choose_road`'s road whatever the estimate, and the estimate (a
    parse of the module for the kernel's size) is never read, neither to take the tape nor on
    it. The iterates are the hand loop's to the last bit."""
    from dirac.codegen.tape_machine import machine

    machine()  # the machine is there before the run (compiled at the install, else numba's loaded once)

    def unread(self):
        raise AssertionError("the compile estimate was read")

    monkeypatch.setattr(tiers, "spare_core", lambda: False)
    monkeypatch.setattr(tiers.TieredFunction, "compile_estimate", unread)
    monkeypatch.setattr(tiers.TieredFunction, "kernel_chars", unread)
    monkeypatch.setattr(tiers.TieredFunction, "seconds_per_step", lambda self: 1e-5)
    function = _loop(tmp_path, monkeypatch)
    assert 1.2e5 * 1e-5 / tiers.TAPE_SPEEDUP < function.compile_floor()
    assert tiers.choose_road(1.2, function.compile_floor(), None, 1.2e5 * 1e-5 / tiers.TAPE_SPEEDUP) == "tape"
    x, info = np.array([0.5]), np.zeros(4)
    function.run_steps(3000, 120_000, x, 0.0, 0.1, 3000, info)
    assert function.tier == "tape" and function.tape_steps == 3000
    assert x[0] == hand_loop(0.5, 3000) and (info[0], info[1], info[2]) == (3000, 0.0, 3000)


def test_a_short_loop_stays_interpreted_without_the_machine(tmp_path, monkeypatch) -> None:
    """40 steps: far below a second interpreted; neither the tape nor the compiler is asked for."""
    function = _loop(tmp_path, monkeypatch)
    x, info = np.array([0.5]), np.zeros(4)
    function.run_steps(40, 40, x, 0.0, 0.1, 40, info)
    assert function.tier == "interpreted" and function.tape_steps == 0
    assert x[0] == hand_loop(0.5, 40)


def test_the_translation_is_priced_by_the_loops_text(tmp_path, monkeypatch) -> None:
    """The price of a translation: the fixed figure before the loop's interpreted text exists,
    then its length times the measured cost of a character (at least the floor), nothing once
    translated."""
    function = _loop(tmp_path, monkeypatch)
    assert function.translate_estimate() == tiers.TAPE_TRANSLATE_SECONDS
    x, info = np.array([0.5]), np.zeros(4)
    function.run_steps(40, 40, x, 0.0, 0.1, 40, info)
    text = function.module._texts["run"]
    assert function.translate_estimate() == max(tiers.TAPE_TRANSLATE_FLOOR,
                                                tiers.TAPE_TRANSLATE_SECONDS_PER_CHAR * len(text))
    function.module.tape_function("run")
    assert function.translate_estimate() == 0.0


def test_a_loop_run_again_and_again_buys_its_tape_once_it_has_spent_its_price(tmp_path, monkeypatch) -> None:
    """Short runs of one loop (as auto's pilots make), each far below its translation: the loop
    stays interpreted until the interpreted time spent reaches the translation's estimate
    (rent or buy), then goes on the tape; the iterates are the hand loop's to the last bit."""
    from dirac.codegen.tape_machine import machine

    machine()
    function = _loop(tmp_path, monkeypatch)
    x, info = np.array([0.5]), np.zeros(4)
    spent: list[float] = []  # the interpreted time before each run
    while function.tier == "interpreted" and len(spent) < 100_000:
        spent.append(function.interpreted_seconds)
        function.run_steps(40, 40, x, 0.0, 0.1, 40, info)
    runs = len(spent)
    assert function.tier == "tape" and runs >= 2
    price = max(tiers.TAPE_TRANSLATE_FLOOR, tiers.TAPE_TRANSLATE_SECONDS_PER_CHAR * len(function.module._texts["run"]))
    assert spent[-2] < price <= spent[-1]  # bought by the first run that started with the price spent
    assert price < tiers.TAPE_TRANSLATE_SECONDS  # the small loop's text: not the fixed figure
    assert x[0] == hand_loop(0.5, 40 * runs)


def test_the_pilots_of_a_longer_run_buy_the_tape_at_their_first_run(tmp_path, monkeypatch) -> None:
    """The same short runs, said to be pilots of a longer run of the loop (auto's): the
    translation counts as paid, so the first run goes on the tape after the one interpreted
    step that measures the rate, long before the interpreted time reaches the price; the
    iterates are still the hand loop's to the last bit."""
    from dirac.codegen.tape_machine import machine

    machine()
    function = _loop(tmp_path, monkeypatch)
    function.expect_longer_run()
    x, info = np.array([0.5]), np.zeros(4)
    function.run_steps(40, 40, x, 0.0, 0.1, 40, info)
    price = max(tiers.TAPE_TRANSLATE_FLOOR, tiers.TAPE_TRANSLATE_SECONDS_PER_CHAR * len(function.module._texts["run"]))
    assert function.tier == "tape" and function.interpreted_steps == 1
    assert function.interpreted_seconds < price
    function.run_steps(40, 40, x, 0.0, 0.1, 40, info)
    assert function.interpreted_steps == 1  # the second run entirely on the tape
    assert x[0] == hand_loop(0.5, 80)


def test_auto_says_its_pilots_are_pilots_and_its_run_is_not(monkeypatch) -> None:
    """``method = "auto"`` runs every pilot with the ``pilot`` option (its loop then buys the tape
    at once) and the run it chose without it."""
    from dirac.flows.methods import constrained_stepper

    calls: list[bool] = []
    original = constrained_stepper.call_tiered

    def spy(kernel, planned_steps, steps_done, steps, args, warm_up=False, pilot=False):
        calls.append(pilot)
        return original(kernel, planned_steps, steps_done, steps, args, warm_up, pilot=pilot)

    monkeypatch.setattr(constrained_stepper, "call_tiered", spy)
    from dirac_systems.latency_models import MODELS

    model = MODELS["double_pendulum_angles"]()
    problem = ConstrainedProblem(model.system, q0=model.state[:2], p0=model.state[2:])
    pilots: list[int] = []
    from dirac.flows.methods import auto

    chosen = auto.choose_method

    def counted(*args, **kwargs):
        choice = chosen(*args, **kwargs)
        pilots.append(len(calls))
        return choice

    monkeypatch.setattr(auto, "choose_method", counted)
    run = integrate(problem, t_end=2.0, samples=11)
    assert run.method.startswith("rattle-") and pilots
    assert calls[:pilots[0]] and all(calls[:pilots[0]])  # every call of the choice: a pilot's
    assert calls[pilots[0]:] and not any(calls[pilots[0]:])  # the run: not a pilot


def test_a_run_of_unknown_length_on_the_tape_compiles(tmp_path, monkeypatch) -> None:
    """Once on the tape, a run whose length is unknown has no tape estimate: it compiles (a
    long run ends on the compiled tier)."""
    monkeypatch.setattr(tiers.TieredFunction, "compile_estimate", lambda self: 1e9)
    roads: list[str] = []
    monkeypatch.setattr(tiers.TieredFunction, "compile", lambda self, why, args=None: roads.append(why))
    function = _loop(tmp_path, monkeypatch)
    x, info = np.array([0.5]), np.zeros(4)
    function.run_steps(3000, 10**9, x, 0.0, 0.1, 3000, info)
    assert function.tier == "tape" and not roads
    function._decide(None, (x, 0.0, 0.1, 1, info))
    assert len(roads) == 1 and function.tier == "interpreted"  # compile() (faked here) takes over


def test_a_division_by_zero_on_the_tape_behaves_as_on_the_interpreted_tier(tmp_path, monkeypatch) -> None:
    """x <- x - 1, then 1 / x, from x = 3000 reaches x = 0 exactly at step 3000: the interpreted
    tier raises ZeroDivisionError there (with the steps before it done in place).
    On the tape the machine stops at the division, the part is rerun interpreted from the
    state it was given, and the same error comes with the same state."""
    source = SINE_LOOP.replace("x[0] = x[0] + math.sin(x[0]) / 8.0", "x[0] = x[0] - 1.0\n        evals += x[1] / x[0]")
    outcomes = []
    for tape in ("1", "0"):
        folder = tmp_path / tape
        folder.mkdir()
        monkeypatch.setattr(tiers.TieredFunction, "compile_estimate", lambda self: 1e9)
        function = _loop(folder, monkeypatch, source)
        monkeypatch.setenv("DIRAC_TAPE", tape)
        x, info = np.array([3000.0, 1.0]), np.zeros(4)
        with pytest.raises(ZeroDivisionError):
            function.run_steps(4000, 10**9, x, 0.0, 0.1, 4000, info)
        outcomes.append((x.tolist(), function.tape_failed))
    (x_tape, failed), (x_interpreted, _) = outcomes
    assert x_tape == x_interpreted == [0.0, 1.0] and failed


def test_a_loop_the_tape_declines_keeps_the_two_other_roads(tmp_path, monkeypatch) -> None:
    """x ** 2 is not translated (CPython's and numba's powers are not the machine's
    multiplication): no tape, and the rule of two roads decides (here: interpreted to the end
    of a loop shorter than its compilation)."""
    monkeypatch.setattr(tiers.TieredFunction, "compile_estimate", lambda self: 1e9)
    source = SINE_LOOP.replace("x[0] + math.sin(x[0]) / 8.0", "x[0] + math.sin(x[0]) ** 2 / 8.0")
    function = _loop(tmp_path, monkeypatch, source)
    x, info = np.array([0.5]), np.zeros(4)
    function.run_steps(3000, 10**9, x, 0.0, 0.1, 3000, info)
    assert function.module.tape_function("run") is None
    assert function.tier == "interpreted" and function.tape_steps == 0


@pytest.mark.parametrize(("interpreted", "compile_seconds", "background", "tape", "road"), [
    # the triple pendulum's 1e5-step study, by hand: 50 us a step interpreted (I = 5 s), E = 4.19 s,
    # the tape at a fifth of the interpreted rate (1 s) after the machine's 1.4 s: T = 2.4 s
    (5.0, 4.19, None, 2.4, "tape"),
    # the same loop for 1e6 steps: I = 50 s, T = 1.4 + 10 = 11.4 s > E: it compiles
    (50.0, 4.19, None, 11.4, "compile"),
    # 3e4 steps: I = 1.5 s, T = 1.4 + 0.3 = 1.7 s > I: interpreted (the machine would not pay)
    (1.5, 4.19, None, 1.7, "interpreted"),
    # I below a second: the tape when the machine costs nothing to get (compiled at the install)
    # and it saves more than the loop's translation (0.1 s): T + 0.1 = 0.3 < 0.9
    (0.9, 4.19, None, 0.2, "tape"),
    # ... not when the machine must first be compiled (numba's import and the loop: T = 1.4 + 0.2)
    (0.9, 4.19, None, 1.6, "interpreted"),
    # ... nor when the saving is below the translation's cost: 0.03 + 0.1 > 0.12
    (0.12, 4.19, None, 0.03, "interpreted"),
    # no tape: the table of two roads, unchanged
    (5.0, 4.19, None, None, "compile"),
    (6.0, 4.19, 5.0, None, "background"),
    (3.0, 4.19, None, None, "interpreted"),
    # T = E: the tape (no wait for a compiler, the same numbers)
    (6.0, 4.19, 5.0, 4.19, "tape"),
])
def test_choose_road_with_a_tape_follows_its_table(interpreted, compile_seconds, background, tape, road) -> None:
    """choose_road against its table, worked by hand with COMPILE_SECONDS = 1 and WAIT_FACTOR = 2."""
    assert tiers.COMPILE_SECONDS == 1.0 and tiers.WAIT_FACTOR == 2.0
    assert tiers.choose_road(interpreted, compile_seconds, background, tape) == road


def test_a_mechanical_midpoint_loop_keeps_its_field_a_call_with_numbas_bits(monkeypatch) -> None:
    """The midpoint loop of a mechanical system (the Cartesian pendulum, ``ConstrainedProblem``)
    hands ``field_into`` a tuple of 17 work arrays, but the field takes views ``z[:n]`` (and
    calls ``dirac_projection``), which the tape does not translate: the interpreted text keeps
    the call (inlining it only made a first run dearer), the tape declines the loop, and 500
    steps interpreted end on numba's z and info."""
    import dirac
    from dirac.codegen.flatten import function_text
    from dirac.codegen.tape_source import translate
    from dirac_systems.latency_models import MODELS

    model = MODELS["pendulum_cartesian"]()
    problem = ConstrainedProblem(model.system, model.state[:2], model.state[2:])
    captured: list[tuple[tiers.TieredModule, str, tuple]] = []
    original = tiers.TieredFunction.run_steps

    def spy(self, steps, planned, *args):
        if not captured and self.name == "midpoint_run":
            captured.append((self.module, self.name, tuple(a.copy() if isinstance(a, np.ndarray) else a for a in args)))
        return original(self, steps, planned, *args)

    monkeypatch.setattr(tiers.TieredFunction, "run_steps", spy)
    monkeypatch.setenv("DIRAC_TAPE", "0")
    dirac.integrate(problem, "midpoint", dt=1e-3, t_end=0.005)
    monkeypatch.setattr(tiers.TieredFunction, "run_steps", original)
    module, name, args = captured[0]
    assert "field_into(zz, " in (function_text(module.source, name) or "")
    assert "field_into(zz, " in module._texts[name]
    reasons: list[str] = []
    assert translate(module._texts[name], name, reasons) is None and reasons
    finals = {}
    for tier, function in {"interpreted": module.interpreted_function(name),
                           "compiled": getattr(module.compiled, name)}.items():
        state = [a.copy() if isinstance(a, np.ndarray) else a for a in args]
        state[4] = 500  # midpoint_run(z, t, c, dt, n_steps, tol, max_iter, info)
        function(*state)
        finals[tier] = state
    for position in (0, 7):
        assert np.array_equal(finals["compiled"][position], finals["interpreted"][position]), position
    assert finals["compiled"][7][0] == 500 and finals["compiled"][7][1] == 0.0
