"""The documentation builds with Sphinx, warnings treated as errors."""

from __future__ import annotations

import subprocess
import sys
from pathlib import Path

ROOT = Path(__file__).resolve().parents[2]


def test_sphinx_build_is_warning_free(tmp_path: Path) -> None:
    command = [
        sys.executable, "-m", "sphinx", "-W", "--keep-going", "-q", "-b", "html",
        "-d", str(tmp_path / "doctrees"), str(ROOT / "docs"), str(tmp_path / "html"),
    ]
    done = subprocess.run(command, capture_output=True, text=True, timeout=300, check=False)
    assert done.returncode == 0, f"sphinx-build failed:\n{done.stderr[-6000:]}"
    html = tmp_path / "html"
    for page in sorted((ROOT / "docs").glob("*.md")):
        assert (html / f"{page.stem}.html").is_file(), f"{page.name} was not built"


def test_every_embedded_image_exists() -> None:
    import re

    for page in (ROOT / "docs").glob("*.md"):
        for target in re.findall(r"!\[[^\]]*\]\(([^)\s]+)", page.read_text(encoding="utf-8")):
            if "://" in target:
                continue
            image = (page.parent / target).resolve()
            assert image.is_file() and image.stat().st_size > 0, f"{page.name} embeds missing image {target}"
