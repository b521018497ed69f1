"""Numba backend: sympy expressions -> ``numba.cfunc`` functions, cached on disk.

Every numerical function of a general (non rigid-body) system is produced here, once,
before any time step; sympy never runs inside a time step.

The expressions of each function are printed by :func:`dirac.codegen.printer.straight_line`
(``sharing="cse"``, target ``"math"``) as plain Python with :mod:`math` calls into a source
file ``dirac_gen_<hash>.py`` in the cache directory, imported, and compiled as
``numba.cfunc`` with the one signature ``void(float64[::1], float64[::1], float64[::1])``
and ``cache=True``: ``f(x, params, out)``. Because the source is a real file named by the
hash of its text, numba's on-disk cache survives between runs. The step loops
(:mod:`dirac.flows.constrained_kernels`) take these functions as first-class function
arguments of that one type, so they are compiled once per machine for every system; per
system only the small generated functions compile.

``x`` is a 1-D float array holding the arguments in the documented order, ``params`` a
1-D float array of parameter values, ``out`` a 1-D float array that the function fills
(matrix outputs in C order). :func:`dirac.codegen.numpy_backend.numpy_function` evaluates
the same expressions with numpy (cross-checks, one-off evaluations).

The cache directory is ``$DIRAC_CACHE_DIR`` if set, else ``~/.cache/dirac/generated``
(falling back to the system temporary directory when the home is not writable).
"""

from __future__ import annotations

import hashlib
import importlib.util
import os
import sys
import tempfile
from collections.abc import Iterable, Sequence
from dataclasses import dataclass
from pathlib import Path
from types import ModuleType

import sympy

from dirac.codegen.printer import flat_expressions, straight_line

__all__ = ["GeneratedFunction", "generate_module", "import_source", "cache_directory"]


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
    expressions: Iterable[object]
    doc: str = ""


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


def _function_source(function: GeneratedFunction, parameters: Sequence[sympy.Symbol]) -> str:
    inputs = {symbol: f"a{index}_" for index, symbol in enumerate(function.arguments)}
    inputs.update({symbol: f"c{index}_" for index, symbol in enumerate(parameters)})
    lines = ["@numba.cfunc(SIGNATURE, cache=True)", f"def {function.name}(x, params, out):"]
    lines.append(f'    """{function.doc or function.name}"""')
    lines.extend(f"    a{index}_ = x[{index}]" for index in range(len(function.arguments)))
    lines.extend(f"    c{index}_ = params[{index}]" for index in range(len(parameters)))
    code = straight_line(inputs, flat_expressions(function.expressions), "math", "cse", f"function {function.name}")
    lines.extend(code.body())
    if not code.outputs:
        lines.append("    return")
    lines.extend(f"    out[{k}] = {value}" for k, value in enumerate(code.outputs))
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
        f'"""{title} -- generated by dirac.codegen; do not edit."""',
        "import math",
        "import numpy as np",
        "import numba",
        "",
        "SIGNATURE = 'void(float64[::1], float64[::1], float64[::1])'",
        "",
    ]
    body = [_function_source(f, parameters) for f in functions]
    source = "\n".join(header) + "\n\n".join(body) + "\n\n" + extra_source
    return import_source(source)


def import_source(source: str) -> ModuleType:
    """Write ``source`` to ``dirac_gen_<hash>.py`` in :func:`cache_directory` (unless a file
    of that name holds it already) and import it, once per process.

    The module name is the hash of the source, so numba's on-disk cache of the module's
    ``cache=True`` functions is reused by every later run that generates the same source.
    """
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
