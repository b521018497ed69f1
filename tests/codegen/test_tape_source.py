"""The translation of a generated function to a tape, and the machine that runs it.

The reference is Python itself: each program below is run by the interpreter and by the
tape machine on the same arguments, and the results must be equal to the last bit (the
tape performs the same IEEE 754 operations in the same order). Constructs the tape does not
translate make :func:`translate` decline (None), never a wrong tape."""

from __future__ import annotations

import math

import numpy as np
import pytest

from dirac.codegen import tape_machine
from dirac.codegen.tape_machine import TapeError, TapeFunction, _execute
from dirac.codegen.tape_source import OPS, translate


@pytest.fixture(autouse=True, params=["ahead-of-time", "numba"])
def machine_kind(request, monkeypatch) -> str:
    """Every test runs on both loops of the machine: the one compiled at the install (the C
    extension) and the one numba compiles (where that extension was not built). An engine
    imported without its C loop (a checkout without a build in place) fails the C loop's tests,
    naming the fix."""
    monkeypatch.setattr(tape_machine, "_MACHINE", None)
    if request.param == "numba":
        monkeypatch.setenv(tape_machine.MACHINE_VARIABLE, "numba")
    else:
        monkeypatch.delenv(tape_machine.MACHINE_VARIABLE, raising=False)
        if tape_machine.ahead_of_time() is None:
            pytest.fail(f"dirac.codegen._tape is not built for the engine imported from {tape_machine.__file__}: "
                        "pip install . (or pip install -e .) builds it")
    assert tape_machine.machine_kind() == request.param
    return request.param

_PROGRAM = '''
def kernel(x, out, a, b, n_steps):
    """A bit of every construct: arithmetic, comparisons with NaN and signed zeros, min/max as
    Python picks, abs, math, if/elif/else, and/or/not, a conditional expression, for over
    ranges (negative step too), while with break and continue, a tuple swap, a 2-D work array."""
    W = np.empty((2, 3))
    acc = 0.0
    k = 0
    for i in range(3):
        for j in range(3):
            W[1 if i > 0 else 0, j] = x.item(i) * (j + 1) - a
    for i in range(2, -1, -1):
        acc += W[1 if i == 2 else 0, i] / (1.0 + abs(x[i]))
    u, v = a, b
    u, v = v, u
    if a < b and not (b != b):
        out[0] = min(a, b)
    elif a > b or a != a:
        out[0] = max(a, b)
    else:
        out[0] = -a
    out[1] = acc
    out[2] = u - v
    out[3] = math.sqrt(abs(a)) + math.sin(b) * math.cos(a) - math.exp(-abs(b)) + math.atan2(a, 1.0 + b * b)
    s = 0.0
    while k < n_steps:
        k += 1
        if k == 2:
            continue
        s = s * 0.5 + k
        if s > 50.0:
            break
    out[4] = s
    out[5] = float(k)
    out[6] = a if a == a else -1.0
    out[7] = (a < b) + 0.0
    out[8] = -0.0 * a
    out[9] = 1.0 / 3.0 * a - b / 7.0
'''


def _python(source: str, name: str):
    namespace = {"np": np, "math": math}
    exec(source, namespace)
    return namespace[name]


def _both(a: float, b: float, n: int) -> tuple[np.ndarray, np.ndarray] | None:
    """Outputs of Python and of the tape; None when Python raised and the tape stopped."""
    x = np.array([0.3, -1.25, 2.0])
    tape = translate(_PROGRAM, "kernel")
    assert tape is not None
    out_python, out_tape = np.zeros(10), np.zeros(10)
    try:
        _python(_PROGRAM, "kernel")(x.copy(), out_python, a, b, n)
    except (ValueError, OverflowError, ZeroDivisionError):
        with pytest.raises(TapeError):
            TapeFunction(tape)(x.copy(), out_tape, a, b, n)
        return None
    TapeFunction(tape)(x.copy(), out_tape, a, b, n)
    return out_python, out_tape


@pytest.mark.parametrize(("a", "b", "n"), [(0.7, 1.9, 5), (2.5, -0.5, 40), (-0.0, 0.0, 0), (0.0, -0.0, 1),
                                           (math.nan, 1.0, 3), (1.0, math.nan, 3), (math.inf, 2.0, 7),
                                           (1e308, 1e308, 100), (-3.0, -3.0, 2)])
def test_the_tape_gives_pythons_numbers_to_the_last_bit(a: float, b: float, n: int) -> None:
    """Python's own evaluation of the same source is the reference; equal bit patterns
    (signed zeros and NaN included) on every output; where Python raises (cos(inf)), the
    machine stops."""
    both = _both(a, b, n)
    if both is not None:
        assert both[0].tobytes() == both[1].tobytes()
    else:
        assert math.isinf(a) or math.isinf(b)


def test_the_machine_run_by_python_agrees_with_the_compiled_machine() -> None:
    """The machine's loop is plain Python too: interpreted on the same tape it gives the same
    registers and memory as the compiled machine (the two readings of one definition)."""
    tape = translate(_PROGRAM, "kernel")
    assert tape is not None
    function = TapeFunction(tape)
    x, out = np.array([0.3, -1.25, 2.0]), np.zeros(10)
    function(x, out, 0.7, 1.9, 5)
    mem, base, rows, cols = function._memory([x, out])
    reg = function.registers.copy()
    for (kind, where), value in zip(tape.parameters, (x, np.zeros(10), 0.7, 1.9, 5)):
        if kind == "scalar":
            reg[where] = float(value)
        else:
            mem[base[where]:base[where] + rows[where]] = value
    assert _execute(function.code, reg, mem, base, rows, cols) == 0
    assert mem[base[1]:base[1] + 10].tobytes() == out.tobytes()


@pytest.mark.parametrize(("body", "why"), [
    ("out[0] = x[0] ** 2", "the operator Pow"),
    ("out[0] = x[0] // 2.0", "the operator FloorDiv"),
    ("out[0] = helper(x[0])", "a call of helper"),
    ("out[0] = x[0] if x[0] > 0 else x[1]\n    return out[0]", "a returned value"),
    ("for i in range(3):\n        out[i] = x[i]\n    else:\n        out[0] = 1.0", "for ... else"),
    ("W = np.empty(3, dtype=np.int64)\n    out[0] = W[0]", "an array of another dtype"),
    ("for i in range(x.shape[0]):\n        W = np.empty(3)\n        out[0] = W[0]", "an array allocated inside a loop"),
    ("out[0:2] = x[0:2]", "slice"),
    ("out[0] = 0.0 < x[0] < 1.0", "chained"),
    # a sum of 3,000 names on one line is deeper than Python's parser builds its tree (RecursionError)
    ("out[0] = " + " + ".join(["x[0]"] * 3000), "nested too deep"),
])
def test_what_the_tape_does_not_translate_is_declined_with_its_reason(body: str, why: str) -> None:
    """A construct outside the machine's operations makes the translation decline (None),
    and the reason names it: the other tiers then run the function."""
    reasons: list[str] = []
    assert translate(f"def kernel(x, out):\n    {body}\n", "kernel", reasons) is None
    assert len(reasons) == 1 and why in reasons[0]


def test_a_division_by_zero_stops_the_machine_where_python_raises_and_leaves_the_arguments() -> None:
    """Python raises ZeroDivisionError on x / 0.0 (so does the compiled code, numba's Python
    error model); the machine stops with an error instead of writing inf or NaN, and the
    arrays it was given are as they were (it copies its results back only on success)."""
    source = "def kernel(x, out):\n    out[0] = 1.0\n    out[1] = x.item(0) / x.item(1)\n"
    tape = translate(source, "kernel")
    assert tape is not None
    x, out = np.array([1.0, 0.0]), np.array([7.0, 7.0])
    with pytest.raises(ZeroDivisionError):
        _python(source, "kernel")(x, out.copy())
    with pytest.raises(TapeError, match="division by zero"):
        TapeFunction(tape)(x, out)
    assert out.tolist() == [7.0, 7.0]


@pytest.mark.parametrize(("call", "value"), [("math.sqrt", -1.0), ("math.log", 0.0), ("math.exp", 1000.0),
                                             ("math.acos", 2.0)])
def test_a_math_domain_or_range_error_stops_the_machine_where_python_raises(call: str, value: float) -> None:
    """Python's math raises ValueError or OverflowError when a finite argument gives NaN or
    an infinity (sqrt(-1), log(0), exp(1000), acos(2)); the machine stops there too."""
    source = f"def kernel(x, out):\n    out[0] = {call}(x[0])\n"
    tape = translate(source, "kernel")
    assert tape is not None
    with pytest.raises((ValueError, OverflowError)):
        _python(source, "kernel")(np.array([value]), np.zeros(1))
    with pytest.raises(TapeError, match="math"):
        TapeFunction(tape)(np.array([value]), np.zeros(1))


def test_an_index_out_of_range_stops_the_machine() -> None:
    """x[3] of a 3-vector raises IndexError in Python; the machine stops (a negative index,
    which Python wraps, stops it too: the interpreted tier then runs the call)."""
    tape = translate("def kernel(x, out, k):\n    out[0] = x[k]\n", "kernel")
    assert tape is not None
    function = TapeFunction(tape)
    for k in (3, -1):
        with pytest.raises(TapeError, match="index"):
            function(np.zeros(3), np.zeros(1), k)
    # an empty array holds no index, not even the 0 that -0.5 truncates to (Python raises too)
    for k in (0, -0.5, 0.5):
        with pytest.raises(TapeError, match="index"):
            function(np.zeros(0), np.zeros(1), k)
    out = np.zeros(1)
    function(np.array([1.0, 2.0, 5.0]), out, 2)
    assert out[0] == 5.0


def test_the_arguments_the_machine_does_not_take_are_refused_before_a_run() -> None:
    """The tape is made for float64 vectors and real scalars: other arguments are not taken
    (the caller runs another tier)."""
    tape = translate("def kernel(x, out, k):\n    out[0] = x[0] * k\n", "kernel")
    assert tape is not None
    function = TapeFunction(tape)
    assert function.accepts((np.zeros(2), np.zeros(1), 3))
    assert not function.accepts((np.zeros(2, dtype=np.int64), np.zeros(1), 3))
    assert not function.accepts((np.zeros((2, 2)), np.zeros(1), 3))
    assert not function.accepts((np.zeros(2), np.zeros(1), np.zeros(1)))
    assert not function.accepts((np.zeros(2), np.zeros(1), 2 ** 60))  # not exact in a double
    assert not function.accepts((np.zeros(2), np.zeros(1)))


def test_the_operation_table_is_the_machines() -> None:
    """The machine's loop tests the numbers of OPS as literals: each operation's number
    appears in it with the operation's name beside it (a renumbering must change both)."""
    import inspect

    text = inspect.getsource(_execute)
    for name, number in OPS.items():
        if name in ("SQRT", "SIN", "COS", "TAN", "EXP", "LOG", "ASIN", "ACOS", "ATAN", "SINH", "COSH", "TANH"):
            assert f"op == {number}:\n                y = math.{name.lower()}(x)" in text
        else:
            assert f"op == {number}:  # {name}" in text


def test_a_unary_minus_of_a_value_that_may_be_an_integer_is_declined() -> None:
    """Python's -k of an integer k = 0 is the integer 0, and x * -k is then -0.0 for a
    negative x; the machine holds k as the double 0.0, its minus is -0.0 and x * -0.0 is
    +0.0: a sign apart. A unary
    minus reached by an integer (a loop counter, an integer constant) is declined; of a
    float it is translated, and a negated parameter must be a float at the call."""
    python = _python("def kernel(x, out):\n    k = 0\n    out[0] = x.item(0) * -k\n", "kernel")
    out = np.zeros(1)
    python(np.array([-1.5]), out)
    assert math.copysign(1.0, out[0]) == -1.0  # -1.5 * 0: -0.0 (the integer's minus is 0)
    reasons: list[str] = []
    assert translate("def kernel(x, out):\n    k = 0\n    out[0] = x.item(0) * -k\n", "kernel", reasons) is None
    assert "integer" in reasons[0]
    assert translate("def kernel(x, out):\n    for k in range(2):\n        out[k] = -k\n", "kernel") is None
    tape = translate("def kernel(out, h):\n    g = h\n    out[0] = -g\n", "kernel")
    assert tape is not None and tape.float_parameters == {1}
    function = TapeFunction(tape)
    assert function.accepts((np.zeros(1), 0.0)) and not function.accepts((np.zeros(1), 0))
    doubled = translate("def kernel(out, h):\n    out[0] = -(h * 2.0)\n", "kernel")  # a float whatever h is
    assert doubled is not None and doubled.float_parameters == set()


def test_a_parameter_the_body_never_reads_takes_any_value() -> None:
    """A loop of a system without parameters is passed an empty parameter vector it never
    reads: the tape takes it whatever it is (an array, a number), as Python does."""
    tape = translate("def kernel(x, c, out):\n    out[0] = x[0] * 2.0\n", "kernel")
    assert tape is not None and tape.parameters[1] == ("unused", -1)
    function = TapeFunction(tape)
    for c in (np.zeros(0), 3.5, np.zeros((2, 2))):
        out = np.zeros(1)
        assert function.accepts((np.array([1.25]), c, out))
        function(np.array([1.25]), c, out)
        assert out[0] == 2.5


def test_arrays_sharing_memory_are_not_taken() -> None:
    """The machine copies its arrays in and out: two arguments that are views of one array
    would not see each other's writes, as they do in Python, so such a call is not taken."""
    tape = translate("def kernel(x, out):\n    out[0] = x[0] + 1.0\n    out[1] = x[0]\n", "kernel")
    assert tape is not None
    function = TapeFunction(tape)
    base = np.zeros(3)
    assert not function.accepts((base[:2], base[1:]))
    assert function.accepts((np.zeros(2), np.zeros(2)))


def test_the_machine_compiled_at_the_install_is_there(machine_kind: str) -> None:
    """The package's install builds the C loop (setup.py): a first run needs neither numba's
    import nor a compilation of the machine. Where it is missing, numba's loop stands in."""
    if machine_kind == "ahead-of-time":
        assert tape_machine.ahead_of_time() is not None and tape_machine.machine_ready()
        assert tape_machine.machine() is tape_machine.ahead_of_time()
    else:
        assert tape_machine.ahead_of_time() is None


_UNARY_VALUES = (0.0, -0.0, 0.5, -0.5, 1.0, -1.0, 0.9999999999999999, 1.5, 2.0, 3.141592653589793, 1e-300, -1e-300,
                 5e-324, 1e15, -7.25, 20.0, 709.7, 710.0, -745.2, 1e308, math.inf, -math.inf, math.nan)


@pytest.mark.parametrize("name", ["sqrt", "sin", "cos", "tan", "exp", "log", "asin", "acos", "atan", "sinh", "cosh",
                                  "tanh", "fabs", "atan2"])
def test_every_function_of_the_machine_gives_pythons_bits_or_stops_where_python_raises(name: str) -> None:
    """Each function of math the machine evaluates, at values that cover its domain, its
    edges, round-off neighbours, overflows, infinities and NaN: the bits of Python's math,
    or a stop where Python raises. (abs for fabs; atan2 against the values in both places.)"""
    call = {"fabs": "abs(x[i])", "atan2": "math.atan2(x[i], x[n - 1 - i])"}.get(name, f"math.{name}(x[i])")
    source = f"def kernel(x, out, n):\n    for i in range(n):\n        out[i] = {call}\n"
    tape = translate(source, "kernel")
    assert tape is not None
    python = _python(source, "kernel")
    for value in _UNARY_VALUES:
        x = np.array([value, 0.25, -2.0 * value])
        out_python, out_tape = np.zeros(3), np.zeros(3)
        try:
            python(x, out_python, 3)
        except (ValueError, OverflowError):
            with pytest.raises(TapeError):
                TapeFunction(tape)(x, out_tape, 3)
            continue
        TapeFunction(tape)(x, out_tape, 3)
        assert out_python.tobytes() == out_tape.tobytes(), (name, value, out_python, out_tape)


def test_two_dimensional_arrays_and_every_jump_run_as_in_python() -> None:
    """LOAD2 and STORE2 (a 2-D work array, a matrix argument stored flat), JLE, JLT and JEQ
    both ways, against Python's own run of the source, and an index out of a row stops."""
    source = (
        "def kernel(x, out, n):\n"
        "    W = np.empty((3, 2))\n"
        "    for i in range(3):\n"
        "        for j in range(2):\n"
        "            W[i, j] = x[i] * (j + 1.5) if x[i] <= x[j] else x[j] - x[i]\n"
        "    k = 0\n"
        "    while k < n:\n"
        "        out[k] = W[2 if k == 2 else (1 if k == 1 else 0), 1] / (1.0 + abs(x[k]))\n"
        "        if out[k] == x[k] or not (out[k] >= 0.0):\n"
        "            out[k] = -out[k]\n"
        "        k += 1\n"
    )
    tape = translate(source, "kernel")
    reasons: list[str] = []
    assert translate(source, "kernel", reasons) is not None, reasons
    python = _python(source, "kernel")
    for x in (np.array([0.3, -1.25, 2.0]), np.array([1.0, 1.0, -0.0]), np.array([math.nan, 2.0, -3.0])):
        out_python, out_tape = np.zeros(3), np.zeros(3)
        python(x.copy(), out_python, 3)
        TapeFunction(tape)(x.copy(), out_tape, 3)
        assert out_python.tobytes() == out_tape.tobytes()
    with pytest.raises(TapeError, match="index"):
        TapeFunction(tape)(np.zeros(3), np.zeros(3), 4)


def test_an_operation_outside_the_table_stops_the_machine_and_a_jump_to_the_end_ends_it() -> None:
    """Hand-made tapes run by the machine and by its Python reading (:func:`_execute`): an
    operation number outside :data:`OPS` (past the last, far past it, negative) stops the
    run with code 4 (unknown operation) after the instructions before it ran; a jump to the
    end of the tape (or beyond it) ends the run with 0, and the instructions it jumps over never
    run. The C loop translates each operation number to the address of its code through a
    table, which must not be read past its end, and clamps each jump to the stop it appends."""
    run = tape_machine.machine()
    base, rows, cols = np.zeros(1, dtype=np.int64), np.ones(1, dtype=np.int64), np.zeros(1, dtype=np.int64)
    add, mov, jmp = OPS["ADD"], OPS["MOV"], OPS["JMP"]
    for unknown in (len(OPS), 99, 2 ** 40, -1):
        code = np.array([add, 0, 1, 2, 0, unknown, 0, 1, 2, 0, mov, 0, 1, 0, 0], dtype=np.int64)
        outcomes = []
        for machine in (run, _execute):
            reg, mem = np.array([0.0, 1.5, 2.25]), np.zeros(1)
            outcomes.append((machine(code, reg, mem, base, rows, cols), reg.tolist()))
        assert outcomes[0] == outcomes[1] == (4, [3.75, 1.5, 2.25]), (unknown, outcomes)
    # instruction 1 jumps to instruction 3, the end of a 3-instruction tape, or beyond it (the C
    # loop clamps the target to its stop): instruction 2 never runs
    for target in (3, 4, 1000):
        code = np.array([add, 0, 1, 2, 0, jmp, target, 0, 0, 0, mov, 0, 1, 0, 0], dtype=np.int64)
        for machine in (run, _execute):
            reg, mem = np.array([0.0, 1.5, 2.25]), np.zeros(1)
            assert machine(code, reg, mem, base, rows, cols) == 0
            assert reg.tolist() == [3.75, 1.5, 2.25]
