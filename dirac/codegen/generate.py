"""The symbolic/numeric boundary: sympy expressions -> numpy and numba functions.

Every numerical function of a general (non rigid-body) system is produced here, once,
before any time step; sympy never runs inside a time step.

Two backends share one calling convention, ``f(x, params, out)``:

* ``numba``: the expressions, after common-subexpression elimination
  (:func:`sympy.cse`), are printed as plain Python with :mod:`math` calls into a source
  file ``dirac_gen_<hash>.py`` in the cache directory, imported, and compiled as
  ``numba.cfunc`` with the one signature ``void(float64[::1], float64[::1],
  float64[::1])`` and ``cache=True``. Because the source is a real file named by the hash
  of its text, numba's on-disk cache survives between runs. The step loops
  (:mod:`dirac.flows.constrained_kernels`) take these functions as first-class function
  arguments of that one type, so they are compiled once per machine for every system;
  per system only the small generated functions compile.
* ``numpy``: :func:`sympy.lambdify` with ``cse=True`` (used to cross-check the generated
  code in tests and for one-off evaluations).

``x`` is a 1-D float array holding the arguments in the documented order, ``params`` a
1-D float array of parameter values, ``out`` a 1-D float array that the function fills
(matrix outputs in C order).

The cache directory is ``$DIRAC_CACHE_DIR`` if set, else ``~/.cache/dirac/generated``
(falling back to the system temporary directory when the home is not writable).
"""

from __future__ import annotations

import hashlib
import importlib.util
import os
import sys
import tempfile
from collections.abc import Mapping, Sequence
from dataclasses import dataclass
from pathlib import Path
from types import ModuleType

import sympy
from sympy.printing.pycode import PythonCodePrinter

__all__ = ["GeneratedFunction", "generate_module", "cache_directory", "numpy_function"]


@dataclass(frozen=True)
class GeneratedFunction:
    """One numerical function to generate.

    Attributes
    ----------
    name : str
        Python name of the function in the generated module.
    arguments : sequence of sympy.Symbol
        The symbols read from ``x``, in order (``x[i]`` is ``arguments[i]``).
    expressions : sympy.Matrix or sequence of sympy.Expr
        The outputs; ``out`` is filled in C order (``out.ravel()[k]`` is the k-th entry).
    doc : str
        One line saying what the function computes and its argument order.
    """

    name: str
    arguments: tuple[sympy.Symbol, ...]
    expressions: object
    doc: str = ""


class _Printer(PythonCodePrinter):
    """Plain-Python printer with ``math`` functions; numba compiles its output."""

    def _print_Rational(self, expr):  # noqa: ANN001, ANN202 -- sympy printer protocol
        return f"({float(expr.p)!r}/{float(expr.q)!r})"

    def _print_Integer(self, expr):  # noqa: ANN001, ANN202
        return f"{float(expr.p)!r}"

    def _print_Pow(self, expr, rational=False):  # noqa: ANN001, ANN202
        base, exponent = expr.as_base_exp()
        if exponent.is_Integer and 0 < int(exponent) <= 4:
            factor = f"({self._print(base)})"
            return "(" + "*".join([factor] * int(exponent)) + ")"
        if exponent.is_Integer and -4 <= int(exponent) < 0:
            factor = f"({self._print(base)})"
            return "(1.0/(" + "*".join([factor] * -int(exponent)) + "))"
        if exponent == sympy.Rational(1, 2):
            return f"math.sqrt({self._print(base)})"
        return f"(({self._print(base)})**({self._print(exponent)}))"


def cache_directory() -> Path:
    """The directory holding generated modules (created on first use)."""
    configured = os.environ.get("DIRAC_CACHE_DIR")
    candidates = [Path(configured)] if configured else []
    candidates.append(Path.home() / ".cache" / "dirac" / "generated")
    candidates.append(Path(tempfile.gettempdir()) / f"dirac-generated-{os.getuid() if hasattr(os, 'getuid') else 0}")
    for candidate in candidates:
        try:
            candidate.mkdir(parents=True, exist_ok=True)
            probe = candidate / ".write-test"
            probe.write_text("ok")
            probe.unlink()
            return candidate
        except OSError:
            continue
    raise OSError("no writable cache directory for generated code; set DIRAC_CACHE_DIR")


def _flat(expressions: object) -> list[sympy.Expr]:
    if isinstance(expressions, sympy.MatrixBase):
        return [sympy.sympify(e) for e in expressions]  # row-major
    return [sympy.sympify(e) for e in expressions]  # type: ignore[union-attr]


def _function_source(function: GeneratedFunction, parameters: Sequence[sympy.Symbol]) -> str:
    printer = _Printer({"fully_qualified_modules": True, "standard": "python3"})
    local_of: dict[sympy.Symbol, sympy.Symbol] = {}
    lines = [f"@numba.cfunc(SIGNATURE, cache=True)", f"def {function.name}(x, params, out):"]
    lines.append(f'    """{function.doc or function.name}"""')
    for index, symbol in enumerate(function.arguments):
        local = sympy.Symbol(f"a{index}_", real=True)
        local_of[symbol] = local
        lines.append(f"    {local.name} = x[{index}]")
    for index, symbol in enumerate(parameters):
        local = sympy.Symbol(f"c{index}_", real=True)
        local_of[symbol] = local
        lines.append(f"    {local.name} = params[{index}]")
    outputs = [e.xreplace(local_of) for e in _flat(function.expressions)]
    leftover = set().union(*(e.free_symbols for e in outputs)) - set(local_of.values()) if outputs else set()
    if leftover:
        names = ", ".join(sorted(s.name for s in leftover))
        raise ValueError(f"function {function.name}: expressions use symbols that are neither arguments nor parameters: {names}")
    replacements, reduced = sympy.cse(outputs, symbols=sympy.numbered_symbols("t", real=True), optimizations="basic")
    for symbol, value in replacements:
        lines.append(f"    {symbol.name} = {printer.doprint(value)}")
    if not outputs:
        lines.append("    return")
    for k, value in enumerate(reduced):
        lines.append(f"    out[{k}] = {printer.doprint(value)}")
    return "\n".join(lines) + "\n"


def generate_module(
    functions: Sequence[GeneratedFunction],
    parameters: Sequence[sympy.Symbol] = (),
    extra_source: str = "",
    title: str = "generated functions",
) -> ModuleType:
    """Generate, write and import a numba module with the given functions.

    Parameters
    ----------
    functions
        The functions to generate (common subexpressions are shared within a function).
    parameters
        Symbols read from ``params`` (same order in every function).
    extra_source
        Additional source appended verbatim.
    title
        First docstring line of the generated module.

    Returns
    -------
    module
        The imported module; its functions are numba ``cfunc`` objects (compiled at import,
        cached on disk).
    """
    header = [
        f'"""{title} -- generated by dirac.codegen.generate; do not edit."""',
        "import math",
        "import numpy as np",
        "import numba",
        "",
        "SIGNATURE = 'void(float64[::1], float64[::1], float64[::1])'",
        "",
    ]
    body = [_function_source(f, parameters) for f in functions]
    source = "\n".join(header) + "\n\n".join(body) + "\n\n" + extra_source
    digest = hashlib.sha256(source.encode()).hexdigest()[:20]
    module_name = f"dirac_gen_{digest}"
    if module_name in sys.modules:
        return sys.modules[module_name]
    path = cache_directory() / f"{module_name}.py"
    if not path.exists() or path.read_text(encoding="utf-8") != source:
        temporary = path.with_suffix(f".{os.getpid()}.tmp")
        temporary.write_text(source, encoding="utf-8")
        os.replace(temporary, path)
    spec = importlib.util.spec_from_file_location(module_name, path)
    assert spec is not None and spec.loader is not None
    module = importlib.util.module_from_spec(spec)
    sys.modules[module_name] = module
    spec.loader.exec_module(module)
    return module


def numpy_function(
    arguments: Sequence[sympy.Symbol],
    expressions: object,
    parameters: Sequence[sympy.Symbol] = (),
    parameter_values: Sequence[float] | Mapping[str, float] = (),
):  # noqa: ANN201
    """A numpy function ``f(x) -> ndarray`` of the expressions (lambdify with cse=True).

    Parameters are substituted by their values first. Used for cross-checks and one-off
    evaluations outside the time loop.
    """
    import numpy as np

    values = list(parameter_values.values()) if isinstance(parameter_values, Mapping) else list(parameter_values)
    substitution = {p: sympy.Float(v, 17) for p, v in zip(parameters, values)}
    flat = [e.xreplace(substitution) for e in _flat(expressions)]
    shape = expressions.shape if isinstance(expressions, sympy.MatrixBase) else (len(flat),)
    compiled = sympy.lambdify([list(arguments)], flat, modules="numpy", cse=True)

    def evaluate(x):  # noqa: ANN001, ANN202
        return np.asarray(compiled(np.asarray(x, dtype=float)), dtype=float).reshape(shape)

    return evaluate
