"""The model layer freezes the objects of sympy's import once (``dirac.model.permanent``):
checked in fresh interpreters, since the test process has frozen them already."""

from __future__ import annotations

import json
import os
import subprocess
import sys

_PROBE = r'''
import gc, json, weakref
import dirac.model.lagrangian
from dirac.model.permanent import freeze_imports
frozen = gc.get_freeze_count()
again = freeze_imports()

class Node:
    pass

a, b = Node(), Node()
a.other, b.other = b, a  # a cycle made after the freeze
probe = weakref.ref(a)
del a, b
gc.collect()
print(json.dumps({"frozen": frozen, "again": again, "cycle_collected": probe() is None}))
'''


def _probe(**environment: str) -> dict:
    env = dict(os.environ, **environment)
    done = subprocess.run([sys.executable, "-c", _PROBE], capture_output=True, text=True, env=env, timeout=300)
    assert done.returncode == 0, done.stderr
    return json.loads(done.stdout.strip().splitlines()[-1])


def test_sympys_objects_are_frozen_once_and_later_garbage_is_still_collected():
    """After ``import dirac.model.lagrangian`` the objects alive (sympy's import: far more than
    ten thousand) are in the permanent generation; a second call does nothing; a reference
    cycle made afterwards is still collected by the cyclic collector."""
    result = _probe(DIRAC_GC_FREEZE="1")
    assert result["frozen"] > 10_000
    assert result["again"] is False
    assert result["cycle_collected"] is True


def test_the_freeze_can_be_turned_off():
    """``DIRAC_GC_FREEZE=0``: nothing is frozen."""
    result = _probe(DIRAC_GC_FREEZE="0")
    assert result["frozen"] == 0
    assert result["cycle_collected"] is True
