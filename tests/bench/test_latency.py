"""The latency corpus of ``dirac bench --latency`` in a tiny bounded form (not timed: the
machinery — fresh processes, empty caches, energy errors, the scipy baseline, the table —
checked against hand derivations of what the runs must conserve)."""

from __future__ import annotations

import math

import numpy as np
import pytest

from dirac.bench.latency import (
    CORPUS,
    LatencyRow,
    format_breakdown,
    format_latency,
    median_row,
    run_breakdown,
    run_latency,
    scipy_ratio,
    targets_met,
)
from dirac.bench.report import wrap_title
from dirac.errors import InputError
from dirac_systems.latency_models import MODELS


def test_every_corpus_name_is_a_model_and_every_model_in_the_corpus() -> None:
    assert set(CORPUS) == set(MODELS)


def test_a_tiny_corpus_runs_in_fresh_processes_and_conserves_energy() -> None:
    """Pendulum in its angle, first result over t = 0.05 with rattle-4 (default), a study of 50
    steps and the scipy baseline: RATTLE's energy error is O(dt^p) and bounded (Hairer, Lubich &
    Wanner IX.8), DOP853 at rtol 1e-8 keeps it below 1e-7 over so short a span."""
    rows = run_latency(["pendulum_angle"], first_t_end=0.05, study_steps=50, long_t_end=0.05, samples=3,
                       analyze=(), timeout=300)
    by_run = {(row.system, row.run.split(" ")[0]): row for row in rows}
    assert [row.failed for row in rows] == [""] * len(rows)
    first = by_run[("pendulum_angle", "first")]
    assert first.method.startswith("rattle-") and first.steps >= 1 and first.error is not None and first.error < 1e-6
    study = by_run[("pendulum_angle", "study")]
    assert study.method == "rattle-2" and study.steps == 50 and study.error is not None
    # rattle-2 at dt = 1e-3 on a pendulum of frequency sqrt(g/l): |dE/E| <= C (w dt)^2 with C < 1
    assert study.error < (math.sqrt(9.81) * 1e-3) ** 2
    baseline = by_run[("scipy pendulum", "t_end=0.05")]
    assert baseline.error is not None and baseline.error < 1e-7
    assert all(row.wall > 0 and row.cpu >= 0 for row in rows)
    table = format_latency(rows)
    assert "pendulum_angle" in table and "scipy pendulum" in table and "energy" in table


def test_the_breakdown_of_a_fresh_run_accounts_for_its_cpu_by_phase() -> None:
    """The pendulum in its angle over t = 0.5 with the default method: a fresh process that
    imports sympy to build its model and neither numba nor scipy (a short run stays
    interpreted and needs no scipy); the phases are CPU times (none below rounding, the model
    taking sympy's import: more than the interpreter's start) and add up to the child's CPU."""
    rows = run_breakdown(["pendulum_angle"], t_end=0.5, samples=3, timeout=300)
    assert [row.failed for row in rows] == [""]
    row = rows[0]
    assert row.method.startswith("rattle-") and row.steps >= 1
    assert row.modules == ["sympy"]
    assert all(value >= -0.02 for value in row.phases.values())
    assert row.phases["model (sympy, Lagrangian)"] > row.phases["interpreter start"]
    background = row.phases["background compilation (child)"]
    assert math.isclose(sum(row.phases.values()) - background, row.total, abs_tol=1e-9)
    table = format_breakdown(rows)
    assert "pendulum_angle" in table and "auto's pilot runs" in table


@pytest.mark.parametrize("name", ["bead_on_rotating_hoop", "double_pendulum_cartesian"])
def test_the_models_start_where_their_hand_derivation_says(name: str) -> None:
    """The Cartesian double pendulum starts at the angles (1, 0.5) of its angle version (rods of
    length 1); the hoop's energy output is its Jacobi integral (Goldstein Sect. 2.7)."""
    model = MODELS[name]()
    if name == "double_pendulum_cartesian":
        x1, y1, x2, y2 = model.state[:4]
        assert (x1, y1) == pytest.approx((np.sin(1.0), -np.cos(1.0)), abs=1e-15)
        assert (x2 - x1, y2 - y1) == pytest.approx((np.sin(0.5), -np.cos(0.5)), abs=1e-15)
    else:
        assert model.conserved == "Jacobi integral"


def test_a_long_title_is_wrapped_to_the_width_with_every_word_kept() -> None:
    title = "dirac bench --scale -- " + ", ".join(f"item{k} version {k}.{k}" for k in range(30))
    wrapped = wrap_title(title, width=60)
    assert all(len(line) <= 60 for line in wrapped.splitlines())
    assert wrapped.splitlines()[0] == "dirac bench --scale"
    assert wrapped.split() == title.replace(" -- ", " ").split()


def test_repeated_runs_give_their_medians_and_the_ratio_is_a_target() -> None:
    """Three runs of CPU 0.5, 0.9 and 0.6 s (walls 0.6, 1.2, 0.7): the medians are 0.6 and 0.7 s,
    the range 0.5-0.9; against a scipy baseline whose median is 0.75 s the ratio is 0.8, met;
    a baseline of 0.5 s makes it 1.2, over target, and the exit status says so."""
    runs = [LatencyRow("pendulum_angle", "t_end=100", wall, cpu, method="rattle-8", steps=2900)
            for wall, cpu in ((0.6, 0.5), (1.2, 0.9), (0.7, 0.6))]
    row = median_row(runs)
    assert (row.cpu, row.wall, row.runs, row.cpu_range) == (0.6, 0.7, 3, (0.5, 0.9))
    assert (row.method, row.steps) == ("rattle-8", 2900) and runs[0].cpu == 0.5  # the runs are left as they were
    baseline = median_row([LatencyRow("scipy pendulum", "t_end=100", w, c) for w, c in ((0.8, 0.7), (0.9, 0.75), (1.0, 0.8))])
    ratio = scipy_ratio([row, baseline], row)
    assert ratio is not None and ratio == pytest.approx((0.6 / 0.75, 0.7 / 0.9))
    assert targets_met([row, baseline])
    slow = median_row([LatencyRow("scipy pendulum", "t_end=100", 0.5, 0.5)])
    assert not targets_met([row, slow])
    assert "(over)" in format_latency([row, slow]) and "medians of 3 fresh processes" in format_latency([row, slow])
    failed = median_row([*runs[:2], LatencyRow("pendulum_angle", "t_end=100", 0.1, 0.1, failed="timed out after 600 s")])
    assert failed.failed == "timed out after 600 s" and not targets_met([failed, baseline])
    with pytest.raises(InputError, match="repeats must be at least 1"):
        run_latency(["pendulum_angle"], repeats=0)
