"""The `DiracError` family of exceptions and the one way to warn.

Every error that `dirac` raises on purpose is a :class:`DiracError`. The command line
turns it into one ``error: …`` line on stderr and exit status 2; anything else is an
internal failure (exit status 1). Messages name the offending item and say what to do.
"""

from __future__ import annotations

import os
import sys
import types
import warnings
from collections.abc import Iterator
from contextlib import contextmanager

__all__ = [
    "inform",
    "quiet_information",
    "DiracError",
    "InputError",
    "InconsistentSystemError",
    "AnalysisError",
    "IntegrationError",
    "CoordinateSingularityError",
    "PoleError",
    "DiracWarning",
    "warn",
    "install_warning_printer",
]


class DiracError(Exception):
    """Base class of every error `dirac` raises on purpose."""


class InputError(DiracError, ValueError):
    """Bad input: a system, scene, expression, parameter or argument that cannot be used."""


class InconsistentSystemError(InputError):
    """The Dirac–Bergmann algorithm met a condition such as ``1 = 0``.

    The Lagrangian has no motion at all (for example ``L = x_dot**2/2 + y`` with no
    kinetic term for ``y``: the consistency of ``p_y = 0`` demands ``1 = 0``).
    """


class AnalysisError(DiracError):
    """The symbolic analysis cannot be carried out in closed form (e.g. primary
    constraints of a Lagrangian that is not quadratic in the velocities)."""


class SeparableParts(AnalysisError):
    """The constraint surface has parts of different structure that can be told apart.

    Attributes
    ----------
    holonomic
        For a holonomic constraint that is a union of crossing branches: its index (1-based)
        in the system's constraints, with ``branches`` its factors; else ``None``.
    branches
        The factors of that constraint (sympy expressions).
    points, ranks, variables
        For a rank that differs between points of the surface: the points (arrays over the
        phase-space ``variables``, by name) and the rank at each.
    """

    def __init__(
        self,
        message: str,
        holonomic: int | None = None,
        branches: list | None = None,
        points: list | None = None,
        ranks: list[int] | None = None,
        variables: list | None = None,
    ) -> None:
        super().__init__(message)
        self.holonomic = holonomic
        self.branches = list(branches or [])
        self.points = list(points or [])
        self.ranks = list(ranks or [])
        self.variables = list(variables or [])


class IntegrationError(DiracError):
    """A numerical integration had to stop (non-finite state, Newton non-convergence,
    constraint drift). ``partial`` holds what was computed up to that point, if any."""

    def __init__(self, message: str, partial: object | None = None) -> None:
        super().__init__(message)
        self.partial = partial


class CoordinateSingularityError(IntegrationError):
    """A run came near a coordinate singularity (``det W = 0``, ``W = d^2 L/dq_dot^2``, e.g. ``sin(theta) = 0``
    for Euler angles): the message names the locus, the time and another chart to use."""


class PoleError(IntegrationError):
    """The motion reached or stepped across a pole of its equations of motion (a denominator of the force, the
    mass matrix, the constraints or the forces vanishing, e.g. ``x = 0`` of the force ``-1/x`` of ``V = log(x)``):
    a singularity of the physics at a finite time, which a smaller step does not cure. The message names the
    expression that vanishes, the interval of time and the remedies; ``partial`` ends before the pole."""


class DiracWarning(UserWarning):
    """Input that is legal but suspicious (e.g. an inertia no physical body has)."""


def warn(message: str) -> None:
    """Report legal but suspicious input as a :class:`DiracWarning`.

    Library callers see an ordinary Python warning (catch it with
    ``warnings.catch_warnings`` or ``pytest.warns``); the command line shows each one as a
    single ``warning: …`` line on stderr (see :func:`install_warning_printer`).

    Parameters
    ----------
    message
        One line that names the suspicious item and why it is suspicious.
    """
    line = " ".join(str(message).split())
    warnings.warn(line, DiracWarning, stacklevel=_user_stacklevel())


#: folder of the ``dirac`` package; frames of files under it are the package's own
_PACKAGE_DIR = os.path.dirname(os.path.abspath(__file__)) + os.sep


def _in_package(frame) -> bool:
    """Whether ``frame`` runs code of the package: a file in it, or code it generated
    (dataclass methods, whose file is ``<string>`` but whose globals are a package module)."""
    module = str(frame.f_globals.get("__name__", ""))
    if module == "dirac" or module.startswith("dirac."):
        return True
    return os.path.abspath(frame.f_code.co_filename).startswith(_PACKAGE_DIR)


def _user_stacklevel() -> int:
    """``stacklevel`` for :func:`warnings.warn` called in :func:`warn`: the first frame outside the package.

    Frame 1 is :func:`warn` itself; walking outwards past every frame of a file in the
    ``dirac`` package finds the user's line (a script, a notebook cell, a test).
    """
    level = 1
    frame: types.FrameType | None = sys._getframe(1)
    while frame is not None and _in_package(frame):
        frame = frame.f_back
        level += 1
    return level


_quiet = False  # quiet_information() in force


@contextmanager
def quiet_information() -> Iterator[None]:
    """Inside: :func:`inform` prints nothing (``-q`` of the command line: no informational
    stderr lines; warnings and errors stay); the state before is restored on leaving."""
    global _quiet
    before, _quiet = _quiet, True
    try:
        yield
    finally:
        _quiet = before


def inform(message: str) -> bool:
    """One informational line on stderr (such as the announcement of a compilation), unless
    inside :func:`quiet_information`; whether it was printed."""
    if _quiet:
        return False
    print(message, file=sys.stderr, flush=True)
    return True


def install_warning_printer() -> None:
    """Show every :class:`DiracWarning` as one ``warning: …`` line on stderr (CLI use).

    Other warnings keep Python's default display.
    """
    previous = warnings.showwarning

    def show(message, category, filename, lineno, file=None, line=None):
        if issubclass(category, DiracWarning):
            print(f"warning: {message}", file=sys.stderr)
        else:
            previous(message, category, filename, lineno, file, line)

    warnings.simplefilter("always", DiracWarning)
    warnings.showwarning = show
