"""Helpers of a generated module inlined at the source level: one function per kernel.

A generated kernel module (:mod:`dirac.codegen.kernel_source`) writes every expression
(``mass``, ``force``, ``jacobian``, ...) and every small solve as its own function and
the step loops call them by name. Marked ``@numba.njit(inline="always")``, numba inlined
them at the level of its own IR: it types and lowers the callee again at every call site,
and a RATTLE step loop of a three-coordinate top took 20 s of CPU to compile (4.6 s
without the marks, where each helper is a separately compiled function). Here the same
inlining is done once on the Python source, before numba sees it, where the policy
(:func:`straight`) says it pays: each such call of a marked helper becomes the helper's
body with its locals renamed, so numba types and lowers each kernel and the few helpers
left as functions once (the top's kernel in about 4-5 s), and the interpreter runs the
same text.

The rewriting keeps the floating-point operations and their order (the syntax tree is
spliced, never re-associated), so the interpreted and the compiled tier still give the
same numbers. What it does, for a call of a marked helper ``h(a_1, ..., a_k)``:

* a statement ``h(...)``: replaced by ``h``'s body; an argument that is a plain name
  (and a parameter the body never rebinds) is substituted, any other argument is bound
  once to a fresh local first, as the call would evaluate it once; a bare ``return`` at
  the end is dropped and ``if cond: ...; return`` becomes ``if cond: ... else: <rest>``;
* an expression containing ``h(...)`` where ``h``'s body is statements and one final
  ``return value`` and writes into none of its arguments (a pure helper): the statements
  go before the statement that holds the call, the call becomes ``value``;
* anything else (a ``return`` inside a loop, a call inside ``and``/``or``, a ``while``
  test, a name clash): the call is left as it is, and the helper is compiled as a
  separate numba function, without the inlining mark.

Then every function is tidied (:func:`tidy_function`), since numba types and lowers
every statement it is given, dead or repeated: a branch whose test compares constants
(``if 0 > 0:`` of a system without constraints) keeps only the side that runs, a loop
``for a in range(0):`` goes, and the loads ``x = c[k]`` of a read-only argument ``c``
(written by no function of the module), one per inlined instance of a helper, become one
load per index at the top of the function. In the RATTLE kernel of a top in Euler angles
these were a third of the statements.

Reference: the inline expansion of a compiler (Aho, Lam, Sethi & Ullman, *Compilers*,
2nd ed., Sect. 12.1.3); numba's ``inline`` option and its cost: numba documentation,
"Notes on Inlining".
"""

from __future__ import annotations

import ast
import itertools
import re
from collections.abc import Callable, Iterator
from typing import Any, TypeVar, cast

__all__ = ["flatten_source", "unparse", "straight", "tidy_function", "specialise_solves", "specialised_function", "function_text", "walk", "replace_children", "copy_tree", "INLINE_MARK",
           "SEPARATE", "SMALL"]

#: the decorator generated modules put on a helper to be inlined
INLINE_MARK = '@numba.njit(cache=True, inline="always")'

_PLAIN = ast.parse("@numba.njit(cache=True)\ndef f():\n    pass").body[0].decorator_list[0]  # type: ignore[attr-defined]


def walk(node: ast.AST) -> Iterator[ast.AST]:
    """Every node of the tree under ``node`` (itself included), as :func:`ast.walk` yields
    them but depth first and about twice as fast (no generator per node: a fresh process
    flattens a module of a few hundred lines in a tenth of a second, most of it walking)."""
    stack = [node]
    pop, push = stack.pop, stack.append
    while stack:
        current = pop()
        yield current
        for name in current._fields:
            value = getattr(current, name, None)
            if value.__class__ is list:
                for item in value:
                    if isinstance(item, ast.AST):
                        push(item)
            elif isinstance(value, ast.AST):
                push(value)


def replace_children(node: ast.AST, visit: Callable[[Any], ast.AST]) -> None:
    """Each child node of ``node`` replaced, in place, by ``visit(child)``: what
    :meth:`ast.NodeTransformer.generic_visit` does for visitors that always return a node,
    several times faster (no ``iter_fields`` generator, no new lists)."""
    for field in node._fields:
        value = getattr(node, field, None)
        if value.__class__ is list:
            for position, item in enumerate(value):
                if isinstance(item, ast.AST):
                    value[position] = visit(item)
        elif isinstance(value, ast.AST):
            setattr(node, field, visit(value))


def unparse(tree: ast.AST) -> str:
    """``ast.unparse(tree)`` of a rewritten tree whose new statements may lack line numbers.

    The unparser reads the ``lineno`` of the statements that can carry a type comment (a
    ``def``, an assignment, a ``for``, a ``with``) and nothing else of the locations, so only
    statements get one (0) where it is missing; :func:`ast.fix_missing_locations` visits every
    node of the expressions too, a sixth of :func:`flatten_source` (the modules of the double
    pendulums, CPU, median of 10 alternated pairs: 0.85 times the time without it). The text
    is the same."""
    stack = [tree]
    while stack:
        node = stack.pop()
        for name in ("body", "orelse", "finalbody", "handlers"):
            children = getattr(node, name, None)
            if children.__class__ is list:
                for child in children:
                    if isinstance(child, (ast.stmt, ast.excepthandler)):
                        if not hasattr(child, "lineno"):
                            child.lineno = 0
                        stack.append(child)
    return ast.unparse(tree)


def _is_marked(function: ast.FunctionDef) -> bool:
    for decorator in function.decorator_list:
        if isinstance(decorator, ast.Call) and any(
                k.arg == "inline" and isinstance(k.value, ast.Constant) and k.value.value == "always"
                for k in decorator.keywords):
            return True
    return False


def _stored_names(nodes: list[ast.stmt]) -> set[str]:
    names: set[str] = set()
    for node in nodes:
        for sub in walk(node):
            if isinstance(sub, ast.Name) and isinstance(sub.ctx, (ast.Store, ast.Del)):
                names.add(sub.id)
    return names


def _loaded_names(nodes: list[ast.stmt]) -> set[str]:
    return {sub.id for node in nodes for sub in walk(node) if isinstance(sub, ast.Name)}


def _has_return(nodes: list[ast.stmt]) -> bool:
    return any(isinstance(sub, ast.Return) for node in nodes for sub in walk(node))


def _without_docstring(body: list[ast.stmt]) -> list[ast.stmt]:
    if body and isinstance(body[0], ast.Expr) and isinstance(body[0].value, ast.Constant) \
            and isinstance(body[0].value.value, str):
        return body[1:]
    return body


def _restructure(statements: list[ast.stmt]) -> list[ast.stmt] | None:
    """``statements`` without bare returns (the code after ``if c: ...; return`` moved into
    the ``else``), or None when a return sits where that cannot be done (in a loop, with a value)."""
    out: list[ast.stmt] = []
    for index, statement in enumerate(statements):
        if isinstance(statement, ast.Return):
            return out if statement.value is None else None
        if isinstance(statement, ast.If) and _has_return([statement]):
            body = statement.body
            if not (isinstance(body[-1], ast.Return) and body[-1].value is None) or _has_return(body[:-1]) \
                    or _has_return(statement.orelse):
                return None
            rest = _restructure(list(statement.orelse) + statements[index + 1:])
            if rest is None:
                return None
            then = body[:-1] or [ast.Pass()]
            out.append(ast.If(test=statement.test, body=then, orelse=rest))
            return out
        if _has_return([statement]):
            return None
        out.append(statement)
    return out


class _Helper:
    """A marked helper: its parameters, its body without returns (statement form) and, for a
    pure helper ending in ``return value``, its statements and that value (expression form)."""

    def __init__(self, function: ast.FunctionDef) -> None:
        self.name = function.name
        args = function.args
        self.simple = not (args.vararg or args.kwarg or args.kwonlyargs or args.defaults or args.posonlyargs)
        self.parameters = [a.arg for a in args.args]
        self.body = _without_docstring(list(function.body))
        self.statements = _restructure(self.body)
        self.value: tuple[list[ast.stmt], ast.expr] | None = None
        # one walk of the body for what five took (a fresh process flattened a triple pendulum's
        # kernels in about 0.15 s, most of it walking trees)
        writes: set[str] = set()  # arrays written through a subscript
        stored: set[str] = set()
        named: set[str] = set()
        self.loops = False
        self.size = 0  # statements, nested ones included
        for node in self.body:
            for sub in walk(node):
                kind = sub.__class__
                if kind is ast.Name:
                    named.add(sub.id)  # type: ignore[attr-defined]
                    if isinstance(sub.ctx, (ast.Store, ast.Del)):  # type: ignore[attr-defined]
                        stored.add(sub.id)  # type: ignore[attr-defined]
                elif kind is ast.Subscript:
                    if isinstance(sub.ctx, ast.Store) and isinstance(sub.value, ast.Name):  # type: ignore[attr-defined]
                        writes.add(sub.value.id)  # type: ignore[attr-defined]
                elif kind is ast.For or kind is ast.While:
                    self.loops = True
                if isinstance(sub, ast.stmt):
                    self.size += 1
        last = self.body[-1] if self.body else None
        if isinstance(last, ast.Return) and last.value is not None and not _has_return(self.body[:-1]):
            if not writes & set(self.parameters):
                self.value = (self.body[:-1], last.value)
        self.stored = stored
        self.locals = self.stored | set(self.parameters)
        self.globals = named - self.locals


_T = TypeVar("_T")


def _copy(node: _T) -> _T:
    """A copy of a syntax tree (what :func:`copy.deepcopy` gives, several times faster: the
    fields of a node are nodes, lists of them, or immutable values)."""
    if isinstance(node, ast.AST):
        new = node.__class__()
        for name in node._fields:  # what ast.iter_fields yields, without its generator
            try:
                value = getattr(node, name)
            except AttributeError:
                continue
            setattr(new, name, _copy(value))
        for name in node._attributes:
            if hasattr(node, name):
                setattr(new, name, getattr(node, name))
        return cast(_T, new)
    if isinstance(node, list):
        return cast(_T, [_copy(item) for item in node])
    return node


#: a copy of a syntax tree (for other rewritings of generated source)
copy_tree = _copy


def _renamed(node: ast.Name, names: dict[str, ast.expr]) -> ast.expr:
    """The name ``node`` as :func:`_rename` replaces it: itself when ``names`` has no entry."""
    replacement = names.get(node.id)
    if replacement is None:
        return node
    if isinstance(replacement, ast.Name):
        return ast.copy_location(ast.Name(id=replacement.id, ctx=node.ctx), node)
    return _copy(replacement)


def _rename(node: ast.AST, names: dict[str, ast.expr]) -> ast.AST:
    """``node`` with each name of ``names`` replaced (a name by a name in the same context, any
    other expression by a copy of it), in place (:func:`replace_children`, several times faster
    than an :class:`ast.NodeTransformer`)."""
    if node.__class__ is ast.Name:
        return _renamed(cast(ast.Name, node), names)
    replace_children(node, lambda child: _rename(child, names))
    return node


def _renamed_copy(node: _T, names: dict[str, ast.expr]) -> _T:
    """``_rename(_copy(node), names)`` in one pass: a statement of an inlined function, copied."""
    if isinstance(node, ast.AST):
        if node.__class__ is ast.Name:
            replaced = _renamed(cast(ast.Name, node), names)
            return cast(_T, _copy(node) if replaced is node else replaced)
        new = node.__class__()
        for name in node._fields:
            try:
                value = getattr(node, name)
            except AttributeError:
                continue
            setattr(new, name, _renamed_copy(value, names))
        for name in node._attributes:
            if hasattr(node, name):
                setattr(new, name, getattr(node, name))
        return cast(_T, new)
    if isinstance(node, list):
        return cast(_T, [_renamed_copy(item, names) for item in node])
    return node


class _Flattener:
    def __init__(self, tree: ast.Module, policy: Callable[[_Helper], bool]) -> None:
        self.functions = {node.name: node for node in tree.body if isinstance(node, ast.FunctionDef)}
        self.helpers = {name: _Helper(node) for name, node in self.functions.items() if _is_marked(node)}
        self.policy = policy
        self.counter = itertools.count()
        self.done: set[str] = set()
        self.active: set[str] = set()

    # -------------------------------------------------------------- one instance of a helper
    def _instance(self, helper: _Helper, call: ast.Call, caller_names: set[str],
                  body: list[ast.stmt]) -> tuple[list[ast.stmt], dict[str, ast.expr]] | None:
        if not self.policy(helper) or not helper.simple or call.keywords or len(call.args) != len(helper.parameters) \
                or any(isinstance(a, ast.Starred) for a in call.args) or helper.globals & caller_names:
            return None
        tag = f"_i{next(self.counter)}_"
        names: dict[str, ast.expr] = {}
        prelude: list[ast.stmt] = []
        for parameter, argument in zip(helper.parameters, call.args):
            if isinstance(argument, ast.Name) and parameter not in helper.stored:
                names[parameter] = argument
            elif isinstance(argument, ast.Constant) and parameter not in helper.stored:
                names[parameter] = argument
            else:
                local = tag + parameter
                prelude.append(ast.Assign(targets=[ast.Name(id=local, ctx=ast.Store())], value=argument, lineno=0))
                names[parameter] = ast.Name(id=local, ctx=ast.Load())
        for local in helper.stored - set(names):
            names[local] = ast.Name(id=tag + local, ctx=ast.Load())
        return prelude + [_renamed_copy(s, names) for s in body], names

    # -------------------------------------------------------------- expressions
    def _expression_calls(self, node: ast.AST) -> Iterator[ast.Call]:
        """Calls of pure helpers in ``node``, not under ``and``/``or``/``if-else``/lambdas."""
        if isinstance(node, (ast.BoolOp, ast.IfExp, ast.Lambda, ast.ListComp, ast.SetComp, ast.DictComp,
                             ast.GeneratorExp)):
            return
        for child in ast.iter_child_nodes(node):
            yield from self._expression_calls(child)
        if isinstance(node, ast.Call) and isinstance(node.func, ast.Name) and node.func.id in self.helpers:
            yield node

    def _inline_expressions(self, statement: ast.stmt, fields: list[str], caller_names: set[str]) -> list[ast.stmt]:
        prelude: list[ast.stmt] = []
        replacements: dict[int, ast.expr] = {}
        for name in fields:
            value = getattr(statement, name, None)
            parts = value if isinstance(value, list) else [value]
            for part in parts:
                if part is None:
                    continue
                for call in list(self._expression_calls(part)):
                    self._flatten_helper(call.func.id)  # type: ignore[attr-defined]
                    helper = self.helpers[call.func.id]  # type: ignore[attr-defined]
                    if helper.value is None or any(id(a) in replacements for a in walk(call) if a is not call):
                        continue
                    statements, result = helper.value
                    instance = self._instance(helper, call, caller_names, [*statements, ast.Expr(value=result)])
                    if instance is None:
                        continue
                    body, _ = instance
                    last = body.pop()
                    assert isinstance(last, ast.Expr)
                    prelude.extend(body)
                    replacements[id(call)] = last.value

        def swap(node: ast.AST) -> ast.AST:  # in place, bottom up: each call replaced by its value
            replace_children(node, swap)
            return replacements.get(id(node), node) if node.__class__ is ast.Call else node

        if not replacements:
            return [statement]
        swapped = swap(statement)
        return [*prelude, cast(ast.stmt, swapped)]

    # -------------------------------------------------------------- statements
    def _block(self, statements: list[ast.stmt], caller_names: set[str]) -> list[ast.stmt]:
        out: list[ast.stmt] = []
        for statement in statements:
            for name in ("body", "orelse", "finalbody"):
                inner = getattr(statement, name, None)
                if isinstance(inner, list) and inner and isinstance(inner[0], ast.stmt):
                    setattr(statement, name, self._block(inner, caller_names))
            if isinstance(statement, ast.Expr) and isinstance(statement.value, ast.Call) \
                    and isinstance(statement.value.func, ast.Name) and statement.value.func.id in self.helpers:
                self._flatten_helper(statement.value.func.id)
                helper = self.helpers[statement.value.func.id]
                if helper.statements is not None:
                    instance = self._instance(helper, statement.value, caller_names, helper.statements)
                    if instance is not None:
                        inlined, _ = instance
                        out.extend(inlined or [ast.Pass()])
                        continue
                out.append(statement)
                continue
            fields = {ast.Assign: ["targets", "value"], ast.AugAssign: ["target", "value"], ast.Return: ["value"],
                      ast.Expr: ["value"], ast.If: ["test"], ast.For: ["iter"], ast.AnnAssign: ["value"]}
            out.extend(self._inline_expressions(statement, fields.get(type(statement), []), caller_names))
        return out

    def _flatten_function(self, function: ast.FunctionDef) -> None:
        names = _stored_names(function.body) | {a.arg for a in function.args.args}
        function.body = self._block(function.body, names)

    def _flatten_helper(self, name: str) -> None:
        """Inline into helper ``name`` the helpers it calls (once), and refresh its forms."""
        if name in self.done or name in self.active:
            return
        self.active.add(name)
        function = self.functions[name]
        written = self.helpers[name].size
        self._flatten_function(function)
        self.helpers[name] = _Helper(function)
        self.helpers[name].size = written  # the policy judges a helper as written, not with its callees inlined
        self.active.discard(name)
        self.done.add(name)

    def run(self) -> None:
        # a helper is flattened when first inlined; one nobody calls stays as written
        for name, function in self.functions.items():
            if name not in self.helpers:
                self._flatten_function(function)
        for name in self.helpers:
            self.functions[name].decorator_list = [_copy(_PLAIN)]


#: helpers with loops kept as functions of their own: the dense LU (its loops over a matrix
#: are most of a kernel's basic blocks, and it is called at many places)
SEPARATE = frozenset({"lu_factor", "lu_solve"})
#: statements (as written) of a helper with loops that is still inlined
SMALL = 40


def straight(helper: _Helper) -> bool:
    """The default policy: inline the helpers without loops (expressions, closed-form
    solves, the bookkeeping of ``info``) and those with loops up to :data:`SMALL`
    statements (a norm, ``v = M^-1 p``, RATTLE's stage residual and closing projection),
    but not the LU of :data:`SEPARATE`. Measured on the RATTLE kernel of a top in Euler
    angles (CPU, 2 cores under load): inlining every helper multiplies the basic blocks
    that numba's reaching-definitions analysis walks (its cost grows with blocks times
    variables) and the compilation took 17 s; inlining only the loop-free ones compiles
    in about 4 s but a step costs 1.6 times numba's own inlining (every call passes a dozen
    arrays); this policy compiles in about 5 s and a step costs about half of it (2.0 us
    against 3.2-3.9 us)."""
    return not helper.loops or (helper.size <= SMALL and helper.name not in SEPARATE)


def _constant_test(test: ast.expr) -> bool | None:
    """The value of an ``if`` test comparing literal numbers (``0 > 0``), else None."""
    if not (isinstance(test, ast.Compare) and isinstance(test.left, ast.Constant)
            and all(isinstance(c, ast.Constant) for c in test.comparators)):
        return None
    values = [test.left.value, *(c.value for c in test.comparators)]  # type: ignore[attr-defined]
    if not all(isinstance(v, (int, float)) and not isinstance(v, bool) for v in values):
        return None
    compare = {ast.Gt: lambda a, b: a > b, ast.GtE: lambda a, b: a >= b, ast.Lt: lambda a, b: a < b,
               ast.LtE: lambda a, b: a <= b, ast.Eq: lambda a, b: a == b, ast.NotEq: lambda a, b: a != b}
    result = True
    for op, left, right in zip(test.ops, values, values[1:]):
        if type(op) not in compare:
            return None
        result = result and bool(compare[type(op)](left, right))
    return result


def _empty_loop(statement: ast.stmt) -> bool:
    """``for x in range(0):`` (a loop over the constraints of a system without any)."""
    return (isinstance(statement, ast.For) and isinstance(statement.iter, ast.Call)
            and isinstance(statement.iter.func, ast.Name) and statement.iter.func.id == "range"
            and len(statement.iter.args) == 1 and isinstance(statement.iter.args[0], ast.Constant)
            and statement.iter.args[0].value == 0 and not statement.orelse)


def _prune(statements: list[ast.stmt]) -> list[ast.stmt]:
    """``statements`` without the code that never runs (constant tests, empty loops)."""
    out: list[ast.stmt] = []
    for statement in statements:
        if isinstance(statement, ast.If):
            value = _constant_test(statement.test)
            if value is not None:
                out.extend(_prune(statement.body if value else statement.orelse))
                continue
        if _empty_loop(statement):
            continue
        for name in ("body", "orelse", "finalbody"):
            inner = getattr(statement, name, None)
            if isinstance(inner, list) and inner and isinstance(inner[0], ast.stmt):
                setattr(statement, name, _prune(inner) or [ast.Pass()])
        out.append(statement)
    return out


def _fold_constant_choice(node: ast.AST) -> ast.AST:
    """``a if True else b`` -> ``a`` (``if False``: ``b``), in place and bottom up: the choice
    of an inlined helper on a literal argument (``report(info, step, True, ...)``): numba makes
    three blocks of each conditional expression; the value is the one the test picks."""
    replace_children(node, _fold_constant_choice)
    if isinstance(node, ast.IfExp) and isinstance(node.test, ast.Constant) and isinstance(node.test.value, bool):
        return node.body if node.test.value else node.orelse
    return node


def _written_arrays(tree: ast.Module) -> set[str]:
    """Names written through a subscript (``a[...] = ``, ``a[...] += ``) anywhere in the module."""
    return {node.value.id for node in walk(tree) if isinstance(node, ast.Subscript)
            and isinstance(node.ctx, (ast.Store, ast.Del)) and isinstance(node.value, ast.Name)}


def tidy_function(function: ast.FunctionDef, written: set[str]) -> None:
    """Remove the code of ``function`` that never runs or whose value nobody reads (a load
    ``x = a[k]`` of an inlined helper's unused input, an allocation nobody uses) and load each entry ``c[k]`` of a
    read-only argument once (see the module docstring); ``written`` are the names the
    module writes through a subscript (such an argument's entries are loaded where they are).

    The values are the same: a branch left out could not run (nor the side of a conditional
    expression whose test is a literal ``True`` or ``False``), a load nobody reads changes
    nothing, and an entry of an argument no function writes cannot change while the function runs. A name assigned such a load is
    replaced only when it is assigned nowhere else in the function."""
    function.body = _prune(function.body) or [ast.Pass()]
    _fold_constant_choice(function)
    used = {node.id for node in walk(function) if isinstance(node, ast.Name) and isinstance(node.ctx, ast.Load)}

    def unused_load(statement: ast.stmt) -> bool:  # ``x = a[k]`` or ``x = np.empty(...)``, x never read
        if not (isinstance(statement, ast.Assign) and len(statement.targets) == 1
                and isinstance(statement.targets[0], ast.Name) and statement.targets[0].id not in used):
            return False
        value = statement.value
        if isinstance(value, ast.Call):  # an allocation nobody uses (the work arrays of absent constraints)
            return (isinstance(value.func, ast.Attribute) and isinstance(value.func.value, ast.Name)
                    and value.func.value.id == "np" and value.func.attr in ("empty", "zeros")
                    and all(isinstance(n, (ast.Constant, ast.Tuple, ast.Attribute, ast.Name, ast.keyword))
                            for a in [*value.args, *value.keywords] for n in [a]))
        return (isinstance(value, ast.Subscript) and isinstance(value.value, ast.Name)
                and isinstance(value.slice, ast.Constant) and type(value.slice.value) is int and value.slice.value >= 0)

    def drop(statements: list[ast.stmt]) -> list[ast.stmt]:
        out = []
        for statement in statements:
            if unused_load(statement):
                continue
            for field in ("body", "orelse", "finalbody"):
                inner = getattr(statement, field, None)
                if isinstance(inner, list) and inner and isinstance(inner[0], ast.stmt):
                    setattr(statement, field, drop(inner) or [ast.Pass()])
            out.append(statement)
        return out

    function.body = drop(function.body) or [ast.Pass()]
    parameters = {a.arg for a in function.args.args}
    stores: dict[str, int] = {}
    named: set[str] = set()  # every name of the body (one walk for both)
    for statement in function.body:  # the decorators and the arguments hold no stored Name
        for node in walk(statement):
            if node.__class__ is ast.Name:
                named.add(node.id)  # type: ignore[attr-defined]
                if isinstance(node.ctx, (ast.Store, ast.Del)):  # type: ignore[attr-defined]
                    stores[node.id] = stores.get(node.id, 0) + 1  # type: ignore[attr-defined]
    constant = {p for p in parameters if p not in written and p not in stores}
    if not constant:
        return
    taken = named | set(stores) | parameters
    loads: dict[tuple[str, int], str] = {}
    alias: dict[str, str] = {}

    def is_load(statement: ast.stmt) -> bool:
        return (isinstance(statement, ast.Assign) and len(statement.targets) == 1
                and isinstance(statement.targets[0], ast.Name) and stores.get(statement.targets[0].id) == 1
                and isinstance(statement.value, ast.Subscript) and isinstance(statement.value.value, ast.Name)
                and statement.value.value.id in constant and isinstance(statement.value.slice, ast.Constant)
                and type(statement.value.slice.value) is int and statement.value.slice.value >= 0)

    def hoist(statements: list[ast.stmt]) -> list[ast.stmt]:
        out: list[ast.stmt] = []
        for statement in statements:
            if is_load(statement):
                value = statement.value  # type: ignore[attr-defined]
                key = (value.value.id, value.slice.value)
                if key not in loads:
                    name = f"_{key[0]}{key[1]}_"
                    while name in taken:
                        name = "_" + name
                    taken.add(name)
                    loads[key] = name
                alias[statement.targets[0].id] = loads[key]  # type: ignore[attr-defined]
                continue
            for field in ("body", "orelse", "finalbody"):
                inner = getattr(statement, field, None)
                if isinstance(inner, list) and inner and isinstance(inner[0], ast.stmt):
                    setattr(statement, field, hoist(inner) or [ast.Pass()])
            out.append(statement)
        return out

    docstring = function.body[:1] if _without_docstring(function.body) is not function.body else []
    body = hoist(function.body[len(docstring):])
    if not loads:
        return
    names: dict[str, ast.expr] = {old: ast.Name(id=new, ctx=ast.Load()) for old, new in alias.items()}
    renamed = [cast(ast.stmt, _rename(s, names)) for s in body]
    head = [ast.Assign(targets=[ast.Name(id=name, ctx=ast.Store())],
                       value=ast.Subscript(value=ast.Name(id=array, ctx=ast.Load()), slice=ast.Constant(value=index),
                                           ctx=ast.Load()), lineno=0)
            for (array, index), name in sorted(loads.items())]
    function.body = [*docstring, *head, *renamed]


def _without_cfunc_wrapper(function: ast.FunctionDef) -> None:
    """``@numba.njit(..., no_cfunc_wrapper=True)``: numba compiles, next to each function and
    its CPython wrapper, a C-callable wrapper for first-class function values (a dispatcher
    passed as an argument to jitted code), which no generated kernel uses; leaving it out
    took about 10 % off the compilation of a RATTLE kernel (paired runs, docs/performance.md).
    It changes no machine code of the function itself, hence no number."""
    for decorator in function.decorator_list:
        if isinstance(decorator, ast.Call) and isinstance(decorator.func, ast.Attribute) \
                and isinstance(decorator.func.value, ast.Name) and decorator.func.value.id == "numba" \
                and decorator.func.attr == "njit" and not any(k.arg == "no_cfunc_wrapper" for k in decorator.keywords):
            decorator.keywords.append(ast.keyword(arg="no_cfunc_wrapper", value=ast.Constant(value=True)))


def flatten_source(source: str, policy: Callable[[_Helper], bool] = straight) -> str:
    """``source`` with every call of a helper marked ``inline="always"`` replaced by the
    helper's body where ``policy`` says so (see the module docstring); every helper stays,
    as a plain ``@numba.njit`` function without the mark, for the calls left and for direct
    calls; every ``njit`` function is compiled without numba's C-callable wrapper
    (:func:`_without_cfunc_wrapper`). A source without marks is returned unchanged."""
    if 'inline="always"' not in source and "inline='always'" not in source:
        return source
    tree = ast.parse(source)
    _Flattener(tree, policy).run()
    written = _written_arrays(tree)
    for node in tree.body:
        if isinstance(node, ast.FunctionDef):
            tidy_function(node, written)
            _without_cfunc_wrapper(node)
    return unparse(tree) + "\n"


def _literal_int(node: ast.AST | None) -> int | None:
    """An integer literal, or sums, differences and products of them (``2 * 2``), else None."""
    if isinstance(node, ast.Constant) and type(node.value) is int:
        return node.value
    if isinstance(node, ast.BinOp) and isinstance(node.op, (ast.Add, ast.Sub, ast.Mult)):
        left, right = _literal_int(node.left), _literal_int(node.right)
        if left is None or right is None:
            return None
        return left + right if isinstance(node.op, ast.Add) else left - right if isinstance(node.op, ast.Sub) \
            else left * right
    return None


def _matrix_allocations(function: ast.FunctionDef) -> dict[str, tuple[int, int]]:
    """Names that ``function`` binds once, to ``np.empty((r, c))`` or ``np.zeros((r, c))`` with
    literal ``r`` and ``c`` (``2 * 2`` counts as literal): their shapes."""
    stores: dict[str, int] = {}
    for node in walk(function):
        if isinstance(node, ast.Name) and isinstance(node.ctx, (ast.Store, ast.Del)):
            stores[node.id] = stores.get(node.id, 0) + 1
    for argument in function.args.args:
        stores[argument.arg] = stores.get(argument.arg, 0) + 1
    shapes: dict[str, tuple[int, int]] = {}
    for node in walk(function):
        if not (isinstance(node, ast.Assign) and len(node.targets) == 1 and isinstance(node.targets[0], ast.Name)
                and stores.get(node.targets[0].id) == 1 and isinstance(node.value, ast.Call)):
            continue
        call = node.value
        if not (isinstance(call.func, ast.Attribute) and isinstance(call.func.value, ast.Name)
                and call.func.value.id == "np" and call.func.attr in ("empty", "zeros") and len(call.args) == 1
                and not call.keywords and isinstance(call.args[0], ast.Tuple) and len(call.args[0].elts) == 2):
            continue
        rows, columns = (_literal_int(e) for e in call.args[0].elts)
        if rows is not None and columns is not None and rows >= 1 and columns >= 1:
            shapes[node.targets[0].id] = (rows, columns)
    return shapes


def _square_size(argument: ast.expr, shapes: dict[str, tuple[int, int]]) -> int:
    """The size ``k`` of a square matrix argument: a name allocated ``(k, k)``, or a slice
    ``A[lo:hi]`` of literal bounds of a name allocated ``(r, k)`` with ``hi - lo = k`` (the
    blocks of one allocation, ``J[:2]`` and ``J[2:]`` of a ``(4, 2)``); 0 otherwise."""
    if isinstance(argument, ast.Name) and argument.id in shapes:
        rows, columns = shapes[argument.id]
        return rows if rows == columns else 0
    if isinstance(argument, ast.Subscript) and isinstance(argument.value, ast.Name) and argument.value.id in shapes \
            and isinstance(argument.slice, ast.Slice) and argument.slice.step is None:
        rows, columns = shapes[argument.value.id]
        low = 0 if argument.slice.lower is None else _literal_int(argument.slice.lower)
        high = rows if argument.slice.upper is None else _literal_int(argument.slice.upper)
        if low is not None and high is not None and 0 <= low < high <= rows and high - low == columns:
            return columns
    return 0


def specialise_solves(source: str, max_size: int | None = None) -> str:
    """``source`` for the interpreted tier: each call ``lu_factor(A, piv)`` / ``lu_solve(A, piv, b)``
    on a matrix ``A`` that its function allocates once as ``np.empty((k, k))``, or on a block
    ``J[lo:hi]`` of literal bounds of a ``np.empty((r, k))`` with ``hi - lo = k`` (the two
    Newton matrices of the unconstrained RATTLE loop), (a literal
    ``k`` from 1 to ``max_size``, default
    :data:`~dirac.codegen.small_solves.UNROLLED_MAX_SIZE`) calls the straight-line
    ``lu_factor_<k>`` / ``lu_solve_<k>`` of :func:`~dirac.codegen.small_solves.unrolled_lu_source`
    instead, appended to the module.

    The unrolled forms make the same floating-point operations in the same order as the
    loops (bit for bit the same results), so the interpreted tier still gives the numbers of
    the compiled one, which keeps the loops (numba compiles them faster). A source without
    such calls is returned unchanged. Run it on a flattened source
    (:func:`flatten_source`), where the helpers that pass the matrix on are inlined.
    """
    from dirac.codegen.small_solves import UNROLLED_MAX_SIZE, unrolled_lu_source

    limit = UNROLLED_MAX_SIZE if max_size is None else max_size
    if "lu_factor(" not in source and "lu_solve(" not in source:
        return source
    tree = ast.parse(source)
    defined = {node.name for node in tree.body if isinstance(node, ast.FunctionDef)}
    if not {"lu_factor", "lu_solve"} <= defined:
        return source
    used: set[int] = set()
    for function in tree.body:
        if not isinstance(function, ast.FunctionDef) or function.name in ("lu_factor", "lu_solve"):
            continue
        shapes = _matrix_allocations(function)
        if not shapes:
            continue
        for node in walk(function):
            if isinstance(node, ast.Call) and isinstance(node.func, ast.Name) \
                    and node.func.id in ("lu_factor", "lu_solve") and node.args \
                    and 1 <= _square_size(node.args[0], shapes) <= limit:
                size = _square_size(node.args[0], shapes)
                name = f"{node.func.id}_{size}"
                if name in defined:  # the module has a function of that name already: leave the call
                    continue
                node.func = ast.Name(id=name, ctx=ast.Load())
                used.add(size)
        _float_pivots(function)
    if not used:
        return source
    return unparse(tree) + "\n" + "".join(unrolled_lu_source(size) for size in sorted(used))


def _float_pivots(function: ast.FunctionDef) -> None:
    """Pivot arrays that only unrolled solves use, allocated as float64 instead of int64.

    The unrolled ``lu_factor_<k>`` stores each row exchange and ``lu_solve_<k>`` compares it
    with integer literals, never indexes with it (:func:`~dirac.codegen.small_solves.unrolled_lu_source`):
    an exchange held as a double compares the same, and a loop without integer arrays runs
    on the tape machine (whose memory is float64), as the RATTLE loops' pivots do. A name
    bound once by ``np.empty(k, dtype=np.int64)`` whose every other use is the second argument
    of such a call loses its ``dtype``.
    """
    unrolled = re.compile(r"lu_(factor|solve)_[0-9]+$")
    uses: dict[str, int] = {}
    as_pivot: dict[str, int] = {}
    allocations: dict[str, ast.Call] = {}
    for node in walk(function):
        if isinstance(node, ast.Name):
            uses[node.id] = uses.get(node.id, 0) + 1
        if isinstance(node, ast.Call) and isinstance(node.func, ast.Name) and unrolled.match(node.func.id) \
                and len(node.args) >= 2 and isinstance(node.args[1], ast.Name):
            as_pivot[node.args[1].id] = as_pivot.get(node.args[1].id, 0) + 1
        if isinstance(node, ast.Assign) and len(node.targets) == 1 and isinstance(node.targets[0], ast.Name) \
                and isinstance(node.value, ast.Call) and ast.unparse(node.value.func) == "np.empty" \
                and len(node.value.args) == 1 and [ast.unparse(k) for k in node.value.keywords] == ["dtype=np.int64"]:
            allocations[node.targets[0].id] = node.value
    for name, call in allocations.items():
        if name in as_pivot and uses.get(name) == as_pivot[name] + 1:
            call.keywords = []


def function_text(source: str, name: str) -> str | None:
    """The text of the top-level ``def name(...)`` of ``source`` (up to the next line that
    starts in the first column), or None."""
    start = source.find(f"\ndef {name}(")
    if start < 0:
        return None
    lines = source[start + 1:].split("\n")
    end = 1
    while end < len(lines) and (not lines[end] or lines[end][0] in " \t"):
        end += 1
    return "\n".join(lines[:end]) + "\n"


def specialised_function(source: str, name: str, max_size: int | None = None) -> str | None:
    """The source of function ``name`` of ``source`` with the helpers it hands a tuple of work
    arrays inlined (:func:`inline_worked_helpers`) and its solves of literal size
    unrolled, followed by the unrolled solves it calls (:func:`specialise_solves` of that
    one function), or None when it has neither. Only this function is parsed: the interpreted
    tier specialises the functions it runs, when it first runs them, and a module whose
    loops never solve with a fixed matrix (a constant mass) pays nothing."""
    text = function_text(source, name)
    if text is None:
        return None
    inlined = inline_worked_helpers(source, text)
    if inlined is not None:
        text = inlined
    if ("lu_factor(" not in text and "lu_solve(" not in text) or "np.empty((" not in text \
            and "np.zeros((" not in text:
        return inlined
    helpers = "".join(t for t in (function_text(source, "lu_factor"), function_text(source, "lu_solve")) if t)
    specialised = specialise_solves(helpers + text, max_size)
    if specialised == helpers + text:
        return None
    tree = ast.parse(specialised)
    tree.body = [node for node in tree.body if not (isinstance(node, ast.FunctionDef)
                                                     and node.name in ("lu_factor", "lu_solve"))]
    # the unrolled solves inlined where they are called: a step loop without calls runs on
    # the tape machine (which translates no calls); the same statements in the same order
    text = ast.unparse(tree) + "\n"
    marked = re.sub(r"@numba\.njit\(cache=True\)\ndef (lu_(?:factor|solve)_[0-9]+)\(",
                    r'@numba.njit(cache=True, inline="always")\ndef \1(', text)
    return flatten_source(marked) if marked != text else text


def _allocations(function: ast.FunctionDef) -> list[ast.expr] | None:
    """The arrays a work function ``def f(): return (np.empty(...), ...)`` (or ``return
    np.empty(...)``) allocates, in order (one for a single array), or None for any other function."""
    body = _without_docstring(list(function.body))
    if function.args.args or len(body) != 1 or not isinstance(body[0], ast.Return) or body[0].value is None:
        return None
    value = body[0].value
    parts = list(value.elts) if isinstance(value, ast.Tuple) else [value]
    for part in parts:
        if not (isinstance(part, ast.Call) and isinstance(part.func, ast.Attribute)
                and isinstance(part.func.value, ast.Name) and part.func.value.id == "np"
                and part.func.attr in ("empty", "zeros")):
            return None
    return parts


def _returns_as_breaks(body: list[ast.stmt]) -> list[ast.stmt] | None:
    """``body`` whose bare ``return`` statements all sit in its last statement, a ``for`` loop
    without ``else``, outside the loops nested in it: with each such return a ``break``
    (leaving that loop, the last statement, is leaving the function). None otherwise, or when
    ``body`` has no return there."""
    if not body or not isinstance(body[-1], ast.For) or body[-1].orelse or _has_return(body[:-1]):
        return None
    loop = _copy(body[-1])
    found = False

    def rewrite(statements: list[ast.stmt]) -> list[ast.stmt] | None:
        nonlocal found
        out: list[ast.stmt] = []
        for statement in statements:
            if isinstance(statement, ast.Return):
                if statement.value is not None:
                    return None
                found = True
                out.append(ast.Break())
                continue
            if isinstance(statement, (ast.For, ast.While)):
                if _has_return([statement]):
                    return None
            else:
                for field in ("body", "orelse"):
                    inner = getattr(statement, field, None)
                    if isinstance(inner, list) and inner and isinstance(inner[0], ast.stmt):
                        rewritten = rewrite(inner)
                        if rewritten is None:
                            return None
                        setattr(statement, field, rewritten)
                if _has_return([statement]) and not isinstance(statement, ast.If):
                    return None
            out.append(statement)
        return out

    loop_body = rewrite(loop.body)
    if loop_body is None or not found:
        return None
    loop.body = loop_body
    return [*body[:-1], loop]


def inline_worked_helpers(source: str, text: str) -> str | None:
    """``text`` (one function of the flattened module ``source``) with the helpers it hands a
    tuple of work arrays inlined, for the interpreted tier and the tape only, or None when it
    has none.

    A step loop allocates a helper's scratch space once, ``w = project_work()`` (a tuple of
    ``np.empty`` arrays), and calls the helper at each step, ``project(z, t, c, tol, w)``,
    which unpacks it first, ``phi, y, D, A, piv = w``. The flattening policy
    (:func:`straight`) keeps such a helper (with loops, over :data:`SMALL` statements) a
    function, for numba's compile time, and the tape machine translates neither calls nor
    tuples. Here, in the text the interpreter runs and the tape translates (the compiled
    source is not touched):

    * ``w = project_work()`` becomes one allocation per array, ``w_phi = np.empty(4)``, ...
      (the arrays have constant shapes where the work function's are literal);
    * the helper loses its tuple parameter for one parameter per array (the unpacking goes);
      a bare ``return`` in the loop that ends it (the projection's test of convergence)
      becomes a ``break``, which leaves the same statements unrun;
    * each statement calling it is replaced by its body with its locals renamed
      (:meth:`_Flattener._instance`, tags above the ``_i<k>_`` already in the text). The
      function is not tidied again: the interpreter and the tape gain nothing measurable
      from it, and it cost a fifth of this rewriting's 0.14 s on the Cartesian pendulum.

    The same floating-point operations run in the same order on the same values (the
    arrays are the same allocations, named apart), so the interpreter, the tape and numba
    still give the same bits, which tests/codegen/test_tape_tiers.py checks. A work tuple
    used in any other way, a helper whose returns cannot be made breaks, or a solve that stays
    looped after the inlining (a matrix over
    :data:`~dirac.codegen.small_solves.UNROLLED_MAX_SIZE`), leaves the text as it is (the tape
    then declines the loop, as before).
    """
    if "_work()" not in text:
        return None
    tree = ast.parse(text)
    function = tree.body[0] if len(tree.body) == 1 and isinstance(tree.body[0], ast.FunctionDef) else None
    if function is None:
        return None
    taken = _loaded_names([function]) | {a.arg for a in function.args.args}
    # w = f_work() at the top level of the function, w a name bound once
    works: dict[str, tuple[ast.Assign, list[ast.expr]]] = {}
    stores: dict[str, int] = {}
    for node in walk(function):
        if isinstance(node, ast.Name) and isinstance(node.ctx, (ast.Store, ast.Del)):
            stores[node.id] = stores.get(node.id, 0) + 1
    for statement in function.body:
        if isinstance(statement, ast.Assign) and len(statement.targets) == 1 \
                and isinstance(statement.targets[0], ast.Name) and stores.get(statement.targets[0].id) == 1 \
                and isinstance(statement.value, ast.Call) and isinstance(statement.value.func, ast.Name) \
                and not statement.value.args and not statement.value.keywords:
            maker = function_text(source, statement.value.func.id)
            parsed = ast.parse(maker).body[0] if maker is not None else None
            arrays = _allocations(parsed) if isinstance(parsed, ast.FunctionDef) else None
            if arrays is not None and len(arrays) > 1:
                works[statement.targets[0].id] = (statement, arrays)
    if not works or not _solves_unrolled(function):  # the caller's own solves first (cheap)
        return None
    # every use of w: an argument (a plain name) of a statement calling a helper that unpacks it
    uses = {name: 0 for name in works}
    for node in walk(function):
        if isinstance(node, ast.Name) and isinstance(node.ctx, ast.Load) and node.id in uses:
            uses[node.id] += 1
    helpers: dict[str, ast.FunctionDef] = {}
    calls: list[tuple[ast.Call, int, str]] = []
    refused: set[str] = set()
    for node in walk(function):
        if not isinstance(node, ast.Call):
            continue
        for position, argument in enumerate(node.args):
            if isinstance(argument, ast.Name) and argument.id in works:
                uses[argument.id] -= 1
                callee = node.func.id if isinstance(node.func, ast.Name) else None
                if callee is None or not _unpacks(source, callee, position, len(works[argument.id][1]), helpers):
                    refused.add(argument.id)
                else:
                    calls.append((node, position, argument.id))
    statement_calls = {id(s.value) for s in walk(function) if isinstance(s, ast.Expr) and isinstance(s.value, ast.Call)}
    for call, _, work in calls:
        if id(call) not in statement_calls:
            refused.add(work)
    usable = {w for w in works if w not in refused and uses[w] == 0}
    calls = [c for c in calls if c[2] in usable]
    if not calls:
        return None
    # one allocation per array, named after the helper's unpacked names
    named: dict[str, list[str]] = {}
    for work in usable:
        statement, arrays = works[work]
        first = next(c for c in calls if c[2] == work)
        targets = _unpacked_names(helpers[first[0].func.id], first[1]) or []  # type: ignore[attr-defined]
        names = []
        for target in targets:
            local = f"{work}_{target}"
            while local in taken:
                local = "_" + local
            taken.add(local)
            names.append(local)
        named[work] = names
    new_body: list[ast.stmt] = []
    for statement in function.body:
        bound = statement.targets[0].id if isinstance(statement, ast.Assign) \
            and isinstance(statement.targets[0], ast.Name) else ""
        if bound in usable:
            new_body.extend(ast.Assign(targets=[ast.Name(id=local, ctx=ast.Store())], value=_copy(array), lineno=0)
                            for local, array in zip(named[bound], works[bound][1]))
        else:
            new_body.append(statement)
    function.body = new_body
    for call, position, work in calls:
        call.args[position:position + 1] = [ast.Name(id=local, ctx=ast.Load()) for local in named[work]]
    inline = {call.func.id for call, _, _ in calls}  # type: ignore[attr-defined]
    flattener = _Flattener(ast.Module(body=[_unpacked_helper(helpers[name]) for name in sorted(inline)],
                                      type_ignores=[]), lambda helper: helper.name in inline)
    # fresh locals: a tag above every ``_i<k>_`` the module's own flattening gave the function
    tags = [int(k) for k in re.findall(r"\b_i([0-9]+)_", text)]
    flattener.counter = itertools.count(max(tags, default=-1) + 1)
    caller_names = _stored_names(function.body) | {a.arg for a in function.args.args}
    if not _splice(function, {id(call) for call, _, _ in calls}, flattener, caller_names):
        return None  # a call could not be inlined: keep the text as it was (the tape declines it)
    if not _solves_unrolled(function):
        # a solve left looped keeps its integer pivots, which the tape declines: the larger text
        # would only cost its rewriting (the analysed Cartesian double pendulum, z of size 12:
        # a first 5-step run took 1.1-1.7 s of CPU instead of 0.2-0.35 s, 3 alternating pairs)
        return None
    return unparse(ast.Module(body=[function], type_ignores=[])) + "\n"


def _solves_unrolled(function: ast.FunctionDef) -> bool:
    """Whether every ``lu_factor`` / ``lu_solve`` of ``function`` works on a matrix that
    :func:`specialise_solves` unrolls (allocated in it with a literal size up to
    :data:`~dirac.codegen.small_solves.UNROLLED_MAX_SIZE`)."""
    from dirac.codegen.small_solves import UNROLLED_MAX_SIZE

    shapes = _matrix_allocations(function)
    return not any(isinstance(node, ast.Call) and isinstance(node.func, ast.Name)
                   and node.func.id in ("lu_factor", "lu_solve")
                   and not (node.args and 1 <= _square_size(node.args[0], shapes) <= UNROLLED_MAX_SIZE)
                   for node in walk(function))


def _splice(node: ast.AST, calls: set[int], flattener: _Flattener, caller_names: set[str]) -> bool:
    """Replace, in the statement lists under ``node``, each statement that is one of ``calls``
    by the called helper's body (:meth:`_Flattener._instance`); False when one cannot be."""
    for field in ("body", "orelse", "finalbody"):
        statements = getattr(node, field, None)
        if not (isinstance(statements, list) and statements and isinstance(statements[0], ast.stmt)):
            continue
        out: list[ast.stmt] = []
        for statement in statements:
            if isinstance(statement, ast.Expr) and id(statement.value) in calls:
                call = statement.value
                assert isinstance(call, ast.Call) and isinstance(call.func, ast.Name)
                helper = flattener.helpers[call.func.id]
                instance = None if helper.statements is None else \
                    flattener._instance(helper, call, caller_names, helper.statements)
                if instance is None:
                    return False
                out.extend(instance[0] or [ast.Pass()])
                continue
            if not _splice(statement, calls, flattener, caller_names):
                return False
            out.append(statement)
        setattr(node, field, out)
    return True


def _unpacks(source: str, name: str, position: int, count: int, helpers: dict[str, ast.FunctionDef]) -> bool:
    """Whether module function ``name`` unpacks its parameter ``position`` into ``count``
    names at the top of its body (``a, b, ... = work``) and uses it nowhere else, takes no
    slice (a view, which the tape does not translate), and can be inlined as a statement
    (its returns, if any, made breaks by :func:`_returns_as_breaks`)."""
    if name not in helpers:
        text = function_text(source, name)
        parsed = ast.parse(text).body[0] if text is not None else None
        if not isinstance(parsed, ast.FunctionDef):
            return False
        helpers[name] = parsed
    function = helpers[name]
    if position >= len(function.args.args):
        return False
    parameter = function.args.args[position].arg
    targets = _unpacked_names(function, position)
    if targets is None or len(targets) != count:
        return False
    loads = 0
    for node in walk(function):
        if isinstance(node, ast.Slice):
            # a view (the mechanical field's q = z[:n]) the tape declines anyway: inlined, the
            # larger text made a first midpoint run of the Cartesian pendulum (1000 steps) cost
            # 1.16x the CPU of the process (median of 4 fresh pairs; 0.01-0.41 s more)
            return False
        if isinstance(node, ast.Name) and node.id == parameter:
            loads += 1
    return loads == 1


def _unpacked_names(function: ast.FunctionDef, position: int) -> list[str] | None:
    """The names of ``a, b, ... = p`` at the top level of ``function``, ``p`` its parameter ``position``."""
    parameter = function.args.args[position].arg
    for statement in _without_docstring(list(function.body)):
        if isinstance(statement, ast.Assign) and len(statement.targets) == 1 \
                and isinstance(statement.targets[0], ast.Tuple) and isinstance(statement.value, ast.Name) \
                and statement.value.id == parameter \
                and all(isinstance(e, ast.Name) for e in statement.targets[0].elts):
            return [e.id for e in statement.targets[0].elts]  # type: ignore[attr-defined]
    return None


def _unpacked_helper(function: ast.FunctionDef) -> ast.FunctionDef:
    """A copy of ``function`` marked for inlining, one parameter per unpacked work array in
    place of the tuple, the unpacking removed, and its final loop's returns made breaks."""
    helper = _copy(function)
    body = _without_docstring(list(helper.body))
    for position, argument in enumerate(list(helper.args.args)):
        names = _unpacked_names(helper, position)
        if names is None:
            continue
        body = [s for s in body if not (isinstance(s, ast.Assign) and isinstance(s.value, ast.Name)
                                        and s.value.id == argument.arg and isinstance(s.targets[0], ast.Tuple))]
        helper.args.args[position:position + 1] = [ast.arg(arg=name) for name in names]
        break
    if _restructure(body) is None:
        breaks = _returns_as_breaks(body)
        body = breaks if breaks is not None else body
    helper.body = body or [ast.Pass()]
    helper.decorator_list = [ast.parse(INLINE_MARK + "\ndef f():\n    pass").body[0].decorator_list[0]]  # type: ignore[attr-defined]
    return helper
