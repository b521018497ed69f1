"""Helpers of the ensemble tests: a scene file from its four tables, the arrays of a finished
store, and ``dirac ensemble`` run as a user runs it (one place, so that the test files agree)."""

from __future__ import annotations

import subprocess
import sys
from pathlib import Path

import numpy as np
import zarr


def damped_pendulum(forcing: float) -> str:
    """The system file of a damped pendulum driven by ``F cos(w t)`` with ``F = forcing``
    (``th'' = -g sin th - c th' + F cos(w t)``; ``g = 9.81``, ``c = 0.5``, ``w = 1``)."""
    return f"""[system]
name = "damped_pendulum_angle"
coordinates = ["th"]
parameters = {{ g = 9.81, c = 0.5, F = {forcing!r}, w = 1.0 }}
lagrangian = "th_dot**2/2 + g*cos(th)"
forces = {{ th = "-c*th_dot + F*cos(w*t)" }}
"""


def scene_file(tmp_path: Path, system: str, initial: str, run: str, ensemble: str, name: str = "scene.toml") -> Path:
    """``name`` in ``tmp_path`` holding ``system`` (with its header) and the other tables' bodies."""
    path = tmp_path / name
    path.write_text(f"{system}\n[initial]\n{initial}\n[run]\n{run}\n[ensemble]\n{ensemble}\n")
    return path


def stored_arrays(out: Path) -> dict[str, np.ndarray]:
    """Every array of the store written to ``out``, by name."""
    group = zarr.open_group(str(out / "data.zarr"), mode="r")
    return {name: np.asarray(group[name][:]) for name in group.array_keys()}


def run_ensemble_cli(scene: Path, out: Path) -> subprocess.CompletedProcess:
    """``python -m dirac ensemble SCENE --out OUT --no-progress`` in a fresh process."""
    return subprocess.run([sys.executable, "-m", "dirac", "ensemble", str(scene), "--out", str(out), "--no-progress"],
                          capture_output=True, text=True, timeout=300)
