"""Two tiers of one generated module: interpreted at once, compiled when that pays.

A generated kernel module (:mod:`dirac.codegen.kernel_source`) is plain Python source
with numba decorators. Compiling it costs seconds on a cold cache; running the same
source in the interpreter (:func:`dirac.codegen.numba_backend.interpret_source`) costs
nothing to start and microseconds per expression. A :class:`TieredModule` holds both
forms of one source; a :class:`TieredFunction` calls one function of it and decides,
like a tiered JIT, when to switch:

* the compiled form is used at once when it costs nothing to get: already compiled in
  this process, or its machine code is in numba's on-disk cache (a warm cache);
* otherwise the interpreted form runs, and its time is measured; once the interpreted
  time spent, or the time a step loop is expected to need (its measured time per step
  times the steps still planned), exceeds :data:`COMPILE_SECONDS`, the function is
  compiled and the compiled form takes over.

``DIRAC_KERNELS=compiled`` in the environment (or :func:`set_policy` ``("compiled")``,
which ``dirac bench`` uses: it times compiled kernels) skips the interpreted tier.

Both forms execute the same source with the same floating-point operations in the same
order: a run gives the same method and the same accuracy on either tier, only the speed
differs. The first compilation in a process writes one line to stderr
(:func:`announce_compilation`): what is compiled, why, and where the cache lives.
"""

from __future__ import annotations

import os
import sys
import time
from collections.abc import Callable
from types import ModuleType
from typing import Any

import numpy as np

from dirac.codegen.flatten import flatten_source
from dirac.codegen.numba_backend import cache_directory, import_source, interpret_source

__all__ = ["set_policy", "current_policy", "COMPILE_SECONDS", "TieredModule", "TieredFunction", "announce_compilation", "is_compiled_or_cached",
           "tiered", "tiered_module"]

#: interpreted seconds after which a function is compiled (about one cold compilation of
#: a small kernel; ``dirac bench`` measures the actual figures)
COMPILE_SECONDS = 1.0

_announced = False

_POLICIES = ("auto", "compiled")
_policy: str | None = None  # set_policy's choice; None: $DIRAC_KERNELS or "auto"
_warned: set[str] = set()


def set_policy(policy: str | None) -> str | None:
    """``"auto"`` (interpreted until compiling pays), ``"compiled"`` (always compiled) or
    None (``$DIRAC_KERNELS``, read at each decision, default ``"auto"``); returns the
    previous setting."""
    global _policy
    if policy is not None and policy not in _POLICIES:
        raise ValueError(f"policy {policy!r}: use one of {', '.join(_POLICIES)}")
    previous, _policy = _policy, policy
    return previous


def current_policy() -> str:
    """The policy in force: :func:`set_policy`'s, else ``$DIRAC_KERNELS``, else ``"auto"``."""
    if _policy is not None:
        return _policy
    value = os.environ.get("DIRAC_KERNELS", "auto")
    if value not in _POLICIES:
        if value not in _warned:
            from dirac.errors import warn

            _warned.add(value)
            warn(f"DIRAC_KERNELS={value!r} is not one of {', '.join(_POLICIES)}; using 'auto'")
        return "auto"
    return value


def announce_compilation(what: str, why: str) -> None:
    """One stderr line, once per process, before the first compilation of generated code."""
    global _announced
    if _announced:
        return
    _announced = True
    print(f"dirac: compiling {what} ({why}); the machine code is cached in {cache_directory()} "
          "(set DIRAC_CACHE_DIR to move it) and later runs load it", file=sys.stderr, flush=True)


def is_compiled_or_cached(dispatcher: Any) -> bool:
    """Whether calling the numba ``dispatcher`` costs no compilation: compiled in this
    process, or numba's on-disk cache holds an index for it (a warm cache)."""
    if getattr(dispatcher, "signatures", None):
        return True
    try:
        index = dispatcher._cache._cache_file._index_path  # numba's cache locator
    except AttributeError:
        return False
    return bool(os.path.exists(index))


class TieredModule:
    """The interpreted and the compiled form of one generated module (each made on first use)."""

    def __init__(self, source: str, title: str) -> None:
        self.source = flatten_source(source)  # helpers inlined at the source level, for both tiers
        self.title = title
        self._compiled: ModuleType | None = None
        self._interpreted: ModuleType | None = None
        self._functions: dict[str, TieredFunction] = {}

    @property
    def compiled(self) -> ModuleType:
        """The module imported with numba (its functions compile lazily, on first call)."""
        if self._compiled is None:
            self._compiled = import_source(self.source)
        return self._compiled

    @property
    def interpreted(self) -> ModuleType:
        """The same source run by the interpreter (nothing compiled)."""
        if self._interpreted is None:
            self._interpreted = interpret_source(self.source)
        return self._interpreted

    def function(self, name: str) -> TieredFunction:
        """The :class:`TieredFunction` of ``name`` (one per name, so time adds up)."""
        if name not in self._functions:
            self._functions[name] = TieredFunction(self, name)
        return self._functions[name]

    def __getattr__(self, name: str) -> Any:
        """``module.name``: the compiled function (the old interface of a kernel module)."""
        if name.startswith("_"):
            raise AttributeError(name)
        return getattr(self.compiled, name)


class TieredFunction:
    """One function of a :class:`TieredModule` that runs interpreted until compiling pays."""

    def __init__(self, module: TieredModule, name: str) -> None:
        self.module = module
        self.name = name
        self._compiled: Callable[..., Any] | None = None
        self.interpreted_seconds = 0.0
        self.interpreted_steps = 0
        self.interpreted_calls = 0

    @property
    def tier(self) -> str:
        """``"compiled"`` or ``"interpreted"``: the form the next call uses."""
        if self._compiled is None and is_compiled_or_cached(getattr(self.module.compiled, self.name)):
            self._compiled = getattr(self.module.compiled, self.name)
        return "interpreted" if self._compiled is None else "compiled"

    def compile(self, why: str) -> Callable[..., Any]:
        """Switch to the compiled form (compiled now, or loaded from the cache)."""
        if self._compiled is None:
            dispatcher = getattr(self.module.compiled, self.name)
            if not is_compiled_or_cached(dispatcher):
                announce_compilation(f"{self.name} of {self.module.title}", why)
            self._compiled = dispatcher
        return self._compiled

    def seconds_per_step(self) -> float | None:
        """Measured interpreted seconds per step (None before an interpreted call)."""
        return self.interpreted_seconds / self.interpreted_steps if self.interpreted_steps else None

    def _interpreted_call(self, steps: int, args: tuple[Any, ...]) -> Any:
        function = getattr(self.module.interpreted, self.name)
        start = time.perf_counter()
        saved = [(a, a.copy()) for a in args if isinstance(a, np.ndarray)]  # the state the call changes in place
        try:
            with np.errstate(divide="raise", over="ignore", invalid="ignore", under="ignore"):
                return function(*args)
        except FloatingPointError as error:  # numpy scalars: a division by zero, as compiled code raises it
            raise ZeroDivisionError(str(error)) from None
        except OverflowError:
            # Python's math raises where the compiled code returns inf (which the run's guard rails
            # then report as a non-finite state): the same call again, compiled, from the saved state
            for array, before in saved:
                array[...] = before
            return self.compile("the interpreted kernel overflowed (math range error)")(*args)
        finally:
            self.interpreted_seconds += time.perf_counter() - start
            self.interpreted_steps += steps
            self.interpreted_calls += 1

    def __call__(self, *args: Any) -> Any:
        """Call with the budget of single evaluations: interpreted until the interpreted
        time reaches :data:`COMPILE_SECONDS`, compiled afterwards."""
        if self.tier == "interpreted" and current_policy() == "compiled":
            self.compile("DIRAC_KERNELS=compiled")
        if self.tier == "interpreted" and self.interpreted_seconds > COMPILE_SECONDS:
            self.compile(f"{self.interpreted_calls} interpreted calls took {self.interpreted_seconds:.1f} s")
        if self._compiled is not None:
            return self._compiled(*args)
        return self._interpreted_call(1, args)

    def run_steps(self, steps: int, planned: int | None, *args: Any) -> Any:
        """Call a step loop advancing ``steps`` steps, of ``planned`` steps still to come
        (these included; None: unknown, which compiles at once).

        Interpreted while the interpreted time of what is planned (measured seconds per
        step times ``planned``) stays below :data:`COMPILE_SECONDS`; compiled otherwise.
        """
        if self.tier == "interpreted":
            per_step = self.seconds_per_step()
            if current_policy() == "compiled":
                self.compile("DIRAC_KERNELS=compiled")
            elif planned is None:
                self.compile("a run of unknown length")
            elif per_step is not None and per_step * planned > COMPILE_SECONDS:
                self.compile(f"about {planned} steps to go, {per_step * planned:.1f} s interpreted")
            elif per_step is None and steps > 1:
                # no estimate yet: one interpreted step first would need a split of the call
                self.compile(f"a run of {planned} steps")
        if self._compiled is not None:
            return self._compiled(*args)
        return self._interpreted_call(steps, args)

    def warm_up(self, planned: int | None, *args: Any) -> None:
        """A one-step call on scratch arguments before a run of ``planned`` steps: measures
        the interpreted time per step and, when the run would take longer than
        :data:`COMPILE_SECONDS` interpreted, compiles now (before the run's clock starts)."""
        if self.tier == "interpreted" and current_policy() == "auto" and planned is not None and self.seconds_per_step() is None:
            self._interpreted_call(1, args)
        self.run_steps(1, planned, *args)


def tiered(module: Any, name: str) -> Any:
    """``name`` of a generated module: its :class:`TieredFunction` when ``module`` is a
    :class:`TieredModule`, else the module's (compiled) function itself."""
    if isinstance(module, TieredModule):
        return module.function(name)
    return getattr(module, name)


_MODULES: dict[str, TieredModule] = {}


def tiered_module(source: str, title: str) -> TieredModule:
    """The one :class:`TieredModule` of ``source`` in this process (systems with the same
    generated source share it, and the time spent interpreting it adds up)."""
    module = _MODULES.get(source)
    if module is None:
        module = _MODULES[source] = TieredModule(source, title)
    return module
