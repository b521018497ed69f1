"""Safe parsing of user expressions into sympy.

User input (system files, ``--param``, scene files) is parsed with Python's :mod:`ast`
and walked against a whitelist: numbers, known names, ``+ - * / **``, parentheses and a
fixed set of elementary functions. Nothing is ever evaluated with :func:`eval` (sympy's
own ``parse_expr`` evaluates code, so it is not used either).

Decimal literals become exact rationals (``0.5`` -> ``1/2``), so the symbolic analysis is
not disturbed by binary round-off.
"""

from __future__ import annotations

import ast
from collections.abc import Callable, Mapping

import sympy

from dirac.errors import InputError
from dirac.validate import did_you_mean

__all__ = ["parse_expression", "non_real_constant", "ALLOWED_FUNCTIONS", "ALLOWED_CONSTANTS", "TIME"]

#: the time ``t`` of an explicitly time-dependent (rheonomic) Lagrangian or constraint
TIME = sympy.Symbol("t", real=True)

#: function name -> sympy function; the only calls an expression may make
ALLOWED_FUNCTIONS: dict[str, Callable[..., sympy.Expr]] = {
    "sin": sympy.sin,
    "cos": sympy.cos,
    "tan": sympy.tan,
    "asin": sympy.asin,
    "acos": sympy.acos,
    "atan": sympy.atan,
    "atan2": sympy.atan2,
    "sinh": sympy.sinh,
    "cosh": sympy.cosh,
    "tanh": sympy.tanh,
    "exp": sympy.exp,
    "log": sympy.log,
    "sqrt": sympy.sqrt,
    "Abs": sympy.Abs,
    "abs": sympy.Abs,
}

#: constant name -> value
ALLOWED_CONSTANTS: dict[str, sympy.Expr] = {"pi": sympy.pi, "E": sympy.E}

_BINARY = {
    ast.Add: lambda a, b: a + b,
    ast.Sub: lambda a, b: a - b,
    ast.Mult: lambda a, b: a * b,
    ast.Div: lambda a, b: a / b,
    ast.Pow: lambda a, b: a**b,
}
_MAX_LENGTH = 100_000
_MAX_EXPONENT = 1000


def parse_expression(
    text: str,
    names: Mapping[str, sympy.Symbol],
    *,
    what: str = "expression",
    time: sympy.Symbol | None = None,
    refused: Mapping[str, str] | None = None,
    unknown_hint: str = "",
) -> sympy.Expr:
    """Parse ``text`` into a sympy expression, allowing only the given ``names``.

    Parameters
    ----------
    text
        The expression, in Python syntax (``**`` for powers).
    names
        Every symbol the expression may use, by name (coordinates, velocities
        ``<q>_dot``, parameters). Elementary functions and ``pi``, ``E`` are always allowed.
    what
        How to call the expression in error messages, e.g. ``"constraint 2"``.
    time
        The time symbol, allowed under its own name (``t``) besides ``names`` when given
        (explicitly time-dependent Lagrangians and constraints); a name in ``names``
        takes precedence.
    refused
        Names that exist but are not allowed here -> why (e.g. velocities in a
        constraint); the error says so instead of "unknown name".
    unknown_hint
        Added to the error of an unknown name that is close to no allowed name (e.g.
        "if it is a parameter, add it to parameters").

    Returns
    -------
    sympy.Expr

    Raises
    ------
    InputError
        On a syntax error, an unknown name, a disallowed construct or an empty string;
        the message quotes the offending piece and lists the allowed names.
    """
    if not isinstance(text, str):
        if isinstance(text, (int, float)) and not isinstance(text, bool):
            text = repr(text)
        else:
            raise InputError(f"{what} must be a string, got {type(text).__name__} {text!r}")
    stripped = text.strip()
    if not stripped:
        raise InputError(f"{what} is empty: write an expression such as 'm/2*x_dot**2'")
    if len(stripped) > _MAX_LENGTH:
        raise InputError(f"{what} is longer than {_MAX_LENGTH} characters")
    if "^" in stripped:
        raise InputError(f"{what} {stripped!r} uses '^': write powers as '**'")
    try:
        tree = ast.parse(stripped, mode="eval")
    except SyntaxError as exc:
        raise InputError(f"{what} {stripped!r} is not a valid expression: {exc.msg}") from None
    except RecursionError:
        raise InputError(f"{what} is nested too deeply to parse: split it into shorter expressions") from None
    listed = list(names)
    if time is not None and time.name not in names:
        names = {**names, time.name: time}
    return _Converter(names, what, stripped, listed, dict(refused or {}), unknown_hint).visit(tree.body)


class _Converter:
    def __init__(self, names: Mapping[str, sympy.Symbol], what: str, text: str, listed: list[str],
                 refused: dict[str, str], unknown_hint: str) -> None:
        self.names = names
        self.listed = listed
        self.what = what
        self.text = text
        self.refused = refused
        self.unknown_hint = unknown_hint

    def fail(self, message: str) -> InputError:
        return InputError(f"{self.what} {self.text!r}: {message}")

    def visit(self, node: ast.AST) -> sympy.Expr:
        if isinstance(node, ast.Constant):
            value = node.value
            if isinstance(value, bool) or not isinstance(value, (int, float)):
                raise self.fail(f"{value!r} is not a number")
            if isinstance(value, int):
                return sympy.Integer(value)
            if value != value or value in (float("inf"), float("-inf")):
                raise self.fail("non-finite number")
            return sympy.Rational(repr(value))
        if isinstance(node, ast.Name):
            name = node.id
            if name in self.names:
                return self.names[name]
            if name in ALLOWED_CONSTANTS:
                return ALLOWED_CONSTANTS[name]
            if name in ALLOWED_FUNCTIONS:
                raise self.fail(f"function {name!r} is used without arguments")
            if name in self.refused:
                raise self.fail(f"{name!r} is not allowed here: {self.refused[name]}")
            known = ", ".join(sorted(self.listed)) or "(none)"
            suggestion = did_you_mean(name, [*self.listed, *ALLOWED_CONSTANTS])
            hint = f"; {self.unknown_hint}" if self.unknown_hint and not suggestion else ""
            raise self.fail(f"unknown name {name!r}{suggestion}{hint}; the names allowed here are: {known}")
        if isinstance(node, ast.BinOp) and isinstance(node.op, (ast.Add, ast.Sub)):
            return self._sum(node)
        if isinstance(node, ast.BinOp):
            op = _BINARY.get(type(node.op))
            if op is None:
                raise self.fail(f"operator {type(node.op).__name__} is not allowed (use + - * / **)")
            left, right = self.visit(node.left), self.visit(node.right)
            if isinstance(node.op, ast.Pow) and right.is_number and abs(right) > _MAX_EXPONENT:
                raise self.fail(f"exponent {right} is too large")
            if isinstance(node.op, ast.Div) and right == 0:
                raise self.fail("division by zero")
            return op(left, right)
        if isinstance(node, ast.UnaryOp):
            operand = self.visit(node.operand)
            if isinstance(node.op, ast.USub):
                return -operand
            if isinstance(node.op, ast.UAdd):
                return operand
            raise self.fail(f"operator {type(node.op).__name__} is not allowed")
        if isinstance(node, ast.Call):
            if not isinstance(node.func, ast.Name) or node.func.id not in ALLOWED_FUNCTIONS:
                called = ast.unparse(node.func)
                allowed = ", ".join(sorted(ALLOWED_FUNCTIONS))
                raise self.fail(f"call of {called!r} is not allowed; allowed functions: {allowed}")
            if node.keywords:
                raise self.fail("keyword arguments are not allowed")
            args = [self.visit(arg) for arg in node.args]
            expected = 2 if node.func.id == "atan2" else 1
            if len(args) != expected:
                raise self.fail(f"{node.func.id} takes {expected} argument(s), got {len(args)}")
            return ALLOWED_FUNCTIONS[node.func.id](*args)
        raise self.fail(f"{ast.unparse(node)!r} is not allowed in an expression")

    def _sum(self, node: ast.BinOp) -> sympy.Expr:
        """A chain ``a + b - c + ...`` as one sum, walked down its left spine without recursion.

        Python parses a long sum (a Lagrangian of a thousand terms) into a left-nested tree
        as deep as the sum is long; visiting it recursively would exceed the recursion
        limit. The terms are converted one by one and added in one ``sympy.Add`` (the same
        expression as adding them pairwise).
        """
        terms: list[tuple[bool, ast.AST]] = []
        head: ast.AST = node
        while isinstance(head, ast.BinOp) and isinstance(head.op, (ast.Add, ast.Sub)):
            terms.append((isinstance(head.op, ast.Sub), head.right))
            head = head.left
        values = [self.visit(head)]
        values.extend(-self.visit(term) if negative else self.visit(term) for negative, term in reversed(terms))
        return sympy.Add(*values)


def non_real_constant(
    expression: sympy.Expr, values: Mapping[sympy.Symbol, sympy.Expr] | None = None
) -> tuple[sympy.Expr, complex] | None:
    """The first part of ``expression`` with a value that is not a real number, or ``None``.

    A Lagrangian, a constraint and a force are real functions of real variables. A
    constant such as ``sqrt(-2)`` (``sqrt(2) I``), ``log(-1)`` (``I pi``), ``acos(2)`` or
    ``(-8)**(1/3)`` (sympy's principal root, ``1 + sqrt(3) I``) makes them complex, and so
    does ``sqrt(m)`` with a parameter ``m = -1``: the analysis's real arithmetic would then
    drop imaginary parts or fail. The largest sub-expressions whose symbols all have a
    value in ``values`` (none: constants) are evaluated with those values (30 digits); the
    first whose imaginary part is not zero, or that has no finite value, is returned with
    its value (``nan`` when it has none).
    """
    values = dict(values or {})
    known = set(values)
    stack = [sympy.sympify(expression)]
    while stack:
        node = stack.pop()
        if node.is_Number or isinstance(node, sympy.NumberSymbol):
            if not node.is_finite:
                return node, complex(float("nan"))
            continue
        if node.free_symbols <= known:
            try:
                value = complex(node.xreplace(values).evalf(30))
            except (TypeError, ValueError):
                return node, complex(float("nan"))
            if value.imag != 0.0 or value.real != value.real or abs(value.real) == float("inf"):
                return node, value
            continue
        if isinstance(node, (sympy.Add, sympy.Mul)):
            # the constant part of a sum or product is the sum or product of its constant terms or
            # factors: sqrt(-2)*y is Mul(-1, sqrt(2), I, y), whose constant part is -sqrt(2)*I
            constant = [a for a in node.args if a.free_symbols <= known]
            if len(constant) > 1:
                stack.append(node.func(*constant))
                stack.extend(reversed([a for a in node.args if not a.free_symbols <= known]))
                continue
        stack.extend(reversed(node.args))
    return None
