"""A short run of an everyday system pays for no import it does not use.

numba (about 0.4 s to import) and scipy are needed by the rigid-body kernels, the scipy
methods and compiled kernels; a short ``rattle`` run of a pendulum in its angle runs its
generated source interpreted and needs neither. The method registry still lists every
method (the rigid-body families import their numba kernels when a body runs).
"""

from __future__ import annotations

import json
import os
import subprocess
import sys

_CHILD = r"""
import json, sys
import dirac
from dirac.model.lagrangian import Lagrangian
from dirac.flows.methods.registry import METHODS
system = Lagrangian.from_strings("pendulum", ["th"], "th_dot**2/2 + 9.81*cos(th)")
run = dirac.integrate(dirac.ConstrainedProblem(system, q0=[1.0], p0=[0.0]), t_end=0.5, samples=3)
print(json.dumps({"numba": "numba" in sys.modules, "scipy": "scipy" in sys.modules,
                  "methods": sorted(METHODS), "method": run.method}))
"""


def test_a_short_constrained_run_imports_neither_numba_nor_scipy(tmp_path):
    env = dict(os.environ, DIRAC_CACHE_DIR=str(tmp_path / "dirac"), NUMBA_CACHE_DIR=str(tmp_path / "numba"))
    env.pop("DIRAC_KERNELS", None)
    done = subprocess.run([sys.executable, "-c", _CHILD], capture_output=True, text=True, env=env, timeout=300)
    assert done.returncode == 0, done.stderr
    result = json.loads(done.stdout.strip().splitlines()[-1])
    assert result["method"].startswith("rattle-")
    assert not result["numba"] and not result["scipy"]
    assert {"exact", "lie-poisson-4", "exact-kick-4", "midpoint", "scipy-DOP853"} <= set(result["methods"])
