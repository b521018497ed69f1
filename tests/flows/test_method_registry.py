"""The method registry (dirac.flows.methods.registry) and the problem kinds methods accept."""

from __future__ import annotations

import subprocess
import sys

import numpy as np
import pytest

from dirac.errors import InputError
from dirac.flows import ConstrainedProblem, HeavyTopProblem, RigidBodyProblem, integrate
from dirac.flows.integration import problem_kind
from dirac.flows.methods.registry import CONTRACT_NAMES, METHODS, get_method, method_names
from dirac.flows.problems import Problem


def test_registry_is_complete_right_after_import_in_a_fresh_interpreter():
    code = (
        "import json, sys\n"
        "from dirac.flows.methods.registry import METHODS\n"
        "json.dump(sorted(METHODS), sys.stdout)\n"
    )
    result = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, check=True)
    names = set(__import__("json").loads(result.stdout))
    assert set(CONTRACT_NAMES) - {"auto"} <= names
    assert names == set(METHODS)


def test_lazy_package_names_are_the_registry():
    import dirac.flows as flows

    assert flows.METHODS is METHODS
    assert flows.get_method is get_method
    assert flows.method_names is method_names


def test_method_names_put_the_contract_names_first_then_the_extras_sorted():
    names = method_names()
    assert names[: len(CONTRACT_NAMES)] == list(CONTRACT_NAMES)
    extras = names[len(CONTRACT_NAMES) :]
    assert extras == sorted(extras) and set(extras) == set(METHODS) - set(CONTRACT_NAMES)


def test_unknown_name_lists_the_known_ones_sorted_and_suggests_the_closest():
    from dirac.flows.methods.registry import method_names

    with pytest.raises(InputError) as error:
        get_method("leapfrog")  # nothing close: no suggestion
    assert str(error.value) == f"unknown method 'leapfrog'; known methods: {', '.join(sorted(method_names()))}"
    with pytest.raises(InputError, match=r"^unknown method 'rattle2' \(did you mean 'rattle-2'"):
        get_method("rattle2")


def test_lie_poisson_methods_integrate_the_free_body_and_the_heavy_top():
    for name in METHODS:
        if name.startswith("lie-poisson-"):
            assert METHODS[name].problems == ("rigid_body", "heavy_top"), name


@pytest.fixture
def free_body() -> RigidBodyProblem:
    return RigidBodyProblem([2.0, 1.5, 1.0], [0.3, 0.6, -0.9])


@pytest.mark.parametrize(("name", "accepted"), [("rattle-2", "constrained"), ("rattle-4", "constrained")])
def test_a_method_refuses_a_kind_it_does_not_accept_naming_both(name, accepted, free_body):
    with pytest.raises(InputError) as info:
        get_method(name).start(free_body, ("M",), {"t_end": 1.0})
    message = str(info.value)
    assert f"method {name!r}" in message and "'rigid_body'" in message and accepted in message


def test_exact_refuses_the_heavy_top():
    top = HeavyTopProblem([2.0, 1.5, 1.0], [0.3, 0.6, -0.9], mass_gravity=0.5)
    with pytest.raises(InputError, match=r"method 'exact' cannot integrate a problem of kind 'heavy_top'; "
                                         r"it accepts: rigid_body"):
        get_method("exact").start(top, ("M",), {"t_end": 1.0})
    with pytest.raises(InputError, match=r"method 'exact' cannot integrate a heavy top problem"):
        integrate(top, "exact", t_end=1.0)


def test_problems_declare_their_kind(free_body, pendulum_system):
    top = HeavyTopProblem([2.0, 1.5, 1.0], [0.3, 0.6, -0.9])
    pendulum = ConstrainedProblem(pendulum_system, [1.0, 0.0], [0.0, 0.0])
    for problem, kind in ((free_body, "rigid_body"), (top, "heavy_top"), (pendulum, "constrained")):
        assert isinstance(problem, Problem)
        assert problem.kind == kind == problem_kind(problem)


def test_a_constrained_system_named_like_a_built_in_problem_is_still_constrained(pendulum_system):
    """Dispatch reads ``kind``, not the system's name."""
    import dataclasses

    renamed = dataclasses.replace(pendulum_system, name="rigid_body")
    pendulum = ConstrainedProblem(renamed, [1.0, 0.0], [0.0, 0.0])
    solution = integrate(pendulum, "midpoint", t_end=0.1, dt=0.01, samples=2, outputs=["q"])
    assert solution["q"].shape == (2, 2) and np.all(np.isfinite(solution["q"]))


def test_problem_kind_refuses_what_is_not_a_problem():
    with pytest.raises(InputError, match="cannot integrate a dict"):
        problem_kind({"kind": "rigid_body"})


def test_get_method_auto_says_what_auto_is():
    with pytest.raises(InputError, match="'auto' is not one method: it chooses one for each problem") as refused:
        get_method("auto")
    assert "did you mean" not in str(refused.value) and "rattle-2" in str(refused.value)
