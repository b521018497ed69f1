"""The ensemble progress bar: open from the start, advanced per chunk as chunks complete, kept ticking."""

from __future__ import annotations

import threading
import time

import pytest
import tqdm

import dirac.ensemble.local_executor as local_executor
from dirac.ensemble.engine import _Progress, run_ensemble


class FakeBar:
    """Records what the engine does with its tqdm bar."""

    made: list[FakeBar] = []

    def __init__(self, **options) -> None:
        self.options = options
        self.created = time.perf_counter()
        self.updates: list[int] = []
        self.refreshes = 0
        self.closed = False
        self._lock = threading.Lock()
        FakeBar.made.append(self)

    def update(self, n: int) -> None:
        self.updates.append(n)

    def refresh(self) -> None:
        with self._lock:
            self.refreshes += 1

    def close(self) -> None:
        self.closed = True


@pytest.fixture
def fake_bar(monkeypatch):
    FakeBar.made = []
    monkeypatch.setattr(tqdm, "tqdm", FakeBar)
    return FakeBar


def test_bar_opens_before_the_first_chunk_and_advances_by_each_chunk_as_it_completes(
    write_scene, tmp_path, fake_bar, monkeypatch
):
    real = local_executor.compute_chunk
    seen: list[tuple[float, int]] = []  # (start of the chunk's computation, members reported when it returned)

    def slow_compute(scene, start, stop, members):
        began = time.perf_counter()
        time.sleep(0.2)  # the previous chunk's write finishes meanwhile
        arrays = real(scene, start, stop, members)
        seen.append((began, sum(fake_bar.made[0].updates)))
        return arrays

    monkeypatch.setattr(local_executor, "compute_chunk", slow_compute)
    scene = write_scene(count=30, outputs="[]", reductions='["final_state"]')
    report = run_ensemble(scene, tmp_path / "out", chunk_size=10, progress=True)
    assert report.chunks_computed == 3
    (bar,) = fake_bar.made
    assert bar.options["total"] == 30 and bar.options["initial"] == 0 and bar.options["unit"] == "member"
    assert bar.options["smoothing"] == 0  # members/s over the whole wall time
    assert bar.created < seen[0][0]  # the clock of the rate starts before the first chunk
    assert bar.updates == [10, 10, 10]  # one update per chunk, by its members
    # chunk k (0-based) is reported while chunk k + 1 is computed, not after it
    assert [members for _, members in seen] == [0, 10, 20]
    assert bar.closed


def test_resumed_run_starts_the_bar_at_the_members_already_done(write_scene, tmp_path, fake_bar):
    scene = write_scene(count=30, outputs="[]", reductions='["final_state"]')
    run_ensemble(scene, tmp_path / "out", chunk_size=10)  # no bar
    assert fake_bar.made == []
    (tmp_path / "out" / "chunks" / "chunk-000001.json").unlink()
    run_ensemble(scene, tmp_path / "out", progress=True)
    (bar,) = fake_bar.made
    assert (bar.options["total"], bar.options["initial"], bar.updates) == (30, 20, [10])


def test_bar_keeps_its_elapsed_time_running_while_no_chunk_completes(fake_bar):
    progress = _Progress(True, total=100, initial=0, refresh=0.02)
    time.sleep(0.3)
    refreshes = fake_bar.made[0].refreshes
    progress.close()
    assert refreshes >= 3  # about 15 redraws of a bar with no update
    count = fake_bar.made[0].refreshes
    time.sleep(0.1)
    assert fake_bar.made[0].refreshes == count  # the ticker stops with the bar


def test_no_bar_when_progress_is_off(fake_bar):
    progress = _Progress(False, total=100, initial=0)
    progress.update(10)
    progress.close()
    assert fake_bar.made == []
