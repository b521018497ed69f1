"""The on-disk store of an ensemble: zarr arrays, per-chunk markers, atomic meta.

Layout of ``DIR``::

    DIR/meta.json              what the run is and what is complete (rewritten atomically)
    DIR/data.zarr/             zarr group: ``t`` and one array per output / reduction,
                               chunked along the members exactly like the ensemble
    DIR/chunks/chunk-000042.json   marker of a finished chunk (written atomically *after*
                               its data): the source of truth for resuming

A chunk counts as done if and only if its marker exists, so a run killed at any moment
resumes by recomputing exactly the chunks without a marker (their half-written zarr
chunks are overwritten). Each ensemble chunk covers whole zarr chunks, so workers never
write the same zarr chunk and need no locks. For a cluster, ``DIR`` must be on a file
system every worker sees.
"""

from __future__ import annotations

import json
import os
import socket
import time
from pathlib import Path

import numpy as np

from dirac.ensemble.arguments import ArgumentError
from dirac.ensemble.general_scene import GeneralEnsembleScene
from dirac.ensemble.reductions import reduction_arrays
from dirac.ensemble.scene import TRAJECTORY_OUTPUTS, AnyScene
from dirac.errors import InputError

__all__ = ["FORMAT", "EnsembleStore", "array_layout", "atomic_write_json"]

#: Format tag written in ``meta.json``.
FORMAT = "dirac-ensemble/1"


def atomic_write_json(path: Path, data: object) -> None:
    """Write JSON so that readers see the old or the new file, never a torn one."""
    tmp = path.with_name(f".{path.name}.{os.getpid()}.{time.monotonic_ns()}.tmp")
    with open(tmp, "w") as handle:
        json.dump(data, handle, indent=1, sort_keys=True)
        handle.flush()
        os.fsync(handle.fileno())
    os.replace(tmp, path)


def array_layout(scene: AnyScene) -> dict[str, tuple[int, ...]]:
    """Array name -> shape of one member's entry, for every array the scene stores."""
    if isinstance(scene, GeneralEnsembleScene):
        return scene.array_layout()
    layout: dict[str, tuple[int, ...]] = {}
    for name in scene.outputs:
        layout[name] = (scene.samples, *TRAJECTORY_OUTPUTS[name])
    for name in scene.reductions:
        layout.update(reduction_arrays(name))
    return layout


class EnsembleStore:
    """An ensemble's output folder (see the module docstring).

    Parameters
    ----------
    root : str or Path
        The folder ``DIR``.
    """

    def __init__(self, root: str | Path) -> None:
        self.root = Path(root).resolve()
        self.meta_path = self.root / "meta.json"
        self.data_path = self.root / "data.zarr"
        self.marker_dir = self.root / "chunks"

    # ------------------------------------------------------------------ set-up
    def read_meta(self) -> dict | None:
        """The current ``meta.json``, or None if the folder holds no ensemble yet."""
        try:
            return json.loads(self.meta_path.read_text())
        except FileNotFoundError:
            return None
        except (OSError, json.JSONDecodeError) as exc:
            raise InputError(f"{self.meta_path} is unreadable ({exc}); delete the folder to start over") from None

    def create(self, scene: AnyScene, chunk_size: int, meta: dict) -> None:
        """Create the folder, the zarr arrays (NaN-filled) and ``meta.json`` (last).

        Raises
        ------
        InputError
            ``DIR`` exists, holds no ensemble and is not empty.
        """
        import zarr

        if self.root.exists():
            if not self.root.is_dir():
                raise ArgumentError("{out} is a file; give a folder", {"out": str(self.root)})
            foreign = sorted(p.name for p in self.root.iterdir() if p.name not in ("data.zarr", "chunks"))
            if foreign:
                raise ArgumentError(
                    "{out} is not empty and holds no ensemble ({found}); give a new or empty folder",
                    {"out": str(self.root)},
                    found=foreign[:3],
                )
        self.marker_dir.mkdir(parents=True, exist_ok=True)
        for stale in self.marker_dir.glob("chunk-*.json"):  # from a creation that crashed
            stale.unlink()
        group = zarr.open_group(str(self.data_path), mode="w")
        times = group.create_array("t", shape=(scene.samples,), chunks=(scene.samples,), dtype="f8", compressors=None)
        times[:] = scene.times()
        for name, shape in array_layout(scene).items():
            group.create_array(
                name,
                shape=(scene.count, *shape),
                chunks=(chunk_size, *shape),
                dtype="f8",
                fill_value=np.nan,
                compressors=None,
            )
        self.write_meta(meta)

    def write_meta(self, meta: dict) -> None:
        """Replace ``meta.json`` atomically."""
        atomic_write_json(self.meta_path, meta)

    # ------------------------------------------------------------------ chunks
    def marker_path(self, index: int) -> Path:
        return self.marker_dir / f"chunk-{index:06d}.json"

    def completed(self) -> dict[int, dict]:
        """Markers of the finished chunks: chunk index -> marker contents."""
        done: dict[int, dict] = {}
        for path in self.marker_dir.glob("chunk-*.json"):
            try:
                marker = json.loads(path.read_text())
            except (OSError, json.JSONDecodeError):
                continue  # cannot happen with atomic writes; recompute to be safe
            done[int(marker["chunk"])] = marker
        return done

    def write_chunk(self, index: int, start: int, stop: int, arrays: dict[str, np.ndarray], info: dict) -> dict:
        """Write one chunk's arrays into the zarr store, then its marker.

        Parameters
        ----------
        index, start, stop : int
            Chunk number and member range.
        arrays : dict
            Array name -> values for the members ``start .. stop-1``.
        info : dict
            Extra marker fields (run id, attempt, seconds, ...).

        Returns
        -------
        dict
            The marker written.
        """
        import zarr

        for name, values in arrays.items():
            target = zarr.open_array(str(self.data_path), path=name, mode="r+")
            target[start:stop] = values
        if "steps" in arrays:  # members of a general ensemble may stop early
            info = {**info, "member_steps": int(np.sum(arrays["steps"]))}
        marker = {
            "chunk": index,
            "start": start,
            "stop": stop,
            "host": socket.gethostname(),
            "pid": os.getpid(),
            "finished_at": time.time(),
            **info,
        }
        atomic_write_json(self.marker_path(index), marker)
        return marker
