"""Regenerate the pictures of the documentation from real runs.

Run from the repository root::

    python docs/images/make_images.py

Each picture is drawn by the same command a reader types (the commands are printed
as they run); ``work_precision.png`` and ``flip_times.png`` are made by ``dirac bench``
and ``dirac ensemble`` (see performance.md and ensembles.md), not here.
"""

from __future__ import annotations

import re
import shutil
import sys
import tempfile
from pathlib import Path

from dirac.cli import main

IMAGES = Path(__file__).resolve().parent
DOCS = IMAGES.parent


def page_files(page: Path) -> dict[str, str]:
    """The files a page writes: a ``<!-- file: NAME -->`` line, then a fenced block."""
    files: dict[str, str] = {}
    lines = page.read_text(encoding="utf-8").splitlines()
    for k, line in enumerate(lines):
        match = re.match(r"<!--\s*file:\s*(\S+)\s*-->", line.strip())
        if match and k + 1 < len(lines) and lines[k + 1].startswith("```"):
            end = next(e for e in range(k + 2, len(lines)) if lines[e].startswith("```"))
            files[match.group(1)] = "\n".join(lines[k + 2:end]) + "\n"
    return files


def run(*argv: str) -> None:
    print("$ dirac", " ".join(argv), flush=True)
    status = main(list(argv))
    if status != 0:
        sys.exit(f"'dirac {' '.join(argv)}' failed with status {status}")


def make_all() -> None:
    with tempfile.TemporaryDirectory() as scratch:
        work = Path(scratch)
        run("demo", "--no-progress", "--out", str(work / "demo.npz"), "--plot", str(IMAGES / "demo.png"))
        run("run", str(DOCS / "scenes" / "pendulum.toml"), "--no-progress", "--out", str(work / "pendulum.npz"),
            "--plot", str(IMAGES / "pendulum.png"))
        run("run", str(DOCS / "scenes" / "rigid_body_splitting.toml"), "--no-progress", "--out",
            str(work / "racket.npz"), "--plot", str(IMAGES / "tennis_racket.png"))
        run("run", str(DOCS / "scenes" / "heavy_top.toml"), "--no-progress", "--out", str(work / "top.npz"),
            "--plot", str(IMAGES / "heavy_top.png"))
        run("run", str(DOCS / "scenes" / "satellite_despin.toml"), "--no-progress", "--out",
            str(work / "satellite.npz"), "--plot", str(IMAGES / "satellite_despin.png"))
        run("run", str(DOCS / "scenes" / "top_friction.toml"), "--no-progress", "--out", str(work / "friction.npz"),
            "--plot", str(IMAGES / "top_friction.png"))
        for name, text in page_files(DOCS / "tutorial.md").items():  # bead.toml, bead_scene.toml
            (work / name).write_text(text, encoding="utf-8")
        run("run", str(work / "bead_scene.toml"), "--no-progress", "--out", str(work / "bead.npz"),
            "--plot", str(IMAGES / "bead.png"))
        shutil.rmtree(work, ignore_errors=True)
    poincare_section(IMAGES / "poincare.png")


def poincare_section(path: Path, periods: int = 20000) -> None:
    """The Poincare section of the chaotic driven damped pendulum of forces.md: the same
    system and method as the page's Python block, with ``periods`` drive periods."""
    import math

    import numpy as np

    import dirac
    from dirac.plots.canvas import new_figure

    print(f"poincare section of the driven pendulum, {periods} periods (docs/forces.md)", flush=True)
    driven = dirac.Lagrangian.from_strings(
        "driven_pendulum", ["x", "y"], "m/2*(x_dot**2 + y_dot**2) - m*g*y",
        constraints=["x**2 + y**2 - l**2"],
        parameters={"m": 1.0, "g": 1.0, "l": 1.0, "c": 0.5, "A": 1.5, "w": 2 / 3},
        forces={"x": "-c*x_dot - A*cos(w*t)*y/l**2", "y": "-c*y_dot + A*cos(w*t)*x/l**2"})
    period = 2 * math.pi / (2 / 3)
    problem = dirac.ForcedProblem(driven, [0.0, -1.0], [0.0, 0.0])
    run = dirac.integrate(problem, "forced-rattle-2", t_end=periods * period, dt=period / 400,
                          samples=periods + 1, outputs=["q", "q_dot"])
    x, y = run.outputs["q"][100:].T
    vx, vy = run.outputs["q_dot"][100:].T
    theta, omega = np.arctan2(x, -y), x * vy - y * vx
    fig = new_figure(8.0, 6.0)
    ax = fig.add_subplot(1, 1, 1)
    ax.plot(theta, omega, ",", color="tab:blue", alpha=0.8)
    ax.set_xlabel(r"angle $\theta$ (rad), once per drive period $2\pi/\omega$")
    ax.set_ylabel(r"angular velocity $\dot\theta$ (rad per unit time)")
    ax.set_title(r"Driven damped pendulum, $c = 0.5$, $A = 1.5$, $\omega = 2/3$: Poincaré section "
                 f"({theta.size} points, forced-rattle-2)", fontsize=10)
    ax.grid(True, alpha=0.3)
    fig.savefig(path, dpi=110)


if __name__ == "__main__":
    make_all()
