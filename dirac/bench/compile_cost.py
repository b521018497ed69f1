"""Where the cold compilation of a generated step loop goes.

For each system, a fresh Python process with an empty cache of generated code
(``DIRAC_CACHE_DIR``) and an empty numba cache (``NUMBA_CACHE_DIR``) builds the system's
generated module (:class:`dirac.flows.mechanics.MechanicalSystem`), then measures in CPU
seconds (user + system of the process, :func:`time.process_time`), one part after the other:

* ``import numba``;
* numba's first compilation in the process (a function ``x + 1.0``): its registries of
  typing and lowering, the reference-counting runtime, and the import of ``scipy.linalg``
  that numba makes to learn whether a BLAS is there (``scipy_linalg_before`` says whether it
  was imported before: the engine's own imports did not need it);
* the step loop itself (``rattle_general`` of a configuration-dependent mass,
  ``rattle_constant_mass`` otherwise), compiled for the argument types a run passes, with
  numba's compilations of library code it needs on the way (``np.empty`` for a shape,
  ``min``, a separately compiled solve), each timed by numba's own compile events
  (:mod:`numba.core.event`);

and counts what numba is given: the statements and blocks of numba's IR of the loop
(:func:`numba.core.compiler.run_frontend`, before any rewriting) and the characters of the
loop and what it calls (:func:`dirac.codegen.background.kernel_chars`, the tier policy's
measure). The compile time of these loops is close to a fixed cost per IR statement
(about 1.5-2 ms on the machine of docs/performance.md), whatever the statement does.

The systems are those of ``dirac_systems.latency_models`` and N-link pendulums in their
angles (``n_link_pendulum_N``: unit masses and rods, ``M_ij = (N - max(i, j)) cos(q_i - q_j)``),
the configuration-dependent masses up to six degrees of freedom.

The module imports only the standard library and the latency bench's environment of a cold child
(:func:`dirac.bench.latency.cold_environment`): the children import ``dirac`` and numba (and only what an
older checkout of the engine has too, so that ``pythonpath`` can time one side by side).
"""

from __future__ import annotations

import json
import subprocess
import sys
import tempfile
from collections.abc import Sequence
from typing import Any

from dirac.bench.latency import cold_environment

__all__ = ["measure_compile_cost", "format_compile_cost", "n_link_pendulum_text", "DEFAULT_SYSTEMS"]

#: the systems of the table: the tops in Euler angles and the triple pendulum (3 coordinates),
#: the double pendulum in angles, and N-link pendulums of 4 and 6 links
DEFAULT_SYSTEMS = ("symmetric_top_euler", "asymmetric_top_euler", "triple_pendulum_angles", "double_pendulum_angles",
                   "n_link_pendulum_4", "n_link_pendulum_6")


def n_link_pendulum_text(links: int) -> tuple[list[str], str]:
    """Coordinates and Lagrangian text of a planar pendulum of ``links`` unit masses on unit
    rods in its angles (bob ``k`` at ``sum_{j <= k} (sin q_j, -cos q_j)``): ``T = 1/2 sum_ij
    (N - max(i, j)) cos(q_i - q_j) q_i' q_j'``, ``V = -g sum_k (N - k) cos q_k`` (indices from 0)."""
    names = [f"a{k}" for k in range(links)]
    terms = []
    for i in range(links):
        for j in range(i, links):
            weight = links - max(i, j)
            terms.append(f"{weight}/2*{names[i]}_dot**2" if i == j
                         else f"{weight}*{names[i]}_dot*{names[j]}_dot*cos({names[i]}-{names[j]})")
    potential = " + ".join(f"{links - k}*cos({names[k]})" for k in range(links))
    return names, " + ".join(terms) + f" + g*({potential})"


_CHILD = r'''
import json, sys, time
start = time.process_time()
import numpy as np
from dirac.codegen.background import kernel_chars
from dirac.flows.mechanics import MechanicalSystem
name = sys.argv[1]
if len(sys.argv) > 2:  # a Lagrangian given as text: coordinates, then the text
    from dirac import Lagrangian
    names, text = json.loads(sys.argv[2])
    system = MechanicalSystem.from_lagrangian(Lagrangian.from_strings(name, names, text, parameters={"g": 9.81}))
    n = len(names)
    q, p = np.linspace(0.2, 0.7, n), np.zeros(n)
else:
    from dirac_systems.latency_models import MODELS
    model = MODELS[name]()
    system = MechanicalSystem.from_lagrangian(model.system)
    n = system.dimension
    q, p = np.array(model.state[:n], dtype=float), np.array(model.state[n:2 * n], dtype=float)
kernel = "rattle_general" if system.constant_mass is None else "rattle_constant_mass"
source = system.module.source
prepared = time.process_time()
scipy_before = "scipy.linalg" in sys.modules
import numba
imported = time.process_time()
@numba.njit
def _first(x):
    return x + 1.0
_first(1.0)
first = time.process_time()
from dirac.codegen.numba_backend import import_source
module = import_source(source)
dispatcher = getattr(module, kernel)
args = (q, p, 0.0, np.asarray(system.params, dtype=float), np.ones(1), 1e-3, 10, 1e-12, 50, np.zeros(4))
nested = []
from numba.core import event
class _Listener(event.Listener):
    def __init__(self):
        self.open = []
    def on_start(self, e):
        self.open.append(time.process_time())
    def on_end(self, e):
        seconds = time.process_time() - self.open.pop()
        what = e.data.get("dispatcher") if e.data else None
        label = getattr(getattr(what, "py_func", None), "__qualname__", str(what))
        if len(self.open) == 1:  # compiled for the loop itself (their own callees are in their seconds)
            nested.append([label.split(".<locals>")[0], round(seconds, 4)])
loaded = time.process_time()
with event.install_listener("numba:compile", _Listener()):
    dispatcher.compile(tuple(numba.typeof(a) for a in args))
compiled = time.process_time()
from numba.core.compiler import run_frontend
ir = run_frontend(dispatcher.py_func)
statements = sum(len(block.body) for block in ir.blocks.values())
times = {}
for result in dispatcher.overloads.values():
    for pipeline in result.metadata.get("pipeline_times", {}).values():
        for pass_name, record in pipeline.items():
            times[pass_name.split("_", 1)[1]] = times.get(pass_name.split("_", 1)[1], 0.0) + record.run
json.dump({"system": name, "n": n, "kernel": kernel, "chars": kernel_chars(source, kernel),
           "statements": statements, "blocks": len(ir.blocks), "prepare": prepared - start,
           "import_numba": imported - prepared, "first_compile": first - imported, "scipy_linalg_before": scipy_before,
           "kernel_compile": compiled - loaded, "nested": nested, "pass_seconds": times}, sys.stdout)
'''


def _child(system: str, pythonpath: str | None = None) -> dict[str, Any]:
    with tempfile.TemporaryDirectory(prefix="dirac-compile-cost-") as scratch:
        environment = cold_environment(scratch, pythonpath)  # the default policy: building the system compiles nothing
        given = [json.dumps(n_link_pendulum_text(int(system.rsplit("_", 1)[1])))] \
            if system.startswith("n_link_pendulum_") else []
        done = subprocess.run([sys.executable, "-c", _CHILD, system, *given], capture_output=True, text=True,
                              env=environment, cwd=scratch, check=False)
    if done.returncode != 0:
        raise RuntimeError(f"the compile-cost child of {system} failed: {done.stderr.strip().splitlines()[-1:]}")
    return dict(json.loads(done.stdout.strip().splitlines()[-1]))


def measure_compile_cost(systems: Sequence[str] = DEFAULT_SYSTEMS, pythonpath: str | None = None) -> list[dict[str, Any]]:
    """One fresh process with empty caches per system (see the module docstring); its row.

    Parameters
    ----------
    systems : sequence of str
        Names of ``dirac_systems.latency_models.MODELS`` or ``n_link_pendulum_N``.
    pythonpath : str or None
        A checkout put first on the children's path (to time another version of the engine
        side by side).

    Returns
    -------
    list of dict
        Per system: ``n``, ``kernel``, ``chars``, ``statements``, ``blocks`` and the CPU
        seconds ``import_numba``, ``first_compile``, ``kernel_compile`` (with ``nested``: the
        library functions numba compiled on the way, with their seconds) and
        ``pass_seconds`` (numba's own timing of each pass of the loop's pipeline, wall clock).
    """
    return [_child(system, pythonpath) for system in systems]


def format_compile_cost(rows: Sequence[dict[str, Any]]) -> str:
    """The rows of :func:`measure_compile_cost` as a table (CPU seconds)."""
    lines = [f"{'system':<26} {'n':>2} {'kernel':<20} {'chars':>6} {'IR stmts':>8} {'blocks':>6} "
             f"{'numba import':>12} {'first':>6} {'kernel s':>8} {'ms/stmt':>7} {'nested s':>8}  passes (share of the loop's)"]
    for row in rows:
        nested = sum(seconds for _, seconds in row["nested"])
        passes = row["pass_seconds"]
        total = sum(passes.values()) or 1.0
        shares = sorted(passes.items(), key=lambda item: -item[1])[:3]
        lines.append(f"{row['system']:<26} {row['n']:>2} {row['kernel']:<20} {row['chars']:>6} {row['statements']:>8} "
                     f"{row['blocks']:>6} {row['import_numba']:>12.2f} {row['first_compile']:>6.2f} "
                     f"{row['kernel_compile']:>8.2f} {1e3 * (row['kernel_compile'] - nested) / row['statements']:>7.2f} "
                     f"{nested:>8.2f}  " + ", ".join(f"{name} {value / total:.0%}" for name, value in shares))
    lines.append("CPU seconds of a fresh process with empty caches; 'first': numba's first compilation in the process "
                 "(its registries, its import of scipy.linalg); 'kernel s': the loop, with 'nested' (library code numba "
                 "compiled on the way: np.empty, min, a separate solve); ms/stmt: the loop's own seconds per statement of "
                 "numba's IR.")
    return "\n".join(lines)
