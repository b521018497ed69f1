"""Ensemble scenes: the single-run sections of a scene file (docs/file_formats.md) plus ``[ensemble]``.

```toml
[system]
name = "rigid_body"
inertia = [2.0, 1.0, 0.6666666666666666]    # shared inertia (unless [ensemble.inertia])

[initial]
M = [0.0, 1.0, 0.0]                          # centre / fixed value of M (optional)

[run]
method = "lie-poisson-4"                     # a Lie-Poisson splitting ("auto" = lie-poisson-4)
dt = 0.01
t_end = 50.0
samples = 2001                               # sample grid: outputs and reductions
outputs = []                                 # full trajectories: "M", "R", "energy", ...

[ensemble]
count = 100000
seed = 2026
reductions = ["flip_time", "max_energy_error", "final_state"]
flip_axis = "intermediate"                   # or 1, 2, 3
# chunk_size = 50000                         # default: from the memory a member needs
# file = "members.npz"                       # M, R, inertia arrays instead of draws

[ensemble.M]
distribution = "gaussian"                    # fixed | sphere | gaussian
std = 1e-3                                   # mean defaults to [initial] M
norm = 1.0

[ensemble.R]
distribution = "uniform"                     # fixed (default: [initial] R or 1) | uniform

[ensemble.inertia]
distribution = "fixed"                       # fixed (default: [system] inertia) | uniform | loguniform
```

:func:`load_ensemble_scene` validates everything up front (``InputError`` naming the key
and the fix; unknown keys are errors that suggest the closest known key) and returns an :class:`EnsembleScene`.
"""

from __future__ import annotations

import hashlib
import json
import math
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from dirac.ensemble.distributions import (
    Distribution,
    Fixed,
    LogUniform,
    Uniform,
    parse_distribution,
)
from dirac.ensemble.general_scene import GeneralEnsembleScene, is_general_scene, parse_general_scene
from dirac.ensemble.sampling import MemberSource, open_member_file
from dirac.errors import InputError, warn
from dirac.io.scene import (
    read_scene_file,
    reject_unknown_keys,
    scene_inertia,
    scene_integer,
    scene_number,
    scene_table,
    scene_vector,
)
from dirac.validate import unknown_name_error

__all__ = [
    "TRAJECTORY_OUTPUTS",
    "REDUCTIONS",
    "AnyScene",
    "EnsembleScene",
    "load_ensemble_scene",
    "parse_ensemble_scene",
]

#: Full-trajectory outputs: name -> shape of one sample of one member.
TRAJECTORY_OUTPUTS: dict[str, tuple[int, ...]] = {
    "M": (3,),
    "R": (3, 3),
    "energy": (),
    "casimir": (),
    "lab_momentum": (3,),
}

#: Per-member reductions (dirac.ensemble.reductions) and what they mean.
REDUCTIONS: dict[str, str] = {
    "flip_time": "first time the flip axis turns over: M_a(t) changes sign (NaN if never)",
    "max_energy_error": "max over the samples of |H_0(t) - H_0(0)| / H_0(0)",
    "max_casimir_error": "max over the samples of ||M(t)|^2 - |M(0)|^2| / |M(0)|^2",
    "final_state": "M and R at t_end (arrays final_M, final_R)",
    "initial_state": "the member's drawn M, R and inertia (arrays initial_M, initial_R, inertia)",
}

_SECTION_KEYS = {
    "system": {"name", "inertia"},
    "initial": {"M", "R"},
    "run": {"t_end", "method", "dt", "tolerance", "samples", "outputs"},
    "ensemble": {"count", "seed", "chunk_size", "reductions", "flip_axis", "file", "M", "R", "inertia"},
}

#: Default composition when ``method = "auto"`` (fixed step dt: 4th order, 3 stages).
AUTO_METHOD = "lie-poisson-4"


@dataclass(frozen=True)
class EnsembleScene:
    """A validated ensemble scene.

    Attributes
    ----------
    source : MemberSource
        Count, seed and distributions (or file) of the members' initial data.
    method, order, coefficients
        The Lie-Poisson splitting (``dirac.rigidbody.splitting.SCHEMES``).
    dt : float
        The step actually taken: the sample spacing divided by ``steps_per_sample``
        (equal to the requested ``dt`` when that divides the spacing).
    dt_requested : float
    t_end : float
    samples : int
        Sample times ``t_k = k t_end / (samples - 1)``, both ends included.
    steps_per_sample : int
    outputs : tuple of str
        Full trajectories stored (keys of :data:`TRAJECTORY_OUTPUTS`).
    reductions : tuple of str
        Per-member summaries stored (keys of :data:`REDUCTIONS`).
    flip_axis : int or None
        Body axis (0-based) of ``flip_time``; None = each member's intermediate axis.
    chunk_size : int or None
        Members per chunk asked for by the scene (None: chosen by the engine).
    path : str or None
        The scene file.
    """

    source: MemberSource
    method: str
    order: int
    coefficients: tuple[float, ...]
    dt: float
    dt_requested: float
    t_end: float
    samples: int
    steps_per_sample: int
    outputs: tuple[str, ...]
    reductions: tuple[str, ...]
    flip_axis: int | None = None
    chunk_size: int | None = None
    path: str | None = None
    file_digest: str | None = field(default=None, compare=False)

    @property
    def count(self) -> int:
        return self.source.count

    @property
    def steps(self) -> int:
        """Steps per member."""
        return self.steps_per_sample * (self.samples - 1)

    @property
    def with_R(self) -> bool:
        """Whether the attitude must be advanced (it costs about twice the work of ``M``)."""
        return bool({"R", "lab_momentum"} & set(self.outputs)) or "final_state" in self.reductions

    def times(self) -> np.ndarray:
        """The sample times, shape (samples,)."""
        return np.linspace(0.0, self.t_end, self.samples)

    def describe(self) -> dict[str, object]:
        """Everything that determines the results, as plain data (for ``meta.json``)."""
        return {
            "count": self.count,
            "seed": self.source.seed,
            "distributions": {q: d.describe() for q, d in self.source.distributions.items()},
            "file": self.source.file,
            "file_digest": self.file_digest,
            "method": self.method,
            "order": self.order,
            "dt": self.dt,
            "dt_requested": self.dt_requested,
            "t_end": self.t_end,
            "samples": self.samples,
            "steps_per_sample": self.steps_per_sample,
            "outputs": list(self.outputs),
            "reductions": list(self.reductions),
            "flip_axis": "intermediate" if self.flip_axis is None else self.flip_axis + 1,
        }

    def fingerprint(self) -> str:
        """SHA-256 of :meth:`describe` (a resumed run must match it).

        A member file enters by its content digest, not its path, so a moved folder
        still resumes.
        """
        described = self.describe()
        described.pop("file")
        text = json.dumps(described, sort_keys=True)
        return hashlib.sha256(text.encode()).hexdigest()


#: An ensemble scene of either kind: the free rigid body's, or any other system's.
AnyScene = EnsembleScene | GeneralEnsembleScene


def load_ensemble_scene(path: str | Path) -> EnsembleScene | GeneralEnsembleScene:
    """Read and validate an ensemble scene file (TOML).

    Parameters
    ----------
    path : str or Path
        The scene; a member ``file`` in it is relative to the scene's folder.

    Raises
    ------
    InputError
        Missing file, TOML syntax error, or any invalid key (named in the message).
    """
    path = Path(path)
    data = read_scene_file(path)
    return parse_ensemble_scene(data, base_dir=path.resolve().parent, path=str(path))


def _section(data: dict, name: str, required: bool, source: str = "") -> dict:
    section = scene_table(data, name, required=required,
                          hint="an ensemble scene needs [system], [run] and [ensemble]; see docs/ensembles.md")
    reject_unknown_keys(section, _SECTION_KEYS[name], f"[{name}]", source)
    return section


def _number(section: dict, key: str, where: str, default: float | None = None) -> float:
    """A number ``> 0`` under ``key`` (``default`` when absent, if there is one)."""
    if key not in section:
        if default is None:
            raise InputError(f"{where} needs '{key}'")
        return default
    return scene_number(section[key], f"{where} {key}", positive=True)


def _optional_integer(section: dict, key: str, where: str, minimum: int) -> int | None:
    """An integer ``>= minimum`` under ``key`` (None when absent); a float with an
    integral value counts."""
    if key not in section:
        return None
    value = section[key]
    if isinstance(value, float) and value.is_integer():
        value = int(value)
    return scene_integer(value, f"{where} {key}", minimum=minimum)


def _integer(section: dict, key: str, where: str, default: int, minimum: int) -> int:
    """As :func:`_optional_integer`, with ``default`` when absent."""
    value = _optional_integer(section, key, where, minimum)
    return default if value is None else value


def _names(section: dict, key: str, where: str, allowed: dict) -> tuple[str, ...]:
    value = section.get(key, [])
    if isinstance(value, str):
        value = [value]
    if not isinstance(value, list) or not all(isinstance(v, str) for v in value):
        raise InputError(f"{where} {key} must be a list of names from {sorted(allowed)}")
    for name in value:
        if name not in allowed:
            kind = "output" if key == "outputs" else "reduction" if key == "reductions" else "name"
            raise unknown_name_error(kind, name, allowed, f"{where} {key}")
    return tuple(dict.fromkeys(value))


def _method(run: dict) -> tuple[str, int, tuple[float, ...]]:
    from dirac.rigidbody.splitting import SCHEMES

    usable = sorted(name for name, scheme in SCHEMES.items() if scheme.splitting == "axes")
    name = run.get("method", "auto")
    if name == "auto":
        name = AUTO_METHOD
    scheme = SCHEMES.get(name) if isinstance(name, str) else None
    if scheme is None or scheme.splitting != "axes":
        raise InputError(
            f"[run] method = {run.get('method')!r} is not available for ensembles (they use the "
            f"batched Lie-Poisson kernels); choose 'auto' or one of {usable}"
        )
    return name, scheme.order, tuple(scheme.coefficients)


def _check_member_file(file: str, count: int | None) -> tuple[int, str]:
    """Validate a member file; return ``(count, digest)``."""
    if not Path(file).exists():
        raise InputError(f"[ensemble] file {file!r} does not exist; give a path relative to the scene file")
    try:
        arrays = open_member_file(file)
    except Exception as exc:
        raise InputError(f"[ensemble] file {file!r} cannot be read ({exc}); give an .npz file or a zarr group") from None
    if "M" not in arrays:
        raise InputError(f"[ensemble] file {file!r} has no array 'M' (shape (count, 3)); add it")
    n = int(arrays["M"].shape[0])
    shapes = {"M": (n, 3), "R": (n, 3, 3), "inertia": (n, 3)}
    digest = hashlib.sha256()
    for name, array in arrays.items():
        if tuple(array.shape) != shapes[name]:
            raise InputError(f"[ensemble] file {file!r}: array {name!r} has shape {tuple(array.shape)}; expected {shapes[name]}")
        for lo in range(0, n, 1_000_000):
            block = np.asarray(array[lo : lo + 1_000_000], dtype=float)
            digest.update(block.tobytes())
            if not np.all(np.isfinite(block)):
                raise InputError(f"[ensemble] file {file!r}: array {name!r} has non-finite entries")
            if name == "inertia" and np.any(block <= 0):
                raise InputError(f"[ensemble] file {file!r}: 'inertia' has a non-positive moment; every I_i must be > 0")
            if name == "R":
                defect = np.abs(np.einsum("nki,nkj->nij", block, block) - np.eye(3)).max(initial=0.0)
                if defect > 1e-10 or np.any(np.linalg.det(block) < 0):
                    raise InputError(f"[ensemble] file {file!r}: 'R' holds a matrix that is not a proper rotation (max |R^T R - 1| = {defect:.3g})")
    if count is not None and count != n:
        raise InputError(f"[ensemble] count = {count} but file {file!r} holds {n} members; drop count or make them agree")
    return n, digest.hexdigest()


def _warn_triangle(distribution: object) -> None:
    """Warn when drawn inertias can violate ``I_i + I_j >= I_k`` (72); docs/conventions.md."""
    if isinstance(distribution, (Uniform, LogUniform)):
        low, high = distribution.low, distribution.high
        for k in range(3):
            i, j = (k + 1) % 3, (k + 2) % 3
            if low[i] + low[j] < high[k]:
                warn(
                    f"[ensemble.inertia] can draw I_{i + 1} + I_{j + 1} < I_{k + 1} (triangle inequality "
                    "violated): such members are no physical body; the Euler-Poisson flow is still "
                    "well defined, continuing"
                )
                return


def parse_ensemble_scene(data: dict, base_dir: Path | str = ".", path: str | None = None
                         ) -> EnsembleScene | GeneralEnsembleScene:
    """Validate a parsed scene (a dict from TOML); see the module docstring for the keys.

    Parameters
    ----------
    data : dict
        The scene.
    base_dir : Path or str
        Folder relative to which ``[ensemble] file`` is resolved.
    path : str, optional
        The scene file's name (kept in the result).

    Returns
    -------
    EnsembleScene

    Raises
    ------
    InputError
        Any invalid or missing key, named with the fix.
    """
    if is_general_scene(data):
        return parse_general_scene(data, base_dir=base_dir, path=path)

    from dirac.rigidbody.inertia import (
        validate_inertia,
        validate_momentum,
        validate_rotation,
    )

    source = path or ""
    if "forces" in data or "impulses" in data:
        raise InputError(f"{source + ': ' if source else ''}a rigid-body ensemble runs the free body; a body driven by a "
                         "torque or angular impulses runs as a heavy top without weight: write [system] name = "
                         "\"heavy_top\" with mass_gravity = 0 and the heavy-top ensemble keys (see "
                         "docs/ensembles_general.md, \"A driven top\")")
    reject_unknown_keys(data, set(_SECTION_KEYS), "the ensemble scene", source, kind="section")
    system = _section(data, "system", required=True, source=source)
    initial = _section(data, "initial", required=False, source=source)
    run = _section(data, "run", required=True, source=source)
    ensemble = _section(data, "ensemble", required=True, source=source)

    if system.get("name", "rigid_body") != "rigid_body":
        raise InputError(f"[system] name = {system.get('name')!r}: ensembles support the free rigid body only; use name = \"rigid_body\"")

    # --- members
    file = ensemble.get("file")
    count = _optional_integer(ensemble, "count", "[ensemble]", 1)
    digest = None
    if file is not None:
        if not isinstance(file, str):
            raise InputError("[ensemble] file must be a path (string)")
        file = str((Path(base_dir) / file).resolve())
        count, digest = _check_member_file(file, count)
        present = set(open_member_file(file))
    else:
        present = set()
        if count is None:
            raise InputError("[ensemble] needs 'count' (the number of members) or 'file'")
    seed = _integer(ensemble, "seed", "[ensemble]", 0, 0)
    if seed >= 2**63:
        raise InputError(f"[ensemble] seed = {seed} is too large; give an integer below 2**63")

    defaults = {
        "M": validate_momentum(scene_vector(initial["M"], "[initial] M", "", (3,))) if "M" in initial else None,
        "R": validate_rotation(scene_vector(initial["R"], "[initial] R", "", (3, 3))) if "R" in initial else np.eye(3),
        "inertia": validate_inertia(scene_inertia(system)) if "inertia" in system else None,
    }
    distributions: dict[str, Distribution] = {}
    for quantity in ("M", "R", "inertia"):
        table = ensemble.get(quantity, {})
        where = f"[ensemble.{quantity}]"
        if quantity in present:
            if table:
                warn(f"{where} is ignored: the member file gives '{quantity}'")
            distributions[quantity] = Fixed(np.zeros((3, 3) if quantity == "R" else 3))  # not drawn
            continue
        if not table and defaults[quantity] is None:
            source = "[initial] M" if quantity == "M" else "[system] inertia"
            raise InputError(f"give {source} or an {where} table with a distribution")
        distribution = parse_distribution(quantity, table, where, defaults[quantity])
        if isinstance(distribution, Fixed) and "value" in table:
            if quantity == "inertia":
                validate_inertia(distribution.value)
            elif quantity == "R":
                validate_rotation(distribution.value)
        _warn_triangle(distribution)
        distributions[quantity] = distribution

    # --- run
    method, order, coefficients = _method(run)
    if "dt" not in run:
        raise InputError("[run] needs 'dt' (the fixed step of the splitting method)")
    dt = _number(run, "dt", "[run]")
    t_end = _number(run, "t_end", "[run]")
    if "tolerance" in run:
        warn("[run] tolerance is not used by ensembles (fixed step dt); ignoring it")
    samples = _integer(run, "samples", "[run]", 101, 2)
    spacing = t_end / (samples - 1)
    steps_per_sample = max(1, math.ceil(spacing / dt * (1.0 - 1e-12)))
    step = spacing / steps_per_sample
    if abs(step - dt) > 1e-12 * dt:
        warn(f"[run] dt = {dt!r} does not divide the sample spacing {spacing!r}; using dt = {step!r} ({steps_per_sample} steps per sample)")
    outputs = _names(run, "outputs", "[run]", TRAJECTORY_OUTPUTS)
    reductions = _names(ensemble, "reductions", "[ensemble]", REDUCTIONS)
    if not outputs and not reductions:
        raise InputError(
            "the scene asks for nothing: give [run] outputs (full trajectories) and/or "
            f"[ensemble] reductions (per-member summaries, from {sorted(REDUCTIONS)})"
        )
    flip = ensemble.get("flip_axis", "intermediate")
    if flip == "intermediate":
        flip_axis = None
    elif flip in (1, 2, 3) and not isinstance(flip, bool):
        flip_axis = int(flip) - 1
    else:
        raise InputError(f"[ensemble] flip_axis = {flip!r}; give 1, 2, 3 or \"intermediate\"")
    chunk_size = _optional_integer(ensemble, "chunk_size", "[ensemble]", 1)
    return EnsembleScene(
        source=MemberSource(count=count, seed=seed, distributions=distributions, file=file),
        method=method,
        order=order,
        coefficients=coefficients,
        dt=step,
        dt_requested=dt,
        t_end=t_end,
        samples=samples,
        steps_per_sample=steps_per_sample,
        outputs=outputs,
        reductions=reductions,
        flip_axis=flip_axis,
        chunk_size=chunk_size,
        path=path,
        file_digest=digest,
    )
