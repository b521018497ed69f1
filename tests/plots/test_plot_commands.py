"""``dirac run SCENE --plot FILE`` and ``dirac demo --plot FILE`` draw real pictures (PNG, PDF, SVG, ...).

(``dirac bench --plot`` is checked in tests/bench/test_bench_command.py.)
"""

from __future__ import annotations

from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[2]
PNG_SIGNATURE = b"\x89PNG\r\n\x1a\n"

SMALL_BODY = """[system]
name = "rigid_body"
inertia = [2.0, 1.5, 1.0]

[initial]
M = [0.3, 0.6, -0.9]

[run]
t_end = 20.0
method = "lie-poisson-4"
dt = 0.05
samples = 81
outputs = ["M", "R", "energy"]
"""


def _assert_picture(path: Path) -> None:
    from matplotlib.image import imread

    data = path.read_bytes()
    assert data[:8] == PNG_SIGNATURE, f"{path} is not a PNG file"
    assert len(data) > 20_000, f"{path} is suspiciously small ({len(data)} bytes)"
    height, width = imread(path).shape[:2]
    assert width >= 800 and height >= 600


def test_run_plot_draws_a_constrained_system(run_cli, tmp_path: Path) -> None:
    picture = tmp_path / "pendulum.png"
    status, out, err = run_cli("run", str(ROOT / "docs" / "scenes" / "pendulum.toml"), "--out",
                               str(tmp_path / "pendulum.npz"), "--plot", str(picture), "--no-progress")
    assert status == 0, err
    assert (tmp_path / "pendulum.npz").is_file()
    _assert_picture(picture)


def test_run_plot_draws_a_rigid_body(run_cli, tmp_path: Path) -> None:
    scene = tmp_path / "body.toml"
    scene.write_text(SMALL_BODY, encoding="utf-8")
    picture = tmp_path / "body.png"
    status, out, err = run_cli("run", str(scene), "--plot", str(picture), "--no-progress")
    assert status == 0, err
    _assert_picture(picture)


def test_demo_plot_draws_the_flagship(run_cli, tmp_path: Path) -> None:
    picture = tmp_path / "demo.png"
    status, out, err = run_cli("demo", "--t-end", "50", "--plot", str(picture), "--no-progress")
    assert status == 0, err
    assert "conserved quantities" in out
    _assert_picture(picture)


@pytest.mark.parametrize("command", [["demo"], ["run", str(ROOT / "docs" / "scenes" / "pendulum.toml")]])
def test_a_plot_suffix_matplotlib_cannot_write_is_refused_before_running(run_cli, tmp_path: Path, command) -> None:
    status, out, err = run_cli(*command, "--plot", str(tmp_path / "motion.xyz"), "--out", str(tmp_path / "x.npz"),
                               "--no-progress")
    assert status == 2
    assert err.startswith("error:") and ".xyz" in err
    for known in (".png", ".pdf", ".svg"):  # the message lists the formats that work
        assert known in err
    assert not (tmp_path / "x.npz").exists()  # failed fast: nothing was run


#: the first bytes of each format (PDF 1.7 section 7.5.2; SVG is XML with an <svg> root)
MAGIC = {".pdf": b"%PDF-", ".svg": b"<?xml", ".png": PNG_SIGNATURE}


@pytest.mark.parametrize("suffix", [".pdf", ".svg"])
def test_run_plot_writes_the_format_its_suffix_names(run_cli, tmp_path: Path, suffix: str) -> None:
    picture = tmp_path / f"pendulum{suffix}"
    status, out, err = run_cli("run", str(ROOT / "docs" / "scenes" / "pendulum.toml"), "--out",
                               str(tmp_path / "pendulum.npz"), "--plot", str(picture), "--no-progress")
    assert status == 0, err
    data = picture.read_bytes()
    assert data.startswith(MAGIC[suffix])
    if suffix == ".svg":
        assert b"<svg" in data[:2000]


def test_demo_plot_writes_svg(run_cli, tmp_path: Path) -> None:
    picture = tmp_path / "demo.svg"
    status, out, err = run_cli("demo", "--t-end", "20", "--plot", str(picture), "--no-progress")
    assert status == 0, err
    data = picture.read_bytes()
    assert data.startswith(MAGIC[".svg"]) and b"<svg" in data[:2000]
