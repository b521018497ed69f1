"""Pictures of runs: the conserved-quantity errors are right and the PNG files are real."""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np
import pytest

from dirac.errors import InputError
from dirac.plots import conserved_quantity_errors, plot_result, result_figure, save_png
from dirac.plots.canvas import check_png_path
from dirac.plots.constrained import constrained_errors

PNG_SIGNATURE = b"\x89PNG\r\n\x1a\n"


def _rotation_z(angle: float) -> np.ndarray:
    c, s = np.cos(angle), np.sin(angle)
    return np.array([[c, -s, 0.0], [s, c, 0.0], [0.0, 0.0, 1.0]])


def _steady_rotation(samples: int = 21) -> dict[str, object]:
    """Paper (165): M = (0, 0, m3), R(t) = rotation about z by w t, w = m3 / I3."""
    inertia, m3 = np.array([2.0, 1.5, 1.0]), 0.8
    t = np.linspace(0.0, 5.0, samples)
    M = np.tile([0.0, 0.0, m3], (samples, 1))
    R = np.stack([_rotation_z(m3 / inertia[2] * s) for s in t])
    meta = {"system": "rigid_body", "parameters": {"inertia": inertia.tolist()}, "method": "exact", "order": 0}
    return {"t": t, "M": M, "R": R, "meta": json.dumps(meta)}


def _assert_png(path: Path, min_bytes: int = 20_000) -> None:
    data = path.read_bytes()
    assert data[:8] == PNG_SIGNATURE
    assert len(data) > min_bytes
    from matplotlib.image import imread

    height, width = imread(path).shape[:2]
    assert width >= 800 and height >= 600


def test_errors_of_an_exact_solution_are_zero() -> None:
    result = _steady_rotation()
    inertia = json.loads(result["meta"])["parameters"]["inertia"]
    errors = conserved_quantity_errors(result["t"], result["M"], result["R"], inertia)
    assert len(errors) == 4
    for values in errors.values():
        assert np.max(values) < 1e-15


def test_errors_measure_what_their_labels_say() -> None:
    inertia = np.array([2.0, 1.0, 0.5])
    t = np.array([0.0, 1.0])
    M = np.array([[1.0, 0.0, 0.0], [1.1, 0.0, 0.0]])  # |M| grows by 10 %
    R = np.stack([np.eye(3), 2.0 * np.eye(3)])  # not a rotation at t = 1
    errors = list(conserved_quantity_errors(t, M, R, inertia).values())
    energy, casimir, lab, orthogonality = (e[1] for e in errors)
    assert energy == pytest.approx(0.21)  # (1.1^2 - 1) / 1
    assert casimir == pytest.approx(0.21)
    assert lab == pytest.approx(1.2)  # |2.2 - 1| / 1
    assert orthogonality == pytest.approx(3.0 * np.sqrt(3.0))  # ||4 I - I||_F
    assert all(e[0] == 0.0 for e in errors)


def test_constrained_errors_use_absolute_energy_when_it_starts_at_zero() -> None:
    errors = constrained_errors(np.array([0.0, 1e-3]), np.array([0.0, -2e-9]))
    (energy_label, energy), (_, residual) = errors.items()
    assert "E_0=0" in energy_label and energy[1] == pytest.approx(1e-3)
    assert residual[1] == pytest.approx(2e-9)


def test_rigid_body_result_draws_a_png(tmp_path: Path) -> None:
    target = plot_result(_steady_rotation(), tmp_path / "steady.png")
    _assert_png(target)


def test_constrained_result_draws_a_png(tmp_path: Path) -> None:
    # a pendulum of length 1 swinging with the small-angle law (a picture test, not physics)
    t = np.linspace(0.0, 4.0, 81)
    theta = 0.3 * np.cos(np.sqrt(9.81) * t)
    q = np.stack([np.sin(theta), -np.cos(theta)], axis=1)
    result = {
        "t": t, "q": q, "energy": -9.81 * np.cos(0.3) + 1e-6 * np.sin(t), "constraint_residual": 1e-12 * t,
        "meta": {"system": "pendulum", "method": "rattle-2", "order": 2, "dt": 0.01, "steps": 400,
                 "coordinates": ["x", "y"]},
    }
    fig = result_figure(result)
    assert [ax.get_xlabel() for ax in fig.axes[:2]] == ["$x$ (system units)", "time $t$ (system units)"]
    _assert_png(save_png(fig, tmp_path / "pendulum.png"))


def test_a_batched_result_is_drawn_for_its_first_state(tmp_path: Path) -> None:
    result = _steady_rotation(5)
    result["M"] = np.stack([result["M"], 2.0 * result["M"]], axis=1)  # (samples, batch, 3)
    result["R"] = np.stack([result["R"], result["R"]], axis=1)
    fig = result_figure(result)
    assert "0.8" in fig.get_suptitle()  # M(0) of the first body, not 1.6


def test_bad_targets_and_results_are_input_errors(tmp_path: Path) -> None:
    with pytest.raises(InputError, match=r"\.png"):
        check_png_path(tmp_path / "motion.jpg")
    with pytest.raises(InputError, match="does not exist"):
        check_png_path(tmp_path / "no-such-folder" / "motion.png")
    no_inertia = dict(_steady_rotation(3), meta="{}")
    with pytest.raises(InputError, match="inertia"):
        result_figure(no_inertia)
    with pytest.raises(InputError, match="neither 'M'"):
        result_figure({"t": np.zeros(2), "energy": np.zeros(2)})
    with pytest.raises(InputError, match=r"shape \(3, 3\)"):
        result = _steady_rotation(3)
        result["M"] = result["M"][:, :2]
        result_figure(result)
