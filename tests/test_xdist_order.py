"""The long test files start first on pytest-xdist's workers (tests/xdist_order.py)."""

from __future__ import annotations

from collections import OrderedDict
from pathlib import Path

from xdist_order import LONG_FILES, long_files_first_scheduler

ROOT = Path(__file__).resolve().parents[1]


def test_the_long_files_exist() -> None:
    """A renamed or removed file would silently lose its place at the front."""
    missing = [name for name in LONG_FILES if not (ROOT / name).is_file()]
    assert not missing, missing
    assert len(set(LONG_FILES)) == len(LONG_FILES)


class _Node:
    """A stand-in for a worker: records the tests it is asked to run."""

    def __init__(self) -> None:
        self.sent: list[list[int]] = []

    def send_runtest_some(self, indexes: list[int]) -> None:
        self.sent.append(indexes)


def test_the_long_files_are_handed_out_first_and_the_rest_keep_their_order(pytestconfig, monkeypatch) -> None:
    """With pytest-xdist's queue (files by number of tests, most first) the long files go out
    first, in the order of LONG_FILES, then the others in the queue's order; every test of
    every file is sent once."""
    monkeypatch.setattr(pytestconfig.option, "dist", "loadfile")
    monkeypatch.setattr(pytestconfig.option, "tx", ["2*popen"])  # two workers (-n 2)
    scheduler = long_files_first_scheduler(pytestconfig, None)
    others = ["tests/a/test_many.py", "tests/b/test_some.py", "tests/c/test_one.py"]
    queued = [others[0], LONG_FILES[3], others[1], LONG_FILES[0], others[2], *LONG_FILES[4:], *LONG_FILES[1:3]]
    collection = [f"{name}::test_{i}" for name in queued for i in range(2)]
    scheduler.workqueue = OrderedDict((name, {f"{name}::test_{i}": False for i in range(2)}) for name in queued)
    node = _Node()
    scheduler.registered_collections[node] = collection
    order = []
    while scheduler.workqueue:
        before = set(scheduler.workqueue)
        scheduler._assign_work_unit(node)
        order += before - set(scheduler.workqueue)
    assert order == [*LONG_FILES, *others]
    assert sorted(i for indexes in node.sent for i in indexes) == list(range(len(collection)))


def test_other_dist_modes_are_left_to_xdist(pytestconfig, monkeypatch) -> None:
    monkeypatch.setattr(pytestconfig.option, "dist", "load")
    assert long_files_first_scheduler(pytestconfig, None) is None
