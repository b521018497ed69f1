"""Compilation in a separate process, and the record of what compilations cost.

A run that would wait for numba (seconds on a cold cache) goes on in the interpreter
instead while a child process compiles the kernel into numba's on-disk cache; the run
switches to the compiled form at the next step boundary after the child is done
(:meth:`dirac.codegen.tiers.TieredFunction.run_steps`). The child is

    python -c BOOTSTRAP .../dirac/codegen/background.py MODULE.py FUNCTION SIGNATURE.json CHARS

(this file run by its path, not as ``dirac.codegen.background``: importing the package would
import sympy and the analysis, about 0.6 s of CPU that the child does not need before
numba even starts; the child imports numpy, numba and the generated module alone). It
imports the generated module file (the same file, under the same name, as the
parent, so numba's cache index is the one the parent reads), compiles ``FUNCTION`` for
the argument types the parent described (:func:`describe`: the parent does not import
numba while the cache is cold), writes the compile time to the history below and the
marker that says the machine code is ready.

The history, ``compile_history.json`` in the cache directory, holds the measured
seconds of recent compilations against the size of the generated source; the tier
policy estimates the cost of a compilation from it before paying it
(:func:`estimate_compile_seconds`). Reference for the approach: tiered and background
JIT compilation, e.g. the HotSpot VM's background compilation (Paleczny, Vick & Click,
"The Java HotSpot server compiler", JVM '01).
"""

from __future__ import annotations

import json
import os
import subprocess
import sys
import tempfile
import time
from pathlib import Path
from typing import Any

__all__ = ["BackgroundCompile", "estimate_compile_seconds", "estimate_child_start_seconds", "record_compile_seconds",
           "HISTORY_FILE", "describe", "numba_type", "mark_ready", "kernel_chars",
           "DEFAULT_SECONDS_PER_CHAR", "DEFAULT_COMPILE_FLOOR", "DEFAULT_CHILD_START_SECONDS"]

HISTORY_FILE = "compile_history.json"
#: without a history: seconds of CPU per character of the kernel numba compiles
#: (:func:`kernel_chars`; the RATTLE loop of a top in Euler angles and the LU it calls,
#: 8.4 kB after flattening, compiled in 2.3 s of CPU in a fresh process on 2 busy cores,
#: numba's own start-up included) and the floor (that start-up, for the smallest kernel)
DEFAULT_SECONDS_PER_CHAR = 2.7e-4
DEFAULT_COMPILE_FLOOR = 0.5
#: without a history: CPU seconds a background child spends before its compilation starts
#: (the interpreter, numpy, numba and the generated module imported: 0.32-0.38 s for
#: ``python -c "import numpy, numba"`` alone, 0.50 s recorded by a child at load average 7, on
#: the 2-core machine of docs/performance.md), which a compilation in the parent, with numba
#: imported once, does not pay
DEFAULT_CHILD_START_SECONDS = 0.5
_KEEP = 64


def kernel_chars(source: str, name: str) -> int:
    """The size of what numba compiles for ``name`` of the module ``source``: the characters
    of its definition and of the definitions of the module's functions it calls, directly or
    through them (each compiled once). The size of the whole module says little: a module
    holds a dozen loops of which a run compiles one or two."""
    import ast

    try:
        tree = ast.parse(source)
    except SyntaxError:
        return len(source)
    functions = {node.name: node for node in tree.body if isinstance(node, ast.FunctionDef)}
    if name not in functions:
        return len(source)
    seen, todo, total = {name}, [name], 0
    while todo:
        node = functions[todo.pop()]
        segment = ast.get_source_segment(source, node)
        total += len(segment) if segment is not None else 0
        for sub in ast.walk(node):
            if isinstance(sub, ast.Call) and isinstance(sub.func, ast.Name) and sub.func.id in functions \
                    and sub.func.id not in seen:
                seen.add(sub.func.id)
                todo.append(sub.func.id)
    return total


def _history_path() -> Path:
    from dirac.codegen.numba_backend import cache_directory

    return cache_directory() / HISTORY_FILE


def _read_history(path: Path | None = None) -> list[dict[str, Any]]:
    try:
        entries = json.loads((path or _history_path()).read_text(encoding="utf-8"))
    except (OSError, ValueError):
        return []
    if not isinstance(entries, list):
        return []
    return [e for e in entries if isinstance(e, dict) and isinstance(e.get("chars"), (int, float))
            and isinstance(e.get("seconds"), (int, float)) and e["chars"] > 0]


def record_compile_seconds(chars: int, seconds: float, what: str, history: Path | None = None,
                           start: float | None = None) -> None:
    """Append one measured compilation (``seconds`` for ``chars`` characters of source) to
    the history in the cache directory, or to the file ``history`` (the child, which does not
    import the engine to find the cache; the last 64 are kept; a failure to write is ignored:
    the history only informs estimates). ``start``: the CPU seconds a background child spent
    before its compilation (its whole CPU is ``start + seconds``), read by
    :func:`estimate_child_start_seconds`."""
    try:
        path = history or _history_path()
        entries = _read_history(path)[-(_KEEP - 1):]
        entry: dict[str, Any] = {"chars": int(chars), "seconds": round(float(seconds), 4), "what": what[:80]}
        if start is not None:
            entry["start"] = round(float(start), 4)
        entries.append(entry)
        temporary = path.with_suffix(f".{os.getpid()}.tmp")
        temporary.write_text(json.dumps(entries), encoding="utf-8")
        os.replace(temporary, path)
    except OSError:
        return


def estimate_compile_seconds(chars: int, shared: float = 1.0) -> float:
    """Estimated seconds to compile a kernel of ``chars`` characters of source in a process of
    its own: the median measured seconds per character of the history times ``chars`` (at
    least :data:`DEFAULT_COMPILE_FLOOR`), else the built-in rate
    :data:`DEFAULT_SECONDS_PER_CHAR`. A background child compiled beside the run it served,
    the two sharing the cores: its seconds count divided by ``shared``, the slowdown that
    sharing brings (:data:`dirac.codegen.tiers.SHARED_CORE_FACTOR`)."""
    rates = sorted(e["seconds"] / e["chars"] / (shared if "background" in str(e.get("what", "")) else 1.0)
                   for e in _read_history())
    rate = rates[len(rates) // 2] if rates else DEFAULT_SECONDS_PER_CHAR
    return max(DEFAULT_COMPILE_FLOOR, rate * chars)


def estimate_child_start_seconds() -> float:
    """Estimated CPU seconds a background child spends before it compiles (its interpreter,
    numpy, numba and the generated module imported): the median of the start-ups the
    history's background compilations recorded, else :data:`DEFAULT_CHILD_START_SECONDS`."""
    starts = sorted(float(e["start"]) for e in _read_history() if isinstance(e.get("start"), (int, float)))
    return starts[len(starts) // 2] if starts else DEFAULT_CHILD_START_SECONDS


class BackgroundCompile:
    """A child process that compiles ``name`` of the generated module at ``path`` for the
    numba types of ``args`` into numba's on-disk cache."""

    def __init__(self, path: Path, name: str, args: tuple[Any, ...], chars: int) -> None:
        signature = [describe(a) for a in args]  # numba's types, named without importing numba here
        handle, signature_file = tempfile.mkstemp(suffix=".sig", dir=path.parent)
        with os.fdopen(handle, "w") as stream:
            json.dump(signature, stream)
        self.signature_file = Path(signature_file)
        self.started = time.perf_counter()
        self.process = subprocess.Popen(
            [sys.executable, "-c", _BOOTSTRAP, __file__, str(path), name, signature_file, str(chars)],
            stdin=subprocess.DEVNULL, stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)

    def poll(self) -> bool | None:
        """None while the child runs; then True (compiled into the cache) or False (failed)."""
        code = self.process.poll()
        if code is None:
            return None
        self.signature_file.unlink(missing_ok=True)
        return code == 0

    def wait(self, timeout: float | None = None) -> bool | None:
        """Wait for the child (at most ``timeout`` seconds); as :meth:`poll`."""
        try:
            self.process.wait(timeout)
        except subprocess.TimeoutExpired:
            return None
        return self.poll()


def describe(value: Any) -> list[Any]:
    """The numba type ``numba.typeof(value)`` would give, as plain data (:func:`numba_type`
    turns it back): arrays by dtype, dimension, layout and writability; Python scalars."""
    import numpy as np

    if isinstance(value, np.ndarray):
        layout = "C" if value.flags.c_contiguous else "F" if value.flags.f_contiguous else "A"
        return ["array", value.dtype.str, value.ndim, layout, bool(value.flags.writeable)]
    if isinstance(value, (bool, np.bool_)):
        return ["bool"]
    if isinstance(value, (int, np.integer)):
        return ["scalar", np.dtype(type(value) if isinstance(value, np.integer) else np.int64).str]
    if isinstance(value, (float, np.floating)):
        return ["scalar", np.dtype(type(value) if isinstance(value, np.floating) else np.float64).str]
    raise TypeError(f"no background compilation for an argument of type {type(value).__name__}")


def numba_type(description: list[Any]) -> Any:
    """The numba type of a :func:`describe` description."""
    import numba
    import numpy as np

    if description[0] == "array":
        _, dtype, ndim, layout, writeable = description
        return numba.types.Array(numba.from_dtype(np.dtype(dtype)), int(ndim), layout, readonly=not writeable)
    if description[0] == "bool":
        return numba.types.boolean
    return numba.from_dtype(np.dtype(description[1]))


def mark_ready(marker: Path) -> None:
    """Write the marker of a finished compilation (:func:`dirac.codegen.numba_backend.ready_marker`)."""
    try:
        marker.write_text("compiled\n", encoding="utf-8")
    except OSError:
        return


#: the child's first line: run this file by its path as ``__main__`` with nothing of the caller's
#: folder on ``sys.path`` (``python FILE`` would put this file's folder first, where its
#: siblings could shadow modules numba imports)
_BOOTSTRAP = "import runpy, sys; del sys.path[0]; runpy.run_path(sys.argv[1], run_name='__main__')"


def _main(argv: list[str]) -> int:
    """The child: compile function ``name`` of the generated module at ``path`` for the types
    in ``signature_file`` into numba's cache, record its CPU seconds (the compilation, and the
    start-up before it: the parent's estimate of a background road counts both) in the
    history of the module's folder (the cache directory) and write its ready marker."""
    import importlib.util

    path, name, signature_file, chars = argv
    with open(signature_file, encoding="utf-8") as stream:
        signature = tuple(numba_type(d) for d in json.load(stream))
    module_name = Path(path).stem
    spec = importlib.util.spec_from_file_location(module_name, path)
    if spec is None or spec.loader is None:
        return 3
    module = importlib.util.module_from_spec(spec)
    sys.modules[module_name] = module
    spec.loader.exec_module(module)
    start = time.process_time()  # the child's CPU so far: its start-up (process_time counts from the start)
    getattr(module, name).compile(signature)
    record_compile_seconds(int(chars), time.process_time() - start, f"{name} (background)",
                           Path(path).parent / HISTORY_FILE, start=start)
    mark_ready(Path(path).with_name(f"{module_name}.{name}.ready"))
    return 0


if __name__ == "__main__":
    # run by _BOOTSTRAP: sys.argv is ["-c", this file, MODULE.py, FUNCTION, SIGNATURE.json, CHARS]
    sys.exit(_main(sys.argv[2:]))
