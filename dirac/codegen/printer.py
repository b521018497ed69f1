"""The one printer from sympy expressions to straight-line Python source.

Every backend of :mod:`dirac.codegen` gets its source from :func:`straight_line`: a list
of assignments ``name = code`` followed by one code string per output, with the inputs
bound to local names. Two targets:

* ``"math"``: scalar Python with :mod:`math` functions (the numba and scalar backends).
  Numbers print as floats, small integer powers as products, ``x**(1/2)`` as ``sqrt``:
  code that numba compiles to plain floating-point arithmetic.
* ``"numpy"``: array expressions with :mod:`numpy` functions (the numpy backend), printed
  as ``sympy.lambdify(..., "numpy")`` prints them, so that values are those lambdify gave.

Three ways to share sub-expressions:

* ``sharing="cse"``: :func:`sympy.cse` over all outputs, each reduced expression printed
  whole (target ``"math"``: ``optimizations="basic"``, names ``t0, t1, …``, the smallest
  code, for functions that run many times; target ``"numpy"``: sympy's defaults, names
  ``x0, x1, …``, as ``lambdify(..., cse=True)``).
* ``sharing="dag"`` (target ``"math"``): one walk over the expression DAG, one assignment
  per distinct sub-expression (structural sharing through sympy's hashing). Fast to
  generate even for brackets whose trees print exponentially long: used for evaluations
  at a few points.
* ``sharing="tree"``: every output printed whole, nothing shared (small expressions).

On every road a sum or product of more than :data:`CHAIN_OPERANDS` operands is printed over
several lines (:func:`chained`), in the order of operations of one line: CPython does not
compile a line of about 3,000 of them.
"""

from __future__ import annotations

import builtins
import keyword
from collections.abc import Iterable, Iterator, Mapping, Sequence
from dataclasses import dataclass
from itertools import count, islice
from typing import Any, Literal

import sympy
from sympy.core.mul import _keep_coeff
from sympy.printing.codeprinter import PrintMethodNotImplementedError
from sympy.printing.numpy import NumPyPrinter
from sympy.printing.precedence import PRECEDENCE, precedence
from sympy.printing.pycode import PythonCodePrinter

__all__ = ["StraightLineCode", "UnsupportedExpression", "distinct_nodes", "flat_expressions", "input_name",
           "straight_line"]

Target = Literal["math", "numpy"]
Sharing = Literal["cse", "dag", "tree"]


class UnsupportedExpression(TypeError):
    """An expression the straight-line printer cannot turn into code (e.g. ``Piecewise``
    under ``sharing="dag"``, an undefined function, a free symbol that is not an input)."""


@dataclass(frozen=True)
class StraightLineCode:
    """Expressions as straight-line code.

    Attributes
    ----------
    assignments : tuple of (str, str)
        ``(name, code)`` in evaluation order; ``code`` uses the input names and earlier names.
    outputs : tuple of str
        The code of each output, in the order of the expressions.
    """

    assignments: tuple[tuple[str, str], ...]
    outputs: tuple[str, ...]

    def body(self, indent: str = "    ") -> list[str]:
        """The assignments as indented source lines."""
        return [f"{indent}{name} = {code}" for name, code in self.assignments]


#: Most operands of one line of a sum or product: a line of ``a + b + ...`` is a left-deep tree
#: whose depth CPython's compiler recurses into, and about 3,000 operands exceed its limit
#: (``RecursionError: maximum recursion depth exceeded during compilation``; CPython 3.11: 2,987
#: names added in a ``return`` compiled from a script's top level, 3 fewer per frame of the caller's
#: stack, 1,187 at 600 frames deep; :func:`ast.parse` fails at 2,989, "during ast construction").
CHAIN_OPERANDS = 200


def chained(operands: Sequence[str], operator: str, lines: list[tuple[str, str]], prefix: str = "t",
            names: Iterator[str] | None = None) -> str:
    """The code of ``operands`` joined by ``operator`` (``" + "``, ``" * "``) for the last line of ``lines``.

    Longer than :data:`CHAIN_OPERANDS`, the leading operands go to lines of their own
    (``<prefix><k>``, ``k`` the line's index in ``lines``, or the next of ``names`` when given,
    appended to it), each continuing the one before: ``t_1 = a_1 + ... + a_200``,
    ``t_2 = t_1 + a_201 + ...``. Python adds left to right, so these are the same operations in
    the same order as one long line: the same bits. ``operator`` may be ``" "`` when each
    operand but the first carries its own (``"- b"``, ``"+ c"``, as sympy prints a sum).
    """
    head = list(operands)
    while len(head) > CHAIN_OPERANDS:
        name = next(names) if names is not None else f"{prefix}{len(lines)}"
        lines.append((name, operator.join(head[:CHAIN_OPERANDS])))
        head = [name, *head[CHAIN_OPERANDS:]]
    return operator.join(head)


class _ChainedPrinting(PythonCodePrinter):
    """A code printer whose sums and products of more than :data:`CHAIN_OPERANDS` operands are printed as
    :func:`chained` lines.

    sympy prints a sum ``a + b - c + ...`` (and a product) on one line, a left-deep tree of binary
    operations that CPython's compiler recurses into: a sum of 3,000 names printed by
    :func:`straight_line` (``"cse"`` and ``"tree"``, targets ``"math"`` and ``"numpy"``) fails to compile
    (``RecursionError``, measured with Python 3.11 from a script's top level at 2,993 names; fewer from
    deeper in a stack, see :data:`CHAIN_OPERANDS`). Sums and products of more than
    :data:`CHAIN_OPERANDS` operands, nested ones too (a long sum under a function, a power or in a
    product), leave their leading operands in :attr:`lines`, each line continuing the one before;
    the code returned continues the last: the text with each line's name replaced by its code is sympy's
    one-line text, so the operations and their order are those of the one line, to the last bit.
    Up to :data:`CHAIN_OPERANDS` operands everything prints as sympy prints it.

    Attributes
    ----------
    lines : list of (str, str)
        The lines ``(name, code)`` left by the printing since the caller last emptied it; they go,
        in order, before the line of the code printed.
    names : iterator of str or None
        Fresh names for these lines; None: long sums print on one line (nothing else may be defined).
    """

    def __init__(self, settings: dict[str, Any]) -> None:
        super().__init__(settings)
        self.lines: list[tuple[str, str]] = []
        self.names: Iterator[str] | None = None

    def _print_Add(self, expr: sympy.Add, order: str | None = None) -> str:
        if len(expr.args) <= CHAIN_OPERANDS or self.names is None:
            code: str = super()._print_Add(expr, order)
            return code
        # sympy's StrPrinter._print_Add, each term with its sign, then chained
        prec = precedence(expr)
        operands = []
        for term in self._as_ordered_terms(expr, order=order):
            text = self._print(term)
            sign = "+"
            if text.startswith("-") and not term.is_Add:
                sign, text = "-", text[1:]
            if precedence(term) < prec or term.is_Add:
                text = f"({text})"
            operands.append(f"{sign} {text}")
        operands[0] = operands[0][2:] if operands[0][0] == "+" else "-" + operands[0][2:]
        return chained(operands, " ", self.lines, names=self.names)

    def _print_Mul(self, expr: sympy.Mul) -> str:
        if len(expr.args) <= CHAIN_OPERANDS or self.names is None:
            code: str = super()._print_Mul(expr)
            return code
        # sympy's CodePrinter._print_Mul (numerator and denominator), each product chained
        prec = precedence(expr)
        c, e = expr.as_coeff_Mul()
        sign = ""
        if c < 0:
            expr = _keep_coeff(-c, e)
            sign = "-"
        args = expr.as_ordered_factors() if self.order not in ("old", "none") else sympy.Mul.make_args(expr)
        a: list[sympy.Expr] = []
        b: list[sympy.Expr] = []
        pow_paren = []
        for item in args:
            if item.is_commutative and item.is_Pow and item.exp.is_Rational and item.exp.is_negative:
                if item.exp != -1:
                    b.append(sympy.Pow(item.base, -item.exp, evaluate=False))
                else:
                    if len(item.args[0].args) != 1 and isinstance(item.base, sympy.Mul):
                        pow_paren.append(item)
                    b.append(sympy.Pow(item.base, -item.exp))
            else:
                a.append(item)
        a = a or [sympy.S.One]
        if len(a) == 1 and sign == "-":
            a_str = [self.parenthesize(a[0], 0.5 * (PRECEDENCE["Pow"] + PRECEDENCE["Mul"]))]
        else:
            a_str = [self.parenthesize(x, prec) for x in a]
        b_str = [self.parenthesize(x, prec) for x in b]
        for item in pow_paren:
            if item.base in b:
                b_str[b.index(item.base)] = f"({b_str[b.index(item.base)]})"
        numerator = chained([sign + a_str[0], *a_str[1:]], "*", self.lines, names=self.names)
        if not b:
            return numerator
        if len(b) == 1:
            return f"{numerator}/{b_str[0]}"
        return f"{numerator}/({chained(b_str, '*', self.lines, names=self.names)})"


class _MathPrinter(_ChainedPrinting):
    """Scalar Python with ``math`` functions and numbers as floats.

    Parameters
    ----------
    unroll_powers
        ``True``: integer powers ``-4..4`` as products (numba then compiles plain
        multiplications); ``False``: as ``x**k`` and ``1.0/(x**k)``.
    exact_floats
        ``True``: floats as ``repr(float(x))`` (every bit); ``False``: as sympy prints them
        (the float's decimal precision).
    """

    def __init__(self, unroll_powers: bool, exact_floats: bool) -> None:
        super().__init__({"fully_qualified_modules": True, "standard": "python3"})
        self.unroll_powers = unroll_powers
        self.exact_floats = exact_floats

    def _print_Float(self, expr: sympy.Float) -> str:
        if self.exact_floats:
            return repr(float(expr))
        code: str = super()._print_Float(expr)
        return code

    def _print_Rational(self, expr: sympy.Rational) -> str:
        return f"({float(expr.p)!r}/{float(expr.q)!r})"

    def _print_Integer(self, expr: sympy.Integer) -> str:
        return f"{float(expr.p)!r}"

    def _print_Pow(self, expr: sympy.Pow, rational: bool = False) -> str:
        base, exponent = expr.as_base_exp()
        return self.power(self._print(base), exponent)

    def power(self, base: str, exponent: sympy.Expr, exponent_code: str | None = None) -> str:
        """``base ** exponent`` with the code ``base`` of the base.

        With ``unroll_powers``, integer exponents ``1..4`` become products and ``-4..-1``
        one over a product (otherwise ``x**k``, ``1.0/(x**k)``); ``1/2`` a square root;
        any other exponent a power of the printed exponent (or of ``exponent_code``).
        """
        if exponent.is_Integer and not self.unroll_powers:
            k = int(exponent)
            return f"{base}**{k}" if k > 0 else f"1.0/({base}**{-k})"
        if exponent.is_Integer and 0 < int(exponent) <= 4:
            factor = f"({base})"
            return "(" + "*".join([factor] * int(exponent)) + ")"
        if exponent.is_Integer and -4 <= int(exponent) < 0:
            factor = f"({base})"
            return "(1.0/(" + "*".join([factor] * -int(exponent)) + "))"
        if exponent == sympy.S.Half:
            return f"math.sqrt({base})"
        code = exponent_code if exponent_code is not None else self._print(exponent)
        return f"{base}**{code}" if not self.unroll_powers else f"(({base})**({code}))"


class _NumPyPrinter(_ChainedPrinting, NumPyPrinter):
    """sympy's numpy printer (as :func:`sympy.lambdify` prints) with long sums and products chained."""


def _printer(target: Target, sharing: Sharing) -> _ChainedPrinting:
    if target == "math":
        # kernels ("cse"): products for small powers; fast-to-build scalar code ("dag"): every
        # bit of a float constant
        return _MathPrinter(unroll_powers=sharing != "dag", exact_floats=sharing == "dag")
    if target == "numpy":
        return _NumPyPrinter({"fully_qualified_modules": True, "inline": True})
    raise ValueError(f"target = {target!r}: use 'math' or 'numpy'")


#: names the printed code itself uses (modules, builtins the printers call)
_RESERVED = frozenset({"math", "numpy"}) | frozenset(dir(builtins))


def input_name(symbol: sympy.Symbol, index: int, taken: set[str]) -> str:
    """The symbol's own name when it is a safe local name (as lambdify keeps it), else ``a<index>_``."""
    name = symbol.name
    if name.isidentifier() and not keyword.iskeyword(name) and name not in _RESERVED and name not in taken:
        return name
    return f"a{index}_"


#: an expression of more distinct sub-expressions than this is left as it is by the preprocessing of cse's "basic"
#: optimizations (sympy's ``factor_terms`` and its sign normalisation), whose cost grows much faster than the size:
#: compiling the analysed flow of the rigid body's (228) (``AnalysedSystem.from_analysis``) spent 145 s of its 187 s
#: in ``factor_terms``, all of it on the 241 of its 1054 expressions above 100 such nodes (0.6 s each); with the
#: bound it took 31 s. The kernels of the latency corpus (at most 46 nodes an expression) and of (78) (89) are
#: printed as before; (19)'s expressions above 100 nodes (up to 190) are shared unfactored.
BASIC_CSE_NODES = 100


def distinct_nodes(expr: sympy.Basic) -> Iterator[sympy.Basic]:
    """The sub-expressions of ``expr`` in preorder, each distinct one once (a shared sub-tree met again is
    skipped whole: its nodes were met at its first occurrence)."""
    seen: set[sympy.Basic] = set()
    stack = [expr]
    while stack:
        node = stack.pop()
        if node in seen:
            continue
        seen.add(node)
        yield node
        stack.extend(reversed(node.args))


def _within(expr: sympy.Basic, limit: int) -> bool:
    """Whether ``expr`` has at most ``limit`` distinct sub-expressions (one walk, stopped at the limit)."""
    return sum(1 for _ in islice(distinct_nodes(expr), limit + 1)) <= limit


def _bounded(pre: Any) -> Any:
    """``pre`` (a preprocessor of :func:`sympy.cse`) for expressions within :data:`BASIC_CSE_NODES`, else identity."""

    def run(expr: sympy.Basic) -> sympy.Basic:
        return pre(expr) if _within(expr, BASIC_CSE_NODES) else expr

    return run


def _basic_optimizations() -> list[tuple[Any, Any]]:
    """sympy's ``optimizations="basic"`` of :func:`sympy.cse`, each preprocessor bounded by :func:`_bounded`
    (the postprocessor only undoes the marks the sign normalisation leaves, so it runs as it is)."""
    from importlib import import_module

    cse_main = import_module("sympy.simplify.cse_main")  # sympy.simplify is also a function's name
    return [(None if pre is None else _bounded(pre), post) for pre, post in cse_main.basic_optimizations]


_BOUNDED_BASIC = _basic_optimizations()


def flat_expressions(expressions: Iterable[object]) -> list[sympy.Expr]:
    """The expressions as a flat list (a matrix in C order, i.e. row by row)."""
    return [sympy.sympify(e) for e in expressions]


def straight_line(
    inputs: Mapping[sympy.Symbol, str],
    expressions: Iterable[object],
    target: Target = "math",
    sharing: Sharing = "cse",
    label: str = "expressions",
) -> StraightLineCode:
    """Straight-line code of ``expressions`` in the local names of their inputs.

    Parameters
    ----------
    inputs
        Every symbol the expressions may use -> its local name in the generated code
        (valid Python names; ``sharing="dag"`` names shared sub-expressions ``t<digits>``,
        so no input may be named so there; :func:`sympy.cse` picks names no input uses, and so
        do the lines of sums longer than :data:`CHAIN_OPERANDS`: ``t<digits>`` (``x<digits>``
        for ``"numpy"``) numbered on after cse's, placed just before the line that uses them).
    expressions
        The outputs: a sympy matrix (row by row) or a sequence of expressions.
    target
        ``"math"`` (scalar) or ``"numpy"`` (arrays).
    sharing
        ``"cse"``, ``"dag"`` (target ``"math"`` only) or ``"tree"`` (see the module
        docstring).
    label
        Names the expressions in error messages.

    Raises
    ------
    ValueError
        An expression uses a symbol that is not an input (``"cse"``, ``"tree"``).
    UnsupportedExpression
        ``sharing="dag"``: a node the walk cannot print, or a symbol that is not an input.
    """
    printer = _printer(target, sharing)
    if sharing == "dag":
        if not isinstance(printer, _MathPrinter):
            raise ValueError("sharing = 'dag' prints for the 'math' target only")
        return _dag_code(printer, inputs, flat_expressions(expressions))
    if sharing not in ("cse", "tree"):
        raise ValueError(f"sharing = {sharing!r}: use 'cse', 'dag' or 'tree'")
    local_of = {symbol: sympy.Symbol(name, real=True) for symbol, name in inputs.items() if symbol.name != name}
    known = {local_of.get(symbol, symbol) for symbol in inputs}
    if isinstance(expressions, sympy.MatrixBase):
        localised: Any = expressions.xreplace(local_of) if local_of else expressions
        free = localised.free_symbols
    else:
        localised = [e.xreplace(local_of) for e in flat_expressions(expressions)]
        free = set().union(*(e.free_symbols for e in localised)) if localised else set()
    leftover = free - known
    if leftover:
        names = ", ".join(sorted(s.name for s in leftover))
        raise ValueError(f"{label}: expressions use symbols that are neither arguments nor parameters: {names}")
    replacements: list[tuple[sympy.Symbol, sympy.Expr]] = []
    if sharing == "tree":
        reduced = localised
    elif target == "math":
        outputs = flat_expressions(localised)
        replacements, reduced = sympy.cse(outputs, symbols=sympy.numbered_symbols("t", real=True),
                                          optimizations=_BOUNDED_BASIC)
    else:  # lambdify's cse=True
        replacements, reduced = sympy.cse(localised, list=False)
    # the lines of long sums (printer.lines) are named on after cse's names (t0, t1, ... for "math", x0, ... for
    # "numpy"), skipping the inputs' and cse's: names of the kind the callers already leave to the printed code
    taken = set(inputs.values()) | {symbol.name for symbol, _ in replacements}
    stem = "t" if target == "math" else "x"
    printer.names = (name for name in (f"{stem}{k}" for k in count(len(replacements))) if name not in taken)
    assignments: list[tuple[str, str]] = []
    for symbol, value in replacements:
        code = printer.doprint(value)
        assignments += printer.lines
        printer.lines.clear()
        assignments.append((symbol.name, code))
    results = tuple(printer.doprint(value) for value in flat_expressions(reduced))
    assignments += printer.lines
    return StraightLineCode(tuple(assignments), results)


def _dag_code(
    printer: _MathPrinter, inputs: Mapping[sympy.Symbol, str], outputs: Sequence[sympy.Expr]
) -> StraightLineCode:
    names: dict[Any, str] = dict(inputs)
    lines: list[tuple[str, str]] = []

    def atom(e: sympy.Basic) -> str | None:
        known = names.get(e)
        if known is not None:
            return known
        if e.is_Number or e is sympy.pi or e is sympy.E:
            code: str = printer.doprint(e)
            names[e] = code
            return code
        return None

    def function_code(node: sympy.Basic, parts: list[str]) -> str:
        # the printer's own function table: print f(operand names)
        try:
            code: str = printer.doprint(node.func(*[sympy.Symbol(part) for part in parts]))
        except (PrintMethodNotImplementedError, TypeError, ValueError):
            raise UnsupportedExpression(f"cannot compile {node.func}") from None
        return code

    def emit(root: sympy.Basic) -> str:
        done = atom(root)
        if done is not None:
            return done
        stack = [(root, False)]
        while stack:
            node, expanded = stack.pop()
            if atom(node) is not None:
                continue
            if not expanded:
                stack.append((node, True))
                stack.extend((a, False) for a in node.args if atom(a) is None)
                continue
            parts = [atom(a) for a in node.args]
            operands = [part for part in parts if part is not None]
            if len(operands) < len(parts):  # only a symbol that is not an input is left
                raise UnsupportedExpression(f"cannot compile {node}: it is not an input")
            if node.is_Add or node.is_Mul:
                code = chained(operands, " + " if node.is_Add else " * ", lines)
            elif node.is_Pow:
                code = printer.power(operands[0], node.exp, operands[1])
            elif isinstance(node, sympy.Function):
                code = function_code(node, operands)
            else:
                raise UnsupportedExpression(f"cannot compile {node.func}")
            name = f"t{len(lines)}"
            lines.append((name, code))
            names[node] = name
        return names[root]

    results = tuple(emit(e) for e in outputs)
    return StraightLineCode(tuple(lines), results)
