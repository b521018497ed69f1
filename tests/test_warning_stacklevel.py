"""Warnings of the package point at the caller's line, not inside the package."""

from __future__ import annotations

import warnings

import dirac
from dirac.errors import DiracWarning


def test_warning_points_at_the_users_line():
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        dirac.RigidBodyProblem(inertia=(1.0, 1.0, 5.0), M0=(1.0, 0.0, 0.0))  # 1 + 1 < 5: warned
        line = __import__("inspect").currentframe().f_lineno - 1
    (warning,) = [w for w in caught if issubclass(w.category, DiracWarning)]
    assert warning.filename == __file__ and warning.lineno == line
