"""Copies and dead writes taken out of a tape (:mod:`dirac.codegen.tape_optimise`).

The references: Python's own run of the same source, and the tape as translated instruction
for instruction (``translate(..., optimised=False)``). The optimised tape must give both their
numbers to the last bit, stop where they stop (a division by zero, an index out of range, a
math domain error: where Python raises), and execute fewer instructions. Programs that defeat
a careless copy propagation (the source written between the copy and its read, a copy on one
path of two, a copy across a loop's back edge) are checked by name; random programs of
copies, arithmetic, branches and loops check the passes together; the step loops of the
latency corpus check what the passes are for."""

from __future__ import annotations

import math
import random

import numpy as np
import pytest

from dirac.codegen.tape_machine import TapeError, TapeFunction, _execute
from dirac.codegen.tape_optimise import optimise
from dirac.codegen.tape_source import OPS, Tape, translate

#: the reference machine in Python computes with numpy scalars: IEEE infinities and NaN (the values these
#: tests feed on purpose) make numpy warn where the C machine and Python stay silent
pytestmark = pytest.mark.filterwarnings("ignore:.*encountered in scalar:RuntimeWarning")


def _python(source: str, name: str = "kernel"):
    namespace = {"np": np, "math": math}
    exec(source, namespace)
    return namespace[name]


def _run_tape(tape: Tape, args: list) -> tuple[np.ndarray | None, int]:
    """The memory of the arguments after the machine (plain Python, :func:`_execute`) ran the
    tape on them, and the number of instructions it executed; None for a stop (an error)."""
    function = TapeFunction(tape)
    arrays = [value for (kind, _), value in zip(tape.parameters, args) if kind == "array"]
    layout, base, rows, cols = function._memory(arrays)
    mem = np.zeros_like(layout)
    reg = function.registers.copy()
    for (kind, where), value in zip(tape.parameters, args):
        if kind == "scalar":
            reg[where] = float(value)
        elif kind == "array":
            mem[base[where]:base[where] + rows[where]] = value
    for where, register in tape.lengths.items():
        reg[register] = float(rows[where])
    executed = [0]
    code = function.code

    class Counted(np.ndarray):  # counts the instructions the machine fetches (each reads its op once)
        def __getitem__(self, key):
            if isinstance(key, (int, np.integer)) and key % 5 == 0:
                executed[0] += 1
            return super().__getitem__(key)

    try:
        status = _execute(code.view(Counted), reg, mem, base, rows, cols)
    except (ValueError, OverflowError):  # the loop run by Python raises where the compiled one returns 3
        status = 3
    return (None if status else mem), executed[0]


def _agree(source: str, args: list, fewer: bool = True) -> None:
    """Python, the plain tape and the optimised tape on ``args``: the same bits of every array
    argument, or all three stop; the optimised tape executes fewer instructions (``fewer``)."""
    plain, optimised = translate(source, "kernel", optimised=False), translate(source, "kernel")
    assert plain is not None and optimised is not None
    python_args = [a.copy() if isinstance(a, np.ndarray) else a for a in args]
    try:
        with np.errstate(all="ignore"):
            _python(source)(*python_args)
        raised = False
    except (ZeroDivisionError, ValueError, OverflowError, IndexError):
        raised = True
    memory_plain, count_plain = _run_tape(plain, args)
    memory_optimised, count_optimised = _run_tape(optimised, args)
    if raised:
        assert memory_plain is None and memory_optimised is None
        with pytest.raises(TapeError):
            TapeFunction(optimised)(*[a.copy() if isinstance(a, np.ndarray) else a for a in args])
        return
    assert memory_plain is not None and memory_optimised is not None
    assert memory_optimised.tobytes() == memory_plain.tobytes()
    machine_args = [a.copy() if isinstance(a, np.ndarray) else a for a in args]
    TapeFunction(optimised)(*machine_args)  # the compiled machine too
    for mine, theirs in zip(machine_args, python_args):
        if isinstance(mine, np.ndarray):
            assert mine.tobytes() == theirs.tobytes()
    if fewer:
        assert count_optimised < count_plain


_OVERWRITTEN = '''
def kernel(out, a, b):
    y = a
    a = a + b
    out[0] = y * 2.0
    out[1] = a
'''

_ONE_PATH = '''
def kernel(out, a, b):
    y = b
    if a > 0.0:
        y = a
    out[0] = y + 1.0
    z = a
    out[1] = z - b
'''

_BACK_EDGE = '''
def kernel(out, a, b, n):
    y = a
    s = 0.0
    for k in range(n):
        s = s + y
        y = s * b
    out[0] = s
    out[1] = y
'''


_REPEATED = '''
def kernel(out, a, b):
    out[0] = a * b + a * b
    x = a * b
    a = a + 1.0
    out[1] = a * b - x
    y = b / a
    b = -b
    out[0] = out[0] + b / a + y + math.sqrt(abs(b)) + math.sqrt(abs(b))
'''


@pytest.mark.parametrize("source", [_OVERWRITTEN, _ONE_PATH, _BACK_EDGE, _REPEATED],
                         ids=["overwritten", "one-path", "back-edge", "repeated"])
@pytest.mark.parametrize(("a", "b"), [(0.7, -1.9), (-0.0, 0.0), (math.nan, 2.0), (-3.0, math.inf)])
def test_a_copy_is_read_only_where_it_holds(source: str, a: float, b: float) -> None:
    """A copy ``y = a`` is not read for ``y`` once ``a`` is written (``a = a + b``), where it
    holds on one path of two (``y = a`` under an ``if``), or across a loop's back edge where
    ``y`` is written; a product repeated is reused, but not once an operand is written
    (``a * b`` after ``a = a + 1.0``): the numbers are Python's, signed zeros and NaN included."""
    args = [np.zeros(2), a, b] + ([5] if "n)" in source else [])
    _agree(source, args, fewer=False)


def test_a_copy_that_holds_is_read_and_the_dead_writes_go() -> None:
    """``u = a; v = u`` read as ``a``, a loop variable nobody reads and the bookkeeping ``i = 1``
    of an unrolled loop gone: fewer instructions, the same numbers."""
    source = '''
def kernel(out, a, b, n):
    u = a
    v = u
    i = 0
    for k in range(n):
        out[0] = out[0] + v * b
        i = 1
    out[1] = v
'''
    _agree(source, [np.zeros(2), 0.3, 1.7, 6])
    plain, optimised = translate(source, "kernel", optimised=False), translate(source, "kernel")
    assert plain is not None and optimised is not None
    moves = [sum(1 for op, *_ in t.code if op == OPS["MOV"]) for t in (plain, optimised)]
    assert moves[1] < moves[0]


@pytest.mark.parametrize(("source", "args"), [
    ("def kernel(out, a, b):\n    z = a / b\n    out[0] = a\n", [np.zeros(1), 1.0, 0.0]),
    ("def kernel(x, out, k):\n    z = x[k]\n    out[0] = 1.0\n", [np.zeros(2), np.zeros(1), 5]),
    ("def kernel(out, a, b):\n    z = math.sqrt(a)\n    out[0] = b\n", [np.zeros(1), -1.0, 2.0]),
])
def test_an_unread_operation_that_can_stop_the_machine_stays(source: str, args: list) -> None:
    """A division, a load and a math function whose results nobody reads still stop the machine
    where Python raises (a zero divisor, an index out of range, a domain error), so the caller
    reruns the call interpreted as before."""
    _agree(source, args, fewer=False)


def _random_program(rng: random.Random, statements: int = 14) -> str:
    """A random function of copies, arithmetic (divisions included), branches and loops over
    six scalars and two outputs."""
    names = [f"v{i}" for i in range(6)]
    lines = ["def kernel(out, a, b, c):", "    v0 = a", "    v1 = b", "    v2 = c", "    v3 = a", "    v4 = b",
             "    v5 = c"]

    def block(depth: int, indent: str, count: int) -> None:
        for _ in range(count):
            kind = rng.random()
            target, left, right = rng.choice(names), rng.choice(names), rng.choice(names)
            if kind < 0.35:
                lines.append(f"{indent}{target} = {left}")
            elif kind < 0.7:
                op = rng.choice(["+", "-", "*", "/"])
                lines.append(f"{indent}{target} = {left} {op} {right}" if op != "/"
                             else f"{indent}{target} = {left} / (1.5 + abs({right}))")
            elif kind < 0.78:
                lines.append(f"{indent}{target} = -{left}")
            elif kind < 0.88 and depth < 2:
                lines.append(f"{indent}if {left} < {right}:")
                block(depth + 1, indent + "    ", rng.randint(1, 3))
                if rng.random() < 0.5:
                    lines.append(f"{indent}else:")
                    block(depth + 1, indent + "    ", rng.randint(1, 3))
            elif depth < 2:
                lines.append(f"{indent}for k{depth} in range({rng.randint(0, 3)}):")
                block(depth + 1, indent + "    ", rng.randint(1, 3))
            else:
                lines.append(f"{indent}out[{rng.randint(0, 1)}] = {left}")

    block(0, "    ", statements)
    lines += [f"    out[0] = out[0] + {rng.choice(names)}", f"    out[1] = {rng.choice(names)}"]
    return "\n".join(lines) + "\n"


@pytest.mark.parametrize("seed", range(40))
def test_random_programs_give_pythons_bits(seed: int) -> None:
    """Random programs (seeded: the same in every run), each on three sets of arguments (signed
    zeros and a NaN among them): the optimised tape ends on the bits of Python and of the
    plain tape."""
    rng = random.Random(seed)
    source = _random_program(rng)
    for a, b, c in [(0.7, -1.3, 2.9), (-0.0, 0.0, 1e300), (math.nan, 0.25, -4.0)]:
        _agree(source, [np.zeros(2), a, b, c], fewer=False)


def test_jumps_are_renumbered_when_instructions_go() -> None:
    """Straight code: a jump past removed instructions lands on the instruction after them."""
    code = [(OPS["MOV"], 3, 0, 0, 0),  # 0: dead (r3 never read)
            (OPS["JEQ"], 4, 0, 1, 0),  # 1: to 4 when r0 == r1
            (OPS["MOV"], 2, 0, 0, 0),  # 2: r2 = r0
            (OPS["JMP"], 5, 0, 0, 0),  # 3
            (OPS["MOV"], 2, 1, 0, 0),  # 4: r2 = r1
            (OPS["STORE"], 0, 5, 2, 0)]  # 5: mem[0][r5] = r2
    out = optimise(code)
    assert out == [(OPS["JEQ"], 3, 0, 1, 0), (OPS["MOV"], 2, 0, 0, 0), (OPS["JMP"], 4, 0, 0, 0),
                   (OPS["MOV"], 2, 1, 0, 0), (OPS["STORE"], 0, 5, 2, 0)]


@pytest.mark.parametrize("model_name", ["double_pendulum_angles", "double_pendulum_cartesian"])
def test_the_step_loops_of_the_corpus_end_on_the_same_bits_in_fewer_instructions(model_name: str, monkeypatch) -> None:
    """The RATTLE loops of the double pendulum in its angles (a configuration-dependent mass)
    and in Cartesian coordinates (two constraints, a constant mass), 40 steps of ``rattle-8``'s
    composition: the optimised tape ends on the plain tape's state, evaluation count and last
    residual, with ``==``, and executes fewer instructions (the pendulum in angles: 17 % fewer,
    its ``MOV`` from 4,800 to 2,200 a step; the Cartesian one 6 % fewer)."""
    from test_tape_tiers import _captured_loop, _fresh

    from dirac.compositions import COMPOSITIONS

    module, name, args = _captured_loop(model_name, monkeypatch)
    text = module._texts[name]
    plain, optimised = translate(text, name, optimised=False), translate(text, name)
    assert plain is not None and optimised is not None
    state = _fresh(args, 40)
    state[4] = np.asarray(next(c for c in COMPOSITIONS if c.suffix == "8").coefficients, dtype=float)
    state[5] = 0.02
    memory_plain, count_plain = _run_tape(plain, state)
    memory_optimised, count_optimised = _run_tape(optimised, state)
    assert memory_plain is not None and memory_optimised is not None
    assert memory_optimised.tobytes() == memory_plain.tobytes()
    # measured: 20,700 -> 17,200 a step in angles; 9,300 -> 8,700 Cartesian (its loop is mostly products)
    assert count_optimised < (0.85 if model_name == "double_pendulum_angles" else 0.95) * count_plain


def test_the_operation_numbers_are_the_translations() -> None:
    """The passes name the operations by number (the translation imports them): the same table."""
    from dirac.codegen import tape_optimise

    for name in ("MOV", "ADD", "SUB", "MUL", "DIV", "NEG", "LOAD", "STORE", "LOAD2", "STORE2", "JMP", "JLT", "JLE",
                 "JEQ", "ABS", "ATAN2"):
        assert getattr(tape_optimise, f"_{name}") == OPS[name]
    assert {OPS[name] for name in ("SQRT", "TANH")} == {15, 26}  # the unary math functions: 15 to 26


def test_a_repeated_operation_is_computed_once_while_its_operands_stand() -> None:
    """In ``_REPEATED`` the product ``a * b`` is written four times: three times before ``a`` is
    written (one product kept) and once after (computed again); the square root of the same
    ``abs(b)`` twice (one kept, once the second ``abs(b)`` is a copy of the first)."""
    plain, optimised = translate(_REPEATED, "kernel", optimised=False), translate(_REPEATED, "kernel")
    assert plain is not None and optimised is not None

    def count(tape: Tape, name: str) -> int:
        return sum(1 for op, *_ in tape.code if op == OPS[name])

    assert (count(plain, "MUL"), count(optimised, "MUL")) == (4, 2)
    assert (count(plain, "SQRT"), count(optimised, "SQRT")) == (2, 1)
