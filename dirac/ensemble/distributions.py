"""Named distributions of the ensemble members' initial data (``[ensemble.M]`` etc.).

Each distribution is a small frozen object built from its scene table by
:func:`parse_distribution` (which validates the keys and values, naming the offending key
and the fix) and drawing a block of members from a ``numpy.random.Generator`` with
``draw(rng, n)``. The generator is keyed by ``(seed, quantity, block)`` in
:mod:`dirac.ensemble.sampling`, so what a member gets never depends on how the ensemble
is cut into chunks.

Quantities and their distributions:

``M`` (body angular momentum, docs/conventions.md)
    ``fixed`` (``value``), ``sphere`` (uniform on the sphere ``|M| = norm``: a standard
    normal 3-vector scaled to length ``norm``, Muller 1959), ``gaussian`` (``mean`` +
    ``std`` times a standard normal 3-vector; ``std`` a number or one per component;
    ``norm`` optionally rescales every draw to ``|M| = norm``).
``R`` (attitude, body to lab)
    ``fixed`` (``value``, default the identity (43)), ``uniform`` (Haar measure on SO(3):
    a uniform unit quaternion from a normalised standard normal 4-vector, Shoemake 1992).
``inertia`` (principal moments ``I_i``)
    ``fixed`` (``value``), ``uniform`` (independent uniforms on ``[low_i, high_i]``),
    ``loguniform`` (``log I_i`` uniform on ``[log low_i, log high_i]``).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from dirac.errors import InputError
from dirac.validate import check_known_keys, unknown_name_error, validate_array, validate_positive

__all__ = [
    "Distribution",
    "Fixed",
    "Sphere",
    "Gaussian",
    "HaarRotation",
    "Uniform",
    "LogUniform",
    "parse_distribution",
    "quaternion_to_rotation",
]


class Distribution:
    """Base class: ``draw(rng, n)`` returns ``n`` samples, shape ``(n, *shape)``."""

    #: name used in scene files
    name: str = ""
    #: shape of one sample
    shape: tuple[int, ...] = (3,)

    def draw(self, rng: np.random.Generator, n: int) -> np.ndarray:  # pragma: no cover - abstract
        raise NotImplementedError

    def describe(self) -> dict[str, object]:
        """The distribution as plain data (for ``meta.json``)."""
        data: dict[str, object] = {"distribution": self.name}
        for key, value in self.__dict__.items():
            data[key] = value.tolist() if isinstance(value, np.ndarray) else value
        return data


@dataclass(frozen=True)
class Fixed(Distribution):
    """Every member gets ``value``."""

    value: np.ndarray
    name = "fixed"

    @property
    def shape(self) -> tuple[int, ...]:  # type: ignore[override]  # a read-only property for the base class attribute: the shape follows value
        return tuple(self.value.shape)

    def draw(self, rng: np.random.Generator, n: int) -> np.ndarray:
        return np.broadcast_to(self.value, (n, *self.value.shape)).copy()


@dataclass(frozen=True)
class Sphere(Distribution):
    """Uniform on the sphere ``|M| = norm``: ``M = norm z / |z|``, ``z ~ N(0, 1_3)``."""

    norm: float
    name = "sphere"

    def draw(self, rng: np.random.Generator, n: int) -> np.ndarray:
        z = rng.standard_normal((n, 3))
        return self.norm * z / np.linalg.norm(z, axis=1, keepdims=True)


@dataclass(frozen=True)
class Gaussian(Distribution):
    """``M = mean + std * z``, ``z ~ N(0, 1_3)``; rescaled to ``|M| = norm`` if ``norm`` is set."""

    mean: np.ndarray
    std: np.ndarray
    norm: float | None = None
    name = "gaussian"

    def draw(self, rng: np.random.Generator, n: int) -> np.ndarray:
        sample = self.mean + self.std * rng.standard_normal((n, 3))
        if self.norm is not None:
            sample *= self.norm / np.linalg.norm(sample, axis=1, keepdims=True)
        return sample


def quaternion_to_rotation(q: np.ndarray) -> np.ndarray:
    """Rotation matrices of unit quaternions ``q = (w, x, y, z)``, shape ``(n, 4) -> (n, 3, 3)``.

    ``R = (w^2 - |v|^2) 1 + 2 v v^T + 2 w hat(v)`` (Rodrigues' formula in quaternion form).
    """
    w, x, y, z = q[:, 0], q[:, 1], q[:, 2], q[:, 3]
    R = np.empty((q.shape[0], 3, 3))
    R[:, 0, 0] = 1 - 2 * (y * y + z * z)
    R[:, 0, 1] = 2 * (x * y - w * z)
    R[:, 0, 2] = 2 * (x * z + w * y)
    R[:, 1, 0] = 2 * (x * y + w * z)
    R[:, 1, 1] = 1 - 2 * (x * x + z * z)
    R[:, 1, 2] = 2 * (y * z - w * x)
    R[:, 2, 0] = 2 * (x * z - w * y)
    R[:, 2, 1] = 2 * (y * z + w * x)
    R[:, 2, 2] = 1 - 2 * (x * x + y * y)
    return R


@dataclass(frozen=True)
class HaarRotation(Distribution):
    """Uniform (Haar) rotations: the unit quaternion ``z / |z|``, ``z ~ N(0, 1_4)``."""

    name = "uniform"
    shape = (3, 3)

    def draw(self, rng: np.random.Generator, n: int) -> np.ndarray:
        z = rng.standard_normal((n, 4))
        return quaternion_to_rotation(z / np.linalg.norm(z, axis=1, keepdims=True))


@dataclass(frozen=True)
class Uniform(Distribution):
    """Independent uniforms ``I_i ~ U[low_i, high_i]``."""

    low: np.ndarray
    high: np.ndarray
    name = "uniform"

    def draw(self, rng: np.random.Generator, n: int) -> np.ndarray:
        return self.low + (self.high - self.low) * rng.random((n, 3))


@dataclass(frozen=True)
class LogUniform(Distribution):
    """``log I_i ~ U[log low_i, log high_i]`` (scale-free sweeps over decades)."""

    low: np.ndarray
    high: np.ndarray
    name = "loguniform"

    def draw(self, rng: np.random.Generator, n: int) -> np.ndarray:
        a, b = np.log(self.low), np.log(self.high)
        return np.exp(a + (b - a) * rng.random((n, 3)))


# ----------------------------------------------------------------------------- parsing

_KEYS = {
    ("M", "fixed"): {"value"},
    ("M", "sphere"): {"norm"},
    ("M", "gaussian"): {"mean", "std", "norm"},
    ("R", "fixed"): {"value"},
    ("R", "uniform"): set(),
    ("inertia", "fixed"): {"value"},
    ("inertia", "uniform"): {"low", "high"},
    ("inertia", "loguniform"): {"low", "high"},
}


def _vector(table: dict, key: str, where: str, shape: tuple[int, ...] = (3,)) -> np.ndarray:
    if key not in table:
        raise InputError(f"{where} needs '{key}' ({shape[0]} numbers)")
    return validate_array(table[key], f"{where}.{key}", shape)


def _positive(table: dict, key: str, where: str) -> float:
    return validate_positive(table[key], f"{where}.{key}")


def parse_distribution(
    quantity: str, table: dict, where: str, default_value: np.ndarray | None = None
) -> Distribution:
    """Build and validate the distribution of one quantity from its scene table.

    Parameters
    ----------
    quantity : {"M", "R", "inertia"}
        Which initial datum the table describes.
    table : dict
        The TOML table, e.g. ``{"distribution": "sphere", "norm": 1.0}``.
    where : str
        Name of the table in messages, e.g. ``"[ensemble.M]"``.
    default_value : numpy.ndarray, optional
        Value from ``[initial]``/``[system]``, used as ``fixed`` value and as the
        ``gaussian`` mean when the table does not give one.

    Returns
    -------
    Distribution

    Raises
    ------
    InputError
        Unknown distribution, missing or malformed parameters.
    """
    if not isinstance(table, dict):
        raise InputError(f"{where} must be a table such as {{ distribution = \"fixed\", value = [...] }}")
    name = table.get("distribution", "fixed")
    choices = sorted(d for q, d in _KEYS if q == quantity)
    if (quantity, name) not in _KEYS:
        raise unknown_name_error("distribution", name, choices, f"{where}.distribution")
    allowed = _KEYS[(quantity, name)] | {"distribution"}
    check_known_keys(table, allowed, f"{where} (distribution {name!r})")
    shape = (3, 3) if quantity == "R" else (3,)
    if name == "fixed":
        if "value" in table:
            value = _vector(table, "value", where, shape)
        elif default_value is not None:
            value = np.array(default_value, dtype=float)
        else:
            raise InputError(f"{where} with distribution 'fixed' needs 'value'")
        return Fixed(value)
    if quantity == "M" and name == "sphere":
        if "norm" not in table:
            raise InputError(f"{where} with distribution 'sphere' needs 'norm' (the radius |M|)")
        return Sphere(_positive(table, "norm", where))
    if quantity == "M" and name == "gaussian":
        if "mean" in table:
            mean = _vector(table, "mean", where)
        elif default_value is not None:
            mean = np.array(default_value, dtype=float)
        else:
            raise InputError(f"{where} with distribution 'gaussian' needs 'mean' (or [initial] M)")
        if "std" not in table:
            raise InputError(f"{where} with distribution 'gaussian' needs 'std' (a number or 3 numbers)")
        raw = table["std"]
        std = np.full(3, _positive(table, "std", where)) if not isinstance(raw, list) else _vector(table, "std", where)
        if np.any(std < 0):
            raise InputError(f"{where}.std = {std.tolist()} has a negative entry; give std >= 0")
        norm = _positive(table, "norm", where) if "norm" in table else None
        return Gaussian(mean, std, norm)
    if quantity == "R":
        return HaarRotation()
    low = _vector(table, "low", where)
    high = _vector(table, "high", where)
    if np.any(low <= 0) or np.any(high < low):
        raise InputError(f"{where}: need 0 < low <= high componentwise; got low = {low.tolist()}, high = {high.tolist()}")
    return Uniform(low, high) if name == "uniform" else LogUniform(low, high)
