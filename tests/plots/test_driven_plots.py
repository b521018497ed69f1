"""Pictures of rigid bodies driven by a torque: energy (not conserved), work, the balance E - W."""

from __future__ import annotations

from pathlib import Path

import numpy as np

from dirac.flows import integrate
from dirac.io.scene import load_scene
from dirac.plots import plot

ROOT = Path(__file__).resolve().parents[2]


def _labels(figure) -> list[str]:
    return [text.get_text() for ax in figure.axes if ax.get_legend() for text in ax.get_legend().get_texts()]


def test_a_torqued_run_shows_energy_work_and_the_error_of_their_difference(run_cli, tmp_path):
    scene = load_scene(ROOT / "docs" / "scenes" / "satellite_despin.toml")
    solution = integrate(scene.problem, **scene.run)
    figure = plot(solution)
    labels = _labels(figure)
    assert any("not conserved" in label and "energy" in label for label in labels)
    assert any("work" in label for label in labels)
    assert any("E-W" in label for label in labels)
    assert not any("polhode" in label for label in labels)  # the free body's picture means nothing here
    balance = [ax for ax in figure.axes if ax.get_yscale() == "log"]
    assert len(balance) == 1
    error = balance[0].get_lines()[0].get_ydata()
    assert np.max(error) < 1e-12  # exact-kick-*: E - W kept to round-off (tests/flows/test_torqued_rigid_body.py)
    picture = tmp_path / "satellite.png"
    status, _, err = run_cli("run", str(ROOT / "docs" / "scenes" / "satellite_despin.toml"), "--out",
                             str(tmp_path / "satellite.npz"), "--plot", str(picture), "--no-progress")
    assert status == 0, err
    assert picture.read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"
