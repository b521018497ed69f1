"""The one compiled part of the package: the tape machine's loop (dirac/codegen/_tape.c).

Everything else is configured in pyproject.toml. The extension is optional: where it cannot
be built (no C compiler), the package installs without it and the tape machine is compiled
by numba on first use instead (dirac.codegen.tape_machine), with the same results.
-ffp-contract=off keeps the compiler from fusing a product and a sum into one rounding,
which would change results against the interpreter.
"""

import sys

from setuptools import Extension, setup

flags = [] if sys.platform == "win32" else ["-ffp-contract=off"]
setup(ext_modules=[Extension("dirac.codegen._tape", ["dirac/codegen/_tape.c"], extra_compile_args=flags, optional=True)])
