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
  time spent exceeds :data:`COMPILE_SECONDS`, the function is compiled and the compiled
  form takes over; a step loop prices its roads first (its measured time per step times
  the steps still planned against the estimated compilation, in this process or in a
  child beside it: :func:`choose_road`).

A step loop has a third road between the two (:mod:`dirac.codegen.tape_machine`): its
source translated to a register tape (:mod:`dirac.codegen.tape_source`) and run by one
loop that numba compiles once for every system, several times faster than the interpreter,
with the same operations in the same order; :func:`choose_road` takes it when it ends a run
before both the interpreter and the compiler (``DIRAC_TAPE=0`` turns it off).

``DIRAC_KERNELS=compiled`` in the environment (or :func:`set_policy` ``("compiled")``,
which ``dirac bench`` uses: it times compiled kernels) skips the interpreted tier.

Both forms execute the same source with the same floating-point operations in the same
order (the interpreted form has its LU solves of fixed size written out as straight-line
code, :func:`dirac.codegen.flatten.specialised_function`, which makes the operations of
the loops in their order): a run gives the same numbers on either tier, only the speed differs. The first compilation in a process writes one line to stderr
(:func:`announce_compilation`): what is compiled, why, and where the cache lives.
"""

from __future__ import annotations

import math
import os
import re
import time
from collections.abc import Callable
from pathlib import Path
from types import ModuleType
from typing import Any

import numpy as np

from dirac.codegen.background import (
    DEFAULT_COMPILE_FLOOR,
    BackgroundCompile,
    estimate_child_start_seconds,
    estimate_compile_seconds,
    kernel_chars,
    mark_ready,
    record_compile_seconds,
)
from dirac.codegen.flatten import flatten_source, function_text, specialised_function
from dirac.codegen.numba_backend import (
    cache_directory,
    import_source,
    interpret_source,
    ready_marker,
    source_path,
    write_source,
)
from dirac.codegen.scalar_arrays import scalar_function
from dirac.codegen.tape_machine import TapeError, TapeFunction, machine, machine_loaded, machine_ready
from dirac.codegen.tape_source import translate
from dirac.errors import inform

__all__ = ["set_policy", "current_policy", "COMPILE_SECONDS", "TAPE_SPEEDUP", "TAPE_MACHINE_SECONDS", "TAPE_LOAD_SECONDS",
           "TAPE_TRANSLATE_SECONDS", "TAPE_TRANSLATE_SECONDS_PER_CHAR", "TAPE_TRANSLATE_FLOOR",
           "TAPE_PROBE_STEPS", "TAPE_RATE_STEPS", "tape_enabled", "NUMBA_IMPORT_SECONDS", "CACHE_LOAD_SECONDS", "SHARED_CORE_FACTOR",
           "CHECK_SECONDS",
           "WARM_UP_STEPS", "WARM_UP_UNTIMED_STEPS", "WAIT_FACTOR", "choose_road", "background_enabled", "spare_core",
           "TieredModule", "TieredFunction", "announce_compilation", "is_compiled_or_cached", "tiered", "tiered_module"]

#: how many times faster the tape machine runs a step loop than the interpreter, assumed before
#: the tape's own rate is measured: 5.9-7.1 measured on the RATTLE loops of the double and triple
#: pendulums and the tops in Euler angles (2-7 us a step against 12-41 us), taken low. With the
#: directly threaded C loop (dirac/codegen/_tape.c) rattle-2 steps ran 7.4-10.5 times faster than
#: interpreted on those loops and 4.6 on the unrolled constant-mass loop of the Cartesian double
#: pendulum (calls of 200 steps, median of 7 alternated pairs; 2.1 with the former switch): kept
#: at 5, the rate the first tape part measures corrects it
TAPE_SPEEDUP = 5.0
#: CPU seconds to compile the tape machine on a cold cache, numba's import apart (about 0.9 s
#: measured: numba's first compilation in a process and the machine's loop), and to load it
#: from numba's on-disk cache (about 0.3 s)
TAPE_MACHINE_SECONDS = 0.9
TAPE_LOAD_SECONDS = 0.3
#: CPU seconds to translate a step loop to a tape, once per loop (:func:`~dirac.codegen.tape_source.translate`:
#: 53-62 ms measured for the RATTLE loops of the triple pendulum, the tops in Euler angles and
#: the Cartesian double pendulum, about 20,000 characters each): the tape must save more
TAPE_TRANSLATE_SECONDS = 0.1
#: the same per character of a loop's interpreted text, once that text is made (its first
#: interpreted call): translation and optimisation of the RATTLE loops took 1.6-2.4 us a character
#: for the double pendulum in angles (13,300 characters), 2.1-2.9 for the symmetric top in Euler
#: angles (18,000), 2.6-3.3 for the triple pendulum (20,700), 2.7-5.2 for the Cartesian double
#: pendulum (7,400), CPU at load 2-4. Taken as 3 us, and at least :data:`TAPE_TRANSLATE_FLOOR`
#: (:meth:`TieredFunction.translate_estimate`)
TAPE_TRANSLATE_SECONDS_PER_CHAR = 3e-6
#: the least translation estimate: a loop of 430 characters translates in 0.66 ms, but a loop's
#: rate is first measured on its cold first call (the sine loop of the tests: 0.16 ms for its
#: first step, 2 us for each next one), which can promise the few steps of a small loop a saving
#: its translation does not bring; every RATTLE loop of the corpus is estimated above it
TAPE_TRANSLATE_FLOOR = 0.02
#: steps of the first part a loop runs on the tape, which measures the tape's own rate
TAPE_PROBE_STEPS = 256
#: parts of fewer steps do not count in the tape's rate (each call costs some microseconds of
#: copies, about a step of the triple pendulum)
TAPE_RATE_STEPS = 32
#: interpreted seconds after which a function is compiled (about one cold compilation of
#: a small kernel; ``dirac bench`` measures the actual figures)
COMPILE_SECONDS = 1.0
#: a step loop whose interpreted remainder exceeds this many times the estimated compile time
#: waits for the compilation in the process (the estimate may be off by this factor and the
#: wait still not exceed the interpreted run); below it, and above the estimate, a background
#: compilation lets the run go on interpreted when that road can end the run sooner than the
#: interpreter (:func:`choose_road`)
WAIT_FACTOR = 2.0
#: CPU seconds of ``import numba`` in a fresh process (0.5-0.55 s measured on the 2-core machine
#: of docs/performance.md, where a bare interpreter starts in 0.04 s), which a first compilation
#: pays on top of the compile times the history records
NUMBA_IMPORT_SECONDS = 0.5
#: CPU seconds the parent spends, after a background compilation, to load the machine code from
#: numba's on-disk cache (the index, the unpickled library; numba's import apart): 0.33 s
#: measured for the RATTLE loop of the symmetric top in Euler angles on a busy machine
CACHE_LOAD_SECONDS = 0.3
#: how much longer a background child takes beside the run it serves: the two processes share
#: the machine's two cores (on a virtual machine, often two threads of one physical core) and
#: each slows the other. On a quiet machine the child compiling the triple pendulum's loop
#: beside the interpreted run took about 5.3 s of CPU where the same compilation alone took
#: 3.6 s (1.47); at load average 3-6, 4.3 s against 3.6 (1.2). The background road's
#: estimate (:meth:`TieredFunction.background_estimate`) scales the child's work by this
SHARED_CORE_FACTOR = 1.45
#: interpreted seconds between two looks at a background compilation (a step loop runs in
#: parts of about this length while one is in flight)
CHECK_SECONDS = 0.05
#: steps of the call on scratch arguments that measures a step loop's interpreted rate before
#: a run (:meth:`TieredFunction.warm_up`): enough that the cost of the call itself (about one
#: step of a small system) adds a few per cent to the rate, few enough to cost milliseconds
WARM_UP_STEPS = 64
#: steps run, untimed, before that call: the interpreter specialises a loop's bytecode over its
#: first tens of executions (the triple pendulum in angles: 65-71 us a step over steps 2-33,
#: 46-51 us from step 34 on), so a rate measured on them overestimates the run
WARM_UP_UNTIMED_STEPS = 32


def choose_road(interpreted: float, compile_seconds: float, background: float | None,
                tape: float | None = None) -> str:
    """The road of a step loop that runs interpreted: ``"interpreted"`` (to its end),
    ``"tape"`` (the rest on the tape machine, :mod:`dirac.codegen.tape_machine`),
    ``"compile"`` (wait for the compiler in this process) or ``"background"`` (a child process
    compiles while the loop goes on interpreted).

    Parameters
    ----------
    interpreted
        ``I``: estimated CPU seconds of the interpreted remainder (measured rate times the steps
        to go; ``inf`` for a run of unknown length).
    compile_seconds
        ``E``: estimated seconds of a compilation in this process (numba's import included
        while it is not imported).
    background
        ``B``: estimated seconds until a background compilation's machine code runs here: the
        child's start-up, its compilation and the parent's load of the result (numba's import,
        :data:`CACHE_LOAD_SECONDS`); None when no background road is open (no idle core, or
        turned off, or failed before, or a loop that cannot be split).
    tape
        ``T``: estimated seconds of the remainder on the tape machine, the machine's compilation
        or load included (:meth:`TieredFunction.tape_estimate`); None when the loop has no tape.

    Returns
    -------
    str
        The road, by this table (with ``c`` = :data:`COMPILE_SECONDS`, ``W`` = :data:`WAIT_FACTOR`,
        ``t`` = :data:`TAPE_TRANSLATE_SECONDS`):

        ================================  ==============
        ``T + t < I``, ``T <= E``         tape
        ``I <= c``                        interpreted
        ``I <= E``                        interpreted
        ``I > W E``                       compile
        ``E < I <= W E``, ``B < I``       background
        ``E < I <= W E``, otherwise       compile
        ================================  ==============

    Notes
    -----
    Wall and CPU of each road, with the compiled steps nearly free: interpreted ``I`` and
    ``I``; compile ``E`` and ``E``; background ``min(I, B)`` and about ``min(I, B) + B`` (the
    interpreted steps before the switch, plus the child's whole compilation). ``B`` exceeds
    ``E`` by the child's start-up, the load from the cache and the slowdown of two processes
    sharing two cores (:data:`SHARED_CORE_FACTOR`), so when the estimate is right the
    compilation in the process wins on both counts wherever compiling pays (``I > E``): a
    background compilation bought on that band ran the triple pendulum's 1e5-step study in
    7.3 s of wall and 13.1 s of CPU where the compilation in the process took 4.9 and 5.2.
    The background road is kept for the one case it serves: the remainder exceeds the estimate
    by less than ``W`` (an estimate off by that much would make the wait in the process longer
    than the interpreted run) and the child can still end the run sooner than the interpreter
    (``B < I``); it then never waits longer than the interpreted run (Paleczny, Vick & Click,
    "The Java HotSpot server compiler", JVM '01, for background compilation in a tiered JIT).
    The tape is taken when it ends the run before both the interpreter and the compiler, by
    more than the translation of the loop costs: its wait (none for the machine compiled at
    the install; numba's import and the machine's compilation or load otherwise) is part of
    ``T``, so it never waits longer than the interpreted run either; a run of less than a
    second interpreted takes it only when the machine costs nothing to get. Without a tape the table is the one of
    two roads: ``I <= max(c, E)`` interpreted.
    """
    if tape is not None and tape + TAPE_TRANSLATE_SECONDS < interpreted and tape <= compile_seconds:
        return "tape"
    if interpreted <= COMPILE_SECONDS:
        return "interpreted"
    if interpreted <= compile_seconds:
        return "interpreted"
    if interpreted > WAIT_FACTOR * compile_seconds:
        return "compile"
    if background is not None and background < interpreted:
        return "background"
    return "compile"


def spare_core() -> bool:
    """Whether a core is idle for a background compilation: the 1-minute load average at
    least one below the number of usable cores (on a busy machine a compiling child shares
    the run's core, and compiling in the process costs less CPU)."""
    try:
        usable = len(os.sched_getaffinity(0)) if hasattr(os, "sched_getaffinity") else (os.cpu_count() or 1)
        return usable - os.getloadavg()[0] >= 1.0
    except OSError:
        return False


def tape_enabled() -> bool:
    """Whether step loops may run on the tape machine (``$DIRAC_TAPE``, default on; ``0``
    leaves the interpreted and compiled tiers only)."""
    return os.environ.get("DIRAC_TAPE", "1") != "0"


def background_enabled() -> bool:
    """Whether step loops compile in a separate process (``$DIRAC_BACKGROUND_COMPILE``,
    default on; ``0`` compiles in this process, when that pays)."""
    return os.environ.get("DIRAC_BACKGROUND_COMPILE", "1") != "0"

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
    """One stderr line, once per process, before the first compilation of generated code
    (:func:`dirac.errors.inform`: none inside :func:`dirac.errors.quiet_information`, as ``-q``
    asks; the next compilation outside it is announced)."""
    global _announced
    if _announced:
        return
    _announced = inform(f"dirac: compiling {what} ({why}); the machine code is cached in {cache_directory()} "
                        "(set DIRAC_CACHE_DIR to move it) and later runs load it")


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
        self._specialised: set[str] = set()
        self._texts: dict[str, str] = {}
        self._tapes: dict[str, TapeFunction | None] = {}
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

    def interpreted_function(self, name: str) -> Callable[..., Any]:
        """Function ``name`` of :attr:`interpreted`, its LU solves of fixed size unrolled
        (:func:`~dirac.codegen.flatten.specialised_function`), its loops of literal length
        unrolled and its small work arrays made Python floats
        (:func:`~dirac.codegen.scalar_arrays.scalar_function`): the same operations in the same
        order, so the same numbers, in a fraction of the interpreter's time; specialised
        when first asked for, and put in the interpreted module in place of the looped one."""
        module = self.interpreted
        if name not in self._specialised:
            text = specialised_function(self.source, name)
            plain = text if text is not None else function_text(self.source, name)
            signature = re.search(rf"def {name}\(([^)]*)\)", plain or "")
            if plain is not None and signature is not None and "n_steps" in signature.group(1):
                # a step loop (its rewriting, tens of milliseconds, pays back over its steps; a
                # function called once per sample would not repay it)
                scalar = scalar_function(plain, name)
                text = scalar if scalar is not None else text
            if text is not None:
                exec(compile(text, f"<dirac generated {module.__name__} {name}>", "exec"), module.__dict__)
            self._texts[name] = text if text is not None else (plain or "")
            self._specialised.add(name)
        function: Callable[..., Any] = getattr(module, name)
        return function

    def tape_function(self, name: str) -> TapeFunction | None:
        """Function ``name`` on the tape machine: the text :meth:`interpreted_function` runs,
        translated (:func:`~dirac.codegen.tape_source.translate`); None when it uses a
        construct the tape does not translate (the other tiers then run it)."""
        if name not in self._tapes:
            self.interpreted_function(name)
            tape = translate(self._texts.get(name) or "", name)
            self._tapes[name] = TapeFunction(tape) if tape is not None else None
        return self._tapes[name]

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
        self.background: BackgroundCompile | None = None
        self.background_failed = False
        self._split: tuple[int, int, int, int] | None | bool = False  # not looked at yet
        self._marker: Path | None = None
        self._chars: int | None = None
        self.on_tape = False
        self._tape_compile_estimate: float | None = None
        self.tape_failed = False
        self.tape_seconds = 0.0
        self.tape_steps = 0
        #: a run of this loop over a longer span follows the runs made now (:meth:`expect_longer_run`)
        self.longer_run_follows = False

    @property
    def tier(self) -> str:
        """``"compiled"``, ``"tape"`` or ``"interpreted"``: the form the next call uses. Without the
        marker of a finished compilation (:func:`~dirac.codegen.numba_backend.ready_marker`)
        the cache is cold, and neither numba nor the compiled module is imported to find out."""
        if self._compiled is None and (self.module._compiled is not None or self.ready_marker().exists()) \
                and is_compiled_or_cached(getattr(self.module.compiled, self.name)):
            self._compiled = getattr(self.module.compiled, self.name)
            if self.background is not None and self.background.poll() is not None:
                self.background = None  # its work is done (or another process's was)
        if self._compiled is not None:
            return "compiled"
        return "tape" if self.on_tape else "interpreted"

    def expect_longer_run(self) -> None:
        """Say that the runs made now are pilots of a run of this loop over a longer span (the
        pilots of ``method = "auto"``, :mod:`dirac.flows.methods.auto`): the price of the
        loop's translation to a tape is then counted as paid in the rent-or-buy rule of
        :meth:`_decide`, so the pilots run on the tape from their second step when the machine
        is there (the translation is paid once, at the first pilot, instead of after the pilots
        have spent its price interpreted). What is bought is the translation the long run
        makes in any case when it runs longer interpreted than the translation costs: every
        ``t_end = 100`` run of the latency corpus does; a shorter run pays at most one
        translation it would not have made (20-30 ms for the double pendulums). The flag stays:
        once translated, the price is paid for every later run alike."""
        self.longer_run_follows = True

    def ready_marker(self) -> Path:
        """The marker file of this function's machine code in the cache (found once)."""
        if self._marker is None:
            self._marker = ready_marker(source_path(self.module.source), self.name)
        return self._marker

    def compile(self, why: str, args: tuple[Any, ...] | None = None) -> Callable[..., Any]:
        """Switch to the compiled form (compiled now, or loaded from the cache); with the
        call's ``args``, the compilation is timed and recorded in the history of
        :mod:`dirac.codegen.background`."""
        if self._compiled is None:
            dispatcher = getattr(self.module.compiled, self.name)
            if not is_compiled_or_cached(dispatcher):
                announce_compilation(f"{self.name} of {self.module.title}", why)
                if args is not None:
                    import numba

                    start = time.process_time()
                    dispatcher.compile(tuple(numba.typeof(a) for a in args))
                    record_compile_seconds(self.kernel_chars(), time.process_time() - start, self.name)
                    mark_ready(self.ready_marker())
            self._compiled = dispatcher
        return self._compiled

    def compile_estimate(self) -> float:
        """Estimated seconds to compile this function (:func:`estimate_compile_seconds` of
        the module's source size and the measured history in the cache), plus
        :data:`NUMBA_IMPORT_SECONDS` while numba is not imported in this process (the history
        times the compilation alone; a first compilation, here or in a child, imports numba
        first)."""
        import sys

        start = 0.0 if "numba" in sys.modules else NUMBA_IMPORT_SECONDS
        return estimate_compile_seconds(self.kernel_chars(), SHARED_CORE_FACTOR) + start

    def compile_floor(self) -> float:
        """A lower bound of :meth:`compile_estimate` known without reading the kernel's size (a
        parse of the generated module: 40-70 ms for the RATTLE loops of the double and triple
        pendulums): :data:`~dirac.codegen.background.DEFAULT_COMPILE_FLOOR`, the least
        :func:`estimate_compile_seconds` gives, plus numba's import while it is not imported.
        A road chosen against it is the road chosen against the estimate."""
        import sys

        return DEFAULT_COMPILE_FLOOR + (0.0 if "numba" in sys.modules else NUMBA_IMPORT_SECONDS)

    def background_estimate(self) -> float:
        """Estimated seconds until a background compilation of this function, started now,
        would have its machine code running here: the child's start-up
        (:func:`~dirac.codegen.background.estimate_child_start_seconds`, numba's import in
        it) and its compilation, both slowed by :data:`SHARED_CORE_FACTOR` beside the run;
        then, in this process, numba's import (while not imported) and the load from the
        cache (:data:`CACHE_LOAD_SECONDS`)::

            B = SHARED_CORE_FACTOR * (start + E - import) + import + CACHE_LOAD_SECONDS

        with ``E`` = :meth:`compile_estimate` and ``import`` its part for numba's import."""
        import sys

        numba_import = 0.0 if "numba" in sys.modules else NUMBA_IMPORT_SECONDS
        child = estimate_child_start_seconds() + self.compile_estimate() - numba_import
        return SHARED_CORE_FACTOR * child + numba_import + CACHE_LOAD_SECONDS

    def tape_estimate(self, planned: int | None, args: tuple[Any, ...]) -> float | None:
        """Estimated CPU seconds of ``planned`` steps on the tape machine, the machine's wait
        included: its compilation (:data:`TAPE_MACHINE_SECONDS`) or load from the cache
        (:data:`TAPE_LOAD_SECONDS`), numba's import while not imported, then the steps at the
        tape's measured rate (before it is measured: the interpreted rate over
        :data:`TAPE_SPEEDUP`). None when the loop has no tape (turned off, not translated,
        failed before, arguments it does not take, or a run of unknown length)."""
        import sys

        if planned is None or not tape_enabled() or self.tape_failed or self._split_positions() is None:
            return None
        tape = self.module.tape_function(self.name)
        if tape is None or not tape.accepts(args):
            return None
        if self.tape_steps:
            rate = self.tape_seconds / self.tape_steps
        else:
            interpreted = self.seconds_per_step()
            if interpreted is None:
                return None
            rate = interpreted / TAPE_SPEEDUP
        wait = 0.0
        if not machine_loaded():
            wait = TAPE_LOAD_SECONDS if machine_ready() else TAPE_MACHINE_SECONDS
            wait += 0.0 if "numba" in sys.modules else NUMBA_IMPORT_SECONDS
        return wait + rate * planned

    def translate_estimate(self) -> float:
        """Estimated CPU seconds to translate this loop to a tape: the length of the text the
        interpreted tier runs (made at its first interpreted call) times
        :data:`TAPE_TRANSLATE_SECONDS_PER_CHAR`, at least :data:`TAPE_TRANSLATE_FLOOR`;
        :data:`TAPE_TRANSLATE_SECONDS` before that text exists, 0 once translated."""
        if self.name in self.module._tapes:
            return 0.0
        text = self.module._texts.get(self.name)
        if text is None:
            return TAPE_TRANSLATE_SECONDS
        return max(TAPE_TRANSLATE_FLOOR, TAPE_TRANSLATE_SECONDS_PER_CHAR * len(text))

    def kernel_chars(self) -> int:
        """The size of what numba compiles for this function (:func:`kernel_chars`)."""
        if self._chars is None:
            self._chars = kernel_chars(self.module.source, self.name)
        return self._chars

    def seconds_per_step(self) -> float | None:
        """Measured interpreted seconds (CPU) per step (None before an interpreted call)."""
        return self.interpreted_seconds / self.interpreted_steps if self.interpreted_steps else None

    def _interpreted_call(self, steps: int, args: tuple[Any, ...]) -> Any:
        function = self.module.interpreted_function(self.name)
        start = time.process_time()  # CPU, as the compile estimates: a busy machine slows both alike
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
            self.interpreted_seconds += time.process_time() - start
            self.interpreted_steps += steps
            self.interpreted_calls += 1

    def __call__(self, *args: Any) -> Any:
        """Call with the budget of single evaluations: interpreted until the interpreted
        time reaches :data:`COMPILE_SECONDS`, compiled afterwards."""
        if self.tier == "interpreted" and current_policy() == "compiled":
            self.compile("DIRAC_KERNELS=compiled", args)
        if self.tier == "interpreted" and self.interpreted_seconds > COMPILE_SECONDS:
            self.compile(f"{self.interpreted_calls} interpreted calls took {self.interpreted_seconds:.1f} s", args)
        if self._compiled is not None:
            return self._compiled(*args)
        return self._interpreted_call(1, args)

    # ------------------------------------------------------------------ step loops
    def _split_positions(self) -> tuple[int, int, int, int] | None:
        """Positions of ``t``, ``dt``, ``n_steps`` and ``info`` among the arguments of a step
        loop (``info = [steps_done, failed, evaluations, residual]``): such a loop can be
        run as consecutive shorter loops, which lets a run switch tier at a step boundary."""
        if self._split is False:
            import inspect

            names = list(inspect.signature(getattr(self.module.interpreted, self.name)).parameters)
            wanted = ("t", "dt", "n_steps", "info")
            self._split = tuple(names.index(w) for w in wanted) if all(w in names for w in wanted) else None  # type: ignore[assignment]
        return self._split  # type: ignore[return-value]

    def _part(self, args: tuple[Any, ...], done: int, count: int, compiled: bool | str) -> tuple[float, bool]:
        """Steps ``done .. done + count`` of the loop ``args`` on the road ``compiled``
        (True or ``"compiled"``, ``"tape"``, False or ``"interpreted"``): (evaluations, failed).
        A tape machine that stops on an error (a division by zero, a math domain error: where
        Python raises) leaves the arguments as they were; the part is then run interpreted,
        which does what it always does there, and the tape is not used again."""
        t, dt, n, info = self._split_positions()  # type: ignore[misc]
        part = list(args)
        part[t] = args[t] + done * args[dt] if done else args[t]
        part[n] = count
        if compiled is True or compiled == "compiled":
            self._compiled(*part)  # type: ignore[misc]
        elif compiled == "tape":
            tape = self.module.tape_function(self.name)
            assert tape is not None
            start = time.process_time()
            try:
                tape(*part)
            except TapeError:
                self.on_tape = False
                self.tape_failed = True
                self._interpreted_call(count, tuple(part))
            else:
                if count >= TAPE_RATE_STEPS:  # a call's own cost (the copies in and out) would swamp a shorter part's rate
                    self.tape_seconds += time.process_time() - start
                    self.tape_steps += count
        else:
            self._interpreted_call(count, tuple(part))
        return float(args[info][2]), bool(args[info][1] != 0.0)

    def _split_run(self, steps: int, planned: int | None, args: tuple[Any, ...]) -> None:
        """The loop ``args`` of ``steps`` steps in parts: one interpreted step first when
        no interpreted time per step is known yet, then parts of about
        :data:`CHECK_SECONDS` interpreted while a background compilation runs, the rest
        compiled as soon as it is done (or all interpreted when compiling does not pay)."""
        info = args[self._split_positions()[3]]  # type: ignore[index]
        done, evaluations = 0, 0.0
        while done < steps:
            if self._compiled is None:
                self._decide(planned if planned is None else max(planned - done, steps - done), args)
            count = steps - done
            road = self.tier
            if road == "interpreted":
                per_step = self.seconds_per_step()
                if per_step is None:
                    count = 1
                elif self.background is not None:
                    count = max(1, min(count, int(CHECK_SECONDS / max(per_step, 1e-9))))
            elif road == "tape" and self.tape_steps < TAPE_PROBE_STEPS:
                count = min(count, TAPE_PROBE_STEPS)  # a first part measures the tape's rate
            used, failed = self._part(args, done, count, road)
            evaluations += used
            if failed:
                info[0] += done
                info[2] = evaluations
                return
            done += count
        info[0] = steps
        info[2] = evaluations

    def _decide(self, planned: int | None, args: tuple[Any, ...]) -> None:
        """Switch to the tape or the compiled form when it is ready or pays (see :meth:`run_steps`)."""
        if self.tier == "compiled":
            return
        if self.on_tape:
            if current_policy() == "compiled":
                self.compile("DIRAC_KERNELS=compiled", args)
                return
            tape = self.tape_estimate(planned, args)
            if tape is not None and tape <= WAIT_FACTOR * self.compile_floor():
                return  # within what any compilation costs: the estimate (a parse of the module) is not read
            if self._tape_compile_estimate is None:  # read once: the history of the cache is a file
                self._tape_compile_estimate = self.compile_estimate()
            estimate = self._tape_compile_estimate
            if tape is None or tape > WAIT_FACTOR * estimate:  # a longer run than the tape was taken for
                self.on_tape = False
                self.compile(f"about {planned} steps to go, {tape or math.inf:.1f} s on the tape machine, about "
                             f"{estimate:.1g} s to compile", args)
            return
        if current_policy() == "compiled":
            self.compile("DIRAC_KERNELS=compiled", args)
            return
        if self.background is not None:
            state = self.background.poll()
            if state is None:
                return
            self.background = None
            if state and is_compiled_or_cached(getattr(self.module.compiled, self.name)):
                self._compiled = getattr(self.module.compiled, self.name)
                return
            self.background_failed = True
            return
        per_step = self.seconds_per_step()
        if per_step is None:
            return
        remaining = math.inf if planned is None else per_step * planned
        if remaining <= COMPILE_SECONDS:
            # no compilation pays; the tape does when the machine costs nothing to get (compiled
            # at the install, or loaded in this process) and it saves more than its translation,
            # which is paid once: a loop called again and again for short runs (the pilots of
            # auto) translates once it has spent that long interpreted (the rent-or-buy rule),
            # the translation's price estimated from the loop's own text: at the fixed 0.1 s, the
            # pilots of a double pendulum in angles ran 0.1 s interpreted before a translation of
            # 25-30 ms, and auto's pilots took 0.27 s of CPU where they take 0.17 with the estimate
            # (a pilot whose longer run follows, :meth:`expect_longer_run`, counts the price as paid)
            translation = self.translate_estimate()
            bought = self.longer_run_follows or self.interpreted_seconds >= translation
            if machine_loaded() and (remaining > translation or bought):
                translated = self.name in self.module._tapes
                cost = 0.0 if translated or bought else translation
                tape = self.tape_estimate(planned, args)
                if tape is not None and tape + cost < remaining:
                    self.on_tape = True
            return
        tape = self.tape_estimate(planned, args)
        if tape is not None and tape + TAPE_TRANSLATE_SECONDS < remaining and tape <= self.compile_floor() \
                and machine_loaded():
            # choose_road's tape, whatever the compilation's estimate: it is never below the floor
            # (read without parsing the module; the machine is there, so no compilation to announce)
            machine(f"about {planned} steps to go, {remaining:.1f} s interpreted", announce_compilation)
            self.on_tape = True
            return
        estimate = self.compile_estimate()
        background = None
        if estimate < remaining <= WAIT_FACTOR * estimate and background_enabled() and not self.background_failed \
                and spare_core():
            background = self.background_estimate()
        road = choose_road(remaining, estimate, background, tape)
        if road == "tape":
            machine(f"about {planned} steps to go, {remaining:.1f} s interpreted, about {estimate:.1g} s to compile "
                    f"{self.name}", announce_compilation)
            self.on_tape = True
        elif road == "compile":
            self.compile(f"about {planned} steps to go, {remaining:.1f} s interpreted, about {estimate:.1g} s to "
                         "compile", args)
        elif road == "background":
            announce_compilation(f"{self.name} of {self.module.title}",
                                 f"in a separate process, about {background:.1g} s, while the run goes "
                                 f"on interpreted ({'an unknown number of' if planned is None else planned} steps to go)")
            path = source_path(self.module.source)
            if not path.exists():  # the file numba compiles from, written without importing it
                write_source(self.module.source)
            self.background = BackgroundCompile(path, self.name, args, self.kernel_chars())

    def run_steps(self, steps: int, planned: int | None, *args: Any) -> Any:
        """Call a step loop advancing ``steps`` steps, of ``planned`` steps still to come
        (these included; None: unknown).

        Interpreted while the interpreted time of what is planned (measured seconds per
        step times ``planned``) stays below :data:`COMPILE_SECONDS`. Beyond it the price
        of each road is compared with the estimated compile time ``E``
        (:func:`~dirac.codegen.background.estimate_compile_seconds`, from the size of the
        kernel and the measured history): when the interpreted remainder exceeds
        :data:`WAIT_FACTOR` ``* E`` (a run of unknown length included), the function is
        compiled in this process at once, the shortest wait. Between ``E`` and that, a loop
        that can be split (arguments ``t, dt, n_steps, info``) is compiled in a separate
        process (:class:`~dirac.codegen.background.BackgroundCompile`) while it goes on
        interpreted, and switches to the compiled form at the first step boundary after
        the compilation is done (such a run never waits for the compiler), when a core is
        idle (:func:`spare_core`) and that road is expected to end the run sooner than the
        interpreter (:meth:`background_estimate` below the remainder); otherwise it compiles
        in this process. The whole table is :func:`choose_road`. Other loops, or with
        ``DIRAC_BACKGROUND_COMPILE=0``, compile in this process when the interpreted time
        still to come exceeds ``E``.
        """
        if self.tier != "compiled" and self._split_positions() is not None:
            return self._split_run(steps, planned, args)
        if self.tier == "interpreted":
            per_step = self.seconds_per_step()
            if current_policy() == "compiled":
                self.compile("DIRAC_KERNELS=compiled", args)
            elif planned is None:
                self.compile("a run of unknown length", args)
            elif per_step is not None and per_step * planned > COMPILE_SECONDS \
                    and choose_road(per_step * planned, self.compile_estimate(), None) == "compile":
                self.compile(f"about {planned} steps to go, {per_step * planned:.1f} s interpreted", args)
            elif per_step is None and steps > 1:
                # no estimate yet: one interpreted step first would need a split of the call
                self.compile(f"a run of {planned} steps", args)
        if self._compiled is not None:
            return self._compiled(*args)
        return self._interpreted_call(steps, args)

    def warm_up(self, planned: int | None, *args: Any) -> None:
        """Calls on scratch arguments before a run of ``planned`` steps: measure the interpreted
        time per step and decide the tier (before the run's clock starts).

        The first interpreted call of a function is cold (the interpreter specialises its
        bytecode, first lookups, first numpy calls: 77 ms where the next one-step call took
        0.1 ms, the symmetric top in Euler angles), and each call has its own cost on top of
        its steps (copies of the state, the floating-point error state: about 60 us, the size
        of a step of such a system). Timed as the rate, they made a 2e4-step run of that top,
        1 s interpreted, look like 5 s and wait 3 s for the compiler. The next tens of steps
        are still slow while the interpreter specialises the loop (the triple pendulum in
        angles: 65-71 us a step, then 46-51 us), which put its 1e5-step study at 7.2 s
        interpreted (4.6-5.1 s at the warm rate) and sent it to a background compilation. So the
        cold call and :data:`WARM_UP_UNTIMED_STEPS` steps after it are left out of the rate,
        and the rate is measured on a call of :data:`WARM_UP_STEPS` steps (a split loop; a
        loop that cannot be split measures its one-step call); for a run of fewer than 512
        steps each is an eighth of it at most (a short run's rate decides little)."""
        if self.tier == "interpreted" and current_policy() == "auto" and planned is not None and self.seconds_per_step() is None:
            seconds, steps = self.interpreted_seconds, self.interpreted_steps
            self._interpreted_call(1, args)
            # a short run spends at most about a quarter more on scratch steps (its rate matters little)
            untimed, timed = min(WARM_UP_UNTIMED_STEPS, planned // 8), min(WARM_UP_STEPS, max(1, planned // 8))
            if self._split_positions() is not None and untimed:
                self._part(args, 0, untimed, compiled=False)
            self.interpreted_seconds, self.interpreted_steps = seconds, steps  # the cold steps: not the rate
            if self._split_positions() is not None:
                self._part(args, 0, timed, compiled=False)
            else:
                self._interpreted_call(1, args)
        self.run_steps(1, planned, *args)

    def finish_background(self, timeout: float | None = None) -> bool | None:
        """Wait for a background compilation of this function (tests, benchmarks): True
        when it filled the cache, False when it failed, None when none ran or it is still running."""
        if self.background is None:
            return None
        return self.background.wait(timeout)


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
