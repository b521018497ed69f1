"""A generated function as a tape: a register program for the tape machine.

:mod:`dirac.codegen.tape_machine` runs one fixed loop, compiled once (numba, cached on
disk), that executes a *tape*: a table of instructions ``(op, a, b, c, d)`` over a file of
float64 registers and one float64 memory holding the function's arrays. This module
translates the Python source of one generated function (the same text the interpreted tier
runs: :func:`dirac.codegen.scalar_arrays.scalar_function` of the flattened module) into such
a tape, statement by statement and operation by operation, so the machine performs the same
IEEE 754 operations in the same order as the interpreter and the compiled code: the same
numbers, to the last bit.

What is translated: assignments (also augmented, tuple swaps) of float and integer scalars
(integers are held exactly in float64 below 2**53), ``+ - * /``, unary minus, comparisons,
``and``/``or``/``not`` in tests, ``x if c else y``, ``abs``/``min``/``max``/``float``, the
functions of :mod:`math` listed in :data:`UNARY`, reads ``a[i]``/``a.item(i)``/``a[i, j]``,
writes ``a[i] = x`` (and ``+=``), ``a.shape[0]``, ``np.empty``/``np.zeros`` of constant
shape, ``if``/``elif``/``else``, ``for ... in range(...)`` (constant step), ``while``,
``break``, ``continue`` and a bare ``return``. Anything else (a call of another function,
``**``, ``//``, ``%``, a ``for ... else``, a returned value, integer arrays...) makes
:func:`translate` return None: the tier is then simply not offered for that function, never
a wrong answer.

The machine reports a division by zero, an index out of range and a non-finite result of a
:mod:`math` function of finite arguments (where Python's ``math`` raises ``ValueError`` or
``OverflowError``) by an error code instead of going on; the caller then reruns the call
from its saved arguments on the interpreted tier, which does what it always does there.
"""

from __future__ import annotations

import ast
from dataclasses import dataclass, field
from typing import cast

from dirac.codegen.flatten import replace_children, walk
from dirac.codegen.tape_optimise import optimise

__all__ = ["Tape", "translate", "OPS", "UNARY"]

#: the machine's operations, by number (:mod:`dirac.codegen.tape_machine` has the same table)
OPS = {name: number for number, name in enumerate((
    "MOV", "ADD", "SUB", "MUL", "DIV", "NEG", "LOAD", "STORE", "LOAD2", "STORE2",
    "JMP", "JLT", "JLE", "JEQ", "ABS",
    "SQRT", "SIN", "COS", "TAN", "EXP", "LOG", "ASIN", "ACOS", "ATAN", "SINH", "COSH", "TANH", "ATAN2",
))}
#: the unary functions of :mod:`math` the machine evaluates (by the same libm as CPython and numba)
UNARY = {"sqrt": "SQRT", "sin": "SIN", "cos": "COS", "tan": "TAN", "exp": "EXP", "log": "LOG", "asin": "ASIN",
         "acos": "ACOS", "atan": "ATAN", "sinh": "SINH", "cosh": "COSH", "tanh": "TANH"}
_BINARY = {ast.Add: "ADD", ast.Sub: "SUB", ast.Mult: "MUL", ast.Div: "DIV"}
_COMPARE = {ast.Lt: "LT", ast.LtE: "LE", ast.Eq: "EQ", ast.NotEq: "NE", ast.Gt: "GT", ast.GtE: "GE"}
_CONSTANTS = {("np", "inf"): float("inf"), ("math", "inf"): float("inf"), ("math", "pi"): 3.141592653589793,
              ("math", "e"): 2.718281828459045, ("np", "pi"): 3.141592653589793, ("np", "nan"): float("nan"),
              ("math", "nan"): float("nan")}


class Decline(Exception):
    """A construct the tape does not translate (the reason is the message)."""


@dataclass
class Tape:
    """One translated function.

    Attributes
    ----------
    name : str
        The function's name.
    code : list of tuple of int
        The instructions ``(op, a, b, c, d)``.
    registers : int
        Size of the register file.
    constants : dict of int to float
        Registers holding constants (loaded before each run).
    parameters : list of tuple
        Per parameter of the function, in order: ``("scalar", register)``, ``("array", slot)``,
        or ``("unused", -1)`` for one the body never reads (any value is taken).
    arrays : list of tuple of int
        Per array slot: ``(rows, cols)`` of a local array of constant shape, ``(-1, -1)`` for an
        argument (its size is known at the call), ``2`` dimensions when ``cols > 0``.
    lengths : dict of int to int
        Array slot -> the register holding its length (``a.shape[0]``), filled at the call.
    written : set of int
        Argument slots the function writes to (copied back after a run).
    float_parameters : set of int
        Positions of scalar parameters whose value reaches a unary minus: they must be floats at
        the call (Python's ``-0`` is the integer 0, the machine's ``-0.0`` a negative zero).
    """

    name: str
    code: list[tuple[int, int, int, int, int]] = field(default_factory=list)
    registers: int = 0
    constants: dict[int, float] = field(default_factory=dict)
    parameters: list[tuple[str, int]] = field(default_factory=list)
    arrays: list[tuple[int, int]] = field(default_factory=list)
    lengths: dict[int, int] = field(default_factory=dict)
    written: set[int] = field(default_factory=set)
    float_parameters: set[int] = field(default_factory=set)


class _Translator:
    def __init__(self, function: ast.FunctionDef) -> None:
        self.function = function
        self.tape = Tape(function.name)
        self.names: dict[str, int] = {}  # scalar variable -> register
        self.array_names: dict[str, int] = {}  # array variable -> slot
        self.constant_registers: dict[float | str, int] = {}
        self.loops: list[tuple[list[int], list[int]]] = []  # (break jumps, continue jumps) to patch
        self.returns: list[int] = []
        self.free: list[int] = []  # temporaries

    # ------------------------------------------------------------------ registers
    def register(self) -> int:
        self.tape.registers += 1
        return self.tape.registers - 1

    def temporary(self) -> int:
        return self.free.pop() if self.free else self.register()

    def release(self, register: int) -> None:
        if register in self._temporaries:
            self.free.append(register)

    def constant(self, value: float) -> int:
        key: float | str = repr(float(value))  # repr keeps -0.0 and nan apart
        if key not in self.constant_registers:
            register = self.register()
            self.constant_registers[key] = register
            self.tape.constants[register] = float(value)
        return self.constant_registers[key]

    def variable(self, name: str) -> int:
        if name in self.array_names:
            raise Decline(f"{name} is both an array and a scalar")
        if name not in self.names:
            self.names[name] = self.register()
        return self.names[name]

    def emit(self, op: str, a: int = 0, b: int = 0, c: int = 0, d: int = 0) -> int:
        self.tape.code.append((OPS[op], a, b, c, d))
        return len(self.tape.code) - 1

    def patch(self, position: int, target: int) -> None:
        op, _, b, c, d = self.tape.code[position]
        self.tape.code[position] = (op, target, b, c, d)

    # ------------------------------------------------------------------ translation
    def run(self) -> Tape:
        arguments = self.function.args
        if arguments.vararg or arguments.kwarg or arguments.kwonlyargs or arguments.defaults or arguments.posonlyargs:
            raise Decline("only plain positional parameters")
        used_as_array = _array_names(self.function)
        negated = _negated_parameters(self.function, used_as_array)
        self.tape.float_parameters = {i for i, a in enumerate(arguments.args) if a.arg in negated}
        loaded = {node.id for node in ast.walk(self.function) if isinstance(node, ast.Name) and isinstance(node.ctx, ast.Load)}
        for argument in arguments.args:
            if argument.arg not in used_as_array and argument.arg not in loaded:
                self.tape.parameters.append(("unused", -1))  # any value (an empty parameter vector)
            elif argument.arg in used_as_array:
                slot = len(self.tape.arrays)
                self.tape.arrays.append((-1, -1))
                self.array_names[argument.arg] = slot
                self.tape.parameters.append(("array", slot))
            else:
                self.tape.parameters.append(("scalar", self.variable(argument.arg)))
        self._temporaries: set[int] = set()
        self.block(self.function.body)
        end = len(self.tape.code)  # the machine stops at the end of the tape
        for position in self.returns:
            self.patch(position, end)
        return self.tape

    def block(self, statements: list[ast.stmt]) -> None:
        for statement in statements:
            self.statement(statement)

    def statement(self, node: ast.stmt) -> None:
        if isinstance(node, ast.Expr) and isinstance(node.value, ast.Constant):
            return  # a docstring
        if isinstance(node, ast.Pass):
            return
        if isinstance(node, ast.Assign):
            if len(node.targets) != 1:
                raise Decline("chained assignment")
            self.assign(node.targets[0], node.value)
        elif isinstance(node, ast.AugAssign):
            if type(node.op) not in _BINARY:
                raise Decline(f"augmented {type(node.op).__name__}")
            target = node.target
            load: ast.expr
            if isinstance(target, ast.Name):
                load = ast.Name(target.id, ast.Load())
            elif isinstance(target, ast.Subscript):
                load = ast.Subscript(target.value, target.slice, ast.Load())
            else:
                raise Decline("augmented assignment to this target")
            self.assign(target, ast.BinOp(load, node.op, node.value))
        elif isinstance(node, ast.If):
            self.branch(node.test, node.body, node.orelse)
        elif isinstance(node, ast.For):
            self.for_range(node)
        elif isinstance(node, ast.While):
            if node.orelse:
                raise Decline("while ... else")
            top = len(self.tape.code)
            exits = self.test(node.test, False)
            self.loops.append(([], []))
            self.block(node.body)
            breaks, continues = self.loops.pop()
            self.emit("JMP", top)
            end = len(self.tape.code)
            for position in exits + breaks:
                self.patch(position, end)
            for position in continues:
                self.patch(position, top)
        elif isinstance(node, ast.Break):
            if not self.loops:
                raise Decline("break outside a loop")
            self.loops[-1][0].append(self.emit("JMP"))
        elif isinstance(node, ast.Continue):
            if not self.loops:
                raise Decline("continue outside a loop")
            self.loops[-1][1].append(self.emit("JMP"))
        elif isinstance(node, ast.Return):
            if node.value is not None and not (isinstance(node.value, ast.Constant) and node.value.value is None):
                raise Decline("a returned value")
            self.returns.append(self.emit("JMP"))
        else:
            raise Decline(f"statement {type(node).__name__}")

    def assign(self, target: ast.expr, value: ast.expr) -> None:
        if isinstance(target, ast.Name):
            if isinstance(value, ast.Call) and _is_allocation(value):
                self.allocate(target.id, value)
                return
            if isinstance(value, ast.Name) and value.id in self.array_names:
                raise Decline("an array bound to a second name")
            register = self.variable(target.id)
            self.expression(value, register)
        elif isinstance(target, ast.Tuple):
            if not isinstance(value, ast.Tuple) or len(value.elts) != len(target.elts):
                raise Decline("tuple assignment of another shape")
            parts = []
            for element in value.elts:  # all of the right side first, as Python does
                register = self.temporary()
                self._temporaries.add(register)
                self.expression(element, register)
                parts.append(register)
            for element, register in zip(target.elts, parts):
                if not isinstance(element, ast.Name):
                    raise Decline("tuple assignment to a subscript")
                self.emit("MOV", self.variable(element.id), register)
            for register in parts:
                self.release(register)
        elif isinstance(target, ast.Subscript):
            slot, indices = self.subscript(target)
            source = self.operand(value)
            if len(indices) == 1:
                self.emit("STORE", slot, indices[0], source)
            else:
                self.emit("STORE2", slot, indices[0], indices[1], source)
            self.tape.written.add(slot)
            for register in (source, *indices):
                self.release(register)
        else:
            raise Decline(f"assignment to {type(target).__name__}")

    def allocate(self, name: str, value: ast.Call) -> None:
        if name in self.array_names or name in self.names:
            raise Decline(f"array {name} allocated twice or also a scalar")
        if value.keywords and not all(k.arg == "dtype" and _attribute(k.value) in (("np", "float64"), ("float",))
                                      for k in value.keywords):
            raise Decline("an array of another dtype")
        shape = _constant(value.args[0]) if len(value.args) == 1 else None
        if isinstance(shape, (int, float)) and int(shape) == shape:
            rows, cols = int(shape), 0
        elif isinstance(shape, tuple) and len(shape) == 2 and all(isinstance(s, int) for s in shape):
            rows, cols = shape
        else:
            raise Decline("an array of non-constant shape")
        slot = len(self.tape.arrays)
        self.tape.arrays.append((rows, cols))
        self.array_names[name] = slot
        if self.loops:
            raise Decline("an array allocated inside a loop")

    def for_range(self, node: ast.For) -> None:
        if node.orelse:
            raise Decline("for ... else")
        if not isinstance(node.target, ast.Name):
            raise Decline("a loop target that is not a name")
        call = node.iter
        if not (isinstance(call, ast.Call) and isinstance(call.func, ast.Name) and call.func.id == "range"
                and not call.keywords and 1 <= len(call.args) <= 3):
            raise Decline("a loop that is not over range(...)")
        step = 1.0
        if len(call.args) == 3:
            constant = _constant(call.args[2])
            if not isinstance(constant, (int, float)) or constant == 0 or int(constant) != constant:
                raise Decline("a range of non-constant step")
            step = float(constant)
        start = self.register()
        stop = self.register()
        if len(call.args) == 1:
            self.emit("MOV", start, self.constant(0.0))
            self.expression(call.args[0], stop)
        else:
            self.expression(call.args[0], start)
            self.expression(call.args[1], stop)
        variable = self.variable(node.target.id)
        counter = start  # the next value; the loop variable gets it at each pass
        top = len(self.tape.code)
        # leave when not counter < stop (not counter > stop for a negative step)
        exit_jump = self.emit("JLT", 0, counter, stop, 1) if step > 0 else self.emit("JLT", 0, stop, counter, 1)
        self.emit("MOV", variable, counter)
        self.emit("ADD", counter, counter, self.constant(step))
        self.loops.append(([], []))
        self.block(node.body)
        breaks, continues = self.loops.pop()
        self.emit("JMP", top)
        end = len(self.tape.code)
        for position in [exit_jump, *breaks]:
            self.patch(position, end)
        for position in continues:
            self.patch(position, top)

    def branch(self, test: ast.expr, body: list[ast.stmt], orelse: list[ast.stmt]) -> None:
        constant = _constant(test)
        if isinstance(constant, (bool, int, float)) and not isinstance(constant, tuple):
            self.block(body if constant else orelse)
            return
        false_jumps = self.test(test, False)
        self.block(body)
        if orelse:
            over = self.emit("JMP")
            for position in false_jumps:
                self.patch(position, len(self.tape.code))
            self.block(orelse)
            self.patch(over, len(self.tape.code))
        else:
            for position in false_jumps:
                self.patch(position, len(self.tape.code))

    def test(self, node: ast.expr, jump_when: bool) -> list[int]:
        """Code that jumps when ``bool(node) == jump_when`` and falls through otherwise;
        returns the jumps to patch with their target."""
        if isinstance(node, ast.UnaryOp) and isinstance(node.op, ast.Not):
            return self.test(node.operand, not jump_when)
        if isinstance(node, ast.BoolOp):
            is_and = isinstance(node.op, ast.And)
            if is_and != jump_when:  # `and` jumping when false, `or` jumping when true: any part decides
                jumps: list[int] = []
                for value in node.values:
                    jumps += self.test(value, jump_when)
                return jumps
            skips: list[int] = []  # `and` jumping when true: all parts true; `or` when false: all false
            for value in node.values[:-1]:
                skips += self.test(value, not jump_when)
            jumps = self.test(node.values[-1], jump_when)
            for position in skips:
                self.patch(position, len(self.tape.code))
            return jumps
        if isinstance(node, ast.Compare):
            if len(node.ops) != 1 or type(node.ops[0]) not in _COMPARE:
                raise Decline("a chained or non-numeric comparison")
            left = self.operand(node.left)
            right = self.operand(node.comparators[0])
            position = self.compare_jump(_COMPARE[type(node.ops[0])], left, right, jump_when)
            self.release(left)
            self.release(right)
            return [position]
        truth = self.operand(node)
        position = self.compare_jump("NE", truth, self.constant(0.0), jump_when)  # Python's truth of a number
        self.release(truth)
        return [position]

    def compare_jump(self, name: str, left: int, right: int, jump_when: bool) -> int:
        """A jump taken when ``(left <name> right) == jump_when`` (to patch). The machine has
        ``<``, ``<=`` and ``==``; ``x > y`` is ``y < x`` and ``x != y`` is ``not x == y``, the
        same IEEE predicates, NaN included."""
        if name in ("GT", "GE"):
            name, left, right = {"GT": "LT", "GE": "LE"}[name], right, left
        if name == "NE":
            name, jump_when = "EQ", not jump_when
        return self.emit("J" + name, 0, left, right, 0 if jump_when else 1)

    # ------------------------------------------------------------------ expressions
    def operand(self, node: ast.expr) -> int:
        """A register holding the value of ``node`` (a variable's own, a constant's, or a
        temporary to :meth:`release` after use)."""
        constant = _constant(node)
        if isinstance(constant, (bool, int, float)):
            return self.constant(float(constant))
        if isinstance(node, ast.Name):
            if node.id not in self.names:
                raise Decline(f"the name {node.id} (not a local scalar)")
            return self.names[node.id]
        register = self.temporary()
        self._temporaries.add(register)
        self.expression(node, register)
        return register

    def expression(self, node: ast.expr, out: int) -> None:
        """Code leaving the value of ``node`` in register ``out``."""
        constant = _constant(node)
        if isinstance(constant, (bool, int, float)):
            self.emit("MOV", out, self.constant(float(constant)))
        elif isinstance(node, ast.Name):
            self.emit("MOV", out, self.operand(node))
        elif isinstance(node, ast.BinOp):
            if type(node.op) not in _BINARY:
                raise Decline(f"the operator {type(node.op).__name__}")
            left = self.operand(node.left)
            right = self.operand(node.right)
            self.emit(_BINARY[type(node.op)], out, left, right)
            self.release(left)
            self.release(right)
        elif isinstance(node, ast.UnaryOp) and isinstance(node.op, ast.USub):
            value = self.operand(node.operand)
            self.emit("NEG", out, value)
            self.release(value)
        elif isinstance(node, ast.UnaryOp) and isinstance(node.op, ast.UAdd):
            self.expression(node.operand, out)
        elif isinstance(node, ast.IfExp):
            false_jumps = self.test(node.test, False)
            self.expression(node.body, out)
            over = self.emit("JMP")
            for position in false_jumps:
                self.patch(position, len(self.tape.code))
            self.expression(node.orelse, out)
            self.patch(over, len(self.tape.code))
        elif isinstance(node, (ast.Compare, ast.BoolOp)) or (isinstance(node, ast.UnaryOp)
                                                             and isinstance(node.op, ast.Not)):
            if isinstance(node, ast.BoolOp):
                raise Decline("and/or as a value")
            false_jumps = self.test(node, False)
            self.emit("MOV", out, self.constant(1.0))
            over = self.emit("JMP")
            for position in false_jumps:
                self.patch(position, len(self.tape.code))
            self.emit("MOV", out, self.constant(0.0))
            self.patch(over, len(self.tape.code))
        elif isinstance(node, ast.Subscript):
            slot, indices = self.subscript(node)
            self.load(out, slot, indices)
        elif isinstance(node, ast.Call):
            self.call(node, out)
        else:
            raise Decline(f"the expression {type(node).__name__}")

    def load(self, out: int, slot: int, indices: list[int]) -> None:
        if len(indices) == 1:
            self.emit("LOAD", out, slot, indices[0])
        else:
            self.emit("LOAD2", out, slot, indices[0], indices[1])
        for register in indices:
            self.release(register)

    def subscript(self, node: ast.Subscript) -> tuple[int, list[int]]:
        """The array slot and index registers of ``a[i]`` / ``a[i, j]``."""
        slot = self.array_slot(node.value)
        parts = node.slice.elts if isinstance(node.slice, ast.Tuple) else [node.slice]
        return slot, self.indices(slot, parts)

    def indices(self, slot: int, parts: list[ast.expr]) -> list[int]:
        rows, cols = self.tape.arrays[slot]
        dimensions = 2 if cols > 0 else 1
        if len(parts) != dimensions or any(isinstance(p, ast.Slice) for p in parts):
            raise Decline("an index of another dimension, or a slice")
        return [self.operand(p) for p in parts]

    def array_slot(self, node: ast.expr) -> int:
        if not isinstance(node, ast.Name) or node.id not in self.array_names:
            raise Decline("a subscript of something that is not an array")
        return self.array_names[node.id]

    def call(self, node: ast.Call, out: int) -> None:
        if node.keywords:
            raise Decline("a call with keywords")
        func = node.func
        if isinstance(func, ast.Attribute) and func.attr == "item" and isinstance(func.value, ast.Name) \
                and func.value.id in self.array_names:
            slot = self.array_names[func.value.id]
            self.load(out, slot, self.indices(slot, list(node.args)))
            return
        name = _attribute(func)
        arguments = node.args
        if name in (("float",),) and len(arguments) == 1:
            self.expression(arguments[0], out)
        elif name in (("abs",),) and len(arguments) == 1:
            value = self.operand(arguments[0])
            self.emit("ABS", out, value)
            self.release(value)
        elif name in (("min",), ("max",)) and len(arguments) == 2:
            # as Python's min(x, y) and max(x, y): y only when y < x (y > x)
            left = self.operand(arguments[0])
            right = self.operand(arguments[1])
            value = self.temporary()
            self._temporaries.add(value)
            self.emit("MOV", value, left)
            skip = self.compare_jump("LT" if name == ("min",) else "GT", right, left, False)
            self.emit("MOV", value, right)
            self.patch(skip, len(self.tape.code))
            self.emit("MOV", out, value)
            for register in (left, right, value):
                self.release(register)
        elif name is not None and len(name) == 2 and name[0] == "math" and name[1] in UNARY and len(arguments) == 1:
            value = self.operand(arguments[0])
            self.emit(UNARY[name[1]], out, value)
            self.release(value)
        elif name == ("math", "atan2") and len(arguments) == 2:
            left = self.operand(arguments[0])
            right = self.operand(arguments[1])
            self.emit("ATAN2", out, left, right)
            self.release(left)
            self.release(right)
        else:
            raise Decline(f"a call of {'.'.join(name) if name else ast.unparse(func)}")


def _attribute(node: ast.expr) -> tuple[str, ...] | None:
    if isinstance(node, ast.Name):
        return (node.id,)
    if isinstance(node, ast.Attribute) and isinstance(node.value, ast.Name):
        return (node.value.id, node.attr)
    return None


def _is_allocation(node: ast.expr) -> bool:
    return isinstance(node, ast.Call) and _attribute(node.func) in (("np", "empty"), ("np", "zeros"))


def _constant(node: ast.expr) -> object:
    """The value of a constant expression (numbers, tuples of them, ``np.inf``...; None otherwise).

    Folded as Python folds it: the same operations on the same doubles (``1.0 / 2.0`` is
    computed here by Python exactly as the interpreter computes it, and numba's constant
    folding by LLVM gives the correctly rounded IEEE result, the same)."""
    if isinstance(node, ast.Constant) and isinstance(node.value, (bool, int, float)):
        return node.value
    name = _attribute(node)
    if name in _CONSTANTS:
        return _CONSTANTS[name]  # type: ignore[index]
    if isinstance(node, ast.Tuple):
        values = [_constant(e) for e in node.elts]
        return tuple(values) if all(isinstance(v, (int, float)) for v in values) else None
    if isinstance(node, ast.UnaryOp) and isinstance(node.op, ast.USub):
        value = _constant(node.operand)
        return -value if isinstance(value, (int, float)) and not isinstance(value, bool) else None
    if isinstance(node, ast.BinOp) and type(node.op) in _BINARY:
        left, right = _constant(node.left), _constant(node.right)
        numbers = all(isinstance(v, (int, float)) and not isinstance(v, bool) for v in (left, right))
        if numbers and not (isinstance(node.op, ast.Div) and right == 0):
            # one IEEE operation on the same operands, here or at run time: the same double
            return {ast.Add: lambda: left + right, ast.Sub: lambda: left - right,  # type: ignore[operator]
                    ast.Mult: lambda: left * right, ast.Div: lambda: left / right}[type(node.op)]()  # type: ignore[operator]
    return None


def _value_names(node: ast.expr) -> set[str]:
    """The names whose values flow into the value of ``node`` (not through indices: an array
    element is a float whatever its index), with ``"#int"`` where an integer constant or a
    truth value does; a superset (what is not known to be a float counts)."""
    constant = _constant(node)
    if isinstance(constant, (bool, int)) and not isinstance(constant, float):
        return {"#int"}
    if isinstance(constant, float) or isinstance(node, ast.Subscript):
        return set()
    if isinstance(node, ast.Name):
        return {node.id}
    if isinstance(node, ast.Call):
        name = _attribute(node.func)
        if isinstance(node.func, ast.Attribute) and node.func.attr == "item":
            return set()
        if name == ("float",) or (name is not None and name[0] == "math"):
            return set()
        return set().union(*(_value_names(a) for a in node.args)) if node.args else set()
    if isinstance(node, ast.BinOp):
        if isinstance(node.op, ast.Div) or isinstance(_constant(node.left), float) \
                or isinstance(_constant(node.right), float):
            return set()  # a true division, or an operand a float: a float
        return _value_names(node.left) | _value_names(node.right)
    if isinstance(node, ast.UnaryOp):
        return {"#int"} if isinstance(node.op, ast.Not) else _value_names(node.operand)
    if isinstance(node, ast.IfExp):
        return _value_names(node.body) | _value_names(node.orelse)
    if isinstance(node, (ast.Compare, ast.BoolOp)):
        return {"#int"}
    names: set[str] = set()
    for child in ast.iter_child_nodes(node):
        if isinstance(child, ast.expr):
            names |= _value_names(child)
    return names


def _negated_parameters(function: ast.FunctionDef, arrays: set[str]) -> set[str]:
    """The scalar parameters whose value reaches a unary minus (they must be floats at the
    call); raises :class:`Decline` when a value that may be an integer does (``-k`` of an
    integer ``k = 0`` is ``0`` in Python, ``-0.0`` on the machine, and a later product
    would carry the sign)."""
    flows: dict[str, set[str]] = {}  # name -> names flowing into it over its assignments
    suspects: set[str] = set()  # names that may hold an integer
    negated: set[str] = set()
    for node in walk(function):  # the order does not matter: sets, and a fixed point
        if isinstance(node, ast.Assign) and len(node.targets) == 1:
            target, value = node.targets[0], node.value
            pairs = list(zip(target.elts, value.elts)) if isinstance(target, ast.Tuple) and \
                isinstance(value, ast.Tuple) else [(target, value)]
            for left, right in pairs:
                if isinstance(left, ast.Name):
                    flows.setdefault(left.id, set()).update(_value_names(right))
        elif isinstance(node, ast.AugAssign) and isinstance(node.target, ast.Name):
            flows.setdefault(node.target.id, set()).update(_value_names(node.value))
        elif isinstance(node, ast.For) and isinstance(node.target, ast.Name):
            suspects.add(node.target.id)
        elif isinstance(node, ast.UnaryOp) and isinstance(node.op, ast.USub) and _constant(node) is None:
            negated |= _value_names(node.operand)
    changed = True
    while changed:
        changed = False
        for name, sources in flows.items():
            if name not in suspects and sources & (suspects | {"#int"}):
                suspects.add(name)
                changed = True
            if name in negated and not sources <= negated:
                negated |= sources
                changed = True
    if negated & (suspects | {"#int"}):
        raise Decline("a unary minus of a value that may be an integer")
    parameters = {a.arg for a in function.args.args} - arrays
    return negated & parameters


def _array_names(function: ast.FunctionDef) -> set[str]:
    """Names used as arrays in ``function``: subscripted, ``.item(...)``, ``.shape``."""
    names: set[str] = set()
    for node in walk(function):  # the order does not matter: sets, and a fixed point
        if isinstance(node, ast.Subscript) and isinstance(node.value, ast.Name):
            names.add(node.value.id)
        elif isinstance(node, ast.Attribute) and node.attr in ("item", "shape") and isinstance(node.value, ast.Name):
            names.add(node.value.id)
    return names


class _Lengths:
    """``a.shape[0]`` of an array -> a name the call fills with its length (an argument's, or a
    local array's constant rows); in place, with :func:`~dirac.codegen.flatten.replace_children`
    (an :class:`ast.NodeTransformer` took a fifth of the translation of a 20,000-character loop)."""

    def __init__(self) -> None:
        self.found: set[str] = set()

    def visit(self, node: ast.AST) -> ast.AST:
        if isinstance(node, ast.Subscript):
            value = node.value
            if isinstance(value, ast.Attribute) and value.attr == "shape" and isinstance(value.value, ast.Name) \
                    and isinstance(node.slice, ast.Constant) and node.slice.value == 0:
                self.found.add(value.value.id)
                return ast.copy_location(ast.Name(f"_len_{value.value.id}", ast.Load()), node)
        replace_children(node, self.visit)
        return node


def translate(source: str, name: str, reasons: list[str] | None = None, optimised: bool = True) -> Tape | None:
    """The tape of function ``name`` of ``source`` (Python text), or None when the function
    uses a construct the tape does not translate (the other tiers then run it; the reason is
    appended to ``reasons`` when given). ``optimised``: its copies and dead writes taken out
    (:func:`~dirac.codegen.tape_optimise.optimise`, the same operations in the same order);
    False gives the instruction-for-instruction translation."""
    try:
        module = ast.parse(source)
    except SyntaxError:
        if reasons is not None:
            reasons.append("not Python source")
        return None
    except RecursionError:  # an expression nested deeper than the parser builds (a line of ~3,000 sums)
        if reasons is not None:
            reasons.append("an expression nested too deep to parse")
        return None
    functions = [n for n in module.body if isinstance(n, ast.FunctionDef) and n.name == name]
    if len(functions) != 1:
        if reasons is not None:
            reasons.append(f"no one function {name}")
        return None
    function = functions[0]
    lengths = _Lengths()
    function = cast(ast.FunctionDef, lengths.visit(function))
    try:
        translator = _Translator(function)
        for array in sorted(lengths.found):  # the lengths are scalars the call provides
            translator.variable(f"_len_{array}")
        tape = translator.run()
        for array in sorted(lengths.found):
            if array not in translator.array_names:
                raise Decline(f"{array}.shape of a name that is not an array")
            # an argument's length comes with the call; a local array's is its constant rows,
            # which the call sets the same way (TapeFunction: reg[length] = rows[slot])
            tape.lengths[translator.array_names[array]] = translator.names[f"_len_{array}"]
        if optimised:
            tape.code = optimise(tape.code)
    except (Decline, RecursionError) as error:
        if reasons is not None:
            reasons.append(str(error) or type(error).__name__)
        return None
    return tape
