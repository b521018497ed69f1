"""The result of :func:`dirac.flows.integrate`: sampled outputs, counters and status."""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

__all__ = ["Solution"]


@dataclass
class Solution:
    """Sampled outputs of one integration.

    Attributes
    ----------
    t : numpy.ndarray, shape (samples,)
        Output times actually reached (fewer than requested when ``complete`` is false).
    outputs : dict
        Output name -> array with leading axis ``samples`` (then the batch axis when the
        problem was batched), e.g. ``M`` (samples, 3), ``R`` (samples, 3, 3).
    system, method : str
    order : int
    dt : float or None
        Step size used (fixed-step methods; adapted so that it divides the sample spacing).
    steps : int
        Steps taken (per initial state).
    evaluations : int
        Vector-field or sub-flow evaluations (all states together).
    cpu_seconds : float
        CPU time of the integration itself; compilation excluded.
    complete : bool
        False when the run stopped early (error or interruption).
    message : str
        Why the run stopped early (empty when complete).
    parameters : dict
        Numerical parameters of the problem.
    """

    t: np.ndarray = field(repr=False)
    outputs: dict[str, np.ndarray]
    system: str
    method: str
    order: int
    dt: float | None
    steps: int
    evaluations: int
    cpu_seconds: float
    complete: bool = True
    message: str = ""
    parameters: dict[str, object] = field(default_factory=dict)
    extra: dict[str, object] = field(default_factory=dict)

    def __getitem__(self, name: str) -> np.ndarray:
        """The samples of one output (``solution["M"]``)."""
        if name == "t":
            return self.t
        try:
            return self.outputs[name]
        except KeyError:
            raise KeyError(f"output {name!r} was not requested; this solution has {sorted(self.outputs)}") from None

    def __contains__(self, name: object) -> bool:
        return name == "t" or name in self.outputs

    def _shapes(self) -> dict[str, tuple[int, ...]]:
        shapes = {"t": tuple(np.shape(self.t))}
        shapes.update({name: tuple(np.shape(value)) for name, value in self.outputs.items()})
        return shapes

    def __repr__(self) -> str:
        """The fields, with the shapes of the arrays instead of their values."""
        shapes = ", ".join(f"{name}{list(shape)}" for name, shape in self._shapes().items())
        status = "complete" if self.complete else f"incomplete: {self.message}"
        return (
            f"Solution(system={self.system!r}, method={self.method!r}, order={self.order}, dt={self.dt!r}, "
            f"steps={self.steps}, evaluations={self.evaluations}, cpu_seconds={self.cpu_seconds:.3g}, "
            f"{status}, outputs: {shapes})"
        )

    def _repr_html_(self) -> str:
        """A small table for Jupyter: system, method, steps, CPU time, outputs with their shapes."""
        from html import escape

        rows = [
            ("system", self.system),
            ("method", f"{self.method} (order {self.order})"),
            ("dt", "(none: not a fixed-step method)" if self.dt is None else f"{self.dt:.6g}"),
            ("steps", str(self.steps)),
            ("evaluations", str(self.evaluations)),
            ("CPU", f"{self.cpu_seconds:.3g} s"),
            ("status", "complete" if self.complete else f"incomplete: {self.message}"),
        ]
        rows += [(f"output {name}", " × ".join(map(str, shape)) or "scalar") for name, shape in self._shapes().items()]
        body = "".join(f"<tr><th style='text-align:left'>{escape(k)}</th><td>{escape(v)}</td></tr>" for k, v in rows)
        return f"<table><caption>dirac Solution</caption>{body}</table>"

    def meta(self) -> dict[str, object]:
        """The ``meta`` record of the result file (docs/file_formats.md)."""
        from dirac.versions import result_versions

        record: dict[str, object] = {
            "system": self.system,
            "parameters": self.parameters,
            "method": self.method,
            "order": self.order,
            "dt": self.dt,
            "steps": self.steps,
            "evaluations": self.evaluations,
            "cpu_seconds": self.cpu_seconds,
            "complete": self.complete,
            "samples": int(self.t.shape[0]),
            "outputs": list(self.outputs),
            "versions": result_versions(),
        }
        if self.message:
            record["message"] = self.message
        record.update(self.extra)
        return record
