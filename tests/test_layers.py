"""The layers of the package and what each may import (docs/architecture.md).

Data flows one way: model -> analysis -> codegen -> flows -> integrate -> Solution, with
files (io), ensembles, benchmarks, plots and the command line built on top. Each layer may
import only the layers listed for it below; function-level imports count, so a lazy import
cannot hide a dependency that runs against the flow. A new package must be added here and
to the architecture page.
"""

from __future__ import annotations

from import_graph import cycles, import_graph, modules, strongly_connected_components

#: layer -> the layers it may import (besides itself)
ALLOWED: dict[str, set[str]] = {
    "errors": set(),
    "lazy_exports": set(),
    "versions": set(),
    "compositions": set(),
    "validate": {"errors"},
    "model": {"errors", "validate"},
    "codegen": {"errors"},
    "analysis": {"errors", "validate", "model", "codegen"},
    "rigidbody": {"errors", "validate", "compositions"},
    "flows": {"errors", "validate", "versions", "compositions", "model", "analysis", "codegen", "rigidbody"},
    "fields": {"errors", "validate", "model", "analysis"},
    "io": {"errors", "validate", "model", "rigidbody", "flows"},
    "ensemble": {"errors", "validate", "versions", "model", "codegen", "rigidbody", "flows", "io"},
    "bench": {"errors", "validate", "versions", "model", "rigidbody", "flows", "io", "fields"},
    "plots": {"errors", "lazy_exports"},
    "commands": {"errors", "validate", "versions", "model", "analysis", "rigidbody", "flows", "io", "ensemble",
                 "bench", "plots", "fields"},
    "cli": {"errors", "commands"},
    "__main__": {"cli"},
    "dirac": {"errors", "lazy_exports"},
}


def layer(module: str) -> str:
    """``dirac.flows.methods.rattle`` -> ``flows``; the package itself -> ``dirac``."""
    parts = module.split(".")
    return parts[1] if len(parts) > 1 else "dirac"


def test_the_cycle_finder_finds_a_cycle():
    graph = {"a": {"b"}, "b": {"c"}, "c": {"a"}, "d": {"a"}}
    assert cycles(graph) == [["a", "b", "c"]]
    assert sorted(map(len, strongly_connected_components(graph))) == [1, 3]


def test_the_graph_sees_function_level_imports():
    graph = import_graph()
    assert "dirac.codegen" in graph["dirac.flows.mechanics"]  # imported inside a method


def test_no_import_cycle_in_the_package():
    assert cycles(import_graph()) == []


def test_every_layer_is_in_the_table():
    assert {layer(m) for m in modules()} <= set(ALLOWED)


def test_each_layer_imports_only_the_layers_below_it():
    against = sorted(
        f"{module} -> {target}"
        for module, imported in import_graph().items()
        for target in imported
        if layer(target) != layer(module) and layer(target) not in ALLOWED.get(layer(module), set())
    )
    assert against == []


def test_the_layer_table_has_no_cycle():
    assert cycles({name: set(allowed) for name, allowed in ALLOWED.items()}) == []


#: sub-package of dirac.analysis -> the sub-packages it may import (the steps of the algorithm,
#: docs/architecture.md); the modules on top of dirac.analysis may import every sub-package
ANALYSIS_ALLOWED: dict[str, set[str]] = {
    "core": set(),
    "legendre": {"core"},
    "classes": {"core", "legendre"},
    "chain": {"core", "legendre", "classes"},
    "brackets": {"core"},
    "gauge": {"core", "chain", "classes", "brackets"},
}


def analysis_step(module: str) -> str | None:
    """``dirac.analysis.chain.constraint_chain`` -> ``chain``; ``None`` outside a sub-package."""
    parts = module.split(".")
    if parts[:2] != ["dirac", "analysis"] or len(parts) < 3 or parts[2] not in ANALYSIS_ALLOWED:
        return None
    return parts[2]


def test_every_analysis_module_but_the_top_two_is_in_a_step():
    top = {"dirac.analysis", "dirac.analysis.constraint_analysis", "dirac.analysis.report", "dirac.analysis.cases", "dirac.analysis.components"}
    assert sorted(m for m in modules() if m.startswith("dirac.analysis") and m not in top and analysis_step(m) is None) == []


def test_each_analysis_step_imports_only_the_steps_it_may():
    against = sorted(
        f"{module} -> {target}"
        for module, imported in import_graph().items()
        if (step := analysis_step(module)) is not None
        for target in imported
        if target.startswith("dirac.analysis")
        and analysis_step(target) != step
        and analysis_step(target) not in ANALYSIS_ALLOWED[step]
    )
    assert against == []


def test_the_analysis_step_table_has_no_cycle():
    assert cycles({name: set(allowed) for name, allowed in ANALYSIS_ALLOWED.items()}) == []
