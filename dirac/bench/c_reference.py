"""The C reference step (``reference_step.c``), compiled at run time and called via ctypes.

``dirac bench`` times the package's numba kernel side by side with this plain C version
of the same Strang step, compiled with ``cc -O3`` (the compiler found as ``$CC``, else
``cc``, ``gcc`` or ``clang``) into a temporary directory. Without a compiler the
comparison is skipped with a note; nothing else depends on it.
"""

from __future__ import annotations

import ctypes
import os
import shutil
import subprocess
import tempfile
from dataclasses import dataclass
from importlib import resources
from pathlib import Path

import numpy as np

__all__ = ["CReference", "compile_reference", "find_compiler"]

_FLAGS = ("-O3", "-shared", "-fPIC")


def find_compiler() -> str | None:
    """Path of a C compiler (``$CC``, ``cc``, ``gcc`` or ``clang``), or None."""
    candidates = [os.environ.get("CC")] if os.environ.get("CC") else []
    candidates += ["cc", "gcc", "clang"]
    for name in candidates:
        path = shutil.which(name) if name else None
        if path:
            return path
    return None


@dataclass
class CReference:
    """A compiled ``strang_advance`` and how it was built."""

    library: ctypes.CDLL
    compiler: str
    command: str
    directory: tempfile.TemporaryDirectory

    def advance(self, M: np.ndarray, R: np.ndarray, inv_inertia: np.ndarray, dt: float, n_steps: int,
                with_R: bool = True) -> None:
        """Advance ``M`` (3,) and ``R`` (3, 3) in place by ``n_steps`` Strang steps (C code)."""
        for name, array in (("M", M), ("R", R)):
            if array.dtype != np.float64 or not array.flags.c_contiguous:
                raise ValueError(f"{name} must be a C-contiguous float64 array")
        inv = np.ascontiguousarray(inv_inertia, dtype=float)
        self._function(
            M.ctypes.data_as(ctypes.POINTER(ctypes.c_double)),
            R.ctypes.data_as(ctypes.POINTER(ctypes.c_double)),
            inv.ctypes.data_as(ctypes.POINTER(ctypes.c_double)),
            ctypes.c_double(dt),
            ctypes.c_long(int(n_steps)),
            ctypes.c_int(1 if with_R else 0),
        )

    @property
    def _function(self):
        function = self.library.strang_advance
        function.restype = None
        return function


def compile_reference() -> tuple[CReference | None, str]:
    """Compile ``reference_step.c``; return ``(reference or None, note)``.

    The note says which compiler and flags were used, or why the reference is skipped.
    """
    compiler = find_compiler()
    if compiler is None:
        return None, "no C compiler found (set $CC or install cc/gcc/clang): C reference skipped"
    directory = tempfile.TemporaryDirectory(prefix="dirac-bench-c-")
    source = Path(directory.name) / "reference_step.c"
    source.write_text(resources.files("dirac.bench").joinpath("reference_step.c").read_text())
    target = Path(directory.name) / "libreference_step.so"
    command = [compiler, *_FLAGS, "-o", str(target), str(source), "-lm"]
    try:
        subprocess.run(command, check=True, capture_output=True, text=True, timeout=120)
    except (OSError, subprocess.SubprocessError) as exc:
        detail = getattr(exc, "stderr", "") or str(exc)
        directory.cleanup()
        return None, f"C reference skipped: compiling with {compiler} failed ({' '.join(str(detail).split())[:200]})"
    library = ctypes.CDLL(str(target))
    shown = " ".join([Path(compiler).name, *_FLAGS, "reference_step.c", "-lm"])
    return CReference(library, compiler, shown, directory), f"C reference compiled with: {shown}"
