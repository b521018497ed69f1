"""Single scenes of systems integrated on the Dirac flow of their analysis (docs/file_formats.md)."""

from __future__ import annotations

import numpy as np
import pytest

from dirac.errors import InputError
from dirac.io.scene import scene_from_dict

#: A velocity-linear pair (x, y) and a particle on the unit circle z^2 + w^2 = 1 in the potential
#: z^2/2: the analysis adds the multiplier lambda_1 (and p_lambda_1), which a scene's initial state
#: leaves to be completed on the constraint surface.
RING = {"name": "ring", "coordinates": ["x", "y", "z", "w"],
        "lagrangian": "x*y_dot - (x**2 + y**2)/2 + z_dot**2/2 + w_dot**2/2 - z**2/2",
        "constraints": ["z**2 + w**2 - 1"]}
A = 0.7
START = {"q": {"x": 1.0, "y": 0.0, "z": float(np.cos(A)), "w": float(np.sin(A))},
         "q_dot": {"z": float(-np.sin(A)), "w": float(np.cos(A))}}
RUN = {"t_end": 0.1, "dt": 0.01, "method": "midpoint"}


def test_the_completed_multiplier_is_the_same_in_every_load():
    """The multiplier is solved by Gauss-Newton from a random start; a scene fixes that start
    (seed 0, the start an ensemble member of the same state gets), so two loads give the same
    bits and equal ``initial_state(..., seed=0)``. By hand: on the circle at angle a with unit
    speed, the radial equation gives lambda_1 = (|q_dot|^2 - z * dV/dz) / 2 = (1 - cos(a)^2) / 2
    in the sign of the analysis, checked up to sign and rounding."""
    first = scene_from_dict({"system": RING, "initial": START, "run": RUN}).problem
    second = scene_from_dict({"system": RING, "initial": START, "run": RUN}).problem
    assert np.array_equal(first.z0, second.z0)
    names = first.analysed.variable_names
    expected = first.analysed.initial_state(START["q"], q_dot=START["q_dot"], seed=0)
    assert np.array_equal(first.z0[0], expected)
    multiplier = first.z0[0][names.index("lambda_1")]
    assert abs(abs(multiplier) - (1.0 - np.cos(A) ** 2) / 2.0) < 1e-12


def test_project_true_is_refused_for_a_system_run_on_its_analysis():
    """``project = true`` would project nothing here (the values given are held, the rest
    completed): it is refused with the way out, as the ensemble of the same system refuses it."""
    with pytest.raises(InputError, match=r"project = true: 'ring' runs on the Dirac flow.*set project = false"):
        scene_from_dict({"system": RING, "initial": {**START, "project": True}, "run": RUN})


def test_initial_state_repeats_by_default():
    """``AnalysedSystem.initial_state`` without a seed completes from the same start as a scene
    does (seed 0), so a Python run repeats to the last bit as a scene run does."""
    problem = scene_from_dict({"system": RING, "initial": START, "run": RUN}).problem
    again = problem.analysed.initial_state(START["q"], q_dot=START["q_dot"])
    assert np.array_equal(problem.z0[0], again)
