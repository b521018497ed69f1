"""The interpreted tier's step loops on Python floats: small loops unrolled, small arrays as locals.

A generated step loop (:mod:`dirac.codegen.kernel_templates`) keeps its work in small
arrays allocated once (``x = np.empty(2)``, ``M0 = np.empty((2, 2))``) and walks them in
loops of literal length (``for i in range(2):``). Compiled, that costs nothing; run by the
interpreter, each iteration of such a loop and each element access costs a bytecode
dispatch and a numpy scalar (about 0.1 us each), and the arithmetic on numpy scalars costs
several times that on Python floats. For the interpreted tier only
(:meth:`dirac.codegen.tiers.TieredModule.interpreted_function`), :func:`scalar_function`
rewrites one function:

1. every loop ``for i in range(K)`` with a literal ``K`` (at most :data:`UNROLL_MAX`
   iterations and :data:`UNROLL_STATEMENTS` statements unrolled, no
   ``break``/``continue``/``else`` of its own, its variable not rebound in its body) is
   unrolled: its body repeated with ``i`` replaced by ``0 .. K - 1`` in order, then
   ``i = K - 1`` as the loop leaves it; integer arithmetic on literals is folded
   (``2 + 1`` -> ``3``) and ``if`` on a literal comparison keeps the side that runs;
2. every array that the function allocates once at its top level with ``np.empty`` /
   ``np.zeros`` of a literal shape, and that it uses only through subscripts of literal
   indices within that shape (never passed on, sliced or indexed by a variable), becomes one
   local name per element (``x[1]`` -> ``_a_x_1``), set to zero at the allocation;
3. every element read from the other arrays (the arguments, and arrays allocated in the
   function) is read as a Python number, ``q.item(0)`` for ``q[0]``, so that the arithmetic
   runs on Python floats rather than numpy scalars (several times faster).

Both keep every floating-point operation and its order (only the loop counters and the
addresses of the operands change; Python floats and numpy's float64 are the same IEEE
doubles and round alike), so the interpreted tier still gives the compiled tier's numbers
bit for bit, which the tier tests check. The compiled tier keeps the loops (numba compiles
them faster than their unrolled text). Reference: loop unrolling and scalar replacement
of aggregates, Muchnick, *Advanced Compiler Design and Implementation* (1997), Sect. 17.4
and 20.3.
"""

from __future__ import annotations

import ast
import itertools
from collections.abc import Callable
from typing import Any, TypeVar, cast

from dirac.codegen.flatten import replace_children, unparse, walk

__all__ = ["scalar_function", "unroll_loops", "scalarise_arrays", "item_loads", "UNROLL_MAX"]

#: the longest literal loop unrolled (the kernels' loops run over the coordinates and
#: constraints of a small system; a longer one is left as a loop)
UNROLL_MAX = 8
#: the most statements one unrolled loop may become (its inner loops already unrolled): a
#: nest of long loops stays a loop rather than growing the function past what pays
UNROLL_STATEMENTS = 512
#: the largest array (elements) replaced by locals
SCALAR_MAX = 64

_Node = TypeVar("_Node", bound=ast.AST)


def _int_constant(node: ast.AST) -> int | None:
    if isinstance(node, ast.Constant) and type(node.value) is int:
        return node.value
    return None


def _fold_binop(node: ast.BinOp) -> ast.AST:
    """``node`` with integer literal operands (already folded) folded: ``+``, ``-``, ``*``."""
    a, b = _int_constant(node.left), _int_constant(node.right)
    if a is None or b is None:
        return node
    if isinstance(node.op, ast.Add):
        return ast.copy_location(ast.Constant(a + b), node)
    if isinstance(node.op, ast.Sub):
        return ast.copy_location(ast.Constant(a - b), node)
    if isinstance(node.op, ast.Mult):
        return ast.copy_location(ast.Constant(a * b), node)
    return node


def _fold_unary(node: ast.UnaryOp) -> ast.AST:
    """``-K`` of an integer literal (already folded) folded."""
    a = _int_constant(node.operand)
    if a is not None and isinstance(node.op, ast.USub):
        return ast.copy_location(ast.Constant(-a), node)
    return node


def _fold_compare(node: ast.Compare) -> ast.AST:
    """One comparison of two integer literals (already folded) folded to ``True``/``False``."""
    a = _int_constant(node.left)
    if a is None or len(node.ops) != 1:
        return node
    b = _int_constant(node.comparators[0])
    if b is None:
        return node
    operations: dict[type, Any] = {ast.Eq: a == b, ast.NotEq: a != b, ast.Lt: a < b, ast.LtE: a <= b,
                                   ast.Gt: a > b, ast.GtE: a >= b}
    value = operations.get(type(node.ops[0]))
    return node if value is None else ast.copy_location(ast.Constant(bool(value)), node)


_FOLD_ONE: dict[type, Callable[[Any], ast.AST]] = {ast.BinOp: _fold_binop, ast.UnaryOp: _fold_unary,
                                                   ast.Compare: _fold_compare}


class _Fold(ast.NodeTransformer):
    """Integer arithmetic and comparisons of integer literals folded; floats never touched."""

    def visit_BinOp(self, node: ast.BinOp) -> ast.AST:
        self.generic_visit(node)
        return _fold_binop(node)

    def visit_UnaryOp(self, node: ast.UnaryOp) -> ast.AST:
        self.generic_visit(node)
        return _fold_unary(node)

    def visit_Compare(self, node: ast.Compare) -> ast.AST:
        self.generic_visit(node)
        return _fold_compare(node)


def _instance(node: _Node, name: str, value: int) -> _Node:
    """A copy of ``node`` with the loads of ``name`` replaced by the literal ``value`` and the
    integer arithmetic on literals folded (bottom up, as :class:`_Fold` folds): the same tree as a
    copy, a substitution and a fold in three passes of :class:`ast.NodeTransformer`, in one pass
    (those passes were most of the unrolling, about half of the 0.13 s :func:`scalar_function`
    took on the RATTLE step of a triple pendulum in angles)."""
    kind = node.__class__
    if kind is ast.Name and node.id == name and node.ctx.__class__ is ast.Load:  # type: ignore[attr-defined]
        constant = ast.Constant(value)
        for attribute in node._attributes:
            if hasattr(node, attribute):
                setattr(constant, attribute, getattr(node, attribute))
        return cast(_Node, constant)
    new = kind()
    for field in node._fields:
        try:
            child = getattr(node, field)
        except AttributeError:
            continue
        if child.__class__ is list:
            child = [_instance(item, name, value) if isinstance(item, ast.AST) else item for item in child]
        elif isinstance(child, ast.AST):
            child = _instance(child, name, value)
        setattr(new, field, child)
    for attribute in node._attributes:
        if hasattr(node, attribute):
            setattr(new, attribute, getattr(node, attribute))
    if kind is ast.BinOp or kind is ast.UnaryOp or kind is ast.Compare:
        return cast(_Node, _FOLD_ONE[kind](new))
    return new


def _fold_tree(node: ast.AST) -> ast.AST:
    """``_Fold().visit(node)``, in place, with :func:`~dirac.codegen.flatten.replace_children`."""
    replace_children(node, _fold_tree)
    fold = _FOLD_ONE.get(node.__class__)
    return fold(node) if fold is not None else node


def _own_jumps(statements: list[ast.stmt]) -> bool:
    """Whether a ``break`` or ``continue`` in ``statements`` belongs to the loop around them."""
    todo: list[ast.AST] = list(statements)
    while todo:
        node = todo.pop()
        if isinstance(node, (ast.Break, ast.Continue)):
            return True
        if isinstance(node, (ast.For, ast.While)):
            todo.extend(node.orelse)  # jumps in a nested loop's body are its own
            continue
        if isinstance(node, (ast.FunctionDef, ast.Lambda)):
            continue
        todo.extend(ast.iter_child_nodes(node))
    return False


def _binds(statements: list[ast.stmt], name: str) -> bool:
    return any(isinstance(sub, ast.Name) and sub.id == name and not isinstance(sub.ctx, ast.Load)
               for node in statements for sub in walk(node))


def _literal_range(loop: ast.For) -> int | None:
    """``K`` of ``for name in range(K)`` with a literal ``K`` in ``[0, UNROLL_MAX]``, else None."""
    call = loop.iter
    if not (isinstance(loop.target, ast.Name) and isinstance(call, ast.Call) and isinstance(call.func, ast.Name)
            and call.func.id == "range" and len(call.args) == 1 and not call.keywords and not loop.orelse):
        return None
    count = _int_constant(call.args[0])
    return count if count is not None and 0 <= count <= UNROLL_MAX else None


def _prune_block(statements: list[ast.stmt]) -> list[ast.stmt]:
    """``if True:``/``if False:`` replaced by the side that runs."""
    out: list[ast.stmt] = []
    for statement in statements:
        if isinstance(statement, ast.If) and isinstance(statement.test, ast.Constant) \
                and isinstance(statement.test.value, bool):
            out.extend(statement.body if statement.test.value else statement.orelse)
        else:
            out.append(statement)
    return out


def _statements(statements: list[ast.stmt]) -> int:
    """The statements in ``statements``, those nested in them included."""
    return sum(isinstance(node, ast.stmt) for s in statements for node in walk(s))


def _unroll_block(statements: list[ast.stmt]) -> list[ast.stmt]:
    out: list[ast.stmt] = []
    for statement in _prune_block(statements):
        for field in ("body", "orelse", "finalbody"):
            inner = getattr(statement, field, None)
            if isinstance(inner, list) and inner and isinstance(inner[0], ast.stmt):
                setattr(statement, field, _unroll_block(inner) or [ast.Pass()])
        if isinstance(statement, ast.Try):
            for handler in statement.handlers:
                handler.body = _unroll_block(handler.body) or [ast.Pass()]
        if isinstance(statement, ast.For):
            count = _literal_range(statement)
            target = statement.target
            if count is not None and isinstance(target, ast.Name) and not _own_jumps(statement.body) \
                    and not _binds(statement.body, target.id) and count * _statements(statement.body) <= UNROLL_STATEMENTS:
                for value in range(count):
                    copies = [_instance(s, target.id, value) for s in statement.body]
                    out.extend(_unroll_block(copies))
                if count:
                    out.append(ast.Assign(targets=[ast.Name(id=target.id, ctx=ast.Store())], value=ast.Constant(count - 1)))
                continue
        out.append(statement)
    return out


def unroll_loops(function: ast.FunctionDef) -> bool:
    """Step 1 of the module docstring, in place; whether a loop was unrolled."""
    loops = sum(isinstance(node, ast.For) for node in walk(function))
    function.body = _unroll_block([cast(ast.stmt, _fold_tree(s)) for s in function.body])
    return sum(isinstance(node, ast.For) for node in walk(function)) != loops


def _allocation(statement: ast.stmt) -> tuple[str, tuple[int, ...], bool] | None:
    """``(name, shape, integer)`` of ``name = np.empty(shape)`` / ``np.zeros(shape)`` with a literal shape."""
    if not (isinstance(statement, ast.Assign) and len(statement.targets) == 1
            and isinstance(statement.targets[0], ast.Name) and isinstance(statement.value, ast.Call)):
        return None
    call = statement.value
    if not (isinstance(call.func, ast.Attribute) and isinstance(call.func.value, ast.Name) and call.func.value.id == "np"
            and call.func.attr in ("empty", "zeros") and len(call.args) == 1):
        return None
    integer = False
    for keyword in call.keywords:
        if keyword.arg != "dtype":
            return None
        dtype = ast.unparse(keyword.value)
        if dtype in ("np.int64", "np.intp", "int"):
            integer = True
        elif dtype not in ("np.float64", "float"):
            return None
    shape_node = _Fold().visit(call.args[0])
    elements = shape_node.elts if isinstance(shape_node, ast.Tuple) else [shape_node]
    shape = tuple(_int_constant(e) for e in elements)
    if any(s is None or s < 1 for s in shape):
        return None
    sizes = tuple(int(s) for s in shape if s is not None)
    total = 1
    for s in sizes:
        total *= s
    return (statement.targets[0].id, sizes, integer) if total <= SCALAR_MAX else None


def _literal_index(node: ast.Subscript, shape: tuple[int, ...]) -> tuple[int, ...] | None:
    index = node.slice
    parts = index.elts if isinstance(index, ast.Tuple) else [index]
    values = tuple(_int_constant(p) for p in parts)
    if len(values) != len(shape) or any(v is None or not 0 <= v < s for v, s in zip(values, shape)):
        return None
    return tuple(int(v) for v in values if v is not None)


def _replace(node: ast.AST, names: dict[str, str]) -> ast.AST:
    """``node`` with every subscript ``x[i, j]`` of an array ``x`` of ``names`` replaced by the
    local ``names[x]_i_j`` (in place)."""
    if isinstance(node, ast.Subscript) and isinstance(node.value, ast.Name) and node.value.id in names:
        index = node.slice.elts if isinstance(node.slice, ast.Tuple) else [node.slice]
        suffix = "_".join(str(_int_constant(i)) for i in index)
        return ast.copy_location(ast.Name(id=f"{names[node.value.id]}_{suffix}", ctx=node.ctx), node)
    replace_children(node, lambda child: _replace(child, names))
    return node


def scalarise_arrays(function: ast.FunctionDef) -> bool:
    """Step 2 of the module docstring, in place; whether any array was replaced."""
    allocations: dict[str, tuple[int, tuple[int, ...], bool]] = {}
    for position, statement in enumerate(function.body):
        found = _allocation(statement)
        if found is not None:
            name, shape, integer = found
            allocations[name] = (-1 if name in allocations else position, shape, integer)
    arguments = {a.arg for a in function.args.args}
    candidates = {name: entry for name, entry in allocations.items() if entry[0] >= 0 and name not in arguments}
    if not candidates:
        return False
    allowed: set[int] = set()  # the Name nodes that are the array of a literal subscript
    stores: dict[str, int] = {}
    uses: list[ast.Name] = []  # the Name nodes of the candidates
    taken = set(arguments)  # every name the function uses
    for node in walk(function):  # one walk of the tree for all three
        if isinstance(node, ast.Subscript) and isinstance(node.value, ast.Name) and node.value.id in candidates:
            if _literal_index(node, candidates[node.value.id][1]) is not None:
                allowed.add(id(node.value))
        elif isinstance(node, ast.Name):
            taken.add(node.id)
            if not isinstance(node.ctx, ast.Load):
                stores[node.id] = stores.get(node.id, 0) + 1
            if node.id in candidates:
                uses.append(node)
    for node in uses:
        if node.id in candidates and id(node) not in allowed:
            if not (isinstance(node.ctx, ast.Store) and stores.get(node.id) == 1):
                candidates.pop(node.id)  # used whole, sliced, indexed by a variable or rebound
    if not candidates:
        return False
    names: dict[str, str] = {}
    for name in candidates:
        prefix = f"_a_{name}"
        while any(t.startswith(prefix) for t in taken):
            prefix += "_"
        names[name] = prefix
    body: list[ast.stmt] = []
    for position, statement in enumerate(function.body):
        entry = next(((n, e) for n, e in candidates.items() if e[0] == position), None)
        if entry is None:
            body.append(statement)
            continue
        name, (_, shape, integer) = entry
        zero = ast.Constant(0 if integer else 0.0)
        for index in itertools.product(*(range(s) for s in shape)):
            target = f"{names[name]}_{'_'.join(map(str, index))}"
            body.append(ast.Assign(targets=[ast.Name(id=target, ctx=ast.Store())], value=zero))
    function.body = [cast(ast.stmt, _replace(statement, names)) for statement in body]
    return True


class _ItemLoads:
    """``a[i, j]`` read from one of ``arrays`` made ``a.item(i, j)`` (in place, with :func:`~dirac.codegen.flatten.replace_children`)."""

    def __init__(self, arrays: set[str]) -> None:
        self.arrays = arrays
        self.changed = False

    def visit(self, node: ast.AST) -> ast.AST:
        replace_children(node, self.visit)
        if not isinstance(node, ast.Subscript):
            return node
        if not (isinstance(node.ctx, ast.Load) and isinstance(node.value, ast.Name) and node.value.id in self.arrays):
            return node
        parts = node.slice.elts if isinstance(node.slice, ast.Tuple) else [node.slice]
        if any(isinstance(part, (ast.Slice, ast.Starred)) for part in parts):
            return node  # a view, not an element
        self.changed = True
        item = ast.Attribute(value=ast.Name(id=node.value.id, ctx=ast.Load()), attr="item", ctx=ast.Load())
        return ast.copy_location(ast.Call(func=item, args=list(parts), keywords=[]), node)


def item_loads(function: ast.FunctionDef) -> bool:
    """Step 3 of the module docstring, in place: ``a[i, j]`` read from an array argument or
    allocation becomes ``a.item(i, j)``."""
    arrays = {a.arg for a in function.args.args}
    arrays |= {found[0] for found in map(_allocation, function.body) if found is not None}
    stored = {node.id for node in walk(function) if isinstance(node, ast.Name) and isinstance(node.ctx, ast.Store)}
    arrays = {name for name in arrays if name not in stored or name in
              {found[0] for found in map(_allocation, function.body) if found is not None}}
    loads = _ItemLoads(arrays)
    function.body = [cast(ast.stmt, loads.visit(statement)) for statement in function.body]
    return loads.changed


def scalar_function(text: str, name: str) -> str | None:
    """``text`` (a module's source, or the part of it that holds function ``name``) with
    function ``name`` rewritten as the module docstring says, or None when nothing changed
    (or the text does not parse)."""
    try:
        tree = ast.parse(text)
    except SyntaxError:
        return None
    function = next((node for node in tree.body if isinstance(node, ast.FunctionDef) and node.name == name), None)
    if function is None:
        return None
    changed = unroll_loops(function)
    changed = scalarise_arrays(function) or changed
    changed = item_loads(function) or changed
    if not changed:
        return None
    return unparse(tree) + "\n"
