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


if __name__ == "__main__":
    make_all()
