"""Tennis-racket flip times against the separatrix asymptotics, and the flip-time plot."""

from __future__ import annotations

import numpy as np

from dirac.commands.ensemble_plot import main as plot_main
from dirac.ensemble.chunk import compute_chunk
from dirac.ensemble.engine import run_ensemble
from dirac.ensemble.plot import predicted_flip_time
from dirac.ensemble.scene import parse_ensemble_scene


def _deviation(inertia: list[float], axis: int, std: float) -> float:
    M0 = [0.0, 0.0, 0.0]
    M0[axis] = 2.0
    scene = parse_ensemble_scene(
        {
            "system": {"name": "rigid_body", "inertia": inertia},
            "initial": {"M": M0},
            "run": {"method": "lie-poisson-4", "dt": 0.01, "t_end": 40.0, "samples": 4001},
            "ensemble": {
                "count": 10,
                "seed": 5,
                "reductions": ["flip_time", "initial_state"],
                "M": {"distribution": "gaussian", "std": std, "norm": 2.0},
            },
        }
    )
    result = compute_chunk(scene, 0, 10)
    assert not np.isnan(result["flip_time"]).any()
    return float(np.max(np.abs(result["flip_time"] - predicted_flip_time(result["initial_M"], np.array(inertia)))))


def test_flip_time_follows_the_separatrix_asymptotics():
    # t_flip = ln(c / |u_0|) / lambda holds as |u_0| -> 0 with O(|u_0|^2) corrections, so
    # a 10x smaller cloud must shrink the deviation far more than 10x (about 100x; the
    # floor of sampling and splitting errors at dt = 0.01 is near 1e-6)
    coarse = _deviation([1.0, 2.0, 3.0], 1, 1e-2)
    fine = _deviation([1.0, 2.0, 3.0], 1, 1e-3)
    assert coarse < 1e-3
    assert fine < coarse / 30


def test_separatrix_prediction_for_an_anticyclic_order_of_the_moments():
    # smallest, middle, largest moment on axes 2, 1, 3: not a cyclic order, the sign of
    # the unstable direction flips; a wrong sign would miss by O(1)
    assert _deviation([2.0, 1.5, 3.0], 0, 1e-2) < 1e-3


def test_plot_command_writes_the_figure(tmp_path, capsys):
    scene = tmp_path / "flip.toml"
    scene.write_text(
        """
[system]
name = "rigid_body"
inertia = [1.0, 2.0, 3.0]
[initial]
M = [0.0, 1.0, 0.0]
[run]
method = "lie-poisson-2"
dt = 0.05
t_end = 20.0
samples = 201
[ensemble]
count = 100
reductions = ["flip_time", "initial_state"]
[ensemble.M]
distribution = "gaussian"
std = 0.01
norm = 1.0
"""
    )
    assert run_ensemble(scene, tmp_path / "run").complete
    image = tmp_path / "flip.png"
    assert plot_main([str(tmp_path / "run"), "--out", str(image)]) == 0
    assert image.read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"
    import zarr

    flipped = int(np.isfinite(zarr.open_group(str(tmp_path / "run" / "data.zarr"), mode="r")["flip_time"][:]).sum())
    assert 0 < flipped < 100  # t_end = 20 lies inside the distribution of flip times
    out = capsys.readouterr().out
    assert f"members = 100, flipped = {flipped}," in out and "max_deviation" in out


def test_plot_command_bad_input_exits_2(tmp_path, capsys):
    assert plot_main([str(tmp_path / "nothing"), "--out", str(tmp_path / "x.png")]) == 2
    err = capsys.readouterr().err
    assert err.startswith("error: ") and "holds no ensemble results" in err and len(err.splitlines()) == 1
