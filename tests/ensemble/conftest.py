"""Fixtures of the ensemble tests: scene files and a two-worker dask LocalCluster."""

from __future__ import annotations

import math
from pathlib import Path

import pytest

STANDARD_INERTIA = [2.0, 1.0, 2.0 / 3.0]
STANDARD_M = [math.cos(1.1), 0.0, math.sin(1.1)]


def scene_text(
    *,
    count: int = 200,
    seed: int = 11,
    t_end: float = 2.0,
    dt: float = 0.01,
    samples: int = 21,
    method: str = "lie-poisson-4",
    outputs: str = '["M", "R", "energy"]',
    reductions: str = '["flip_time", "max_energy_error", "max_casimir_error", "final_state", "initial_state"]',
    extra: str = "",
    members: str = '[ensemble.M]\ndistribution = "sphere"\nnorm = 1.0\n[ensemble.R]\ndistribution = "uniform"\n'
    '[ensemble.inertia]\ndistribution = "uniform"\nlow = [1.5, 1.5, 1.5]\nhigh = [2.5, 2.5, 2.5]\n',
) -> str:
    """A small ensemble scene (TOML text)."""
    return f"""
[system]
name = "rigid_body"
inertia = [3.0, 2.0, 1.5]

[run]
method = "{method}"
dt = {dt!r}
t_end = {t_end!r}
samples = {samples}
outputs = {outputs}

[ensemble]
count = {count}
seed = {seed}
reductions = {reductions}
{extra}
{members}
"""


@pytest.fixture
def write_scene(tmp_path: Path):
    """Write a scene file; return its path."""

    def write(name: str = "scene.toml", text: str | None = None, **options) -> Path:
        path = tmp_path / name
        path.write_text(scene_text(**options) if text is None else text)
        return path

    return write


@pytest.fixture(scope="module")
def dask_client():
    """A dask LocalCluster of two workers (in-process transport, no network), closed after the module.

    The workers are threads of the test process (``processes=False``: no spawn, the
    kernels are loaded once); worker processes are exercised by the command-line test
    with ``--cluster local`` and by ``dirac bench --ensemble``.
    """
    import distributed  # in the test extra

    cluster = distributed.LocalCluster(
        n_workers=2, threads_per_worker=1, processes=False, dashboard_address=None
    )
    client = distributed.Client(cluster)
    try:
        yield client
    finally:
        client.close()
        cluster.close()
