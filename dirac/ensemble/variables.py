"""Named ensemble variables: a grid and/or random draws, member by member.

```toml
[ensemble]
grid = { a = [-3.0, 3.0, 256], b = [-3.0, 3.0, 256] }   # lo, hi, n points (both ends included)
count = 1                                               # draws per grid point (default 1)
seed = 2026

[ensemble.variables]
g = { distribution = "uniform", low = 9.7, high = 9.9 }  # or gaussian (mean, std), loguniform
```

Members are numbered grid point by grid point (C order over the grid variables as
listed: the last one varies fastest), ``count`` draws per grid point: member
``i = g * count + k``. A grid variable takes ``lo + (hi - lo) * j / (n - 1)`` (``lo``
when ``n = 1``). A random variable is drawn by the counter-based generators of
:mod:`dirac.ensemble.sampling` keyed by ``(seed, 100 + its position, block)``, so member
``i`` gets the same value whatever the chunking, the executor or the number of workers.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from dirac.ensemble.sampling import draw_range
from dirac.errors import InputError
from dirac.validate import check_known_keys, unknown_name_error

__all__ = ["GridAxis", "RandomVariable", "VariableSource", "parse_variables"]

#: Streams of random ensemble variables start here (0-2 are the rigid body's M, R, inertia).
FIRST_STREAM = 100

_DISTRIBUTIONS = {"uniform": {"low", "high"}, "gaussian": {"mean", "std"}, "loguniform": {"low", "high"}}


@dataclass(frozen=True)
class GridAxis:
    """One grid variable: ``n`` points from ``lo`` to ``hi``, both included."""

    name: str
    lo: float
    hi: float
    n: int

    def values(self) -> np.ndarray:
        if self.n == 1:
            return np.array([self.lo])
        return self.lo + (self.hi - self.lo) * (np.arange(self.n) / (self.n - 1))


@dataclass(frozen=True)
class RandomVariable:
    """One random variable: ``uniform(low, high)``, ``gaussian(mean, std)`` or ``loguniform(low, high)``."""

    name: str
    distribution: str
    a: float
    b: float
    shape: tuple[int, ...] = ()

    def draw(self, rng: np.random.Generator, n: int) -> np.ndarray:
        if self.distribution == "uniform":
            return rng.uniform(self.a, self.b, n)
        if self.distribution == "gaussian":
            return self.a + self.b * rng.standard_normal(n)
        return np.exp(rng.uniform(np.log(self.a), np.log(self.b), n))

    def describe(self) -> dict[str, object]:
        keys = ("mean", "std") if self.distribution == "gaussian" else ("low", "high")
        return {"distribution": self.distribution, keys[0]: self.a, keys[1]: self.b}


@dataclass(frozen=True)
class VariableSource:
    """The ensemble variables and how members are numbered (module docstring).

    Attributes
    ----------
    grid : tuple of GridAxis
    random : tuple of RandomVariable
    draws : int
        Draws per grid point (``count``).
    seed : int
    """

    grid: tuple[GridAxis, ...]
    random: tuple[RandomVariable, ...]
    draws: int
    seed: int

    @property
    def names(self) -> tuple[str, ...]:
        return tuple(a.name for a in self.grid) + tuple(r.name for r in self.random)

    @property
    def grid_shape(self) -> tuple[int, ...]:
        return tuple(a.n for a in self.grid)

    @property
    def count(self) -> int:
        return int(np.prod(self.grid_shape, dtype=np.int64)) * self.draws

    def members(self, start: int, stop: int) -> np.ndarray:
        """The variables' values of members ``start .. stop-1``: shape ``(stop - start, len(names))``."""
        index = np.arange(start, stop, dtype=np.int64)
        columns = []
        point = index // self.draws
        if self.grid:
            coordinates = np.unravel_index(point, self.grid_shape)
            columns += [axis.values()[j] for axis, j in zip(self.grid, coordinates)]
        for position, variable in enumerate(self.random):
            columns.append(draw_range(variable, self.seed, FIRST_STREAM + position, start, stop))  # type: ignore[arg-type]  # draws like a Distribution
        if not columns:
            return np.empty((stop - start, 0))
        return np.ascontiguousarray(np.stack(columns, axis=1))

    def describe(self) -> dict[str, object]:
        """The variables as plain data (``meta.json``; the scene's fingerprint hashes it).

        JSON writes a table's keys sorted, but the order of the grid variables numbers the
        members and the order of the random ones picks their streams: when either is not
        alphabetical, ``order`` keeps both as lists (so two scenes that list the same
        variables in another order have other fingerprints, and a map is drawn the right way
        round).
        """
        described: dict[str, object] = {
            "grid": {a.name: [a.lo, a.hi, a.n] for a in self.grid},
            "random": {r.name: r.describe() for r in self.random},
            "draws": self.draws,
            "seed": self.seed,
        }
        grid_names = [a.name for a in self.grid]
        random_names = [r.name for r in self.random]
        if grid_names != sorted(grid_names) or random_names != sorted(random_names):
            described["order"] = {"grid": grid_names, "random": random_names}
        return described


def _number(value: object, where: str) -> float:
    if isinstance(value, bool) or not isinstance(value, (int, float)) or not np.isfinite(value):
        raise InputError(f"{where} must be a finite number, got {value!r}")
    return float(value)


def parse_variables(ensemble: dict) -> VariableSource:
    """Read ``grid``, ``variables``, ``count`` and ``seed`` of ``[ensemble]``.

    Raises
    ------
    InputError
        A grid entry that is not ``[lo, hi, n]`` or has ``n < 1``, an unknown distribution
        or key, a name given twice, ``count < 1``, or no variable at all.
    """
    grid_table = ensemble.get("grid", {})
    if not isinstance(grid_table, dict):
        raise InputError("[ensemble] grid must be a table of variables, e.g. grid = { a = [-3.0, 3.0, 256] }")
    grid = []
    for name, entry in grid_table.items():
        where = f"[ensemble] grid {name}"
        if not isinstance(entry, list) or len(entry) != 3:
            raise InputError(f"{where} = {entry!r}: give [lo, hi, n] (n points from lo to hi, both included)")
        lo, hi = _number(entry[0], f"{where} lo"), _number(entry[1], f"{where} hi")
        n = entry[2]
        if isinstance(n, float) and n.is_integer():
            n = int(n)
        if isinstance(n, bool) or not isinstance(n, int) or n < 1:
            raise InputError(f"{where}: n = {entry[2]!r} must be an integer >= 1 (the number of points)")
        grid.append(GridAxis(name, lo, hi, n))
    random_table = ensemble.get("variables", {})
    if not isinstance(random_table, dict):
        raise InputError("[ensemble] variables must be a table, e.g. [ensemble.variables] g = { distribution = \"uniform\", low = 9.7, high = 9.9 }")
    random = []
    for name, table in random_table.items():
        where = f"[ensemble.variables] {name}"
        if name in grid_table:
            raise InputError(f"{where}: {name!r} is also a grid variable; give each variable once")
        if not isinstance(table, dict) or "distribution" not in table:
            raise InputError(f"{where} must be a table with a distribution ({', '.join(_DISTRIBUTIONS)})")
        kind = table["distribution"]
        if kind not in _DISTRIBUTIONS:
            raise unknown_name_error("distribution", str(kind), _DISTRIBUTIONS, where)
        keys = _DISTRIBUTIONS[kind]
        check_known_keys(table, {"distribution", *keys}, where)
        missing = sorted(keys - set(table))
        if missing:
            raise InputError(f"{where}: a {kind} distribution needs {', '.join(missing)}")
        first, second = ("mean", "std") if kind == "gaussian" else ("low", "high")
        a, b = _number(table[first], f"{where} {first}"), _number(table[second], f"{where} {second}")
        if kind == "gaussian" and b < 0:
            raise InputError(f"{where}: std = {b} must be >= 0")
        if kind != "gaussian" and not a < b:
            raise InputError(f"{where}: low = {a} must be below high = {b}")
        if kind == "loguniform" and a <= 0:
            raise InputError(f"{where}: a loguniform distribution needs low > 0")
        random.append(RandomVariable(name, str(kind), a, b))
    draws = ensemble.get("count", 1 if grid else None)
    if draws is None:
        raise InputError("[ensemble] needs grid = { ... } and/or count = N with [ensemble.variables] random draws")
    if isinstance(draws, float) and draws.is_integer():
        draws = int(draws)
    if isinstance(draws, bool) or not isinstance(draws, int) or draws < 1:
        raise InputError(f"[ensemble] count = {draws!r} must be an integer >= 1")
    seed = ensemble.get("seed", 0)
    if isinstance(seed, bool) or not isinstance(seed, int) or seed < 0:
        raise InputError(f"[ensemble] seed = {seed!r} must be an integer >= 0")
    return VariableSource(tuple(grid), tuple(random), draws, seed)
