"""The one boundary from sympy expressions to numbers.

One printer (:mod:`dirac.codegen.printer`) turns expressions into straight-line Python
source; three backends compile that source:

* :mod:`~dirac.codegen.numba_backend`: ``numba.cfunc`` functions ``f(x, params, out)``
  for the time-step kernels, cached on disk by the hash of their source
  (:class:`GeneratedFunction`, :func:`generate_module`);
* :mod:`~dirac.codegen.numpy_backend`: array evaluation with numpy, broadcasting over
  array arguments (:func:`array_function`, :func:`numpy_function`);
* :mod:`~dirac.codegen.scalar_backend`: plain-Python scalar functions that are fast to
  build, for the symbolic engine's numerical decisions (:func:`scalar_function`).

On top of the numba backend, :mod:`~dirac.codegen.kernel_source` writes whole step
kernels of one system (RATTLE, the Dirac field, the midpoint rule, residuals) with the
expressions inlined (:func:`mechanical_kernel_source`, :func:`analysed_kernel_source`,
:func:`load_kernels`).

Sympy never runs inside the generated functions.
"""

from dirac.codegen.kernel_source import analysed_kernel_source, load_kernels, mechanical_kernel_source
from dirac.codegen.numba_backend import GeneratedFunction, cache_directory, generate_module
from dirac.codegen.numpy_backend import array_function, numpy_function
from dirac.codegen.printer import StraightLineCode, UnsupportedExpression, chained, straight_line
from dirac.codegen.scalar_backend import scalar_function

__all__ = [
    "GeneratedFunction",
    "StraightLineCode",
    "UnsupportedExpression",
    "analysed_kernel_source",
    "array_function",
    "cache_directory",
    "chained",
    "generate_module",
    "load_kernels",
    "mechanical_kernel_source",
    "numpy_function",
    "scalar_function",
    "straight_line",
]
