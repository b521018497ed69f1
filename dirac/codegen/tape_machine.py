"""The tape machine: one compiled loop that runs any translated function.

A generated function costs numba seconds to compile, per system; the interpreter runs it at
once but at tens of nanoseconds per operation. The tape machine sits between them: its loop
(:func:`_execute`) is the same source for every system, compiled once by numba and kept in
numba's on-disk cache, and it executes a *tape* (:mod:`dirac.codegen.tape_source`): a table
of instructions ``(op, a, b, c, d)`` over a float64 register file and one float64 memory that
holds the function's arrays (Ertl & Gregg, "The structure and performance of efficient
interpreters", J. Instruction-Level Parallelism 5, 2003, for such register machines). Each
instruction is one IEEE 754 operation, in the order of the source, and the functions of
:mod:`math` call the same libm as CPython and numba: the results are those of the other two
tiers, bit for bit.

:class:`TapeFunction` calls a tape like the function it was translated from: array arguments
are copied into the memory and the ones the function writes are copied back; when the
machine stops on an error (a division by zero, an index out of range, a :mod:`math` function
giving a non-finite value of finite arguments), the arguments are restored and
:class:`TapeError` is raised, so the caller can run the call on another tier, which then
behaves as it always does.

The loop exists twice, as the same instructions: compiled ahead of time, at the package's
install, as the C extension :mod:`dirac.codegen._tape` (``setup.py``; a first run costs no
compilation and no import of numba), and as :func:`_execute` here, which numba compiles on
first use where that extension was not built (no C compiler at the install) or where
``DIRAC_TAPE_MACHINE=numba`` asks for it; numba is imported only then (not at the import of
this module). Both give the interpreter's numbers, bit for bit.
"""

from __future__ import annotations

import math
import time
from collections.abc import Callable
from typing import Any

import numpy as np

from dirac.codegen.tape_source import Tape

__all__ = ["TapeFunction", "TapeError", "machine", "machine_kind", "machine_loaded", "machine_ready", "machine_source",
           "machine_compile_seconds", "ahead_of_time", "ERRORS", "MACHINE_VARIABLE"]

#: error codes of the machine
ERRORS = {1: "division by zero", 2: "index out of range (or negative)", 3: "math domain or range error",
          4: "unknown operation"}

_MACHINE: Any = None
_SOURCE: str | None = None
_COMPILE_SECONDS: float | None = None
#: the environment variable that chooses the machine: ``numba`` for the numba-compiled loop
#: (else the one compiled at the install, when it was built)
MACHINE_VARIABLE = "DIRAC_TAPE_MACHINE"


class TapeError(Exception):
    """The tape machine stopped where Python would raise (the arguments are restored)."""


def _execute(code: np.ndarray, reg: np.ndarray, mem: np.ndarray, base: np.ndarray, rows: np.ndarray,
             cols: np.ndarray) -> int:
    """Run ``code`` on the registers ``reg`` and the memory ``mem`` (array ``k`` at
    ``base[k]``, ``rows[k]`` x ``cols[k]`` elements, ``cols[k] = 0`` for one dimension);
    returns 0, or an error code of :data:`ERRORS`. The operation numbers are those of
    :data:`dirac.codegen.tape_source.OPS`."""
    pc = 0
    n = code.shape[0]
    while pc < n:
        op = code[pc]
        a = code[pc + 1]
        b = code[pc + 2]
        c = code[pc + 3]
        pc += 5
        if op == 3:  # MUL
            reg[a] = reg[b] * reg[c]
        elif op == 1:  # ADD
            reg[a] = reg[b] + reg[c]
        elif op == 2:  # SUB
            reg[a] = reg[b] - reg[c]
        elif op == 0:  # MOV
            reg[a] = reg[b]
        elif op == 6:  # LOAD reg a <- array b [reg c]
            i = int(reg[c])
            if i < 0 or i >= rows[b]:
                return 2
            reg[a] = mem[base[b] + i]
        elif op == 11:  # JLT: to a when (reg b < reg c) is not d
            if (reg[b] < reg[c]) != (code[pc - 1] != 0):
                pc = 5 * a
        elif op == 13:  # JEQ
            if (reg[b] == reg[c]) != (code[pc - 1] != 0):
                pc = 5 * a
        elif op == 10:  # JMP
            pc = 5 * a
        elif op == 4:  # DIV
            if reg[c] == 0.0:
                return 1
            reg[a] = reg[b] / reg[c]
        elif op == 5:  # NEG
            reg[a] = -reg[b]
        elif op == 7:  # STORE array a [reg b] <- reg c
            i = int(reg[b])
            if i < 0 or i >= rows[a]:
                return 2
            mem[base[a] + i] = reg[c]
        elif op == 8:  # LOAD2 reg a <- array b [reg c, reg d]
            i = int(reg[c])
            j = int(reg[code[pc - 1]])
            if i < 0 or i >= rows[b] or j < 0 or j >= cols[b]:
                return 2
            reg[a] = mem[base[b] + i * cols[b] + j]
        elif op == 9:  # STORE2 array a [reg b, reg c] <- reg d
            i = int(reg[b])
            j = int(reg[c])
            if i < 0 or i >= rows[a] or j < 0 or j >= cols[a]:
                return 2
            mem[base[a] + i * cols[a] + j] = reg[code[pc - 1]]
        elif op == 12:  # JLE
            if (reg[b] <= reg[c]) != (code[pc - 1] != 0):
                pc = 5 * a
        elif op == 14:  # ABS
            reg[a] = abs(reg[b])
        elif op == 27:  # ATAN2
            reg[a] = math.atan2(reg[b], reg[c])
        else:
            x = reg[b]
            if op == 15:
                y = math.sqrt(x)
            elif op == 16:
                y = math.sin(x)
            elif op == 17:
                y = math.cos(x)
            elif op == 18:
                y = math.tan(x)
            elif op == 19:
                y = math.exp(x)
            elif op == 20:
                y = math.log(x)
            elif op == 21:
                y = math.asin(x)
            elif op == 22:
                y = math.acos(x)
            elif op == 23:
                y = math.atan(x)
            elif op == 24:
                y = math.sinh(x)
            elif op == 25:
                y = math.cosh(x)
            elif op == 26:
                y = math.tanh(x)
            else:
                return 4
            if (y != y and x == x) or (math.isinf(y) and math.isfinite(x)):  # where Python's math raises
                return 3
            reg[a] = y
    return 0


#: what the machine's module is compiled with: the loop of :func:`_execute` behind numba's decorator
_DECORATOR = '@numba.njit(cache=True, nogil=True, error_model="numpy", boundscheck=False)'


def machine_source() -> str:
    """The machine's module: :func:`_execute` as ``run_tape`` under numba's decorator. Written
    to the cache of generated code like a kernel module (:func:`~dirac.codegen.numba_backend.import_source`),
    so numba's on-disk cache of it sits there too and the folder's safety checks apply."""
    global _SOURCE
    if _SOURCE is None:
        import inspect

        body = inspect.getsource(_execute).replace("def _execute(", "def run_tape(", 1)
        _SOURCE = ('"""The tape machine of dirac.codegen.tape_machine -- do not edit."""\n'
                   "import math\nimport numpy as np\nimport numba\n\n\n" + _DECORATOR + "\n" + body)
    return _SOURCE


def ahead_of_time() -> Any:
    """The machine compiled at the install (:mod:`dirac.codegen._tape`'s ``run_tape``), or None
    where it was not built or ``DIRAC_TAPE_MACHINE=numba`` asks for numba's."""
    import os

    if os.environ.get(MACHINE_VARIABLE, "").strip().lower() == "numba":
        return None
    try:
        from dirac.codegen import _tape
    except ImportError:
        return None
    return _tape.run_tape


def machine_kind() -> str:
    """``"ahead-of-time"`` (the C extension) or ``"numba"``: which loop :func:`machine` gives."""
    return "ahead-of-time" if ahead_of_time() is not None else "numba"


def machine_loaded() -> bool:
    """Whether the machine is compiled or loaded in this process (the one compiled at the
    install is, as soon as it can be imported: that costs no compilation)."""
    return _MACHINE is not None or ahead_of_time() is not None


def machine_ready() -> bool:
    """Whether the machine costs no compilation: compiled at the install, loaded in this
    process, or its marker in the cache says numba's on-disk cache holds it (read without
    importing numba)."""
    if _MACHINE is not None or ahead_of_time() is not None:
        return True
    from dirac.codegen.numba_backend import ready_marker, source_path

    return ready_marker(source_path(machine_source()), "run_tape").exists()


def machine(why: str = "a run on the tape machine", announce: Callable[[str, str], None] | None = None) -> Any:
    """The compiled machine (compiled, or loaded from numba's cache, on first use); a
    compilation is first announced by ``announce(what, why)`` when given (the tiers' one
    stderr line, :func:`dirac.codegen.tiers.announce_compilation`)."""
    global _MACHINE, _COMPILE_SECONDS
    if _MACHINE is None:
        start = time.process_time()
        compiled = ahead_of_time()
        if compiled is not None:
            _COMPILE_SECONDS = time.process_time() - start
            _MACHINE = compiled
            return _MACHINE
        import numba

        from dirac.codegen.background import mark_ready
        from dirac.codegen.numba_backend import import_source, ready_marker, source_path

        source = machine_source()
        marker = ready_marker(source_path(source), "run_tape")
        if not marker.exists() and announce is not None:
            announce("the tape machine (once for every system)", why)
        dispatcher = import_source(source).run_tape
        ints = numba.int64[::1]
        floats = numba.float64[::1]
        dispatcher.compile((ints, floats, floats, ints, ints, ints))
        mark_ready(marker)
        _COMPILE_SECONDS = time.process_time() - start
        _MACHINE = dispatcher
    return _MACHINE


def machine_compile_seconds() -> float | None:
    """CPU seconds this process spent getting the machine (numba's import, compiling or
    loading it), None before."""
    return _COMPILE_SECONDS


class TapeFunction:
    """A :class:`~dirac.codegen.tape_source.Tape` called like the function it translates."""

    def __init__(self, tape: Tape) -> None:
        self.tape = tape
        self.name = tape.name
        self.code = np.array(tape.code, dtype=np.int64).reshape(-1)
        self.registers = np.zeros(max(tape.registers, 1))
        for register, value in tape.constants.items():
            self.registers[register] = value
        self._layout: tuple[Any, ...] | None = None
        self._layout_key: tuple[int, ...] | None = None

    def _memory(self, arrays: list[np.ndarray]) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
        sizes = tuple(a.shape[0] for a in arrays)
        if self._layout_key != sizes:
            base, rows, cols = [], [], []
            offset = 0
            index = 0
            for shape in self.tape.arrays:
                if shape == (-1, -1):
                    r, k = sizes[index], 0
                    index += 1
                else:
                    r, k = shape
                base.append(offset)
                rows.append(r)
                cols.append(k)
                offset += r * (k if k > 0 else 1)
            self._layout = (np.zeros(offset), np.array(base, dtype=np.int64), np.array(rows, dtype=np.int64),
                            np.array(cols, dtype=np.int64))
            self._layout_key = sizes
        return self._layout  # type: ignore[return-value]

    def accepts(self, args: tuple[Any, ...]) -> bool:
        """Whether the machine can take these arguments: float64 vectors for the arrays, not
        sharing memory (the machine copies them); Python or numpy doubles and integers exact
        in a double for the scalars (floats where the tape asks for them)."""
        if len(args) != len(self.tape.parameters):
            return False
        arrays = []
        for position, ((kind, _), value) in enumerate(zip(self.tape.parameters, args)):
            if kind == "unused":
                continue
            if kind == "array":
                if not (isinstance(value, np.ndarray) and value.dtype == np.float64 and value.ndim == 1):
                    return False
                arrays.append(value)
            elif isinstance(value, (float, np.float64)):
                continue
            elif position in self.tape.float_parameters:
                return False  # an integer where a unary minus would give Python's 0, not -0.0
            elif not isinstance(value, (int, np.integer)) or abs(int(value)) > 2 ** 53:
                return False  # float32 arithmetic, or an integer not exact in a double
        # arrays sharing memory: writes through one would be seen in the other, not in the copies
        return not any(np.may_share_memory(a, b) for i, a in enumerate(arrays) for b in arrays[i + 1:])

    def __call__(self, *args: Any) -> None:
        run = machine()
        arrays = [value for (kind, _), value in zip(self.tape.parameters, args) if kind == "array"]
        layout, base, rows, cols = self._memory(arrays)
        mem = np.zeros_like(layout)  # one per call: calls from two threads share nothing
        reg = self.registers.copy()
        slot = 0
        for (kind, where), value in zip(self.tape.parameters, args):
            if kind == "scalar":
                reg[where] = float(value)
            elif kind == "array":
                mem[base[where]:base[where] + rows[where]] = value
                slot += 1
        for where, register in self.tape.lengths.items():
            reg[register] = float(rows[where])
        code = run(self.code, reg, mem, base, rows, cols)
        if code:
            raise TapeError(f"{self.name}: {ERRORS.get(code, f'error {code}')}")
        for (kind, where), value in zip(self.tape.parameters, args):
            if kind == "array" and where in self.tape.written:
                value[...] = mem[base[where]:base[where] + rows[where]]
